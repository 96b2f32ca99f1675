//! The numerical machinery the solved families share: the shortest shaper that meets a set of
//! vibration constraints.
//!
//! A family states its constraints as a [`Problem`]: zero vibration (with zero frequency
//! derivatives) at some modes, V ≤ Vtol at sampled (frequency, damping) points, and V ≤ Vtol(f)
//! over whole bands of frequency and damping. [`minimum_duration`] then
//!
//! 1. **grid + bisection** (`grid.rs`): for a candidate duration T it places impulses on a fine
//!    grid of times in [0, T] and solves a convex program for the amplitudes (linear
//!    constraints and second-order cones, Clarabel); the shortest feasible T is found by
//!    bisection. For a fixed grid this is the global optimum, so the result is the globally
//!    shortest shaper up to the grid spacing, whatever its number of impulses;
//! 2. **reduction**: neighbouring grid impulses are merged into the few impulses the solution
//!    really uses;
//! 3. **polish** (`polish.rs`): the times and amplitudes of those impulses (and the frequencies
//!    of the sensitivity humps that touch Vtol) are refined by Newton's method on the active
//!    constraints with the shortest duration as objective (a reduced-Hessian SQP), so the
//!    result is exact, not grid-limited;
//! 4. **guarantee** (`scan.rs`): the result is checked at every sampled point and on a dense
//!    grid over every band (local maxima refined); where a band is exceeded the offending points
//!    are added to the program's constraints and the design is repeated (an exchange, or
//!    cutting-plane, loop) until the guarantee holds.
//!
//! Internally everything is non-dimensional: times in periods of the highest frequency of the
//! problem, so the numbers stay O(1) for any mode from millihertz to megahertz. Every iteration
//! is bounded (see the constants below).

// Built without the solver (Cargo feature `solver`), the driver below is cut off after the
// problem's checks: the programs, the polish and the scans are then unused.
#![cfg_attr(not(feature = "solver"), allow(dead_code, unused_imports))]

pub(crate) mod grid;
pub(crate) mod polish;
pub(crate) mod scan;
pub(crate) mod vertex;

use crate::error::{finite, Error, Result};
use crate::shaper::{Impulse, Shaper};
use crate::vibration::vibration_rad;
use std::f64::consts::PI;

/// Grid points per period of the highest frequency of the problem.
const POINTS_PER_CYCLE: f64 = 16.0;
/// Fewest grid intervals on [0, T].
const MIN_POINTS: usize = 24;
/// Longest duration the grid can represent, in periods of the highest frequency (keeps the
/// program at most `POINTS_PER_CYCLE × MAX_CYCLES` amplitudes).
pub const MAX_CYCLES: f64 = 40.0;
/// Most rounds of the exchange loop (adding band points where the bound is exceeded).
const MAX_EXCHANGE_ROUNDS: usize = 8;
/// Most times the grid is refined around the solution's impulses when the polish fails.
const MAX_REFINEMENTS: usize = 2;
/// Refined points per cluster on each side of its centre, and how much finer they are.
const REFINE_POINTS: i32 = 6;
const REFINE_FACTOR: f64 = 4.0;
/// Most convex programs one bisection may solve.
const MAX_PROGRAMS: usize = 60;
/// Relative slack by which a grid solution must beat Vtol to count as feasible.
const FEASIBILITY_MARGIN: f64 = 1e-6;
/// A grid solution's noise level ([`zero_level`]) lies in a gap of at least this ratio …
const ZERO_GAP: f64 = 10.0;
/// … whose lower side is at most this fraction of the largest amplitude.
const ZERO_CEILING: f64 = 1e-3;
/// Relative excess over Vtol tolerated when checking a result (rounding).
pub const CHECK_TOLERANCE: f64 = 1e-9;
/// Largest zero-vibration moment (scaled by t_nᵏ) accepted as zero.
pub const ZERO_TOLERANCE: f64 = 1e-9;

/// Most points a Vtol profile may have.
pub const MAX_PROFILE_POINTS: usize = 1000;

/// A tolerable-vibration level that may vary with frequency: piecewise linear through
/// `(frequency in Hz, Vtol)` points, constant beyond the first and last.
#[derive(Debug, Clone, PartialEq)]
pub struct Tolerance {
    points: Vec<(f64, f64)>,
}

impl Tolerance {
    /// The same Vtol at every frequency.
    pub fn constant(vtol: f64) -> Result<Self> {
        Tolerance::profile(vec![(0.0, vtol)])
    }

    /// Vtol linear between the given `(frequency in Hz, Vtol)` points (sorted by frequency,
    /// distinct), constant outside them. Each Vtol must lie in (0, 1) and be a normal number
    /// (at least 2.2·10⁻³⁰⁸).
    pub fn profile(points: Vec<(f64, f64)>) -> Result<Self> {
        if points.is_empty() {
            return Err(Error::invalid("vtolProfile", "give at least one point"));
        }
        crate::error::count("vtolProfile", points.len(), 1, MAX_PROFILE_POINTS)?;
        for (i, &(f, v)) in points.iter().enumerate() {
            finite(&format!("vtolProfile[{i}][0]"), f)?;
            finite(&format!("vtolProfile[{i}][1]"), v)?;
            if f < 0.0 {
                return Err(Error::invalid(
                    format!("vtolProfile[{i}][0]"),
                    format!("frequency must be ≥ 0 Hz, got {f}"),
                ));
            }
            if !tolerable(v) {
                return Err(Error::invalid(
                    format!("vtolProfile[{i}][1]"),
                    format!("tolerable vibration must lie in (0, 1), got {}", shown(v)),
                ));
            }
            if i > 0 && f <= points[i - 1].0 {
                return Err(Error::invalid(
                    format!("vtolProfile[{i}][0]"),
                    "frequencies must be strictly increasing",
                ));
            }
        }
        Ok(Tolerance { points })
    }

    /// Vtol at `frequency_hz`.
    pub fn at(&self, frequency_hz: f64) -> f64 {
        let pts = &self.points;
        let (first, last) = (pts[0], pts[pts.len() - 1]);
        if frequency_hz <= first.0 {
            return first.1;
        }
        if frequency_hz >= last.0 {
            return last.1;
        }
        for w in pts.windows(2) {
            let ((f0, v0), (f1, v1)) = (w[0], w[1]);
            if frequency_hz <= f1 {
                return v0 + (v1 - v0) * (frequency_hz - f0) / (f1 - f0);
            }
        }
        last.1
    }

