//! Shapers with negative impulses: unity-magnitude (UM-ZV, UM-ZVD, UM-EI), the time-optimal
//! bang-bang shaper and the fuel-efficient on/off shaper (Singhose 2009 §5, Figs. 13–14).
//!
//! All are solved exactly with damping by Newton's method (`design/equations.rs`) from an
//! undamped solution, with continuation in ζ. The review gives the idea and the figures; the
//! constraint sets below are reconstructed from it and from the papers it cites (Singhose,
//! Seering & Singer 1997, "Time-optimal negative input shapers"; Vaughan, Yano & Singhose 2009
//! for UM-EI), and the tests compare with their published curve fits.
//!
//! ## Unity magnitude (UM): amplitudes alternating +1, −1, …, +1
//! The amplitudes sum to 1, so a UM shaper is used like any other: convolve the reference
//! command with it. Convolved with a step of height `max`, it gives a command that only
//! switches between `max` and 0 — suitable for on/off actuators — and is shorter than the
//! positive shaper with the same constraints. The times are the unknowns:
//!
//! - **UM-ZV**: [1, −1, 1]; V = 0 at the mode (2 equations, t₂ and t₃). At ζ = 0,
//!   t = [0, T/6, T/3]: centred on T/6 the phasor is 2cos(ωT/6) − 1, zero at ω = 2π/T.
//! - **UM-ZVD**: [1, −1, 1, −1, 1]; V = 0 and ∂P/∂ω = 0 at the mode (4 equations, 4 times).
//!   At ζ = 0 the solution is symmetric, t = [0, x − y, x, x + y, 2x]/ω, with
//!   1 + 2cos x − 2cos y = 0 and x sin x = y sin y; x is found by bisection on (π/3, π)
//!   (y = arccos(cos x + ½)). This gives t ≈ [0, 0.0895, 0.3662, 0.6430, 0.7325]·T.
//! - **UM-EI**: the same five impulses with a hump V = Vtol, dV/dω = 0 at the mode and zeros
//!   either side (6 equations: 4 times and the 2 zero frequencies). At ζ = 0, symmetric:
//!   1 + 2cos x − 2cos y = −Vtol, x sin x = y sin y, continued in Vtol from UM-ZVD.
//!
//! With several modes the UM shapers are convolved like the others: V = 0 at every mode
//! holds, but the product is no longer unity-magnitude (its running sum leaves {0, 1}).
//!
//! ## Bang-bang (time-optimal rest-to-rest move), Fig. 13
//! A rigid body with one flexible mode, moved a distance D with acceleration limited to
//! ±a_max, fastest: the acceleration command is a_max × (shaper ∗ unit step) with the shaper
//! [1, −2, 2, −2, 1] at [0, t₁, t₂, t₃, t_f]. **Its amplitudes sum to 0**: the command is an
//! acceleration (force) profile that ends at zero, not a position reference; apply it by
//! convolving a step of height a_max (or feed the switch times to an on/off actuator). The
//! equations are V = 0 at the mode (2), final velocity Σ Aᵢ(t_f − tᵢ) = 0 and final position
//! ½ Σ Aᵢ(t_f − tᵢ)² = D/a_max. At ζ = 0 the solution is symmetric: with x = ωt_f/2 and
//! y = ω(t_f/2 − t₁), the vibration gives cos y = cos²(x/2) and the position
//! x² − 2y² = ω²D/a_max, increasing in x, solved by bisection.
//!
//! ## On/off with coasting (fuel-efficient), Fig. 14
//! Amplitudes ±1: [1, −1, 1, −1, −1, 1, −1, 1] — two accelerating pulses, a coast of
//! `coast_time` with the actuator off, two decelerating pulses; sum 0, applied like bang-bang.
//! The equations are: the accelerating half and the decelerating half each leave V = 0 at the
//! mode (so the structure does not vibrate while coasting; 4 rows), final velocity 0, final
//! position D/a_max, and t₅ − t₄ = coast (7 equations, 7 times). At ζ = 0 each half is a pulse
//! of width p repeated half a period later (a pulse convolved with ZV), and
//! D/a_max = 2p(T/2 + p + coast); p < T/2 is required (otherwise the two pulses of a half
//! merge — choose a longer coast). Fuel used: ∫|u| dt = 4p·a_max at ζ = 0.

