//! Linear time-invariant plants driven by a piecewise-polynomial command, simulated exactly.
//!
//! The plant is x' = A x + E w(t), where w = (u, u', u'', …) is the command and its
//! derivatives. Between knots the command is a polynomial, so w' = S w (S shifts each
//! derivative down one row) and the augmented state z = (x, w) obeys z' = M z with
//! M = [[A, E], [0, S]]: over a step h the exact update is z(t + h) = e^{Mh} z(t) (the matrix
//! exponential, computed by nalgebra's Padé scaling-and-squaring). A knot adds its jumps to w at
//! its own time τ, so its contribution at the next sample t is e^{M(t − τ)} (impulse, jumps).
//! Hence the response is exact (to rounding) at any sample rate, for any command built from
//! polynomial pieces; the states are split into independent diagonal blocks (one per mode) so
//! the matrices stay small.
//!
//! Outputs are rows y = C x + D w: base position/velocity/acceleration and endpoint
//! position/velocity/acceleration.

use crate::command::{Cursor, Piecewise, ORDER};
use crate::error::{Error, Result};
use nalgebra::DMatrix;
use std::collections::HashMap;

/// Number of output rows of an [`Lti`] plant.
pub const OUTPUTS: usize = 6;
/// Output row: base position.
pub const BASE_POSITION: usize = 0;
/// Output row: base velocity.
pub const BASE_VELOCITY: usize = 1;
/// Output row: base acceleration.
pub const BASE_ACCELERATION: usize = 2;
/// Output row: endpoint position.
pub const ENDPOINT: usize = 3;
/// Output row: endpoint velocity.
pub const ENDPOINT_VELOCITY: usize = 4;
/// Output row: endpoint acceleration.
pub const ENDPOINT_ACCELERATION: usize = 5;

/// A linear plant x' = A x + E w with outputs C x + D w (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Lti {
    /// State matrix, n × n.
    pub a: DMatrix<f64>,
    /// Input matrix, n × [`ORDER`]: column k multiplies the command's k-th derivative.
    pub e: DMatrix<f64>,
    /// Output matrix, [`OUTPUTS`] × n.
    pub c: DMatrix<f64>,
    /// Feedthrough, [`OUTPUTS`] × [`ORDER`].
    pub d: DMatrix<f64>,
    /// Independent diagonal blocks of A as (first state, number of states); E may couple
    /// each block only to w.
    pub blocks: Vec<(usize, usize)>,
}

/// The exact one-step maps of one block for a step h: x ← Φ x + Γ w.
#[derive(Debug, Clone)]
struct BlockMaps {
    phi: Vec<f64>,   // m × m, row-major
    gamma: Vec<f64>, // m × q, row-major
}

/// One output row as (state index, coefficient) and (command derivative, coefficient) pairs.
type SparseRow = (Vec<(usize, f64)>, Vec<(usize, f64)>);

/// Samples of the six outputs and the final state.
#[derive(Debug, Clone, PartialEq)]
pub struct LtiResponse {
    /// Output rows (see the row constants), each one value per sample.
    pub outputs: [Vec<f64>; OUTPUTS],
    /// The state at each sample, n values per sample (row-major), if requested.
    pub states: Option<Vec<f64>>,
}

impl Lti {
    /// Number of states.
    pub fn states(&self) -> usize {
        self.a.nrows()
    }