    /// The smallest Vtol anywhere.
    pub fn min(&self) -> f64 {
        self.points
            .iter()
            .map(|p| p.1)
            .fold(f64::INFINITY, f64::min)
    }

    fn scaled(&self, f_ref: f64) -> Vec<(f64, f64)> {
        self.points.iter().map(|&(f, v)| (f / f_ref, v)).collect()
    }
}

/// A tolerable vibration the solver can work with: in (0, 1) and a normal number. A subnormal
/// one (under 2.2·10⁻³⁰⁸) has no finite reciprocal, and the constraints scaled by it were
/// infinite: `minimum_duration` never returned (the 10⁶-case property run, 2026-12-06:
/// Vtol 10⁻³¹⁰ at one sample; 10⁻³⁰⁰ ends at once as infeasible).
fn tolerable(v: f64) -> bool {
    (f64::MIN_POSITIVE..1.0).contains(&v)
}

/// A refused Vtol as the error shows it: a subnormal one in e-notation, with the reason.
fn shown(v: f64) -> String {
    if v > 0.0 && v < f64::MIN_POSITIVE {
        format!("{v:e} (a subnormal number: give at least 2.2e-308)")
    } else {
        format!("{v}")
    }
}

/// Zero vibration and `derivatives` zero frequency derivatives at a mode (the ZV/ZVD/ZV-Dⁿ
/// constraints of Singer & Seering 1988, imposed as vanishing moments).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZeroVibration {
    /// Undamped natural frequency in Hz.
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping: f64,
    /// Number of zero derivatives (0 = ZV, 1 = ZVD, …).
    pub derivatives: u32,
}

/// V ≤ `vtol` at one (frequency, damping) point (Singhose 2009 eq. 18).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limit {
    /// Frequency in Hz.
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping: f64,
    /// Tolerable vibration (fraction).
    pub vtol: f64,
}

/// V ≤ Vtol(f) everywhere on a band of frequencies and damping ratios.
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    /// Lowest frequency in Hz.
    pub from_hz: f64,
    /// Highest frequency in Hz.
    pub to_hz: f64,
    /// Lowest damping ratio.
    pub damping_from: f64,
    /// Highest damping ratio (equal to `damping_from` for a single damping).
    pub damping_to: f64,
    /// Tolerable vibration over the band.
    pub tolerance: Tolerance,
}

/// The constraints of a minimum-duration design.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// Modes with zero vibration (and derivatives).
    pub zeros: Vec<ZeroVibration>,
    /// Sampled vibration limits.
    pub limits: Vec<Limit>,
    /// Bands where the vibration limit must hold everywhere.
    pub bands: Vec<Band>,
    /// Smallest amplitude allowed (0 for positive shapers, e.g. −1 for negative ones).
    pub amplitude_min: f64,
    /// Largest amplitude allowed.
    pub amplitude_max: f64,
    /// Longest duration accepted, in seconds (`None`: up to [`MAX_CYCLES`] periods of the
    /// highest frequency).
    pub max_duration: Option<f64>,
}

/// A point at which a design was checked: (frequency in Hz, damping ratio, Vtol there).
pub type CheckedPoint = (f64, f64, f64);

/// How the optimisation solver reached a design: the part of [`Design`] a caller of
/// [`crate::design::design_report`] sees (JS: `design(spec).solver`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "camelCase")]
pub struct SolverReport {
    /// Whether the Newton polish converged: the shaper is then exact and locally optimal.
    /// Otherwise it is the grid solution: it meets every constraint, but it is up to a grid
    /// step longer than the optimum and its impulses are the grid's (often many).
    pub polished: bool,
    /// Rounds of the exchange loop (1 when the first design already met every band).
    pub rounds: usize,
    /// Convex programs solved.
    pub programs: usize,
}

/// The result of [`minimum_duration`].
#[derive(Debug, Clone)]
pub struct Design {
    /// The shaper (times in seconds).
    pub shaper: Shaper,
    /// Whether the Newton polish converged (the result is then exact and locally optimal;
    /// otherwise it is the grid solution, feasible but up to a grid step longer).
    pub polished: bool,
    /// Every point where V was checked against its Vtol (sampled limits, and the dense grid
    /// and refined maxima over each band).
    pub checked: Vec<CheckedPoint>,
    /// Convex programs solved.
    pub programs: usize,
    /// Rounds of the exchange loop (1 when the first design already met every band).
    pub rounds: usize,
}

