//! Klipper's shaper fit: the frequency scan per family (`fit_shaper`), the choice among
//! families (`find_best_shaper`), and Klipper's figures of any shaper on measured data.
//!
//! Read from Klipper3d/klipper `klippy/extras/shaper_calibrate.py` (commit
//! 034cb6734a9a2b0c56e3ccee6c33866526c8cbab: `_estimate_shaper`,
//! `_estimate_remaining_vibrations`, `_get_shaper_smoothing`, `fit_shaper`, `_bisect`,
//! `find_shaper_max_accel`, `find_best_shaper`); the code here is our own.
//!
//! **Remaining vibration** of a shaper on one run, at test damping ratio ζ: with V(f, ζ) the
//! shaper's residual vibration over Σ Aᵢ (Klipper's `_estimate_shaper`, the crate's
//! [`vibration_rad`] divided by Σ Aᵢ: both reference the exponential to the last impulse),
//! P_k the PSD at the bins f_k ≤ `max_freq` and the threshold P_max/20,
//!
//! R(ζ) = Σ max(V(f_k, ζ)·P_k − P_max/20, 0) / Σ max(P_k − P_max/20, 0),
//!
//! and Klipper's `vibrs` is the largest R over the test damping ratios (0.075, 0.1, 0.15) and
//! over the runs. Its `vals` curve is the largest V over the test damping ratios, on each run's
//! bins, then linearly interpolated (numpy's `interp`) onto the grid `min_freq`, +0.2 Hz, …,
//! below `max_freq` (min_freq the lowest bin of any run) and maximised over the runs.
//!
//! **Smoothing** at 5000 mm/s² and **max_accel** (smoothing 0.12 mm, Klipper's bisection to
//! 10⁻⁸ mm/s²) are [`crate::smoothing`]'s, which implement `_get_shaper_smoothing` and
//! `_bisect` as Klipper does. The **score** is smoothing · (R^1.5 + 0.2 R + 0.01).
//!
//! **The scan** (`fit_shaper`): test frequencies from the family's `min_freq` (or the given
//! start) up to but excluding `MAX_SHAPER_FREQ` = 200 Hz in 0.2 Hz steps, formed as numpy's
//! `arange` forms them (start + i·((start + step) − start)), visited from the highest down.
//! The best is the first with the lowest R; the selected one is then, walking up from the
//! lowest frequency, any with R < 1.1·R_best + 0.0005 and a lower score than the selected one
//! so far. With `max_smoothing`, the scan stops at the first frequency whose smoothing exceeds
//! it (once it has a best) and returns that best without the selection walk.
//!
//! **The families** (`find_best_shaper`), in order: a family's pick replaces the best when its
//! score is 20 % lower, or 5 % lower with 10 % less smoothing, or (with `max_vibrations`) the
//! best leaves more vibration than allowed and this one less; then any frequency of this
//! family's scan with both less vibration and less smoothing than the best becomes the best
//! (and this family's reported pick). At the end, if the best is ZV, the first other family
//! with 10 % less vibration replaces it.
//!
//! **Speed, exactly**: V/ΣA ≤ Σ|Aᵢ|/ΣAᵢ (= 1 for positive amplitudes), so a bin whose
//! P_k·Σ|Aᵢ|/ΣAᵢ does not exceed the threshold adds exactly 0 to R and is skipped; V is
//! evaluated only where the PSD stands above P_max/20.
//!
//! Python's `or` defaults are kept: a `damping_ratio`, `max_smoothing`, `max_freq` or range
//! bound of 0 means "the default", as in Klipper.

use super::data::{CalibrationData, Channel, Dataset};
use super::shapers::{self, shaper_def, AUTOTUNE_SHAPERS, DEFAULT_DAMPING_RATIO};
use crate::error::{count, finite, Error, Result};
use crate::shaper::Shaper;
use crate::smoothing;
use crate::vibration::vibration_rad;
use serde::Serialize;
use std::f64::consts::PI;

/// Klipper's `MAX_FREQ`: the fit reads bins up to this frequency by default, Hz.
pub const MAX_FREQ: f64 = 200.0;
/// Klipper's `MAX_SHAPER_FREQ`: the scan stops below it by default, Hz.
pub const MAX_SHAPER_FREQ: f64 = 200.0;
/// Klipper's default scan step, Hz.
pub const FREQ_STEP: f64 = 0.2;
/// Klipper's `TEST_DAMPING_RATIOS`.
pub const TEST_DAMPING_RATIOS: [f64; 3] = [0.075, 0.1, 0.15];
/// Most test frequencies per family.
pub const MAX_TEST_FREQS: usize = 100_000;
/// Most test damping ratios.
pub const MAX_TEST_DAMPING_RATIOS: usize = 32;

