//! Mode identification: from a recording to frequencies and damping ratios, each with an
//! uncertainty (Singhose 2009 §3.2: "a frequency-domain identification scheme to estimate the
//! vibration frequencies … The system identification can also be accomplished in the time
//! domain").
//!
//! 1. **Peaks.** A Welch PSD (Hann, half overlap, segments of 2^⌊log₂(n/8)⌋ samples by default)
//!    is smoothed in dB over 7 bins; its local maxima with a topographic prominence of at least
//!    `minProminenceDb` inside the band are the candidate modes, the most prominent first.
//! 2. **Half-power bandwidth** (frequency domain). On a PSD whose segments are long enough
//!    that the narrowest peak spans ≥ 12 bins (when the record allows), the peak f_p
//!    (parabolic interpolation in log) and the two frequencies f₁ < f_p < f₂ where the PSD —
//!    averaged over a tenth of the peak's width so the bins' noise does not move the crossings —
//!    falls to half the peak give ζ ≈ (f₂ − f₁)/(2f_p). The natural frequency is f_p·√(1−2ζ²) for a
//!    position signal, f_p for velocity, f_p/√(1−2ζ²) for acceleration (where each |H|² peaks).
//! 3. **Spectrum fit** (frequency domain, refines 2). The PSD around the peaks is fitted, in
//!    log, by the power spectrum of a modal sum driven by white noise,
//!    S(f) = |Σᵢ gᵢ (ω/ωᵢ)^p ωᵢ² / (ωᵢ² − ω² + 2iζᵢωᵢω)|² + B, p = 2, 1, 0 for acceleration,
//!    velocity, position (real, signed modal gains gᵢ: classically damped modes), convolved
//!    with the window's spectral kernel |W(ν)|² where peaks are narrow, so leakage does not
//!    widen them. Levenberg–Marquardt; every sign pattern of the gains is tried.
//! 4. **Free decay** (time domain). If the recording rings down after a hit (a block of two
//!    periods at least 20 dB above the median block, less than half of it two blocks earlier;
//!    the decay ends where the blocks fall below twice the median), the ring-down is
//!    fitted by least squares with y(τ) = Σᵢ e^{−σᵢτ}(aᵢ cos ω_dᵢτ + bᵢ sin ω_dᵢτ) + c₀ + c₁τ
//!    (variable projection: the linear aᵢ, bᵢ, c₀, c₁ are solved for every σ, ω_d; the drift
//!    terms absorb a slow offset). This is the least-squares form of the logarithmic decrement
//!    (δ = σ·T_d), using every sample instead of two peaks. Then ωᵢ = √(σᵢ² + ω_dᵢ²),
//!    ζᵢ = σᵢ/ωᵢ.
//!
//! Uncertainties are one standard deviation: for the fits, s²(JᵀJ)⁻¹ with s² the residual
//! variance (the spectrum fit's inflated by √ENBW because neighbouring bins are correlated);
//! for the half-power estimate, the Welch variance of the bins propagated through the crossings,
//! plus half the window's noise bandwidth and the formula's bias (≈ 2.5ζ²) added in quadrature.
//! Each mode reports the spectrum fit (the half-power estimate is only its starting point and
//! the fallback when it fails), or the free-decay fit when its relative damping uncertainty is
//! smaller.

use super::fft::Complex;
use super::fit::levenberg_marquardt;
use super::psd::{check_signal, welch, window, Detrend, Psd, Scaling, WelchOptions, WindowKind};
use crate::error::{count, finite, positive, Error, Result};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Most modes [`identify`] returns.
pub const MAX_MODES: usize = 8;

/// What the signal measures (sets the exponent p of the spectrum model).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum SignalKind {
    /// Acceleration (accelerometers, Klipper's files; default).
    #[default]
    Acceleration,
    /// Velocity.
    Velocity,
    /// Position or deflection.
    Position,
}

impl SignalKind {
    fn power(self) -> i32 {
        match self {
            SignalKind::Acceleration => 2,
            SignalKind::Velocity => 1,
            SignalKind::Position => 0,
        }
    }
}

