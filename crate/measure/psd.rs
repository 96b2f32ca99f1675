//! Power spectral density by Welch's method, and the plain FFT amplitude spectrum.
//!
//! Welch (1967): split the signal into segments of `segment_length` samples overlapping by
//! `overlap`, detrend and window each, and average the periodograms |X_k|². With `scaling =
//! density` the one-sided PSD is P(f_k) = c · mean |X_k|², c = 2/(f_s Σw²) (1/(f_s Σw²) at DC
//! and at Nyquist), in signal-units²/Hz, so that Σ P Δf is the signal's variance (Parseval).
//! These are exactly the definitions of `scipy.signal.welch` (defaults: periodic Hann window,
//! 256 samples, half overlap, constant detrend, mean average) and of Klipper's
//! `ShaperCalibrate._psd` (symmetric Kaiser β = 6, 0.5 s rounded up to a power of two, half
//! overlap) — see [`WelchOptions::klipper`].

use super::fft::{Complex, Fft};
use crate::error::{count, positive, Error, Result};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Longest signal accepted by [`welch`] (2²⁶ samples, 512 MB of f64 would be absurd in a page).
pub const MAX_SIGNAL_LENGTH: usize = 1 << 26;
/// Longest Welch segment (and FFT of [`fft_spectrum`]).
pub const MAX_SEGMENT_LENGTH: usize = 1 << 22;

/// The tapering window applied to each segment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum WindowKind {
    /// w = 1 (`boxcar`).
    Rectangular,
    /// w = 0.5 − 0.5 cos(2πn/M) (default).
    #[default]
    Hann,
    /// w = 0.54 − 0.46 cos(2πn/M).
    Hamming,
    /// w = 0.42 − 0.5 cos(2πn/M) + 0.08 cos(4πn/M).
    Blackman,
    /// w = I₀(β √(1 − (2n/M − 1)²)) / I₀(β), β = `kaiserBeta`.
    Kaiser,
}

/// What is subtracted from each segment before windowing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Detrend {
    /// Nothing.
    None,
    /// The segment's mean (default, as scipy and Klipper).
    #[default]
    Constant,
    /// The segment's least-squares line.
    Linear,
}

/// Density (units²/Hz) or power spectrum (units², a sinusoid's mean square at its bin).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Scaling {
    /// Power spectral density, units²/Hz (default).
    #[default]
    Density,
    /// Power spectrum, units²: c = 2/(Σw)².
    Spectrum,
}

/// Options of [`welch`] (JS: `{ sampleRateHz, segmentLength, overlap, window, kaiserBeta,
/// symmetricWindow, detrend, scaling }`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", default)]
pub struct WelchOptions {
    /// Sampling rate f_s in Hz (required, > 0).
    pub sample_rate_hz: f64,
    /// Samples per segment (default 256, as scipy; clamped to the signal length).
    pub segment_length: Option<usize>,
    /// Samples shared by consecutive segments (default `segment_length / 2`).
    pub overlap: Option<usize>,
    /// Window (default Hann).
    pub window: WindowKind,
    /// β of the Kaiser window (default 6, Klipper's).
    pub kaiser_beta: f64,
    /// Symmetric window (M = N − 1, numpy's `np.hanning`/`np.kaiser`) instead of the periodic
    /// one (M = N, scipy's `get_window` default). Default false.
    pub symmetric_window: bool,
    /// Detrending of each segment (default constant).
    pub detrend: Detrend,
    /// Density or spectrum (default density).
    pub scaling: Scaling,
}

impl Default for WelchOptions {
    fn default() -> Self {
        WelchOptions {
            sample_rate_hz: f64::NAN,
            segment_length: None,
            overlap: None,
            window: WindowKind::Hann,
            kaiser_beta: 6.0,
            symmetric_window: false,
            detrend: Detrend::Constant,
            scaling: Scaling::Density,
        }
    }
}

