//! Newton polish of a grid solution: exact times and amplitudes, shortest duration.
//!
//! The grid solution, merged to a few impulses, fixes the structure of the answer: how many
//! impulses, which constraints are active (V = Vtol at which sampled points and at which
//! sensitivity humps of a band, which amplitudes sit at a bound). The polish then solves
//!
//!   minimise t_n  subject to  c(y) = 0 (the active constraints),
//!
//! for y = (t₁ … t_n, A₀ … A_n, the frequencies/dampings of the active humps), with t₀ = 0. A
//! hump inside a band is a maximum of V/Vtol, so it contributes two equations: V/Vtol = 1 and
//! ∂(ln V/Vtol)/∂ω = 0 (and ∂/∂ζ = 0 inside a damping range). The method is a reduced-Hessian
//! SQP: a Gauss–Newton step onto c = 0 (pseudo-inverse of the Jacobian) plus a Newton step on
//! the duration in the null space of the Jacobian, whose Hessian is taken by finite differences
//! of the Lagrangian. When the active constraints are as many as the unknowns this is plain
//! Newton on c = 0. An outer active-set loop drops constraints whose multiplier has the wrong
//! sign and adds those the result violates. All loops are bounded; on failure the caller falls
//! back to the (feasible, slightly longer) grid solution.

use super::scan::{band_peaks, Peak};
use super::{
    clusters, clusters_above_noise, ratio, Cluster, GridSolution, NormalizedLimit,
    NormalizedProblem, CHECK_TOLERANCE,
};
use crate::shaper::Impulse;
use crate::vibration::{impulse_phasor, moment_factor, moments_of_factors, vibration_moments};
use nalgebra::{DMatrix, DVector};
use std::sync::atomic::{AtomicBool, Ordering};

/// Most clusters split in two when looking for a structure that polishes.
const MAX_SPLITS: usize = 2;
/// The polish's second start ([`polish`]) is tried only while the grid solution's highest
/// V/Vtol (at its samples and between them) is at most this: farther off, the next exchange
/// round's samples change the structure anyway. Over the full convergence grid (2026-12-07)
/// the second start succeeded once above 1.5 (at 1.66), on a design the next round reached
/// the same; three-mode `si`, I 0.7, starts at 1.84, where neither start polishes.
const SECOND_START_MAX_RATIO: f64 = 1.5;
/// Newton/SQP iterations per active set.
const MAX_NEWTON_ITERATIONS: usize = 60;
/// Active-set changes tried.
const MAX_ACTIVE_SET_ROUNDS: usize = 16;
/// Active points left out in turn when the active set is inconsistent.
const MAX_DROPS: usize = 4;
/// Gauss–Newton gives up when ‖c‖ has not halved in this many iterations.
const STALL_ITERATIONS: usize = 6;
/// Candidates within this of the highest V/Vtol on the grid solution start out active.
const ACTIVE_BAND: f64 = 0.05;
/// Converged when every residual is below this.
const RESIDUAL_TOLERANCE: f64 = 1e-13;
/// … and the reduced gradient of the duration is below this.
const GRADIENT_TOLERANCE: f64 = 1e-9;
/// Above this largest residual, steps only restore c = 0.
const RESTORATION_THRESHOLD: f64 = 1e-4;
/// Largest null-space step per unknown (normalized units: periods of the highest frequency,
/// amplitudes, rad per period).
const MAX_NULL_STEP: f64 = 0.05;
/// Largest the null-space step's cap grows to after full steps (the reference path keeps
/// [`MAX_NULL_STEP`]).
const LARGEST_NULL_STEP: f64 = 0.8;
/// Chord iterations that pull a trial point back onto c = 0, at most. Each costs one
/// evaluation of c; the reduced Hessian of the step they test costs 1 + nz² (issue 24: with 4,
/// as before, a 17-impulse polish over three bands took its null-space steps at α = 1/64 …
/// 1/32 for 30 iterations — a longer step was restorable, not in 4 chords to the 1e-13
/// tolerance).
const MAX_CHORD_ITERATIONS: usize = 12;
/// … while each leaves at most this fraction of the previous largest residual (a chord that
/// does not contract will not restore the point: stop early).
const CHORD_CONTRACTION: f64 = 0.5;
/// The reference path's fixed chord count.
const REFERENCE_CHORD_ITERATIONS: usize = 4;
/// Finite-difference step for the Jacobian.
const JACOBIAN_STEP: f64 = 1e-7;
/// Finite-difference step for the reduced Hessian.
const HESSIAN_STEP: f64 = 1e-4;

/// The polish as it was before issue 24's speed work (the four-point Hessian stencil, a fixed
/// null-step cap, four chord iterations per trial point, the first split start that converges
/// kept), for benchmarks that compare the two in one run.
static REFERENCE_POLISH: AtomicBool = AtomicBool::new(false);

/// Whether the reference (previous) polish is selected.
fn reference_polish() -> bool {
    REFERENCE_POLISH.load(Ordering::Relaxed)
}

/// Selects the previous polish (`true`) or the current one (`false`, the default), process-wide.
/// For benchmarks only (`benches/si.rs`): both give the same guarantees.
pub(crate) fn set_reference_polish(on: bool) {
    REFERENCE_POLISH.store(on, Ordering::Relaxed);
}

/// A coordinate of an active point: fixed, or the unknown at `index` of y.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Coord {
    Fixed(f64),
    Free(usize),
}

/// Where an active point's Vtol comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Vtol {
    Constant(f64),
    Band(usize),
}

/// A point where V = Vtol is imposed.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Point {
    omega: Coord,
    zeta: Coord,
    vtol: Vtol,
    /// Band limits of the free coordinates: (ω_lo, ω_hi, ζ_lo, ζ_hi).
    bounds: (f64, f64, f64, f64),
    /// V/Vtol on the grid solution (for ordering).
    grid_ratio: f64,
}

/// One scalar equation of c(y) = 0.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Con {
    /// Σ A = 1.
    Sum,
    /// A component of the k-th moment at a zero constraint, divided by `scale`.
    Moment {
        zero: usize,
        order: u32,
        part: usize,
        scale: f64,
    },
    /// A_i = bound (`upper` says which bound; an inequality in disguise).
    Bound {
        index: usize,
        value: f64,
        upper: bool,
    },
    /// V/Vtol − 1 = 0 at point p (an inequality in disguise).
    Limit(usize),
    /// ∂ ln(V/Vtol)/∂ω = 0 (coord 0) or ∂/∂ζ = 0 (coord 1) at point p.
    Stationary { point: usize, coord: usize },
}

/// What a column of [`Setup::jacobian`] moves.
#[derive(Clone, Copy)]
enum Moved {
    /// Impulse i's time (`true`; never the last one's) or amplitude.
    Impulse(usize, bool),
    /// A free coordinate of active point p.
    Point(usize),
    /// Anything else (the last time): every sum.
    All,
}

/// The moment sums of [`Setup::sums`]: per zero, M₀ … M_d; per active point, its (ω, ζ) and
/// M₀ (and M₁).
#[derive(Debug, Clone)]
struct Sums {
    zeros: Vec<Vec<[f64; 2]>>,
    points: Vec<(f64, f64, Vec<[f64; 2]>)>,
}

/// Each impulse's factors of the moment sums at one iterate ([`Setup::factors`]): per zero and
/// per active point, [e^{−ζω(t_n − tᵢ)}, sin ω_d tᵢ, cos ω_d tᵢ] for every impulse i.
struct Factors {
    /// The last impulse's time.
    t_n: f64,
    zeros: Vec<Vec<[f64; 3]>>,
    points: Vec<Vec<[f64; 3]>>,
}

/// The unknowns and equations of one Newton solve.
#[derive(Debug, Clone)]
struct Setup<'a> {
    norm: &'a NormalizedProblem,
    /// Number of impulses m (t₀ = 0 fixed; y = [t₁..t_{m−1}, A₀..A_{m−1}, extra]).
    m: usize,
    points: Vec<Point>,
    cons: Vec<Con>,
    n: usize,
}

