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
//! is at most `maxRemainingVibration` (default 5 %), then the others by R. Every candidate is
//! designed at the identified modes (all of them, and — with several modes — the dominant one
//! alone, the one whose PSD peak is highest), and the spectrum is scored as given (no
//! normalisation): the band is `minFrequencyHz` … `maxFrequencyHz` (default half the lowest
//! mode … three times the highest). Spectra of more than [`MAX_SCORED_BINS`] bins in the band
//! are averaged over groups of neighbouring bins.
//!
//! `criterion: "klipper"` is Klipper's own recommendation, reproduced exactly
//! ([`super::klipper`]): Klipper's shaper table (its MZV and damped EI forms at
//! `dampingRatio` 0.1), its frequency scan per family on the spectrum alone (the modes are not
//! used and may be empty), its normalisation of the PSD (applied unless the spectrum says
//! `normalization: "klipper"`), its pessimised vibrations, smoothing, max_accel, score and
//! selection rules (`find_best_shaper`), and its options (`shapers`, `dampingRatio`, `scv`,
//! `maxSmoothing`, `maxVibrations`, `testDampingRatios`, `maxFrequencyHz`,
//! `shaperFrequencies` or `shaperFrequencyRange`). `ranked` holds each family's pick by score,
//! `recommended` Klipper's choice, and `klipper` the table as Klipper prints it (family order,
//! exact and printed figures, each pick's V(f) curve on Klipper's 0.2 Hz grid). The spectrum's
//! `psd` is fitted (Klipper fits the x + y + z sum; a spectrum whose `channel` is an axis fits
//! that axis); with `runs` (one PSD per run on the same bins, the sum channel), the runs are
//! kept apart and pessimised over, as Klipper does.
//! The computation is deterministic: the same inputs give the same table.

use super::klipper::data::Normalization;
use super::klipper::{
    self, CalibrationData, Channel, Dataset, FitOptions, KlipperFit, ShaperFreqs,
};
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

/// The measured spectrum (JS: `{ frequencyHz, psd, normalization?, channel?, psdX?, psdY?,
/// psdZ?, psdSum?, runs? }`, e.g. `identification.spectrum` or a parsed Klipper spectrum file).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct MeasuredSpectrum {
    /// Bin frequencies, Hz, increasing.
    pub frequency_hz: Vec<f64>,
    /// PSD at each bin (≥ 0): the channel fitted.
    pub psd: Vec<f64>,
    /// Whether Klipper's frequency normalisation is already applied (`"none"`, the default: a
    /// Welch PSD as computed; `"klipper"`: a calibration-data file's PSD). Only
    /// `criterion: "klipper"` reads it.
    #[serde(default)]
    pub normalization: Normalization,
    /// Which channel `psd` is (`"sum"`, the default, `"x"`, `"y"`, `"z"`).
    #[serde(default)]
    pub channel: Channel,
    /// The x, y, z and summed PSDs, when known (carried along; `psd` is the one fitted).
    #[serde(default)]
    pub psd_x: Option<Vec<f64>>,
    /// See `psd_x`.
    #[serde(default)]
    pub psd_y: Option<Vec<f64>>,
    /// See `psd_x`.
    #[serde(default)]
    pub psd_z: Option<Vec<f64>>,
    /// See `psd_x`.
    #[serde(default)]
    pub psd_sum: Option<Vec<f64>>,
    /// Several runs of one axis, each run's summed PSD on these bins (`[{ name, values }]`).
    /// With two or more and the sum channel, `criterion: "klipper"` fits them apart as Klipper
    /// does; `psd` is then not read.
    #[serde(default)]
    pub runs: Vec<SpectrumRun>,
}

/// One run's PSD on the spectrum's bins.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct SpectrumRun {
    /// A name (the file's).
    pub name: String,
    /// The summed PSD at each bin.
    pub values: Vec<f64>,
}

/// How the table is ranked.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Criterion {
    /// Shortest with worst-case R ≤ `maxRemainingVibration` (default).
    #[default]
    Duration,
    /// Klipper's own recommendation, reproduced (see the module docs).
    Klipper,
    /// The shaper optimised for the spectrum by Klipper's own score, never worse than
    /// Klipper's pick ([`super::optimal`]); `firmware` says which kind (mainline Klipper's
    /// family × frequency × damping ratio, or a custom impulse sequence).
    Optimal,
}