impl Design {
    /// What the caller of a solved family sees of the design ([`SolverReport`]).
    pub fn report(&self) -> SolverReport {
        SolverReport {
            polished: self.polished,
            rounds: self.rounds,
            programs: self.programs,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Non-dimensional form

/// A zero-vibration constraint in normalized units (ω in rad per normalized time unit).
#[derive(Debug, Clone, Copy)]
pub(crate) struct NormalizedZero {
    pub omega: f64,
    pub zeta: f64,
    pub derivatives: u32,
}

/// A vibration limit in normalized units.
#[derive(Debug, Clone, Copy)]
pub(crate) struct NormalizedLimit {
    pub omega: f64,
    pub zeta: f64,
    pub vtol: f64,
}

/// A band in normalized units; Vtol is piecewise linear in ω.
#[derive(Debug, Clone)]
pub(crate) struct NormalizedBand {
    pub omega_lo: f64,
    pub omega_hi: f64,
    pub zeta_lo: f64,
    pub zeta_hi: f64,
    /// (ω, Vtol) points.
    pub tolerance: Vec<(f64, f64)>,
}

impl NormalizedBand {
    pub fn vtol(&self, omega: f64) -> f64 {
        let pts = &self.tolerance;
        let (first, last) = (pts[0], pts[pts.len() - 1]);
        if omega <= first.0 {
            return first.1;
        }
        if omega >= last.0 {
            return last.1;
        }
        for w in pts.windows(2) {
            let ((w0, v0), (w1, v1)) = (w[0], w[1]);
            if omega <= w1 {
                return v0 + (v1 - v0) * (omega - w0) / (w1 - w0);
            }
        }
        last.1
    }
}

/// The problem with times in periods of `f_ref` (the highest frequency) and ω = 2πf/f_ref.
#[derive(Debug, Clone)]
pub(crate) struct NormalizedProblem {
    pub f_ref: f64,
    pub zeros: Vec<NormalizedZero>,
    pub limits: Vec<NormalizedLimit>,
    pub bands: Vec<NormalizedBand>,
    pub amplitude_min: f64,
    pub amplitude_max: f64,
    /// Longest duration, normalized.
    pub max_duration: f64,
    /// Lowest constrained ω.
    pub omega_min: f64,
}

fn check_damping(field: &str, zeta: f64) -> Result<()> {
    crate::vibration::damping_ratio(field, zeta).map(|_| ())
}

fn check_frequency(field: &str, f: f64) -> Result<()> {
    finite(field, f)?;
    if !(crate::mode::MIN_FREQUENCY_HZ..=crate::mode::MAX_FREQUENCY_HZ).contains(&f) {
        return Err(Error::invalid(
            field,
            format!(
                "must lie between {} and {} Hz, got {f}",
                crate::mode::MIN_FREQUENCY_HZ,
                crate::mode::MAX_FREQUENCY_HZ
            ),
        ));
    }
    Ok(())
}

/// Most zero-vibration constraints (modes) a problem may have.
pub const MAX_ZEROS: usize = crate::mode::MAX_MODES;
/// Most zero derivatives per mode (each adds two equality rows per derivative); the direct
/// family's `derivatives` limit (`design::direct::MAX_DIRECT_DERIVATIVES`) is this one.
pub const MAX_ZERO_DERIVATIVES: u32 = 4;
/// Most sampled limits (200 frequencies at up to 64 damping ratios).
pub const MAX_LIMITS: usize = 200 * crate::mode::MAX_MODES;
/// Most bands.
pub const MAX_BANDS: usize = crate::mode::MAX_MODES;

impl NormalizedProblem {
    /// The most any amplitude of `n` can be when they sum to 1 and none is below amplitudeMin:
    /// 1 − (n − 1)·min(amplitudeMin, 0). An amplitudeMax at or above it cannot bind.
    pub(crate) fn amplitude_reach(&self, n: usize) -> f64 {
        1.0 - n.saturating_sub(1) as f64 * self.amplitude_min.min(0.0)
    }

    /// Whether amplitudeMax can bind on `n` amplitudes (is below [`Self::amplitude_reach`]):
    /// only then is it a row of the grid program.
    pub(crate) fn upper_bound_binds(&self, n: usize) -> bool {
        self.amplitude_max < self.amplitude_reach(n)
    }

    /// The scale of the amplitude bounds for `n` amplitudes, for tolerances and for telling an
    /// amplitude near a bound: amplitudeMax − amplitudeMin with amplitudeMax taken at most
    /// [`Self::amplitude_reach`] (a larger bound, up to `amplitudeMax: 1e12`, binds nothing and
    /// must not widen the tolerances).
    pub(crate) fn amplitude_range(&self, n: usize) -> f64 {
        self.amplitude_max.min(self.amplitude_reach(n)) - self.amplitude_min
    }

    fn new(p: &Problem) -> Result<Self> {
        check_sizes(p)?;
        check_amplitudes(p)?;
        let (f_ref, f_min) = frequency_span(p)?;
        let w = |f: f64| 2.0 * PI * f / f_ref;
        let max_duration = match p.max_duration {
            Some(d) => {
                crate::error::positive("maxDuration", d)?;
                (d * f_ref).min(MAX_CYCLES)
            }
            None => MAX_CYCLES,
        };
        Ok(NormalizedProblem {
            f_ref,
            zeros: p
                .zeros
                .iter()
                .map(|z| NormalizedZero {
                    omega: w(z.frequency_hz),
                    zeta: z.damping,
                    derivatives: z.derivatives,
                })
                .collect(),
            limits: p
                .limits
                .iter()
                .map(|l| NormalizedLimit {
                    omega: w(l.frequency_hz),
                    zeta: l.damping,
                    vtol: l.vtol,
                })
                .collect(),
            bands: p
                .bands
                .iter()
                .map(|b| NormalizedBand {
                    omega_lo: w(b.from_hz),
                    omega_hi: w(b.to_hz),
                    zeta_lo: b.damping_from,
                    zeta_hi: b.damping_to,
                    tolerance: b
                        .tolerance
                        .scaled(f_ref)
                        .into_iter()
                        .map(|(f, v)| (2.0 * PI * f, v))
                        .collect(),
                })
                .collect(),
            amplitude_min: p.amplitude_min,
            amplitude_max: p.amplitude_max,
            max_duration,
            omega_min: w(f_min),
        })
    }

    /// A shaper in normalized units back in seconds.
    fn to_seconds(&self, impulses: &[Impulse]) -> Result<Shaper> {
        Shaper::new(
            impulses
                .iter()
                .map(|imp| Impulse {
                    time: imp.time / self.f_ref,
                    amplitude: imp.amplitude,
                })
                .collect(),
        )
    }
}

/// Sizes first, so nothing below (or in the programs) grows without bound.
fn check_sizes(p: &Problem) -> Result<()> {
    crate::error::count("modes", p.zeros.len(), 0, MAX_ZEROS)?;
    crate::error::count("sampleFrequenciesHz", p.limits.len(), 0, MAX_LIMITS)?;
    crate::error::count("bands", p.bands.len(), 0, MAX_BANDS)?;
    for z in &p.zeros {
        if z.derivatives > MAX_ZERO_DERIVATIVES {
            return Err(Error::TooLarge {
                field: "derivatives".into(),
                value: f64::from(z.derivatives),
                limit: f64::from(MAX_ZERO_DERIVATIVES),
            });
        }
    }
    Ok(())
}

/// The amplitude bounds: finite, amplitudeMin < amplitudeMax, amplitudeMax > 0 and
/// amplitudeMin ≤ 1 (else Σ A = 1 is out of reach).
fn check_amplitudes(p: &Problem) -> Result<()> {
    finite("amplitudeMin", p.amplitude_min)?;
    finite("amplitudeMax", p.amplitude_max)?;
    if p.amplitude_max <= 0.0 || p.amplitude_min >= p.amplitude_max || p.amplitude_min > 1.0 {
        return Err(Error::invalid(
            "amplitudeMax",
            format!(
                "need amplitudeMin < amplitudeMax, amplitudeMax > 0 and amplitudeMin ≤ 1, got \
                 [{}, {}]",
                p.amplitude_min, p.amplitude_max
            ),
        ));
    }
    Ok(())
}

/// Checks every constraint's frequencies, damping ratios and tolerances, and returns the
/// highest and lowest constrained frequencies (Hz); an error if there is no constraint.
fn frequency_span(p: &Problem) -> Result<(f64, f64)> {
    let mut f_ref: f64 = 0.0;
    let mut f_min = f64::INFINITY;
    for (i, z) in p.zeros.iter().enumerate() {
        check_frequency(&format!("modes[{i}].frequencyHz"), z.frequency_hz)?;
        check_damping(&format!("modes[{i}].damping"), z.damping)?;
        f_ref = f_ref.max(z.frequency_hz);
        f_min = f_min.min(z.frequency_hz);
    }
    for l in &p.limits {
        check_frequency("sampleFrequenciesHz", l.frequency_hz)?;
        check_damping("damping", l.damping)?;
        if !tolerable(l.vtol) {
            return Err(Error::invalid(
                "vtol",
                format!("must lie in (0, 1), got {}", shown(l.vtol)),
            ));
        }
        f_ref = f_ref.max(l.frequency_hz);
        f_min = f_min.min(l.frequency_hz);
    }
    for b in &p.bands {
        check_frequency("bandHz[0]", b.from_hz)?;
        check_frequency("bandHz[1]", b.to_hz)?;
        if b.to_hz < b.from_hz {
            return Err(Error::invalid("bandHz", "the band's ends are reversed"));
        }
        check_damping("dampingRange[0]", b.damping_from)?;
        check_damping("dampingRange[1]", b.damping_to)?;
        if b.damping_to < b.damping_from {
            return Err(Error::invalid(
                "dampingRange",
                "the range's ends are reversed",
            ));
        }
        f_ref = f_ref.max(b.to_hz);
        f_min = f_min.min(b.from_hz);
    }
    if f_ref <= 0.0 {
        return Err(Error::invalid(
            "modes",
            "the design has no constraint (no mode, sample or band)",
        ));
    }
    Ok((f_ref, f_min))
}

// ---------------------------------------------------------------------------------------------
// The driver

/// The shortest shaper meeting `problem`'s constraints (see the module docs for the method).
///
/// Errors: [`Error::InvalidInput`] for out-of-range data, [`Error::Infeasible`] when no shaper
/// within the duration limit meets the constraints (with the reason).
///
/// In a build without the Cargo feature `solver` (the page's first wasm module) the problem is
/// still checked, but a valid one is answered with [`Error::Unavailable`].
pub fn minimum_duration(problem: &Problem) -> Result<Design> {
    let norm = NormalizedProblem::new(problem)?;
    shortest(norm)
}

/// Selects the polish as it was before issue 24's speed work (`true`: the four-point Hessian
/// stencil and a fixed null-step cap) or the current one (`false`, the default), process-wide.
/// For benchmarks that time both in one run (`benches/si.rs`); not part of the API.
#[doc(hidden)]
pub fn set_reference_polish(on: bool) {
    polish::set_reference_polish(on);
}

/// Without the solver: nothing below is compiled into the wasm.
#[cfg(not(feature = "solver"))]
fn shortest(_: NormalizedProblem) -> Result<Design> {
    Err(Error::solver_left_out())
}

/// [`minimum_duration`] on the normalised problem: rounds of the exchange loop (grid program,
/// polish, check over the bands), each adding the points where the last design broke a band.
#[cfg(feature = "solver")]
fn shortest(norm: NormalizedProblem) -> Result<Design> {
    let mut samples: Vec<NormalizedLimit> = norm.limits.clone();
    for band in &norm.bands {
        samples.extend(scan::initial_samples(band));
    }
    let mut programs = 0;
    for round in 1..=MAX_EXCHANGE_ROUNDS {
        let mut grid = shortest_on_grid(&norm, &samples, None, &mut programs)?;
        // Neighbouring grid impulses that add up beyond the amplitude bounds mean the grid is
        // emulating impulses the bounds forbid (binding bounds, e.g. negative shapers): no
        // few-impulse structure to polish, and finer grids only emulate more closely.
        let beyond_bounds = clusters(&grid).iter().any(|c| {
            c.amplitude > norm.amplitude_max * (1.0 + 1e-3)
                || c.amplitude < norm.amplitude_min * (1.0 + 1e-3)
        });
        let polished = if beyond_bounds {
            None
        } else {
            polished_grid(&norm, &samples, &mut grid)
        };
        if polished.is_none() && round < MAX_EXCHANGE_ROUNDS {
            // The polish failed. If the grid solution itself exceeds a band between the samples,
            // the samples are too few to fix the structure: add its maxima and start again.
            let violations = grid_violations(&norm, &grid);
            if !violations.is_empty() {
                samples.extend(violations);
                continue;
            }
        }
        let (grid, polished) = if beyond_bounds {
            (grid, polished)
        } else {
            refine(&norm, &samples, grid, polished, &mut programs)?
        };
        let (impulses, polished) = accepted(&norm, &samples, &grid, polished, &mut programs)?;
        let report = scan::check(&norm, &impulses);
        if report.worst_limit > 1.0 + CHECK_TOLERANCE || report.worst_moment > ZERO_TOLERANCE {
            // Not something more samples can fix: the numbers are at their limits.
            return Err(Error::Infeasible {
                reason: format!(
                    "the design could not meet its constraints to rounding (V/Vtol = {:.6} at \
                     the samples, zero-vibration residual {:.2e}): the problem is numerically \
                     too hard (modes too far apart or too many constraints)",
                    report.worst_limit, report.worst_moment
                ),
            });
        }
        if report.violations.is_empty() {
            let shaper = norm.to_seconds(&impulses)?;
            let checked = report
                .checked
                .iter()
                .map(|&(w, z, v)| (w * norm.f_ref / (2.0 * PI), z, v))
                .collect();
            return Ok(Design {
                shaper,
                polished,
                checked,
                programs,
                rounds: round,
            });
        }
        samples.extend(report.violations);
    }
    Err(Error::Infeasible {
        reason: format!(
            "the vibration bound could not be met everywhere on the band after \
             {MAX_EXCHANGE_ROUNDS} rounds of refinement"
        ),
    })
}

/// Where the grid solution itself exceeds a band between the samples (its maxima there).
#[cfg(feature = "solver")]
fn grid_violations(norm: &NormalizedProblem, grid: &GridSolution) -> Vec<NormalizedLimit> {
    scan::check(norm, &grid.impulses()).violations
}

/// While the polish fails (impulses too close for the grid to resolve, a poor start), the
/// grid refined around the impulses the solution uses, solved and polished again, at most
/// [`MAX_REFINEMENTS`] times. Returns the last grid and its polish.
#[cfg(feature = "solver")]
fn refine(
    norm: &NormalizedProblem,
    samples: &[NormalizedLimit],
    mut grid: GridSolution,
    mut polished: Option<Vec<Impulse>>,
    programs: &mut usize,
) -> Result<(GridSolution, Option<Vec<Impulse>>)> {
    for _ in 0..MAX_REFINEMENTS {
        if polished.is_some() {
            break;
        }
        let pattern = refine_pattern(&grid);
        grid = shortest_on_grid(norm, samples, Some((&pattern, grid.duration)), programs)?;
        polished = polished_grid(norm, samples, &mut grid);
    }
    Ok((grid, polished))
}

/// The impulses of the round: the polish if within the amplitude bounds, else the fallback
/// (whether polished is returned too), rescaled to Σ A = 1, and refused (with the reason) if
/// the rescaled amplitudes leave the bounds.
#[cfg(feature = "solver")]
fn accepted(
    norm: &NormalizedProblem,
    samples: &[NormalizedLimit],
    grid: &GridSolution,
    polished: Option<Vec<Impulse>>,
    programs: &mut usize,
) -> Result<(Vec<Impulse>, bool)> {
    // The polish and the fallback's projection solve equalities and may step outside the
    // amplitude bounds (the convergence grid found direct ZVDD designs with amplitudes down
    // to −0.008 at amplitudeMin = 0): a result outside them is not accepted.
    let (mut impulses, polished) = match polished.filter(|p| within_bounds(norm, p)) {
        Some(imps) => (imps, true),
        None => (fallback(norm, samples, grid, programs)?, false),
    };
    // Σ A = 1 only to the polish's Newton tolerance (the convergence grid found SI for four
    // modes at 1 + 1.8e-8): rescale to Σ A = 1 to rounding. Everything after (the bounds,
    // V ≤ Vtol, the zero moments) is checked on the rescaled amplitudes.
    renormalize(&mut impulses);
    if !within_bounds(norm, &impulses) {
        let worst = impulses
            .iter()
            .map(|i| i.amplitude)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), a| {
                (lo.min(a), hi.max(a))
            });
        return Err(Error::Infeasible {
            reason: format!(
                "the design's amplitudes ({:.6} … {:.6}) leave the bounds [{}, {}] when its \
                 constraints are solved exactly: the problem is numerically degenerate here \
                 (modes very close, many derivatives); widen the bounds or drop a derivative",
                worst.0, worst.1, norm.amplitude_min, norm.amplitude_max
            ),
        });
    }
    Ok((impulses, polished))
}

/// The grid solution of the shortest feasible duration.
#[derive(Debug, Clone)]
pub(crate) struct GridSolution {
    /// Grid times (normalized), the last one the duration.
    pub times: Vec<f64>,
    /// Amplitudes at those times.
    pub amplitudes: Vec<f64>,
    /// The duration (the last time).
    pub duration: f64,
}

impl GridSolution {
    /// Every grid point as an impulse (zero amplitudes included).
    pub(crate) fn impulses(&self) -> Vec<Impulse> {
        self.times
            .iter()
            .zip(&self.amplitudes)
            .map(|(&time, &amplitude)| Impulse { time, amplitude })
            .collect()
    }
}

/// Grid intervals for a duration `t` (normalized).
fn grid_intervals(t: f64) -> usize {
    ((POINTS_PER_CYCLE * t).ceil() as usize).max(MIN_POINTS)
}

fn grid_times(t: f64) -> Vec<f64> {
    let n = grid_intervals(t);
    (0..=n).map(|k| t * k as f64 / n as f64).collect()
}

/// One evaluation of the grid program at a duration: its level (V/Vtol reachable; `INFINITY`
/// when the linear constraints cannot be met) and the solution.
struct Probe {
    t: f64,
    level: f64,
    solution: Option<GridSolution>,
}

/// The shortest duration whose grid program is feasible.
///
/// With vibration limits, the program's optimal level s(T) (the smallest common V/Vtol the
/// amplitudes can reach) falls as T grows, and the answer is the first T with s(T) ≤ 1: it is
/// bracketed by stepping T up (or down) by ×1.5 from half a period of the lowest constrained
/// frequency, then found by regula falsi on ln s(T) (Illinois variant; each step also halves
/// the bracket at worst, as bisection would). Without limits (zero-vibration equalities only)
/// feasibility is all there is, and plain bisection is used. Either way it stops once the
/// bracket is below half a grid step, and after at most [`MAX_PROGRAMS`] programs.
fn shortest_on_grid(
    norm: &NormalizedProblem,
    samples: &[NormalizedLimit],
    refined: Option<(&[f64], f64)>,
    programs: &mut usize,
) -> Result<GridSolution> {
    let mut grid = GridPrograms {
        norm,
        samples,
        refined,
        programs,
        solved: 0,
    };
    let (lo, hi) = bracket(&mut grid)?;
    let hi = shrink(&mut grid, lo, hi)?;
    hi.solution.ok_or_else(|| Error::Infeasible {
        reason: infeasible_reason(norm),
    })
}

/// The polish of a grid solution; if it fails where the grid program is a plain LP — no
/// vibration limits, amplitudes ≥ 0 with no upper bound that can bind (the `direct` family's
/// default) — the solution is moved to a vertex of its face with no larger centroid
/// ([`vertex::to_vertex`]: at most one impulse per equality) and polished again. The
/// interior-point solver returns the centre of the optimal face, which is the vertex itself
/// when the optimum is unique (every design that polished before is unchanged: this runs only
/// after a failure); when it is not (six-mode `direct` ZVD), every grid point is positive —
/// 818 impulses after the fallback natively, an error in wasm, where the fallback's program
/// could not reproduce them (issue 24). The grid is left at the vertex for the refinement and
/// the fallback that follow a second failure.
#[cfg(feature = "solver")]
fn polished_grid(
    norm: &NormalizedProblem,
    samples: &[NormalizedLimit],
    grid: &mut GridSolution,
) -> Option<Vec<Impulse>> {
    let polished = polish::polish(norm, grid);
    let n = grid.times.len();
    let lp = samples.is_empty() && norm.amplitude_min == 0.0 && !norm.upper_bound_binds(n);
    if polished.is_some() || !lp || n == 0 {
        return polished;
    }
    let rows = grid::equality_rows(norm, &grid.times);
    let t_end = grid.duration.max(f64::MIN_POSITIVE);
    let centroid: Vec<f64> = grid.times.iter().map(|t| t / t_end).collect();
    vertex::to_vertex(&rows, &centroid, &mut grid.amplitudes);
    polish::polish(norm, grid)
}

/// The grid programs of one [`shortest_on_grid`] search, counted.
struct GridPrograms<'a> {
    norm: &'a NormalizedProblem,
    samples: &'a [NormalizedLimit],
    /// A refined pattern (relative times) and the coarse answer, or `None` for the uniform
    /// grid.
    refined: Option<(&'a [f64], f64)>,
    /// Every program solved (over all searches).
    programs: &'a mut usize,
    /// Programs solved in this search.
    solved: usize,
}

impl GridPrograms<'_> {
    /// Times for a duration: the uniform grid, or the refined pattern scaled.
    fn times_for(&self, t: f64) -> Vec<f64> {
        match self.refined {
            None => grid_times(t),
            Some((pattern, _)) => pattern.iter().map(|s| s * t).collect(),
        }
    }