impl Setup<'_> {
    fn impulses(&self, y: &[f64]) -> Vec<Impulse> {
        let m = self.m;
        (0..m)
            .map(|i| Impulse {
                time: if i == 0 { 0.0 } else { y[i - 1] },
                amplitude: y[m - 1 + i],
            })
            .collect()
    }

    fn coord(&self, c: Coord, y: &[f64]) -> f64 {
        match c {
            Coord::Fixed(v) => v,
            Coord::Free(i) => y[i],
        }
    }

    fn vtol_of(&self, p: &Point, omega: f64) -> (f64, f64) {
        match p.vtol {
            Vtol::Constant(v) => (v, 0.0),
            Vtol::Band(b) => {
                let band = &self.norm.bands[b];
                let h = 1e-7 * omega.abs().max(1e-3);
                let slope = (band.vtol(omega + h) - band.vtol(omega - h)) / (2.0 * h);
                (band.vtol(omega), slope)
            }
        }
    }

    /// c(y).
    fn residuals(&self, y: &[f64]) -> Vec<f64> {
        let imps = self.impulses(y);
        let sums = self.sums(&imps, y);
        self.rows(&sums, &imps)
    }

    /// The moments c(y) is made of, each computed once: every order at each zero, and M₀ (with
    /// M₁ where a stationarity row needs it) at each active point — not once per row.
    fn sums(&self, imps: &[Impulse], y: &[f64]) -> Sums {
        let zeros = self
            .norm
            .zeros
            .iter()
            .map(|z| vibration_moments(imps, z.omega, z.zeta, z.derivatives))
            .collect();
        let points = self
            .points
            .iter()
            .map(|pt| self.point_sums(pt, imps, y))
            .collect();
        Sums { zeros, points }
    }

    /// One active point's entry of [`Sums`]: its (ω, ζ) at `y` and M₀ (with M₁ where a
    /// stationarity row needs it).
    fn point_sums(&self, pt: &Point, imps: &[Impulse], y: &[f64]) -> (f64, f64, Vec<[f64; 2]>) {
        let (w, z) = (self.coord(pt.omega, y), self.coord(pt.zeta, y));
        let stationary = matches!(pt.omega, Coord::Free(_)) || matches!(pt.zeta, Coord::Free(_));
        (w, z, vibration_moments(imps, w, z, u32::from(stationary)))
    }

    /// c(y) where `y` differs from the iterate of `base` (its sums) only in a free coordinate
    /// of active point `point`: that point's sums computed again, every other entry taken
    /// from `base` — the same numbers as [`Setup::residuals`], whose other entries depend on
    /// neither the point's ω nor its ζ (each free coordinate belongs to one point).
    fn residuals_at_point(&self, base: &Sums, y: &[f64], point: usize) -> Vec<f64> {
        let imps = self.impulses(y);
        let mut sums = base.clone();
        sums.points[point] = self.point_sums(&self.points[point], &imps, y);
        self.rows(&sums, &imps)
    }

    /// c from its moments (and the impulses, for Σ A, the bounds and t_n).
    fn rows(&self, sums: &Sums, imps: &[Impulse]) -> Vec<f64> {
        let t_n = imps.last().map_or(0.0, |i| i.time);
        self.cons
            .iter()
            .map(|con| match *con {
                Con::Sum => imps.iter().map(|i| i.amplitude).sum::<f64>() - 1.0,
                Con::Moment {
                    zero,
                    order,
                    part,
                    scale,
                } => sums.zeros[zero][order as usize][part] / scale,
                Con::Bound { index, value, .. } => imps[index].amplitude - value,
                Con::Limit(p) => {
                    let (w, _, m) = &sums.points[p];
                    let [c0, s0] = m[0];
                    crate::vibration::magnitude(c0, s0) / self.vtol_of(&self.points[p], *w).0 - 1.0
                }
                Con::Stationary { point, coord } => {
                    let (w, z, m) = &sums.points[point];
                    let vtol = self.vtol_of(&self.points[point], *w);
                    log_slope(m[0], m[1], t_n, *w, *z, coord, vtol)
                }
            })
            .collect()
    }

    /// Central-difference Jacobian of c. A column that moves one impulse's amplitude, or the
    /// time of one impulse but the last, changes one term of each moment sum: its residuals
    /// keep the other impulses' factors of the iterate ([`Setup::residuals_moved`], the same
    /// numbers as [`Setup::residuals`]; a unit test compares them on every column of every
    /// Jacobian a design takes). A free ω or ζ of an active point moves that point's sums
    /// alone: its columns keep every other sum of the iterate ([`Setup::residuals_at_point`],
    /// compared the same way). The last time (the vibration's reference instant) moves every
    /// term.
    fn jacobian(&self, y: &[f64]) -> DMatrix<f64> {
        let m = self.m;
        let imps = self.impulses(y);
        let base = self.factors(&imps, y);
        let base_sums = self.sums(&imps, y);
        let mut j = DMatrix::zeros(self.cons.len(), self.n);
        let mut yp = y.to_vec();
        for col in 0..self.n {
            let moved = if col + 2 < m {
                Moved::Impulse(col + 1, true)
            } else if (m - 1..2 * m - 1).contains(&col) {
                Moved::Impulse(col + 1 - m, false)
            } else if let Some(p) = self
                .points
                .iter()
                .position(|p| p.omega == Coord::Free(col) || p.zeta == Coord::Free(col))
            {
                Moved::Point(p)
            } else {
                Moved::All
            };
            let residuals = |yy: &[f64]| {
                let r = match moved {
                    Moved::Impulse(i, time) => self.residuals_moved(&base, yy, i, time),
                    Moved::Point(p) => self.residuals_at_point(&base_sums, yy, p),
                    Moved::All => return self.residuals(yy),
                };
                #[cfg(test)]
                assert_eq!(
                    r.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    self.residuals(yy)
                        .iter()
                        .map(|v| v.to_bits())
                        .collect::<Vec<_>>(),
                    "column {col}: the kept factors or sums give the residuals to the bit"
                );
                r
            };
            let h = JACOBIAN_STEP * y[col].abs().max(1.0);
            yp[col] = y[col] + h;
            let rp = residuals(&yp);
            yp[col] = y[col] - h;
            let rm = residuals(&yp);
            yp[col] = y[col];
            for (row, (a, b)) in rp.iter().zip(&rm).enumerate() {
                j[(row, col)] = (a - b) / (2.0 * h);
            }
        }
        j
    }

    /// Each impulse's factors of the moment sums ([`moment_factor`]) at every zero and active
    /// point, at the iterate `y` (its impulses `imps`).
    fn factors(&self, imps: &[Impulse], y: &[f64]) -> Factors {
        let t_n = imps.last().map_or(0.0, |i| i.time);
        let of = |w: f64, z: f64| {
            let damped = (1.0 - z * z).sqrt();
            imps.iter()
                .map(|i| moment_factor(i.time, t_n, w, z, damped))
                .collect()
        };
        Factors {
            t_n,
            zeros: self
                .norm
                .zeros
                .iter()
                .map(|z| of(z.omega, z.zeta))
                .collect(),
            points: self
                .points
                .iter()
                .map(|pt| of(self.coord(pt.omega, y), self.coord(pt.zeta, y)))
                .collect(),
        }
    }

    /// c(y) where `y` differs from the iterate of `base` only in impulse `moved`'s amplitude, or
    /// (`time`) in its time — never the last one's: that impulse's factors are computed again,
    /// the others taken from `base`, summed in the same order as [`Setup::residuals`] sums.
    fn residuals_moved(&self, base: &Factors, y: &[f64], moved: usize, time: bool) -> Vec<f64> {
        let imps = self.impulses(y);
        let sums_of = |w: f64, z: f64, kept: &[[f64; 3]], k_max: u32| {
            let fresh = time.then(|| {
                let damped = (1.0 - z * z).sqrt();
                moment_factor(imps[moved].time, base.t_n, w, z, damped)
            });
            moments_of_factors(
                &imps,
                |i| match fresh {
                    Some(f) if i == moved => f,
                    _ => kept[i],
                },
                k_max,
            )
        };
        let zeros = self
            .norm
            .zeros
            .iter()
            .zip(&base.zeros)
            .map(|(z, kept)| sums_of(z.omega, z.zeta, kept, z.derivatives))
            .collect();
        let points = self
            .points
            .iter()
            .zip(&base.points)
            .map(|(pt, kept)| {
                let (w, z) = (self.coord(pt.omega, y), self.coord(pt.zeta, y));
                let stationary =
                    matches!(pt.omega, Coord::Free(_)) || matches!(pt.zeta, Coord::Free(_));
                (w, z, sums_of(w, z, kept, u32::from(stationary)))
            })
            .collect();
        self.rows(&Sums { zeros, points }, &imps)
    }

    /// Index in y of the duration t_{m−1}.
    fn duration_index(&self) -> usize {
        self.m - 2
    }

    /// Whether y is a valid point: times strictly increasing and positive, free coordinates
    /// inside their ranges.
    fn valid(&self, y: &[f64]) -> bool {
        if y.iter().any(|v| !v.is_finite()) {
            return false;
        }
        let mut last = 0.0;
        for &t in &y[..self.m - 1] {
            if t <= last {
                return false;
            }
            last = t;
        }
        for p in &self.points {
            let (wl, wh, zl, zh) = p.bounds;
            if let Coord::Free(i) = p.omega {
                if y[i] < wl || y[i] > wh {
                    return false;
                }
            }
            if let Coord::Free(i) = p.zeta {
                if y[i] < zl || y[i] > zh {
                    return false;
                }
            }
        }
        true
    }
}

