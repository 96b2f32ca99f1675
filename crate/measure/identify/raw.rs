//! The stages of [`identify`](super::identify) on a raw recording: the detection PSD and the
//! band, the spectrum the modes are fitted on (a Welch PSD whose segments suit the peaks, or a
//! sweep's whole-record periodogram inside its band), the peaks' half-power seeds, and the
//! free decay.

use super::decay::{decay_fit, find_decay};
use super::half_power::{half_power, smoothed, HalfPower};
use super::peaks::{detect_within, rising_into_end, smoothed_db, to_db, Peak};
use super::sweep::Sweep;
use super::{FreeDecay, IdentifyOptions, Slot, MAX_MODES};
use crate::error::{count, positive, Error, Result};
use crate::measure::psd::{welch, Detrend, Psd, Scaling, WelchOptions, WindowKind};

/// What the fits start from: the spectrum, its peaks with their half-power seeds (one per
/// maximum), the band fitted, peaks fitted each on its own (a sweep's start), and a response
/// still rising into the band's top (a sweep's end).
pub(super) struct Stage {
    pub psd: Psd,
    pub found: Vec<(Peak, HalfPower)>,
    pub band: [f64; 2],
    pub local: Vec<Local>,
    pub rising: Option<Rising>,
}

/// A response still rising into the top of a sweep's fitted band: a mode peaking near or past
/// the sweep's end (see [`sweep_stage`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct Rising {
    /// How far the top stands over the lowest point of its left flank, dB.
    pub prominence_db: f64,
    /// The top's bin.
    pub top: usize,
    /// The smoothed PSD there.
    pub level: f64,
    /// Where the fit's extra mode is seeded, Hz: past the band for a rise into its top, the
    /// peak's own frequency for a peak whose high side the end cuts.
    pub seed_hz: f64,
}

/// A peak below the part of a sweep whose spectrum is smooth, to be fitted alone on `band`
/// (see [`sweep_stage`]).
pub(super) struct Local {
    pub peak: Peak,
    pub half: HalfPower,
    pub band: [f64; 2],
}

fn pow2_floor(n: usize) -> usize {
    if n == 0 {
        0
    } else {
        1usize << (usize::BITS - 1 - n.leading_zeros())
    }
}

fn hann_welch(fs: f64, segment: usize) -> WelchOptions {
    WelchOptions {
        sample_rate_hz: fs,
        segment_length: Some(segment),
        overlap: Some(segment / 2),
        window: WindowKind::Hann,
        kaiser_beta: 6.0,
        symmetric_window: false,
        detrend: Detrend::Constant,
        scaling: Scaling::Density,
    }
}

/// The detection PSD (Hann, half overlap, `segmentLength` or 2^⌊log₂(n/4)⌋ samples) and its
/// segment length.
pub(super) fn detection_psd(
    signal: &[f64],
    fs: f64,
    options: &IdentifyOptions,
) -> Result<(Psd, usize)> {
    let n = signal.len();
    let n0 = match options.segment_length {
        Some(s) => {
            count("segmentLength", s, 64, n)?;
            s
        }
        None => pow2_floor(n / 4).clamp(64, 65536),
    };
    Ok((welch(signal, &hann_welch(fs, n0))?, n0))
}

/// The band searched: the options' or [3 bins, 0.45 f_s].
pub(super) fn search_band(options: &IdentifyOptions, fs: f64, df0: f64) -> Result<[f64; 2]> {
    let f_lo = match options.min_frequency_hz {
        Some(f) => positive("minFrequencyHz", f)?,
        None => 3.0 * df0,
    };
    let f_hi = match options.max_frequency_hz {
        Some(f) => positive("maxFrequencyHz", f)?,
        None => 0.45 * fs,
    };
    if f_hi > 0.5 * fs {
        return Err(Error::invalid(
            "maxFrequencyHz",
            format!("must not exceed half the sample rate, {} Hz", 0.5 * fs),
        ));
    }
    if f_lo >= f_hi {
        return Err(Error::invalid(
            "minFrequencyHz",
            format!("must be below maxFrequencyHz ({f_hi} Hz), got {f_lo}"),
        ));
    }
    Ok([f_lo, f_hi])
}

fn bins(psd: &Psd, band: [f64; 2]) -> (usize, usize) {
    let bin = |f: f64| ((f / psd.resolution_hz).round() as usize).min(psd.psd.len() - 1);
    (bin(band[0]).max(1), bin(band[1]))
}