    fn block_maps(&self, (start, m): (usize, usize), q: usize, h: f64) -> Result<BlockMaps> {
        let size = m + q;
        let mut big = DMatrix::<f64>::zeros(size, size);
        for i in 0..m {
            for j in 0..m {
                big[(i, j)] = self.a[(start + i, start + j)] * h;
            }
            for k in 0..q {
                big[(i, m + k)] = self.e[(start + i, k)] * h;
            }
        }
        for k in 0..q.saturating_sub(1) {
            big[(m + k, m + k + 1)] = h;
        }
        if big.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid(
                "plant",
                "the plant's matrices are not finite at this sample period",
            ));
        }
        let ex = expm(&big);
        if ex.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid(
                "samplePeriod",
                "the plant's response overflows over one sample period (unstable plant?)",
            ));
        }
        let mut phi = vec![0.0; m * m];
        let mut gamma = vec![0.0; m * q];
        for i in 0..m {
            for j in 0..m {
                phi[i * m + j] = ex[(i, j)];
            }
            for k in 0..q {
                gamma[i * q + k] = ex[(i, m + k)];
            }
        }
        Ok(BlockMaps { phi, gamma })
    }

    /// The state jump a knot causes: a jump Jⱼ in the command's j-th derivative is a Dirac
    /// Jⱼδ in derivative j + 1, which E turns into the state jump E[:, j+1]·Jⱼ. A Dirac's
    /// derivative (E reading derivative ≥ j + 2 of a jump in j) is rejected.
    /// Written into `imp` (one entry per state), reused across knots.
    fn impulse(&self, jumps: &[f64; ORDER], time: f64, imp: &mut [f64]) -> Result<()> {
        imp.iter_mut().for_each(|v| *v = 0.0);
        for (j, &jump) in jumps.iter().enumerate() {
            if jump == 0.0 {
                continue;
            }
            for k in j + 1..ORDER {
                let col = self.e.column(k);
                if col.iter().all(|&v| v == 0.0) {
                    continue;
                }
                if k > j + 1 {
                    let what = ["position", "velocity", "acceleration", "jerk"]
                        .get(j)
                        .copied()
                        .unwrap_or("a derivative");
                    return Err(Error::invalid(
                        "command",
                        format!(
                            "the command's {what} jumps at t = {time} s, which this plant (driven \
                             by a higher derivative of the command, e.g. force = mass × \
                             acceleration) cannot follow with a finite input; use a smoother \
                             command (ramp, trapezoid, S-curve or profile)"
                        ),
                    ));
                }
                for (s, v) in imp.iter_mut().zip(col.iter()) {
                    *s += v * jump;
                }
            }
        }
        Ok(())
    }

    /// Exact response to `command` at t = k·`sample_period`, k = 0 … `samples` − 1. The plant
    /// starts at rest (x = 0) before the command's first knot.
    pub fn respond(
        &self,
        command: &Piecewise,
        sample_period: f64,
        samples: usize,
        keep_states: bool,
    ) -> Result<LtiResponse> {
        let n = self.states();
        let q = command.degree() + 1;
        let maps: Vec<BlockMaps> = self
            .blocks
            .iter()
            .map(|&b| self.block_maps(b, q, sample_period))
            .collect::<Result<_>>()?;
        let mut cache: HashMap<u64, Vec<BlockMaps>> = HashMap::new();
        let mut x = vec![0.0; n];
        let mut xn = vec![0.0; n];
        let mut imp = vec![0.0; n];
        let mut outputs: [Vec<f64>; OUTPUTS] = Default::default();
        for o in outputs.iter_mut() {
            o.reserve_exact(samples);
        }
        let mut states = keep_states.then(|| Vec::with_capacity(n * samples));
        let mut cursor = Cursor::new(command);
        let knots = command.knots();
        // Outputs as sparse rows: (state index, coefficient) and (derivative, coefficient).
        let sparse: Vec<SparseRow> = (0..OUTPUTS)
            .map(|row| {
                (
                    (0..n)
                        .filter(|&j| self.c[(row, j)] != 0.0)
                        .map(|j| (j, self.c[(row, j)]))
                        .collect(),
                    (0..q)
                        .filter(|&kk| self.d[(row, kk)] != 0.0)
                        .map(|kk| (kk, self.d[(row, kk)]))
                        .collect(),
                )
            })
            .collect();
        let mut w_prev = [0.0; ORDER];
        for k in 0..samples {
            let t = k as f64 * sample_period;
            // Advance x from t_prev to t.
            if k > 0 {
                for (bm, &(start, m)) in maps.iter().zip(&self.blocks) {
                    if m == 2 {
                        // A mode (the common block): unrolled, no inner loops over m.
                        let (x0, x1) = (x[start], x[start + 1]);
                        let (p, g) = (&bm.phi, &bm.gamma);
                        let (mut s0, mut s1) = (p[0] * x0 + p[1] * x1, p[2] * x0 + p[3] * x1);
                        for (kk, wv) in w_prev[..q].iter().enumerate() {
                            s0 += g[kk] * wv;
                            s1 += g[q + kk] * wv;
                        }
                        xn[start] = s0;
                        xn[start + 1] = s1;
                        continue;
                    }
                    let xb = &x[start..start + m];
                    for (i, xo) in xn[start..start + m].iter_mut().enumerate() {
                        let phi = &bm.phi[i * m..(i + 1) * m];
                        let gam = &bm.gamma[i * q..(i + 1) * q];
                        let mut s = 0.0;
                        for (p, xv) in phi.iter().zip(xb) {
                            s += p * xv;
                        }
                        for (g, wv) in gam.iter().zip(&w_prev[..q]) {
                            s += g * wv;
                        }
                        *xo = s;
                    }
                }
                std::mem::swap(&mut x, &mut xn);
            }
            // Knots in (t_prev, t].
            while let Some(knot) = knots.get(cursor.next_index()) {
                if knot.time > t {
                    break;
                }
                let delta = t - knot.time;
                self.impulse(&knot.jumps, knot.time, &mut imp)?;
                if delta == 0.0 {
                    for (xi, v) in x.iter_mut().zip(&imp) {
                        *xi += v;
                    }
                } else {
                    let key = delta.to_bits();
                    if !cache.contains_key(&key) {
                        if cache.len() > 4096 {
                            cache.clear();
                        }
                        let m: Vec<BlockMaps> = self
                            .blocks
                            .iter()
                            .map(|&b| self.block_maps(b, q, delta))
                            .collect::<Result<_>>()?;
                        cache.insert(key, m);
                    }
                    if let Some(dm) = cache.get(&key) {
                        for (b, &(start, m)) in self.blocks.iter().enumerate() {
                            let bm = &dm[b];
                            for i in 0..m {
                                let mut s = 0.0;
                                for j in 0..m {
                                    s += bm.phi[i * m + j] * imp[start + j];
                                }
                                for kk in 0..q {
                                    s += bm.gamma[i * q + kk] * knot.jumps[kk];
                                }
                                x[start + i] += s;
                            }
                        }
                    }
                }
                cursor.pass_next();
            }
            let w = cursor.state_at(t);
            for (out, (cs, ds)) in outputs.iter_mut().zip(&sparse) {
                let mut y = 0.0;
                for &(j, c) in cs {
                    y += c * x[j];
                }
                for &(kk, d) in ds {
                    y += d * w[kk];
                }
                out.push(y);
            }
            if let Some(s) = states.as_mut() {
                s.extend_from_slice(&x);
            }
            w_prev = w;
        }
        Ok(LtiResponse { outputs, states })
    }
}