/// Options of [`recommend`] (JS: `{ families, criterion, maxRemainingVibration, scv,
/// uncertaintySigmas, minFrequencyHz, maxFrequencyHz, shapers, dampingRatio, maxSmoothing,
/// maxVibrations, testDampingRatios, shaperFrequencies, shaperFrequencyRange }`; the last six
/// are Klipper's and read by `criterion: "klipper"` only).
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
    /// With `criterion: "klipper"`, Klipper's `max_freq` (default 200).
    pub max_frequency_hz: Option<f64>,
    /// Klipper's families to fit, its names (default zv, mzv, ei, 2hump_ei, 3hump_ei).
    pub shapers: Option<Vec<String>>,
    /// The damping ratio Klipper's shapers are built for (default 0.1).
    pub damping_ratio: Option<f64>,
    /// Klipper's `max_smoothing`, mm (default none).
    pub max_smoothing: Option<f64>,
    /// Klipper's `max_vibrations` (its `--max_vibrs_pcnt` / 100), fraction (default none).
    pub max_vibrations: Option<f64>,
    /// Damping ratios Klipper pessimises over (default 0.075, 0.1, 0.15).
    pub test_damping_ratios: Option<Vec<f64>>,
    /// Klipper's scan as a list of frequencies, Hz (default each family's range).
    pub shaper_frequencies: Option<Vec<f64>>,
    /// Klipper's scan as a range (`--shaper_freq start:end:step`; a missing bound is Klipper's
    /// default).
    pub shaper_frequency_range: Option<FrequencyRange>,
    /// With `criterion: "optimal"`: the firmware (`klipper`, `kalico`, `reprapfirmware`;
    /// default `klipper`).
    pub firmware: super::optimal::Firmware,
}