/// ∂ ln(V/Vtol) / ∂ω (coord 0) or ∂ ln V / ∂ζ (coord 1), scaled to O(1), from the moments M₀, M₁
/// of eq. 11: with M = M₀ as a complex number, dM/dω = −ζ t_n M₀ + (ζ + i√(1−ζ²)) M₁ and
/// dM/dζ = −ω t_n M₀ + ω(1 − iζ/√(1−ζ²)) M₁ (differentiating e^{−ζω(t_n−t)} e^{iω√(1−ζ²) t}).
fn log_slope(
    [c0, s0]: [f64; 2],
    [c1, s1]: [f64; 2],
    t_n: f64,
    omega: f64,
    zeta: f64,
    coord: usize,
    (vtol, vtol_slope): (f64, f64),
) -> f64 {
    let root = (1.0 - zeta * zeta).sqrt();
    let (dc, ds) = if coord == 0 {
        (
            -zeta * t_n * c0 + zeta * c1 - root * s1,
            -zeta * t_n * s0 + zeta * s1 + root * c1,
        )
    } else {
        let q = zeta / root;
        (
            omega * (-t_n * c0 + c1 + q * s1),
            omega * (-t_n * s0 + s1 - q * c1),
        )
    };
    let v2 = (c0 * c0 + s0 * s0).max(1e-300);
    let dlnv = (c0 * dc + s0 * ds) / v2;
    let scale = if coord == 0 {
        t_n.max(1.0)
    } else {
        (omega * t_n).max(1.0)
    };
    if coord == 0 {
        (dlnv - vtol_slope / vtol) / scale
    } else {
        dlnv / scale
    }
}

/// The singular value decomposition of `m` (U and Vᵀ computed), or `None` when it has a NaN or
/// an infinity or does not converge within a budget of iterations: nalgebra's `svd` iterates
/// until it converges, and on a matrix with a NaN it never does — a design request of the
/// 10⁶-case property run spun there for over an hour (docs/testing.md). Same tolerance as `svd`
/// (5 ε), so the same decomposition wherever that one ends.
fn bounded_svd(
    m: DMatrix<f64>,
) -> Option<nalgebra::linalg::SVD<f64, nalgebra::Dyn, nalgebra::Dyn>> {
    if m.iter().any(|v| !v.is_finite()) {
        return None;
    }
    // Each of nalgebra's iterations is one implicit QR sweep of the bidiagonal (min(m, n)
    // wide), which takes two or three per singular value (LAPACK's dbdsqr allows 6n²).
    let budget = 1000 + 100 * m.nrows().min(m.ncols());
    m.try_svd(true, true, 5.0 * f64::EPSILON, budget)
}

/// The eigen-decomposition of the symmetric `m`, bounded as [`bounded_svd`] is (nalgebra's
/// `symmetric_eigen` iterates without limit too): `None` for a NaN or an infinity or past the
/// budget, else nalgebra's own (same tolerance, ε).
fn bounded_symmetric_eigen(
    m: DMatrix<f64>,
) -> Option<nalgebra::linalg::SymmetricEigen<f64, nalgebra::Dyn>> {
    if m.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let budget = 1000 + 100 * m.nrows();
    m.try_symmetric_eigen(f64::EPSILON, budget)
}

/// Result of the inner solve: y and the multipliers of c.
struct Solved {
    y: Vec<f64>,
    lambda: Vec<f64>,
}

/// The linear algebra of one iterate: the pseudo-inverse of the Jacobian, a basis of its null
/// space, and the least-squares multipliers.
struct Linearization {
    /// Number of unknowns.
    n: usize,
    /// Rows of Vᵀ and columns of U over the numerical range, with the singular values.
    range: Vec<(DVector<f64>, DVector<f64>, f64)>,
    /// Orthonormal basis of the null space of J.
    null: Vec<DVector<f64>>,
    /// Multipliers λ with Jᵀλ ≈ ∇t_n.
    lambda: DVector<f64>,
}

impl Linearization {
    fn new(jac: DMatrix<f64>, grad_f: &DVector<f64>) -> Option<Self> {
        let n = jac.ncols();
        let svd = bounded_svd(jac)?;
        let (u, vt) = (svd.u.as_ref()?, svd.v_t.as_ref()?);
        let smax = svd.singular_values.iter().fold(0.0_f64, |a, &b| a.max(b));
        let cut = 1e-10 * smax.max(1e-300);
        let mut range = Vec::new();
        let mut lambda = DVector::zeros(u.nrows());
        for k in 0..svd.singular_values.len() {
            let s = svd.singular_values[k];
            if s > cut {
                let uk = u.column(k).into_owned();
                let vk = vt.row(k).transpose();
                lambda += &uk * (vk.dot(grad_f) / s);
                range.push((vk, uk, s));
            }
        }
        // Unit vectors with the range of Jᵀ (and earlier basis vectors) projected out.
        let mut null: Vec<DVector<f64>> = Vec::new();
        for e in 0..n {
            if null.len() + range.len() >= n {
                break;
            }
            let mut v = DVector::zeros(n);
            v[e] = 1.0;
            for r in range.iter().map(|r| &r.0).chain(null.iter()) {
                let d = r.dot(&v);
                v -= r * d;
            }
            let norm = v.norm();
            if norm > 1e-6 {
                null.push(v / norm);
            }
        }
        Some(Linearization {
            n,
            range,
            null,
            lambda,
        })
    }

    /// `y` as the solution, with these multipliers.
    fn solved(&self, y: Vec<f64>) -> Solved {
        Solved {
            y,
            lambda: self.lambda.iter().copied().collect(),
        }
    }

    /// The least-norm δ with J δ = −c.
    fn restore(&self, c: &DVector<f64>) -> DVector<f64> {
        let mut dy = DVector::zeros(self.n);
        for (vk, uk, s) in &self.range {
            dy -= vk * (uk.dot(c) / s);
        }
        dy
    }
}