    /// The finest spacing of the grid at duration t: the bracket is shrunk to half of it.
    fn resolution(&self, t: f64) -> f64 {
        match self.refined {
            None => t / grid_intervals(t) as f64,
            Some((pattern, _)) => {
                t * pattern
                    .windows(2)
                    .map(|w| w[1] - w[0])
                    .fold(f64::INFINITY, f64::min)
            }
        }
    }

    /// The program at duration `t`.
    fn probe(&mut self, t: f64) -> Result<Probe> {
        self.solved += 1;
        *self.programs += 1;
        let times = self.times_for(t);
        let outcome = grid::solve_on_times(
            self.norm,
            self.samples,
            &times,
            None,
            grid::SEARCH_TOLERANCE,
        )?;
        Ok(match outcome {
            Some(o) => Probe {
                t,
                level: if self.samples.is_empty() {
                    0.0
                } else {
                    o.level
                },
                solution: Some(GridSolution {
                    times,
                    amplitudes: o.amplitudes,
                    duration: t,
                }),
            },
            None => Probe {
                t,
                level: f64::INFINITY,
                solution: None,
            },
        })
    }
}

/// A probe meets the constraints (with a margin).
fn feasible(p: &Probe) -> bool {
    p.level <= 1.0 - FEASIBILITY_MARGIN && p.solution.is_some()
}

