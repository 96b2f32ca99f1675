//! Linear time-invariant plants driven by a piecewise-polynomial command, simulated exactly.
//!
//! The plant is x' = A x + E w(t), where w = (u, u', u'', …) is the command and its
//! derivatives. Between knots the command is a polynomial, so w' = S w (S shifts each
//! derivative down one row) and the augmented state z = (x, w) obeys z' = M z with
//! M = [[A, E], [0, S]]: over a step h the exact update is z(t + h) = e^{Mh} z(t) (the matrix
//! exponential, computed here by balancing, then scaling and squaring a Taylor series — see
//! `expm`; not nalgebra's Padé `exp`, which was too slow per knot; and between samples applied
//! to one vector by its Taylor series, see `Generator`). A knot adds its jumps to w at
//! its own time τ, so its contribution at the next sample t is e^{M(t − τ)} (impulse, jumps).
//! Hence the response is exact (to rounding) at any sample rate, for any command built from
//! polynomial pieces; the states are split into independent diagonal blocks (one per mode) so
//! the matrices stay small.
//!
//! Outputs are rows y = C x + D w: base position/velocity/acceleration and endpoint
//! position/velocity/acceleration.

use crate::error::{Error, Result};
use crate::piecewise::{Piecewise, ORDER};
use nalgebra::DMatrix;
use std::collections::HashMap;
use std::sync::OnceLock;

mod shaped;

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

/// How many 2 × 2 blocks (modes) [`Lti::respond`] marches together in one loop.
const LANES: usize = 4;

/// Up to [`LANES`] modes marched together: `rows[k]` = (first state of each lane, then second
/// state of each lane) at sample k; `starts[lane]` = the lane's first state, `usize::MAX` if
/// the lane is unused.
struct ModeGroup {
    starts: [usize; LANES],
    rows: Vec<[f64; 2 * LANES]>,
}