/// The frequencies a family is scanned at.
#[derive(Debug, Clone, PartialEq)]
pub enum ShaperFreqs {
    /// An explicit list, Hz (Klipper's `--shaper_freq a,b,c`).
    List(Vec<f64>),
    /// `[start, end, step]`, Hz; a missing or 0 entry takes Klipper's default (the family's
    /// `min_freq`, 200, 0.2). Klipper's `--shaper_freq start:end:step`.
    Range([Option<f64>; 3]),
}

/// The options of Klipper's `find_best_shaper` (the JS names of
/// [`RecommendOptions`](crate::measure::recommend::RecommendOptions) in brackets).
#[derive(Debug, Clone, PartialEq)]
pub struct FitOptions {
    /// Families to try, Klipper's names (`shapers`; default zv, mzv, ei, 2hump_ei, 3hump_ei).
    pub shapers: Option<Vec<String>>,
    /// The damping ratio the shapers are built for (`dampingRatio`; default 0.1).
    pub damping_ratio: Option<f64>,
    /// Square corner velocity, mm/s (`scv`; default 5).
    pub scv: f64,
    /// The scan (`shaperFrequencies`; default each family's range).
    pub shaper_freqs: Option<ShaperFreqs>,
    /// Largest smoothing accepted, mm (`maxSmoothing`; default none).
    pub max_smoothing: Option<f64>,
    /// Largest remaining vibration wanted, fraction (`maxVibrations`; Klipper's
    /// `--max_vibrs_pcnt` / 100; default none).
    pub max_vibrations: Option<f64>,
    /// Damping ratios R is pessimised over (`testDampingRatios`; default 0.075, 0.1, 0.15).
    pub test_damping_ratios: Option<Vec<f64>>,
    /// Bins read up to this frequency, Hz (`maxFrequencyHz`; default 200, and never below the
    /// highest test frequency).
    pub max_freq: Option<f64>,
    /// The PSD fitted (`channel`; default the sum, Klipper's).
    pub channel: Channel,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            shapers: None,
            damping_ratio: None,
            scv: smoothing::KLIPPER_SCV,
            shaper_freqs: None,
            max_smoothing: None,
            max_vibrations: None,
            test_damping_ratios: None,
            max_freq: None,
            channel: Channel::Sum,
        }
    }
}

/// One shaper of a scan with Klipper's figures (Klipper's `CalibrationResult` without its
/// curve).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct FitPoint {
    /// Shaper frequency, Hz.
    pub freq: f64,
    /// Remaining vibration, fraction (Klipper's `vibrs`).
    pub vibrs: f64,
    /// Smoothing at 5000 mm/s², mm.
    pub smoothing: f64,
    /// Klipper's score.
    pub score: f64,
    /// Suggested max acceleration, mm/s².
    pub max_accel: f64,
}

/// A family's fit: the pick, the whole scan (highest frequency first, as Klipper's `results`),
/// the pick's shaper and its curve.
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct FamilyFit {
    /// Klipper's name.
    pub name: &'static str,
    /// The reported pick (what `calibrate_shaper` prints for this family).
    pub pick: FitPoint,
    /// The pick as Klipper prints it: frequency to 0.1 Hz, vibrations in % to 0.1, smoothing
    /// to 0.001, max_accel rounded to 100 mm/s².
    pub printed: Printed,
    /// The pick's shaper (Klipper's amplitudes, not normalised).
    pub shaper: crate::shaper::ShaperData,
    /// Grid of the curve, Hz.
    pub freq_bins: Vec<f64>,
    /// The pick's V pessimised over the test damping ratios and runs, on `freq_bins`.
    pub vals: Vec<f64>,
    /// Every test frequency's figures, highest frequency first.
    #[serde(skip)]
    pub scan: Vec<FitPoint>,
}

/// Klipper's printed figures (`Fitted shaper '…' frequency = %.1f Hz (vibrations = %.1f%%,
/// smoothing ~= %.3f)` and `max_accel <= %.0f` of the acceleration rounded to 100).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Printed {
    /// Frequency, Hz, to 0.1.
    pub freq: f64,
    /// Vibrations, %, to 0.1.
    pub vibrations_percent: f64,
    /// Smoothing, mm, to 0.001.
    pub smoothing: f64,
    /// Max acceleration, mm/s², to 100.
    pub max_accel: f64,
}

impl Printed {
    /// The figures of `p` as Klipper prints them (decimal rounding of the exact binary value,
    /// ties to even, as Python's `%` formatting and `round`).
    pub fn of(p: &FitPoint) -> Self {
        Printed {
            freq: fixed(p.freq, 1),
            vibrations_percent: fixed(p.vibrs * 100.0, 1),
            smoothing: fixed(p.smoothing, 3),
            max_accel: (p.max_accel / 100.0).round_ties_even() * 100.0,
        }
    }
}