/// The bracket [lo, hi]: lo infeasible (or 0), hi feasible. From half a period of the lowest
/// constrained frequency (a refined grid: from the coarse answer, which it can reproduce),
/// stepping down while feasible, or up (×1.5, or past the secant's crossing) until feasible;
/// an error past the duration limit.
fn bracket(grid: &mut GridPrograms<'_>) -> Result<(Probe, Probe)> {
    let norm = grid.norm;
    let limit = norm.max_duration;
    let start = match grid.refined {
        Some((_, known)) => known,
        None => (PI / norm.omega_min).min(limit),
    };
    let first = grid.probe(start)?;
    let down = if grid.refined.is_some() { 1.02 } else { 1.5 };
    if feasible(&first) {
        let mut hi = first;
        loop {
            let t = hi.t / down;
            if t < 1e-3 {
                let zero = Probe {
                    t: 0.0,
                    level: f64::INFINITY,
                    solution: None,
                };
                return Ok((zero, hi));
            }
            let p = grid.probe(t)?;
            if feasible(&p) {
                hi = p;
            } else {
                return Ok((p, hi));
            }
        }
    }
    let mut lo = first;
    let mut previous: Option<(f64, f64)> = None;
    loop {
        if lo.t >= limit {
            return Err(Error::Infeasible {
                reason: infeasible_reason(norm),
            });
        }
        // Step ×1.5, or to just past where the secant through the last two levels
        // crosses 1 (kept within ×1.1 … ×2).
        let f = lo.level.ln();
        let step = match previous {
            Some((t0, f0)) if f.is_finite() && f0.is_finite() && f0 > f && f > 0.0 => {
                let root = lo.t + (lo.t - t0) * f / (f0 - f);
                (1.02 * root).clamp(1.1 * lo.t, 2.0 * lo.t)
            }
            _ => 1.5 * lo.t,
        };
        let p = grid.probe(step.min(limit))?;
        if feasible(&p) {
            return Ok((lo, p));
        }
        previous = Some((lo.t, f));
        lo = p;
    }
}