/// Options of [`identify`] (JS: `{ sampleRateHz, signal, maxModes, minFrequencyHz,
/// maxFrequencyHz, minProminenceDb, segmentLength, freeDecay }`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", default)]
pub struct IdentifyOptions {
    /// Sampling rate, Hz (required).
    pub sample_rate_hz: f64,
    /// What the signal measures (default acceleration).
    pub signal: SignalKind,
    /// Most modes to return, 1 … [`MAX_MODES`] (default 3).
    pub max_modes: usize,
    /// Lowest frequency searched (default 4 bins of the detection PSD), Hz.
    pub min_frequency_hz: Option<f64>,
    /// Highest frequency searched (default 0.45 f_s), Hz.
    pub max_frequency_hz: Option<f64>,
    /// Least prominence of a peak over the smoothed spectrum around it, dB (default 6).
    pub min_prominence_db: f64,
    /// Segment length of the detection PSD (default 2^⌊log₂(n/8)⌋, 64 … 65536).
    pub segment_length: Option<usize>,
    /// Look for a free decay and fit it (default true).
    pub free_decay: bool,
}

impl Default for IdentifyOptions {
    fn default() -> Self {
        IdentifyOptions {
            sample_rate_hz: f64::NAN,
            signal: SignalKind::Acceleration,
            max_modes: 3,
            min_frequency_hz: None,
            max_frequency_hz: None,
            min_prominence_db: 6.0,
            segment_length: None,
            free_decay: true,
        }
    }
}

impl IdentifyOptions {
    /// Defaults at sampling rate `sample_rate_hz`.
    pub fn new(sample_rate_hz: f64) -> Self {
        IdentifyOptions {
            sample_rate_hz,
            ..IdentifyOptions::default()
        }
    }
}

/// How an estimate was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "camelCase")]
pub enum Method {
    /// Half-power bandwidth of the PSD peak.
    HalfPower,
    /// Least-squares fit of the modal power spectrum.
    SpectrumFit,
    /// Least-squares fit of damped sinusoids to the free decay.
    FreeDecay,
}

/// One estimate of a mode.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Estimate {
    /// The method.
    pub method: Method,
    /// Undamped natural frequency, Hz.
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping: f64,
    /// One standard deviation of `frequency_hz`, Hz.
    pub frequency_uncertainty_hz: f64,
    /// One standard deviation of `damping`.
    pub damping_uncertainty: f64,
}

/// An identified mode: the best estimate and all of them.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct IdentifiedMode {
    /// Undamped natural frequency (best estimate), Hz.
    pub frequency_hz: f64,
    /// Damping ratio (best estimate).
    pub damping: f64,
    /// One standard deviation of the frequency, Hz.
    pub frequency_uncertainty_hz: f64,
    /// One standard deviation of the damping ratio.
    pub damping_uncertainty: f64,
    /// Which estimate is the best one.
    pub method: Method,
    /// Frequency of the PSD peak, Hz.
    pub peak_frequency_hz: f64,
    /// PSD at the peak.
    pub peak_psd: f64,
    /// Prominence of the peak, dB.
    pub prominence_db: f64,
    /// Every estimate obtained, in the order half-power, spectrum fit, free decay.
    pub estimates: Vec<Estimate>,
}

/// Where the free decay was found.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct FreeDecay {
    /// Start of the fitted ring-down, s from the first sample.
    pub start_s: f64,
    /// End of it, s from the first sample.
    pub end_s: f64,
    /// RMS of the strongest block over the median block, dB.
    pub level_db: f64,
}

/// What [`identify`] found.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Identification {
    /// The modes, by increasing frequency.
    pub modes: Vec<IdentifiedMode>,
    /// The PSD the estimates were made on.
    pub spectrum: Psd,
    /// Segment length of the detection PSD.
    pub detection_segment_length: usize,
    /// The band searched, Hz.
    pub band_hz: [f64; 2],
    /// The free decay, if one was found and fitted.
    pub free_decay: Option<FreeDecay>,
}

fn pow2_floor(n: usize) -> usize {
    if n == 0 {
        0
    } else {
        1usize << (usize::BITS - 1 - n.leading_zeros())
    }
}

/// A detected peak: bin on the detection PSD and its prominence in dB.
#[derive(Debug, Clone, Copy)]
struct Peak {
    frequency_hz: f64,
    prominence_db: f64,
}