/// exp(M) of a small square matrix: scaling and squaring of a Taylor series. The maps are
/// recomputed for every knot between samples (a shaped command has hundreds), where nalgebra's
/// Padé `exp` — with its norm estimates, allocations and LU solve — dominated a page frame.
/// After scaling ‖M/2ˢ‖∞ ≤ ½, the series is summed until a term is below 10⁻¹⁸ of the sum (at
/// most 30 terms; the remainder is then below 2⁻³⁰/30!), then squared s times. The tests of
/// the simulation (closed-form step and ramp responses, Singhose 2009 eq. 11) check the result.
fn expm(m: &DMatrix<f64>) -> DMatrix<f64> {
    let n = m.nrows();
    // Row-major flat copy, balanced first: B = D⁻¹MD with D diagonal powers of two (exact),
    // chosen so each state's row and column weigh alike (Parlett–Reinsch). A mode block
    // [[0, h], [−ω²h, −2ζωh]] has ∞-norm ω²h but balances to about ωh, which saves the
    // squarings; exp(M) = D·exp(B)·D⁻¹.
    let mut a: Vec<f64> = (0..n * n).map(|k| m[(k / n, k % n)]).collect();
    let mut d = vec![1.0_f64; n];
    for _ in 0..8 {
        let mut changed = false;
        for i in 0..n {
            let (mut c, mut r) = (0.0, 0.0);
            for j in (0..n).filter(|&j| j != i) {
                c += a[j * n + i].abs();
                r += a[i * n + j].abs();
            }
            if c == 0.0 || r == 0.0 || !(c.is_finite() && r.is_finite()) {
                continue;
            }
            let mut f = 1.0;
            while c * f * f < r * 0.25 && f < 1e150 {
                f *= 2.0;
            }
            while c * f * f > r * 4.0 && f > 1e-150 {
                f *= 0.5;
            }
            if f != 1.0 {
                changed = true;
                d[i] *= f;
                for j in 0..n {
                    a[i * n + j] /= f;
                    a[j * n + i] *= f;
                }
            }
        }
        if !changed {
            break;
        }
    }
    let norm = (0..n)
        .map(|i| (0..n).map(|j| a[i * n + j].abs()).sum::<f64>())
        .fold(0.0_f64, f64::max);
    let squarings = if norm > 0.5 {
        ((norm / 0.5).log2().ceil() as i32).clamp(0, 1000)
    } else {
        0
    };
    let scale = 0.5_f64.powi(squarings);
    a.iter_mut().for_each(|v| *v *= scale);
    let mul = |x: &[f64], y: &[f64], out: &mut [f64]| {
        for i in 0..n {
            for j in 0..n {
                let mut acc = 0.0;
                for k in 0..n {
                    acc += x[i * n + k] * y[k * n + j];
                }
                out[i * n + j] = acc;
            }
        }
    };
    let mut sum = vec![0.0; n * n];
    let mut term = vec![0.0; n * n];
    for i in 0..n {
        sum[i * n + i] = 1.0;
        term[i * n + i] = 1.0;
    }
    let mut next = vec![0.0; n * n];
    for k in 1..=30 {
        mul(&term, &a, &mut next);
        let inv = 1.0 / k as f64;
        let mut biggest = 0.0_f64;
        for (t, v) in term.iter_mut().zip(&next) {
            *t = v * inv;
            biggest = biggest.max(t.abs());
        }
        for (s, t) in sum.iter_mut().zip(&term) {
            *s += t;
        }
        let size = sum.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if biggest <= 1e-18 * size {
            break;
        }
    }
    for _ in 0..squarings {
        mul(&sum, &sum, &mut next);
        std::mem::swap(&mut sum, &mut next);
    }
    // Undo the balancing: exp(M) = D·exp(B)·D⁻¹.
    for i in 0..n {
        for j in 0..n {
            sum[i * n + j] *= d[i] / d[j];
        }
    }
    DMatrix::from_row_slice(n, n, &sum)
}