/// Shrinks the bracket by regula falsi on ln s(T) (Illinois), kept in the bracket's middle
/// 90 %, until it is below half a grid step, a feasible level is within a fraction of the
/// bound, or [`MAX_PROGRAMS`] programs were solved; returns the feasible end.
fn shrink(grid: &mut GridPrograms<'_>, mut lo: Probe, mut hi: Probe) -> Result<Probe> {
    let tight_level = if grid.refined.is_some() { -1e-5 } else { -1e-2 };
    let mut side = 0i32; // Illinois: which end was kept last time
    let (mut f_lo, mut f_hi) = (lo.level.ln(), hi.level.ln());
    while hi.t - lo.t > grid.resolution(hi.t) && grid.solved < MAX_PROGRAMS {
        let mid = 0.5 * (lo.t + hi.t);
        let t = if f_lo.is_finite() && f_hi.is_finite() && f_lo > f_hi {
            // Root of the line through (lo, f_lo), (hi, f_hi), kept inside the middle 90 %.
            let r = lo.t + (hi.t - lo.t) * f_lo / (f_lo - f_hi);
            r.clamp(lo.t + 0.05 * (hi.t - lo.t), hi.t - 0.05 * (hi.t - lo.t))
        } else {
            mid
        };
        let p = grid.probe(t)?;
        let f = p.level.ln();
        if feasible(&p) {
            // Already within a fraction of the level of the bound: close enough.
            let tight = f > tight_level;
            hi = p;
            f_hi = f;
            if side == 1 {
                f_lo *= 0.5;
            }
            side = 1;
            if tight {
                break;
            }
        } else {
            lo = p;
            f_lo = f;
            if side == -1 {
                f_hi *= 0.5;
            }
            side = -1;
        }
    }
    Ok(hi)
}

fn infeasible_reason(norm: &NormalizedProblem) -> String {
    let seconds = norm.max_duration / norm.f_ref;
    if norm.max_duration >= MAX_CYCLES {
        format!(
            "no shaper of up to {MAX_CYCLES} periods of the highest frequency ({seconds:.6} s) \
             meets the constraints with amplitudes in [{}, {}]: narrow the band, raise vtol or \
             widen the amplitude bounds",
            norm.amplitude_min, norm.amplitude_max
        )
    } else {
        format!(
            "no shaper of at most maxDuration = {seconds} s meets the constraints with \
             amplitudes in [{}, {}]: allow a longer duration, narrow the band or raise vtol",
            norm.amplitude_min, norm.amplitude_max
        )
    }
}