/// Reduced-Hessian SQP for min t_n s.t. c(y) = 0, from y0.
///
/// Far from c = 0 it takes Gauss–Newton steps on c alone (line search on ‖c‖₁). Near it, each
/// step is the Gauss–Newton correction plus a Newton step on t_n in the null space of J (the
/// reduced Hessian of the Lagrangian by finite differences, made positive definite, the step
/// capped at [`MAX_NULL_STEP`]); the trial point is pulled back onto c = 0 by a few chord
/// iterations with the same Jacobian before t_n is compared, which keeps the steps long on
/// curved constraint sets.
fn sqp(setup: &Setup, y0: Vec<f64>) -> Option<Solved> {
    let n = setup.n;
    let mut grad_f = DVector::zeros(n);
    grad_f[setup.duration_index()] = 1.0;
    let mut y = y0;
    if !setup.valid(&y) {
        return None;
    }
    let (mut best_c, mut since_best) = (f64::INFINITY, 0);
    // The null-space step's cap (a trust radius): doubled after a full step, back towards
    // MAX_NULL_STEP after a shortened one, never below it.
    let mut cap = MAX_NULL_STEP;
    for _ in 0..MAX_NEWTON_ITERATIONS {
        let c = DVector::from_vec(setup.residuals(&y));
        let lin = Linearization::new(setup.jacobian(&y), &grad_f)?;
        let gz: Vec<f64> = lin.null.iter().map(|z| z.dot(&grad_f)).collect();
        let c_max = c.amax();
        let gz_max = gz.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
        // Stalled far from c = 0: an inconsistent system, Gauss–Newton stuck in least squares.
        if c_max < 0.5 * best_c {
            (best_c, since_best) = (c_max, 0);
        } else if c_max > RESTORATION_THRESHOLD {
            since_best += 1;
            if since_best >= STALL_ITERATIONS {
                return None;
            }
        }
        if c_max <= RESIDUAL_TOLERANCE && gz_max <= GRADIENT_TOLERANCE {
            return Some(lin.solved(y));
        }
        let dy_range = lin.restore(&c);
        // The step, and how far from optimal a point without one may still be accepted.
        let (next, gradient_slack) = if c_max > RESTORATION_THRESHOLD || lin.null.is_empty() {
            (restoration_step(setup, &y, &dy_range, c_max), 1.0)
        } else {
            let null_step = null_space_step(setup, &y, &lin, &gz, cap);
            let capped = null_step.amax() >= cap * (1.0 - 1e-12);
            let step = optimality_step(setup, &y, &lin, &dy_range, &null_step, c_max);
            if !reference_polish() {
                let full = matches!(step, Some((_, alpha)) if alpha == 1.0);
                cap = match (full, capped) {
                    (true, true) => (2.0 * cap).min(LARGEST_NULL_STEP),
                    (true, false) => cap,
                    (false, _) => (0.5 * cap).max(MAX_NULL_STEP),
                };
            }
            (step.map(|(t, _)| t), 1e3)
        };
        match next {
            Some(t) => y = t,
            // No decrease found: converged as far as rounding allows, or stuck.
            None if c_max <= 1e3 * RESIDUAL_TOLERANCE
                && gz_max <= gradient_slack * GRADIENT_TOLERANCE =>
            {
                return Some(lin.solved(y))
            }
            None => return None,
        }
    }
    None
}

/// The largest |cᵢ|.
fn infeasibility(c: &[f64]) -> f64 {
    c.iter().fold(0.0_f64, |a, b| a.max(b.abs()))
}

/// y + α·dy.
fn step_to(y: &[f64], dy: &DVector<f64>, alpha: f64) -> Vec<f64> {
    y.iter()
        .zip(dy.iter())
        .map(|(a, b)| a + alpha * b)
        .collect()
}

/// Far from c = 0: the Gauss–Newton step `dy_range` on c alone, halved until ‖c‖∞ falls below
/// `c_max` (`None` if it never does).
fn restoration_step(
    setup: &Setup,
    y: &[f64],
    dy_range: &DVector<f64>,
    c_max: f64,
) -> Option<Vec<f64>> {
    let mut alpha = 1.0;
    for _ in 0..30 {
        let trial = step_to(y, dy_range, alpha);
        if setup.valid(&trial) && infeasibility(&setup.residuals(&trial)) < c_max {
            return Some(trial);
        }
        alpha *= 0.5;
    }
    None
}

/// The Newton step on t_n in the null space of J at `y`: the reduced Hessian of the
/// Lagrangian L = t_n − λ·c by central differences, its eigenvalues floored by magnitude (a
/// minimum, not a saddle), the step capped at [`MAX_NULL_STEP`].
fn null_space_step(
    setup: &Setup,
    y: &[f64],
    lin: &Linearization,
    gz: &[f64],
    cap: f64,
) -> DVector<f64> {
    // t_n is linear: only −λ·c is curved.
    let lag = |yy: &[f64]| -> f64 {
        let r = setup.residuals(yy);
        -r.iter()
            .zip(lin.lambda.iter())
            .map(|(a, b)| a * b)
            .sum::<f64>()
    };
    let hz = if reference_polish() {
        reduced_hessian_four_point(y, &lin.null, &lag)
    } else {
        reduced_hessian(y, &lin.null, &lag)
    };
    // Positive definite (a minimum, not a saddle): eigenvalues by magnitude, floored. No step
    // when the Hessian has no decomposition (not finite).
    let Some(eig) = bounded_symmetric_eigen(hz) else {
        return DVector::zeros(setup.n);
    };
    let emax = eig
        .eigenvalues
        .iter()
        .fold(0.0_f64, |a, &b| a.max(b.abs()))
        .max(1e-6);
    let mut pz = DVector::zeros(lin.null.len());
    for k in 0..lin.null.len() {
        let e = eig.eigenvalues[k].abs().max(1e-6 * emax);
        let vk = eig.eigenvectors.column(k);
        let g: f64 = vk.iter().zip(gz).map(|(a, b)| a * b).sum();
        pz -= vk * (g / e);
    }
    let mut null_step = DVector::zeros(setup.n);
    for (k, z) in lin.null.iter().enumerate() {
        null_step += z * pz[k];
    }
    let big = null_step.amax();
    if big > cap {
        null_step *= cap / big;
    }
    null_step
}

/// L at y + h·(sa·a + sb·b).
fn shifted(y: &[f64], a: &DVector<f64>, b: &DVector<f64>, sa: f64, sb: f64) -> Vec<f64> {
    y.iter()
        .enumerate()
        .map(|(i, &v)| v + HESSIAN_STEP * (sa * a[i] + sb * b[i]))
        .collect()
}

/// The reduced Hessian Zᵀ∇²L Z by central differences along the null-space basis `null`, the
/// previous stencil (the reference path): four evaluations of L per entry,
/// H_pq ≈ [L(+p+q) − L(+p−q) − L(−p+q) + L(−p−q)] / 4h², nz(nz+1)/2 entries.
fn reduced_hessian_four_point(
    y: &[f64],
    null: &[DVector<f64>],
    lag: &dyn Fn(&[f64]) -> f64,
) -> DMatrix<f64> {
    let nz = null.len();
    let h = HESSIAN_STEP;
    let mut hz = DMatrix::zeros(nz, nz);
    for p in 0..nz {
        for q in p..nz {
            let (a, b) = (&null[p], &null[q]);
            let val = (lag(&shifted(y, a, b, 1.0, 1.0))
                - lag(&shifted(y, a, b, 1.0, -1.0))
                - lag(&shifted(y, a, b, -1.0, 1.0))
                + lag(&shifted(y, a, b, -1.0, -1.0)))
                / (4.0 * h * h);
            hz[(p, q)] = val;
            hz[(q, p)] = val;
        }
    }
    hz
}

