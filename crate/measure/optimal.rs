//! A shaper designed for the measured spectrum, better than Klipper's pick on Klipper's own
//! terms (issue 25).
//!
//! Klipper's `calibrate_shaper` (klippy/extras/shaper_calibrate.py, `find_best_shaper` and
//! `fit_shaper`) walks five fixed families at one assumed `damping_ratio` (0.1), scanning only
//! the frequency, and picks by its score
//!
//! score = smoothing · (R^1.5 + 0.2 R + 0.01),
//!
//! R the remaining vibration pessimised over the test damping ratios 0.075 / 0.1 / 0.15 on its
//! frequency-normalised PSD. Its pick is not the score's minimum: within a family it keeps the
//! frequencies whose R is within 10 % of the family's least R, and across families a later one
//! must be 20 % better (or 5 % better with 10 % less smoothing). Every figure here is computed
//! by the crate's one reproduction of Klipper ([`super::klipper`]); nothing of it is re-coded.
//!
//! **1. Best mainline-Klipper shaper.** Mainline Klipper runs any family (zv, mzv, zvd, ei,
//! 2hump_ei, 3hump_ei) at any `shaper_freq` and any `damping_ratio` (its `[input_shaper]`
//! takes all three). The search: for every family and a grid of damping ratios (up to the
//! family's `max_damping_ratio`), a log-spaced frequency scan (0.5 % steps), then a local
//! pattern search in (frequency, damping ratio) around the best few. The objective is
//! Klipper's own score (its three ratios, factor 1). The measured modes' uncertainty is a
//! constraint: R pessimised over a widened damping set — Klipper's three ratios and, for every
//! measured mode, ζ − kσ, ζ, ζ + kσ — and, when the modes carry a frequency uncertainty, over
//! V evaluated at f·(1 ± kσ_f/f) (the *robust* R) may not exceed max(Klipper pick's robust R,
//! 5 %): no less robust to what was measured than Klipper's pick, or within Klipper's own 5 %.
//! (Ranked by the robust score instead, as before 2026-12-04, the optimised shapers gained
//! nothing on real files: real modes come with ζ − 2σ below Klipper's 0.075, and over that set
//! the pick, held only to Klipper's three ratios, stayed the best; docs/measured-data.md, *On
//! real recordings*.) Candidates must also satisfy, under Klipper's own scoring: score ≤
//! Klipper's pick's, and R ≤ max(Klipper pick's R, 5 %). Klipper's pick itself is a candidate,
//! so the guarantees always hold.
//!
//! **2. Best custom shaper.** For firmware that takes an impulse sequence
//! ([`Firmware::limits`]), a local optimisation of all impulse times and amplitudes
//! (Nelder–Mead on log-gaps and softmax amplitudes above the smallest admitted one, so the
//! times stay ordered and the amplitudes above it and summing to 1) started from the best
//! mainline shapers (a continuation from the best families), grown one impulse at a time (the
//! largest split, or a smallest one appended after the last) and finally restarted from its
//! best point, on the same objective with the same
//! constraints (the robust R against the pick's on this search's frequency band), plus the firmware's limits (impulse count, duration, smallest amplitude) and
//! Klipper's own score ≤ the best mainline shaper's. The start is feasible and the simplex
//! keeps its best vertex, so the result is never worse than the best mainline shaper. A second
//! search, behind the `solver` feature ([`CustomMethod::Grid`], `optimal_grid.rs`), solves a
//! convex program on a time grid (least smoothing with no remaining vibration, Clarabel) over
//! a sweep of durations and centroids and polishes the result the same way; it finds somewhat
//! lower scores at 5–20 times the cost (docs/measured-data.md, *Optimised shapers*), so the
//! page uses the continuation. Every custom impulse carries at least
//! [`MIN_CUSTOM_AMPLITUDE`]. [`no_vibration_bound`] (solver) computes the floor every custom
//! shaper with no remaining vibration meets on a time grid: on the test set the grid search
//! reaches it, the continuation comes within a few per cent. The frequency band of the robust score is the modes' frequency
//! uncertainty (none without modes, [`DEFAULT_FREQUENCY_BAND`]): a ±2 % band halved the gain on
//! the test set, and without it the shaper designed on one run of a machine scores within 10 %
//! on the other run (tests/optimal.rs).
//!
//! **3. The table**: Klipper's pick, the best mainline shaper and the best custom shaper, each
//! with Klipper's own figures, the robust ones, the improvement over Klipper's pick and a note
//! saying plainly when the custom shaper buys little.

use crate::error::{count, finite, Error, Result};
use crate::shaper::{Impulse, Shaper, ShaperData};
use crate::smoothing;
use serde::{Deserialize, Serialize};

use super::klipper::fit::Prepared;
use super::klipper::{
    find_best_shaper, klipper_figures_on, klipper_shaper, CalibrationData, Channel, FitOptions,
    KLIPPER_SHAPERS,
};
use super::recommend::{MeasuredMode, MeasuredSpectrum};

#[cfg(feature = "solver")]
#[path = "optimal_grid.rs"]
mod grid;

/// Klipper's test damping ratios (shaper_calibrate.py `TEST_DAMPING_RATIOS`).
pub const KLIPPER_TEST_DAMPING: [f64; 3] = [0.075, 0.1, 0.15];
/// The largest remaining vibration always tolerated (issue 25: never more than the larger of
/// Klipper's pick's and 5 %).
pub const VIBRATION_ALLOWANCE: f64 = 0.05;
/// Smallest relative frequency band (± this fraction) scored for the custom shaper; the modes'
/// frequency uncertainty widens it.
pub const DEFAULT_FREQUENCY_BAND: f64 = 0.0;
/// Damping ratios of the mainline scan (each family up to its `max_damping_ratio`).
const DAMPING_GRID: [f64; 7] = [0.05, 0.075, 0.1, 0.125, 0.15, 0.2, 0.25];
/// Relative step of the mainline frequency scan (refined afterwards by a pattern search).
const FREQUENCY_STEP: f64 = 0.02;
/// Local minima of each family's scan refined.
const REFINED_PER_FAMILY: usize = 2;
/// Most objective evaluations of one Nelder–Mead run.
const MAX_EVALUATIONS: usize = 700;
/// Most objective evaluations of the whole custom search (keeps the time per axis bounded:
/// one evaluation is a few tens of microseconds).
const CUSTOM_EVALUATION_BUDGET: usize = 4200;
/// Most restarts of the final polish of the best custom shaper.
const FINAL_RESTARTS: usize = 3;
/// Mainline shapers (best first) the continuation starts from.
const CONTINUATION_STARTS: usize = 2;
/// Most impulses the custom optimiser uses (beyond this the gain is nil on measured spectra and
/// the time grows).
pub const MAX_CUSTOM_IMPULSES: usize = 7;
/// Smallest amplitude of a custom impulse, whatever the firmware allows. Klipper's V is
/// referenced to the last impulse (`_estimate_shaper`: e^{−ζω(T_last − Tᵢ)}), so a tiny impulse
/// placed late lowers V of every damped case without any physical benefit (the vibration has
/// merely been given time to decay, while the toolhead waits) and costs almost no smoothing: an
/// optimiser left free finds it (on the test set, −5 to −8 % of score with a 0.1 % impulse at
/// 2.4 times the duration). Every impulse must carry at least 2 % so the score is not gamed.
pub const MIN_CUSTOM_AMPLITUDE: f64 = 0.02;
/// The custom shaper is called a small gain below this relative improvement over the best
/// mainline shaper.
const SMALL_GAIN: f64 = 0.05;