/// `x` printed with `digits` decimals and read back (Rust's formatting rounds the exact binary
/// value, as Python's `%.nf`).
fn fixed(x: f64, digits: usize) -> f64 {
    format!("{x:.digits$}").parse().unwrap_or(x)
}

/// Klipper's recommendation: every family's fit and the best.
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct KlipperFit {
    /// Index into `families` of the recommended one.
    pub best: usize,
    /// The families fitted, in the order tried.
    pub families: Vec<FamilyFit>,
    /// Names asked for that Klipper does not know (skipped, as Klipper logs and skips them).
    pub unknown: Vec<String>,
    /// The damping ratio the shapers were built for.
    pub damping_ratio: f64,
    /// The test damping ratios.
    pub test_damping_ratios: Vec<f64>,
    /// The bins read up to this frequency, Hz (the largest over the families).
    pub max_freq: f64,
}

/// Klipper's figures of one shaper on measured data (see [`klipper_figures_on`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct ShaperFigures {
    /// Remaining vibration, fraction (Klipper's `vibrs`).
    pub vibrations: f64,
    /// Smoothing at 5000 mm/s², mm.
    pub smoothing: f64,
    /// Suggested max acceleration, mm/s² (∞ for a single impulse).
    pub max_accel: f64,
    /// Klipper's score.
    pub score: f64,
    /// Grid of the curve, Hz.
    pub freq_bins: Vec<f64>,
    /// V pessimised over the test damping ratios and runs, on `freq_bins`.
    pub vals: Vec<f64>,
}

/// A run prepared for scoring: the bins ≤ max_freq of the fitted channel, the threshold and
/// the denominator of R. The optimised shapers (`super::super::optimal`) score their
/// candidates with it too ([`Prepared::from_bins`], one per run and frequency factor).
pub(crate) struct Prepared {
    psd: Vec<f64>,
    threshold: f64,
    all: f64,
    /// ω of each bin, rad/s.
    omega: Vec<f64>,
    /// The test damping ratios.
    tests: Vec<f64>,
    /// Per test damping ratio, per bin: ζω and ω√(1 − ζ²).
    rates: Vec<(Vec<f64>, Vec<f64>)>,
    /// The distinct steps between neighbouring bins' ω (to 10⁻⁹ relative), or empty when
    /// there are more than [`MAX_STEPS`] (then every bin is evaluated directly).
    steps: Vec<f64>,
    /// For bin k ≥ 1: which step leads to it from bin k − 1, and the remainder ω_k − ω_{k−1} − step.
    step_of: Vec<(usize, f64)>,
}

/// Most distinct bin steps for the chained evaluation (evenly spaced bins have one; bins
/// printed to 0.1 Hz, as Klipper's files have them, two).
const MAX_STEPS: usize = 8;

impl Prepared {
    fn new(d: &Dataset, channel: Channel, max_freq: f64, tests: &[f64]) -> Result<Self> {
        let psd_all = d.psd(channel).ok_or_else(|| {
            Error::invalid(
                "channel",
                format!("run '{}' stores the summed PSD only", d.name),
            )
        })?;
        let n = d.freq_bins.partition_point(|&f| f <= max_freq);
        if n == 0 {
            return Err(Error::invalid(
                "maxFrequencyHz",
                format!("run '{}' has no bin at or below {max_freq} Hz", d.name),
            ));
        }
        let psd = &psd_all[..n];
        if psd.iter().copied().fold(0.0, f64::max) <= 0.0 {
            return Err(Error::invalid(
                "psd",
                format!("run '{}' is zero at every bin up to {max_freq} Hz", d.name),
            ));
        }
        Ok(Self::from_bins(&d.freq_bins[..n], psd, 1.0, tests))
    }

    /// A run of bins `freq` (Hz, increasing) and PSD `psd` (same length, not all zero),
    /// scored at the test damping ratios `tests` with every bin's ω scaled by `factor`
    /// (ω = 2π·f·factor, the operations of [`crate::measure::recommend::remaining_vibration`],
    /// so factor 1 gives Klipper's bins to the bit).
    pub(crate) fn from_bins(freq: &[f64], psd: &[f64], factor: f64, tests: &[f64]) -> Self {
        let p_max = psd.iter().copied().fold(0.0, f64::max);
        let threshold = p_max / shapers::SHAPER_VIBRATION_REDUCTION;
        let all = psd.iter().map(|&p| (p - threshold).max(0.0)).sum();
        let omega: Vec<f64> = freq.iter().map(|&f| 2.0 * PI * f * factor).collect();
        let rates = tests
            .iter()
            .map(|&z| {
                let damped = (1.0 - z * z).sqrt();
                (
                    omega.iter().map(|&w| z * w).collect(),
                    omega.iter().map(|&w| w * damped).collect(),
                )
            })
            .collect();
        let (steps, step_of) = bin_steps(&omega);
        Prepared {
            psd: psd.to_vec(),
            threshold,
            all,
            omega,
            tests: tests.to_vec(),
            rates,
            steps,
            step_of,
        }
    }