/// The reduced Hessian Zᵀ∇²L Z by central differences with shared evaluations: L(y),
/// L(y ± h z_p) for every p, and L(y ± h(z_p + z_q)) for p < q, then
///
///   H_pp ≈ [L(+p) − 2L + L(−p)] / h²,
///   H_pq ≈ [L(+p+q) + L(−p−q) − L(+p) − L(−p) − L(+q) − L(−q) + 2L] / 2h²,
///
/// both exact for quadratics and O(h²) otherwise (Taylor: the odd terms cancel between the
/// ± pairs; the second is ½[D²(z_p+z_q) − D²z_p − D²z_q]). 1 + nz² evaluations instead of the
/// four-point stencil's 2nz(nz+1).
fn reduced_hessian(y: &[f64], null: &[DVector<f64>], lag: &dyn Fn(&[f64]) -> f64) -> DMatrix<f64> {
    let nz = null.len();
    let h = HESSIAN_STEP;
    let zero = DVector::zeros(y.len());
    let l0 = lag(y);
    let plus: Vec<f64> = null
        .iter()
        .map(|a| lag(&shifted(y, a, &zero, 1.0, 0.0)))
        .collect();
    let minus: Vec<f64> = null
        .iter()
        .map(|a| lag(&shifted(y, a, &zero, -1.0, 0.0)))
        .collect();
    let mut hz = DMatrix::zeros(nz, nz);
    for p in 0..nz {
        hz[(p, p)] = (plus[p] - 2.0 * l0 + minus[p]) / (h * h);
        for q in p + 1..nz {
            let (a, b) = (&null[p], &null[q]);
            let both = lag(&shifted(y, a, b, 1.0, 1.0)) + lag(&shifted(y, a, b, -1.0, -1.0));
            let val = (both - plus[p] - minus[p] - plus[q] - minus[q] + 2.0 * l0) / (2.0 * h * h);
            hz[(p, q)] = val;
            hz[(q, p)] = val;
        }
    }
    hz
}

/// Near c = 0: the Gauss–Newton step plus α times `null_step`, pulled back onto c = 0, with α
/// halved until t_n beats the restored point without the null-space step (or, if that cannot
/// be restored, the current one). Without such an α, the restored point itself while c is
/// not yet at its tolerance (α = 0); `None` otherwise. Returns the point and α.
fn optimality_step(
    setup: &Setup,
    y: &[f64],
    lin: &Linearization,
    dy_range: &DVector<f64>,
    null_step: &DVector<f64>,
    c_max: f64,
) -> Option<(Vec<f64>, f64)> {
    let di = setup.duration_index();
    // A trial point: the Gauss–Newton step plus α times the null-space step, pulled back
    // onto c = 0 with the current Jacobian (chord iterations, while they contract).
    let (chords, contraction) = if reference_polish() {
        (REFERENCE_CHORD_ITERATIONS, f64::INFINITY)
    } else {
        (MAX_CHORD_ITERATIONS, CHORD_CONTRACTION)
    };
    let trial_at = |alpha: f64| -> Option<Vec<f64>> {
        let dy = dy_range + null_step * alpha;
        let mut trial = step_to(y, &dy, 1.0);
        let mut last = f64::INFINITY;
        for _ in 0..chords {
            if !setup.valid(&trial) {
                return None;
            }
            let ct = DVector::from_vec(setup.residuals(&trial));
            let now = ct.amax();
            if now <= RESIDUAL_TOLERANCE || now > contraction * last {
                break;
            }
            last = now;
            let corr = lin.restore(&ct);
            for (t, d) in trial.iter_mut().zip(corr.iter()) {
                *t += d;
            }
        }
        let ok = setup.valid(&trial)
            && infeasibility(&setup.residuals(&trial)) <= c_max.max(RESIDUAL_TOLERANCE);
        ok.then_some(trial)
    };
    // The restored point without the null-space step is the baseline the step must beat:
    // making c = 0 exact may itself cost some duration.
    let base = trial_at(0.0);
    let mut alpha = 1.0;
    for _ in 0..30 {
        if let Some(trial) = trial_at(alpha) {
            let beats = match &base {
                Some(b) => trial[di] < b[di],
                None => trial[di] < y[di],
            };
            if beats {
                return Some((trial, alpha));
            }
        }
        alpha *= 0.5;
    }
    base.filter(|_| c_max > RESIDUAL_TOLERANCE)
        .map(|b| (b, 0.0))
}

/// The state of the active-set loop: impulses and active points.
#[derive(Clone)]
struct Active {
    impulses: Vec<Impulse>,
    points: Vec<PointSpec>,
    bounds: Vec<(usize, bool)>,
}

impl Active {
    /// The same Newton problem as `other`: the same impulses and bounds, and the same active
    /// points in any order (their order only orders the equations).
    fn same_structure(&self, other: &Active) -> bool {
        self.impulses == other.impulses
            && self.bounds == other.bounds
            && self.points.len() == other.points.len()
            && self.points.iter().all(|p| other.points.contains(p))
    }
}

/// An active point before it is given unknowns.
#[derive(Debug, Clone, Copy, PartialEq)]
struct PointSpec {
    omega: f64,
    zeta: f64,
    omega_free: bool,
    zeta_free: bool,
    vtol: Vtol,
    bounds: (f64, f64, f64, f64),
    grid_ratio: f64,
}

impl PointSpec {
    fn from_peak(norm: &NormalizedProblem, p: &Peak) -> Self {
        let b = &norm.bands[p.band];
        PointSpec {
            omega: p.omega,
            zeta: p.zeta,
            omega_free: p.omega_free,
            zeta_free: p.zeta_free,
            vtol: Vtol::Band(p.band),
            bounds: (b.omega_lo, b.omega_hi, b.zeta_lo, b.zeta_hi),
            grid_ratio: p.ratio,
        }
    }
}

fn build<'a>(norm: &'a NormalizedProblem, active: &Active) -> (Setup<'a>, Vec<f64>) {
    let m = active.impulses.len();
    let mut y: Vec<f64> = active.impulses[1..].iter().map(|i| i.time).collect();
    y.extend(active.impulses.iter().map(|i| i.amplitude));
    let t_n = active.impulses.last().map_or(1.0, |i| i.time).max(1e-9);
    let mut cons = vec![Con::Sum];
    for (zi, z) in norm.zeros.iter().enumerate() {
        for order in 0..=z.derivatives {
            for part in 0..2 {
                cons.push(Con::Moment {
                    zero: zi,
                    order,
                    part,
                    scale: t_n.powi(order as i32),
                });
            }
        }
    }
    for &(index, upper) in &active.bounds {
        let value = if upper {
            norm.amplitude_max
        } else {
            norm.amplitude_min
        };
        cons.push(Con::Bound {
            index,
            value,
            upper,
        });
    }
    let mut points = Vec::new();
    for (pi, spec) in active.points.iter().enumerate() {
        let omega = if spec.omega_free {
            y.push(spec.omega);
            Coord::Free(y.len() - 1)
        } else {
            Coord::Fixed(spec.omega)
        };
        let zeta = if spec.zeta_free {
            y.push(spec.zeta);
            Coord::Free(y.len() - 1)
        } else {
            Coord::Fixed(spec.zeta)
        };
        points.push(Point {
            omega,
            zeta,
            vtol: spec.vtol,
            bounds: spec.bounds,
            grid_ratio: spec.grid_ratio,
        });
        cons.push(Con::Limit(pi));
        if spec.omega_free {
            cons.push(Con::Stationary {
                point: pi,
                coord: 0,
            });
        }
        if spec.zeta_free {
            cons.push(Con::Stationary {
                point: pi,
                coord: 1,
            });
        }
    }
    let n = y.len();
    (
        Setup {
            norm,
            m,
            points,
            cons,
            n,
        },
        y,
    )
}

/// Number of unknowns minus equations for an active set (negative: overdetermined).
fn freedom(norm: &NormalizedProblem, active: &Active) -> i64 {
    let m = active.impulses.len() as i64;
    let mut unknowns = 2 * m - 1;
    let mut equations = 1 + active.bounds.len() as i64;
    for z in &norm.zeros {
        equations += 2 * (z.derivatives as i64 + 1);
    }
    for p in &active.points {
        unknowns += i64::from(p.omega_free) + i64::from(p.zeta_free);
        equations += 1 + i64::from(p.omega_free) + i64::from(p.zeta_free);
    }
    unknowns - equations
}