/// Local maxima of the 7-bin-smoothed dB spectrum in bins `lo..=hi`, with their topographic
/// prominence (height over the higher of the lowest points between it and a higher point on
/// each side, or the band's end).
fn detect(psd: &Psd, lo: usize, hi: usize, min_db: f64, max_modes: usize) -> Vec<Peak> {
    let db: Vec<f64> = psd
        .psd
        .iter()
        .map(|p| 10.0 * p.max(1e-300).log10())
        .collect();
    let h = 3usize;
    let sm: Vec<f64> = (lo..=hi)
        .map(|k| {
            let a = k.saturating_sub(h).max(lo);
            let b = (k + h).min(hi);
            db[a..=b].iter().sum::<f64>() / (b - a + 1) as f64
        })
        .collect();
    let n = sm.len();
    let mut peaks = Vec::new();
    for i in 1..n.saturating_sub(1) {
        if !(sm[i] > sm[i - 1] && sm[i] >= sm[i + 1]) {
            continue;
        }
        let mut left = sm[i];
        let mut j = i;
        while j > 0 {
            j -= 1;
            if sm[j] > sm[i] {
                break;
            }
            left = left.min(sm[j]);
        }
        let mut right = sm[i];
        let mut j = i;
        while j + 1 < n {
            j += 1;
            if sm[j] > sm[i] {
                break;
            }
            right = right.min(sm[j]);
        }
        let prominence = sm[i] - left.max(right);
        if prominence >= min_db {
            // The raw maximum near the smoothed one.
            let k0 = lo + i;
            let a = k0.saturating_sub(h).max(lo);
            let b = (k0 + h).min(hi);
            let k = (a..=b)
                .max_by(|&x, &y| psd.psd[x].total_cmp(&psd.psd[y]))
                .unwrap_or(k0);
            peaks.push(Peak {
                frequency_hz: psd.frequency_hz[k],
                prominence_db: prominence,
            });
        }
    }
    crate::sort::sort_by(&mut peaks, |a, b| {
        b.prominence_db.total_cmp(&a.prominence_db)
    });
    peaks.truncate(max_modes);
    crate::sort::sort_by(&mut peaks, |a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    peaks
}

/// The half-power analysis of one peak.
#[derive(Debug, Clone, Copy)]
struct HalfPower {
    peak_hz: f64,
    peak_psd: f64,
    width_hz: f64,
    estimate: Estimate,
}

/// Half-power bandwidth around the largest bin within ±`search_hz` of `near_hz`.
fn half_power(
    psd: &Psd,
    near_hz: f64,
    search_hz: f64,
    lo: usize,
    hi: usize,
    kind: SignalKind,
) -> Option<HalfPower> {
    let df = psd.resolution_hz;
    let a = (((near_hz - search_hz) / df).floor().max(lo as f64) as usize).max(lo + 1);
    let b = (((near_hz + search_hz) / df).ceil() as usize).min(hi.saturating_sub(1));
    if a > b {
        return None;
    }
    let p = &psd.psd;
    let k = (a..=b).max_by(|&x, &y| p[x].total_cmp(&p[y]))?;
    if p[k] <= 0.0 {
        return None;
    }
    let (ym, y0, yp) = (
        p[k - 1].max(1e-300).ln(),
        p[k].ln(),
        p[k + 1].max(1e-300).ln(),
    );
    let denom = ym - 2.0 * y0 + yp;
    let delta = if denom < 0.0 {
        (0.5 * (ym - yp) / denom).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    let peak_hz = (k as f64 + delta) * df;
    let peak = (y0 - 0.25 * (ym - yp) * delta).exp();
    let half = 0.5 * peak;
    // Left crossing.
    let mut j = k;
    while j > lo && p[j] > half {
        j -= 1;
    }
    if p[j] > half {
        return None;
    }
    let slope_l = (p[j + 1] - p[j]) / df;
    let f1 = (j as f64 + (half - p[j]) / (p[j + 1] - p[j])) * df;
    let mut j = k;
    while j < hi && p[j] > half {
        j += 1;
    }
    if p[j] > half {
        return None;
    }
    let slope_r = (p[j - 1] - p[j]) / df;
    let f2 = (j as f64 - (half - p[j]) / (p[j - 1] - p[j])) * df;
    let width = f2 - f1;
    if width.is_nan() || width <= 0.0 {
        return None;
    }
    let zeta_raw = width / (2.0 * peak_hz);
    let z2 = (1.0 - 2.0 * zeta_raw * zeta_raw).max(0.05).sqrt();
    let fn_hz = match kind {
        SignalKind::Position => peak_hz / z2,
        SignalKind::Velocity => peak_hz,
        SignalKind::Acceleration => peak_hz * z2,
    };
    // Uncertainty: each bin's relative standard deviation 1/√K moves a crossing by
    // s·half/slope; leakage widens by up to ENBW/2 bins; the formula is biased by ~2.5ζ².
    let s = 1.0 / (psd.segments.max(1) as f64).sqrt();
    let d1 = s * half / slope_l.abs().max(1e-300);
    let d2 = s * half / slope_r.abs().max(1e-300);
    let d1 = d1.min(width);
    let d2 = d2.min(width);
    let sigma_width = (d1 * d1
        + d2 * d2
        + (0.5 * psd.enbw_bins * df).powi(2)
        + (2.5 * zeta_raw * zeta_raw * width).powi(2))
    .sqrt();
    let sigma_f = (0.25 * (d1 * d1 + d2 * d2) + df * df / 12.0).sqrt();
    Some(HalfPower {
        peak_hz,
        peak_psd: peak,
        width_hz: width,
        estimate: Estimate {
            method: Method::HalfPower,
            frequency_hz: fn_hz,
            damping: zeta_raw,
            frequency_uncertainty_hz: sigma_f,
            damping_uncertainty: sigma_width / (2.0 * peak_hz),
        },
    })
}

/// The PSD averaged over 2h + 1 bins (fewer at the ends).
fn smoothed(psd: &Psd, h: usize) -> Psd {
    if h == 0 {
        return psd.clone();
    }
    let p = &psd.psd;
    let n = p.len();
    let mut prefix = vec![0.0; n + 1];
    for i in 0..n {
        prefix[i + 1] = prefix[i] + p[i];
    }
    let psd_s = (0..n)
        .map(|i| {
            let a = i.saturating_sub(h);
            let b = (i + h + 1).min(n);
            (prefix[b] - prefix[a]) / (b - a) as f64
        })
        .collect();
    Psd {
        psd: psd_s,
        segments: psd.segments * (2 * h + 1),
        ..psd.clone()
    }
}

/// Modal power spectrum (see the module docs) at frequency `f`.
fn modal_psd(params: &[f64], modes: usize, power: i32, f: f64) -> f64 {
    let w = 2.0 * PI * f;
    let mut h = Complex::default();
    for i in 0..modes {
        let wn = 2.0 * PI * params[3 * i].exp();
        let z = params[3 * i + 1].exp();
        let g = params[3 * i + 2];
        let den = Complex::new(wn * wn - w * w, 2.0 * z * wn * w);
        let num = g * (w / wn).powi(power) * wn * wn / den.norm_sqr();
        // g·(ω/ωₙ)^p·ωₙ²/den = num·conj(den)
        h += den.conj() * num;
    }
    h.norm_sqr() + params[3 * modes].exp()
}

/// The window's spectral kernel |W(ν)|² at ν = j·Δf/q, j = −J … J, normalised to sum 1.
fn kernel(kind: WindowKind, n: usize, q: usize, j_max: usize) -> Vec<f64> {
    let w = window(kind, n, false, 6.0);
    let mut out: Vec<f64> = (0..=2 * j_max)
        .map(|jj| {
            let j = jj as f64 - j_max as f64;
            let mut acc = Complex::default();
            for (i, &wi) in w.iter().enumerate() {
                acc += Complex::cis(-2.0 * PI * j * i as f64 / (q * n) as f64) * wi;
            }
            acc.norm_sqr()
        })
        .collect();
    let s: f64 = out.iter().sum();
    out.iter_mut().for_each(|v| *v /= s);
    out
}

/// Fits the modal spectrum to the PSD around the peaks; returns one estimate per mode.
fn spectrum_fit(
    psd: &Psd,
    initial: &[HalfPower],
    lo: usize,
    hi: usize,
    kind: SignalKind,
) -> Option<Vec<Estimate>> {
    let m = initial.len();
    let df = psd.resolution_hz;
    let power = kind.power();
    let fns: Vec<f64> = initial.iter().map(|h| h.estimate.frequency_hz).collect();
    let zs: Vec<f64> = initial
        .iter()
        .map(|h| h.estimate.damping.clamp(1e-4, 0.6))
        .collect();
    let f_lo = initial
        .iter()
        .map(|h| h.estimate.frequency_hz * (1.0 - (6.0 * h.estimate.damping).clamp(0.3, 0.9)))
        .fold(f64::INFINITY, f64::min);
    let f_hi = initial
        .iter()
        .map(|h| h.estimate.frequency_hz * (1.0 + (6.0 * h.estimate.damping).max(0.3)))
        .fold(0.0, f64::max);
    let a = ((f_lo / df).floor() as usize).max(lo).max(1);
    let b = ((f_hi / df).ceil() as usize).min(hi);
    if b <= a + 8 {
        return None;
    }
    // Bins: all within ±3 half-power widths of a peak, the others thinned to ~1500.
    let near = |k: usize| {
        let f = k as f64 * df;
        initial
            .iter()
            .any(|h| (f - h.peak_hz).abs() <= 3.0 * h.width_hz.max(2.0 * df))
    };
    let far = (a..=b).filter(|&k| !near(k)).count();
    let stride = (far / 1500).max(1);
    let mut bins = Vec::new();
    let mut far_seen = 0;
    for k in a..=b {
        if near(k) {
            bins.push(k);
        } else {
            if far_seen % stride == 0 {
                bins.push(k);
            }
            far_seen += 1;
        }
    }
    let bins: Vec<usize> = bins.into_iter().filter(|&k| psd.psd[k] > 0.0).collect();
    if bins.len() < 3 * m + 4 {
        return None;
    }
    // Leakage kernel near narrow peaks (half-power width below 12 bins).
    let (q, j_max) = (4usize, 16usize);
    let narrow: Vec<&HalfPower> = initial.iter().filter(|h| h.width_hz < 12.0 * df).collect();
    let kern = if narrow.is_empty() {
        Vec::new()
    } else {
        kernel(WindowKind::Hann, psd.segment_length, q, j_max)
    };
    let convolve: Vec<bool> = bins
        .iter()
        .map(|&k| {
            let f = k as f64 * df;
            narrow
                .iter()
                .any(|h| (f - h.peak_hz).abs() <= 4.0 * h.width_hz + 4.0 * df)
        })
        .collect();
    let logs: Vec<f64> = bins.iter().map(|&k| psd.psd[k].ln()).collect();
    let floor0 = {
        let mut v: Vec<f64> = bins.iter().map(|&k| psd.psd[k]).collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 10].max(1e-300) * 0.5
    };
    let model = |x: &[f64], out: &mut Vec<f64>| -> bool {
        out.clear();
        for (i, &k) in bins.iter().enumerate() {
            let f = k as f64 * df;
            let s = if convolve[i] && !kern.is_empty() {
                kern.iter()
                    .enumerate()
                    .map(|(jj, c)| {
                        let nu = f + (jj as f64 - j_max as f64) * df / q as f64;
                        c * modal_psd(x, m, power, nu.abs())
                    })
                    .sum::<f64>()
            } else {
                modal_psd(x, m, power, f)
            };
            if !(s > 0.0 && s.is_finite()) {
                return false;
            }
            out.push(logs[i] - s.ln());
        }
        true
    };
    let mut best: Option<super::fit::FitResult> = None;
    for signs in 0..(1usize << (m - 1)) {
        let mut x0 = Vec::with_capacity(3 * m + 1);
        for i in 0..m {
            let sign = if i > 0 && (signs >> (i - 1)) & 1 == 1 {
                -1.0
            } else {
                1.0
            };
            x0.push(fns[i].ln());
            x0.push(zs[i].ln());
            x0.push(sign * initial[i].peak_psd.sqrt() * 2.0 * zs[i]);
        }
        x0.push(floor0.ln());
        let steps: Vec<f64> = (0..3 * m + 1)
            .map(|i| {
                if i == 3 * m {
                    1e-5
                } else if i % 3 == 0 {
                    1e-7
                } else if i % 3 == 1 {
                    1e-5
                } else {
                    1e-6 * x0[i].abs().max(1e-300)
                }
            })
            .collect();
        if let Some(fit) = levenberg_marquardt(model, &x0, &steps, 60) {
            if best.as_ref().is_none_or(|b| fit.rss < b.rss) {
                best = Some(fit);
            }
        }
    }
    let fit = best?;
    let inflate = psd.enbw_bins.sqrt();
    (0..m)
        .map(|i| {
            let f = fit.x[3 * i].exp();
            let z = fit.x[3 * i + 1].exp();
            let sf = fit.sigma(3 * i)? * inflate * f;
            let sz = fit.sigma(3 * i + 1)? * inflate * z;
            (f.is_finite() && z > 0.0 && z < 1.0 && f > 0.0).then_some(Estimate {
                method: Method::SpectrumFit,
                frequency_hz: f,
                damping: z,
                frequency_uncertainty_hz: sf,
                damping_uncertainty: sz,
            })
        })
        .collect()
}

/// Finds a ring-down: returns (start, end) sample indices and its level in dB.
fn find_decay(signal: &[f64], fs: f64, lowest_hz: f64) -> Option<(usize, usize, f64)> {
    let n = signal.len();
    let block = ((2.0 * fs / lowest_hz).round() as usize).max(8);
    let blocks = n / block;
    if blocks < 8 {
        return None;
    }
    let rms: Vec<f64> = (0..blocks)
        .map(|b| {
            let s = &signal[b * block..(b + 1) * block];
            let mean = s.iter().sum::<f64>() / block as f64;
            (s.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / block as f64).sqrt()
        })
        .collect();
    let mut sorted = rms.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[blocks / 2].max(1e-300);
    let (b_max, &top) = rms.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1))?;
    let level_db = 20.0 * (top / median).log10();
    if level_db < 20.0 {
        return None;
    }
    // It must be a hit: the block two before the top is at most half of it.
    if b_max >= 2 && rms[b_max - 2] > 0.5 * top {
        return None;
    }
    let from = b_max.saturating_sub(1) * block;
    let to = ((b_max + 1) * block).min(n);
    let mean = signal[from..to].iter().sum::<f64>() / (to - from) as f64;
    let peak = (from..to).max_by(|&a, &b| {
        (signal[a] - mean)
            .abs()
            .total_cmp(&(signal[b] - mean).abs())
    })?;
    let start = peak + 2;
    let end_block = (b_max + 1..blocks)
        .find(|&b| rms[b] < 2.0 * median)
        .unwrap_or(blocks - 1);
    let end = ((end_block + 2) * block).min(n);
    (end > start + 32).then_some((start, end, level_db))
}