    /// R of `shaper` at the `t`-th test damping ratio (bins that cannot contribute skipped;
    /// see the module docs).
    pub(crate) fn remaining(&self, shaper: &Shaper, t: usize) -> f64 {
        let imp = shaper.impulses();
        let d = shaper.amplitude_sum();
        let bound = imp.iter().map(|i| i.amplitude.abs()).sum::<f64>() / d.abs();
        let active = |k: usize| self.psd[k] * bound > self.threshold;
        let (Some(k0), Some(k1)) = (
            (0..self.psd.len()).find(|&k| active(k)),
            (0..self.psd.len()).rev().find(|&k| active(k)),
        ) else {
            return 0.0;
        };
        let mut remaining = 0.0;
        let mut add = |k: usize, v: f64| {
            remaining += (v / d * self.psd[k] - self.threshold).max(0.0);
        };
        if self.steps.is_empty() || k1 - k0 < 8 {
            let (a, b) = &self.rates[t];
            for k in (k0..=k1).filter(|&k| active(k)) {
                add(k, vibration_at(imp, a[k], b[k]));
            }
        } else {
            self.chained(imp, t, k0, k1, &active, &mut add);
        }
        remaining / self.all
    }

    /// V at the bins k0 … k1 by the chain e^{ω_k sᵢ} = e^{ω_{k−1} sᵢ} · e^{q sᵢ} · (1 + δ sᵢ),
    /// with sᵢ = −ζ(t_n − tᵢ) + i√(1−ζ²) tᵢ, q the bin step and δ = ω_k − ω_{k−1} − q ≤ 10⁻⁹ q
    /// (second order ≤ 10⁻¹⁸): one complex exponential per impulse and step instead of one per
    /// impulse and bin. Agrees with [`vibration_at`] to ~10⁻¹³ (tested through the golden fits).
    fn chained(
        &self,
        imp: &[crate::shaper::Impulse],
        t: usize,
        k0: usize,
        k1: usize,
        active: &dyn Fn(usize) -> bool,
        add: &mut dyn FnMut(usize, f64),
    ) {
        let zeta = self.tests[t];
        let damped = (1.0 - zeta * zeta).sqrt();
        let t_n = imp.last().map_or(0.0, |i| i.time);
        let rate: Vec<(f64, f64)> = imp
            .iter()
            .map(|i| (-zeta * (t_n - i.time), damped * i.time))
            .collect();
        let cexp = |w: f64, (re, im): (f64, f64)| {
            let m = (w * re).exp();
            let (sin, cos) = (w * im).sin_cos();
            (m * cos, m * sin)
        };
        let q: Vec<Vec<(f64, f64)>> = self
            .steps
            .iter()
            .map(|&q| rate.iter().map(|&r| cexp(q, r)).collect())
            .collect();
        let mut e: Vec<(f64, f64)> = imp
            .iter()
            .zip(&rate)
            .map(|(i, &r)| {
                let (c, s) = cexp(self.omega[k0], r);
                (i.amplitude * c, i.amplitude * s)
            })
            .collect();
        for k in k0..=k1 {
            if k > k0 {
                let (qi, delta) = self.step_of[k - 1];
                for ((ei, &(mr, mi)), &(rr, ri)) in e.iter_mut().zip(&q[qi]).zip(&rate) {
                    let (xr, xi) = (1.0 + delta * rr, delta * ri);
                    let (mr, mi) = (mr * xr - mi * xi, mr * xi + mi * xr);
                    *ei = (ei.0 * mr - ei.1 * mi, ei.0 * mi + ei.1 * mr);
                }
            }
            if active(k) {
                let (c, s) = e.iter().fold((0.0, 0.0), |(c, s), &(a, b)| (c + a, s + b));
                // √(c² + s²), not `hypot`: wasm has no fused multiply-add and the libm `hypot`
                // Rust links there emulates one in software, which took over half of the
                // optimised shapers' time in the page's module (a node CPU profile of
                // resonances_y_three.csv). |c|, |s| ≤ Σ|Aᵢ| here, so nothing overflows, and the
                // two differ by an ulp or so, far below the chain's own 10⁻¹³.
                add(k, (c * c + s * s).sqrt());
            }
        }
    }
}