/// Polishes the grid solution; `None` when no exact solution with the same structure is found.
///
/// The first structure tried is one impulse per cluster of the grid solution. A cluster
/// spread over more grid points than one impulse between two points explains may be two
/// impulses close together: the structures with the widest one, two, … ([`MAX_SPLITS`])
/// clusters split in two (same amplitude sum, mean time and spread) are tried as well, and the
/// shortest result is kept. When none polishes, the same is tried from the clusters with the
/// grid solution's noise taken for zero ([`clusters_above_noise`]), if they differ, the problem
/// has vibration limits and the grid solution is within [`SECOND_START_MAX_RATIO`] of them.
pub(crate) fn polish(norm: &NormalizedProblem, grid: &GridSolution) -> Option<Vec<Impulse>> {
    // Ranked on the grid solution, which every start shares: scanned once.
    let candidates = candidates(norm, &grid.impulses());
    let found = clusters(grid);
    let polished = polish_clusters(norm, grid, &candidates, &found);
    if polished.is_some() || reference_polish() {
        return polished;
    }
    // The interior-point solution's unused grid points are small, not 0, and a run of them
    // can join impulses into one cluster: the clusters with that noise taken for zero are a
    // second start, tried when the first fails (issue 24: over the convergence grid, 10 of the
    // 24 `si` designs that fell back to the grid solution polish to a few impulses, and one
    // that was infeasible after 8 rounds is designed). The first stays first: it also
    // polishes designs whose small impulses the second drops. Without vibration limits (no
    // candidates: `direct`) a failed polish has its own retry, from a vertex of the program's
    // optimal face (`polished_grid`); over the convergence grid the second start changed no
    // `direct` design and cost six-mode ZVD 4 % in wasm.
    if candidates
        .first()
        .is_none_or(|c| c.grid_ratio > SECOND_START_MAX_RATIO)
    {
        return None;
    }
    let denoised = clusters_above_noise(grid);
    let same = denoised.len() == found.len()
        && denoised
            .iter()
            .zip(&found)
            .all(|(a, b)| a.time == b.time && a.amplitude == b.amplitude);
    if same {
        return None;
    }
    polish_clusters(norm, grid, &candidates, &denoised)
}

/// [`polish`] from the clusters `found`: unsplit, and with the widest one, two, …
/// ([`MAX_SPLITS`]) split in two; the shortest result.
fn polish_clusters(
    norm: &NormalizedProblem,
    grid: &GridSolution,
    candidates: &[PointSpec],
    found: &[Cluster],
) -> Option<Vec<Impulse>> {
    let mut wide: Vec<usize> = (0..found.len())
        .filter(|&i| found[i].spacing > 0.0 && found[i].spread > 0.55 * found[i].spacing)
        .collect();
    crate::sort::sort_indices(&mut wide, &|a, b| {
        let r = |c: &Cluster| c.spread / c.spacing;
        r(&found[b]).total_cmp(&r(&found[a]))
    });
    // Every start is polished and the shortest result kept: one that converges need not be
    // the best (three modes 1 / 3 / 7 Hz, I 0.5: the unsplit start polishes to 13 impulses,
    // 5 ppm longer than the 14 of the start with one cluster split).
    let mut best: Option<Vec<Impulse>> = None;
    for splits in 0..=wide.len().min(MAX_SPLITS) {
        let mut start = Vec::new();
        for (i, c) in found.iter().enumerate() {
            if wide[..splits].contains(&i) {
                start.push(Impulse {
                    time: c.time - c.spread,
                    amplitude: 0.5 * c.amplitude,
                });
                start.push(Impulse {
                    time: c.time + c.spread,
                    amplitude: 0.5 * c.amplitude,
                });
            } else {
                start.push(Impulse {
                    time: c.time,
                    amplitude: c.amplitude,
                });
            }
        }
        if start.len() < 2 {
            return best;
        }
        let t0 = start[0].time;
        for imp in &mut start {
            imp.time = (imp.time - t0).max(0.0);
        }
        if let Some(result) = polish_from(norm, candidates, start) {
            // Every grid solution is itself a feasible shaper, so with exact (sampled)
            // constraints a longer result is a worse local optimum: reject it. (With bands the
            // grid only saw samples and may be shorter than any shaper meeting the whole band.)
            let t_n = result.last().map_or(0.0, |i| i.time);
            let shorter = best
                .as_ref()
                .is_none_or(|b: &Vec<Impulse>| t_n < b.last().map_or(0.0, |i| i.time));
            if (!norm.bands.is_empty() || t_n <= grid.duration * (1.0 + 1e-9)) && shorter {
                best = Some(result);
                if reference_polish() {
                    // As before issue 24: the first start that converged.
                    return best;
                }
            }
        }
    }
    best
}

/// The active-set loop from one starting structure, with the candidate points of
/// [`candidates`].
fn polish_from(
    norm: &NormalizedProblem,
    candidates: &[PointSpec],
    start: Vec<Impulse>,
) -> Option<Vec<Impulse>> {
    let top = candidates.first().map_or(0.0, |c| c.grid_ratio);
    let mut active = initial_active(norm, start, candidates, top);
    let mut retry = Retry {
        dropped_from: None,
        drops: 0,
    };
    // Structures with no exact solution. A drop frees room, and the next restructure refills
    // it, often with the point just dropped: the structure that already failed, solved again
    // the same way (issue 24: 4 of the 9 Newton solves of a three-mode si polish's first
    // start). Such a structure counts as a round and fails at once.
    let mut failed: Vec<Active> = Vec::new();
    for _ in 0..MAX_ACTIVE_SET_ROUNDS {
        // (More equations than unknowns is allowed: degenerate but consistent systems, e.g.
        // a single-mode ZVD that also cancels a mode at an odd multiple of its frequency, are
        // solved by Gauss–Newton in the least-squares sense; inconsistent ones fail there.)
        if active.impulses.len() < 2 {
            return None;
        }
        let known_failure = failed.iter().any(|f| f.same_structure(&active));
        let solved = if known_failure {
            None
        } else {
            let (setup, y0) = build(norm, &active);
            sqp(&setup, y0).map(|solved| (setup, solved))
        };
        let Some((setup, solved)) = solved else {
            if !known_failure {
                failed.push(active.clone());
            }
            if retry.restructure(norm, &mut active, candidates, top) {
                continue;
            }
            return None;
        };
        let imps = setup.impulses(&solved.y);
        if merge_coincident(&mut active, &imps, &setup, &solved.y)
            || fix_amplitude(norm, &mut active, &imps, &setup, &solved.y)
            || release_wrong_sign(&mut active, &imps, &setup, &solved)
        {
            continue;
        }
        // Constraints the result violates: add the worst one.
        if let Some(spec) = worst_violation(norm, &imps) {
            active.impulses = imps;
            update_points(&mut active, &setup, &solved.y);
            // Free coordinates of an existing point may have slid onto the new one's place.
            active.points.push(spec);
            continue;
        }
        return Some(imps);
    }
    None
}

/// A sampled limit as an active point (fixed frequency and damping), with its V/Vtol `ratio`.
fn limit_point(l: &NormalizedLimit, ratio: f64) -> PointSpec {
    PointSpec {
        omega: l.omega,
        zeta: l.zeta,
        omega_free: false,
        zeta_free: false,
        vtol: Vtol::Constant(l.vtol),
        bounds: (l.omega, l.omega, l.zeta, l.zeta),
        grid_ratio: ratio,
    }
}

/// Candidate active points (the sampled limits and the bands' peaks), ranked by V/Vtol on the
/// grid solution `raw`, highest first.
fn candidates(norm: &NormalizedProblem, raw: &[Impulse]) -> Vec<PointSpec> {
    let mut candidates: Vec<PointSpec> = norm
        .limits
        .iter()
        .map(|l| limit_point(l, ratio(raw, l.omega, l.zeta, l.vtol)))
        .collect();
    for (b, band) in norm.bands.iter().enumerate() {
        candidates.extend(
            band_peaks(raw, band, b, None)
                .iter()
                .map(|p| PointSpec::from_peak(norm, p)),
        );
    }
    crate::sort::sort_by(&mut candidates, |a, b| {
        b.grid_ratio.total_cmp(&a.grid_ratio)
    });
    candidates
}