/// The half-power analysis of each peak on `psd`, on the spectrum averaged over a tenth of the
/// peak's width so that the bins' noise does not move the crossings: from a heavy average down
/// to that. `search_hz` is the least search radius around a peak.
fn half_powers(
    psd: &Psd,
    peaks: &[Peak],
    band: [f64; 2],
    search_hz: f64,
    options: &IdentifyOptions,
) -> Vec<Option<HalfPower>> {
    let (lo, hi) = bins(psd, band);
    peaks
        .iter()
        .map(|p| {
            let search = search_hz.max(0.02 * p.frequency_hz);
            let mut h = ((hi - lo) / 100).clamp(3, 2000);
            let mut found = None;
            for _ in 0..10 {
                let Some(hp) = half_power(
                    &smoothed(psd, h),
                    p.frequency_hz,
                    search,
                    lo,
                    hi,
                    options.signal,
                ) else {
                    break;
                };
                found = Some(hp);
                let next = ((hp.width_hz / psd.resolution_hz) / 10.0).floor() as usize;
                if next + 1 >= h && next <= h + 1 {
                    break;
                }
                h = next.min(2000);
            }
            found
        })
        .collect()
}

/// Pairs the peaks with their half-power seeds; peaks that collapse onto the same maximum are
/// one mode.
fn unique(peaks: &[Peak], widths: &[Option<HalfPower>]) -> Vec<(Peak, HalfPower)> {
    let mut out: Vec<(Peak, HalfPower)> = Vec::new();
    for (p, h) in peaks.iter().zip(widths) {
        let Some(h) = h else { continue };
        if !out
            .iter()
            .any(|(_, o)| (o.peak_hz - h.peak_hz).abs() < 0.5 * o.width_hz.min(h.width_hz))
        {
            out.push((*p, *h));
        }
    }
    out
}

/// The Welch path: peaks of the detection PSD, then segments from the record and the peaks:
/// the narrowest half-power width should span 4 to 12 bins (the fit models the window's
/// smearing, so a few bins suffice, and shorter segments average more of them). Longer while
/// it spans fewer (up to n/4), or once shorter when it spans more (down to 64 samples). None
/// when no peak stands out.
pub(super) fn welch_stage(
    signal: &[f64],
    psd0: Psd,
    n0: usize,
    band: [f64; 2],
    options: &IdentifyOptions,
) -> Result<Option<Stage>> {
    let fs = psd0.sample_rate_hz;
    let df0 = psd0.resolution_hz;
    let (lo0, hi0) = bins(&psd0, band);
    if hi0 <= lo0 + 4 {
        return Ok(None);
    }
    // Smoothed and read from the second bin (below the band too): a peak a few bins above
    // the band's start keeps its own flank instead of a smoothing cut at the start.
    let peaks = detect_within(
        &psd0,
        [lo0, hi0],
        [1, hi0],
        options.min_prominence_db,
        options.max_modes,
        3,
    );
    if peaks.is_empty() {
        return Ok(None);
    }
    let n_max = pow2_floor(signal.len() / 4).max(n0).min(1 << 20);
    let mut psd = psd0;
    let (mut seg, mut shrunk) = (n0, false);
    let widths = loop {
        let widths = half_powers(
            &psd,
            &peaks,
            [psd.resolution_hz, band[1]],
            4.0 * df0,
            options,
        );
        let narrowest = widths
            .iter()
            .flatten()
            .map(|h| h.width_hz / psd.resolution_hz)
            .fold(f64::INFINITY, f64::min);
        if !narrowest.is_finite() {
            break widths;
        }
        if narrowest > 12.0 && !shrunk && seg > 64 {
            shrunk = true;
            let factor = pow2_floor((narrowest / 6.0).floor() as usize).max(1);
            seg = (seg / factor).max(64);
        } else if narrowest < 4.0 && !shrunk && seg < n_max {
            let factor = (8.0 / narrowest).ceil() as usize;
            seg = (seg * factor.next_power_of_two()).min(n_max);
        } else {
            break widths;
        }
        psd = welch(signal, &hann_welch(fs, seg))?;
    };
    let found = unique(&peaks, &widths);
    Ok(Some(Stage {
        psd,
        found,
        band,
        local: Vec::new(),
        rising: None,
    }))
}