#[cfg(test)]
mod expm_tests {
    use super::*;

    /// exp of a rotation generator is the rotation; of a nilpotent Jordan block the truncated
    /// exponential series; both against their closed forms, with and without squarings.
    #[wasm_bindgen_test::wasm_bindgen_test(unsupported = test)]
    fn expm_matches_closed_forms() {
        for theta in [0.3, 2.0, 40.0] {
            let m = DMatrix::from_row_slice(2, 2, &[0.0, theta, -theta, 0.0]);
            let e = expm(&m);
            let (s, c) = f64::sin_cos(theta);
            for (got, want) in e.iter().zip([c, -s, s, c]) {
                assert!((got - want).abs() < 1e-12, "θ = {theta}: {got} vs {want}");
            }
        }
        let h = 3.0;
        let m = DMatrix::from_row_slice(3, 3, &[0.0, h, 0.0, 0.0, 0.0, h, 0.0, 0.0, 0.0]);
        let e = expm(&m);
        let want = [1.0, h, h * h / 2.0, 0.0, 1.0, h, 0.0, 0.0, 1.0];
        for (got, want) in e.transpose().iter().zip(want) {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
        // A damped mode block against nalgebra's Padé exponential.
        let (w, z, t) = (2.0 * std::f64::consts::PI * 7.9, 0.02, 0.013);
        let m = DMatrix::from_row_slice(2, 2, &[0.0, t, -w * w * t, -2.0 * z * w * t]);
        let diff = (expm(&m) - m.exp()).abs().max();
        assert!(diff < 1e-12, "{diff}");
        // The augmented block of the simulation (mode + quadratic input chain), unbalanced
        // by a large ω², against nalgebra's Padé exponential.
        let (w, h) = (2.0 * std::f64::consts::PI * 45.0, 0.004);
        let mut big = DMatrix::<f64>::zeros(5, 5);
        big[(0, 1)] = h;
        big[(1, 0)] = -w * w * h;
        big[(1, 1)] = -2.0 * 0.1 * w * h;
        big[(1, 2)] = w * w * h;
        big[(2, 3)] = h;
        big[(3, 4)] = h;
        let (ours, pade) = (expm(&big), big.exp());
        let rel = (&ours - &pade).abs().max() / pade.abs().max();
        assert!(rel < 1e-12, "{rel}");
    }
}
