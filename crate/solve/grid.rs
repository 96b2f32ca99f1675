//! The convex program on fixed impulse times, solved with Clarabel (an interior-point
//! LP/QP/SOCP solver).
//!
//! With the times t₀ … t_N fixed and the last one t_N = T taken as the end of the shaper, every
//! design constraint of the literature is linear or second-order-cone in the amplitudes A:
//!
//! - Σ Aₖ = 1 (Singhose 2009 eq. 12), amplitude bounds A_min ≤ Aₖ ≤ A_max and increment bounds
//!   |Aₖ − Aₖ₋₁| ≤ ΔA_max (Kamel et al. eq. 7) are linear;
//! - zero vibration and zero frequency derivatives at a mode are the linear equalities
//!   M₀ = … = M_d = 0 of [`crate::vibration::vibration_moment`];
//! - V(ωⱼ, ζⱼ) ≤ Vtolⱼ (Singhose 2009 eq. 18) says that the 2-vector Σ Aₖ pⱼ(tₖ), with pⱼ the
//!   [`crate::vibration::impulse_phasor`], has length at most Vtolⱼ: a second-order cone.
//!
//! When there are vibration limits the program minimises the common level s with
//! V(ωⱼ, ζⱼ) ≤ s·Vtolⱼ (so s ≤ 1 means feasible, and the solution is unique and sparse at the
//! shortest feasible duration); otherwise it minimises the centroid Σ Aₖtₖ (an LP whose optimal
//! vertex uses few grid points; where the optimum is not unique the interior-point solver
//! returns the centre of the optimal face instead, and a failed polish is retried from a vertex:
//! [`super::vertex`]).

use super::{NormalizedLimit, NormalizedProblem};
use crate::error::{Error, Result};
use crate::vibration::impulse_phasor;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};

/// Most iterations the interior-point solver may take on one program.
const MAX_SOLVER_ITERATIONS: u32 = 200;

/// The solver's feasibility and gap tolerance in the duration search: it needs the level to
/// ~1e-6, and the polish makes the result exact.
pub(crate) const SEARCH_TOLERANCE: f64 = 1e-7;
/// The same for a result that is returned as it is (the fallback, when the polish fails): Σ A,
/// the amplitude bounds and the level to near rounding, so that renormalising to Σ A = 1
/// moves V by far less than the result check's tolerance.
pub(crate) const EXACT_TOLERANCE: f64 = 1e-10;
/// The KKT solves' iterative refinement stops at this fraction of a search program's
/// tolerance …
const REFINEMENT_FACTOR: f64 = 0.1;
/// … and at clarabel's default (relative 1e-13) for an exact one.
const EXACT_REFINEMENT: f64 = 1e-13;

/// What the program found on one set of times.
#[derive(Debug, Clone)]
pub(crate) struct Outcome {
    /// Amplitudes at the given times.
    pub amplitudes: Vec<f64>,
    /// The smallest common level s with V ≤ s·Vtol at every limit (0 without limits).
    pub level: f64,
}

/// The rows of the program's equalities on `times` (Σ A = 1, then the zero-vibration moments,
/// each part scaled to a largest coefficient of 1), dense: the matrix of the LP that
/// [`super::vertex::to_vertex`] reduces a solution of.
pub(crate) fn equality_rows(problem: &NormalizedProblem, times: &[f64]) -> Vec<Vec<f64>> {
    let mut program = Program::default();
    program.zero_cone(problem, times);
    let mut rows = vec![vec![0.0; times.len()]; program.row];
    for ((&r, &c), &v) in program.rows.iter().zip(&program.cols).zip(&program.vals) {
        rows[r][c] = v;
    }
    rows
}