/// A run of neighbouring grid impulses of one sign: the impulse it stands for.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Cluster {
    /// Amplitude-weighted mean time.
    pub time: f64,
    /// Sum of the amplitudes.
    pub amplitude: f64,
    /// Amplitude-weighted standard deviation of the times.
    pub spread: f64,
    /// Grid spacing around the cluster.
    pub spacing: f64,
}

/// Neighbouring grid impulses of the same sign grouped into clusters. An impulse between two
/// grid points shows as two or three neighbours; a run is split where it dips to a local
/// minimum below a tenth of its neighbours (two impulses close together).
pub(crate) fn clusters(grid: &GridSolution) -> Vec<Cluster> {
    let max = grid.amplitudes.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
    clusters_above(grid, 1e-6 * max)
}

/// [`clusters`] with every amplitude up to the solution's [`zero_level`] taken for zero: the
/// polish's second start.
pub(crate) fn clusters_above_noise(grid: &GridSolution) -> Vec<Cluster> {
    clusters_above(grid, zero_level(&grid.amplitudes))
}

/// The magnitude up to which a grid amplitude is noise. An interior-point solution leaves
/// unused grid points at small values, not at 0 (issue 24: up to 5e-5 of the largest
/// amplitude on a three-mode `si` grid solved to the search's tolerance), where [`clusters`]
/// counts everything above 1e-6 of it, so a run of such values can join two impulses into one
/// cluster. The level sits in the widest gap, by ratio and of at least [`ZERO_GAP`], between
/// consecutive sorted magnitudes whose lower side is at most [`ZERO_CEILING`] of the largest
/// (at the gap's geometric middle); 1e-6 of the largest when there is no such gap.
fn zero_level(a: &[f64]) -> f64 {
    let max = a.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
    let floor = 1e-6 * max;
    let mut mags: Vec<f64> = a.iter().map(|x| x.abs()).filter(|&m| m > 0.0).collect();
    crate::sort::sort_by(&mut mags, |x, y| y.total_cmp(x));
    let mut best: Option<(f64, f64)> = None;
    for w in mags.windows(2) {
        let (hi, lo) = (w[0], w[1]);
        let wider = best.is_none_or(|(ratio, _)| hi / lo > ratio);
        if lo <= ZERO_CEILING * max && hi >= ZERO_GAP * lo && wider {
            best = Some((hi / lo, (hi * lo).sqrt()));
        }
    }
    best.map_or(floor, |(_, level)| level.max(floor))
}

/// [`clusters`] of the amplitudes above `threshold` in magnitude.
fn clusters_above(grid: &GridSolution, threshold: f64) -> Vec<Cluster> {
    let a = &grid.amplitudes;
    let t = &grid.times;
    let max = a.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
    let significant = |k: usize| a[k].abs() > threshold;
    let mut out: Vec<Cluster> = Vec::new();
    let mut k = 0;
    while k < a.len() {
        if !significant(k) {
            k += 1;
            continue;
        }
        let sign = a[k].signum();
        let (mut sum, mut moment, mut second) = (0.0, 0.0, 0.0);
        let start = k;
        while k < a.len() && significant(k) && a[k].signum() == sign {
            let dip = k > start
                && k + 1 < a.len()
                && a[k].abs() <= a[k - 1].abs()
                && a[k].abs() <= a[k + 1].abs()
                && a[k + 1].signum() == sign
                && a[k].abs() < 0.1 * a[k - 1].abs().min(a[k + 1].abs());
            if dip {
                break;
            }
            sum += a[k];
            moment += a[k] * t[k];
            second += a[k] * t[k] * t[k];
            k += 1;
        }
        let end = k;
        if k < a.len() && significant(k) && a[k].signum() == sign && k > start {
            // Split at a dip: the dip's own (tiny) amplitude is left out.
            k += 1;
        }
        if sum.abs() > 1e-4 * max {
            let mean = moment / sum;
            let spacing = (start.saturating_sub(1)..end.min(t.len().saturating_sub(1)))
                .map(|i| t[i + 1] - t[i])
                .fold(f64::INFINITY, f64::min);
            out.push(Cluster {
                time: mean,
                amplitude: sum,
                spread: (second / sum - mean * mean).max(0.0).sqrt(),
                spacing: if spacing.is_finite() { spacing } else { 0.0 },
            });
        }
    }
    out
}

/// The clusters as impulses (amplitude: the sum; time: the amplitude-weighted mean, which
/// matches the phasor to first order in the spacing).
pub(crate) fn merge(grid: &GridSolution) -> Vec<Impulse> {
    clusters(grid)
        .iter()
        .map(|c| Impulse {
            time: c.time,
            amplitude: c.amplitude,
        })
        .collect()
}

/// A finer time pattern (relative times in [0, 1]) for a grid solution: its own points plus,
/// around every cluster of impulses it uses, points [`REFINE_FACTOR`] times closer together.
fn refine_pattern(grid: &GridSolution) -> Vec<f64> {
    let t = grid.duration.max(f64::MIN_POSITIVE);
    let rel: Vec<f64> = grid.times.iter().map(|x| x / t).collect();
    let mut pattern = rel.clone();
    let max = grid.amplitudes.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
    for imp in merge(grid) {
        let centre = imp.time / t;
        // Local spacing: the gap of the pattern around the centre.
        let k = rel.partition_point(|&x| x < centre);
        let gap = |i: usize| rel.get(i + 1).zip(rel.get(i)).map(|(b, a)| b - a);
        let h = [k.checked_sub(1).and_then(gap), gap(k)]
            .into_iter()
            .flatten()
            .fold(f64::INFINITY, f64::min);
        if !h.is_finite() || imp.amplitude.abs() <= 1e-4 * max {
            continue;
        }
        for j in -REFINE_POINTS..=REFINE_POINTS {
            let x = centre + f64::from(j) * h / REFINE_FACTOR;
            if (0.0..=1.0).contains(&x) {
                pattern.push(x);
            }
        }
    }
    crate::sort::sort_by(&mut pattern, f64::total_cmp);
    pattern.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    if let Some(last) = pattern.last_mut() {
        *last = 1.0;
    }
    if let Some(first) = pattern.first_mut() {
        *first = 0.0;
    }
    pattern
}