impl WelchOptions {
    /// scipy's defaults at sampling rate `sample_rate_hz`.
    pub fn new(sample_rate_hz: f64) -> Self {
        WelchOptions {
            sample_rate_hz,
            ..WelchOptions::default()
        }
    }

    /// Klipper's `calc_freq_response`/`_psd` settings: segments of 0.5 s rounded up to a power
    /// of two (`1 << int(fs·0.5 − 1).bit_length()`), half overlap, symmetric Kaiser β = 6,
    /// constant detrend, density scaling.
    pub fn klipper(sample_rate_hz: f64) -> Self {
        let v = (sample_rate_hz * 0.5 - 1.0) as i64;
        let bits = if v > 0 { 64 - v.leading_zeros() } else { 0 };
        let n = 1usize << bits.min(22);
        WelchOptions {
            sample_rate_hz,
            segment_length: Some(n),
            overlap: Some(n / 2),
            window: WindowKind::Kaiser,
            kaiser_beta: 6.0,
            symmetric_window: true,
            detrend: Detrend::Constant,
            scaling: Scaling::Density,
        }
    }
}

/// A one-sided spectrum estimate.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Psd {
    /// Bin frequencies k·f_s/N, k = 0 … ⌊N/2⌋, Hz.
    pub frequency_hz: Vec<f64>,
    /// The estimate at each bin (units²/Hz for density, units² for spectrum).
    pub psd: Vec<f64>,
    /// Segment length N actually used.
    pub segment_length: usize,
    /// Overlap actually used.
    pub overlap: usize,
    /// Number of averaged segments.
    pub segments: usize,
    /// Bin spacing f_s/N, Hz.
    pub resolution_hz: f64,
    /// Equivalent noise bandwidth of the window, in bins: N Σw² / (Σw)² (1.5 for Hann).
    pub enbw_bins: f64,
    /// Sampling rate, Hz.
    pub sample_rate_hz: f64,
}

/// Modified Bessel function I₀ by its power series (β ≤ 100 converges in < 200 terms).
fn bessel_i0(x: f64) -> f64 {
    let q = 0.25 * x * x;
    let (mut term, mut sum) = (1.0, 1.0);
    for k in 1..500 {
        term *= q / ((k * k) as f64);
        sum += term;
        if term < 1e-17 * sum {
            break;
        }
    }
    sum
}

/// The window of length `n`.
pub fn window(kind: WindowKind, n: usize, symmetric: bool, kaiser_beta: f64) -> Vec<f64> {
    if n <= 1 {
        return vec![1.0; n];
    }
    let m = if symmetric { n - 1 } else { n } as f64;
    let i0b = bessel_i0(kaiser_beta);
    (0..n)
        .map(|i| {
            let x = i as f64 / m;
            match kind {
                WindowKind::Rectangular => 1.0,
                WindowKind::Hann => 0.5 - 0.5 * (2.0 * PI * x).cos(),
                WindowKind::Hamming => 0.54 - 0.46 * (2.0 * PI * x).cos(),
                WindowKind::Blackman => {
                    0.42 - 0.5 * (2.0 * PI * x).cos() + 0.08 * (4.0 * PI * x).cos()
                }
                WindowKind::Kaiser => {
                    let r = 2.0 * x - 1.0;
                    bessel_i0(kaiser_beta * (1.0 - r * r).max(0.0).sqrt()) / i0b
                }
            }
        })
        .collect()
}

/// Checks a signal: at least `min` samples, at most [`MAX_SIGNAL_LENGTH`], all finite.
pub(crate) fn check_signal(signal: &[f64], min: usize) -> Result<()> {
    count("signal", signal.len(), min, MAX_SIGNAL_LENGTH)?;
    if let Some(i) = signal.iter().position(|v| !v.is_finite()) {
        return Err(Error::invalid(
            format!("signal[{i}]"),
            format!("must be a finite number, got {}", signal[i]),
        ));
    }
    Ok(())
}