/// Solves the program on `times` (sorted, first 0; the last is the shaper's end).
/// `Ok(None)` when no amplitudes satisfy the linear constraints (or the solver fails, which
/// the callers treat the same way: as "not feasible at this duration"). `tolerance`: the
/// solver's feasibility and gap tolerance ([`SEARCH_TOLERANCE`] or [`EXACT_TOLERANCE`]).
pub(crate) fn solve_on_times(
    problem: &NormalizedProblem,
    limits: &[NormalizedLimit],
    times: &[f64],
    increment_max: Option<f64>,
    tolerance: f64,
) -> Result<Option<Outcome>> {
    let n_amp = times.len();
    if n_amp == 0 {
        return Err(Error::invalid("times", "at least one time is required"));
    }
    let t_end = times[n_amp - 1];
    let has_level = !limits.is_empty();
    let n = n_amp + usize::from(has_level);

    let mut program = Program::default();
    program.zero_cone(problem, times);
    let n_zero = program.row;
    program.nonnegative_cone(problem, n_amp, increment_max);
    let n_nonneg = program.row - n_zero;
    program.second_order_cones(limits, times);
    if program
        .vals
        .iter()
        .chain(program.b.iter())
        .any(|v| !v.is_finite())
    {
        return Err(Error::invalid(
            "modes",
            "the design program has non-finite coefficients (frequencies or times out of range)",
        ));
    }

    let mut q = vec![0.0; n];
    if has_level {
        q[n_amp] = 1.0;
    } else if t_end > 0.0 {
        for (k, &t) in times.iter().enumerate() {
            q[k] = t / t_end;
        }
    }
    let mut cones = vec![SupportedConeT::ZeroConeT(n_zero)];
    if n_nonneg > 0 {
        cones.push(SupportedConeT::NonnegativeConeT(n_nonneg));
    }
    cones.extend(limits.iter().map(|_| SupportedConeT::SecondOrderConeT(3)));
    let Some(x) = program.solve(n, &q, &cones, tolerance)? else {
        return Ok(None);
    };
    let amplitudes = x[..n_amp].to_vec();
    if amplitudes.iter().any(|a| !a.is_finite()) {
        return Ok(None);
    }
    let level = if has_level {
        level(times, &amplitudes, limits)
    } else {
        0.0
    };
    Ok(Some(Outcome { amplitudes, level }))
}

/// The program's constraints A x + z = b, z in the cones: the triplets (row, col, value) of A
/// and b, in cone order. The variables are the amplitudes, then the level s (with limits).
#[derive(Default)]
struct Program {
    rows: Vec<usize>,
    cols: Vec<usize>,
    vals: Vec<f64>,
    b: Vec<f64>,
    /// The next row.
    row: usize,
}

impl Program {
    /// A[row, col] = `value` in the current row (zeros are left out).
    fn push(&mut self, col: usize, value: f64) {
        if value != 0.0 {
            self.rows.push(self.row);
            self.cols.push(col);
            self.vals.push(value);
        }
    }

    /// Ends the current row with b = `rhs`.
    fn end_row(&mut self, rhs: f64) {
        self.b.push(rhs);
        self.row += 1;
    }

    /// Zero cone: Σ A = 1, then the moment equalities.
    fn zero_cone(&mut self, problem: &NormalizedProblem, times: &[f64]) {
        let n_amp = times.len();
        let t_end = times[n_amp - 1];
        for k in 0..n_amp {
            self.push(k, 1.0);
        }
        self.end_row(1.0);
        for zero in &problem.zeros {
            for order in 0..=zero.derivatives {
                let mut coeffs = vec![[0.0; 2]; n_amp];
                for (k, &t) in times.iter().enumerate() {
                    let p = impulse_phasor(t, t_end, zero.omega, zero.zeta);
                    let w = if order == 0 {
                        1.0
                    } else {
                        t.powi(order as i32)
                    };
                    coeffs[k] = [w * p[0], w * p[1]];
                }
                for part in 0..2 {
                    let scale = coeffs.iter().map(|c| c[part].abs()).fold(0.0_f64, f64::max);
                    if scale == 0.0 {
                        continue; // e.g. the sine part at ω_d t = 0 only
                    }
                    for (k, c) in coeffs.iter().enumerate() {
                        self.push(k, c[part] / scale);
                    }
                    self.end_row(0.0);
                }
            }
        }
    }

