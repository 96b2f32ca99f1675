//! Which shaper for a measured machine: every candidate family, designed for the identified
//! modes, scored over the measured spectrum against its duration.
//!
//! **Remaining vibration** follows Klipper's `calibrate_shaper` exactly
//! (klippy/extras/shaper_calibrate.py, `_estimate_remaining_vibrations`): with P_k the PSD at
//! bins f_k in the band, V(f, ζ) the shaper's residual vibration divided by Σ Aᵢ (Klipper's
//! `_estimate_shaper`; here [`crate::vibration::vibration_rad`], the crate's one V), and the
//! threshold P_max/20 (Klipper's `SHAPER_VIBRATION_REDUCTION`: a shaper cannot reduce vibration
//! more than 20 times, so what lies below is ignored),
//!
//! R(ζ) = Σ max(V(f_k, ζ)·P_k − P_max/20, 0) / Σ max(P_k − P_max/20, 0).
//!
//! Klipper pessimises R over test damping ratios 0.075, 0.1, 0.15 because it does not know the
//! machine's damping. Here the damping *is* measured, with an uncertainty: R is maximised over
//! ζ ∈ {ζᵢ − kσᵢ, ζᵢ, ζᵢ + kσᵢ} for every mode (k = `uncertaintySigmas`, default 2) and over the
//! frequency uncertainty (V evaluated at f·(1 ± kσ_f/f), the worst relative σ_f of the modes).
//! That worst case is `remainingVibration`; `nominalRemainingVibration` is R at the estimates.
//!
//! **Smoothing and max_accel** are Klipper's (see [`crate::smoothing`]), and
//! `klipperScore` = smoothing · (R^1.5 + 0.2R + 0.01), Klipper's `fit_shaper` score.
//!
//! **Ranking.** `criterion: "duration"` (default): the shortest candidate whose worst-case R
//! is at most `maxRemainingVibration` (default 5 %), then the others by R. `criterion:
//! "klipper"`: by `klipperScore`, and the recommendation by Klipper's `find_best_shaper` rule
//! (walking the families in order, a candidate replaces the best when its score is 20 % lower,
//! or 5 % lower with 10 % less smoothing). Unlike Klipper, which scans each family's frequency
//! over 5–200 Hz on the spectrum alone, every candidate is designed at the identified modes
//! (all of them, and — with several modes — the dominant one alone, the one whose PSD peak
//! is highest), and Klipper's low-frequency normalisation of its sweep data
//! (`normalize_to_frequencies`) is not applied: the band is `minFrequencyHz` …
//! `maxFrequencyHz` (default half the lowest mode … three times the highest). Spectra of more
//! than [`MAX_SCORED_BINS`] bins in the band are averaged over groups of neighbouring bins.
//! The computation is deterministic: the same inputs give the same table.

use crate::design::{design_for, ShaperSpec};
use crate::error::{count, finite, Error, Result};
use crate::mode::Mode;
use crate::shaper::{Shaper, ShaperData};
use crate::smoothing;
use crate::vibration::vibration_rad;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Klipper's `SHAPER_VIBRATION_REDUCTION`.
pub const SHAPER_VIBRATION_REDUCTION: f64 = 20.0;
/// Most spectrum bins accepted.
pub const MAX_BINS: usize = 1 << 21;
/// Most bins scored: longer spectra are averaged over groups of neighbouring bins.
pub const MAX_SCORED_BINS: usize = 1024;
/// Most candidate families.
pub const MAX_FAMILIES: usize = 16;

/// A mode with its uncertainty (JS: `{ frequencyHz, damping, frequencyUncertaintyHz,
/// dampingUncertainty }`, as [`identify`](super::identify::identify) returns them).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct MeasuredMode {
    /// Undamped natural frequency, Hz.
    pub frequency_hz: f64,
    /// Damping ratio.
    #[serde(default)]
    pub damping: f64,
    /// One standard deviation of the frequency, Hz (default 0).
    #[serde(default)]
    pub frequency_uncertainty_hz: f64,
    /// One standard deviation of the damping ratio (default 0).
    #[serde(default)]
    pub damping_uncertainty: f64,
}