/// The starting structure: amplitudes near a bound pinned to it, and the candidates near the
/// top ratio `top` active (while there is freedom for them).
fn initial_active(
    norm: &NormalizedProblem,
    start: Vec<Impulse>,
    candidates: &[PointSpec],
    top: f64,
) -> Active {
    let range = norm.amplitude_range(start.len());
    let mut active = Active {
        bounds: start
            .iter()
            .enumerate()
            .filter_map(|(i, imp)| {
                if norm.amplitude_min != 0.0
                    && (imp.amplitude - norm.amplitude_min).abs() < 0.02 * range
                {
                    Some((i, false))
                } else if (norm.amplitude_max - imp.amplitude).abs() < 0.02 * range {
                    Some((i, true))
                } else {
                    None
                }
            })
            .collect(),
        impulses: start,
        points: Vec::new(),
    };
    // The grid solution sits at a level ≤ 1 at its samples, but a band's humps between samples
    // may exceed 1: measure nearness from min(top, 1).
    for c in candidates {
        if c.grid_ratio >= top.min(1.0) - ACTIVE_BAND && freedom(norm, &active) > 0 {
            active.points.push(*c);
        }
    }
    active
}

/// What the loop tries when a structure has no exact solution: the active points before the
/// first drop, and how many drops were tried.
struct Retry {
    dropped_from: Option<Vec<PointSpec>>,
    drops: usize,
}

impl Retry {
    /// No exact solution with this structure: if there is room for another constraint,
    /// activates the next candidate (by V/Vtol on the grid solution); otherwise (too many,
    /// inconsistent constraints) leaves one of them out, in turn, starting from the one the
    /// grid solution held furthest below Vtol. False when nothing is left to try.
    fn restructure(
        &mut self,
        norm: &NormalizedProblem,
        active: &mut Active,
        candidates: &[PointSpec],
        top: f64,
    ) -> bool {
        let next = candidates
            .iter()
            .find(|c| c.grid_ratio >= 0.5 * top && !active.points.contains(c));
        if let Some(c) = next {
            if freedom(norm, active) > 0 {
                active.points.push(*c);
                return true;
            }
        }
        let base = self
            .dropped_from
            .get_or_insert_with(|| active.points.clone());
        let mut order: Vec<usize> = (0..base.len()).collect();
        crate::sort::sort_indices(&mut order, &|a, b| {
            base[a].grid_ratio.total_cmp(&base[b].grid_ratio)
        });
        match order.get(self.drops) {
            Some(&k) if self.drops < MAX_DROPS => {
                let mut points = base.clone();
                points.remove(k);
                active.points = points;
                self.drops += 1;
                true
            }
            _ => false,
        }
    }
}

/// Two impulses that converged onto one time are one impulse: merges them (true: solve again).
fn merge_coincident(active: &mut Active, imps: &[Impulse], setup: &Setup, y: &[f64]) -> bool {
    let t_n = imps.last().map_or(0.0, |i| i.time);
    let Some(k) = (1..imps.len()).find(|&k| imps[k].time - imps[k - 1].time < 1e-7 * t_n) else {
        return false;
    };
    let mut merged = imps.to_vec();
    let (a, b) = (merged[k - 1], merged[k]);
    let sum = a.amplitude + b.amplitude;
    merged[k - 1] = Impulse {
        time: if sum != 0.0 {
            (a.time * a.amplitude + b.time * b.amplitude) / sum
        } else {
            a.time
        },
        amplitude: sum,
    };
    merged.remove(k);
    active.impulses = merged;
    active.bounds = shift_bounds(&active.bounds, k);
    update_points(active, setup, y);
    true
}

/// Amplitudes out of bounds: drops the impulse furthest out if it wants to vanish (lower bound
/// 0), otherwise pins it to the bound (true: solve again).
fn fix_amplitude(
    norm: &NormalizedProblem,
    active: &mut Active,
    imps: &[Impulse],
    setup: &Setup,
    y: &[f64],
) -> bool {
    let tol = 1e-12;
    let Some((i, imp)) = imps
        .iter()
        .enumerate()
        .filter(|(_, imp)| {
            imp.amplitude < norm.amplitude_min - tol || imp.amplitude > norm.amplitude_max + tol
        })
        .max_by(|a, b| {
            let ex = |x: &Impulse| {
                (norm.amplitude_min - x.amplitude).max(x.amplitude - norm.amplitude_max)
            };
            ex(a.1).total_cmp(&ex(b.1))
        })
    else {
        return false;
    };
    let upper = imp.amplitude > norm.amplitude_max;
    active.impulses = imps.to_vec();
    if !upper && norm.amplitude_min == 0.0 {
        active.impulses.remove(i);
        active.bounds = shift_bounds(&active.bounds, i);
        if i == 0 {
            let t0 = active.impulses.first().map_or(0.0, |x| x.time);
            for x in &mut active.impulses {
                x.time -= t0;
            }
        }
    } else {
        active.bounds.push((i, upper));
    }
    update_points(active, setup, y);
    true
}

/// Multipliers of the inequalities: with L = t_n − λ·c, an inequality c ≤ 0 needs λ ≤ 0
/// (V/Vtol − 1 ≤ 0; A − A_max ≤ 0) and c = A − A_min ≥ 0 needs λ ≥ 0. Releases the constraint
/// whose multiplier is most wrong (true: solve again).
fn release_wrong_sign(
    active: &mut Active,
    imps: &[Impulse],
    setup: &Setup,
    solved: &Solved,
) -> bool {
    let lmax = solved.lambda.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
    let mut worst: Option<(usize, f64)> = None;
    for (k, con) in setup.cons.iter().enumerate() {
        let wrong = match con {
            Con::Limit(_) | Con::Bound { upper: true, .. } => solved.lambda[k],
            Con::Bound { upper: false, .. } => -solved.lambda[k],
            _ => continue,
        };
        if wrong > 1e-7 * lmax.max(1e-12) && worst.is_none_or(|(_, w)| wrong > w) {
            worst = Some((k, wrong));
        }
    }
    let Some((k, _)) = worst else {
        return false;
    };
    active.impulses = imps.to_vec();
    update_points(active, setup, &solved.y);
    match setup.cons[k] {
        Con::Limit(p) => {
            active.points.remove(p);
        }
        Con::Bound { index, upper, .. } => {
            active.bounds.retain(|&b| b != (index, upper));
        }
        _ => {}
    }
    true
}

/// The constraint `imps` violates most (a sampled limit or a band's peak), if any.
fn worst_violation(norm: &NormalizedProblem, imps: &[Impulse]) -> Option<PointSpec> {
    let mut worst: Option<(PointSpec, f64)> = None;
    for l in &norm.limits {
        let r = ratio(imps, l.omega, l.zeta, l.vtol);
        if r > 1.0 + CHECK_TOLERANCE * 0.1 && worst.is_none_or(|(_, w)| r > w) {
            worst = Some((limit_point(l, r), r));
        }
    }
    for (b, band) in norm.bands.iter().enumerate() {
        for p in band_peaks(imps, band, b, None) {
            if p.ratio > 1.0 + CHECK_TOLERANCE * 0.1 && worst.is_none_or(|(_, w)| p.ratio > w) {
                worst = Some((PointSpec::from_peak(norm, &p), p.ratio));
            }
        }
    }
    worst.map(|(spec, _)| spec)
}

fn shift_bounds(bounds: &[(usize, bool)], removed: usize) -> Vec<(usize, bool)> {
    bounds
        .iter()
        .filter(|&&(i, _)| i != removed)
        .map(|&(i, u)| (if i > removed { i - 1 } else { i }, u))
        .collect()
}

/// Copies the solved free coordinates back into the point specs.
fn update_points(active: &mut Active, setup: &Setup, y: &[f64]) {
    for (spec, pt) in active.points.iter_mut().zip(&setup.points) {
        spec.omega = setup.coord(pt.omega, y);
        spec.zeta = setup.coord(pt.zeta, y);
    }
}