/// The distinct steps between neighbouring ω (grouped to 10⁻⁹ relative) and, for each bin
/// after the first, its step's index and remainder; no steps when there are more than
/// [`MAX_STEPS`].
fn bin_steps(omega: &[f64]) -> (Vec<f64>, Vec<(usize, f64)>) {
    let mut steps: Vec<f64> = Vec::new();
    let mut step_of = Vec::with_capacity(omega.len().saturating_sub(1));
    for w in omega.windows(2) {
        let d = w[1] - w[0];
        let i = match steps.iter().position(|&q| (d - q).abs() <= 1e-9 * q.abs()) {
            Some(i) => i,
            None if steps.len() < MAX_STEPS => {
                steps.push(d);
                steps.len() - 1
            }
            None => return (Vec::new(), Vec::new()),
        };
        step_of.push((i, d - steps[i]));
    }
    (steps, step_of)
}

/// [`vibration_rad`] with ζω = `a` and ω_d = `b` given, the same operations in the same order
/// (so the same bits), minus the two that are exact anyway: e^{−ζω·0} = 1 for the last impulse
/// and sin, cos of 0 for the first (tested equal to `vibration_rad`).
pub fn vibration_at(impulses: &[crate::shaper::Impulse], a: f64, b: f64) -> f64 {
    let t_n = impulses.last().map_or(0.0, |i| i.time);
    let (mut c, mut s) = (0.0, 0.0);
    for imp in impulses {
        let w = if imp.time == t_n {
            imp.amplitude
        } else {
            imp.amplitude * (-a * (t_n - imp.time)).exp()
        };
        if imp.time == 0.0 {
            c += w;
        } else {
            let (sin, cos) = (b * imp.time).sin_cos();
            c += w * cos;
            s += w * sin;
        }
    }
    crate::vibration::magnitude(c, s)
}

/// numpy's `arange(start, end, step)` for floats: ⌈(end − start)/step⌉ values
/// start + i·δ with δ = (start + step) − start (numpy fills from the first two values).
pub fn numpy_arange(start: f64, end: f64, step: f64) -> Vec<f64> {
    let n = ((end - start) / step).ceil();
    if n.is_nan() || n < 1.0 || n.is_infinite() {
        return Vec::new();
    }
    let n = n as usize;
    let delta = (start + step) - start;
    (0..n)
        .map(|i| {
            if i == 0 {
                start
            } else {
                start + i as f64 * delta
            }
        })
        .collect()
}

/// numpy's `interp(x, xp, fp)`: linear, the end values beyond the ends (`xp` non-decreasing,
/// non-empty).
pub fn numpy_interp(x: f64, xp: &[f64], fp: &[f64]) -> f64 {
    let n = xp.len();
    if x <= xp[0] {
        return fp[0];
    }
    if x >= xp[n - 1] {
        return fp[n - 1];
    }
    let j = xp.partition_point(|&v| v <= x) - 1;
    let slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j]);
    if slope.is_finite() {
        slope * (x - xp[j]) + fp[j]
    } else {
        fp[j]
    }
}

/// Python's truthiness default: `None` or 0 → `default`.
fn or(value: Option<f64>, default: f64) -> f64 {
    match value {
        Some(v) if v != 0.0 => v,
        _ => default,
    }
}

/// The checked test damping ratios (default Klipper's).
fn test_dampings(test: Option<&[f64]>) -> Result<Vec<f64>> {
    let list = match test {
        Some(t) if !t.is_empty() => t.to_vec(),
        _ => TEST_DAMPING_RATIOS.to_vec(),
    };
    count("testDampingRatios", list.len(), 1, MAX_TEST_DAMPING_RATIOS)?;
    for (i, &z) in list.iter().enumerate() {
        if !(z.is_finite() && (0.0..1.0).contains(&z)) {
            return Err(Error::invalid(
                format!("testDampingRatios[{i}]"),
                format!("must lie in [0, 1), got {z}"),
            ));
        }
    }
    Ok(list)
}

