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
//! 3. **Spectrum fit** (frequency domain, refines 2): all modes fitted jointly to the PSD by
//!    the expected Welch estimate of a modal response to a smooth excitation — coherent modal
//!    sum with a direct term, excitation (f/f_ref)^a with a fitted, white floor, convolved with
//!    the window's kernel, Klipper's normalisation when a file has it — in log by
//!    Levenberg–Marquardt, with modes hidden on a neighbour's flank added from the residuals by
//!    an information criterion (identify/model.rs has the details). The older per-peak fit
//!    (identify/spectrum_fit.rs: white-noise excitation, kernel only near narrow peaks) is the
//!    fallback when the joint fit fails.
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

mod decay;
mod half_power;
mod model;
mod peaks;
mod spectrum_fit;

use super::psd::{check_signal, welch, Detrend, Psd, Scaling, WelchOptions, WindowKind};
use crate::error::{count, finite, positive, Error, Result};
use decay::{decay_fit, find_decay};
use half_power::{half_power, smoothed, HalfPower};
use model::{fit_modes, ModelInput, Seed, WindowSpec};
use peaks::{detect, Peak};
use serde::{Deserialize, Serialize};
use spectrum_fit::spectrum_fit;

/// One mode on its way out: where its peak is and every estimate made of it.
struct Slot {
    peak_hz: f64,
    peak_psd: f64,
    prominence_db: f64,
    estimates: Vec<Estimate>,
}

impl Slot {
    /// Adds a spectrum-fit estimate unless it wandered off the peak.
    fn push_fit(&mut self, f: Estimate) {
        let e0 = self.estimates[0];
        if (f.frequency_hz - e0.frequency_hz).abs()
            < 3.0 * e0.frequency_hz * e0.damping.clamp(0.01, 0.3)
        {
            self.estimates.push(f);
        }
    }

    fn into_mode(self) -> IdentifiedMode {
        // The spectrum fit refines the half-power estimate; the free-decay fit replaces it
        // when its relative damping uncertainty is smaller.
        let estimates = self.estimates;
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
            peak_frequency_hz: self.peak_hz,
            peak_psd: self.peak_psd,
            prominence_db: self.prominence_db,
            estimates,
        }
    }
}