use super::equations::{continue_in_damping, newton, to_shaper, Equation, Param, System};
use super::extra_insensitive::{check_parameters, verify_extra_insensitive, ExtraInsensitive};
use super::Guarantee;
use crate::error::{finite, positive, Error, Result};
use crate::mode::Mode;
use crate::shaper::Shaper;
use crate::vibration::vibration_rad;
use nalgebra::DVector;
use std::f64::consts::PI;

/// Highest zero of UM-EI accepted, as a multiple of the mode's frequency (the family ends
/// where its upper zero escapes).
const MAX_ZERO_RATIO: f64 = 20.0;

/// Shortest on/off pulse accepted, radians of the mode (1/2000 of a period): below it the
/// move's position is lost in rounding against its duration.
const MIN_PULSE: f64 = PI / 1000.0;
/// Smallest bang-bang move accepted, as distance / (maxAcceleration · T²): it lasts about
/// 2 % of a period; shorter moves are below any actuator's resolution and lose their
/// position to rounding.
pub const MIN_BANG_BANG_MOVE: f64 = 1e-8;

/// Longest bang-bang or on/off move accepted, in periods of the mode.
pub const MAX_MOVE_PERIODS: f64 = 1000.0;

/// Alternating ±1 amplitudes, n of them.
fn alternating(n: usize) -> Vec<Param> {
    (0..n)
        .map(|k| Param::Fixed(if k % 2 == 0 { 1.0 } else { -1.0 }))
        .collect()
}

/// Times [0, x₀, x₁, …] from the unknowns.
fn free_times(n: usize) -> Vec<Param> {
    std::iter::once(Param::Fixed(0.0))
        .chain((0..n - 1).map(Param::Free))
        .collect()
}

/// The first `n` unknowns, read as times after t = 0, strictly increase.
fn increasing(x: &DVector<f64>, n: usize) -> bool {
    let mut last = 0.0;
    for k in 0..n {
        if x[k] <= last {
            return false;
        }
        last = x[k];
    }
    true
}

fn damping_error(what: &str, zeta: f64, reached: f64) -> Error {
    Error::invalid(
        "damping",
        format!(
            "no {what} shaper was found for ζ = {zeta}: followed from ζ = 0, the solution ends \
             near ζ ≈ {reached:.3} (its impulses merge or a zero escapes)"
        ),
    )
}

/// Solves the UM system for `mode` and returns its dimensionless solution.
fn solve(
    what: &str,
    mode: &Mode,
    x0: DVector<f64>,
    system_at: impl Fn(f64) -> System,
    valid: impl Fn(&DVector<f64>) -> bool,
) -> Result<DVector<f64>> {
    let zeta = mode.damping();
    continue_in_damping(zeta, x0, system_at, valid).map_err(|r| damping_error(what, zeta, r))
}

/// UM-ZV: [1, −1, 1], V = 0 at the mode (module docs). At ζ = 0, t = [0, T/6, T/3].
///
/// ```
/// use input_shaping::{design::negative::um_zv, vibration::residual_vibration, Mode};
/// let mode = Mode::new(1.0, 0.0)?;
/// let shaper = um_zv(&mode)?; // undamped: [1, −1, 1] at [0, T/6, T/3]
/// let i = shaper.impulses();
/// assert_eq!(i.iter().map(|i| i.amplitude).collect::<Vec<_>>(), [1.0, -1.0, 1.0]);
/// assert!((i[1].time - 1.0 / 6.0).abs() < 1e-9 && (i[2].time - 1.0 / 3.0).abs() < 1e-9);
/// assert!(residual_vibration(&shaper, &mode) < 1e-9);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn um_zv(mode: &Mode) -> Result<Shaper> {
    let system_at = |zeta| System {
        zeta,
        amplitudes: alternating(3),
        times: free_times(3),
        equations: vec![(Equation::Zero(Param::Fixed(1.0)), 0..3)],
        unknowns: 2,
    };
    let x0 = DVector::from_vec(vec![PI / 3.0, 2.0 * PI / 3.0]);
    let x = solve("UM-ZV", mode, x0, system_at, |x| increasing(x, 2))?;
    to_shaper(&system_at(mode.damping()).impulses(&x), mode.omega_rad_s())
}

