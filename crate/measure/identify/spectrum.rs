//! The stages of [`identify_spectrum`](super::identify_spectrum): the file's bins checked and
//! put on a grid from 0 Hz, the band, and the peaks' half-power seeds.

use super::half_power::{half_power, HalfPower};
use super::model::WindowSpec;
use super::peaks::{detect_within, rising_into_end, smoothed_db};
use super::{IdentifyOptions, Slot};
use crate::error::{count, positive, Error, Result};
use crate::measure::psd::{window, Psd, WindowKind, MAX_SEGMENT_LENGTH};
use crate::measure::spectrum_file::{resolution, Normalization, SpectrumFile};

/// A spectrum file on the grid f_k = k·Δf with the window it was estimated with.
pub(super) struct Grid {
    pub psd: Psd,
    pub window: WindowSpec,
    pub normalized: bool,
}

/// Checks the bins (count, matching lengths, finite non-negative PSD, even increasing
/// frequencies) and puts them on the grid from 0 (Klipper's rows start at bin 0; a file
/// starting later gets empty bins in front), with Klipper's window: symmetric Kaiser β = 6 of
/// the file's segment length (or the shortest power of two covering the bins).
pub(super) fn grid(spectrum: &SpectrumFile) -> Result<Grid> {
    let f = &spectrum.frequency_hz;
    let p = &spectrum.psd;
    count("spectrum.frequencyHz", f.len(), 8, MAX_SEGMENT_LENGTH)?;
    if p.len() != f.len() {
        return Err(Error::invalid(
            "spectrum.psd",
            format!("has {} values for {} frequencies", p.len(), f.len()),
        ));
    }
    if let Some(i) = p.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
        return Err(Error::invalid(
            format!("spectrum.psd[{i}]"),
            format!("must be a finite number ≥ 0, got {}", p[i]),
        ));
    }
    if let Some(i) = f.windows(2).position(|w| w[1] <= w[0] || w[1].is_nan()) {
        return Err(Error::invalid(
            format!("spectrum.frequencyHz[{}]", i + 1),
            "frequencies must increase",
        ));
    }
    let (df, even) = resolution(f);
    if !even {
        return Err(Error::invalid(
            "spectrum.frequencyHz",
            "the bins are not evenly spaced",
        ));
    }
    let k0 = (f[0] / df).round().max(0.0) as usize;
    let n = k0 + f.len();
    let mut psd_full = vec![0.0; k0];
    psd_full.extend_from_slice(p);
    let segment = spectrum
        .segment_length
        .unwrap_or_else(|| (2 * (n - 1)).next_power_of_two().max(256));
    let w = window(WindowKind::Kaiser, 2048, true, 6.0);
    let (s1, s2) = w.iter().fold((0.0, 0.0), |(a, b), v| (a + v, b + v * v));
    let psd = Psd {
        frequency_hz: (0..n).map(|k| k as f64 * df).collect(),
        psd: psd_full,
        segment_length: segment,
        overlap: segment / 2,
        segments: 0,
        resolution_hz: df,
        enbw_bins: 2048.0 * s2 / (s1 * s1),
        sample_rate_hz: df * segment as f64,
    };
    Ok(Grid {
        psd,
        window: WindowSpec {
            kind: WindowKind::Kaiser,
            length: segment,
            symmetric: true,
            beta: 6.0,
        },
        normalized: spectrum.normalization == Normalization::Klipper,
    })
}

/// The band: the options' or [5 Hz (10 Hz normalised) or the second bin, the last bin].
pub(super) fn band(grid: &Grid, options: &IdentifyOptions) -> Result<[f64; 2]> {
    let df = grid.psd.resolution_hz;
    let n = grid.psd.psd.len();
    let lowest: f64 = if grid.normalized { 10.0 } else { 5.0 };
    let f_lo = match options.min_frequency_hz {
        Some(v) => positive("minFrequencyHz", v)?,
        None => lowest.max(2.0 * df),
    };
    let f_hi = match options.max_frequency_hz {
        Some(v) => positive("maxFrequencyHz", v)?,
        None => (n - 1) as f64 * df,
    };
    if f_lo >= f_hi {
        return Err(Error::invalid(
            "minFrequencyHz",
            format!("must be below maxFrequencyHz ({f_hi} Hz), got {f_lo}"),
        ));
    }
    Ok([f_lo, f_hi])
}