/// Firmware the optimised shaper is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Firmware {
    /// Mainline Klipper: a family, `shaper_freq` and `damping_ratio` only.
    #[default]
    Klipper,
    /// Kalico (formerly Danger-Klipper): `shaper_type_x: custom` with `shaper_a_x`, `shaper_t_x`.
    #[serde(alias = "dangerklipper", alias = "danger-klipper")]
    Kalico,
    /// RepRapFirmware 3.5+: `M593 P"custom" H… T…`.
    #[serde(alias = "rrf")]
    Reprapfirmware,
}

pub use crate::firmware_limits::FirmwareLimits;

impl Firmware {
    /// The firmware's custom-shaper limits; `None` for mainline Klipper (no custom shaper).
    /// The numbers and their citations (Kalico's `_parse_custom_shaper` and kin_shaper.c,
    /// RepRapFirmware's AxisShaper.h) are in [`crate::firmware_limits`], which the config
    /// writer checks against too.
    pub fn limits(self) -> Option<FirmwareLimits> {
        match self {
            Firmware::Klipper => None,
            Firmware::Kalico => Some(crate::firmware_limits::KALICO_CUSTOM),
            Firmware::Reprapfirmware => Some(crate::firmware_limits::RRF_CUSTOM),
        }
    }
}

/// Options of [`optimal`] (JS: `{ firmware, uncertaintySigmas, scv }`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", default)]
pub struct OptimalOptions {
    /// Firmware (default `klipper`: the mainline shaper only).
    pub firmware: Firmware,
    /// k: how many standard deviations of the modes' estimates the robust score covers
    /// (default 2).
    pub uncertainty_sigmas: f64,
    /// Square corner velocity for smoothing, mm/s (default 5, Klipper's).
    pub scv: f64,
    /// How the custom shaper is searched (default `both` with the solver, else
    /// `continuation`).
    pub custom_method: CustomMethod,
}

impl Default for OptimalOptions {
    fn default() -> Self {
        OptimalOptions {
            firmware: Firmware::Klipper,
            uncertainty_sigmas: 2.0,
            scv: smoothing::KLIPPER_SCV,
            custom_method: CustomMethod::default(),
        }
    }
}

/// The custom shaper's search (the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CustomMethod {
    /// Nelder–Mead from the best mainline shapers, growing one impulse at a time.
    Continuation,
    /// The convex program on a time grid (R = 0, least smoothing) swept over duration and
    /// centroid, then the same polish. Needs the `solver` feature (else `unavailable`).
    Grid,
    /// Both, the better result kept.
    Both,
}

impl Default for CustomMethod {
    fn default() -> Self {
        if cfg!(feature = "solver") {
            CustomMethod::Both
        } else {
            CustomMethod::Continuation
        }
    }
}

/// Klipper's figures of one shaper, by Klipper's own scoring.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Figures {
    /// Remaining vibration R (fraction), pessimised over 0.075 / 0.1 / 0.15.
    pub vibrations: f64,
    /// Smoothing at 5000 mm/s², mm.
    pub smoothing: f64,
    /// Suggested max acceleration (smoothing 0.12 mm), mm/s².
    pub max_accel: f64,
    /// Klipper's score.
    pub score: f64,
}

/// One row of the table.
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct OptimalRow {
    /// `klipper` (Klipper's own pick), `mainline` (best mainline-Klipper shaper) or `custom`.
    pub kind: &'static str,
    /// Family name in Klipper's spelling (`custom` for a custom sequence).
    pub family: String,
    /// `shaper_freq` (Hz) for a family, `null` for a custom sequence.
    pub shaper_freq_hz: Option<f64>,
    /// `damping_ratio` for a family, `null` for a custom sequence.
    pub damping_ratio: Option<f64>,
    /// The impulses.
    pub shaper: ShaperData,
    /// Klipper's own figures.
    pub klipper: Figures,
    /// R over the widened damping set and frequency band.
    pub robust_vibrations: f64,
    /// Klipper's score with `robustVibrations`.
    pub robust_score: f64,
    /// 1 − score / Klipper pick's score (Klipper's own scoring).
    pub improvement: f64,
}

/// The table of [`optimal`].
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct OptimalReport {
    /// Klipper's pick, the best mainline shaper, and (for a custom-shaper firmware) the best
    /// custom shaper, in that order.
    pub rows: Vec<OptimalRow>,
    /// Index of the recommended row (the custom one for a custom-shaper firmware, else the
    /// mainline one).
    pub recommended: usize,
    /// Plain words on what the optimisation bought.
    pub note: String,
    /// Damping ratios of the robust score.
    pub damping_tested: Vec<f64>,
    /// Frequency factors of the robust score of the custom shaper.
    pub frequency_factors: Vec<f64>,
    /// Objective evaluations spent.
    pub evaluations: usize,
}

/// The runs as Klipper scores them, with the evaluation sets.
struct Scorer {
    /// Per run: the bins with PSD above Klipper's threshold (the grid program's cones).
    #[cfg(feature = "solver")]
    runs: Vec<Run>,
    /// (ζ, factor, part of Klipper's own set)
    #[cfg(feature = "solver")]
    cases: Vec<(f64, f64, bool)>,
    /// Per run and distinct frequency factor: the bins prepared for Klipper's chained V
    /// evaluation (`klipper::fit::Prepared`) at that factor's damping ratios, and for each of
    /// them whether it is one of Klipper's own cases.
    groups: Vec<(Prepared, Vec<bool>)>,
    scv: f64,
    evaluations: std::cell::Cell<usize>,
}

/// One run's bins above Klipper's threshold.
#[cfg(feature = "solver")]
struct Run {
    freq: Vec<f64>,
    psd: Vec<f64>,
}

/// Klipper's score from smoothing and R (shaper_calibrate.py `fit_shaper`).
fn score_of(smoothing: f64, r: f64) -> f64 {
    smoothing * (r.powf(1.5) + 0.2 * r + 0.01)
}