/// The symmetric undamped UM-ZVD: (x, y) with 1 + 2cos x − 2cos y = 0 and x sin x = y sin y,
/// by bisection on x ∈ (π/3, π) with y = arccos(cos x + ½).
fn um_zvd_undamped() -> (f64, f64) {
    let y_of = |x: f64| (x.cos() + 0.5).clamp(-1.0, 1.0).acos();
    let h = |x: f64| x * x.sin() - y_of(x) * y_of(x).sin();
    // h(π/3) = (π/3)(√3/2) > 0 (y = 0) and h(π) = −(2π/3)(√3/2) < 0.
    let (mut lo, mut hi) = (PI / 3.0, PI);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if h(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let x = 0.5 * (lo + hi);
    (x, y_of(x))
}

/// Symmetric five-impulse times [0, x − y, x, x + y, 2x] as unknowns t₁ … t₄.
fn symmetric_five(x: f64, y: f64) -> Vec<f64> {
    vec![x - y, x, x + y, 2.0 * x]
}

/// UM-ZVD: [1, −1, 1, −1, 1], V = 0 and dV/dω = 0 at the mode (module docs).
///
/// ```
/// use input_shaping::{design::negative::um_zvd, vibration::residual_vibration, Mode};
/// let mode = Mode::new(1.0, 0.05)?;
/// let shaper = um_zvd(&mode)?; // [1, −1, 1, −1, 1], V = 0 and dV/dω = 0 at the mode
/// assert_eq!(shaper.len(), 5);
/// assert!((shaper.amplitude_sum() - 1.0).abs() < 1e-12);
/// assert!(residual_vibration(&shaper, &mode) < 1e-9);
/// // Flat at the mode: 1 % off it, V is still below 0.1 %.
/// assert!(residual_vibration(&shaper, &mode.with_frequency_hz(1.01)?) < 1e-3);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn um_zvd(mode: &Mode) -> Result<Shaper> {
    let system_at = |zeta| System {
        zeta,
        amplitudes: alternating(5),
        times: free_times(5),
        equations: vec![
            (Equation::Zero(Param::Fixed(1.0)), 0..5),
            (Equation::ZeroSlope(Param::Fixed(1.0)), 0..5),
        ],
        unknowns: 4,
    };
    let (x, y) = um_zvd_undamped();
    let x0 = DVector::from_vec(symmetric_five(x, y));
    let x = solve("UM-ZVD", mode, x0, system_at, |x| increasing(x, 4))?;
    to_shaper(&system_at(mode.damping()).impulses(&x), mode.omega_rad_s())
}

/// The symmetric undamped UM-EI: Newton on g(1) = 1 + 2cos x − 2cos y = −Vtol and
/// g'(1)/2 = y sin y − x sin x = 0, continued in Vtol from UM-ZVD (Vtol = 0).
fn um_ei_undamped(vtol: f64) -> Option<(f64, f64)> {
    let (mut x, mut y) = um_zvd_undamped();
    let steps = 20;
    for k in 1..=steps {
        let v = vtol * f64::from(k) / f64::from(steps);
        for _ in 0..50 {
            let f1 = 1.0 + 2.0 * x.cos() - 2.0 * y.cos() + v;
            let f2 = y * y.sin() - x * x.sin();
            if f1.abs().max(f2.abs()) < 1e-15 {
                break;
            }
            let (a, b) = (-2.0 * x.sin(), 2.0 * y.sin());
            let (c, d) = (-(x.sin() + x * x.cos()), y.sin() + y * y.cos());
            let det = a * d - b * c;
            if det.abs() < 1e-300 {
                return None;
            }
            x -= (d * f1 - b * f2) / det;
            y -= (a * f2 - c * f1) / det;
        }
    }
    let ok = (1.0 + 2.0 * x.cos() - 2.0 * y.cos() + vtol).abs() < 1e-12 && 0.0 < y && y < x;
    ok.then_some((x, y))
}

