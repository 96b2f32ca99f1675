//! The equations solved designs share, and Newton's method with continuation to solve them.
//!
//! A solved design is a list of impulses whose amplitudes and times are either fixed or
//! unknowns, and a square set of equations on them: amplitude sum, rigid-body moments, V = 0 at
//! a frequency, dV/dω = 0, a hump V = Vtol with zero slope. Frequencies in an equation may be
//! unknowns too (the zeros and humps of an EI shaper move with damping). Everything is
//! dimensionless: the design mode has ω = 1 rad/s, so times are in radians of the undamped
//! mode (one period = 2π); [`to_shaper`] scales back to seconds.
//!
//! V and its derivatives come from [`crate::vibration::vibration_phasor`] (Singhose 2009
//! eq. 11), so this file holds no formula of its own for the vibration.

use crate::error::{Error, Result};
use crate::shaper::{Impulse, Shaper};
use crate::vibration::vibration_phasor;
use nalgebra::{Complex, DMatrix, DVector};
use std::ops::Range;

/// A quantity that is either known or the `usize`-th unknown.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Param {
    /// A fixed value.
    Fixed(f64),
    /// The unknown at this index of the solution vector.
    Free(usize),
}

impl Param {
    /// The value of this parameter for the unknowns `x`.
    pub fn value(self, x: &DVector<f64>) -> f64 {
        match self {
            Param::Fixed(v) => v,
            Param::Free(i) => x[i],
        }
    }
}

/// One equation (one or two rows of the system) on the impulses in `range`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Equation {
    /// Σ Aᵢ = value (one row).
    AmplitudeSum(f64),
    /// Σ Aᵢ (t_L − tᵢ)^k / k! = value (one row, divided by `scale`): for a rigid body driven
    /// by acceleration steps Aᵢ at tᵢ, k = 1 is the final velocity and k = 2 the final
    /// position.
    Moment {
        /// k ≥ 1.
        order: u32,
        /// Required value.
        value: f64,
        /// Typical size of the terms, so the row is of order one.
        scale: f64,
    },
    /// t_L − t_F = value: the time from the first to the last impulse of the range (one row).
    Span(f64),
    /// P(ω) = 0: V = 0 (two rows, real and imaginary parts).
    Zero(Param),
    /// ∂P/∂ω = 0 at ω where P = 0 too: dV/dω = 0 in the ZVD sense (two rows).
    ZeroSlope(Param),
    /// A hump: V(ω) = vtol and dV/dω = 0 (two rows; scaled by 1/vtol).
    Hump {
        /// Frequency of the hump.
        frequency: Param,
        /// Height of the hump.
        vtol: f64,
    },
}

impl Equation {
    fn rows(&self) -> usize {
        match self {
            Equation::AmplitudeSum(_) | Equation::Moment { .. } | Equation::Span(_) => 1,
            _ => 2,
        }
    }
}

/// A square system on an impulse sequence at damping ratio `zeta`.
#[derive(Debug, Clone)]
pub(crate) struct System {
    /// Damping ratio of the design mode.
    pub zeta: f64,
    /// Amplitude of each impulse.
    pub amplitudes: Vec<Param>,
    /// Time of each impulse (radians of the design mode), in intended order.
    pub times: Vec<Param>,
    /// The equations, each on a contiguous range of impulses (usually all of them).
    pub equations: Vec<(Equation, Range<usize>)>,
    /// Number of unknowns.
    pub unknowns: usize,
}

impl System {
    /// The impulses for the unknowns `x`.
    pub fn impulses(&self, x: &DVector<f64>) -> Vec<Impulse> {
        self.amplitudes
            .iter()
            .zip(&self.times)
            .map(|(a, t)| Impulse {
                time: t.value(x),
                amplitude: a.value(x),
            })
            .collect()
    }

    /// Residual F(x) and Jacobian J(x): each equation fills its rows (see [`Block`]).
    fn evaluate(&self, x: &DVector<f64>) -> (DVector<f64>, DMatrix<f64>) {
        let rows: usize = self.equations.iter().map(|(e, _)| e.rows()).sum();
        let mut f = DVector::zeros(rows);
        let mut j = DMatrix::zeros(rows, self.unknowns);
        let all = self.impulses(x);
        let mut row = 0;
        for (equation, range) in &self.equations {
            let block = Block {
                imps: &all[range.clone()],
                amplitudes: &self.amplitudes[range.clone()],
                times: &self.times[range.clone()],
                row,
            };
            let (f, j) = (&mut f, &mut j);
            match equation {
                Equation::AmplitudeSum(value) => block.amplitude_sum(*value, f, j),
                Equation::Span(value) => block.span(*value, f, j),
                Equation::Moment {
                    order,
                    value,
                    scale,
                } => block.moment(*order, *value, *scale, f, j),
                Equation::Zero(freq) => block.zero(*freq, x, self.zeta, false, f, j),
                Equation::ZeroSlope(freq) => block.zero(*freq, x, self.zeta, true, f, j),
                Equation::Hump { frequency, vtol } => {
                    block.hump(*frequency, *vtol, x, self.zeta, f, j)
                }
            }
            row += equation.rows();
        }
        (f, j)
    }
}

