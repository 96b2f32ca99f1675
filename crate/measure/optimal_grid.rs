//! The custom shaper by a convex program on a time grid (Cargo feature `solver`).
//!
//! With the impulse times fixed on a grid t₀ = 0 < … < t_N = T (the last one used, so that
//! Klipper's V — referenced to the last impulse — is the grid's) and the centroid fixed at c
//! (Σ Aⱼtⱼ = c), Klipper's smoothing is the larger of two **linear** functions of the amplitudes
//! (`_get_shaper_smoothing`: the 180° offset a/2 Σ Aⱼ(tⱼ − c)², and the 90° offset √2 Σ over
//! tⱼ ≥ c of Aⱼ(scv + a/2 (tⱼ − c))(tⱼ − c)); and "no remaining vibration" — every bin above
//! Klipper's threshold P_max/20 left below it, V(f_k, ζ)·P_k ≤ P_max/20, for every scored damping
//! ratio and frequency factor — is a second-order cone |Σ Aⱼ wⱼ(f_k, ζ)| ≤ P_max/(20 P_k) on the
//! amplitudes. Minimising the smoothing under R = 0 is a second-order-cone program (Clarabel),
//! globally optimal on the grid for the given (T, c). A sweep over T and c/T, the grid solution
//! merged into its clusters of impulses ([`crate::solve::merge`]), the firmware's impulse count
//! enforced by dropping the smallest, then the same Nelder–Mead polish as the continuation
//! (which may trade a little R for less smoothing).

use crate::error::Result;
use crate::shaper::{Impulse, Shaper};
use crate::solve::{merge, GridSolution};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use std::f64::consts::{PI, SQRT_2};

/// Grid intervals on [0, T].
const GRID_INTERVALS: usize = 40;
/// Durations tried, relative to the start's.
const DURATIONS: [f64; 5] = [0.9, 1.0, 1.1, 1.2, 1.35];
/// Centroids tried, relative to the duration.
const CENTROIDS: [f64; 4] = [0.38, 0.42, 0.46, 0.5];

/// Bins above the threshold: (frequency Hz, bound on V there), per scored case (ζ, factor).
pub(super) struct Cones {
    pub(super) bins: Vec<(f64, f64)>,
    pub(super) cases: Vec<(f64, f64)>,
}

/// The conic program's constraints `A x + s = b`, `s ∈ K` (x: the amplitudes on the grid, then
/// the smoothing bound).
struct Program {
    a: CscMatrix<f64>,
    b: Vec<f64>,
    cones: Vec<SupportedConeT<f64>>,
}

/// Sparse triplets of the constraint matrix, its right-hand side, and the row count.
#[derive(Default)]
struct Triplets {
    rows: Vec<usize>,
    cols: Vec<usize>,
    vals: Vec<f64>,
    b: Vec<f64>,
}

impl Triplets {
    fn push(&mut self, r: usize, c: usize, v: f64) {
        if v != 0.0 {
            self.rows.push(r);
            self.cols.push(c);
            self.vals.push(v);
        }
    }
}