/// A scan range, Hz (`{ start?, end?, step? }`).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", default)]
pub struct FrequencyRange {
    /// First frequency (default the family's `min_freq`).
    pub start: Option<f64>,
    /// End, excluded (default 200).
    pub end: Option<f64>,
    /// Step (default 0.2).
    pub step: Option<f64>,
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
            shapers: None,
            damping_ratio: None,
            max_smoothing: None,
            max_vibrations: None,
            test_damping_ratios: None,
            shaper_frequencies: None,
            shaper_frequency_range: None,
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
    /// With `criterion: "optimal"`: the row's kind (`klipper`: Klipper's own pick, `mainline`:
    /// the best mainline-Klipper shaper, `custom`); absent for the other criteria.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kind: Option<&'static str>,
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
    /// With `criterion: "klipper"`: Klipper's table as `calibrate_shaper` prints it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub klipper: Option<KlipperFit>,
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
/// (`modes[i].damping`; not with `criterion: "klipper"`, which does not use the modes), no
/// candidate that can be designed (`infeasible`), bad options (`maxRemainingVibration` outside
/// (0, 1], `uncertaintySigmas` outside [0, 10], Klipper's options out of their domains).
pub fn recommend(
    spectrum: &MeasuredSpectrum,
    modes: &[MeasuredMode],
    options: &RecommendOptions,
) -> Result<Recommendation> {
    check_spectrum(spectrum)?;
    if options.criterion == Criterion::Klipper {
        return klipper_recommendation(spectrum, options);
    }
    if options.criterion == Criterion::Optimal {
        return super::optimal::recommend_optimal(spectrum, modes, options);
    }
    let scoring = Scoring::new(spectrum, modes, options)?;
    let (candidates, skipped) = design_candidates(&scoring, spectrum, options)?;
    let (ranked, recommended) = rank_by_duration(candidates);
    Ok(Recommendation {
        criterion: options.criterion,
        recommended,
        ranked,
        skipped,
        damping_tested: scoring.damping_tested,
        frequency_factors: scoring.frequency_factors,
        band_hz: scoring.band_hz,
        klipper: None,
        note: None,
    })
}

/// Checks the spectrum's bins: 2 … [`MAX_BINS`], equal lengths, finite frequencies ≥ 0 and
/// PSD values ≥ 0.
fn check_spectrum(spectrum: &MeasuredSpectrum) -> Result<()> {
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
    Ok(())
}

/// What the candidates are scored on: the validated modes, the band's bins (grouped when
/// long), and the damping ratios and frequency factors covering the uncertainty.
struct Scoring {
    valid: Vec<Mode>,
    nominal_dampings: Vec<f64>,
    freq: Vec<f64>,
    psd: Vec<f64>,
    damping_tested: Vec<f64>,
    frequency_factors: Vec<f64>,
    band_hz: [f64; 2],
    vmax: f64,
    scv: f64,
}

impl Scoring {
    fn new(
        spectrum: &MeasuredSpectrum,
        modes: &[MeasuredMode],
        options: &RecommendOptions,
    ) -> Result<Self> {
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
        let band_hz = band(spectrum, &valid, options)?;
        let (freq, psd) = band_bins(spectrum, band_hz)?;
        let (damping_tested, frequency_factors) = uncertainty_sets(modes, k);
        Ok(Scoring {
            valid,
            nominal_dampings: modes.iter().map(|m| m.damping).collect(),
            freq,
            psd,
            damping_tested,
            frequency_factors,
            band_hz,
            vmax,
            scv: options.scv,
        })
    }
}

/// The scored band: `minFrequencyHz` … `maxFrequencyHz`, by default half the lowest mode …
/// three times the highest (at most the last bin).
fn band(
    spectrum: &MeasuredSpectrum,
    valid: &[Mode],
    options: &RecommendOptions,
) -> Result<[f64; 2]> {
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
    Ok([f_lo, f_hi])
}

/// The bins in the band; long spectra averaged over groups of neighbouring bins (PSD level
/// kept), so the score costs the same for a 0.05 Hz and a 1.5 Hz resolution.
fn band_bins(spectrum: &MeasuredSpectrum, [f_lo, f_hi]: [f64; 2]) -> Result<(Vec<f64>, Vec<f64>)> {
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
    let group = freq.len().div_ceil(MAX_SCORED_BINS);
    if group == 1 {
        return Ok((freq, psd));
    }
    Ok(freq
        .chunks(group)
        .zip(psd.chunks(group))
        .map(|(f, p)| {
            let n = f.len() as f64;
            (f.iter().sum::<f64>() / n, p.iter().sum::<f64>() / n)
        })
        .unzip())
}

/// Damping ratios ζᵢ − kσᵢ, ζᵢ, ζᵢ + kσᵢ of every mode (sorted, deduplicated) and frequency
/// factors 1 ∓ kσ_f/f (the worst relative σ_f).
fn uncertainty_sets(modes: &[MeasuredMode], k: f64) -> (Vec<f64>, Vec<f64>) {
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
    (damping_tested, frequency_factors)
}

/// The mode whose PSD peak is highest, when there are several.
fn dominant_mode(spectrum: &MeasuredSpectrum, valid: &[Mode]) -> Option<Mode> {
    if valid.len() < 2 {
        return None;
    }
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
}

/// Every family designed for all modes and for the dominant one alone, and scored.
fn design_candidates(
    sc: &Scoring,
    spectrum: &MeasuredSpectrum,
    options: &RecommendOptions,
) -> Result<(Vec<Candidate>, Vec<Skipped>)> {
    let families = options.families.clone().unwrap_or_else(default_families);
    count("families", families.len(), 1, MAX_FAMILIES)?;
    let dominant = dominant_mode(spectrum, &sc.valid);
    let mut candidates = Vec::new();
    let mut skipped = Vec::new();
    for (i, spec) in families.iter().enumerate() {
        let title = spec.info().map_or(spec.name(), |f| f.title);
        let mut sets: Vec<(String, Vec<Mode>)> = vec![(title.to_string(), sc.valid.clone())];
        if let Some(d) = dominant {
            sets.push((
                format!("{title} ({:.1} Hz only)", d.frequency_hz()),
                vec![d],
            ));
        }
        for (label, design_modes) in sets {
            match design_for(spec, &design_modes) {
                Ok(shaper) => {
                    candidates.push(score_candidate(sc, spec, label, &design_modes, &shaper)?)
                }
                Err(e) => skipped.push(Skipped {
                    label,
                    reason: e.within(&format!("families[{i}]")).to_string(),
                }),
            }
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
    Ok((candidates, skipped))
}

/// One candidate's row: R at the estimates and in the worst case, Klipper's figures.
fn score_candidate(
    sc: &Scoring,
    spec: &ShaperSpec,
    label: String,
    design_modes: &[Mode],
    shaper: &Shaper,
) -> Result<Candidate> {
    let nominal = sc
        .nominal_dampings
        .iter()
        .map(|&z| remaining_vibration(shaper, &sc.freq, &sc.psd, z, 1.0))
        .fold(0.0, f64::max);
    let mut worst = nominal;
    for &z in &sc.damping_tested {
        for &s in &sc.frequency_factors {
            worst = worst.max(remaining_vibration(shaper, &sc.freq, &sc.psd, z, s));
        }
    }
    let (smooth, max_accel) = match shaper.centroid_delay() {
        Some(_) if shaper.amplitude_sum() > 0.0 => (
            Some(smoothing::smoothing(
                shaper,
                smoothing::KLIPPER_ACCEL,
                sc.scv,
            )?),
            Some(smoothing::max_accel(shaper, sc.scv)?).filter(|a| a.is_finite()),
        ),
        _ => (None, None),
    };
    Ok(Candidate {
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
        klipper_score: smooth.map(|s| klipper::fit::score(s, worst)),
        acceptable: worst <= sc.vmax,
        kind: None,
    })
}

/// `duration`: acceptable candidates first, the shortest of them first; the others by R.
fn rank_by_duration(mut candidates: Vec<Candidate>) -> (Vec<Candidate>, usize) {
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
    (candidates, 0)
}

/// Klipper's calibration data of a spectrum: its runs (two or more, sum channel) or its `psd`,
/// normalised as Klipper does unless it says it is.
pub fn calibration_data(spectrum: &MeasuredSpectrum) -> Result<CalibrationData> {
    let normalized = spectrum.normalization == Normalization::Klipper;
    let f = &spectrum.frequency_hz;
    let one = |name: &str, psd: &[f64]| {
        Dataset::new(name, f.clone(), psd.to_vec(), None, normalized)
            .map_err(|e| e.within("spectrum"))
    };
    let mut data = if spectrum.runs.len() >= 2 && spectrum.channel == Channel::Sum {
        let mut runs = spectrum
            .runs
            .iter()
            .enumerate()
            .map(|(i, r)| one(&r.name, &r.values).map_err(|e| e.within(&format!("runs[{i}]"))));
        let mut data = CalibrationData::new(
            runs.next()
                .unwrap_or_else(|| one("spectrum", &spectrum.psd))?,
        );
        for run in runs {
            data.add_data(CalibrationData::new(run?))?;
        }
        data
    } else {
        CalibrationData::new(one("spectrum", &spectrum.psd)?)
    };
    data.normalize_to_frequencies();
    Ok(data)
}

/// Klipper's options from [`RecommendOptions`].
fn fit_options(options: &RecommendOptions) -> FitOptions {
    let shaper_freqs = match (&options.shaper_frequencies, options.shaper_frequency_range) {
        (Some(list), _) if !list.is_empty() => Some(ShaperFreqs::List(list.clone())),
        (_, Some(r)) => Some(ShaperFreqs::Range([r.start, r.end, r.step])),
        _ => None,
    };
    FitOptions {
        shapers: options.shapers.clone(),
        damping_ratio: options.damping_ratio,
        scv: options.scv,
        shaper_freqs,
        max_smoothing: options.max_smoothing,
        max_vibrations: options.max_vibrations,
        test_damping_ratios: options.test_damping_ratios.clone(),
        max_freq: options.max_frequency_hz,
        channel: Channel::Sum,
    }
}

/// `criterion: "klipper"`: Klipper's `find_best_shaper` on the spectrum (see the module docs).
fn klipper_recommendation(
    spectrum: &MeasuredSpectrum,
    options: &RecommendOptions,
) -> Result<Recommendation> {
    let data = calibration_data(spectrum)?;
    let fit = klipper::find_best_shaper(&data, &fit_options(options))?;
    let vmax = options.max_remaining_vibration;
    let mut ranked = Vec::with_capacity(fit.families.len());
    for fam in &fit.families {
        let p = &fam.pick;
        let shaper = Shaper::from_data(&fam.shaper)?;
        ranked.push(Candidate {
            label: format!("{} ({:.1} Hz)", fam.name.to_uppercase(), fam.printed.freq),
            family: fam.name,
            spec: ShaperSpec::Custom {
                impulses: fam.shaper.impulses.clone(),
                normalize: false,
            },
            modes: vec![crate::mode::ModeSpec {
                frequency_hz: p.freq,
                damping: fit.damping_ratio,
            }],
            duration_s: shaper.duration(),
            shaper: fam.shaper.clone(),
            remaining_vibration: p.vibrs,
            nominal_remaining_vibration: p.vibrs,
            smoothing: Some(p.smoothing),
            max_accel: Some(p.max_accel).filter(|a| a.is_finite()),
            klipper_score: Some(p.score),
            acceptable: p.vibrs <= vmax,
            kind: None,
        });
    }
    // By score; `recommended` is Klipper's pick wherever it lands.
    let mut order: Vec<usize> = (0..ranked.len()).collect();
    crate::sort::sort_by(&mut order, |&a, &b| {
        fit.families[a]
            .pick
            .score
            .total_cmp(&fit.families[b].pick.score)
    });
    let recommended = order.iter().position(|&i| i == fit.best).unwrap_or(0);
    let mut slots: Vec<Option<Candidate>> = ranked.into_iter().map(Some).collect();
    let ranked = order.iter().filter_map(|&i| slots[i].take()).collect();
    let lowest = data
        .datasets()
        .iter()
        .map(|d| d.freq_bins[0])
        .fold(fit.max_freq, f64::min);
    Ok(Recommendation {
        criterion: Criterion::Klipper,
        recommended,
        ranked,
        skipped: fit
            .unknown
            .iter()
            .map(|n| Skipped {
                label: n.clone(),
                reason: format!("Klipper has no shaper '{n}'"),
            })
            .collect(),
        damping_tested: fit.test_damping_ratios.clone(),
        frequency_factors: vec![1.0],
        band_hz: [lowest, fit.max_freq],
        klipper: Some(fit),
        note: None,
    })
}