/// The rows of one equation: its impulses, their amplitudes' and times' parameters, and its
/// first row in F and J.
struct Block<'s> {
    imps: &'s [Impulse],
    amplitudes: &'s [Param],
    times: &'s [Param],
    row: usize,
}

impl Block<'_> {
    /// The column of impulse `k`'s amplitude, if it is an unknown.
    fn a_col(&self, k: usize) -> Option<usize> {
        match self.amplitudes[k] {
            Param::Free(c) => Some(c),
            Param::Fixed(_) => None,
        }
    }

    /// The column of impulse `k`'s time, if it is an unknown.
    fn t_col(&self, k: usize) -> Option<usize> {
        match self.times[k] {
            Param::Free(c) => Some(c),
            Param::Fixed(_) => None,
        }
    }

    /// Σ Aᵢ = `value`.
    fn amplitude_sum(&self, value: f64, f: &mut DVector<f64>, j: &mut DMatrix<f64>) {
        let (imps, row) = (self.imps, self.row);
        f[row] = imps.iter().map(|i| i.amplitude).sum::<f64>() - value;
        for k in 0..imps.len() {
            if let Some(c) = self.a_col(k) {
                j[(row, c)] += 1.0;
            }
        }
    }

    /// t_L − t_F = `value`.
    fn span(&self, value: f64, f: &mut DVector<f64>, j: &mut DMatrix<f64>) {
        let (imps, row) = (self.imps, self.row);
        let last = imps.len() - 1;
        f[row] = imps[last].time - imps[0].time - value;
        if let Some(c) = self.t_col(last) {
            j[(row, c)] += 1.0;
        }
        if let Some(c) = self.t_col(0) {
            j[(row, c)] -= 1.0;
        }
    }

    /// Σ Aᵢ (t_L − tᵢ)^order / order! = `value`, the row divided by `scale`.
    fn moment(
        &self,
        order: u32,
        value: f64,
        scale: f64,
        f: &mut DVector<f64>,
        j: &mut DMatrix<f64>,
    ) {
        let (imps, row) = (self.imps, self.row);
        let k_fact: f64 = (1..=order).map(f64::from).product();
        let last = imps.len() - 1;
        let t_l = imps[last].time;
        let mut sum = 0.0;
        let mut d_last = 0.0;
        for (k, imp) in imps.iter().enumerate() {
            let d = t_l - imp.time;
            sum += imp.amplitude * d.powi(order as i32) / k_fact;
            if let Some(c) = self.a_col(k) {
                j[(row, c)] += d.powi(order as i32) / k_fact;
            }
            if k != last {
                // ∂/∂tₖ of Aₖ (t_L − tₖ)^m/m! = −Aₖ (t_L − tₖ)^{m−1}/(m−1)!
                let g = imp.amplitude * d.powi(order as i32 - 1) * f64::from(order) / k_fact;
                if let Some(c) = self.t_col(k) {
                    j[(row, c)] -= g;
                }
                d_last += g;
            }
        }
        if let Some(c) = self.t_col(last) {
            j[(row, c)] += d_last;
        }
        f[row] = sum - value;
        f[row] /= scale;
        for c in 0..j.ncols() {
            j[(row, c)] /= scale;
        }
    }

    /// P(ω) = 0 at ω = `freq` (or, with `slope`, ∂P/∂ω = 0): real and imaginary parts.
    fn zero(
        &self,
        freq: Param,
        x: &DVector<f64>,
        zeta: f64,
        slope: bool,
        f: &mut DVector<f64>,
        j: &mut DMatrix<f64>,
    ) {
        let (imps, row) = (self.imps, self.row);
        let w = freq.value(x);
        let p = vibration_phasor(imps, w, zeta);
        let (value, d_w, d_a, d_t) = if slope {
            (
                p.d_omega,
                p.d_omega2,
                &p.d_omega_d_amplitude,
                &p.d_omega_d_time,
            )
        } else {
            (p.value, p.d_omega, &p.d_amplitude, &p.d_time)
        };
        let mut put = |col: usize, d: Complex<f64>| {
            j[(row, col)] += d.re;
            j[(row + 1, col)] += d.im;
        };
        for k in 0..imps.len() {
            if let Some(c) = self.a_col(k) {
                put(c, d_a[k]);
            }
            if let Some(c) = self.t_col(k) {
                put(c, d_t[k]);
            }
        }
        if let Param::Free(c) = freq {
            put(c, d_w);
        }
        f[row] = value.re;
        f[row + 1] = value.im;
    }

    /// A hump at ω = `frequency`: V = `vtol` and dV/dω = 0, both rows scaled by 1/vtol.
    fn hump(
        &self,
        frequency: Param,
        vtol: f64,
        x: &DVector<f64>,
        zeta: f64,
        f: &mut DVector<f64>,
        j: &mut DMatrix<f64>,
    ) {
        let (imps, row) = (self.imps, self.row);
        let w = frequency.value(x);
        let p = vibration_phasor(imps, w, zeta);
        let (pv, pw) = (p.value, p.d_omega);
        // h₁ = (|P|² − v²)/(2v), h₂ = Re(P̄ P')/v  (h₂ = ½ d|P|²/dω / v).
        f[row] = (pv.norm_sqr() - vtol * vtol) / (2.0 * vtol);
        f[row + 1] = (pv.conj() * pw).re / vtol;
        let mut put = |col: usize, dp: Complex<f64>, dpw: Complex<f64>| {
            j[(row, col)] += (pv.conj() * dp).re / vtol;
            j[(row + 1, col)] += (dp.conj() * pw + pv.conj() * dpw).re / vtol;
        };
        for k in 0..imps.len() {
            if let Some(c) = self.a_col(k) {
                put(c, p.d_amplitude[k], p.d_omega_d_amplitude[k]);
            }
            if let Some(c) = self.t_col(k) {
                put(c, p.d_time[k], p.d_omega_d_time[k]);
            }
        }
        if let Param::Free(c) = frequency {
            put(c, pw, p.d_omega2);
        }
    }
}