/// The command at the samples (pass 1 of [`Lti::respond`]): w[k·q + kk] is its kk-th
/// derivative at sample k; the knots' state jumps are events, at sample `event_at[e]` the n
/// values `event_jump[e·n ..]`.
struct SampledCommand {
    w: Vec<f64>,
    q: usize,
    event_at: Vec<usize>,
    event_jump: Vec<f64>,
}

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

    /// Appends the event of a knot δ before sample k through the one-step maps for δ (cached
    /// by δ's bits): the state jump Φ(δ)·impulse + Γ(δ)·jumps of every block.
    fn jump_by_maps(
        &self,
        cache: &mut HashMap<u64, Vec<BlockMaps>>,
        (delta, q): (f64, usize),
        (imp, jumps): (&[f64], &[f64; ORDER]),
        k: usize,
        (event_at, event_jump): (&mut Vec<usize>, &mut Vec<f64>),
    ) -> Result<()> {
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
            event_at.push(k);
            let base = event_jump.len();
            event_jump.resize(base + self.states(), 0.0);
            let jump = &mut event_jump[base..];
            for (bm, &(start, m)) in dm.iter().zip(&self.blocks) {
                for i in 0..m {
                    let mut s = 0.0;
                    for j in 0..m {
                        s += bm.phi[i * m + j] * imp[start + j];
                    }
                    for (g, j) in bm.gamma[i * q..(i + 1) * q].iter().zip(jumps) {
                        s += g * j;
                    }
                    jump[start + i] = s;
                }
            }
        }
        Ok(())
    }

    /// The block's augmented generator M = [[A, E], [0, S]] (see the module docs), balanced,
    /// for [`Generator::apply`].
    fn generator(&self, (start, m): (usize, usize), q: usize) -> Generator {
        let size = m + q;
        let mut a = vec![0.0; size * size];
        for i in 0..m {
            for j in 0..m {
                a[i * size + j] = self.a[(start + i, start + j)];
            }
            for k in 0..q {
                a[i * size + m + k] = self.e[(start + i, k)];
            }
        }
        for k in 0..q.saturating_sub(1) {
            a[(m + k) * size + m + k + 1] = 1.0;
        }
        let d = balance(&mut a, size);
        let norm = (0..size)
            .map(|i| {
                a[i * size..(i + 1) * size]
                    .iter()
                    .map(|v| v.abs())
                    .sum::<f64>()
            })
            .fold(0.0_f64, f64::max);
        let mut entries = Vec::new();
        let mut rows = vec![0];
        for row in a.chunks_exact(size) {
            entries.extend(
                row.iter()
                    .enumerate()
                    .filter(|(_, v)| **v != 0.0)
                    .map(|(j, &v)| (j, v)),
            );
            rows.push(entries.len());
        }
        let mut g = Generator {
            size,
            entries,
            rows,
            d,
            norm,
            powers: Vec::new(),
        };
        g.powers = g.taylor_columns();
        g
    }

    /// The state jump a knot causes: a jump Jⱼ in the command's j-th derivative is a Dirac
    /// Jⱼδ in derivative j + 1, which E turns into the state jump E[:, j+1]·Jⱼ. A Dirac's
    /// derivative (E reading derivative ≥ j + 2 of a jump in j) is rejected.
    /// Written into `imp` (one entry per state), reused across knots; `columns` are E's non-zero
    /// columns as (derivative, column), from [`Self::input_columns`]. Returns false (and leaves
    /// `imp` untouched) when the jump is zero, the common case of a plant driven by u alone.
    fn impulse(
        columns: &[(usize, Vec<f64>)],
        jumps: &[f64; ORDER],
        time: f64,
        imp: &mut [f64],
    ) -> Result<bool> {
        let mut any = false;
        // A jump in derivative j matters only if E reads a higher derivative.
        let reach = columns.last().map_or(0, |(k, _)| *k).min(ORDER);
        for (j, &jump) in jumps[..reach].iter().enumerate() {
            if jump == 0.0 {
                continue;
            }
            for (k, col) in columns.iter().filter(|(k, _)| *k > j) {
                if *k > j + 1 {
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
                if !any {
                    imp.iter_mut().for_each(|v| *v = 0.0);
                    any = true;
                }
                for (s, v) in imp.iter_mut().zip(col) {
                    *s += v * jump;
                }
            }
        }
        Ok(any)
    }

    /// E's non-zero columns as (command derivative, column).
    fn input_columns(&self) -> Vec<(usize, Vec<f64>)> {
        (0..self.e.ncols().min(ORDER))
            .filter_map(|k| {
                let col: Vec<f64> = self.e.column(k).iter().copied().collect();
                col.iter().any(|&v| v != 0.0).then_some((k, col))
            })
            .collect()
    }

    /// Exact response to `command` at t = k·`sample_period`, k = 0 … `samples` − 1. The plant
    /// starts at rest (x = 0) before the command's first knot.
    ///
    /// Three passes, each a tight loop: (1) the command's derivatives w at every sample and the
    /// state jumps of the knots (a knot between two samples contributes e^{M(t − τ)}(impulse,
    /// jumps) at the next sample); (2) each independent block of states marched over all samples,
    /// x ← Φx + Γw, the modes' 2 × 2 blocks `LANES` (4) at a time with their input terms formed
    /// before the recurrence; (3) each output row as a sum of whole columns (vectorised).
    pub fn respond(
        &self,
        command: &Piecewise,
        sample_period: f64,
        samples: usize,
        keep_states: bool,
    ) -> Result<LtiResponse> {
        let q = command.degree() + 1;
        let maps: Vec<BlockMaps> = self
            .blocks
            .iter()
            .map(|&b| self.block_maps(b, q, sample_period))
            .collect::<Result<_>>()?;
        let sampled = self.sample_command(command, sample_period, samples)?;
        let groups = self.march_modes(&maps, &sampled, samples);
        let xs = self.march_blocks(&maps, &sampled, samples);
        let outputs = self.outputs(&groups, &xs, &sampled.w, q, samples);
        let states = keep_states.then(|| self.states_by_sample(&groups, &xs, samples));
        Ok(LtiResponse { outputs, states })
    }

    /// Pass 1: w[k·q + kk] = the command's kk-th derivative at sample k; the knots' state
    /// jumps as events (sample index, n values), in sample order.
    fn sample_command(
        &self,
        command: &Piecewise,
        sample_period: f64,
        samples: usize,
    ) -> Result<SampledCommand> {
        let n = self.states();
        let q = command.degree() + 1;
        let columns = self.input_columns();
        let generators: Vec<Generator> =
            self.blocks.iter().map(|&b| self.generator(b, q)).collect();
        let mut scratch = Scratch::default();
        let knots = command.knots();
        let mut w: Vec<f64> = vec![0.0; samples * q];
        let mut event_at: Vec<usize> = Vec::new();
        let mut event_jump: Vec<f64> = Vec::new();
        let mut cache: HashMap<u64, Vec<BlockMaps>> = HashMap::new();
        let mut imp = vec![0.0; n];
        // The command's Taylor state (first q derivatives) just after the last knot passed.
        let mut anchor = vec![0.0; q];
        let mut shifted = vec![0.0; q];
        let mut anchor_time = command.start_time();
        let mut next = 0;
        for (k, wk) in w.chunks_exact_mut(q).enumerate() {
            let t = k as f64 * sample_period;
            while let Some(knot) = knots.get(next) {
                if knot.time > t {
                    break;
                }
                let delta = t - knot.time;
                let jumped = Self::impulse(&columns, &knot.jumps, knot.time, &mut imp)?;
                if delta == 0.0 {
                    if jumped {
                        event_at.push(k);
                        event_jump.extend_from_slice(&imp);
                    }
                } else {
                    if !jumped {
                        imp.iter_mut().for_each(|v| *v = 0.0);
                    }
                    // Usually e^{Mδ}·(impulse, jumps) directly (a few matrix–vector products);
                    // the one-step maps only when δ·‖M‖ is so large that the vector series
                    // would need many substeps.
                    if generators.iter().all(|g| g.substeps(delta).is_some()) {
                        event_at.push(k);
                        let base = event_jump.len();
                        event_jump.resize(base + n, 0.0);
                        let jump = &mut event_jump[base..];
                        for (g, &(start, m)) in generators.iter().zip(&self.blocks) {
                            scratch.input(&imp[start..start + m], &knot.jumps[..q]);
                            g.apply(delta, &mut scratch.z, &mut scratch.work, m);
                            jump[start..start + m].copy_from_slice(&scratch.z[..m]);
                        }
                    } else {
                        self.jump_by_maps(
                            &mut cache,
                            (delta, q),
                            (&imp, &knot.jumps),
                            k,
                            (&mut event_at, &mut event_jump),
                        )?;
                    }
                }
                taylor_shift(&anchor, knot.time - anchor_time, &mut shifted);
                for ((a, s), j) in anchor.iter_mut().zip(&shifted).zip(&knot.jumps) {
                    *a = s + j;
                }
                anchor_time = knot.time;
                next += 1;
            }
            if next > 0 {
                taylor_shift(&anchor, t - anchor_time, wk);
            }
        }
        Ok(SampledCommand {
            w,
            q,
            event_at,
            event_jump,
        })
    }

    /// Pass 2, the modes: the 2 × 2 blocks are marched LANES at a time in one loop, so their
    /// recurrences — each a chain of dependent multiply-adds — overlap instead of running one
    /// after another. Each sample's input term cₖ = Γ wₖ₋₁ + (the knots' jumps at k) is formed
    /// first, off the chain, in the rows themselves; the chain is then xₖ = Φ xₖ₋₁ + cₖ (a
    /// multiply and two adds deep).
    fn march_modes(
        &self,
        maps: &[BlockMaps],
        sampled: &SampledCommand,
        samples: usize,
    ) -> Vec<ModeGroup> {
        let n = self.states();
        let SampledCommand {
            w,
            q,
            event_at,
            event_jump,
        } = sampled;
        let q = *q;
        let pair_blocks: Vec<usize> = (0..self.blocks.len())
            .filter(|&b| self.blocks[b].1 == 2)
            .collect();
        let mut groups: Vec<ModeGroup> = Vec::with_capacity(pair_blocks.len().div_ceil(LANES));
        for members in pair_blocks.chunks(LANES) {
            let mut g = GroupMaps {
                phi: [[0.0; LANES]; 4],
                gamma: vec![[0.0; 2 * LANES]; q],
                starts: [usize::MAX; LANES],
            };
            for (lane, &b) in members.iter().enumerate() {
                let bm = &maps[b];
                g.starts[lane] = self.blocks[b].0;
                for (p, &v) in g.phi.iter_mut().zip(&bm.phi) {
                    p[lane] = v;
                }
                for (i, gi) in g.gamma.iter_mut().enumerate() {
                    gi[lane] = bm.gamma.get(i).copied().unwrap_or(0.0);
                    gi[LANES + lane] = bm.gamma.get(q + i).copied().unwrap_or(0.0);
                }
            }
            let events = (&event_at[..], &event_jump[..], n);
            let rows = match q {
                1 => march_group::<1>(&g, w, events, samples),
                2 => march_group::<2>(&g, w, events, samples),
                3 => march_group::<3>(&g, w, events, samples),
                4 => march_group::<4>(&g, w, events, samples),
                _ => march_group::<0>(&g, w, events, samples),
            };
            groups.push(ModeGroup {
                starts: g.starts,
                rows,
            });
        }
        groups
    }

    /// Pass 2, the other blocks: xs[j][k] = state j at sample k, marched one block at a time
    /// (empty for the states of the modes' 2 × 2 blocks).
    fn march_blocks(
        &self,
        maps: &[BlockMaps],
        sampled: &SampledCommand,
        samples: usize,
    ) -> Vec<Vec<f64>> {
        let n = self.states();
        let SampledCommand {
            w,
            q,
            event_at,
            event_jump,
        } = sampled;
        let q = *q;
        let mut xs: Vec<Vec<f64>> = vec![Vec::new(); n];
        for (bm, &(start, m)) in maps.iter().zip(&self.blocks) {
            if m == 2 {
                continue;
            }
            let mut out: Vec<Vec<f64>> = vec![vec![0.0; samples]; m];
            let mut events = event_at
                .iter()
                .zip(event_jump.chunks_exact(n))
                .map(|(&k, jump)| (k, &jump[start..start + m]))
                .peekable();
            let mut w_prev = w.chunks_exact(q);
            let mut xb = vec![0.0; m];
            let mut prev = vec![0.0; m];
            for k in 0..samples {
                if k > 0 {
                    prev.copy_from_slice(&xb);
                    let wp = w_prev.next().unwrap_or(&[]);
                    for (i, xo) in xb.iter_mut().enumerate() {
                        let mut s = 0.0;
                        for (p, xv) in bm.phi[i * m..(i + 1) * m].iter().zip(&prev) {
                            s += p * xv;
                        }
                        for (g, wv) in bm.gamma[i * q..(i + 1) * q].iter().zip(wp) {
                            s += g * wv;
                        }
                        *xo = s;
                    }
                }
                while let Some((_, jump)) = events.next_if(|(at, _)| *at == k) {
                    for (xi, v) in xb.iter_mut().zip(jump) {
                        *xi += v;
                    }
                }
                for (o, &v) in out.iter_mut().zip(&xb) {
                    o[k] = v;
                }
            }
            for (i, o) in out.into_iter().enumerate() {
                xs[start + i] = o;
            }
        }
        xs
    }

    /// Pass 3: outputs y = C x + D w, row by row over whole columns (a mode group's rows at
    /// once).
    fn outputs(
        &self,
        groups: &[ModeGroup],
        xs: &[Vec<f64>],
        w: &[f64],
        q: usize,
        samples: usize,
    ) -> [Vec<f64>; OUTPUTS] {
        let mut outputs: [Vec<f64>; OUTPUTS] = Default::default();
        for (row, out) in outputs.iter_mut().enumerate() {
            *out = vec![0.0; samples];
            for g in groups {
                let mut coef = [0.0; 2 * LANES];
                for (lane, &start) in g.starts.iter().enumerate() {
                    if start != usize::MAX {
                        coef[lane] = self.c[(row, start)];
                        coef[LANES + lane] = self.c[(row, start + 1)];
                    }
                }
                let (first, second) = coef.split_at(LANES);
                match (
                    first.iter().any(|&c| c != 0.0),
                    second.iter().any(|&c| c != 0.0),
                ) {
                    (true, true) => accumulate_rows::<0, { 2 * LANES }>(out, &g.rows, &coef),
                    (true, false) => accumulate_rows::<0, LANES>(out, &g.rows, &coef),
                    (false, true) => accumulate_rows::<LANES, LANES>(out, &g.rows, &coef),
                    (false, false) => {}
                }
            }
            for (j, xj) in xs.iter().enumerate() {
                let c = self.c[(row, j)];
                if c != 0.0 && !xj.is_empty() {
                    for (y, x) in out.iter_mut().zip(xj) {
                        *y += c * x;
                    }
                }
            }
            let mut dk = [0.0; ORDER];
            for (kk, v) in dk.iter_mut().enumerate().take(q) {
                *v = self.d[(row, kk)];
            }
            if dk.iter().any(|&v| v != 0.0) {
                match q {
                    1 => feedthrough::<1>(out, w, &dk),
                    2 => feedthrough::<2>(out, w, &dk),
                    3 => feedthrough::<3>(out, w, &dk),
                    4 => feedthrough::<4>(out, w, &dk),
                    _ => feedthrough::<0>(out, w, &dk[..q]),
                }
            }
        }
        outputs
    }

    /// The states sample by sample (n per sample), from the mode groups' rows and `xs`.
    fn states_by_sample(&self, groups: &[ModeGroup], xs: &[Vec<f64>], samples: usize) -> Vec<f64> {
        let n = self.states();
        // Where state j lives: (group, slot) of a mode group, or xs[j].
        let mut at: Vec<Option<(usize, usize)>> = vec![None; n];
        for (gi, g) in groups.iter().enumerate() {
            for (lane, &start) in g.starts.iter().enumerate() {
                if start != usize::MAX {
                    at[start] = Some((gi, lane));
                    at[start + 1] = Some((gi, LANES + lane));
                }
            }
        }
        let mut s = Vec::with_capacity(n * samples);
        for k in 0..samples {
            s.extend(at.iter().zip(xs).map(|(loc, xj)| match *loc {
                Some((gi, slot)) => groups[gi].rows[k][slot],
                None => xj[k],
            }));
        }
        s
    }
}