/// The measured spectrum (JS: `{ frequencyHz, psd }`, e.g. `identification.spectrum`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct MeasuredSpectrum {
    /// Bin frequencies, Hz, increasing.
    pub frequency_hz: Vec<f64>,
    /// PSD at each bin (≥ 0).
    pub psd: Vec<f64>,
}

/// How the table is ranked.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Criterion {
    /// Shortest with worst-case R ≤ `maxRemainingVibration` (default).
    #[default]
    Duration,
    /// Klipper's score and selection rule.
    Klipper,
    /// The shaper optimised for the spectrum by Klipper's own score, never worse than
    /// Klipper's pick ([`super::optimal`]); `firmware` says which kind (mainline Klipper's
    /// family × frequency × damping ratio, or a custom impulse sequence).
    Optimal,
}

/// Options of [`recommend`] (JS: `{ families, criterion, maxRemainingVibration, scv,
/// uncertaintySigmas, minFrequencyHz, maxFrequencyHz }`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", default)]
pub struct RecommendOptions {
    /// Candidate families as design specs (default ZV, MZV, ZVD, EI, 2-hump EI, 3-hump EI).
    pub families: Option<Vec<ShaperSpec>>,
    /// Ranking (default `duration`).
    pub criterion: Criterion,
    /// Largest acceptable worst-case remaining vibration, fraction (default 0.05).
    pub max_remaining_vibration: f64,
    /// Square corner velocity for smoothing, mm/s (default 5, Klipper's).
    pub scv: f64,
    /// k: how many standard deviations of the estimates are covered (default 2).
    pub uncertainty_sigmas: f64,
    /// Lower end of the scored band (default half the lowest mode's frequency), Hz.
    pub min_frequency_hz: Option<f64>,
    /// Upper end (default 3 × the highest mode's frequency, or the spectrum's last bin), Hz.
    pub max_frequency_hz: Option<f64>,
    /// With `criterion: "optimal"`: the firmware (`klipper`, `kalico`, `reprapfirmware`;
    /// default `klipper`).
    pub firmware: super::optimal::Firmware,
}

impl Default for RecommendOptions {
    fn default() -> Self {
        RecommendOptions {
            families: None,
            criterion: Criterion::Duration,
            max_remaining_vibration: 0.05,
            scv: smoothing::KLIPPER_SCV,
            uncertainty_sigmas: 2.0,
            min_frequency_hz: None,
            max_frequency_hz: None,
            firmware: super::optimal::Firmware::Klipper,
        }
    }
}

/// The default candidates: Klipper's autotune list (zv, mzv, ei, 2hump_ei, 3hump_ei) and ZVD.
pub fn default_families() -> Vec<ShaperSpec> {
    let vtol = crate::design::extra_insensitive::DEFAULT_VTOL;
    vec![
        ShaperSpec::Zv,
        ShaperSpec::Mzv,
        ShaperSpec::Zvd,
        ShaperSpec::Ei { vtol },
        ShaperSpec::Ei2 { vtol },
        ShaperSpec::Ei3 { vtol },
    ]
}

/// One row of the table.
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Candidate {
    /// "ZVD", or "ZVD (32.1 Hz only)" for the dominant-mode variant.
    pub label: String,
    /// The family name.
    pub family: &'static str,
    /// The spec it was designed from.
    pub spec: ShaperSpec,
    /// The modes it was designed for.
    pub modes: Vec<crate::mode::ModeSpec>,
    /// The shaper.
    pub shaper: ShaperData,
    /// Its duration, s.
    pub duration_s: f64,
    /// Worst-case remaining vibration over the uncertainty, fraction.
    pub remaining_vibration: f64,
    /// Remaining vibration at the estimates, fraction.
    pub nominal_remaining_vibration: f64,
    /// Klipper's smoothing, mm (`null` for zero-sum shapers).
    pub smoothing: Option<f64>,
    /// Klipper's suggested max acceleration, mm/s² (`null` when unbounded or undefined).
    pub max_accel: Option<f64>,
    /// Klipper's score (`null` without smoothing).
    pub klipper_score: Option<f64>,
    /// Whether `remainingVibration ≤ maxRemainingVibration`.
    pub acceptable: bool,
}