/// Subtracts the trend from `seg` in place.
fn detrend(seg: &mut [f64], how: Detrend) {
    let n = seg.len() as f64;
    match how {
        Detrend::None => {}
        Detrend::Constant => {
            let mean = seg.iter().sum::<f64>() / n;
            seg.iter_mut().for_each(|v| *v -= mean);
        }
        Detrend::Linear => {
            // Least squares v ≈ a + b·(i − c), c = (n−1)/2: b = Σ(i−c)v / Σ(i−c)².
            let c = 0.5 * (n - 1.0);
            let mean = seg.iter().sum::<f64>() / n;
            let sxx = n * (n * n - 1.0) / 12.0;
            let sxy: f64 = seg
                .iter()
                .enumerate()
                .map(|(i, v)| (i as f64 - c) * v)
                .sum();
            let b = if sxx > 0.0 { sxy / sxx } else { 0.0 };
            seg.iter_mut()
                .enumerate()
                .for_each(|(i, v)| *v -= mean + b * (i as f64 - c));
        }
    }
}

/// Welch's power spectral density estimate of `signal` (see the module docs).
///
/// Errors: fewer than 2 samples, a non-finite sample (`signal[i]`), a non-positive or
/// non-finite `sampleRateHz`, `segmentLength` < 2 or > [`MAX_SEGMENT_LENGTH`], `overlap` ≥
/// `segmentLength`, a Kaiser β outside [0, 100].
pub fn welch(signal: &[f64], options: &WelchOptions) -> Result<Psd> {
    check_signal(signal, 2)?;
    let fs = positive("sampleRateHz", options.sample_rate_hz)?;
    let n = match options.segment_length {
        Some(n) => count("segmentLength", n, 2, MAX_SEGMENT_LENGTH)?.min(signal.len()),
        None => 256.min(signal.len()),
    };
    let overlap = options.overlap.unwrap_or(n / 2);
    if overlap >= n {
        return Err(Error::invalid(
            "overlap",
            format!("must be less than the segment length {n}, got {overlap}"),
        ));
    }
    if !(0.0..=100.0).contains(&options.kaiser_beta) {
        return Err(Error::invalid(
            "kaiserBeta",
            format!("must lie in [0, 100], got {}", options.kaiser_beta),
        ));
    }
    let w = window(
        options.window,
        n,
        options.symmetric_window,
        options.kaiser_beta,
    );
    let step = n - overlap;
    let segments = (signal.len() - overlap) / step;
    let bins = n / 2 + 1;
    let mut acc = vec![0.0; bins];
    let mut plan = Fft::new(n);
    let mut buffer = Vec::with_capacity(n);
    let (mut sx, mut sy) = (vec![0.0; n], vec![0.0; n]);
    let (mut fx, mut fy) = (
        vec![Complex::default(); bins],
        vec![Complex::default(); bins],
    );
    let prepare = |start: usize, out: &mut [f64]| {
        out.copy_from_slice(&signal[start..start + n]);
        detrend(out, options.detrend);
        out.iter_mut().zip(&w).for_each(|(v, w)| *v *= w);
    };
    let mut k = 0;
    while k < segments {
        prepare(k * step, &mut sx);
        if k + 1 < segments {
            prepare((k + 1) * step, &mut sy);
        } else {
            sy.iter_mut().for_each(|v| *v = 0.0);
        }
        plan.forward_real_pair(&sx, &sy, &mut buffer, &mut fx, &mut fy);
        for (a, z) in acc.iter_mut().zip(&fx) {
            *a += z.norm_sqr();
        }
        if k + 1 < segments {
            for (a, z) in acc.iter_mut().zip(&fy) {
                *a += z.norm_sqr();
            }
        }
        k += 2;
    }
    let sum_w: f64 = w.iter().sum();
    let sum_w2: f64 = w.iter().map(|v| v * v).sum();
    let scale = match options.scaling {
        Scaling::Density => 1.0 / (fs * sum_w2),
        Scaling::Spectrum => 1.0 / (sum_w * sum_w),
    } / segments as f64;
    let nyquist = if n.is_multiple_of(2) {
        Some(n / 2)
    } else {
        None
    };
    let psd = acc
        .iter()
        .enumerate()
        .map(|(k, a)| {
            let one_sided = if k == 0 || Some(k) == nyquist {
                1.0
            } else {
                2.0
            };
            a * scale * one_sided
        })
        .collect();
    Ok(Psd {
        frequency_hz: (0..bins).map(|k| k as f64 * fs / n as f64).collect(),
        psd,
        segment_length: n,
        overlap,
        segments,
        resolution_hz: fs / n as f64,
        enbw_bins: n as f64 * sum_w2 / (sum_w * sum_w),
        sample_rate_hz: fs,
    })
}