/// `out[k] = Σ_{m ≥ k} state[m] hᵐ⁻ᵏ/(m − k)!`: a polynomial's derivatives shifted by `h`
/// (the same sums, in the same order, as `piecewise::taylor_shift`, on the first
/// `state.len()` derivatives only).
#[inline]
fn taylor_shift(state: &[f64], h: f64, out: &mut [f64]) {
    // The common degrees (step, ramp, trapezoid, S-curve) with the loops unrolled: called for
    // every sample, where the general loop's bookkeeping cost more than the sums.
    match (state.len(), out.len()) {
        (1, 1) => taylor_shift_fixed::<1>(state, h, out),
        (2, 2) => taylor_shift_fixed::<2>(state, h, out),
        (3, 3) => taylor_shift_fixed::<3>(state, h, out),
        (4, 4) => taylor_shift_fixed::<4>(state, h, out),
        _ => taylor_shift_any(state, h, out),
    }
}

/// [`taylor_shift`] for `Q` derivatives (`state.len() == out.len() == Q`).
#[inline(always)]
fn taylor_shift_fixed<const Q: usize>(state: &[f64], h: f64, out: &mut [f64]) {
    let mut st = [0.0; Q];
    for (d, v) in st.iter_mut().zip(state) {
        *d = *v;
    }
    // hp[i] = hⁱ/i! by the recurrence pw *= h / i, as `piecewise::taylor_shift` forms it (the
    // constant divisions by 1 and 2 are exact, so the compiler turns them into moves and
    // multiplications without changing a bit).
    let mut hp = [1.0; Q];
    for i in 1..Q {
        hp[i] = hp[i - 1] * (h / i as f64);
    }
    for (k, o) in out.iter_mut().enumerate().take(Q) {
        let mut sum = 0.0;
        for i in 0..Q - k {
            sum += st[k + i] * hp[i];
        }
        *o = sum;
    }
}