/// The peaks of the spectrum with Klipper's normalisation undone (the modal peaks are those of
/// the un-normalised PSD; 3-bin smoothing: Klipper's bins are coarse) in bins `lo..=hi`, and
/// their half-power seeds, one per maximum. Leakage widens a narrow peak to the kernel's
/// width: a seed's damping is an upper bound, kept as it is.
///
/// With the sweep's end found ([`sweep_end`]; `cut` the last bin before it), peaks are
/// searched in `lo..=cut` only, their prominence still read over `lo..=hi` (a mode just under
/// the end has its high side's base past the cliff), and kept only when the PSD falls ≥ 3 dB
/// between them and bin `cut`: their half-power point on the high side lies in the fitted bins. The cliff's
/// shoulder, flat up to the cliff, is no such peak. The bin of the last peak dropped so (a
/// mode a few bins under the end, or the cliff's shoulder: the fit tells) is returned too.
pub(super) fn seeds(
    grid: &Grid,
    lo: usize,
    hi: usize,
    cut: Option<usize>,
    options: &IdentifyOptions,
) -> (Vec<HalfPower>, Vec<Slot>, Option<usize>) {
    let psd = &grid.psd;
    let df = psd.resolution_hz;
    let unnormalized = Psd {
        psd: psd
            .psd
            .iter()
            .zip(&psd.frequency_hz)
            .map(|(v, f)| if grid.normalized { v * (f + 0.1) } else { *v })
            .collect(),
        ..psd.clone()
    };
    let top = cut.unwrap_or(hi);
    let (peaks, shoulders): (Vec<_>, Vec<_>) = detect_within(
        &unnormalized,
        [lo, top],
        [lo, hi],
        options.min_prominence_db,
        options.max_modes,
        1,
    )
    .into_iter()
    .partition(|pk| {
        let k = (pk.frequency_hz / df).round() as usize;
        cut.is_none_or(|c| {
            let low = unnormalized.psd[k.min(c)..=c]
                .iter()
                .cloned()
                .fold(f64::INFINITY, f64::min);
            unnormalized.psd[k] >= low * 10f64.powf(0.3)
        })
    });
    let shoulder = shoulders
        .iter()
        .map(|pk| (pk.frequency_hz / df).round() as usize)
        .max();
    let mut slots = Vec::new();
    let mut halves: Vec<HalfPower> = Vec::new();
    for pk in &peaks {
        let Some(h) = half_power(
            &unnormalized,
            pk.frequency_hz,
            2.0 * df,
            lo,
            top,
            options.signal,
        ) else {
            continue;
        };
        if !halves.iter().any(|o| (o.peak_hz - h.peak_hz).abs() < df) {
            halves.push(h);
            slots.push(Slot {
                peak_hz: h.peak_hz,
                peak_psd: h.peak_psd,
                prominence_db: pk.prominence_db,
                estimates: vec![h.estimate],
            });
        }
    }
    (halves, slots, shoulder)
}

/// The end of the sweep in a spectrum file, the last bin before it (`None` when there is
/// none). Klipper's releases of 2021–2023 swept to 133.33 Hz and wrote rows to 200 Hz; its
/// PSD falls off a cliff there, smeared over 2–3 bins by the window, and a modal fit reads the
/// cliff's shoulder as a lightly damped mode. A mode cannot make that shape: its high side
/// falls no faster than its low side rises (a narrow peak is the window's symmetric kernel),
/// then flattens to its f⁻⁴ (PSD) asymptote. So a cliff at bin k is, on the un-normalised
/// PSD, going up from the band's start: a fall of ≥ 8 dB from k to k + 3 (≥ 8 dB over
/// 3 bins: 2.3–3.5 % of 133 Hz, hundreds of dB per decade) with ≥ 5 dB from one bin to the
/// next among them (a step smeared by the window; a mode's high side falling into an
/// anti-resonance falls ~3 dB per bin), at least twice the fall over k − 3..k (the slope
/// steepens abruptly: not a mode's high side, whose fall per bin lessens away from its peak),
/// and either
/// - no rise of more than 3 dB anywhere over k − 5..k (not a peak's flank: a peak that sharp
///   rises as fast as it falls) and the PSD staying ≥ 6 dB under bin k for the 6 bins past
///   k + 3 (not an anti-resonance between two modes, whose notch comes back up); or
/// - a response rising into the cliff (a mode past the sweep's end): bin k the top of
///   k − 5..k (within 1.5 dB, three times the scatter of a bin averaged over 80 segments), its
///   rise at most a third of the fall, or its steepest rise per bin (on 3-bin means, where a
///   bin's noise is a third) at most a third of the cliff's steepest drop per bin (it rises
///   far more slowly than the cliff falls, while a sharp peak, the window's symmetric kernel,
///   rises as fast as it falls: a sharp mode just past the end rises 8 dB over the 5 bins
///   but ≤ 2 dB per bin into a 10 dB step), and the PSD staying ≥ 6 dB under bin k from
///   k + 3 to the file's last row (a mode followed by a deep anti-resonance also falls from
///   its top by far more than it rose, but its notch comes back up to the next mode, however
///   far away: 60 Hz then 142 Hz, the notch near 70–80 Hz low for many bins).
///
/// Returned:
/// the bin before the steepest one-bin drop of those 3, already inside the window's smear of
/// the cliff; the caller fits up to the bin before it.
/// Measured on 11 public Klipper files (docs/measured-data.md, *On real recordings*).
pub(super) fn sweep_end(grid: &Grid, lo: usize, hi: usize) -> Option<usize> {
    let db = unnormalized_db(grid);
    let n = db.len();
    let start = lo.max(5);
    let end = hi.min(n.saturating_sub(10));
    let k = (start..end).find(|&k| {
        let fall = db[k] - db[k + 3];
        let w = &db[k - 5..=k];
        let rise = (1..w.len())
            .map(|j| w[j] - w[..j].iter().cloned().fold(f64::INFINITY, f64::min))
            .fold(f64::NEG_INFINITY, f64::max);
        // Rising into k (k the top of the window): a response still rising at the cliff.
        let top = w.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let steepest = (k..k + 3).map(|j| db[j] - db[j + 1]).fold(0.0, f64::max);
        // The steepest rise per bin into k, on the 3-bin mean (its noise a third of a bin's
        // power, ~0.3 dB over 80 segments) of the bins up to k.
        let mean3 = |j: usize| (db[j - 1] + db[j] + db[j + 1]) / 3.0;
        let steepest_rise = (k - 3..k)
            .map(|j| mean3(j) - mean3(j - 1))
            .fold(0.0, f64::max);
        let rising_into =
            db[k] >= top - 1.5 && (rise <= fall / 3.0 || 3.0 * steepest_rise <= steepest);
        let before = db[k - 3] - db[k];
        let highest = |r: &[f64]| r.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let down = |r: &[f64]| highest(r) <= db[k] - 6.0;
        fall >= 8.0
            && steepest >= 5.0
            && fall >= 2.0 * before
            && ((rise <= 3.0 && down(&db[k + 3..k + 9])) || (rising_into && down(&db[k + 3..])))
    })?;
    let drop = |j: usize| db[j] - db[j + 1];
    let k = (k..k + 3).fold(k, |best, j| if drop(j) > drop(best) { j } else { best });
    Some(k)
}