/// The joint fit of [`model`] seeded by the half-power estimates: each fitted mode joins its
/// seed's slot; modes found in the residuals get slots of their own. False when it failed.
fn joint_fit(
    input: &ModelInput,
    halves: &[HalfPower],
    max_modes: usize,
    slots: &mut Vec<Slot>,
) -> bool {
    let seeds: Vec<Seed> = halves
        .iter()
        .enumerate()
        .map(|(i, h)| Seed {
            frequency_hz: h.estimate.frequency_hz,
            damping: h.estimate.damping,
            peak_psd: h.peak_psd,
            peak: Some(i),
        })
        .collect();
    let Some(fitted) = fit_modes(input, &seeds, max_modes) else {
        return false;
    };
    for m in fitted {
        match m.peak {
            Some(i) => slots[i].push_fit(m.estimate),
            None => slots.push(Slot {
                peak_hz: m.estimate.frequency_hz,
                peak_psd: m.peak_psd,
                prominence_db: m.standing_db,
                estimates: vec![m.estimate],
            }),
        }
    }
    true
}

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
        None => pow2_floor(n / 4).clamp(64, 65536),
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
    let bin = |psd: &Psd, f: f64| ((f / psd.resolution_hz).round() as usize).min(psd.psd.len() - 1);
    let (lo0, hi0) = (bin(&psd0, f_lo).max(1), bin(&psd0, f_hi));
    let peaks = if hi0 > lo0 + 4 {
        detect(
            &psd0,
            lo0,
            hi0,
            options.min_prominence_db,
            options.max_modes,
            3,
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
    // Segments from the record and the peaks: the narrowest half-power width should span 4 to
    // 8 bins (the fit models the window's smearing, so a few bins suffice, and shorter
    // segments average more of them: a sweep's PSD is then steadier). Longer while it spans
    // fewer (up to n/4), or once shorter when it spans more (down to 64 samples).
    let n_max = pow2_floor(n / 4).max(n0).min(1 << 20);
    let mut psd = psd0;
    let mut widths: Vec<Option<HalfPower>>;
    let mut seg = n0;
    let mut shrunk = false;
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
        if !narrowest.is_finite() {
            break;
        }
        if narrowest > 8.0 && !shrunk && seg > 64 {
            shrunk = true;
            let factor = pow2_floor((narrowest / 4.0).floor() as usize).max(1);
            seg = (seg / factor).max(64);
        } else if narrowest < 4.0 && !shrunk && seg < n_max {
            let factor = (8.0 / narrowest).ceil() as usize;
            seg = (seg * factor.next_power_of_two()).min(n_max);
        } else {
            break;
        }
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
    let mut slots: Vec<Slot> = found_unique
        .iter()
        .map(|(p, h)| Slot {
            peak_hz: h.peak_hz,
            peak_psd: h.peak_psd,
            prominence_db: p.prominence_db,
            estimates: vec![h.estimate],
        })
        .collect();
    let input = ModelInput {
        frequency_hz: &psd.frequency_hz,
        psd: &psd.psd,
        resolution_hz: psd.resolution_hz,
        even: true,
        window: Some(WindowSpec {
            kind: WindowKind::Hann,
            length: psd.segment_length,
            symmetric: false,
            beta: 6.0,
        }),
        klipper_normalized: false,
        kind: options.signal,
        enbw_bins: psd.enbw_bins,
        band: [f_lo, f_hi],
    };
    let joint = joint_fit(&input, &halves, options.max_modes, &mut slots);
    if !joint && !halves.is_empty() {
        if let Some(fits) = spectrum_fit(&psd, &halves, lo, hi, options.signal) {
            for (slot, f) in slots.iter_mut().zip(fits) {
                slot.push_fit(f);
            }
        }
    }
    let mut estimates: Vec<Vec<Estimate>> = slots.iter().map(|s| s.estimates.clone()).collect();
    if options.free_decay && !slots.is_empty() {
        let lowest = slots
            .iter()
            .map(|s| s.estimates[0].frequency_hz)
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
    for (slot, e) in slots.iter_mut().zip(estimates) {
        slot.estimates = e;
    }
    result.modes = slots.into_iter().map(Slot::into_mode).collect();
    crate::sort::sort_by(&mut result.modes, |a, b| {
        a.frequency_hz.total_cmp(&b.frequency_hz)
    });
    result.spectrum = psd;
    Ok(result)
}

/// Identifies the modes in a spectrum alone (a Klipper spectrum file, or a raw file's Klipper
/// spectrum): the peaks of `spectrum.psd` (3-bin smoothing: Klipper's bins are coarse) seed the
/// joint fit of the module docs' step 3 (identify/model.rs), which models Klipper's Welch
/// window (symmetric Kaiser β = 6) and,
/// when `spectrum.normalization` says so, its normalisation (fitted above 10 Hz only, where the
/// released and the current Klipper agree: psd/(f + 0.1)). `options.sampleRateHz` is not used;
/// the band defaults to [5 Hz or the second bin, the last bin].
///
/// Errors: fewer than 8 bins, an uneven or non-increasing frequency column, a negative or
/// non-finite PSD (`spectrum.psd[i]`), and the option errors of [`identify`].
pub fn identify_spectrum(
    spectrum: &super::spectrum_file::SpectrumFile,
    options: &IdentifyOptions,
) -> Result<Identification> {
    use super::spectrum_file::{resolution, Normalization};
    count("maxModes", options.max_modes, 1, MAX_MODES)?;
    finite("minProminenceDb", options.min_prominence_db)?;
    let f = &spectrum.frequency_hz;
    let p = &spectrum.psd;
    count(
        "spectrum.frequencyHz",
        f.len(),
        8,
        super::psd::MAX_SEGMENT_LENGTH,
    )?;
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
    // The grid from 0: f_k = k·Δf (Klipper's rows start at bin 0; a file starting later gets
    // empty bins in front).
    let k0 = (f[0] / df).round().max(0.0) as usize;
    let n = k0 + f.len();
    let grid: Vec<f64> = (0..n).map(|k| k as f64 * df).collect();
    let mut psd_full = vec![0.0; k0];
    psd_full.extend_from_slice(p);
    let normalized = spectrum.normalization == Normalization::Klipper;
    let segment = spectrum
        .segment_length
        .unwrap_or_else(|| (2 * (n - 1)).next_power_of_two().max(256));
    let kaiser = WindowSpec {
        kind: WindowKind::Kaiser,
        length: segment,
        symmetric: true,
        beta: 6.0,
    };
    let w = super::psd::window(WindowKind::Kaiser, 2048, true, 6.0);
    let (s1, s2) = w.iter().fold((0.0, 0.0), |(a, b), v| (a + v, b + v * v));
    let enbw = 2048.0 * s2 / (s1 * s1);
    let psd = Psd {
        frequency_hz: grid,
        psd: psd_full,
        segment_length: segment,
        overlap: segment / 2,
        segments: 0,
        resolution_hz: df,
        enbw_bins: enbw,
        sample_rate_hz: df * segment as f64,
    };
    let lowest: f64 = if normalized { 10.0 } else { 5.0 };
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
    let lo = ((f_lo / df).ceil() as usize).clamp(1, n - 1);
    let hi = ((f_hi / df).floor() as usize).min(n - 1);
    let mut result = Identification {
        modes: Vec::new(),
        spectrum: psd.clone(),
        detection_segment_length: segment,
        band_hz: [f_lo, f_hi],
        free_decay: None,
    };
    if hi < lo + 4 {
        return Ok(result);
    }
    // Peaks of the spectrum with Klipper's normalisation undone (the modal peaks are those of
    // the un-normalised PSD).
    let unnormalized = Psd {
        psd: psd
            .psd
            .iter()
            .zip(&psd.frequency_hz)
            .map(|(v, f)| if normalized { v * (f + 0.1) } else { *v })
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
    let mut halves = Vec::new();
    for pk in &peaks {
        let search = 2.0 * df;
        if let Some(h) = half_power(
            &unnormalized,
            pk.frequency_hz,
            search,
            lo,
            hi,
            options.signal,
        ) {
            if !halves
                .iter()
                .any(|o: &HalfPower| (o.peak_hz - h.peak_hz).abs() < df)
            {
                // Leakage widens a narrow peak to the kernel's width: the seed's damping is an
                // upper bound, kept as it is.
                halves.push(h);
                slots.push(Slot {
                    peak_hz: h.peak_hz,
                    peak_psd: h.peak_psd,
                    prominence_db: pk.prominence_db,
                    estimates: vec![h.estimate],
                });
            }
        }
    }
    let input = ModelInput {
        frequency_hz: &psd.frequency_hz,
        psd: &psd.psd,
        resolution_hz: df,
        even: true,
        window: Some(kaiser),
        klipper_normalized: normalized,
        kind: options.signal,
        enbw_bins: enbw,
        band: [f_lo, f_hi],
    };
    joint_fit(&input, &halves, options.max_modes, &mut slots);
    result.modes = slots.into_iter().map(Slot::into_mode).collect();
    crate::sort::sort_by(&mut result.modes, |a, b| {
        a.frequency_hz.total_cmp(&b.frequency_hz)
    });
    Ok(result)
}