/// The test frequencies of family `def` (Klipper's `fit_shaper` preamble).
fn test_freqs(def: &shapers::KlipperShaperDef, freqs: Option<&ShaperFreqs>) -> Result<Vec<f64>> {
    let list = match freqs {
        Some(ShaperFreqs::List(l)) if !l.is_empty() => {
            for (i, &f) in l.iter().enumerate() {
                if !(f.is_finite() && f > 0.0) {
                    return Err(Error::invalid(
                        format!("shaperFrequencies[{i}]"),
                        format!("must be a finite frequency > 0, got {f}"),
                    ));
                }
            }
            l.clone()
        }
        other => {
            let [s, e, st] = match other {
                Some(ShaperFreqs::Range(r)) => *r,
                _ => [None; 3],
            };
            for (v, field) in [(s, "start"), (e, "end"), (st, "step")] {
                if let Some(v) = v {
                    if !(v.is_finite() && v >= 0.0) {
                        return Err(Error::invalid(
                            format!("shaperFrequencies.{field}"),
                            format!("must be finite and ≥ 0, got {v}"),
                        ));
                    }
                }
            }
            let end = or(e, MAX_SHAPER_FREQ);
            let start = or(s, def.min_freq_hz).min(end - 1e-7);
            let step = or(st, FREQ_STEP);
            if ((end - start) / step).ceil() > MAX_TEST_FREQS as f64 {
                return Err(Error::TooLarge {
                    field: "shaperFrequencies".into(),
                    value: ((end - start) / step).ceil(),
                    limit: MAX_TEST_FREQS as f64,
                });
            }
            numpy_arange(start, end, step)
        }
    };
    count("shaperFrequencies", list.len(), 1, MAX_TEST_FREQS)?;
    if let Some(&f) = list.iter().find(|&&f| f <= 0.0) {
        return Err(Error::invalid(
            "shaperFrequencies",
            format!("the scan reaches {f} Hz; every frequency must be > 0"),
        ));
    }
    Ok(list)
}

/// Runs prepared at `max_freq`, and the curve's grid (Klipper's `shaper_freq_bins`).
fn prepare(
    data: &CalibrationData,
    channel: Channel,
    max_freq: f64,
    tests: &[f64],
) -> Result<(Vec<Prepared>, Vec<f64>)> {
    let runs = data
        .datasets()
        .iter()
        .map(|d| Prepared::new(d, channel, max_freq, tests))
        .collect::<Result<Vec<_>>>()?;
    let min_freq = data
        .datasets()
        .iter()
        .map(|d| d.freq_bins[0])
        .fold(max_freq, f64::min);
    Ok((runs, numpy_arange(min_freq, max_freq, 0.2)))
}

/// R of `shaper`, pessimised over `tests` and the runs.
fn vibrations(shaper: &Shaper, runs: &[Prepared]) -> f64 {
    let mut worst = 0.0_f64;
    for run in runs {
        for t in 0..run.rates.len() {
            let r = run.remaining(shaper, t);
            if r > worst {
                worst = r;
            }
        }
    }
    worst
}

/// The curve of `shaper`: V/ΣA maximised over `tests` on each run's bins ≤ `max_freq`,
/// interpolated onto `grid`, maximised over the runs.
fn curve(
    shaper: &Shaper,
    data: &CalibrationData,
    channel: Channel,
    max_freq: f64,
    tests: &[f64],
    grid: &[f64],
) -> Vec<f64> {
    let d = shaper.amplitude_sum();
    let mut out = vec![0.0_f64; grid.len()];
    for run in data.datasets() {
        if run.psd(channel).is_none() {
            continue;
        }
        let n = run.freq_bins.partition_point(|&f| f <= max_freq);
        let bins = &run.freq_bins[..n];
        let vals: Vec<f64> = bins
            .iter()
            .map(|&f| {
                tests.iter().fold(0.0, |m: f64, &z| {
                    m.max(vibration_rad(shaper.impulses(), 2.0 * PI * f, z) / d)
                })
            })
            .collect();
        if bins.is_empty() {
            continue;
        }
        for (o, &x) in out.iter_mut().zip(grid) {
            *o = (*o).max(numpy_interp(x, bins, &vals));
        }
    }
    out
}

/// Smoothing, max_accel and score of `shaper` with remaining vibration `vibrs`.
fn point(shaper: &Shaper, freq: f64, vibrs: f64, scv: f64) -> Result<FitPoint> {
    let smoothing = smoothing::smoothing(shaper, smoothing::KLIPPER_ACCEL, scv)?;
    let max_accel = smoothing::max_accel(shaper, scv)?;
    Ok(FitPoint {
        freq,
        vibrs,
        smoothing,
        score: score(smoothing, vibrs),
        max_accel,
    })
}

/// Klipper's score: smoothing · (R^1.5 + 0.2 R + 0.01).
pub fn score(smoothing: f64, vibrs: f64) -> f64 {
    smoothing * (vibrs.powf(1.5) + vibrs * 0.2 + 0.01)
}