/// A root of `g` between `inside` (g < 0) and the first sign change found stepping by `step`
/// (at most 4000 steps), refined by bisection.
fn first_crossing(g: &impl Fn(f64) -> f64, inside: f64, step: f64) -> Option<f64> {
    let mut a = inside;
    for _ in 0..4000 {
        let b = a + step;
        if b <= 0.0 {
            return None;
        }
        if g(b) >= 0.0 {
            let (mut lo, mut hi) = (a, b);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if g(mid) < 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            return Some(0.5 * (lo + hi));
        }
        a = b;
    }
    None
}

/// UM-EI: [1, −1, 1, −1, 1] with a hump V = `vtol` at the mode and zeros either side (module
/// docs); returns the zeros and the hump too.
///
/// ```
/// use input_shaping::{design::negative::um_ei_design, vibration::residual_vibration, Mode};
/// let mode = Mode::new(2.0, 0.0)?;
/// let um = um_ei_design(&mode, 0.05)?;
/// assert_eq!(um.humps_hz, [2.0]); // the hump, V = Vtol, at the mode itself
/// assert!((residual_vibration(&um.shaper, &mode) - 0.05).abs() < 1e-9);
/// for &f in &um.zeros_hz {
///     assert!(residual_vibration(&um.shaper, &mode.with_frequency_hz(f)?) < 1e-9);
/// }
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn um_ei_design(mode: &Mode, vtol: f64) -> Result<ExtraInsensitive> {
    check_parameters(1, vtol)?;
    let (x, y) = um_ei_undamped(vtol).ok_or_else(|| Error::Infeasible {
        reason: format!("no undamped UM-EI shaper found for vtol = {vtol}"),
    })?;
    let g = |w: f64| 1.0 + 2.0 * (w * x).cos() - 2.0 * (w * y).cos();
    let (low, high) = match (
        first_crossing(&g, 1.0, -1e-3),
        first_crossing(&g, 1.0, 1e-3),
    ) {
        (Some(l), Some(h)) => (l, h),
        _ => {
            return Err(Error::Infeasible {
                reason: format!(
                    "the undamped UM-EI for vtol = {vtol} has no zeros around the mode"
                ),
            })
        }
    };
    let system_at = |zeta| System {
        zeta,
        amplitudes: alternating(5),
        times: free_times(5),
        equations: vec![
            (
                Equation::Hump {
                    frequency: Param::Fixed(1.0),
                    vtol,
                },
                0..5,
            ),
            (Equation::Zero(Param::Free(4)), 0..5),
            (Equation::Zero(Param::Free(5)), 0..5),
        ],
        unknowns: 6,
    };
    let mut start = symmetric_five(x, y);
    start.extend([low, high]);
    let valid = |x: &DVector<f64>| {
        increasing(x, 4) && 0.0 < x[4] && x[4] < 1.0 && 1.0 < x[5] && x[5] < MAX_ZERO_RATIO
    };
    let sol = solve("UM-EI", mode, DVector::from_vec(start), system_at, valid)?;
    let f = mode.frequency_hz();
    let design = ExtraInsensitive {
        shaper: to_shaper(
            &system_at(mode.damping()).impulses(&sol),
            mode.omega_rad_s(),
        )?,
        humps_hz: vec![f],
        zeros_hz: vec![sol[4] * f, sol[5] * f],
    };
    verify_extra_insensitive(&design, mode, vtol)?;
    Ok(design)
}