/// Where the excitation ends, Hz, given [`sweep_end`]'s bin `e`: where the un-normalised PSD
/// crosses 3 dB under its level at `e − 1` (interpolated in dB between bins `e − 1 … e + 2`),
/// the half-level point of the window's smear of a step (the real files' cliff: their bin
/// 1.3 bins under Klipper's 133.33 Hz is ≤ 0.3 dB down, the one 0.3 bins under it ~3 dB,
/// docs/measured-data.md), and of a gentler taper's middle. Half a bin past `e` when the
/// drop is not found there.
pub(super) fn end_hz(grid: &Grid, e: usize) -> f64 {
    let db = unnormalized_db(grid);
    let f = &grid.psd.frequency_hz;
    let df = grid.psd.resolution_hz;
    let level = db[e - 1] - 3.0;
    (e - 1..(e + 2).min(db.len() - 1))
        .find(|&j| db[j] >= level && db[j + 1] < level)
        .map_or(f[e] + 0.5 * df, |j| {
            f[j] + df * (db[j] - level) / (db[j] - db[j + 1])
        })
}

/// The PSD in dB with Klipper's normalisation undone (the modal peaks are those of the
/// un-normalised PSD), every bin of the grid.
fn unnormalized_db(grid: &Grid) -> Vec<f64> {
    let psd = &grid.psd;
    psd.psd
        .iter()
        .zip(&psd.frequency_hz)
        .map(|(v, f)| {
            let v = if grid.normalized { v * (f + 0.1) } else { *v };
            10.0 * v.max(1e-300).log10()
        })
        .collect()
}

/// A response cut off by the sweep's end: the PSD (un-normalised, 3-bin smoothed) still
/// rising into the last fitted bins. Its top — the highest of the last three (the window
/// smears the cliff over ±2 bins, and the sweep's own taper takes a little off them) — stands
/// `min_db` or more over the lowest
/// point between it and the nearest higher bin on its left (or the band's start): the
/// topographic prominence of a peak whose right side is not in the file. Returned: that
/// prominence, dB, and the top's bin. Such a response may have its maximum at or past the
/// sweep's end (where, and its damping, the file cannot say: issue 20, a file whose spectrum
/// rises to the end must not come out as "no mode"), or be a mode a few bins under it: the
/// caller's fit tells (identify/mod.rs, `identify_spectrum`).
pub(super) fn rising_to_end(
    grid: &Grid,
    lo: usize,
    cut: usize,
    min_db: f64,
) -> Option<(f64, usize)> {
    if cut < lo + 4 {
        return None;
    }
    rising_into_end(&smoothed_db(&unnormalized_db(grid), lo, cut, 1), 3, min_db)
        .map(|(p, at)| (p, lo + at))
}