/// Makes the equalities (Σ A = 1 and the zero moments) hold exactly at fixed times by the
/// smallest change of the amplitudes (least-norm correction through the pseudo-inverse).
pub(crate) fn project_equalities(norm: &NormalizedProblem, impulses: &mut [Impulse]) {
    let n = impulses.len();
    let t_n = impulses.last().map_or(0.0, |i| i.time);
    let mut rows: Vec<Vec<f64>> = vec![vec![1.0; n]];
    let mut rhs = vec![1.0];
    for z in &norm.zeros {
        for order in 0..=z.derivatives {
            for part in 0..2 {
                let row: Vec<f64> = impulses
                    .iter()
                    .map(|imp| {
                        let p = impulse_phasor(imp.time, t_n, z.omega, z.zeta);
                        p[part] * imp.time.powi(order as i32)
                    })
                    .collect();
                let scale = row.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
                if scale > 0.0 {
                    rows.push(row.iter().map(|v| v / scale).collect());
                    rhs.push(0.0);
                }
            }
        }
    }
    let e = DMatrix::from_fn(rows.len(), n, |r, c| rows[r][c]);
    let a = DVector::from_iterator(n, impulses.iter().map(|i| i.amplitude));
    let residual = DVector::from_vec(rhs) - &e * &a;
    let Some(svd) = bounded_svd(&e * e.transpose()) else {
        return;
    };
    if let Ok(w) = svd.solve(&residual, 1e-12) {
        let delta = e.transpose() * w;
        for (imp, d) in impulses.iter_mut().zip(delta.iter()) {
            imp.amplitude += d;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A matrix with a NaN or an infinity has no decomposition (nalgebra's own `svd` and
    /// `symmetric_eigen` never return on it), and a finite one gets nalgebra's own, bit for bit
    /// (the SVD of a 5 × 7 matrix, the eigen-decomposition of its 5 × 5 Gram matrix).
    #[wasm_bindgen_test::wasm_bindgen_test(unsupported = test)]
    fn decompositions_end_on_any_matrix() {
        let m = DMatrix::from_fn(5, 7, |r, c| {
            ((r * 7 + c) as f64 * 0.37).sin() + 0.1 * r as f64
        });
        let ours = bounded_svd(m.clone()).expect("a finite matrix");
        let theirs = m.clone().svd(true, true);
        assert_eq!(ours.singular_values, theirs.singular_values);
        assert_eq!(ours.u, theirs.u);
        assert_eq!(ours.v_t, theirs.v_t);
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut b = m.clone();
            b[(2, 3)] = bad;
            assert!(bounded_svd(b).is_none(), "{bad}");
        }
        let sym = &m * m.transpose();
        let ours = bounded_symmetric_eigen(sym.clone()).expect("a finite matrix");
        let theirs = sym.clone().symmetric_eigen();
        assert_eq!(ours.eigenvalues, theirs.eigenvalues);
        assert_eq!(ours.eigenvectors, theirs.eigenvectors);
        let mut bad = sym;
        bad[(1, 1)] = f64::NAN;
        assert!(bounded_symmetric_eigen(bad).is_none());
    }

    /// A smooth non-quadratic test function with a closed-form Hessian:
    /// f(y) = e^{y₀} sin(y₁) + y₀² y₂ + cos(y₁ y₂).
    fn f(y: &[f64]) -> f64 {
        y[0].exp() * y[1].sin() + y[0] * y[0] * y[2] + (y[1] * y[2]).cos()
    }

    fn hessian(y: &[f64]) -> DMatrix<f64> {
        let (a, b, c) = (y[0], y[1], y[2]);
        let (s, k) = ((b * c).sin(), (b * c).cos());
        DMatrix::from_row_slice(
            3,
            3,
            &[
                a.exp() * b.sin() + 2.0 * c,
                a.exp() * b.cos(),
                2.0 * a,
                a.exp() * b.cos(),
                -a.exp() * b.sin() - c * c * k,
                -s - b * c * k,
                2.0 * a,
                -s - b * c * k,
                -b * b * k,
            ],
        )
    }

    /// Both stencils against Zᵀ H Z in closed form, along an orthonormal basis that is not the
    /// unit vectors (as the null-space bases are). O(h²) with h = 1e-4: errors ~1e-8, plus
    /// rounding ε·|f|/h² ~ 1e-8.
    #[test]
    fn reduced_hessian_matches_closed_form() {
        let y = [0.3, 0.7, -0.4];
        let r = 0.5_f64.sqrt();
        let null = vec![
            DVector::from_vec(vec![r, r, 0.0]),
            DVector::from_vec(vec![r, -r, 0.0]),
            DVector::from_vec(vec![0.0, 0.0, 1.0]),
        ];
        let z = DMatrix::from_columns(&null);
        let exact = z.transpose() * hessian(&y) * &z;
        let shared = reduced_hessian(&y, &null, &f);
        let four = reduced_hessian_four_point(&y, &null, &f);
        for (p, q) in (0..3).flat_map(|p| (0..3).map(move |q| (p, q))) {
            let e = exact[(p, q)];
            assert!(
                (shared[(p, q)] - e).abs() < 1e-6,
                "shared ({p},{q}): {} vs {e}",
                shared[(p, q)]
            );
            assert!(
                (four[(p, q)] - e).abs() < 1e-6,
                "four-point ({p},{q}): {} vs {e}",
                four[(p, q)]
            );
        }
    }
    /// Every Jacobian column that moves one impulse alone is computed from the iterate's kept
    /// factors, every column that moves an active point's free ω or ζ from the iterate's other
    /// sums; under `cfg(test)` each such column is also computed in full and must equal it
    /// to the bit (the assertion in [`Setup::jacobian`]). These problems take the polish through
    /// bands over one and three damped modes (the decay factors), negative amplitudes (bound
    /// rows), zero-vibration constraints with their moments (a `direct` ZVD over three) and a
    /// damping range (free ζ).
    #[test]
    fn jacobian_columns_from_kept_factors_are_the_full_ones() {
        use crate::solve::{minimum_duration, Band, Problem, Tolerance, ZeroVibration};
        let band = |f: f64, zeta: f64, half: f64| Band {
            from_hz: f * (1.0 - half),
            to_hz: f * (1.0 + half),
            damping_from: zeta,
            damping_to: zeta,
            tolerance: Tolerance::constant(0.05).unwrap(),
        };
        let problem = |zeros: Vec<ZeroVibration>, bands: Vec<Band>, amplitude_min: f64| Problem {
            zeros,
            limits: Vec::new(),
            bands,
            amplitude_min,
            amplitude_max: 1.0,
            max_duration: None,
        };
        let zvd = |f: f64| ZeroVibration {
            frequency_hz: f,
            damping: 0.02,
            derivatives: 1,
        };
        let problems = [
            problem(Vec::new(), vec![band(0.5, 0.002, 0.35)], 0.0),
            problem(
                Vec::new(),
                vec![
                    band(1.2, 0.02, 0.15),
                    band(3.4, 0.02, 0.15),
                    band(7.9, 0.02, 0.15),
                ],
                0.0,
            ),
            problem(Vec::new(), vec![band(1.0, 0.05, 0.25)], -0.2),
            problem(vec![zvd(1.2), zvd(3.4), zvd(7.9)], Vec::new(), 0.0),
            // A damping range: active points with a free ζ as well as a free ω.
            problem(
                Vec::new(),
                vec![Band {
                    damping_from: 0.01,
                    damping_to: 0.08,
                    ..band(2.0, 0.0, 0.2)
                }],
                0.0,
            ),
        ];
        // The polish runs on all five (its Jacobians checked); with negative amplitudes it
        // ends on the grid solution here.
        let polished: Vec<bool> = problems
            .iter()
            .map(|p| minimum_duration(p).unwrap().polished)
            .collect();
        assert_eq!(polished, [true, true, false, true, true]);
    }
}