/// UM-EI shaper (see [`um_ei_design`]).
///
/// ```
/// use input_shaping::{design::negative::um_ei, vibration::residual_vibration, Mode};
/// let mode = Mode::new(2.0, 0.03)?;
/// let shaper = um_ei(&mode, 0.05)?; // five impulses of ±1
/// assert!(shaper.impulses().iter().all(|i| i.amplitude.abs() == 1.0));
/// assert!((residual_vibration(&shaper, &mode) - 0.05).abs() < 1e-9);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn um_ei(mode: &Mode, vtol: f64) -> Result<Shaper> {
    Ok(um_ei_design(mode, vtol)?.shaper)
}

/// UM-EI for every mode, convolved; V = 0 at every mode's zeros (the humps are multiplied by
/// the other shapers' V, which for negative shapers may exceed 1, so only the zeros are
/// promised for several modes).
pub(crate) fn um_ei_for_modes(modes: &[Mode], vtol: f64) -> Result<(Shaper, Guarantee)> {
    check_parameters(1, vtol)?;
    let mut shaper = Shaper::identity();
    let mut zeros = Vec::new();
    for (i, mode) in modes.iter().enumerate() {
        let d = um_ei_design(mode, vtol).map_err(|e| e.within(&format!("modes[{i}]")))?;
        zeros.extend(d.zeros_hz.iter().map(|&f| (f, mode.damping())));
        shaper = shaper.convolve(&d.shaper)?;
    }
    Ok((shaper, Guarantee::ZeroAt(zeros)))
}

/// A rest-to-rest move: `distance` (any length unit) with acceleration limited to
/// `max_acceleration` (the same unit per s²). Returns ω²D/a, the move in radians² of the mode.
fn move_size(mode: &Mode, distance: f64, max_acceleration: f64) -> Result<f64> {
    positive("distance", distance)?;
    positive("maxAcceleration", max_acceleration)?;
    let omega = mode.omega_rad_s();
    let delta = omega * omega * (distance / max_acceleration);
    finite("distance", delta)?;
    Ok(delta)
}

/// Rejects moves longer than [`MAX_MOVE_PERIODS`] (time `t` in radians of the mode).
fn check_duration(t: f64) -> Result<()> {
    if t > MAX_MOVE_PERIODS * 2.0 * PI {
        return Err(Error::invalid(
            "distance",
            format!(
                "the move would last {:.0} periods of the mode, more than {MAX_MOVE_PERIODS}; \
                 shorten it or raise maxAcceleration",
                t / (2.0 * PI)
            ),
        ));
    }
    Ok(())
}