/// [`taylor_shift`] for any number of derivatives.
fn taylor_shift_any(state: &[f64], h: f64, out: &mut [f64]) {
    for (k, o) in out.iter_mut().enumerate() {
        let mut sum = 0.0;
        let mut pw = 1.0; // h^{m-k}/(m-k)!
        for (i, s) in state.iter().skip(k).enumerate() {
            if i > 0 {
                pw *= h / i as f64;
            }
            sum += s * pw;
        }
        *o = sum;
    }
}

/// The exact one-step maps of up to [`LANES`] modes, lane by lane: `phi[r][lane]` is entry r
/// of the lane's row-major Φ; `gamma[i]` = (Γ's first row, then its second row) at the
/// command's i-th derivative; `starts[lane]` the lane's first state (`usize::MAX`: unused).
struct GroupMaps {
    phi: [[f64; LANES]; 4],
    gamma: Vec<[f64; 2 * LANES]>,
    starts: [usize; LANES],
}

/// The states of a group of modes at every sample: xₖ = Φ xₖ₋₁ + cₖ with
/// cₖ = Γ wₖ₋₁ + (the knots' jumps at k), x₋₁ = 0, all lanes in one loop. The input term is
/// formed off the recurrence's dependency chain (it needs only w), so the chain per sample is
/// one multiply and two adds and the lanes' chains overlap. `Q` is the number of command
/// derivatives per sample, or 0 for "as many as `g.gamma` has" (the loops are then not
/// unrolled). `events` = (sample index of each event, n jumps per event, n).
fn march_group<const Q: usize>(
    g: &GroupMaps,
    w: &[f64],
    (event_at, event_jump, n): (&[usize], &[f64], usize),
    samples: usize,
) -> Vec<[f64; 2 * LANES]> {
    let q = if Q == 0 { g.gamma.len() } else { Q };
    let mut gamma = [[0.0; 2 * LANES]; ORDER];
    for (d, s) in gamma.iter_mut().zip(&g.gamma) {
        *d = *s;
    }
    let [p00, p01, p10, p11] = g.phi;
    let mut events = event_at
        .iter()
        .zip(event_jump.chunks_exact(n.max(1)))
        .peekable();
    let mut rows = Vec::with_capacity(samples);
    let mut x = [0.0; 2 * LANES];
    let mut w_prev: &[f64] = &[];
    for (k, wk) in (0..samples).zip(w.chunks_exact(q.max(1)).chain(std::iter::repeat(&[][..]))) {
        let mut c = [0.0; 2 * LANES];
        for (i, wv) in w_prev.iter().enumerate().take(q.min(ORDER)) {
            for (cl, gl) in c.iter_mut().zip(&gamma[i]) {
                *cl += gl * wv;
            }
        }
        while let Some((_, jump)) = events.next_if(|(at, _)| **at == k) {
            for (lane, &start) in g.starts.iter().enumerate() {
                if let (Some(&j0), Some(&j1)) = (jump.get(start), jump.get(start.wrapping_add(1))) {
                    c[lane] += j0;
                    c[LANES + lane] += j1;
                }
            }
        }
        let mut next = [0.0; 2 * LANES];
        for l in 0..LANES {
            let (x0, x1) = (x[l], x[LANES + l]);
            next[l] = (p00[l] * x0 + p01[l] * x1) + c[l];
            next[LANES + l] = (p10[l] * x0 + p11[l] * x1) + c[LANES + l];
        }
        x = next;
        rows.push(x);
        w_prev = wk;
    }
    rows
}