/// (own R, robust R, smoothing) of one evaluation.
#[derive(Debug, Clone, Copy)]
struct Eval {
    own_r: f64,
    robust_r: f64,
    smoothing: f64,
}

impl Eval {
    fn own_score(&self) -> f64 {
        score_of(self.smoothing, self.own_r)
    }
    fn robust_score(&self) -> f64 {
        score_of(self.smoothing, self.robust_r)
    }
}

impl Scorer {
    fn new(
        runs: &[(Vec<f64>, Vec<f64>)],
        robust_damping: &[f64],
        factors: &[f64],
        scv: f64,
    ) -> Self {
        let mut cases: Vec<(f64, f64, bool)> = KLIPPER_TEST_DAMPING
            .iter()
            .map(|&z| (z, 1.0, true))
            .collect();
        for &z in robust_damping {
            for &s in factors {
                if !cases
                    .iter()
                    .any(|c| (c.0 - z).abs() < 1e-12 && (c.1 - s).abs() < 1e-12)
                {
                    cases.push((z, s, false));
                }
            }
        }
        let mut groups = Vec::new();
        for (freq, psd) in runs {
            let mut factors: Vec<f64> = Vec::new();
            for c in &cases {
                if !factors.contains(&c.1) {
                    factors.push(c.1);
                }
            }
            for s in factors {
                let of_s = cases.iter().filter(|c| c.1 == s);
                let tests: Vec<f64> = of_s.clone().map(|c| c.0).collect();
                let own = of_s.map(|c| c.2).collect();
                groups.push((Prepared::from_bins(freq, psd, s, &tests), own));
            }
        }
        Scorer {
            #[cfg(feature = "solver")]
            runs: runs
                .iter()
                .map(|(freq, psd)| {
                    let p_max = psd.iter().copied().fold(0.0, f64::max);
                    let threshold = p_max / super::recommend::SHAPER_VIBRATION_REDUCTION;
                    let (freq, psd) = freq
                        .iter()
                        .zip(psd)
                        .filter(|(_, &p)| p > threshold)
                        .map(|(&f, &p)| (f, p))
                        .unzip();
                    Run { freq, psd }
                })
                .collect(),
            #[cfg(feature = "solver")]
            cases,
            groups,
            scv,
            evaluations: std::cell::Cell::new(0),
        }
    }

    /// Own and robust R and the smoothing of `shaper`; `robust` false skips the robust cases.
    /// R is Klipper's ([`Prepared::remaining`]: V chained over the bins, the bins that cannot
    /// add to R skipped), the largest over the runs and the cases.
    fn eval(&self, shaper: &Shaper, robust: bool) -> Result<Eval> {
        self.evaluations.set(self.evaluations.get() + 1);
        let (mut own_r, mut robust_r) = (0.0_f64, 0.0_f64);
        for (prepared, own) in &self.groups {
            for (t, &own) in own.iter().enumerate() {
                if !own && !robust {
                    continue;
                }
                let r = prepared.remaining(shaper, t);
                if own {
                    own_r = own_r.max(r);
                }
                robust_r = robust_r.max(r);
            }
        }
        let smoothing = smoothing::smoothing(shaper, smoothing::KLIPPER_ACCEL, self.scv)?;
        Ok(Eval {
            own_r,
            robust_r,
            smoothing,
        })
    }
}

/// A mainline candidate.
#[derive(Debug, Clone)]
struct Mainline {
    family: &'static str,
    freq: f64,
    damping_ratio: f64,
    shaper: Shaper,
    eval: Eval,
}

/// The constraints against Klipper's pick.
#[derive(Debug, Clone, Copy)]
struct Bounds {
    /// Klipper's own score may not exceed this.
    score: f64,
    /// Klipper's own R may not exceed this.
    vibrations: f64,
    /// R over the widened set (the measured modes' uncertainty) may not exceed this:
    /// max(Klipper pick's R over that set, 5 %).
    robust_vibrations: f64,
}

impl Bounds {
    fn admits(&self, e: &Eval) -> bool {
        e.own_score() <= self.score * (1.0 + 1e-12)
            && e.own_r <= self.vibrations + 1e-12
            && e.robust_r <= self.robust_vibrations + 1e-12
    }
}

/// Klipper's pick on `data`: `find_best_shaper` of the crate's reproduction, and its shaper.
fn klipper_pick(scorer: &Scorer, data: &CalibrationData, scv: f64) -> Result<Mainline> {
    let fit = find_best_shaper(
        data,
        &FitOptions {
            scv,
            ..FitOptions::default()
        },
    )?;
    let best = fit
        .families
        .get(fit.best)
        .ok_or_else(|| Error::Infeasible {
            reason: "Klipper's fit returned no family".into(),
        })?;
    let shaper = klipper_shaper(best.name, best.pick.freq, fit.damping_ratio)?;
    Ok(Mainline {
        family: best.name,
        freq: best.pick.freq,
        damping_ratio: fit.damping_ratio,
        eval: scorer.eval(&shaper, true)?,
        shaper,
    })
}

/// The best mainline shaper by the robust score under `bounds`; `pick` is the fallback.
fn best_mainline(
    scorer: &Scorer,
    bounds: Bounds,
    pick: &Mainline,
    band: [f64; 2],
) -> Result<Vec<Mainline>> {
    // Per family: the scan's best points (one per damping ratio, the best few overall), each
    // refined by a pattern search; the best refined one is the family's.
    let mut per_family: Vec<Mainline> = Vec::new();
    for def in &KLIPPER_SHAPERS {
        let (name, max_dr) = (def.name, def.max_damping_ratio);
        let mut seeds: Vec<Mainline> = Vec::new();
        for &dr in DAMPING_GRID.iter().filter(|&&d| d <= max_dr) {
            let mut best: Option<Mainline> = None;
            let mut f = band[0];
            while f <= band[1] {
                if let Ok(shaper) = klipper_shaper(name, f, dr) {
                    let e = scorer.eval(&shaper, true)?;
                    if bounds.admits(&e)
                        && best
                            .as_ref()
                            .is_none_or(|b| e.own_score() < b.eval.own_score())
                    {
                        best = Some(Mainline {
                            family: name,
                            freq: f,
                            damping_ratio: dr,
                            shaper,
                            eval: e,
                        });
                    }
                }
                f *= 1.0 + FREQUENCY_STEP;
            }
            seeds.extend(best);
        }
        crate::sort::sort_by(&mut seeds, |a, b| {
            a.eval.own_score().total_cmp(&b.eval.own_score())
        });
        let mut family_best: Option<Mainline> = None;
        for seed in seeds.into_iter().take(REFINED_PER_FAMILY) {
            let r = refine_mainline(scorer, bounds, seed, max_dr)?;
            if family_best
                .as_ref()
                .is_none_or(|b| r.eval.own_score() < b.eval.own_score())
            {
                family_best = Some(r);
            }
        }
        per_family.extend(family_best);
    }
    if pick.eval.own_score().is_finite() {
        per_family.push(pick.clone());
    }
    crate::sort::sort_by(&mut per_family, |a, b| {
        a.eval.own_score().total_cmp(&b.eval.own_score())
    });
    Ok(per_family)
}