    /// Nonnegative cone: bounds and increments. With A ≥ A_min and Σ A = 1, no amplitude can
    /// exceed 1 − (n − 1)·min(A_min, 0), so an upper bound at or above that is left out: it
    /// cannot bind, and a huge one (`amplitudeMax: 1e12`) would set the interior-point
    /// solver's scale — its tolerances are relative to the data — leaving Σ A off by 4e-5.
    fn nonnegative_cone(
        &mut self,
        problem: &NormalizedProblem,
        n_amp: usize,
        increment_max: Option<f64>,
    ) {
        let upper = problem.upper_bound_binds(n_amp);
        for k in 0..n_amp {
            self.push(k, -1.0); // A_k − A_min ≥ 0
            self.end_row(-problem.amplitude_min);
            if upper {
                self.push(k, 1.0); // A_max − A_k ≥ 0
                self.end_row(problem.amplitude_max);
            }
        }
        if let Some(d) = increment_max {
            for k in 1..n_amp {
                self.push(k, 1.0);
                self.push(k - 1, -1.0);
                self.end_row(d);
                self.push(k, -1.0);
                self.push(k - 1, 1.0);
                self.end_row(d);
            }
        }
    }

    /// Second-order cones: (Vtolⱼ s, Σ Aₖ pⱼ(tₖ)), the level s in the column after the
    /// amplitudes.
    fn second_order_cones(&mut self, limits: &[NormalizedLimit], times: &[f64]) {
        let t_end = times[times.len() - 1];
        let level_col = times.len();
        for limit in limits {
            self.push(level_col, -limit.vtol);
            self.end_row(0.0);
            let phasors: Vec<[f64; 2]> = times
                .iter()
                .map(|&t| impulse_phasor(t, t_end, limit.omega, limit.zeta))
                .collect();
            for part in 0..2 {
                for (k, p) in phasors.iter().enumerate() {
                    self.push(k, -p[part]);
                }
                self.end_row(0.0);
            }
        }
    }

    /// Minimises q·x over the `n` variables subject to the constraints in `cones`. `Ok(None)`
    /// when the solver finds no solution to the accuracy asked for.
    fn solve(
        self,
        n: usize,
        q: &[f64],
        cones: &[SupportedConeT<f64>],
        tolerance: f64,
    ) -> Result<Option<Vec<f64>>> {
        let p = CscMatrix::zeros((n, n));
        let a = by_columns(self.row, n, &self.rows, &self.cols, &self.vals);
        let refinement = if tolerance > EXACT_TOLERANCE {
            REFINEMENT_FACTOR * tolerance
        } else {
            EXACT_REFINEMENT
        };
        let settings = DefaultSettings {
            verbose: false,
            max_iter: MAX_SOLVER_ITERATIONS,
            presolve_enable: false,
            tol_gap_abs: tolerance,
            tol_gap_rel: tolerance,
            tol_feas: tolerance,
            iterative_refinement_max_iter: 3,
            iterative_refinement_reltol: refinement,
            iterative_refinement_abstol: refinement,
            ..DefaultSettings::default()
        };
        let Ok(mut solver) = DefaultSolver::new(&p, q, &a, &self.b, cones, settings) else {
            return Err(Error::Infeasible {
                reason: "the design program could not be set up".into(),
            });
        };
        solver.solve();
        let solution = &solver.solution;
        match solution.status {
            SolverStatus::Solved => {}
            // "Almost" is the solver's reduced accuracy (~1e-4), useless when asked for
            // exactness.
            SolverStatus::AlmostSolved if tolerance > EXACT_TOLERANCE => {}
            _ => return Ok(None),
        }
        Ok(Some(solution.x.clone()))
    }
}