/// Divides the amplitudes by their sum, so Σ A = 1 to rounding. V scales by 1/Σ A and the zero
/// moments stay zero; the caller re-checks both. A sum that is not finite and positive (no
/// design has one: Σ A = 1 is a constraint of every program) is left alone.
fn renormalize(impulses: &mut [Impulse]) {
    let sum: f64 = impulses.iter().map(|i| i.amplitude).sum();
    if sum.is_finite() && sum > 0.0 && sum != 1.0 {
        for imp in impulses.iter_mut() {
            imp.amplitude /= sum;
        }
    }
}

/// When the polish fails: the grid solution itself, on the grid points it really uses, with
/// the amplitudes re-solved there (and the equalities made exact by projection). The support
/// is the points above 10⁻⁶ of the largest amplitude (the interior-point solver leaves ~10⁻¹⁰
/// elsewhere); if the program is not feasible on it, every point above 10⁻⁹ is kept.
/// Amplitude bound slack, relative to the bounds' range: the solver's tolerance, not more.
const BOUND_TOLERANCE: f64 = 1e-8;

/// Every amplitude within [amplitudeMin, amplitudeMax] up to [`BOUND_TOLERANCE`] of the
/// bounds' [`NormalizedProblem::amplitude_range`] (the range itself before 2026-12-06: with
/// `amplitudeMax: 1e12` that let an amplitude 10⁴ below amplitudeMin through).
fn within_bounds(norm: &NormalizedProblem, impulses: &[Impulse]) -> bool {
    let tol = BOUND_TOLERANCE * norm.amplitude_range(impulses.len());
    impulses
        .iter()
        .all(|i| i.amplitude >= norm.amplitude_min - tol && i.amplitude <= norm.amplitude_max + tol)
}

fn fallback(
    norm: &NormalizedProblem,
    samples: &[NormalizedLimit],
    grid: &GridSolution,
    programs: &mut usize,
) -> Result<Vec<Impulse>> {
    let max = grid.amplitudes.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
    for threshold in [1e-6, 1e-9] {
        let mut times: Vec<f64> = grid
            .times
            .iter()
            .zip(&grid.amplitudes)
            .filter(|(_, a)| a.abs() > threshold * max)
            .map(|(&t, _)| t)
            .collect();
        // Keep the grid's ends so V is measured from the same instant.
        if let Some(&end) = grid.times.last() {
            if times.last() != Some(&end) {
                times.push(end);
            }
        }
        if times.first() != Some(&0.0) {
            times.insert(0, 0.0);
        }
        // Solved tightly: this result is returned as it is (a program without zero constraints
        // is not projected, so its Σ A and bounds are the solver's; the convergence grid found
        // SI for four modes with Σ A = 1 − 5e-8 and an amplitude of −2e-6 at the search's
        // tolerance). If the solver cannot get that close, the search's tolerance is next.
        *programs += 1;
        let mut solved = grid::solve_on_times(norm, samples, &times, None, grid::EXACT_TOLERANCE)?;
        if solved.is_none() {
            *programs += 1;
            solved = grid::solve_on_times(norm, samples, &times, None, grid::SEARCH_TOLERANCE)?;
        }
        let Some(outcome) = solved else {
            continue;
        };
        if !samples.is_empty() && outcome.level > 1.0 {
            continue;
        }
        let mut impulses: Vec<Impulse> = times
            .iter()
            .zip(&outcome.amplitudes)
            .map(|(&time, &amplitude)| Impulse { time, amplitude })
            .collect();
        if !norm.zeros.is_empty() {
            polish::project_equalities(norm, &mut impulses);
        }
        // Drop the solver's zeros except the first and last, which fix t = 0 and t_n.
        let n = impulses.len();
        return Ok(impulses
            .into_iter()
            .enumerate()
            .filter(|(i, imp)| *i == 0 || *i + 1 == n || imp.amplitude.abs() > 1e-12)
            .map(|(_, imp)| imp)
            .collect());
    }
    Err(Error::Infeasible {
        reason: "the design program is numerically degenerate (modes very close together for \
                 this many derivatives, or constraints at the limits of precision): the grid \
                 solution could not be reproduced on its own impulse times"
            .into(),
    })
}

/// V(ω, ζ) / Vtol on a normalized impulse sequence.
pub(crate) fn ratio(impulses: &[Impulse], omega: f64, zeta: f64, vtol: f64) -> f64 {
    vibration_rad(impulses, omega, zeta) / vtol
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid_of(amplitudes: &[f64]) -> GridSolution {
        let times: Vec<f64> = (0..amplitudes.len()).map(|k| 0.1 * k as f64).collect();
        GridSolution {
            duration: times[times.len() - 1],
            times,
            amplitudes: amplitudes.to_vec(),
        }
    }

    /// Two impulses (0.5, and 0.3 + 0.2 on neighbouring points) with an interior-point
    /// solution's noise between them (2e-5 … 4e-5): one cluster when everything above 1e-6 of
    /// the largest counts, two once the noise is taken for zero. The noise level is the
    /// geometric middle of the widest gap (0.2 over 4e-5; the gap 2e-5 over 1e-8 is narrower).
    #[test]
    fn noise_between_impulses_is_taken_for_zero() {
        let a = [0.0, 0.5, 2e-5, 4e-5, 3e-5, 0.3, 0.2, 1e-8];
        assert_eq!(clusters(&grid_of(&a)).len(), 1);
        assert_eq!(zero_level(&a), (0.2_f64 * 4e-5).sqrt());
        let two = clusters_above_noise(&grid_of(&a));
        assert_eq!(two.len(), 2);
        assert!((two[0].amplitude - 0.5).abs() < 1e-15 && (two[1].amplitude - 0.5).abs() < 1e-15);
    }

    /// A small impulse above the noise (4e-3 of the largest) stays a cluster of its own; with
    /// no magnitude at or below 1e-3 of the largest there is no gap, and the level is 1e-6 of
    /// the largest.
    #[test]
    fn small_impulses_stay_and_gapless_solutions_keep_the_floor() {
        let a = [0.5, 1e-5, 0.002, 1e-5, 0.4];
        assert_eq!(zero_level(&a), (0.002_f64 * 1e-5).sqrt());
        let sums: Vec<f64> = clusters_above_noise(&grid_of(&a))
            .iter()
            .map(|c| c.amplitude)
            .collect();
        assert_eq!(sums, [0.5, 0.002, 0.4]);
        assert_eq!(zero_level(&[0.5, 0.4, 0.3]), 1e-6 * 0.5);
    }
}