/// Klipper's figures of any `shaper` on `data` (what `fit_shaper` computes for each test
/// frequency): remaining vibration pessimised over `test_damping_ratios` (default Klipper's)
/// and the runs, on the `channel` PSD bins up to `max_freq` (default 200 Hz); smoothing at
/// 5000 mm/s² and max_accel at square corner velocity `scv`; the score; and the curve `vals` on
/// Klipper's 0.2 Hz grid.
///
/// Errors: a run with no bin up to `max_freq` or zero there, a bad test damping ratio, a
/// shaper whose amplitudes sum to zero or less (field `impulses`).
pub fn klipper_figures_on(
    shaper: &Shaper,
    data: &CalibrationData,
    test_damping_ratios: Option<&[f64]>,
    scv: f64,
    max_freq: Option<f64>,
    channel: Channel,
) -> Result<ShaperFigures> {
    let tests = test_dampings(test_damping_ratios)?;
    finite("scv", scv)?;
    let max_freq = or(
        max_freq.map(|f| finite("maxFrequencyHz", f)).transpose()?,
        MAX_FREQ,
    );
    if shaper.amplitude_sum() <= 0.0 {
        return Err(Error::invalid(
            "impulses",
            "Klipper's figures need amplitudes with a positive sum",
        ));
    }
    let (runs, grid) = prepare(data, channel, max_freq, &tests)?;
    let p = point(shaper, 0.0, vibrations(shaper, &runs), scv)?;
    let vals = curve(shaper, data, channel, max_freq, &tests, &grid);
    Ok(ShaperFigures {
        vibrations: p.vibrs,
        smoothing: p.smoothing,
        max_accel: p.max_accel,
        score: p.score,
        freq_bins: grid,
        vals,
    })
}

/// One family's scan: the pick and the whole scan, highest frequency first (Klipper's
/// `fit_shaper`; see the module docs). `max_freq` is Klipper's `max_freq` argument (None = 200).
pub fn fit_shaper(
    name: &str,
    data: &CalibrationData,
    options: &FitOptions,
) -> Result<(FitPoint, Vec<FitPoint>, f64)> {
    let def = shaper_def(name)
        .ok_or_else(|| Error::invalid("shapers", format!("unknown Klipper shaper '{name}'")))?;
    let damping = or(options.damping_ratio, DEFAULT_DAMPING_RATIO);
    let tests = test_dampings(options.test_damping_ratios.as_deref())?;
    finite("scv", options.scv)?;
    let freqs = test_freqs(def, options.shaper_freqs.as_ref())?;
    let top = freqs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let max_freq = or(
        options
            .max_freq
            .map(|f| finite("maxFrequencyHz", f))
            .transpose()?,
        MAX_FREQ,
    )
    .max(top);
    let (runs, _) = prepare(data, options.channel, max_freq, &tests)?;
    let max_smoothing = options.max_smoothing.filter(|&s| s != 0.0);
    let mut results: Vec<FitPoint> = Vec::with_capacity(freqs.len());
    let mut best: Option<usize> = None;
    for &f in freqs.iter().rev() {
        let shaper = shapers::klipper_shaper(name, f, damping)?;
        let smooth = smoothing::smoothing(&shaper, smoothing::KLIPPER_ACCEL, options.scv)?;
        if let (Some(limit), Some(b)) = (max_smoothing, best) {
            if smooth > limit {
                return Ok((results[b], results, max_freq));
            }
        }
        let p = point(&shaper, f, vibrations(&shaper, &runs), options.scv)?;
        results.push(p);
        if best.is_none_or(|b| results[b].vibrs > p.vibrs) {
            best = Some(results.len() - 1);
        }
    }
    let best = results[best.unwrap_or(0)];
    let over = options.max_vibrations.is_some_and(|m| best.vibrs > m);
    let mut selected = best;
    for r in results.iter().rev() {
        if r.vibrs < best.vibrs * 1.1 + 0.0005 && (r.score < selected.score || over) {
            selected = *r;
        }
    }
    Ok((selected, results, max_freq))
}