/// The m × n matrix of the triplets (rows[k], cols[k], vals[k]) in compressed columns, for a
/// program's triplets: pushed row by row, each (row, column) at most once. A counting sort by
/// column keeps the push order within each column, so the rows come out ascending: the matrix
/// `CscMatrix::new_from_triplets` builds (compared in the tests below), without its
/// comparison sort of every entry (2 % of a three-mode `si` design in wasm, issue 24).
fn by_columns(m: usize, n: usize, rows: &[usize], cols: &[usize], vals: &[f64]) -> CscMatrix<f64> {
    let mut colptr = vec![0usize; n + 1];
    for &c in cols {
        colptr[c + 1] += 1;
    }
    for c in 0..n {
        colptr[c + 1] += colptr[c];
    }
    let mut next = colptr.clone();
    let mut rowval = vec![0usize; vals.len()];
    let mut nzval = vec![0.0; vals.len()];
    for ((&r, &c), &v) in rows.iter().zip(cols).zip(vals) {
        rowval[next[c]] = r;
        nzval[next[c]] = v;
        next[c] += 1;
    }
    CscMatrix::new(m, n, colptr, rowval, nzval)
}

/// The level of the amplitudes: max V/Vtol over the limits, recomputed from the amplitudes
/// rather than trusting the solver's s.
fn level(times: &[f64], amplitudes: &[f64], limits: &[NormalizedLimit]) -> f64 {
    let imps: Vec<crate::shaper::Impulse> = times
        .iter()
        .zip(amplitudes)
        .map(|(&time, &amplitude)| crate::shaper::Impulse { time, amplitude })
        .collect();
    limits
        .iter()
        .map(|l| crate::vibration::vibration_rad(&imps, l.omega, l.zeta) / l.vtol)
        .fold(0.0_f64, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A program's triplets in compressed columns: the matrix clarabel's own
    /// `new_from_triplets` builds from them, entry for entry, on the programs of a three-mode
    /// band problem with a ZVD zero (every cone kind: Σ A, moments, both amplitude bounds,
    /// increments, second-order cones).
    #[test]
    fn columns_are_the_triplet_constructors() {
        use crate::solve::{Band, Problem, Tolerance, ZeroVibration};
        let band = |f: f64| Band {
            from_hz: 0.85 * f,
            to_hz: 1.15 * f,
            damping_from: 0.02,
            damping_to: 0.02,
            tolerance: Tolerance::constant(0.05).unwrap(),
        };
        let problem = Problem {
            zeros: vec![ZeroVibration {
                frequency_hz: 2.0,
                damping: 0.02,
                derivatives: 1,
            }],
            limits: Vec::new(),
            bands: vec![band(1.2), band(3.4), band(7.9)],
            amplitude_min: -0.1,
            amplitude_max: 0.5,
            max_duration: None,
        };
        let norm = NormalizedProblem::new(&problem).unwrap();
        let limits: Vec<NormalizedLimit> = norm
            .bands
            .iter()
            .flat_map(super::super::scan::initial_samples)
            .collect();
        assert!(!limits.is_empty());
        let times: Vec<f64> = (0..=40).map(|k| 0.2 * k as f64).collect();
        let mut program = Program::default();
        program.zero_cone(&norm, &times);
        program.nonnegative_cone(&norm, times.len(), Some(0.3));
        program.second_order_cones(&limits, &times);
        let n = times.len() + 1;
        let ours = by_columns(program.row, n, &program.rows, &program.cols, &program.vals);
        let theirs = CscMatrix::new_from_triplets(
            program.row,
            n,
            program.rows.clone(),
            program.cols.clone(),
            program.vals.clone(),
        );
        assert_eq!((ours.m, ours.n), (theirs.m, theirs.n));
        assert_eq!(ours.colptr, theirs.colptr);
        assert_eq!(ours.rowval, theirs.rowval);
        assert_eq!(ours.nzval, theirs.nzval);
    }
}