/// Options of [`fft_spectrum`] (JS: `{ sampleRateHz, window, kaiserBeta, detrend }`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", default)]
pub struct FftOptions {
    /// Sampling rate in Hz (required, > 0).
    pub sample_rate_hz: f64,
    /// Window (default rectangular: the plain FFT).
    pub window: WindowKind,
    /// β of the Kaiser window (default 6).
    pub kaiser_beta: f64,
    /// Detrending of the whole record before the transform (default constant).
    pub detrend: Detrend,
}

impl Default for FftOptions {
    fn default() -> Self {
        FftOptions {
            sample_rate_hz: f64::NAN,
            window: WindowKind::Rectangular,
            kaiser_beta: 6.0,
            detrend: Detrend::Constant,
        }
    }
}

/// The amplitude spectrum of the whole record.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct AmplitudeSpectrum {
    /// Bin frequencies k·f_s/N, Hz.
    pub frequency_hz: Vec<f64>,
    /// |X_k| · 2/Σw (|X_0|/Σw at DC and Nyquist): a sinusoid of amplitude A on a bin reads A.
    pub magnitude: Vec<f64>,
    /// Bin spacing f_s/N, Hz.
    pub resolution_hz: f64,
}

/// The plain FFT magnitude of the whole record, of any length (radix-2 or Bluestein), as an
/// amplitude spectrum (see [`AmplitudeSpectrum::magnitude`]).
///
/// Errors: as [`welch`]; more than [`MAX_SEGMENT_LENGTH`] samples is `tooLarge`.
pub fn fft_spectrum(signal: &[f64], options: &FftOptions) -> Result<AmplitudeSpectrum> {
    check_signal(signal, 2)?;
    count("signal", signal.len(), 2, MAX_SEGMENT_LENGTH)?;
    let fs = positive("sampleRateHz", options.sample_rate_hz)?;
    if !(0.0..=100.0).contains(&options.kaiser_beta) {
        return Err(Error::invalid(
            "kaiserBeta",
            format!("must lie in [0, 100], got {}", options.kaiser_beta),
        ));
    }
    let n = signal.len();
    let w = window(options.window, n, false, options.kaiser_beta);
    let mut x = signal.to_vec();
    detrend(&mut x, options.detrend);
    let mut data: Vec<Complex> = x
        .iter()
        .zip(&w)
        .map(|(v, w)| Complex::new(v * w, 0.0))
        .collect();
    Fft::new(n).forward(&mut data);
    let sum_w: f64 = w.iter().sum();
    let bins = n / 2 + 1;
    let magnitude = (0..bins)
        .map(|k| {
            let f = if k == 0 || (n.is_multiple_of(2) && k == n / 2) {
                1.0
            } else {
                2.0
            };
            data[k].norm() * f / sum_w
        })
        .collect();
    Ok(AmplitudeSpectrum {
        frequency_hz: (0..bins).map(|k| k as f64 * fs / n as f64).collect(),
        magnitude,
        resolution_hz: fs / n as f64,
    })
}