/// Fits damped sinusoids to `y` (sampled at `fs`) from initial (fₙ, ζ) per mode.
fn decay_fit(y: &[f64], fs: f64, initial: &[(f64, f64)]) -> Option<Vec<Estimate>> {
    let m = initial.len();
    let n = y.len();
    let tau: Vec<f64> = (0..n).map(|i| i as f64 / fs).collect();
    let t_end = tau[n - 1].max(1e-300);
    let cols = 2 * m + 2;
    // Projected residual for θ = (ln σᵢ, ln ω_dᵢ).
    let residual = |x: &[f64], out: &mut Vec<f64>| -> bool {
        let mut basis = vec![0.0; cols * n];
        for i in 0..m {
            let s = x[2 * i].exp();
            let w = x[2 * i + 1].exp();
            for k in 0..n {
                let e = (-s * tau[k]).exp();
                let (sn, cs) = (w * tau[k]).sin_cos();
                basis[k * cols + 2 * i] = e * cs;
                basis[k * cols + 2 * i + 1] = e * sn;
            }
        }
        for k in 0..n {
            basis[k * cols + 2 * m] = 1.0;
            basis[k * cols + 2 * m + 1] = tau[k] / t_end;
        }
        let mut ata = nalgebra::DMatrix::<f64>::zeros(cols, cols);
        let mut aty = nalgebra::DVector::<f64>::zeros(cols);
        for k in 0..n {
            let row = &basis[k * cols..(k + 1) * cols];
            for a in 0..cols {
                aty[a] += row[a] * y[k];
                for b in a..cols {
                    ata[(a, b)] += row[a] * row[b];
                }
            }
        }
        for a in 0..cols {
            for b in 0..a {
                ata[(a, b)] = ata[(b, a)];
            }
            ata[(a, a)] *= 1.0 + 1e-12;
            ata[(a, a)] += 1e-300;
        }
        let Some(chol) = ata.cholesky() else {
            return false;
        };
        let c = chol.solve(&aty);
        out.clear();
        for k in 0..n {
            let row = &basis[k * cols..(k + 1) * cols];
            let fit: f64 = row.iter().zip(c.iter()).map(|(a, b)| a * b).sum();
            out.push(y[k] - fit);
        }
        true
    };
    let mut x: Vec<f64> = initial
        .iter()
        .flat_map(|&(f, z)| {
            let w = 2.0 * PI * f;
            [
                (z.max(1e-4) * w).ln(),
                (w * (1.0 - z * z).max(1e-6).sqrt()).ln(),
            ]
        })
        .collect();
    // Coarse scan of each frequency over ±3 half-power widths before the local fit.
    let mut buf = Vec::new();
    for i in 0..m {
        let (f, z) = initial[i];
        let w0 = x[2 * i + 1].exp();
        let span = (3.0 * z.max(0.002)).min(0.3);
        let mut best = (f64::INFINITY, x[2 * i + 1]);
        for s in 0..=40 {
            let w = w0 * (1.0 + span * (s as f64 / 20.0 - 1.0));
            let mut xs = x.clone();
            xs[2 * i + 1] = w.ln();
            if residual(&xs, &mut buf) {
                let rss: f64 = buf.iter().map(|v| v * v).sum();
                if rss < best.0 {
                    best = (rss, w.ln());
                }
            }
        }
        x[2 * i + 1] = best.1;
        let _ = f;
    }
    let steps: Vec<f64> = (0..2 * m)
        .map(|i| if i % 2 == 0 { 1e-6 } else { 1e-8 })
        .collect();
    let fit = levenberg_marquardt(residual, &x, &steps, 80)?;
    (0..m)
        .map(|i| {
            let s = fit.x[2 * i].exp();
            let w = fit.x[2 * i + 1].exp();
            let big_w = s.hypot(w);
            let z = s / big_w;
            let (vs, vw, c) = (
                fit.covariance(2 * i, 2 * i)?,
                fit.covariance(2 * i + 1, 2 * i + 1)?,
                fit.covariance(2 * i, 2 * i + 1)?,
            );
            // Gradients with respect to (ln σ, ln ω_d).
            let dz = [s * w * w / big_w.powi(3), -s * w * w / big_w.powi(3)];
            let dw = [s * s / big_w, w * w / big_w];
            let var = |g: [f64; 2]| g[0] * g[0] * vs + 2.0 * g[0] * g[1] * c + g[1] * g[1] * vw;
            let sz = var(dz).max(0.0).sqrt();
            let sf = var(dw).max(0.0).sqrt() / (2.0 * PI);
            (z.is_finite() && z < 1.0).then_some(Estimate {
                method: Method::FreeDecay,
                frequency_hz: big_w / (2.0 * PI),
                damping: z,
                frequency_uncertainty_hz: sf,
                damping_uncertainty: sz,
            })
        })
        .collect()
}