/// The sweep path: the whole record's periodogram (rectangular window, linear trend removed:
/// the sensor's drift), searched and fitted inside the swept band less a margin at each end
/// where the excitation's spectrum is not smooth (a chirp's spectrum ripples within about √r
/// of its ends, r the sweep rate in Hz/s there; at least 4 bins). The peaks are those of
/// the periodogram smoothed over about √r/4. A response still rising into the band's top —
/// the highest bin of the periodogram smoothed over about √r within √r of the top, standing
/// `minProminenceDb` over its left flank (`peaks::rising_into_end`) — is returned as
/// [`Rising`]: a mode at or past the sweep's end (a 138 Hz mode past Klipper's 133.33 Hz), or
/// one just under it whose fall is not in the band; so is, when there is no such rise, a peak
/// that does not fall 3 dB before the band's top (56.8 Hz, ζ 0.06, swept to 62.1 Hz); the
/// joint fit tells which, as for a spectrum file's cliff. None when the band is empty or
/// nothing stands out in it (`identify` then reports the sweep, no mode and a note).
pub(super) fn sweep_stage(
    signal: &[f64],
    fs: f64,
    sweep: Sweep,
    band: [f64; 2],
    options: &IdentifyOptions,
) -> Result<Option<Stage>> {
    let psd = periodogram(signal, fs)?;
    let df = psd.resolution_hz;
    // √r where the sweep starts and ends (the margins), and in the middle of the band fitted
    // (the smoothing: an exponential sweep's rate grows with the frequency).
    let root_at = |f: f64| sweep.rate_at(f).sqrt();
    let (low_root, top_root) = (root_at(sweep.band_hz[0]), root_at(sweep.band_hz[1]));
    let fit_band = [
        band[0].max(sweep.band_hz[0] + low_root.max(4.0 * df)),
        band[1].min(sweep.band_hz[1] - top_root.max(4.0 * df)),
    ];
    let (lo, hi) = bins(&psd, fit_band);
    if hi <= lo + 16 {
        return Ok(None);
    }
    let root = root_at((fit_band[0] * fit_band[1]).sqrt());
    let h = ((0.125 * root / df).round() as usize).clamp(1, 200);
    let band_bins = bins(&psd, band);
    let context = [band_bins.0.min(lo), band_bins.1.max(hi)];
    let h2 = heavy_bins(h);
    let BandPeaks {
        peaks,
        shoulders,
        heavy,
    } = band_peaks(&psd, [lo, hi], context, h, options);
    let widths = half_powers(&psd, &peaks, fit_band, (2 * h + 1) as f64 * df, options);
    let over_noise = partial_noise_gate(&psd, sweep, band, h);
    let found: Vec<(Peak, HalfPower)> = unique(&peaks, &widths)
        .into_iter()
        .filter(|(_, hp)| stands_at_its_width(&psd, hp, [lo, context[1]], h, options))
        .filter(|(_, hp)| over_noise(hp.peak_hz))
        .collect();
    // A sweep seen in part stands over the noise only inside its band: what lies below it
    // is the noise's (peaks of 0.7 Hz at 28–32 Hz under a sweep seen from 38.6 Hz).
    let local = if sweep.partial {
        Vec::new()
    } else {
        start_peaks(&psd, sweep, band, fit_band, h, options)
    };
    // Rising into the top, or else the highest peak without its 3 dB fall (a mode whose high
    // side the band's end cuts: seeded at its own frequency, a mode if the fit holds it).
    let rising = rising_into_top(&psd, &heavy, lo, h2, top_root, options.min_prominence_db)
        .map(|(prominence_db, top)| Rising {
            prominence_db,
            top,
            level: smoothed(&psd, h2).psd[top],
            seed_hz: 1.05 * fit_band[1],
        })
        .or_else(|| {
            let p = shoulders.last()?;
            let top = ((p.frequency_hz / df).round() as usize).clamp(lo, hi);
            Some(Rising {
                prominence_db: p.prominence_db,
                top,
                level: smoothed(&psd, h2).psd[top],
                seed_hz: p.frequency_hz,
            })
        });
    if found.is_empty() && local.is_empty() && rising.is_none() {
        return Ok(None);
    }
    Ok(Some(Stage {
        psd,
        found,
        band: fit_band,
        local,
        rising,
    }))
}

/// The heavy smoothing's half-width for the peaks' smoothing of ±h bins: 4h, at most 800.
fn heavy_bins(h: usize) -> usize {
    (4 * h).min(800)
}

/// What a sweep's band shows ([`sweep_stage`]), in bins `lo..=hi`: its peaks (at most
/// `max_modes`, the most prominent, in frequency order), the shoulders under its top (peaks
/// without their 3 dB fall there) and the periodogram smoothed over ±[`heavy_bins`] bins (dB,
/// from `lo`).
struct BandPeaks {
    peaks: Vec<Peak>,
    shoulders: Vec<Peak>,
    heavy: Vec<f64>,
}