/// Pattern search in (log frequency, damping ratio) from `start`.
fn refine_mainline(
    scorer: &Scorer,
    bounds: Bounds,
    start: Mainline,
    max_dr: f64,
) -> Result<Mainline> {
    let mut best = start;
    let (mut df, mut dd) = (0.5 * FREQUENCY_STEP, 0.025);
    for _ in 0..60 {
        let mut improved = false;
        for (sf, sd) in [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)] {
            let f = best.freq * (1.0 + sf * df);
            let dr = (best.damping_ratio + sd * dd).clamp(0.0, max_dr);
            let Ok(shaper) = klipper_shaper(best.family, f, dr) else {
                continue;
            };
            let e = scorer.eval(&shaper, true)?;
            if bounds.admits(&e) && e.own_score() < best.eval.own_score() {
                best = Mainline {
                    family: best.family,
                    freq: f,
                    damping_ratio: dr,
                    shaper,
                    eval: e,
                };
                improved = true;
            }
        }
        if !improved {
            df *= 0.5;
            dd *= 0.5;
            if df < 1e-4 {
                break;
            }
        }
    }
    Ok(best)
}

/// Nelder–Mead (adaptive coefficients, Gao & Han 2012) minimising `f` from `x0` with initial
/// steps `step`; returns the best point and its value.
fn nelder_mead(
    f: &mut dyn FnMut(&[f64]) -> f64,
    x0: &[f64],
    step: &[f64],
    max_evals: usize,
) -> (Vec<f64>, f64) {
    let n = x0.len();
    let nf = n as f64;
    let (alpha, beta, gamma, delta) =
        (1.0, 1.0 + 2.0 / nf, 0.75 - 1.0 / (2.0 * nf), 1.0 - 1.0 / nf);
    let mut simplex: Vec<(Vec<f64>, f64)> = Vec::with_capacity(n + 1);
    let f0 = f(x0);
    simplex.push((x0.to_vec(), f0));
    for i in 0..n {
        let mut x = x0.to_vec();
        x[i] += step[i];
        let v = f(&x);
        simplex.push((x, v));
    }
    let mut evals = n + 1;
    while evals < max_evals {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let best = simplex[0].1;
        let worst = simplex[n].1;
        if best.is_finite() && (worst - best).abs() <= 1e-10 * best.abs().max(1e-300) {
            break;
        }
        let mut centroid = vec![0.0; n];
        for (x, _) in &simplex[..n] {
            for (c, xi) in centroid.iter_mut().zip(x) {
                *c += xi / nf;
            }
        }
        let along = |t: f64, from: &[f64]| -> Vec<f64> {
            centroid
                .iter()
                .zip(from)
                .map(|(c, w)| c + t * (c - w))
                .collect()
        };
        let xr = along(alpha, &simplex[n].0);
        let fr = f(&xr);
        evals += 1;
        if fr < simplex[0].1 {
            let xe = along(alpha * beta, &simplex[n].0);
            let fe = f(&xe);
            evals += 1;
            simplex[n] = if fe < fr { (xe, fe) } else { (xr, fr) };
        } else if fr < simplex[n - 1].1 {
            simplex[n] = (xr, fr);
        } else {
            let outside = fr < simplex[n].1;
            let xc = if outside {
                along(alpha * gamma, &simplex[n].0)
            } else {
                along(-gamma, &simplex[n].0)
            };
            let fc = f(&xc);
            evals += 1;
            if (outside && fc <= fr) || (!outside && fc < simplex[n].1) {
                simplex[n] = (xc, fc);
            } else {
                let x_best = simplex[0].0.clone();
                for item in simplex.iter_mut().skip(1) {
                    let x: Vec<f64> = x_best
                        .iter()
                        .zip(&item.0)
                        .map(|(b, xi)| b + delta * (xi - b))
                        .collect();
                    let v = f(&x);
                    *item = (x, v);
                }
                evals += n;
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    let (x, v) = simplex.swap_remove(0);
    (x, v)
}

/// Impulses from the custom parameters: n − 1 log-gaps (× `t_ref`), n amplitude logits. Each
/// amplitude is `floor` plus its softmax share of the rest (1 − n·floor), so every parameter
/// vector gives amplitudes ≥ `floor` summing to 1: the smallest-amplitude rule is built in, and
/// the optimiser can approach it (where the best shapers sit) without meeting a wall.
fn custom_impulses(x: &[f64], n: usize, t_ref: f64, floor: f64) -> Vec<Impulse> {
    let logits = &x[n - 1..];
    let m = logits.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let w: Vec<f64> = logits.iter().map(|l| (l - m).exp()).collect();
    let sum: f64 = w.iter().sum();
    let free = 1.0 - n as f64 * floor;
    let mut t = 0.0;
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        if i > 0 {
            t += x[i - 1].clamp(-30.0, 30.0).exp() * t_ref;
        }
        out.push(Impulse {
            time: t,
            amplitude: floor + free * w[i] / sum,
        });
    }
    out
}

/// Parameters of `shaper` for [`custom_impulses`] (amplitudes normalised; those at or below
/// `floor` start just above it); `None` when n·floor ≥ 1.
fn custom_params(shaper: &Shaper, t_ref: f64, floor: f64) -> Option<Vec<f64>> {
    let imps = shaper.impulses();
    let d = shaper.amplitude_sum();
    let free = 1.0 - imps.len() as f64 * floor;
    if free <= 0.0 {
        return None;
    }
    let mut x = Vec::with_capacity(2 * imps.len() - 1);
    for w in imps.windows(2) {
        x.push(((w[1].time - w[0].time) / t_ref).ln());
    }
    for imp in imps {
        let share = (imp.amplitude / d - floor) / free;
        x.push(share.max(1e-6).ln());
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// A custom result.
struct Custom {
    shaper: Shaper,
    eval: Eval,
}

/// Nelder–Mead over all times and amplitudes of a sequence of `start.len()` impulses, restarted
/// (at most `restarts` times) from its best point with fresh steps while a restart still lowers
/// the score by 0.1 % (a collapsed simplex is Nelder–Mead's usual way of stopping short) and the
/// budget allows.
fn polish_custom(
    scorer: &Scorer,
    bounds: Bounds,
    limits: FirmwareLimits,
    start: &Shaper,
    restarts: usize,
) -> Result<Option<Custom>> {
    let n = start.len();
    if n < 2 || !admissible(limits, start) {
        return Ok(None);
    }
    let floor = custom_floor(limits);
    let t_ref = start.duration() / (n - 1) as f64;
    let Some(mut x) = custom_params(start, t_ref, floor) else {
        return Ok(None);
    };
    let mut objective = |x: &[f64]| -> f64 {
        let Ok(s) = Shaper::new(custom_impulses(x, n, t_ref, floor)) else {
            return f64::INFINITY;
        };
        if s.len() != n || !admissible(limits, &s) {
            return f64::INFINITY;
        }
        match scorer.eval(&s, true) {
            Ok(e) if bounds.admits(&e) => e.own_score(),
            _ => f64::INFINITY,
        }
    };
    let mut value = f64::INFINITY;
    for round in 0..=restarts {
        if round > 0 && scorer.evaluations.get() + MAX_EVALUATIONS / 2 > CUSTOM_EVALUATION_BUDGET {
            break;
        }
        let step = vec![if round == 0 { 0.1 } else { 0.05 }; x.len()];
        let evals = if round == 0 {
            MAX_EVALUATIONS
        } else {
            MAX_EVALUATIONS / 2
        };
        let (xr, vr) = nelder_mead(&mut objective, &x, &step, evals);
        let gained = vr < 0.999 * value;
        if vr < value {
            (x, value) = (xr, vr);
        }
        if !gained {
            break;
        }
    }
    if !value.is_finite() {
        return Ok(None);
    }
    let shaper = Shaper::new(custom_impulses(&x, n, t_ref, floor))?;
    let eval = scorer.eval(&shaper, true)?;
    Ok((bounds.admits(&eval) && admissible(limits, &shaper)).then_some(Custom { shaper, eval }))
}

/// The smallest custom amplitude: the firmware's, at least [`MIN_CUSTOM_AMPLITUDE`].
fn custom_floor(limits: FirmwareLimits) -> f64 {
    limits.min_amplitude.max(MIN_CUSTOM_AMPLITUDE)
}

/// Whether a firmware with `limits` takes `s` (within [`MAX_CUSTOM_IMPULSES`]).
fn admissible(limits: FirmwareLimits, s: &Shaper) -> bool {
    let imps = s.impulses();
    let d = s.amplitude_sum();
    imps.len() <= limits.max_impulses.min(MAX_CUSTOM_IMPULSES)
        && s.duration() <= limits.max_duration_s
        && (imps.len() == 1 || s.duration() >= limits.min_duration_s)
        && imps
            .iter()
            .all(|i| i.amplitude / d >= custom_floor(limits) * (1.0 - 1e-9))
}

/// `s` with its largest impulse split in two (half the amplitude each, a tenth of the mean gap
/// apart): the start of a run with one impulse more.
fn split_largest(s: &Shaper) -> Result<Shaper> {
    let imps = s.impulses();
    let n = imps.len();
    let gap = s.duration() / (n.max(2) - 1) as f64;
    let k = (0..n)
        .max_by(|&a, &b| imps[a].amplitude.total_cmp(&imps[b].amplitude))
        .unwrap_or(0);
    let mut out = Vec::with_capacity(n + 1);
    for (i, imp) in imps.iter().enumerate() {
        if i == k {
            let half = 0.5 * imp.amplitude;
            let (lo, hi) = if i == 0 {
                (imp.time, imp.time + 0.1 * gap)
            } else if i == n - 1 {
                (imp.time - 0.1 * gap, imp.time)
            } else {
                (imp.time - 0.05 * gap, imp.time + 0.05 * gap)
            };
            out.push(Impulse {
                time: lo,
                amplitude: half,
            });
            out.push(Impulse {
                time: hi,
                amplitude: half,
            });
        } else {
            out.push(*imp);
        }
    }
    Shaper::new(out)
}

/// `s` with an impulse of the smallest admitted amplitude appended half a mean gap after the
/// last (the others scaled to keep Σ A = 1): the start of a run with one impulse more. The
/// bound of the grid program (`no_vibration_bound`) puts its optimum there on the test set: a
/// three-impulse core and a smallest impulse at the end.
fn append_trailing(s: &Shaper, limits: FirmwareLimits) -> Result<Shaper> {
    let imps = s.impulses();
    let n = imps.len();
    let gap = s.duration() / (n.max(2) - 1) as f64;
    let a = custom_floor(limits) * 1.5;
    let d = s.amplitude_sum();
    let mut out: Vec<Impulse> = imps
        .iter()
        .map(|i| Impulse {
            time: i.time,
            amplitude: i.amplitude / d * (1.0 - a),
        })
        .collect();
    out.push(Impulse {
        time: s.duration() + 0.5 * gap,
        amplitude: a,
    });
    Shaper::new(out)
}

/// The best custom shaper: a run from each of the best mainline shapers, then runs with one
/// impulse more from the best so far (its largest impulse split, or a smallest one appended
/// after the last) while that lowers the score by 0.5 % or more.
fn best_custom(
    scorer: &Scorer,
    bounds: Bounds,
    limits: FirmwareLimits,
    starts: &[Mainline],
    method: CustomMethod,
) -> Result<Option<Custom>> {
    if method == CustomMethod::Both {
        // Each method on its own, with its own evaluation budget, the better kept. Run as one
        // path (the grid's starts and the continuation's sharing the growth and the budget) the
        // grid's polished start could take the budget and the growth away from the
        // continuation's own: on a real file (bassco ender3 y, with its modes) `both` scored
        // −4.0 % against Klipper's pick where the continuation alone scored −8.1 %.
        let start = scorer.evaluations.get();
        let continuation = best_custom(scorer, bounds, limits, starts, CustomMethod::Continuation)?;
        let used = scorer.evaluations.get() - start;
        scorer.evaluations.set(start);
        let grid = best_custom(scorer, bounds, limits, starts, CustomMethod::Grid)?;
        scorer.evaluations.set(scorer.evaluations.get() + used);
        return Ok(match (continuation, grid) {
            (Some(a), Some(b)) => Some(if b.eval.own_score() < a.eval.own_score() {
                b
            } else {
                a
            }),
            (a, b) => a.or(b),
        });
    }
    let mut best: Option<Custom> = None;
    let consider = |c: Option<Custom>, best: &mut Option<Custom>| {
        if let Some(c) = c {
            if best
                .as_ref()
                .is_none_or(|b| c.eval.own_score() < b.eval.own_score())
            {
                *best = Some(c);
            }
        }
    };
    if method != CustomMethod::Grid {
        for start in starts.iter().take(CONTINUATION_STARTS) {
            consider(
                polish_custom(scorer, bounds, limits, &start.shaper, 0)?,
                &mut best,
            );
        }
    }
    if method != CustomMethod::Continuation {
        for start in grid_starts(scorer, limits, starts)?.iter().take(2) {
            consider(polish_custom(scorer, bounds, limits, start, 0)?, &mut best);
        }
    }
    while let Some(b) = &best {
        if b.shaper.len() >= limits.max_impulses.min(MAX_CUSTOM_IMPULSES)
            || scorer.evaluations.get() + MAX_EVALUATIONS > CUSTOM_EVALUATION_BUDGET
        {
            break;
        }
        let mut grown: Option<Custom> = None;
        for next in [
            split_largest(&b.shaper)?,
            append_trailing(&b.shaper, limits)?,
        ] {
            if scorer.evaluations.get() + MAX_EVALUATIONS > CUSTOM_EVALUATION_BUDGET {
                break;
            }
            consider(polish_custom(scorer, bounds, limits, &next, 0)?, &mut grown);
        }
        match grown {
            Some(c) if c.eval.own_score() < 0.995 * b.eval.own_score() => best = Some(c),
            _ => break,
        }
    }
    if let Some(b) = &best {
        let again = polish_custom(scorer, bounds, limits, &b.shaper, FINAL_RESTARTS)?;
        consider(again, &mut best);
    }
    Ok(best)
}

/// The grid program's cones of `scorer`: every bin above Klipper's threshold with its bound on
/// V (threshold / PSD), for every scored case.
#[cfg(feature = "solver")]
fn cones_of(scorer: &Scorer) -> grid::Cones {
    let mut bins = Vec::new();
    for run in &scorer.runs {
        let p_max = run.psd.iter().copied().fold(0.0, f64::max);
        let threshold = p_max / super::recommend::SHAPER_VIBRATION_REDUCTION;
        bins.extend(
            run.freq
                .iter()
                .zip(&run.psd)
                .map(|(&f, &p)| (f, threshold / p)),
        );
    }
    grid::Cones {
        bins,
        cases: scorer.cases.iter().map(|c| (c.0, c.1)).collect(),
    }
}

/// The best Klipper score of any shaper that leaves no remaining vibration (R = 0, by Klipper's
/// own scoring: its three damping ratios, every bin ≤ 200 Hz of every run under the threshold)
/// with its impulses on a time grid (`optimal_grid.rs`, `least_smoothing`: 60 intervals of the
/// duration, duration and centroid swept), positive amplitudes, any number of them, the last
/// carrying at least `last_min`. With R = 0 Klipper's score is 0.01 × smoothing, so this is
/// the floor every R = 0 custom shaper meets (up to the grid's resolution); a shaper with
/// R > 0 pays 0.2 R + R^1.5 against 0.01 and may only beat it by trading a little vibration
/// for less smoothing.
#[cfg(feature = "solver")]
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct NoVibrationBound {
    /// 0.01 × `smoothing`.
    pub score: f64,
    /// The program's least smoothing, mm.
    pub smoothing: f64,
    /// Duration of the best grid, s.
    pub duration_s: f64,
    /// Impulses of its solution after merging clusters (not limited to a firmware's count).
    pub impulses: usize,
    /// Its smallest merged amplitude.
    pub smallest_amplitude: f64,
}

/// [`NoVibrationBound`] of Klipper's calibration `data` (durations swept from ½ to 3 times
/// Klipper's pick's); `None` when no grid is feasible. Needs the `solver` feature.
#[cfg(feature = "solver")]
pub fn no_vibration_bound(
    data: &CalibrationData,
    scv: f64,
    last_min: f64,
) -> Result<Option<NoVibrationBound>> {
    finite("scv", scv)?;
    finite("lastMin", last_min)?;
    let runs = prepared(data)?;
    let scorer = Scorer::new(&runs, &[], &[1.0], scv);
    let pick = klipper_pick(&scorer, data, scv)?;
    let cones = cones_of(&scorer);
    Ok(
        grid::least_smoothing(&cones, pick.shaper.duration(), scv, last_min).map(
            |(smoothing, duration_s, imps)| NoVibrationBound {
                score: 0.01 * smoothing,
                smoothing,
                duration_s,
                impulses: imps.len(),
                smallest_amplitude: imps
                    .iter()
                    .map(|i| i.amplitude)
                    .fold(f64::INFINITY, f64::min),
            },
        ),
    )
}

/// Starts from the convex grid program around the best mainline shaper's duration.
#[cfg(feature = "solver")]
fn grid_starts(
    scorer: &Scorer,
    limits: FirmwareLimits,
    starts: &[Mainline],
) -> Result<Vec<Shaper>> {
    let Some(first) = starts.first() else {
        return Ok(Vec::new());
    };
    let cones = cones_of(scorer);
    let max_n = limits.max_impulses.min(MAX_CUSTOM_IMPULSES);
    grid::starts(
        &cones,
        first.shaper.duration(),
        scorer.scv,
        limits.min_amplitude.max(MIN_CUSTOM_AMPLITUDE),
        max_n,
    )
}

/// Without the solver the grid method is unavailable.
#[cfg(not(feature = "solver"))]
fn grid_starts(_: &Scorer, _: FirmwareLimits, _: &[Mainline]) -> Result<Vec<Shaper>> {
    Err(Error::Unavailable {
        field: "customMethod".into(),
        reason: "the grid method needs the optimisation solver (Cargo feature `solver`)".into(),
    })
}

/// Each run's bins up to Klipper's 200 Hz on the summed PSD (Klipper's `fit_shaper` input),
/// checked: every run must have a non-zero PSD there.
fn prepared(data: &CalibrationData) -> Result<Vec<(Vec<f64>, Vec<f64>)>> {
    let mut out = Vec::new();
    for run in data.datasets() {
        let psd = run.psd(Channel::Sum).unwrap_or(&[]);
        let n = run
            .freq_bins
            .partition_point(|&f| f <= super::klipper::fit::MAX_FREQ);
        let (f, p) = (
            run.freq_bins[..n].to_vec(),
            psd[..n.min(psd.len())].to_vec(),
        );
        if p.iter().all(|&x| x == 0.0) {
            return Err(Error::invalid(
                "spectrum.psd",
                format!(
                    "run '{}' is zero everywhere up to 200 Hz: nothing to shape",
                    run.name
                ),
            ));
        }
        out.push((f, p));
    }
    Ok(out)
}

/// Klipper's own figures of `shaper` on `data`, by the crate's reproduction
/// ([`klipper_figures_on`]: R over 0.075 / 0.1 / 0.15 and the runs, bins ≤ 200 Hz).
fn own_figures(shaper: &Shaper, data: &CalibrationData, scv: f64) -> Result<Figures> {
    let f = klipper_figures_on(shaper, data, None, scv, None, Channel::Sum)?;
    Ok(Figures {
        vibrations: f.vibrations,
        smoothing: f.smoothing,
        max_accel: f.max_accel,
        score: f.score,
    })
}

/// Whether a mode can contribute to Klipper's remaining vibration R on `runs` (the PSDs
/// Klipper scores): R sums max(V·P − P_max/20, 0) over the bins, so a bin whose P is at most
/// P_max/20 adds 0 whatever V is (V ≤ 1 for positive impulses). A mode counts when a bin
/// within its half-power band f·(1 ± ζ), widened to at least one bin each side, stands above
/// that threshold in some run. A weak mode (a small peak on a real spectrum, often fitted with
/// a wide uncertainty) cannot change R, so its uncertainty must not widen the robust score.
fn mode_reaches_threshold(runs: &[(Vec<f64>, Vec<f64>)], m: &MeasuredMode) -> bool {
    runs.iter().any(|(freq, psd)| {
        let p_max = psd.iter().copied().fold(0.0, f64::max);
        let threshold = p_max / super::recommend::SHAPER_VIBRATION_REDUCTION;
        let step = if freq.len() > 1 {
            (freq[freq.len() - 1] - freq[0]) / (freq.len() - 1) as f64
        } else {
            0.0
        };
        let half = (m.damping * m.frequency_hz).max(step);
        freq.iter()
            .zip(psd)
            .any(|(&f, &p)| (f - m.frequency_hz).abs() <= half && p > threshold)
    })
}

/// The robust score's damping ratios (Klipper's three, and ζ − kσ, ζ, ζ + kσ of every mode
/// that can contribute to R on `runs` ([`mode_reaches_threshold`]), sorted, deduplicated) and
/// frequency factors (for the mainline search: 1 ± kσ_f/f of those modes when they carry a
/// frequency uncertainty, else 1 alone; for the custom search: the same band, at least
/// [`DEFAULT_FREQUENCY_BAND`]). Every mode is validated; errors name the bad mode
/// (`modes[i]…`).
fn robust_sets(
    modes: &[MeasuredMode],
    k: f64,
    runs: &[(Vec<f64>, Vec<f64>)],
) -> Result<(Vec<f64>, Vec<f64>, Vec<f64>)> {
    count("modes", modes.len(), 0, super::identify::MAX_MODES)?;
    let mut damping: Vec<f64> = KLIPPER_TEST_DAMPING.to_vec();
    let mut rel_f: f64 = 0.0;
    for (i, m) in modes.iter().enumerate() {
        let at = |e: Error| e.within(&format!("modes[{i}]"));
        crate::mode::Mode::new(m.frequency_hz, m.damping).map_err(at)?;
        finite("frequencyUncertaintyHz", m.frequency_uncertainty_hz).map_err(at)?;
        finite("dampingUncertainty", m.damping_uncertainty).map_err(at)?;
        if !mode_reaches_threshold(runs, m) {
            continue;
        }
        let s = k * m.damping_uncertainty.abs();
        for z in [m.damping - s, m.damping, m.damping + s] {
            damping.push(z.clamp(0.0, 0.95));
        }
        rel_f = rel_f.max(k * m.frequency_uncertainty_hz.abs() / m.frequency_hz);
    }
    damping.sort_by(f64::total_cmp);
    damping.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    let mainline_factors = if rel_f > 0.0 {
        let d = rel_f.min(0.5);
        vec![1.0 - d, 1.0, 1.0 + d]
    } else {
        vec![1.0]
    };
    let d = rel_f.clamp(DEFAULT_FREQUENCY_BAND, 0.5);
    Ok((damping, mainline_factors, vec![1.0 - d, 1.0, 1.0 + d]))
}

/// The best custom shaper within `limits` on `custom_scorer` (the robust score with the
/// custom frequency band), started from the `mainlines` (best first); the best mainline shaper
/// when no custom one is admissible.
fn custom_for(
    custom_scorer: &Scorer,
    limits: FirmwareLimits,
    mainlines: &[Mainline],
    bounds: Bounds,
    pick_robust_r: f64,
    options: &OptimalOptions,
) -> Result<Shaper> {
    let starts: Vec<Mainline> = mainlines
        .iter()
        .map(|m| -> Result<Mainline> {
            Ok(Mainline {
                eval: custom_scorer.eval(&m.shaper, true)?,
                ..m.clone()
            })
        })
        .collect::<Result<_>>()?;
    let main = &mainlines[0];
    let custom_bounds = Bounds {
        score: bounds.score.min(main.eval.own_score()),
        vibrations: bounds.vibrations,
        robust_vibrations: pick_robust_r.max(VIBRATION_ALLOWANCE),
    };
    let custom = best_custom(
        custom_scorer,
        custom_bounds,
        limits,
        &starts,
        options.custom_method,
    )?;
    Ok(custom.map_or_else(|| main.shaper.clone(), |c| c.shaper))
}

/// The note's sentence on the custom shaper: plainly a small gain below [`SMALL_GAIN`].
fn custom_note(gain_over_main: f64, improvement: f64) -> String {
    if gain_over_main < SMALL_GAIN {
        format!(
            " The custom shaper buys little: {:.1} % lower score than the best mainline \
             shaper; the mainline one is as good in practice.",
            100.0 * gain_over_main
        )
    } else {
        format!(
            " The custom shaper scores a further {:.1} % lower ({:.1} % below Klipper's pick).",
            100.0 * gain_over_main,
            100.0 * improvement
        )
    }
}

/// Klipper's pick, the best mainline-Klipper shaper and (for a custom-shaper firmware) the best
/// custom shaper for Klipper's calibration `data` (normalised as Klipper scores it: see
/// [`CalibrationData::normalize_to_frequencies`]; several runs are pessimised over, as Klipper
/// does), with the robust score widened by `modes` (may be empty: Klipper's damping set then).
/// See the module docs.
///
/// Errors: a run whose PSD is zero up to 200 Hz, a bad mode (`modes[i]…`),
/// `uncertaintySigmas` outside [0, 10], Klipper's fit's errors.
pub fn optimal(
    data: &CalibrationData,
    modes: &[MeasuredMode],
    options: &OptimalOptions,
) -> Result<OptimalReport> {
    let runs = prepared(data)?;
    let k = options.uncertainty_sigmas;
    if !(0.0..=10.0).contains(&k) {
        return Err(Error::invalid(
            "uncertaintySigmas",
            format!("must lie in [0, 10], got {k}"),
        ));
    }
    finite("scv", options.scv)?;
    let (damping, mainline_factors, custom_factors) = robust_sets(modes, k, &runs)?;

    let scorer = Scorer::new(&runs, &damping, &mainline_factors, options.scv);
    let pick = klipper_pick(&scorer, data, options.scv)?;
    let bounds = Bounds {
        score: pick.eval.own_score(),
        vibrations: pick.eval.own_r.max(VIBRATION_ALLOWANCE),
        robust_vibrations: pick.eval.robust_r.max(VIBRATION_ALLOWANCE),
    };
    let band = [5.0, super::klipper::fit::MAX_SHAPER_FREQ];
    let mainlines = best_mainline(&scorer, bounds, &pick, band)?;
    let main = mainlines[0].clone();

    let row_of = |kind: &'static str, m: &Mainline| -> Result<OptimalRow> {
        let e = scorer.eval(&m.shaper, true)?;
        let fig = own_figures(&m.shaper, data, options.scv)?;
        Ok(OptimalRow {
            kind,
            family: m.family.to_string(),
            shaper_freq_hz: Some(m.freq),
            damping_ratio: Some(m.damping_ratio),
            shaper: m.shaper.to_data(),
            klipper: fig,
            robust_vibrations: e.robust_r,
            robust_score: e.robust_score(),
            improvement: 1.0 - fig.score / bounds.score,
        })
    };
    let mut rows = vec![row_of("klipper", &pick)?, row_of("mainline", &main)?];
    let mut recommended = 1;
    let main_gain = rows[1].improvement;
    let mut note = format!(
        "The best mainline-Klipper shaper ({} at {:.2} Hz, damping_ratio {:.3}) scores {:.1} % \
         lower than Klipper's pick by Klipper's own score.",
        main.family,
        main.freq,
        main.damping_ratio,
        100.0 * main_gain
    );
    if let Some(limits) = options.firmware.limits() {
        let custom_scorer = Scorer::new(&runs, &damping, &custom_factors, options.scv);
        let pick_robust_r = custom_scorer.eval(&pick.shaper, true)?.robust_r;
        let shaper = custom_for(
            &custom_scorer,
            limits,
            &mainlines,
            bounds,
            pick_robust_r,
            options,
        )?;
        scorer
            .evaluations
            .set(scorer.evaluations.get() + custom_scorer.evaluations.get());
        let e = scorer.eval(&shaper, true)?;
        let fig = own_figures(&shaper, data, options.scv)?;
        let gain_over_main = 1.0 - fig.score / rows[1].klipper.score;
        rows.push(OptimalRow {
            kind: "custom",
            family: "custom".into(),
            shaper_freq_hz: None,
            damping_ratio: None,
            shaper: shaper.to_data(),
            klipper: fig,
            robust_vibrations: e.robust_r,
            robust_score: e.robust_score(),
            improvement: 1.0 - fig.score / bounds.score,
        });
        recommended = 2;
        note.push_str(&custom_note(gain_over_main, rows[2].improvement));
    }
    Ok(OptimalReport {
        rows,
        recommended,
        note,
        damping_tested: damping,
        frequency_factors: custom_factors,
        evaluations: scorer.evaluations.get(),
    })
}

/// `criterion: "optimal"` of [`super::recommend::recommend`]: the measured `spectrum` read as
/// Klipper reads it ([`super::recommend::calibration_data`]: its runs, normalised unless it
/// says it is), [`optimal`] run for `options.firmware`, and
/// its table as the ranked candidates: the recommended one (custom for a custom-shaper
/// firmware, else the best mainline one) first, then the others by Klipper's score. Each
/// candidate's `spec` is its impulse sequence (`custom`), `remainingVibration` and
/// `klipperScore` Klipper's own, `nominalRemainingVibration` the robust R.
pub fn recommend_optimal(
    spectrum: &MeasuredSpectrum,
    modes: &[MeasuredMode],
    options: &super::recommend::RecommendOptions,
) -> Result<super::recommend::Recommendation> {
    use super::recommend::{Candidate, Criterion, Recommendation};
    let data = super::recommend::calibration_data(spectrum)?;
    let report = optimal(
        &data,
        modes,
        &OptimalOptions {
            firmware: options.firmware,
            uncertainty_sigmas: options.uncertainty_sigmas,
            scv: options.scv,
            custom_method: CustomMethod::Continuation,
        },
    )?;
    let vmax = options.max_remaining_vibration;
    let mut order: Vec<usize> = (0..report.rows.len()).collect();
    order.sort_by(|&a, &b| {
        (b == report.recommended)
            .cmp(&(a == report.recommended))
            .then(
                report.rows[a]
                    .klipper
                    .score
                    .total_cmp(&report.rows[b].klipper.score),
            )
    });
    let ranked = order
        .iter()
        .map(|&i| {
            let row = &report.rows[i];
            let family = super::klipper::shaper_def(&row.family).map_or("custom", |d| d.name);
            let label = match (row.kind, row.shaper_freq_hz, row.damping_ratio) {
                ("klipper", Some(f), _) => format!("{family} {f:.1} Hz (Klipper's pick)"),
                (_, Some(f), Some(z)) => format!("{family} {f:.2} Hz, damping_ratio {z:.3}"),
                _ => format!("custom, {} impulses", row.shaper.impulses.len()),
            };
            Candidate {
                label,
                family,
                spec: crate::design::ShaperSpec::Custom {
                    impulses: row.shaper.impulses.clone(),
                    normalize: false,
                },
                // A family row is designed for its `shaper_freq` at its `damping_ratio`, as the
                // `klipper` criterion's rows are; a custom sequence for no single mode.
                modes: match (row.shaper_freq_hz, row.damping_ratio) {
                    (Some(frequency_hz), Some(damping)) => vec![crate::mode::ModeSpec {
                        frequency_hz,
                        damping,
                    }],
                    _ => Vec::new(),
                },
                duration_s: row.shaper.duration,
                shaper: row.shaper.clone(),
                remaining_vibration: row.klipper.vibrations,
                nominal_remaining_vibration: row.robust_vibrations,
                smoothing: Some(row.klipper.smoothing),
                max_accel: Some(row.klipper.max_accel).filter(|a| a.is_finite()),
                klipper_score: Some(row.klipper.score),
                acceptable: row.klipper.vibrations <= vmax,
                kind: Some(row.kind),
            }
        })
        .collect();
    Ok(Recommendation {
        criterion: Criterion::Optimal,
        recommended: 0,
        ranked,
        skipped: Vec::new(),
        damping_tested: report.damping_tested,
        frequency_factors: report.frequency_factors,
        band_hz: [0.0, super::klipper::fit::MAX_FREQ],
        klipper: None,
        note: Some(report.note),
    })
}