/// `out[k] += D_row · w_k` in one pass over the samples (`Q` command derivatives per sample,
/// or 0 for `d.len()` of them, loops not unrolled).
fn feedthrough<const Q: usize>(out: &mut [f64], w: &[f64], d: &[f64]) {
    let q = if Q == 0 { d.len() } else { Q };
    let mut dk = [0.0; ORDER];
    for (a, b) in dk.iter_mut().zip(d) {
        *a = *b;
    }
    for (y, wk) in out.iter_mut().zip(w.chunks_exact(q.max(1))) {
        let mut s = 0.0;
        for (a, v) in dk.iter().zip(wk).take(q) {
            s += a * v;
        }
        *y += s;
    }
}

/// `out[k] += Σ_{j < LEN} coef[j] · rows[k][OFF + j]`.
fn accumulate_rows<const OFF: usize, const LEN: usize>(
    out: &mut [f64],
    rows: &[[f64; 2 * LANES]],
    coef: &[f64; 2 * LANES],
) {
    for (y, r) in out.iter_mut().zip(rows) {
        let mut s = 0.0;
        for j in 0..LEN {
            s += coef[OFF + j] * r[OFF + j];
        }
        *y += s;
    }
}

/// A block's augmented generator, balanced: B = D⁻¹MD (`size` × `size`), `d` = D's diagonal
/// (powers of two), `norm` = ‖B‖∞. B is kept by rows as its non-zero entries (column, value),
/// row i being `entries[rows[i]..rows[i + 1]]`: M = [[A, E], [0, N]] with N the command's
/// nilpotent shift is mostly zeros (9 of 25 entries for a mode driven by a trapezoid), and
/// skipping them changes no sum.
#[derive(Debug, Clone)]
struct Generator {
    size: usize,
    entries: Vec<(usize, f64)>,
    rows: Vec<usize>,
    d: Vec<f64>,
    norm: f64,
    /// Bᵏeⱼ/k! for every unit vector eⱼ and k = 0 … [`TAYLOR_TERMS`] − 1, at
    /// `powers[(j·TAYLOR_TERMS + k)·size ..][..size]`: the Taylor coefficients of e^{Bh}eⱼ,
    /// so a knot's e^{Bh}·y is a polynomial in h per non-zero yⱼ (see [`Generator::apply`]).
    powers: Vec<f64>,
}