/// The program of [`solve`] on the grid `times` (last = T) with centroid `centroid`, or `None`
/// when a coefficient is not finite.
fn program(
    cones: &Cones,
    times: &[f64],
    centroid: f64,
    scv: f64,
    last_min: f64,
) -> Option<Program> {
    let n_amp = times.len();
    let t_end = times[n_amp - 1];
    let s_col = n_amp;
    let mut t = Triplets::default();
    // Zero cone: Σ A = 1, Σ A t / T = c / T.
    let mut row = 0;
    for (j, &tj) in times.iter().enumerate() {
        t.push(row, j, 1.0);
        t.push(row + 1, j, tj / t_end);
    }
    t.b.push(1.0);
    t.b.push(centroid / t_end);
    row += 2;
    // Nonnegative: A ≥ 0 (the last ≥ last_min), s ≥ o180, s ≥ o90 (in mm, as Klipper's).
    for j in 0..n_amp {
        t.push(row, j, -1.0);
        t.b.push(if j == n_amp - 1 { -last_min } else { 0.0 });
        row += 1;
    }
    let half = 0.5 * crate::smoothing::KLIPPER_ACCEL;
    for (j, &tj) in times.iter().enumerate() {
        let d = tj - centroid;
        t.push(row, j, half * d * d);
        if tj >= centroid {
            t.push(row + 1, j, SQRT_2 * (scv + half * d) * d);
        }
    }
    t.push(row, s_col, -1.0);
    t.push(row + 1, s_col, -1.0);
    t.b.push(0.0);
    t.b.push(0.0);
    row += 2;
    let n_nonneg = n_amp + 2;
    // Second-order cones: (bound, Re, Im) of Klipper's V sum at each bin and case.
    let mut n_soc = 0;
    for &(zeta, factor) in &cones.cases {
        let damped = (1.0 - zeta * zeta).sqrt();
        for &(f, bound) in &cones.bins {
            let w = 2.0 * PI * f * factor;
            t.b.push(bound);
            row += 1;
            for (j, &tj) in times.iter().enumerate() {
                let decay = (-zeta * w * (t_end - tj)).exp();
                let (sn, cs) = (w * damped * tj).sin_cos();
                t.push(row, j, -decay * cs);
                t.push(row + 1, j, -decay * sn);
            }
            t.b.push(0.0);
            t.b.push(0.0);
            row += 2;
            n_soc += 1;
        }
    }
    if t.vals.iter().chain(t.b.iter()).any(|v| !v.is_finite()) {
        return None;
    }
    let mut k = vec![
        SupportedConeT::ZeroConeT(2),
        SupportedConeT::NonnegativeConeT(n_nonneg),
    ];
    k.extend((0..n_soc).map(|_| SupportedConeT::SecondOrderConeT(3)));
    Some(Program {
        a: CscMatrix::new_from_triplets(row, n_amp + 1, t.rows, t.cols, t.vals),
        b: t.b,
        cones: k,
    })
}

/// The least-smoothing amplitudes on the grid with R = 0, or `None` when infeasible.
fn solve(
    cones: &Cones,
    t_end: f64,
    centroid: f64,
    scv: f64,
    last_min: f64,
) -> Option<Vec<Impulse>> {
    solve_on(cones, GRID_INTERVALS, t_end, centroid, scv, last_min).map(|(_, imps)| imps)
}

/// [`solve`] on `intervals` grid intervals; also the program's optimum (the least smoothing on
/// the grid, mm, before merging).
fn solve_on(
    cones: &Cones,
    intervals: usize,
    t_end: f64,
    centroid: f64,
    scv: f64,
    last_min: f64,
) -> Option<(f64, Vec<Impulse>)> {
    let n_amp = intervals + 1;
    let times: Vec<f64> = (0..n_amp)
        .map(|j| t_end * j as f64 / intervals as f64)
        .collect();
    let prog = program(cones, &times, centroid, scv, last_min)?;
    let n = n_amp + 1;
    let mut q = vec![0.0; n];
    q[n_amp] = 1.0;
    let p = CscMatrix::zeros((n, n));
    let settings = DefaultSettings {
        verbose: false,
        max_iter: 100,
        presolve_enable: false,
        tol_gap_abs: 1e-8,
        tol_gap_rel: 1e-8,
        tol_feas: 1e-8,
        ..DefaultSettings::default()
    };
    let mut solver = DefaultSolver::new(&p, &q, &prog.a, &prog.b, &prog.cones, settings).ok()?;
    solver.solve();
    if !matches!(
        solver.solution.status,
        SolverStatus::Solved | SolverStatus::AlmostSolved
    ) {
        return None;
    }
    let amplitudes: Vec<f64> = solver.solution.x[..n_amp]
        .iter()
        .map(|a| a.max(0.0))
        .collect();
    let least = solver.solution.x[n_amp];
    let grid = GridSolution {
        duration: t_end,
        times,
        amplitudes,
    };
    Some((least, merge(&grid)))
}