/// A candidate left out, and why.
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Skipped {
    /// Its label.
    pub label: String,
    /// The design error.
    pub reason: String,
}

/// The recommendation and the ranked table.
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Recommendation {
    /// The ranking used.
    pub criterion: Criterion,
    /// Index into `ranked` of the recommended candidate.
    pub recommended: usize,
    /// The candidates, best first.
    pub ranked: Vec<Candidate>,
    /// Candidates that could not be designed for the modes (e.g. a 2-hump EI at ζ = 0.6).
    pub skipped: Vec<Skipped>,
    /// Damping ratios R was maximised over.
    pub damping_tested: Vec<f64>,
    /// Frequency factors V was evaluated at (f·factor).
    pub frequency_factors: Vec<f64>,
    /// Band scored, Hz.
    pub band_hz: [f64; 2],
    /// With `criterion: "optimal"`: what the optimisation bought, in words.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// Klipper's remaining vibration R of `shaper` over bins (f, P), V at `zeta` and f·`factor`.
pub fn remaining_vibration(
    shaper: &Shaper,
    frequency_hz: &[f64],
    psd: &[f64],
    zeta: f64,
    factor: f64,
) -> f64 {
    let p_max = psd.iter().copied().fold(0.0, f64::max);
    let threshold = p_max / SHAPER_VIBRATION_REDUCTION;
    let d = shaper.amplitude_sum();
    let (mut remaining, mut all) = (0.0, 0.0);
    for (&f, &p) in frequency_hz.iter().zip(psd) {
        let v = vibration_rad(shaper.impulses(), 2.0 * PI * f * factor, zeta) / d;
        remaining += (v * p - threshold).max(0.0);
        all += (p - threshold).max(0.0);
    }
    if all > 0.0 {
        remaining / all
    } else {
        0.0
    }
}

/// Scores the candidate families over the measured spectrum (see the module docs).
///
/// Candidates that cannot be designed for the modes are listed in `skipped`. Errors: an empty
/// or mismatched spectrum, a non-finite or negative bin, no modes or a bad mode
/// (`modes[i].damping`), no candidate that can be designed (`infeasible`), bad
/// options (`maxRemainingVibration` outside (0, 1], `uncertaintySigmas` outside [0, 10]).
pub fn recommend(
    spectrum: &MeasuredSpectrum,
    modes: &[MeasuredMode],
    options: &RecommendOptions,
) -> Result<Recommendation> {
    if options.criterion == Criterion::Optimal {
        return super::optimal::recommend_optimal(spectrum, modes, options);
    }
    count("spectrum.psd", spectrum.psd.len(), 2, MAX_BINS)?;
    if spectrum.frequency_hz.len() != spectrum.psd.len() {
        return Err(Error::invalid(
            "spectrum.frequencyHz",
            format!(
                "has {} values but psd has {}",
                spectrum.frequency_hz.len(),
                spectrum.psd.len()
            ),
        ));
    }
    for (i, (&f, &p)) in spectrum.frequency_hz.iter().zip(&spectrum.psd).enumerate() {
        if !(f.is_finite() && f >= 0.0) {
            return Err(Error::invalid(
                format!("spectrum.frequencyHz[{i}]"),
                format!("must be a finite frequency ≥ 0, got {f}"),
            ));
        }
        if !(p.is_finite() && p >= 0.0) {
            return Err(Error::invalid(
                format!("spectrum.psd[{i}]"),
                format!("must be a finite value ≥ 0, got {p}"),
            ));
        }
    }
    count("modes", modes.len(), 1, super::identify::MAX_MODES)?;
    let k = options.uncertainty_sigmas;
    if !(0.0..=10.0).contains(&k) {
        return Err(Error::invalid(
            "uncertaintySigmas",
            format!("must lie in [0, 10], got {k}"),
        ));
    }
    let vmax = options.max_remaining_vibration;
    if !(vmax > 0.0 && vmax <= 1.0) {
        return Err(Error::invalid(
            "maxRemainingVibration",
            format!("must lie in (0, 1], got {vmax}"),
        ));
    }
    finite("scv", options.scv)?;
    let mut valid = Vec::with_capacity(modes.len());
    for (i, m) in modes.iter().enumerate() {
        let at = |e: Error| e.within(&format!("modes[{i}]"));
        valid.push(Mode::new(m.frequency_hz, m.damping).map_err(at)?);
        finite("frequencyUncertaintyHz", m.frequency_uncertainty_hz).map_err(at)?;
        finite("dampingUncertainty", m.damping_uncertainty).map_err(at)?;
    }
    let lowest = valid
        .iter()
        .map(Mode::frequency_hz)
        .fold(f64::INFINITY, f64::min);
    let last = spectrum.frequency_hz[spectrum.frequency_hz.len() - 1];
    let f_lo = match options.min_frequency_hz {
        Some(f) => finite("minFrequencyHz", f)?,
        None => 0.5 * lowest,
    };
    let highest = valid.iter().map(Mode::frequency_hz).fold(0.0, f64::max);
    let f_hi = match options.max_frequency_hz {
        Some(f) => finite("maxFrequencyHz", f)?,
        None => last.min(3.0 * highest),
    };
    let (freq, psd): (Vec<f64>, Vec<f64>) = spectrum
        .frequency_hz
        .iter()
        .zip(&spectrum.psd)
        .filter(|(f, _)| (f_lo..=f_hi).contains(*f))
        .map(|(f, p)| (*f, *p))
        .unzip();
    if freq.is_empty() {
        return Err(Error::invalid(
            "minFrequencyHz",
            format!("the band [{f_lo}, {f_hi}] Hz holds no spectrum bin"),
        ));
    }
    // Long spectra are averaged over groups of neighbouring bins (PSD level kept), so the
    // score costs the same for a 0.05 Hz and a 1.5 Hz resolution (Klipper's 0.5 s windows).
    let group = freq.len().div_ceil(MAX_SCORED_BINS);
    let (freq, psd): (Vec<f64>, Vec<f64>) = if group > 1 {
        freq.chunks(group)
            .zip(psd.chunks(group))
            .map(|(f, p)| {
                let n = f.len() as f64;
                (f.iter().sum::<f64>() / n, p.iter().sum::<f64>() / n)
            })
            .unzip()
    } else {
        (freq, psd)
    };
    // Damping ratios and frequency factors covering the uncertainty.
    let mut damping_tested: Vec<f64> = Vec::new();
    for m in modes {
        for z in [
            m.damping - k * m.damping_uncertainty.abs(),
            m.damping,
            m.damping + k * m.damping_uncertainty.abs(),
        ] {
            damping_tested.push(z.clamp(0.0, 0.95));
        }
    }
    damping_tested.sort_by(f64::total_cmp);
    damping_tested.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    let rel_f = modes
        .iter()
        .map(|m| m.frequency_uncertainty_hz.abs() / m.frequency_hz)
        .fold(0.0, f64::max);
    let mut frequency_factors = vec![1.0];
    if rel_f * k > 0.0 {
        let d = (rel_f * k).min(0.5);
        frequency_factors = vec![1.0 - d, 1.0, 1.0 + d];
    }
    // Candidates: every family for all modes, and for the dominant mode alone.
    let families = options.families.clone().unwrap_or_else(default_families);
    count("families", families.len(), 1, MAX_FAMILIES)?;
    let dominant = if valid.len() > 1 {
        let level = |f: f64| {
            let i = spectrum
                .frequency_hz
                .partition_point(|&x| x < f)
                .min(spectrum.psd.len() - 1);
            spectrum.psd[i]
        };
        valid
            .iter()
            .copied()
            .max_by(|a, b| level(a.frequency_hz()).total_cmp(&level(b.frequency_hz())))
    } else {
        None
    };
    let mut candidates = Vec::new();
    let mut skipped = Vec::new();
    for (i, spec) in families.iter().enumerate() {
        let title = spec.info().map_or(spec.name(), |f| f.title);
        let mut sets: Vec<(String, Vec<Mode>)> = vec![(title.to_string(), valid.clone())];
        if let Some(d) = dominant {
            sets.push((
                format!("{title} ({:.1} Hz only)", d.frequency_hz()),
                vec![d],
            ));
        }
        for (label, design_modes) in sets {
            let shaper = match design_for(spec, &design_modes) {
                Ok(s) => s,
                Err(e) => {
                    skipped.push(Skipped {
                        label,
                        reason: e.within(&format!("families[{i}]")).to_string(),
                    });
                    continue;
                }
            };
            let nominal = modes
                .iter()
                .map(|m| remaining_vibration(&shaper, &freq, &psd, m.damping, 1.0))
                .fold(0.0, f64::max);
            let mut worst = nominal;
            for &z in &damping_tested {
                for &s in &frequency_factors {
                    worst = worst.max(remaining_vibration(&shaper, &freq, &psd, z, s));
                }
            }
            let (smooth, max_accel) = match shaper.centroid_delay() {
                Some(_) if shaper.amplitude_sum() > 0.0 => (
                    Some(smoothing::smoothing(
                        &shaper,
                        smoothing::KLIPPER_ACCEL,
                        options.scv,
                    )?),
                    Some(smoothing::max_accel(&shaper, options.scv)?).filter(|a| a.is_finite()),
                ),
                _ => (None, None),
            };
            let score = smooth.map(|s| s * (worst.powf(1.5) + 0.2 * worst + 0.01));
            candidates.push(Candidate {
                label,
                family: spec.name(),
                spec: spec.clone(),
                modes: design_modes
                    .iter()
                    .map(|m| crate::mode::ModeSpec {
                        frequency_hz: m.frequency_hz(),
                        damping: m.damping(),
                    })
                    .collect(),
                duration_s: shaper.duration(),
                shaper: shaper.to_data(),
                remaining_vibration: worst,
                nominal_remaining_vibration: nominal,
                smoothing: smooth,
                max_accel,
                klipper_score: score,
                acceptable: worst <= vmax,
            });
        }
    }
    if candidates.is_empty() {
        return Err(Error::Infeasible {
            reason: format!(
                "no candidate could be designed for the modes: {}",
                skipped
                    .iter()
                    .map(|s| s.reason.as_str())
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        });
    }
    let recommended_label;
    match options.criterion {
        Criterion::Duration => {
            crate::sort::sort_by(&mut candidates, |a, b| {
                b.acceptable
                    .cmp(&a.acceptable)
                    .then_with(|| {
                        if a.acceptable {
                            a.duration_s.total_cmp(&b.duration_s)
                        } else {
                            a.remaining_vibration.total_cmp(&b.remaining_vibration)
                        }
                    })
                    .then_with(|| a.remaining_vibration.total_cmp(&b.remaining_vibration))
            });
            recommended_label = candidates[0].label.clone();
        }
        // (`Optimal` returned at the top; it never reaches here.)
        Criterion::Klipper | Criterion::Optimal => {
            // find_best_shaper's walk, in the candidates' (families') order.
            let mut best: Option<&Candidate> = None;
            for c in candidates.iter().filter(|c| c.klipper_score.is_some()) {
                let (s, sm) = (
                    c.klipper_score.unwrap_or(f64::INFINITY),
                    c.smoothing.unwrap_or(0.0),
                );
                best = match best {
                    None => Some(c),
                    Some(b) => {
                        let (bs, bsm) = (
                            b.klipper_score.unwrap_or(f64::INFINITY),
                            b.smoothing.unwrap_or(0.0),
                        );
                        if s * 1.2 < bs || (s * 1.05 < bs && sm * 1.1 < bsm) {
                            Some(c)
                        } else {
                            Some(b)
                        }
                    }
                };
            }
            recommended_label = best.map_or(candidates[0].label.clone(), |b| b.label.clone());
            crate::sort::sort_by(&mut candidates, |a, b| {
                a.klipper_score
                    .unwrap_or(f64::INFINITY)
                    .total_cmp(&b.klipper_score.unwrap_or(f64::INFINITY))
            });
        }
    }
    let recommended = candidates
        .iter()
        .position(|c| c.label == recommended_label)
        .unwrap_or(0);
    Ok(Recommendation {
        criterion: options.criterion,
        recommended,
        ranked: candidates,
        skipped,
        damping_tested,
        frequency_factors,
        band_hz: [f_lo, f_hi],
        note: None,
    })
}