/// Taylor terms kept per unit vector: enough for ‖B‖h ≤ ½, where 0.5¹⁸/18! < 10⁻²¹.
const TAYLOR_TERMS: usize = 18;

/// `reach[K − 1]`: the largest ‖B‖δ for which K Taylor terms leave a tail bound
/// (‖B‖δ)ᴷ/K!·e^{½} ≤ 2⁻⁶⁰ (K = 1 … `TAYLOR_TERMS` − 1), x_K = (2⁻⁶⁰·K!/e^{½})^{1/K}: the
/// same for every block, formed once.
fn taylor_reach() -> &'static [f64; TAYLOR_TERMS - 1] {
    static REACH: OnceLock<[f64; TAYLOR_TERMS - 1]> = OnceLock::new();
    REACH.get_or_init(|| {
        let mut reach = [0.0; TAYLOR_TERMS - 1];
        let mut factorial = 1.0;
        for (k, r) in reach.iter_mut().enumerate() {
            let terms = (k + 1) as f64;
            factorial *= terms;
            *r = (f64::powi(2.0, -60) * factorial / 0.5_f64.exp()).powf(terms.recip());
        }
        reach
    })
}

/// Buffers reused across knots.
#[derive(Debug, Default)]
struct Scratch {
    z: Vec<f64>,
    work: Vec<f64>,
}

impl Scratch {
    /// `z` = (state, jumps) as one vector.
    fn input(&mut self, state: &[f64], jumps: &[f64]) {
        self.z.clear();
        self.z.extend_from_slice(state);
        self.z.extend_from_slice(jumps);
    }
}

/// Substeps beyond which a knot's exponential is formed as a matrix instead.
const MAX_SUBSTEPS: usize = 8;

impl Generator {
    /// How many substeps of length δ/s keep ‖B‖·δ/s ≤ ½, or `None` beyond [`MAX_SUBSTEPS`]
    /// (or for a non-finite δ·‖B‖).
    fn substeps(&self, delta: f64) -> Option<usize> {
        let x = self.norm * delta.abs() / 0.5;
        if !x.is_finite() {
            return None;
        }
        let s = x.ceil().max(1.0);
        (s <= MAX_SUBSTEPS as f64).then_some(s as usize)
    }

    /// The Taylor coefficients kept in `powers` (B applied by its non-zero entries).
    fn taylor_columns(&self) -> Vec<f64> {
        let n = self.size;
        let mut powers = vec![0.0; n * TAYLOR_TERMS * n];
        for (j, col) in powers.chunks_exact_mut(TAYLOR_TERMS * n).enumerate() {
            col[j] = 1.0;
            for k in 1..TAYLOR_TERMS {
                let (done, rest) = col.split_at_mut(k * n);
                let last = &done[(k - 1) * n..];
                for (o, ends) in rest[..n].iter_mut().zip(self.rows.windows(2)) {
                    let mut acc = -0.0;
                    for &(i, v) in &self.entries[ends[0]..ends[1]] {
                        acc += v * last[i];
                    }
                    *o = acc / k as f64;
                }
            }
        }
        powers
    }

    /// z ← e^{Mδ} z when one step suffices (‖B‖δ ≤ ½, the common case of a knot between
    /// samples): y = D⁻¹z, e^{Bδ}y = Σⱼ yⱼ Σₖ δᵏ (Bᵏeⱼ/k!) evaluated by Horner's rule over the
    /// kept columns, for the non-zero yⱼ only (a trapezoid's knot jumps one derivative: one
    /// column). K terms are kept, the fewest whose tail bound (‖B‖δ)ᴷ/K!·e^{½} is below
    /// 2⁻⁶⁰ of ‖y‖∞ (at most [`TAYLOR_TERMS`]). Only the first `keep` entries are formed
    /// (z[keep..] is left as it was). Returns false (z untouched) if ‖B‖δ > ½.
    fn apply_one_step(&self, delta: f64, z: &mut [f64], work: &mut Vec<f64>, keep: usize) -> bool {
        let n = self.size;
        let keep = keep.min(n);
        let x = self.norm * delta.abs();
        // NaN (a non-finite δ) fails the test too.
        if x.is_nan() || x > 0.5 {
            return false;
        }
        // K terms (k = 0 … K − 1): the first K with xᴷ/K!·e^{½} ≤ 2⁻⁶⁰ (K ≤ 17 for x ≤ ½).
        let terms = 1 + taylor_reach().iter().take_while(|&&r| x > r).count();
        work.clear();
        work.resize(2 * keep, 0.0);
        let (sum, acc) = work.split_at_mut(keep);
        for (j, (zj, dj)) in z.iter().zip(&self.d).enumerate() {
            // D is powers of two: y = z/d exactly.
            let y = zj * dj.recip();
            if y == 0.0 {
                continue;
            }
            let col = &self.powers[j * TAYLOR_TERMS * n..][..terms * n];
            let mut rows = col.chunks_exact(n).rev();
            if let Some(top) = rows.next() {
                acc.copy_from_slice(&top[..keep]);
            }
            if let [a0, a1] = acc {
                // A mode's two states (the usual case), without a loop per term.
                for row in rows {
                    *a0 = *a0 * delta + row[0];
                    *a1 = *a1 * delta + row[1];
                }
            } else {
                for row in rows {
                    for (a, c) in acc.iter_mut().zip(row) {
                        *a = *a * delta + c;
                    }
                }
            }
            for (s, a) in sum.iter_mut().zip(acc.iter()) {
                *s += y * a;
            }
        }
        for ((v, s), d) in z.iter_mut().zip(sum.iter()).zip(&self.d) {
            *v = s * d;
        }
        true
    }