/// Largest residual accepted as a solution (the equations are scaled to order one).
const RESIDUAL_TOLERANCE: f64 = 1e-12;
/// Residual accepted when rounding stops Newton (its step is below 1e-14 of the unknowns):
/// a row's terms may be much larger than its value, e.g. the position of a short move. The
/// designs' own checks then decide whether the result is good enough.
const ROUNDING_LIMITED_TOLERANCE: f64 = 1e-9;
/// Newton iterations per solve.
const MAX_NEWTON_ITERATIONS: usize = 60;

/// Newton's method with backtracking on ‖F‖ from `x0`; `None` if it does not converge or the
/// Jacobian is singular. The system must be square.
pub(crate) fn newton(system: &System, x0: &DVector<f64>) -> Option<DVector<f64>> {
    let mut x = x0.clone();
    let (mut f, mut j) = system.evaluate(&x);
    if f.len() != system.unknowns || x.len() != system.unknowns {
        return None;
    }
    let mut stalled = 0;
    for _ in 0..MAX_NEWTON_ITERATIONS {
        let norm = f.norm();
        if !norm.is_finite() {
            return None;
        }
        if f.amax() <= RESIDUAL_TOLERANCE {
            return Some(x);
        }
        let step = j.clone().lu().solve(&(-&f))?;
        if !step.iter().all(|s| s.is_finite()) {
            return None;
        }
        if step.amax() <= 1e-14 * (1.0 + x.amax()) {
            return (f.amax() <= ROUNDING_LIMITED_TOLERANCE).then_some(x);
        }
        let mut lambda = 1.0;
        loop {
            let trial = &x + &step * lambda;
            let (ft, jt) = system.evaluate(&trial);
            if ft.norm() < norm || lambda < 1e-3 {
                // Two full backtracks in a row: Newton is not converging from here.
                stalled = if lambda < 1e-3 { stalled + 1 } else { 0 };
                if stalled >= 2 {
                    return None;
                }
                x = trial;
                f = ft;
                j = jt;
                break;
            }
            lambda *= 0.5;
        }
    }
    (f.amax() <= RESIDUAL_TOLERANCE).then_some(x)
}

/// Largest damping step of the continuation in ζ.
const MAX_DAMPING_STEP: f64 = 0.05;
/// Smallest step, as a fraction of the whole parameter range, before giving up.
const MIN_STEP_FRACTION: f64 = 1e-4;
/// Most Newton solves one continuation may take.
const MAX_SOLVES: usize = 400;

/// Follows the solution of `system_at(ζ)` from `x0` (a solution at ζ = 0) to ζ = `zeta`
/// (see [`continuation`]). Returns the solution at `zeta`, or the largest ζ reached.
pub(crate) fn continue_in_damping(
    zeta: f64,
    x0: DVector<f64>,
    system_at: impl Fn(f64) -> System,
    valid: impl Fn(&DVector<f64>) -> bool,
) -> std::result::Result<DVector<f64>, f64> {
    continuation(0.0, zeta, MAX_DAMPING_STEP, x0, system_at, valid)
}