/// The undamped time-optimal bang-bang move of size δ = ω²D/a (module docs): unknowns
/// t₁, t₂, t₃, t_f = x − y, x, x + y, 2x with x² − 2y² = δ and cos y = cos²(x/2), by bisection
/// (the left side increases with x).
fn bang_bang_undamped(delta: f64) -> Result<DVector<f64>> {
    let y_of = |x: f64| ((x / 2.0).cos().powi(2)).clamp(-1.0, 1.0).acos();
    let position = |x: f64| x * x - 2.0 * y_of(x).powi(2);
    let mut hi = 2.0 * PI;
    while position(hi) < delta {
        check_duration(2.0 * hi)?;
        hi *= 2.0;
    }
    let mut lo = 0.0;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if position(mid) < delta {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let x = 0.5 * (lo + hi);
    check_duration(2.0 * x)?;
    Ok(DVector::from_vec(symmetric_five(x, y_of(x))))
}

/// The bang-bang system at damping `zeta` for a move of size `delta` (radians²).
fn bang_bang_system(zeta: f64, delta: f64) -> System {
    let scale = delta;
    System {
        zeta,
        amplitudes: [1.0, -2.0, 2.0, -2.0, 1.0]
            .iter()
            .map(|&a| Param::Fixed(a))
            .collect(),
        times: free_times(5),
        equations: vec![
            (Equation::Zero(Param::Fixed(1.0)), 0..5),
            (
                Equation::Moment {
                    order: 1,
                    value: 0.0,
                    scale: scale.sqrt(),
                },
                0..5,
            ),
            (
                Equation::Moment {
                    order: 2,
                    value: delta,
                    scale,
                },
                0..5,
            ),
        ],
        unknowns: 4,
    }
}

/// The bang-bang switch times t₁, t₂, t₃, t_f for the last two switches at times-to-go
/// a = t_f − t₂ > b = t_f − t₃ > 0, from the rigid-body equations: final velocity zero gives
/// t_f − t₁ = t_f/2 + a − b, and the final position δ gives
/// t_f = 2(a − b) + 2√(2(a − b)² − a² + b² + δ). `None` if no such move exists.
fn bang_bang_from_last_switches(a: f64, b: f64, delta: f64) -> Option<[f64; 4]> {
    let radicand = 2.0 * (a - b).powi(2) - a * a + b * b + delta;
    if radicand < 0.0 {
        return None;
    }
    let tf = 2.0 * (a - b) + 2.0 * radicand.sqrt();
    let t1 = tf / 2.0 - a + b;
    let times = [t1, tf - a, tf - b, tf];
    let ordered = 0.0 < t1 && times.windows(2).all(|w| w[0] < w[1]);
    ordered.then_some(times)
}

/// Grid resolution (radians of the mode) and extent (periods) of the search over the last two
/// switches.
const SWITCH_GRID_STEP: f64 = PI / 16.0;
const SWITCH_GRID_PERIODS: f64 = 4.0;

/// Starting points for the damped bang-bang with its last two switches within
/// [`SWITCH_GRID_PERIODS`] of the end: the local minima of V over a grid of (a, b).
fn end_cluster_starts(zeta: f64, delta: f64) -> Vec<DVector<f64>> {
    let n = (SWITCH_GRID_PERIODS * 2.0 * PI / SWITCH_GRID_STEP) as usize;
    let v_at = |i: usize, j: usize| -> f64 {
        if j == 0 || j >= i {
            return f64::INFINITY;
        }
        let (a, b) = (i as f64 * SWITCH_GRID_STEP, j as f64 * SWITCH_GRID_STEP);
        match bang_bang_from_last_switches(a, b, delta) {
            Some([t1, t2, t3, tf]) => {
                let imps = [(0.0, 1.0), (t1, -2.0), (t2, 2.0), (t3, -2.0), (tf, 1.0)]
                    .map(|(time, amplitude)| crate::shaper::Impulse { time, amplitude });
                vibration_rad(&imps, 1.0, zeta)
            }
            None => f64::INFINITY,
        }
    };
    let grid: Vec<Vec<f64>> = (0..=n + 1)
        .map(|i| (0..=n + 1).map(|j| v_at(i, j)).collect())
        .collect();
    let mut starts = Vec::new();
    for i in 1..=n {
        for j in 1..i {
            let v = grid[i][j];
            let minimum = v.is_finite()
                && v < grid[i - 1][j]
                && v <= grid[i + 1][j]
                && v < grid[i][j - 1]
                && v <= grid[i][j + 1];
            if minimum {
                let (a, b) = (i as f64 * SWITCH_GRID_STEP, j as f64 * SWITCH_GRID_STEP);
                if let Some(t) = bang_bang_from_last_switches(a, b, delta) {
                    starts.push(DVector::from_row_slice(&t));
                }
            }
        }
    }
    starts
}

/// Time-optimal bang-bang shaper [1, −2, 2, −2, 1] for a rest-to-rest move of `distance` at
/// `max_acceleration` with one flexible `mode` (module docs). Amplitudes sum to 0: apply it by
/// convolving a step of height `max_acceleration` to get the acceleration command.
///
/// At ζ = 0 the symmetric closed form is used. With damping the solution is the shortest
/// (smallest t_f) of the candidates found by (1) following the undamped solution in ζ — the
/// −2, +2, −2 cluster of switches stays near the middle — and (2) Newton from every local
/// minimum of V over a grid of the last two switches' times-to-go within four periods of the
/// end: for long moves with damping the cluster must sit near the end, where its vibration
/// can still cancel that of the final step. This is a search over the 3-switch solutions, not
/// a proof of time-optimality; the tests compare it with a brute-force scan.
///
/// ```
/// use input_shaping::{design::negative::bang_bang, vibration::residual_vibration, Mode};
/// let mode = Mode::new(1.0, 0.0)?;
/// let (distance, max_acceleration) = (0.5, 2.0);
/// let shaper = bang_bang(&mode, distance, max_acceleration)?; // [1, −2, 2, −2, 1]
/// let i = shaper.impulses();
/// assert_eq!(i.iter().map(|i| i.amplitude).collect::<Vec<_>>(), [1.0, -2.0, 2.0, -2.0, 1.0]);
/// assert!(residual_vibration(&shaper, &mode) < 1e-9);
/// // The acceleration a_max × (shaper ∗ step) ends at rest, `distance` away.
/// let tf = shaper.duration();
/// let velocity: f64 = i.iter().map(|i| i.amplitude * (tf - i.time)).sum();
/// let position: f64 = i.iter().map(|i| i.amplitude * (tf - i.time).powi(2) / 2.0).sum();
/// assert!(velocity.abs() < 1e-9 && (max_acceleration * position - distance).abs() < 1e-9);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn bang_bang(mode: &Mode, distance: f64, max_acceleration: f64) -> Result<Shaper> {
    let delta = move_size(mode, distance, max_acceleration)?;
    // δ = ω²D/a = 4π² D/(aT²).
    if delta < MIN_BANG_BANG_MOVE * 4.0 * PI * PI {
        return Err(Error::invalid(
            "distance",
            format!(
                "too short: distance / (maxAcceleration · T²) must be at least \
                 {MIN_BANG_BANG_MOVE:e} (T the mode's period), got {:e}",
                delta / (4.0 * PI * PI)
            ),
        ));
    }
    let zeta = mode.damping();
    let omega = mode.omega_rad_s();
    let undamped = bang_bang_undamped(delta)?;
    let system = bang_bang_system(zeta, delta);
    if zeta == 0.0 {
        return to_shaper(&system.impulses(&undamped), omega);
    }
    let valid = |x: &DVector<f64>| increasing(x, 4);
    let mut candidates: Vec<DVector<f64>> = Vec::new();
    // Shortest starts first; Newton moves t_f by much less than half a period, so starts
    // beyond the best solution so far plus half a period cannot win.
    let mut starts = end_cluster_starts(zeta, delta);
    crate::sort::sort_by(&mut starts, |a, b| a[3].total_cmp(&b[3]));
    let mut best = f64::INFINITY;
    for x0 in &starts {
        if x0[3] > best + PI {
            break;
        }
        if let Some(x) = newton(&system, x0).filter(valid) {
            best = best.min(x[3]);
            candidates.push(x);
        }
    }
    if let Ok(x) = continue_in_damping(zeta, undamped, |z| bang_bang_system(z, delta), valid) {
        candidates.push(x);
    }
    let best = candidates
        .into_iter()
        .min_by(|a, b| a[3].total_cmp(&b[3]))
        .ok_or_else(|| {
            Error::invalid(
                "damping",
                format!(
                    "no bang-bang move [1, −2, 2, −2, 1] of this distance was found for \
                     ζ = {zeta}"
                ),
            )
        })?;
    check_duration(best[3])?;
    to_shaper(&system.impulses(&best), omega)
}