    /// z[..keep] ← (e^{Mδ} z)[..keep] (`z.len()` must be `size`; the rest of z is left
    /// unspecified): by the kept Taylor columns when one step suffices
    /// ([`Generator::apply_one_step`]), else by [`Generator::apply_series`].
    fn apply(&self, delta: f64, z: &mut [f64], work: &mut Vec<f64>, keep: usize) {
        if !self.apply_one_step(delta, z, work, keep) {
            self.apply_series(delta, z, work);
        }
    }

    /// z ← e^{Mδ} z: on the balanced generator, e^{Bh} applied s times (h = δ/s, ‖Bh‖ ≤ ½)
    /// by its Taylor series summed until a term is below 10⁻¹⁸ of the sum (at most 30
    /// terms), as [`expm`] sums its series, but on one vector — a few matrix–vector products
    /// instead of matrix products.
    fn apply_series(&self, delta: f64, z: &mut [f64], work: &mut Vec<f64>) {
        let n = self.size;
        let Some(steps) = self.substeps(delta) else {
            return;
        };
        let h = delta / steps as f64;
        work.clear();
        work.resize(2 * n, 0.0);
        let (first, second) = work.split_at_mut(n);
        for (v, d) in z.iter_mut().zip(&self.d) {
            *v /= d;
        }
        for _ in 0..steps {
            // The last term and the next one, swapped after each term instead of copied.
            let (mut term, mut next) = (&mut *first, &mut *second);
            term.copy_from_slice(z);
            for k in 1..=30 {
                let c = h / k as f64;
                let (mut biggest, mut size) = (0.0_f64, 0.0_f64);
                for ((o, ends), s) in next.iter_mut().zip(self.rows.windows(2)).zip(z.iter_mut()) {
                    let mut acc = -0.0;
                    for &(j, v) in &self.entries[ends[0]..ends[1]] {
                        acc += v * term[j];
                    }
                    *o = c * acc;
                    *s += *o;
                    // As f64::max, which ignores NaN, without its NaN branches.
                    if o.abs() > biggest {
                        biggest = o.abs();
                    }
                    if s.abs() > size {
                        size = s.abs();
                    }
                }
                std::mem::swap(&mut term, &mut next);
                if biggest <= 1e-18 * size {
                    break;
                }
            }
        }
        for (v, d) in z.iter_mut().zip(&self.d) {
            *v *= d;
        }
    }
}

