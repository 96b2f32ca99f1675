//! The stages of [`identify_spectrum`](super::identify_spectrum): the file's bins checked and
//! put on a grid from 0 Hz, the band, and the peaks' half-power seeds.

use super::half_power::{half_power, HalfPower};
use super::model::WindowSpec;
use super::peaks::detect;
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
pub(super) fn seeds(
    grid: &Grid,
    lo: usize,
    hi: usize,
    options: &IdentifyOptions,
) -> (Vec<HalfPower>, Vec<Slot>) {
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
    let peaks = detect(
        &unnormalized,
        lo,
        hi,
        options.min_prominence_db,
        options.max_modes,
        1,
    );
    let mut slots = Vec::new();
    let mut halves: Vec<HalfPower> = Vec::new();
    for pk in &peaks {
        let Some(h) = half_power(
            &unnormalized,
            pk.frequency_hz,
            2.0 * df,
            lo,
            hi,
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
    (halves, slots)
}