/// The peaks of a sweep's band `lo..=hi` on the periodogram smoothed over ±h bins, with those
/// its ends cut, read on over `context` (the bins of the whole band asked for).
fn band_peaks(
    psd: &Psd,
    [lo, hi]: [usize; 2],
    context: [usize; 2],
    h: usize,
    options: &IdentifyOptions,
) -> BandPeaks {
    let df = psd.resolution_hz;
    // Peaks standing out on both sides inside the band; then peaks whose high side the band's
    // end cuts, their prominence read on through the sweep's end (past it the periodogram falls
    // to the floor) on the periodogram smoothed 4 times as heavily: one side's 6 dB must not be
    // one dip of the noise (a 2h + 1-bin mean of the periodogram scatters ~2 dB, and its
    // lowest over thousands of bins lies 6–7 dB under its mean: a sweep over a band with no
    // mode, the response at the noise floor, read a 74 Hz mode so). Those are kept when the
    // smoothed periodogram falls ≥ 3 dB between them and the band's top (their high
    // half-power point is fitted), as for a spectrum file's cliff (`spectrum::seeds`); the
    // others are shoulders. A response still rising into the top is `rising`'s.
    let h2 = heavy_bins(h);
    let heavy = smoothed_db(&to_db(&psd.psd[lo..=hi]), 0, hi - lo, h2);
    let mut peaks = detect_within(
        psd,
        [lo, hi],
        [lo, hi],
        options.min_prominence_db,
        options.max_modes,
        h,
    );
    let reach = (2 * h2 + 1) as f64 * df;
    // The peaks of the heavy smoothing in the band, their prominence read over `context`, away
    // from those of `taken`.
    let beyond = |context: [usize; 2], taken: &[Peak]| -> Vec<Peak> {
        detect_within(
            psd,
            [lo, hi],
            context,
            options.min_prominence_db,
            MAX_MODES,
            h2,
        )
        .into_iter()
        .filter(|p| {
            taken
                .iter()
                .all(|q| (q.frequency_hz - p.frequency_hz).abs() > reach)
        })
        .collect()
    };
    // A peak's index in the band's smoothings.
    let at = |p: &Peak| ((p.frequency_hz / df).round() as usize).clamp(lo, hi) - lo;
    let (edge, shoulders): (Vec<Peak>, Vec<Peak>) = beyond([lo, context[1]], &peaks)
        .into_iter()
        .partition(|p| falls_3db(&heavy[at(p)..], heavy[at(p)]));
    // Likewise a peak whose low side the band's start cuts (the margin of √r above a fast
    // sweep's start takes its flank): its prominence read on through the sweep's start on the
    // heavy smoothing, kept when the periodogram smoothed as for the peaks falls ≥ 3 dB on
    // each side of it inside the band (both half-power points fitted). A 1.5 s sweep at
    // 23 Hz/s from 31.3 Hz through 41.3 Hz, ζ 0.08: the band fitted starts at 36.1 Hz, 5.3 dB
    // under the peak (2.7 dB on the heavy smoothing), and no mode was found.
    let light = smoothed_db(&to_db(&psd.psd[lo..=hi]), 0, hi - lo, h);
    let taken: Vec<Peak> = [&peaks[..], &edge, &shoulders].concat();
    let start_cut: Vec<Peak> = beyond([context[0], hi], &taken)
        .into_iter()
        .filter(|p| {
            let k = at(p);
            falls_3db(&light[..=k], light[k]) && falls_3db(&light[k..], light[k])
        })
        .collect();
    peaks.extend(edge);
    peaks.extend(start_cut);
    crate::sort::sort_by(&mut peaks, |a, b| {
        b.prominence_db.total_cmp(&a.prominence_db)
    });
    peaks.truncate(options.max_modes);
    crate::sort::sort_by(&mut peaks, |a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    BandPeaks {
        peaks,
        shoulders,
        heavy,
    }
}

/// Whether any of `values` (dB) lies 3 dB or more under `top`: a peak's half-power point on
/// that side.
fn falls_3db(values: &[f64], top: f64) -> bool {
    values.iter().any(|&v| v <= top - 3.0)
}

/// Whether a peak still stands out (by half `minProminenceDb`, on both sides within `context`)
/// on the periodogram smoothed over an eighth of its half-power width, where the width is more
/// than the detection's smoothing: a mode that wide rises over several hertz, while a wiggle
/// of the periodogram a hertz wide, read with a wide half-power band (a sweep over a band
/// where the response is flat: 74 Hz, "ζ 0.041", standing 6.2 dB on the √r/8 smoothing), goes
/// under the heavier smoothing.
fn stands_at_its_width(
    psd: &Psd,
    hp: &HalfPower,
    context: [usize; 2],
    h: usize,
    options: &IdentifyOptions,
) -> bool {
    let df = psd.resolution_hz;
    let hw = ((hp.width_hz / 8.0 / df).round() as usize).min(2000);
    if hw <= h {
        return true;
    }
    let k = (hp.peak_hz / df).round() as usize;
    let band = [
        k.saturating_sub(hw).max(context[0]),
        (k + hw).min(context[1]),
    ];
    !detect_within(psd, band, context, 0.5 * options.min_prominence_db, 1, hw).is_empty()
}

/// For a sweep seen in part ([`Sweep::partial`]), whether a peak at a frequency stands 10 dB
/// over the sensor's noise: its periodogram smoothed over ±`h` bins against the noise's mean
/// level, read as the median of the periodogram over the search band `band` divided by ln 2
/// (a periodogram bin of white noise is exponential, its median ln 2 of its mean; the sweep
/// holds a small part of the band, or the gate is only stricter). Inside such a sweep's band
/// the noise competes with the response: peaks of the noise's periodogram stood 7.5 dB over
/// their surroundings there and were fitted as modes of ζ 0.003–0.004 (a 6 s logarithmic
/// sweep at 1.6 kHz through a low-pass mode, benches/reference/sweep_chirps.py). A sweep seen
/// whole passes every peak.
fn partial_noise_gate(psd: &Psd, sweep: Sweep, band: [f64; 2], h: usize) -> impl Fn(f64) -> bool {
    let floor = if sweep.partial {
        let (lo, hi) = bins(psd, band);
        let mut values: Vec<f64> = psd.psd[lo..=hi.min(psd.psd.len() - 1)].to_vec();
        values.sort_by(f64::total_cmp);
        values
            .get(values.len() / 2)
            .map_or(0.0, |m| m / std::f64::consts::LN_2)
    } else {
        0.0
    };
    let smooth = sweep.partial.then(|| smoothed(psd, h));
    let df = psd.resolution_hz;
    move |f: f64| {
        smooth.as_ref().is_none_or(|s| {
            let k = ((f / df).round() as usize).min(s.psd.len() - 1);
            s.psd[k] >= 10.0 * floor
        })
    }
}

/// A rise into the top of `sm`, a sweep's periodogram on bins `lo..` smoothed over ±`h` bins
/// in dB ([`smoothed_db`]): its prominence, dB, and the top's bin, the top within the last
/// `width_hz` (√r, as the band's margin: the chirp's spectrum still ripples by a dB or two
/// there, and the smoothed bins scatter as much: a 72 Hz mode past a 70 Hz end rose 11 dB over
/// the last 10 Hz fitted, its top 0.7 Hz under the band's end) and at least 2h + 1 bins.
fn rising_into_top(
    psd: &Psd,
    sm: &[f64],
    lo: usize,
    h: usize,
    width_hz: f64,
    min_db: f64,
) -> Option<(f64, usize)> {
    let last = ((width_hz / psd.resolution_hz).round() as usize).max(2 * h + 1);
    rising_into_end(sm, last, min_db).map(|(prominence_db, at)| (prominence_db, lo + at))
}

/// A sweep's whole-record periodogram (rectangular window, linear detrend): what its stage
/// reads.
fn periodogram(signal: &[f64], fs: f64) -> Result<Psd> {
    welch(
        signal,
        &WelchOptions {
            sample_rate_hz: fs,
            segment_length: Some(signal.len()),
            overlap: Some(0),
            window: WindowKind::Rectangular,
            kaiser_beta: 6.0,
            symmetric_window: false,
            detrend: Detrend::Linear,
            scaling: Scaling::Density,
        },
    )
}

/// The fundamental of Klipper's slow sweep in a sweep's periodogram, Hz, if it shows one
/// (klippy/extras/resonance_tester.py, `SweepingVibrationsTestGenerator`: a square wave of
/// ±`sweeping_accel` with period `sweeping_period`, 1.2 s by default, added to the test's
/// moves so that the toolhead drifts over the test point). Its lines stand at the odd
/// multiples of 1/P, steady through the record: below a sweep's band they look like narrow
/// modes rung by its start (a 16 s sweep from 44.8 Hz at noise 424 mm/s²: the 17th, 14.15 Hz,
/// 11 dB over the floor, was read as a 14.4 Hz, ζ 0.008 mode). Found as the highest bin in
/// 0.3–2.5 Hz whose 3rd and 5th multiples are peaks too (≥ 6 dB over the median of ±10 bins
/// around them), refined through the 9th, 17th and 33rd while those stand out as well.
fn slow_sweep_comb(psd: &Psd) -> Option<f64> {
    let df = psd.resolution_hz;
    let p = &psd.psd;
    let n = p.len();
    let bin = |f: f64| (f / df).round() as usize;
    let (a, b) = (bin(0.3).max(1), bin(2.5).min(n.saturating_sub(1)));
    if b <= a + 2 {
        return None;
    }
    let k1 = (a..=b).max_by(|&x, &y| p[x].total_cmp(&p[y]))?;
    // The peak within ±2 bins of `f`, if it stands ≥ 6 dB over the median of ±10 bins.
    let line = |f: f64| -> Option<f64> {
        let c = bin(f);
        if c < 12 || c + 12 >= n {
            return None;
        }
        let k = (c - 2..=c + 2).max_by(|&x, &y| p[x].total_cmp(&p[y]))?;
        let mut around: Vec<f64> = (k - 10..=k + 10)
            .filter(|&j| j + 1 < k || j > k + 1)
            .map(|j| p[j])
            .collect();
        around.sort_by(f64::total_cmp);
        (p[k] >= 10f64.powf(0.6) * around[around.len() / 2]).then_some(k as f64 * df)
    };
    let mut f1 = k1 as f64 * df;
    for m in [3.0, 5.0] {
        f1 = line(m * f1)? / m;
    }
    for m in [9.0, 17.0, 33.0] {
        match line(m * f1) {
            Some(f) => f1 = f / m,
            None => break,
        }
    }
    Some(f1)
}

/// The peaks of a sweep's periodogram between the search band's start (or 4√r under the
/// sweep's start, at most half of it, whichever is higher) and the smooth part of the sweep
/// (`fit_band`), each with the band it is fitted on alone: ± 3 half-power widths
/// (at least ± 6 bins).
///
/// Why alone: near its start a sweep's spectrum is not the smooth ∝ f² of the band (the
/// chirp's Fresnel ripple, about √r wide, and Klipper's coarse first steps: f rises by
/// r/(2f) per half period), so one excitation law cannot hold from there to the band's
/// modes. Over a few half-power widths of a narrow mode it is smooth, and a local power law
/// stands for it (the joint model of identify/model.rs on that band, one mode). Only peaks
/// narrower than √r/4 qualify (so the ± 3 widths fitted stay within the scale the excitation
/// varies on), and the fit must find them resolved (identify/mod.rs). The prominence is read
/// on the periodogram from its second bin (below the search band too: the spectrum rising
/// towards a mode near the band's start is its flank, not its base). A peak within 2 bins of
/// a line of the slow sweep's comb ([`slow_sweep_comb`]) is none.
fn start_peaks(
    psd: &Psd,
    sweep: Sweep,
    band: [f64; 2],
    fit_band: [f64; 2],
    h: usize,
    options: &IdentifyOptions,
) -> Vec<Local> {
    let df = psd.resolution_hz;
    let (lo, _) = bins(psd, band);
    let (fit_lo, fit_hi) = bins(psd, fit_band);
    if fit_lo <= lo + 2 {
        return Vec::new();
    }
    let peaks = detect_within(
        psd,
        [lo, fit_lo - 1],
        [1, fit_hi],
        options.min_prominence_db,
        MAX_MODES,
        h,
    );
    let widest = 0.25 * sweep.rate_at(fit_band[0]).sqrt();
    let widths = half_powers(
        psd,
        &peaks,
        [df, fit_band[1]],
        (2 * h + 1) as f64 * df,
        options,
    );
    // Below the sweep's start nothing is excited but within a few √r of it (the chirp's
    // spectrum falls off over about √r under its start): a 2.8 Hz "mode" under a sweep from
    // 35 Hz at 8.8 Hz/s was the record's drift and onset (benches/reference/sweep_chirps.py,
    // seed 3). The floor allows 4√r, and never less than half the start (the start read from
    // the data can lie above the drive's: 33.3 Hz read for a pulse sweep from 23 Hz).
    let start = sweep.band_hz[0];
    let floor = start - (4.0 * sweep.rate_at(start).sqrt()).max(0.5 * start);
    let comb = slow_sweep_comb(psd);
    let on_comb = |f: f64| {
        comb.is_some_and(|f1| {
            let m = (f / f1 - 1.0) / 2.0;
            let odd = 2.0 * m.round().max(0.0) + 1.0;
            (f - odd * f1).abs() <= 2.0 * df
        })
    };
    unique(&peaks, &widths)
        .into_iter()
        .filter(|(_, hp)| hp.width_hz <= widest && hp.peak_hz < fit_band[0])
        .filter(|(_, hp)| hp.peak_hz >= floor)
        .filter(|(_, hp)| !on_comb(hp.peak_hz))
        .map(|(peak, half)| {
            let reach = (3.0 * half.width_hz).max(6.0 * df);
            Local {
                peak,
                half,
                band: [(half.peak_hz - reach).max(df), half.peak_hz + reach],
            }
        })
        .collect()
}

/// Stage 4: when the recording rings down after a hit, the free-decay fit of every slot's
/// mode joins its estimates (when it agrees with the first one within 20 %).
pub(super) fn free_decay_stage(signal: &[f64], fs: f64, slots: &mut [Slot]) -> Option<FreeDecay> {
    let lowest = slots
        .iter()
        .map(|s| s.estimates[0].frequency_hz)
        .fold(f64::INFINITY, f64::min);
    let (start, end, level_db) = find_decay(signal, fs, lowest)?;
    let initial: Vec<(f64, f64)> = slots
        .iter()
        .map(|s| {
            let best = s.estimates.last().copied().unwrap_or(s.estimates[0]);
            (best.frequency_hz, best.damping)
        })
        .collect();
    let f_max = initial.iter().map(|p| p.0).fold(0.0, f64::max);
    let mut stride = 1;
    while (end - start) / stride > 40_000 && fs / (stride as f64 * 2.0) > 3.0 * f_max {
        stride *= 2;
    }
    let y: Vec<f64> = signal[start..end].iter().step_by(stride).copied().collect();
    let end = start + y.len() * stride;
    let decays = decay_fit(&y, fs / stride as f64, &initial)?;
    for (slot, d) in slots.iter_mut().zip(decays) {
        let f0 = slot.estimates[0].frequency_hz;
        let agrees = (d.frequency_hz - f0).abs() < 0.2 * f0
            && d.damping > 0.0
            && d.damping_uncertainty.is_finite();
        if agrees {
            slot.estimates.push(d);
        }
    }
    Some(FreeDecay {
        start_s: start as f64 / fs,
        end_s: end as f64 / fs,
        level_db,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 16.5 s at 3.2 kHz of white noise (σ ≈ 424 mm/s², a fixed linear congruential
    /// sequence) plus, when `square`, Klipper's slow sweep: ±400 mm/s², period 1.2 s, its
    /// switches at P√2/8, then P(√2/8 + 1/4) later, then every P/2 (resonance_tester.py).
    fn record(square: bool, tone_hz: Option<f64>) -> (Vec<f64>, f64) {
        let (fs, n) = (3200.0, 52_800);
        let p = 1.2;
        let first = p * 2f64.sqrt() / 8.0;
        let mut state = 777u64;
        let x = (0..n)
            .map(|i| {
                let t = i as f64 / fs;
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let u = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                let second = first + p * (2f64.sqrt() / 8.0 + 0.25);
                let switches = if t < first {
                    0
                } else if t < second {
                    1
                } else {
                    2 + ((t - second) / (p / 2.0)).floor() as i64
                };
                let sq = if switches % 2 == 0 { 400.0 } else { -400.0 };
                let tone =
                    tone_hz.map_or(0.0, |f| 60.0 * (2.0 * std::f64::consts::PI * f * t).sin());
                1470.0 * u + if square { sq } else { 0.0 } + tone
            })
            .collect();
        (x, fs)
    }

    /// The slow sweep's comb is found at 1/1.2 s (to a fifth of a bin of the whole record:
    /// its 33rd line within 2 bins); noise alone, or with one steady tone, has none.
    #[wasm_bindgen_test::wasm_bindgen_test(unsupported = test)]
    fn finds_the_slow_sweeps_comb_and_nothing_else() {
        let (x, fs) = record(true, None);
        let psd = periodogram(&x, fs).unwrap();
        let f1 = slow_sweep_comb(&psd).expect("the comb");
        assert!(
            (f1 - 1.0 / 1.2).abs() < 0.2 * psd.resolution_hz,
            "{f1} against {}",
            1.0 / 1.2
        );
        let (x, fs) = record(false, None);
        assert_eq!(slow_sweep_comb(&periodogram(&x, fs).unwrap()), None);
        let (x, fs) = record(false, Some(1.1));
        assert_eq!(slow_sweep_comb(&periodogram(&x, fs).unwrap()), None);
    }

    /// A 5 s record's periodogram at 1 kHz (one rectangular segment) of the given bins.
    fn periodogram_of(frequency_hz: Vec<f64>, psd: Vec<f64>, df: f64) -> Psd {
        Psd {
            frequency_hz,
            psd,
            segment_length: 5000,
            overlap: 0,
            segments: 1,
            resolution_hz: df,
            enbw_bins: 1.0,
            sample_rate_hz: 1000.0,
        }
    }

    /// A periodogram of 0.2 Hz bins: a floor of 1, the sweep's band (from `start` Hz to 86 Hz)
    /// at 100·(f/50)², and narrow resonances (frequency, ζ) 30 times their surroundings.
    fn sweep_psd(start: f64, peaks: &[(f64, f64)]) -> Psd {
        let df = 0.2;
        let frequency_hz: Vec<f64> = (0..2500).map(|k| k as f64 * df).collect();
        let psd = frequency_hz
            .iter()
            .map(|&f| {
                let base = 1.0
                    + if f >= start && f <= 86.0 {
                        100.0 * (f / 50.0).powi(2)
                    } else {
                        0.0
                    };
                let lift: f64 = peaks
                    .iter()
                    .map(|&(fp, z)| {
                        let r = f / fp;
                        30.0 * (2.0 * z).powi(2) / ((1.0 - r * r).powi(2) + (2.0 * z * r).powi(2))
                    })
                    .sum();
                base * (1.0 + lift)
            })
            .collect();
        periodogram_of(frequency_hz, psd, df)
    }

    /// A peak far under a sweep's start is not one of its start's peaks (nothing is excited
    /// there: a 2.8 Hz "mode" under a sweep from 35 Hz at 8.8 Hz/s), one just under it is;
    /// under a sweep from 5 Hz the same low peak is within reach.
    #[wasm_bindgen_test::wasm_bindgen_test(unsupported = test)]
    fn start_peaks_stay_within_reach_of_the_sweeps_start() {
        use super::super::sweep::SweepLaw;
        let options = IdentifyOptions::default();
        let peaks_of = |start: f64| {
            let psd = sweep_psd(start, &[(3.0, 0.05), (36.0, 0.008)]);
            let sweep = Sweep {
                band_hz: [start, 86.0],
                rate_hz_per_s: 8.8,
                law: SweepLaw::Linear,
                partial: false,
            };
            let fit_band = [start + 8.8f64.sqrt(), 86.0 - 8.8f64.sqrt()];
            start_peaks(&psd, sweep, [0.6, 400.0], fit_band, 1, &options)
                .iter()
                .map(|l| l.half.peak_hz)
                .collect::<Vec<f64>>()
        };
        let from_35 = peaks_of(35.0);
        assert!(
            from_35.iter().any(|f| (f - 36.0).abs() < 0.5),
            "{from_35:?}"
        );
        assert!(from_35.iter().all(|f| *f > 10.0), "{from_35:?}");
        let from_5 = peaks_of(5.0);
        assert!(from_5.iter().any(|f| (f - 3.0).abs() < 0.5), "{from_5:?}");
    }

    /// Inside a sweep seen in part, a peak must stand 10 dB over the noise's mean level (the
    /// median of the search band's periodogram over ln 2): a lump of the noise 7.5 dB over it
    /// does not, a mode 20 dB over it does; a sweep seen whole passes both.
    #[wasm_bindgen_test::wasm_bindgen_test(unsupported = test)]
    fn a_partial_sweeps_peaks_stand_over_the_noise() {
        let df = 0.2;
        let frequency_hz: Vec<f64> = (0..2500).map(|k| k as f64 * df).collect();
        // white noise's periodogram: exponential bins of mean 1 (a fixed sequence), with a
        // lump of 10^0.75 at 30 Hz and a mode of 100 at 64.5 Hz, each 5 bins wide
        let mut state = 99u64;
        let psd: Vec<f64> = frequency_hz
            .iter()
            .map(|&f| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let u = ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
                let noise = -u.ln();
                if (f - 30.0).abs() <= 0.5 {
                    10f64.powf(0.75)
                } else if (f - 64.5).abs() <= 0.5 {
                    100.0
                } else {
                    noise
                }
            })
            .collect();
        let psd = periodogram_of(frequency_hz, psd, df);
        let mut sweep = Sweep {
            band_hz: [25.0, 86.0],
            rate_hz_per_s: 24.0,
            law: super::super::sweep::SweepLaw::Linear,
            partial: true,
        };
        let gate = partial_noise_gate(&psd, sweep, [3.0, 450.0], 2);
        assert!(!gate(30.0));
        assert!(gate(64.5));
        sweep.partial = false;
        let gate = partial_noise_gate(&psd, sweep, [3.0, 450.0], 2);
        assert!(gate(30.0) && gate(64.5));
    }
}