/// Klipper's recommendation on `data` (`find_best_shaper`; see the module docs): every family
/// fitted, the best chosen by Klipper's rules, each pick's curve on Klipper's grid.
///
/// Unknown names are skipped and listed (Klipper logs and skips them). Errors: bad options
/// (field named), no known family (`shapers`), a run with no usable bin.
pub fn find_best_shaper(data: &CalibrationData, options: &FitOptions) -> Result<KlipperFit> {
    let names: Vec<String> = match &options.shapers {
        Some(s) if !s.is_empty() => s.clone(),
        _ => AUTOTUNE_SHAPERS.iter().map(|s| s.to_string()).collect(),
    };
    count("shapers", names.len(), 1, 64)?;
    let damping = or(options.damping_ratio, DEFAULT_DAMPING_RATIO);
    let tests = test_dampings(options.test_damping_ratios.as_deref())?;
    let mut unknown = Vec::new();
    // (family index, point) of the best; per family (name, reported point, scan, max_freq).
    let mut best: Option<(usize, FitPoint)> = None;
    let mut fits: Vec<(&'static str, FitPoint, Vec<FitPoint>, f64)> = Vec::new();
    for name in &names {
        let Some(def) = shaper_def(name) else {
            unknown.push(name.clone());
            continue;
        };
        let (pick, scan, max_freq) = fit_shaper(def.name, data, options)?;
        let i = fits.len();
        let mut shown = pick;
        let replace = match best {
            None => true,
            Some((_, b)) => {
                pick.score * 1.2 < b.score
                    || (pick.score * 1.05 < b.score && pick.smoothing * 1.1 < b.smoothing)
                    || options
                        .max_vibrations
                        .is_some_and(|m| b.vibrs > m && pick.vibrs < b.vibrs)
            }
        };
        if replace {
            best = Some((i, pick));
        }
        for s in scan.iter().rev() {
            if let Some((_, b)) = best {
                if s.vibrs < b.vibrs && s.smoothing < b.smoothing {
                    best = Some((i, *s));
                    shown = *s;
                }
            }
        }
        fits.push((def.name, shown, scan, max_freq));
    }
    let Some((mut best_i, best_p)) = best else {
        return Err(Error::invalid(
            "shapers",
            format!("no Klipper shaper among {}", names.join(", ")),
        ));
    };
    if fits[best_i].0 == "zv" {
        if let Some(j) = fits
            .iter()
            .position(|(n, p, _, _)| *n != "zv" && p.vibrs * 1.1 < best_p.vibrs)
        {
            best_i = j;
        }
    }
    let max_freq = fits.iter().map(|f| f.3).fold(0.0, f64::max);
    let mut families = Vec::with_capacity(fits.len());
    for (name, pick, scan, mf) in fits {
        let shaper = shapers::klipper_shaper(name, pick.freq, damping)?;
        let (_, grid) = prepare(data, options.channel, mf, &tests)?;
        let vals = curve(&shaper, data, options.channel, mf, &tests, &grid);
        families.push(FamilyFit {
            name,
            pick,
            printed: Printed::of(&pick),
            shaper: shaper.to_data(),
            freq_bins: grid,
            vals,
            scan,
        });
    }
    Ok(KlipperFit {
        best: best_i,
        families,
        unknown,
        damping_ratio: damping,
        test_damping_ratios: tests,
        max_freq,
    })
}

#[cfg(test)]
mod tests {
    use super::Prepared;
    use crate::measure::recommend::remaining_vibration;
    use crate::shaper::{Impulse, Shaper};

    /// The optimised shapers' scorer (`optimal.rs`) takes R from [`Prepared::from_bins`] at
    /// frequency factors other than 1 (the modes' frequency band): it must be the R of
    /// `remaining_vibration` (V by `vibration_rad` bin by bin, independent of the chain) at
    /// f·factor, for positive shapers and for one with a negative impulse, on bins printed to
    /// 0.1 Hz as Klipper's files have them (two bin steps, so the chain runs).
    #[test]
    fn prepared_bins_at_a_frequency_factor_match_the_direct_remaining_vibration() {
        let freq: Vec<f64> = (0..194)
            .map(|k| (k as f64 * 1.5625 * 10.0).round() / 10.0)
            .collect();
        // Two resonances and a floor: many bins above Klipper's threshold, some below.
        let psd: Vec<f64> = freq
            .iter()
            .map(|&f| {
                let peak = |f0: f64, w: f64| 1.0 / (1.0 + ((f - f0) / w).powi(2));
                0.002 + peak(47.0, 4.0) + 0.6 * peak(83.0, 6.0)
            })
            .collect();
        let imp = |time: f64, amplitude: f64| Impulse { time, amplitude };
        let shapers = [
            Shaper::new(vec![imp(0.0, 0.3), imp(0.0104, 0.45), imp(0.0211, 0.25)]).unwrap(),
            Shaper::new(vec![
                imp(0.0, 0.18),
                imp(0.006, 0.3),
                imp(0.0133, 0.27),
                imp(0.019, 0.2),
                imp(0.031, 0.05),
            ])
            .unwrap(),
            Shaper::new(vec![imp(0.0, 0.7), imp(0.008, -0.2), imp(0.016, 0.5)]).unwrap(),
        ];
        let tests = [0.05, 0.1, 0.15];
        let mut chained_any = false;
        for factor in [0.93, 1.0, 1.06] {
            let prepared = Prepared::from_bins(&freq, &psd, factor, &tests);
            chained_any |= !prepared.steps.is_empty();
            for shaper in &shapers {
                for (t, &zeta) in tests.iter().enumerate() {
                    let direct = remaining_vibration(shaper, &freq, &psd, zeta, factor);
                    let chained = prepared.remaining(shaper, t);
                    assert!(direct > 1e-4, "a case that leaves vibration: {direct}");
                    assert!(
                        (chained - direct).abs() <= 1e-12 * direct,
                        "factor {factor}, ζ {zeta}: chained {chained} vs direct {direct}"
                    );
                }
            }
        }
        assert!(chained_any, "the bins must take the chained path");
    }
}