/// Identifies the modes in `signal` (see the module docs).
///
/// Errors: fewer than 64 samples, a non-finite sample (`signal[i]`), a bad `sampleRateHz`,
/// `maxModes` outside 1 … [`MAX_MODES`], a band outside (0, f_s/2) or empty, a
/// `segmentLength` < 64 or longer than the signal. Finding no peak is not an error: `modes` is
/// empty.
pub fn identify(signal: &[f64], options: &IdentifyOptions) -> Result<Identification> {
    check_signal(signal, 64)?;
    let fs = positive("sampleRateHz", options.sample_rate_hz)?;
    count("maxModes", options.max_modes, 1, MAX_MODES)?;
    finite("minProminenceDb", options.min_prominence_db)?;
    let n = signal.len();
    let n0 = match options.segment_length {
        Some(s) => {
            count("segmentLength", s, 64, n)?;
            s
        }
        None => pow2_floor(n / 8).clamp(64, 65536),
    };
    let detect_options = WelchOptions {
        sample_rate_hz: fs,
        segment_length: Some(n0),
        overlap: Some(n0 / 2),
        window: WindowKind::Hann,
        kaiser_beta: 6.0,
        symmetric_window: false,
        detrend: Detrend::Constant,
        scaling: Scaling::Density,
    };
    let psd0 = welch(signal, &detect_options)?;
    let df0 = psd0.resolution_hz;
    let f_lo = match options.min_frequency_hz {
        Some(f) => positive("minFrequencyHz", f)?,
        None => 4.0 * df0,
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
    let bin = |psd: &Psd, f: f64| ((f / psd.resolution_hz).round() as usize).min(psd.psd.len() - 1);
    let (lo0, hi0) = (bin(&psd0, f_lo).max(1), bin(&psd0, f_hi));
    let peaks = if hi0 > lo0 + 4 {
        detect(
            &psd0,
            lo0,
            hi0,
            options.min_prominence_db,
            options.max_modes,
        )
    } else {
        Vec::new()
    };
    let mut result = Identification {
        modes: Vec::new(),
        spectrum: psd0.clone(),
        detection_segment_length: n0,
        band_hz: [f_lo, f_hi],
        free_decay: None,
    };
    if peaks.is_empty() {
        return Ok(result);
    }
    // Longer segments until the narrowest peak spans ≥ 12 bins (at least 4 segments kept).
    let n_max = pow2_floor(n / 4).max(n0).min(1 << 20);
    let mut psd = psd0;
    let mut widths: Vec<Option<HalfPower>>;
    let mut seg = n0;
    loop {
        let (lo, hi) = (bin(&psd, f_lo).max(1), bin(&psd, f_hi));
        widths = peaks
            .iter()
            .map(|p| {
                let search = (4.0 * df0).max(0.02 * p.frequency_hz);
                // On the spectrum averaged over a tenth of the peak's width, so that the bins'
                // noise does not move the crossings: from a heavy average down to that.
                let mut h = ((hi - lo) / 100).clamp(3, 2000);
                let mut found = None;
                for _ in 0..10 {
                    let Some(hp) = half_power(
                        &smoothed(&psd, h),
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
            .collect();
        let narrowest = widths
            .iter()
            .flatten()
            .map(|h| h.width_hz / psd.resolution_hz)
            .fold(f64::INFINITY, f64::min);
        if !narrowest.is_finite() || narrowest >= 12.0 || seg >= n_max {
            break;
        }
        let factor = (16.0 / narrowest).ceil() as usize;
        seg = (seg * factor.next_power_of_two()).min(n_max);
        psd = welch(
            signal,
            &WelchOptions {
                segment_length: Some(seg),
                overlap: Some(seg / 2),
                ..detect_options.clone()
            },
        )?;
    }
    let (lo, hi) = (bin(&psd, f_lo).max(1), bin(&psd, f_hi));
    let found: Vec<(Peak, HalfPower)> = peaks
        .iter()
        .zip(&widths)
        .filter_map(|(p, h)| h.map(|h| (*p, h)))
        .collect();
    // Peaks that collapse onto the same maximum are one mode.
    let mut found_unique: Vec<(Peak, HalfPower)> = Vec::new();
    for item in found {
        if !found_unique.iter().any(|(_, h)| {
            (h.peak_hz - item.1.peak_hz).abs() < 0.5 * h.width_hz.min(item.1.width_hz)
        }) {
            found_unique.push(item);
        }
    }
    let halves: Vec<HalfPower> = found_unique.iter().map(|(_, h)| *h).collect();
    let fitted = if halves.is_empty() {
        None
    } else {
        spectrum_fit(&psd, &halves, lo, hi, options.signal)
    };
    let mut estimates: Vec<Vec<Estimate>> = halves.iter().map(|h| vec![h.estimate]).collect();
    if let Some(fits) = &fitted {
        for (e, f) in estimates.iter_mut().zip(fits) {
            // A fit that wandered off its peak is not kept.
            if (f.frequency_hz - e[0].frequency_hz).abs()
                < 3.0 * e[0].frequency_hz * e[0].damping.max(0.01)
            {
                e.push(*f);
            }
        }
    }
    if options.free_decay && !halves.is_empty() {
        let lowest = halves
            .iter()
            .map(|h| h.estimate.frequency_hz)
            .fold(f64::INFINITY, f64::min);
        if let Some((start, end, level_db)) = find_decay(signal, fs, lowest) {
            let initial: Vec<(f64, f64)> = estimates
                .iter()
                .map(|e| {
                    let best = e.last().copied().unwrap_or(e[0]);
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
            if let Some(decays) = decay_fit(&y, fs / stride as f64, &initial) {
                result.free_decay = Some(FreeDecay {
                    start_s: start as f64 / fs,
                    end_s: end as f64 / fs,
                    level_db,
                });
                for (e, d) in estimates.iter_mut().zip(decays) {
                    let f0 = e[0].frequency_hz;
                    let agrees = (d.frequency_hz - f0).abs() < 0.2 * f0
                        && d.damping > 0.0
                        && d.damping_uncertainty.is_finite();
                    if agrees {
                        e.push(d);
                    }
                }
            }
        }
    }
    result.modes = found_unique
        .iter()
        .zip(estimates)
        .map(|((peak, half), estimates)| {
            // The spectrum fit refines the half-power estimate; the free-decay fit replaces it
            // when its relative damping uncertainty is smaller.
            let relative = |e: &Estimate| e.damping_uncertainty / e.damping;
            let fit = estimates.iter().find(|e| e.method == Method::SpectrumFit);
            let decay = estimates.iter().find(|e| e.method == Method::FreeDecay);
            let best = match (fit, decay) {
                (Some(f), Some(d)) if relative(d) < relative(f) => *d,
                (Some(f), _) => *f,
                (None, Some(d)) => *d,
                (None, None) => estimates[0],
            };
            IdentifiedMode {
                frequency_hz: best.frequency_hz,
                damping: best.damping,
                frequency_uncertainty_hz: best.frequency_uncertainty_hz,
                damping_uncertainty: best.damping_uncertainty,
                method: best.method,
                peak_frequency_hz: half.peak_hz,
                peak_psd: half.peak_psd,
                prominence_db: peak.prominence_db,
                estimates,
            }
        })
        .collect();
    crate::sort::sort_by(&mut result.modes, |a, b| {
        a.frequency_hz.total_cmp(&b.frequency_hz)
    });
    result.spectrum = psd;
    Ok(result)
}