/// Follows the solution of `system_at(s)` from `x0` (a solution, or a close guess, at
/// s = `from`) to s = `to`, in steps of at most `max_step` that grow while Newton converges
/// and shrink when it fails, predicting each step by extrapolating the last two solutions.
/// `valid` rejects solutions that left the family (impulses out of order, a zero running
/// away). Returns the solution at `to`, or the parameter reached on failure.
pub(crate) fn continuation(
    from: f64,
    to: f64,
    max_step: f64,
    x0: DVector<f64>,
    system_at: impl Fn(f64) -> System,
    valid: impl Fn(&DVector<f64>) -> bool,
) -> std::result::Result<DVector<f64>, f64> {
    let mut x = newton(&system_at(from), &x0).filter(&valid).ok_or(from)?;
    let span = to - from;
    let mut s = from;
    let mut previous: Option<(f64, DVector<f64>)> = None;
    let mut h = max_step.min(span.abs());
    let min_step = MIN_STEP_FRACTION * span.abs();
    let mut solves = 0;
    while (to - s) * span.signum() > 0.0 {
        if solves >= MAX_SOLVES || h < min_step {
            return Err(s);
        }
        solves += 1;
        let s_next = if (to - s).abs() <= h * 1.0001 {
            to
        } else {
            s + h * span.signum()
        };
        let guess = match &previous {
            Some((sp, xp)) if s != *sp => &x + (&x - xp) * ((s_next - s) / (s - sp)),
            _ => x.clone(),
        };
        match newton(&system_at(s_next), &guess).filter(&valid) {
            Some(x_next) => {
                previous = Some((s, std::mem::replace(&mut x, x_next)));
                s = s_next;
                h = (h * 1.5).min(max_step);
            }
            None => h *= 0.5,
        }
    }
    Ok(x)
}

/// Converts dimensionless impulses (times in radians of a mode of ω = 1) to a shaper for a
/// mode of `omega` rad/s.
pub(crate) fn to_shaper(impulses: &[Impulse], omega: f64) -> Result<Shaper> {
    if !(omega.is_finite() && omega > 0.0) {
        return Err(Error::invalid("frequencyHz", "must be positive"));
    }
    Shaper::new(
        impulses
            .iter()
            .map(|imp| Impulse {
                time: imp.time / omega,
                amplitude: imp.amplitude,
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Jacobian agrees with central differences of the residual for every equation kind.
    #[wasm_bindgen_test::wasm_bindgen_test(unsupported = test)]
    fn jacobian_matches_finite_differences() {
        let system = System {
            zeta: 0.13,
            amplitudes: vec![
                Param::Free(0),
                Param::Free(1),
                Param::Fixed(-0.4),
                Param::Free(2),
            ],
            times: vec![
                Param::Fixed(0.0),
                Param::Free(3),
                Param::Free(4),
                Param::Free(5),
            ],
            equations: vec![
                (Equation::AmplitudeSum(1.0), 0..4),
                (
                    Equation::Moment {
                        order: 2,
                        value: 0.3,
                        scale: 2.0,
                    },
                    0..4,
                ),
                (Equation::Span(2.0), 1..3),
                (
                    Equation::Moment {
                        order: 1,
                        value: 0.1,
                        scale: 1.0,
                    },
                    1..4,
                ),
                (Equation::Zero(Param::Free(6)), 0..4),
                (Equation::ZeroSlope(Param::Fixed(1.1)), 0..3),
                (
                    Equation::Hump {
                        frequency: Param::Free(7),
                        vtol: 0.05,
                    },
                    0..4,
                ),
            ],
            unknowns: 8,
        };
        let x = DVector::from_vec(vec![0.3, 0.5, 0.6, 1.1, 2.3, 3.4, 0.8, 1.3]);
        let (f, j) = system.evaluate(&x);
        assert_eq!(f.len(), 10);
        for c in 0..8 {
            let h = 1e-6;
            let mut xp = x.clone();
            let mut xm = x.clone();
            xp[c] += h;
            xm[c] -= h;
            let fd = (system.evaluate(&xp).0 - system.evaluate(&xm).0) / (2.0 * h);
            for r in 0..f.len() {
                assert!(
                    (fd[r] - j[(r, c)]).abs() < 1e-6 * (1.0 + fd[r].abs()),
                    "row {r} col {c}: analytic {} numeric {}",
                    j[(r, c)],
                    fd[r]
                );
            }
        }
    }
}