/// At most `max_n` impulses: the smallest dropped, the rest renormalised; `None` if fewer
/// than two remain.
fn limited(mut imps: Vec<Impulse>, max_n: usize) -> Option<Shaper> {
    while imps.len() > max_n {
        let k = (0..imps.len())
            .min_by(|&a, &b| imps[a].amplitude.total_cmp(&imps[b].amplitude))
            .unwrap_or(0);
        imps.remove(k);
    }
    if imps.len() < 2 {
        return None;
    }
    Shaper::new(imps).ok()?.normalized().ok()
}

/// Grid-program starts around `duration` (the best mainline shaper's), best-smoothing first.
pub(super) fn starts(
    cones: &Cones,
    duration: f64,
    scv: f64,
    last_min: f64,
    max_n: usize,
) -> Result<Vec<Shaper>> {
    let mut out: Vec<(f64, Shaper)> = Vec::new();
    for &dt in &DURATIONS {
        for &dc in &CENTROIDS {
            let t_end = dt * duration;
            let Some(imps) = solve(cones, t_end, dc * t_end, scv, last_min) else {
                continue;
            };
            if let Some(s) = limited(imps, max_n) {
                let sm = crate::smoothing::smoothing(&s, crate::smoothing::KLIPPER_ACCEL, scv)?;
                out.push((sm, s));
            }
        }
    }
    crate::sort::sort_by(&mut out, |a, b| a.0.total_cmp(&b.0));
    Ok(out.into_iter().map(|(_, s)| s).collect())
}

/// Grid intervals of [`least_smoothing`].
const BOUND_INTERVALS: usize = 60;

/// The least smoothing (mm) with no remaining vibration (R = 0) of any shaper whose impulses lie
/// on a [`BOUND_INTERVALS`]-interval grid of its duration, whatever their number, the last
/// carrying at least `last_min`: the program of [`solve`] minimised over the duration (from
/// ½ to 3 times `duration`) and the centroid (0.2 to 0.6 of the duration), a coarse sweep then
/// two finer ones around the best. Klipper's score of such a shaper is 0.01 × its smoothing,
/// so 0.01 × this is the best score any R = 0 shaper on the grid reaches; `None` when no
/// (duration, centroid) is feasible. Returns (smoothing, duration s, merged impulses).
pub(super) fn least_smoothing(
    cones: &Cones,
    duration: f64,
    scv: f64,
    last_min: f64,
) -> Option<(f64, f64, Vec<Impulse>)> {
    let mut best: Option<(f64, f64, f64, Vec<Impulse>)> = None;
    let try_at = |dt: f64, dc: f64, best: &mut Option<(f64, f64, f64, Vec<Impulse>)>| {
        if !(0.05..=0.95).contains(&dc) || dt <= 0.0 {
            return;
        }
        let t_end = dt * duration;
        if let Some((s, imps)) = solve_on(cones, BOUND_INTERVALS, t_end, dc * t_end, scv, last_min)
        {
            if best.as_ref().is_none_or(|b| s < b.0) {
                *best = Some((s, dt, dc, imps));
            }
        }
    };
    let (mut step_t, mut step_c) = (0.125, 0.05);
    let mut dt = 0.5;
    while dt <= 3.0 + 1e-9 {
        let mut dc = 0.2;
        while dc <= 0.6 + 1e-9 {
            try_at(dt, dc, &mut best);
            dc += step_c;
        }
        dt += step_t;
    }
    for _ in 0..2 {
        let (t0, c0) = best.as_ref().map(|b| (b.1, b.2))?;
        step_t /= 3.0;
        step_c /= 3.0;
        for i in -2..=2 {
            for j in -2..=2 {
                try_at(
                    t0 + f64::from(i) * step_t,
                    c0 + f64::from(j) * step_c,
                    &mut best,
                );
            }
        }
    }
    best.map(|(s, dt, _, imps)| (s, dt * duration, imps))
}