/// Fuel-efficient on/off shaper [1, −1, 1, −1, −1, 1, −1, 1] with a coast of `coast_time`
/// seconds between the accelerating and decelerating pulse pairs (module docs). Amplitudes sum
/// to 0; apply like [`bang_bang`].
///
/// ```
/// use input_shaping::{design::negative::on_off, vibration::residual_vibration, Mode};
/// let mode = Mode::new(1.0, 0.0)?;
/// let shaper = on_off(&mode, 2.0, 2.0, 0.5)?; // accelerate, coast 0.5 s, decelerate
/// let a: Vec<f64> = shaper.impulses().iter().map(|i| i.amplitude).collect();
/// assert_eq!(a, [1.0, -1.0, 1.0, -1.0, -1.0, 1.0, -1.0, 1.0]);
/// assert!(residual_vibration(&shaper, &mode) < 1e-9);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn on_off(
    mode: &Mode,
    distance: f64,
    max_acceleration: f64,
    coast_time: f64,
) -> Result<Shaper> {
    let delta = move_size(mode, distance, max_acceleration)?;
    finite("coastTime", coast_time)?;
    if coast_time <= 0.0 {
        return Err(Error::invalid(
            "coastTime",
            format!(
                "must be greater than 0 s (with no coast the pulses join: use the bang-bang \
                 shaper), got {coast_time}"
            ),
        ));
    }
    let omega = mode.omega_rad_s();
    let c = coast_time * omega;
    check_duration(c)?;
    // ζ = 0: δ = 2p(π + p + c), p = δ / ((π + c) + √((π + c)² + 2δ)) without cancellation.
    let p = delta / ((PI + c) + ((PI + c).powi(2) + 2.0 * delta).sqrt());
    if p < MIN_PULSE {
        return Err(Error::invalid(
            "distance",
            format!(
                "too short for an on/off move with this coast: its pulses would last {:.3e} s, \
                 under 1/2000 of a period of the mode; a shorter coastTime lengthens them, or use \
                 bangbang",
                p / omega
            ),
        ));
    }
    if p >= PI * (1.0 - 1e-6) {
        let min_coast = (delta / (2.0 * PI) - 2.0 * PI) / omega;
        return Err(Error::invalid(
            "coastTime",
            format!(
                "too short for this distance: the pulses of each half would overlap; use \
                 coastTime > {min_coast:.6} s (or the bang-bang shaper)"
            ),
        ));
    }
    let s = PI + p + c;
    check_duration(s + PI + p)?;
    let x0 = DVector::from_vec(vec![p, PI, PI + p, s, s + p, s + PI, s + PI + p]);
    let scale = delta;
    let system_at = |zeta| System {
        zeta,
        amplitudes: [1.0, -1.0, 1.0, -1.0, -1.0, 1.0, -1.0, 1.0]
            .iter()
            .map(|&a| Param::Fixed(a))
            .collect(),
        times: free_times(8),
        equations: vec![
            (Equation::Zero(Param::Fixed(1.0)), 0..4),
            (Equation::Zero(Param::Fixed(1.0)), 4..8),
            (
                Equation::Moment {
                    order: 1,
                    value: 0.0,
                    scale: scale.sqrt(),
                },
                0..8,
            ),
            (
                Equation::Moment {
                    order: 2,
                    value: delta,
                    scale,
                },
                0..8,
            ),
            (Equation::Span(c), 3..5),
        ],
        unknowns: 7,
    };
    let sol = solve("on/off", mode, x0, system_at, |x| increasing(x, 7))?;
    to_shaper(&system_at(mode.damping()).impulses(&sol), omega)
}

/// Checks that a bang-bang or on/off design is one flexible mode, and returns it.
pub(crate) fn single_mode<'a>(modes: &'a [Mode], family: &str) -> Result<&'a Mode> {
    match modes {
        [mode] => Ok(mode),
        _ => Err(Error::invalid(
            "modes",
            format!(
                "the {family} shaper is designed for one flexible mode (plus the rigid body); \
                 got {} modes",
                modes.len()
            ),
        )),
    }
}