/// Balances the row-major `n` × `n` matrix `a` in place: B = D⁻¹AD with D diagonal powers of
/// two (exact), chosen so each state's row and column weigh alike (Parlett–Reinsch). Returns
/// D's diagonal.
fn balance(a: &mut [f64], n: usize) -> Vec<f64> {
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
    d
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
    let d = balance(&mut a, n);
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

    /// One mode at `hz`, damping `zeta`, driven through ω²u by a cubic command (q = 4).
    fn mode_block(hz: f64, zeta: f64) -> Lti {
        let w = 2.0 * std::f64::consts::PI * hz;
        Lti {
            a: DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -w * w, -2.0 * zeta * w]),
            e: DMatrix::from_row_slice(2, 4, &[0.0, 0.0, 0.0, 0.0, w * w, 0.0, 0.0, 0.0]),
            c: DMatrix::zeros(OUTPUTS, 2),
            d: DMatrix::zeros(OUTPUTS, 4),
            blocks: vec![(0, 2)],
        }
    }

    /// A knot's e^{Mδ}·z as `respond` forms it (`apply`: the kept Taylor columns for the
    /// small δ, the vector series in substeps beyond) against the matrix exponential
    /// `block_maps` forms, for a lightly damped 3 Hz mode driven through
    /// ω²u with a cubic command (q = 4), over sub-sample offsets from 10⁻⁵ s to the largest
    /// one the vector path takes; beyond it `substeps` refuses.
    #[test]
    fn vector_exponential_matches_the_matrix_one() {
        let lti = mode_block(3.0, 0.05);
        let g = lti.generator((0, 2), 4);
        let z0 = [0.3, -1.7, 0.9, 2.5, -4.0, 11.0];
        let limit = MAX_SUBSTEPS as f64 * 0.5 / g.norm;
        for delta in [1e-5, 1e-3, 0.01, 0.05, 0.9 * limit] {
            assert!(g.substeps(delta).is_some(), "{delta}");
            let mut z = z0.to_vec();
            g.apply(delta, &mut z, &mut Vec::new(), 2);
            let maps = lti.block_maps((0, 2), 4, delta).unwrap();
            for (i, got) in z.iter().enumerate().take(2) {
                let want: f64 = (0..2).map(|j| maps.phi[i * 2 + j] * z0[j]).sum::<f64>()
                    + (0..4)
                        .map(|k| maps.gamma[i * 4 + k] * z0[2 + k])
                        .sum::<f64>();
                let scale = want.abs().max(1.0);
                assert!(
                    (got - want).abs() <= 1e-13 * scale,
                    "δ {delta}: {got} vs {want}"
                );
            }
        }
        assert_eq!(g.substeps(1.1 * limit), None);
        assert_eq!(g.substeps(f64::INFINITY), None);
    }

    /// The one-step path (Horner's rule over the kept Taylor columns, with the term count
    /// from the tail bound) against the term-by-term series it replaces, on every state it
    /// forms: a 2-state mode (the unrolled loop) and a 4-state block (the general loop), each
    /// with a cubic command (q = 4), every entry of z non-zero and single entries alone, over
    /// δ up to ‖B‖δ = ½. Agreement to a few ulps of the result's size: both sum the same
    /// series to below 2⁻⁶⁰ of it.
    #[test]
    fn one_step_taylor_columns_match_the_term_by_term_series() {
        let mode = mode_block(7.0, 0.02);
        #[rustfmt::skip]
        let two_mass = Lti {
            a: DMatrix::from_row_slice(4, 4, &[
                0.0, 1.0, 0.0, 0.0,
                -400.0, -2.0, 400.0, 2.0,
                0.0, 0.0, 0.0, 1.0,
                40.0, 0.2, -90.0, -0.9,
            ]),
            e: DMatrix::from_row_slice(4, 4, &[
                0.0, 0.0, 0.0, 0.0,
                0.0, 0.0, 1.0, 0.0,
                0.0, 0.0, 0.0, 0.0,
                0.0, 3.0, 0.0, 0.0,
            ]),
            c: DMatrix::zeros(OUTPUTS, 4),
            d: DMatrix::zeros(OUTPUTS, 4),
            blocks: vec![(0, 4)],
        };
        for (lti, m) in [(mode, 2), (two_mass, 4)] {
            let g = lti.generator((0, m), 4);
            let n = m + 4;
            let mut inputs: Vec<Vec<f64>> = (0..n)
                .map(|j| (0..n).map(|i| if i == j { 1.5 } else { 0.0 }).collect())
                .collect();
            inputs.push(
                (0..n)
                    .map(|i| [0.3, -1.7, 0.9, 2.5, -4.0, 11.0, 0.7, -0.2][i])
                    .collect(),
            );
            let limit = 0.5 / g.norm;
            for z0 in &inputs {
                for delta in [0.0, 1e-9, 1e-6, 1e-4, 0.1 * limit, 0.5 * limit, limit] {
                    let (mut fast, mut slow) = (z0.clone(), z0.clone());
                    assert!(g.apply_one_step(delta, &mut fast, &mut Vec::new(), m));
                    g.apply_series(delta, &mut slow, &mut Vec::new());
                    let size = slow.iter().fold(0.0_f64, |s, v| s.max(v.abs()));
                    for (i, (f, s)) in fast.iter().zip(&slow).enumerate().take(m) {
                        assert!(
                            (f - s).abs() <= 8.0 * f64::EPSILON * size,
                            "m {m}, δ {delta}, state {i}: {f} vs {s}"
                        );
                    }
                }
            }
            // Beyond ‖B‖δ = ½ the one-step path declines and leaves z alone.
            let mut z = inputs[n].clone();
            assert!(!g.apply_one_step(1.01 * limit, &mut z, &mut Vec::new(), m));
            assert_eq!(z, inputs[n]);
        }
    }

    /// Both ways of adding a knot between samples give the same exact samples: a 50 Hz mode
    /// sampled every 50 ms (δ·‖M‖ beyond the vector series' substeps, so the one-step maps are
    /// used) against the same trapezoid sampled every 1 ms (the vector series), compared at the
    /// coarse samples.
    #[test]
    fn knots_by_maps_and_by_vector_series_agree() {
        use crate::command::trapezoid;
        use crate::plant::ModalPlant;
        use crate::Mode;
        let plant = ModalPlant::new(
            vec![Mode::new(50.0, 0.03).unwrap(), Mode::new(3.0, 0.1).unwrap()],
            vec![0.5, 0.5],
        )
        .unwrap()
        .to_lti();
        // Knots at 0.0123 s and every corner after: between the samples of both grids.
        let cmd = trapezoid(1.0, 0.8, 7.0, 0.0123).unwrap();
        let coarse = plant.respond(&cmd, 0.05, 40, false).unwrap();
        let fine = plant.respond(&cmd, 0.001, 1951, false).unwrap();
        let g = plant.generator(plant.blocks[0], cmd.degree() + 1);
        assert_eq!(g.substeps(0.03), None, "the coarse grid takes the maps");
        for row in [
            BASE_POSITION,
            ENDPOINT,
            ENDPOINT_VELOCITY,
            ENDPOINT_ACCELERATION,
        ] {
            for k in 0..40 {
                let (a, b) = (coarse.outputs[row][k], fine.outputs[row][50 * k]);
                assert!(
                    (a - b).abs() <= 1e-9 * b.abs().max(1.0),
                    "row {row} t {k}: {a} vs {b}"
                );
            }
        }
    }
}
