//! The response of a modal plant to a command shaped by a convolved shaper, from the factors.
//!
//! A command u shaped by S = S₁ ∗ … ∗ S_F has a knot at τ_k + tᵢ for every knot k of u and
//! every impulse i of S: for a three-mode ZV-D³ and a trapezoid, 4 · 5³ = 500 knots, for six
//! modes 62 500, each of which [`Lti::respond`] carries to the next sample with a matrix
//! exponential per mode. Here the knots are never formed. A mode y'' + 2ζω y' + ω² y = g u
//! driven from rest by the polynomial a knot starts, Σₘ Jₘ vᵐ/m! (v the time since the knot),
//! answers with (Q(v), Q'(v)) + e^{Av} r: Q the polynomial particular solution, r = −(Q(0),
//! Q'(0)), and e^{Av} = e^{σv}(cos ω_d v · I + sin ω_d v · (A − σI)/ω_d) with p = σ + iω_d the
//! mode's pole. Between two samples, the knots that land there add, at the later sample t_s,
//!
//! Σᵢ Aᵢ Q(vᵢ) = Σₘ cₘ Mₘ with the moments Mₘ = Σᵢ Aᵢ vᵢᵐ, vᵢ = t_s − τ_k − tᵢ, and
//! Σᵢ Aᵢ e^{p vᵢ} = e^{p(t_s − τ_k)} · Σᵢ Aᵢ e^{−p tᵢ}.
//!
//! The last sum's terms Aᵢ e^{−p tᵢ} are products over the factors (e^{−p(a+b)} = e^{−pa}e^{−pb}),
//! formed once per shaper and mode by one complex multiplication per impulse instead of an
//! exponential, a sine and a cosine per knot and mode. The factor e^{p(t_s − τ_k)} is itself
//! a product, e^{p·jT} · e^{p(s_k T − τ_k)} (s_k the knot's first sample, j = s − s_k): a
//! table over j shared by the knots, and one value per knot and mode; and the particular
//! solution Q is the knot's, not the sample's. The command's own samples (its Taylor
//! state, for the feedthrough rows) take the moments too. The rest — each mode marched over the
//! samples, the output rows — is [`Lti::respond`]'s own. Same response to rounding (tested
//! against the expanded command in `tests/shaped_response.rs`).

use super::{Lti, LtiResponse, SampledCommand};
use crate::error::Result;
use crate::piecewise::{Piecewise, ORDER};
use crate::shaper::Impulse;

/// Largest ζω·t for which the factored sums are formed: the terms Aᵢe^{−p tᵢ} grow like
/// e^{ζω tᵢ} (each sum is then scaled back), so beyond this the plain path is used.
const MAX_GROWTH: f64 = 300.0;
/// Most knots of the unshaped command for the factored path (each adds a pass over the
/// samples).
const MAX_BASE_KNOTS: usize = 64;

/// A mode block in companion form: states (y, y'), y'' = −ω²y − 2ζω y' + g·u.
struct ModeBlock {
    start: usize,
    omega2: f64,
    /// 2ζω.
    two_zeta_omega: f64,
    gain: f64,
    /// The pole p = σ + iω_d.
    sigma: f64,
    omega_d: f64,
}

impl Lti {
    /// The response to `base` shaped by the convolution of `factors` (each an impulse sequence,
    /// times from 0), at t = k·`sample_period`, k = 0 … `samples` − 1: the same as
    /// [`Lti::respond`] on `base` shaped by the expanded shaper, to rounding (the method is
    /// derived in `crate/plant/lti/shaped.rs`). `None` when the plant is not a set of modes driven by the position alone (the
    /// modal plant), a mode is not underdamped, the sums would grow past e^300, a factor
    /// holds a negative time, or `base` has more than 64 knots: then the caller expands the
    /// command.
    pub fn respond_shaped(
        &self,
        base: &Piecewise,
        factors: &[&[Impulse]],
        sample_period: f64,
        samples: usize,
    ) -> Result<Option<LtiResponse>> {
        let Some(modes) = self.mode_blocks() else {
            return Ok(None);
        };
        let knots = base.knots();
        let span: f64 = factors
            .iter()
            .map(|f| f.last().map_or(0.0, |i| i.time))
            .sum();
        let growth = modes
            .iter()
            .map(|m| -m.sigma * (span + sample_period))
            .fold(0.0_f64, f64::max);
        // Times from 0 (a shaper's always are): a knot's impulses then land at or after its
        // first sample, where the table of `sample` starts.
        let from_zero = factors.iter().all(|f| f.iter().all(|i| i.time >= 0.0));
        let usable = growth.is_finite() && growth <= MAX_GROWTH && sample_period > 0.0 && from_zero;
        if knots.len() > MAX_BASE_KNOTS || !usable || samples == 0 {
            return Ok(None);
        }
        let q = base.degree() + 1;
        let (times, amps, ae) = expand(factors, &modes);
        let sampled = sample(
            &Sums {
                modes: &modes,
                times: &times,
                amps: &amps,
                ae: &ae,
                n: self.states(),
            },
            knots,
            q,
            sample_period,
            samples,
        );
        let maps = self
            .blocks
            .iter()
            .map(|&b| self.block_maps(b, q, sample_period))
            .collect::<Result<Vec<_>>>()?;
        let groups = self.march_modes(&maps, &sampled, samples);
        let xs = self.march_blocks(&maps, &sampled, samples);
        let outputs = self.outputs(&groups, &xs, &sampled.w, q, samples);
        Ok(Some(LtiResponse {
            outputs,
            states: None,
        }))
    }

    /// The blocks as modes in companion form driven by the position only, or `None`.
    fn mode_blocks(&self) -> Option<Vec<ModeBlock>> {
        let e_other =
            (0..self.e.nrows()).any(|i| (1..self.e.ncols()).any(|k| self.e[(i, k)] != 0.0));
        if e_other {
            return None;
        }
        self.blocks
            .iter()
            .map(|&(start, m)| {
                let a = |i: usize, j: usize| self.a[(start + i, start + j)];
                let companion = m == 2 && a(0, 0) == 0.0 && a(0, 1) == 1.0;
                let omega2 = -a(1, 0);
                let two_zeta_omega = -a(1, 1);
                let sigma = -0.5 * two_zeta_omega;
                let omega_d2 = omega2 - sigma * sigma;
                let ok = companion
                    && self.e[(start, 0)] == 0.0
                    && omega2.is_finite()
                    && two_zeta_omega.is_finite()
                    && omega_d2 > 0.0
                    && sigma <= 0.0;
                ok.then(|| ModeBlock {
                    start,
                    omega2,
                    two_zeta_omega,
                    gain: self.e[(start + 1, 0)],
                    sigma,
                    omega_d: omega_d2.sqrt(),
                })
            })
            .collect()
    }
}

/// The expanded shaper, never sorted: every impulse's time and amplitude (summed and
/// multiplied in the order [`crate::shaper::Shaper::convolve`] uses), and per impulse and mode
/// Aᵢe^{−p tᵢ} as (re, im), `modes` values per impulse.
type Expanded = (Vec<f64>, Vec<f64>, Vec<[f64; 2]>);

fn expand(factors: &[&[Impulse]], modes: &[ModeBlock]) -> Expanded {
    let nm = modes.len();
    let mut times = vec![0.0];
    let mut amps = vec![1.0];
    let mut ae = vec![[1.0, 0.0]; nm];
    for factor in factors {
        // e^{−p t} of this factor's impulses, per mode.
        let rot: Vec<[f64; 2]> = factor
            .iter()
            .flat_map(|imp| {
                modes.iter().map(move |m| {
                    let w = (-m.sigma * imp.time).exp();
                    let (s, c) = (m.omega_d * imp.time).sin_cos();
                    [w * c, -w * s]
                })
            })
            .collect();
        let n = times.len() * factor.len();
        let (mut t2, mut a2, mut e2) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n * nm),
        );
        for (i, (&t, &a)) in times.iter().zip(&amps).enumerate() {
            let e = &ae[i * nm..(i + 1) * nm];
            for (j, imp) in factor.iter().enumerate() {
                t2.push(t + imp.time);
                a2.push(a * imp.amplitude);
                let r = &rot[j * nm..(j + 1) * nm];
                e2.extend(e.iter().zip(r).map(|(x, y)| {
                    let re = (x[0] * y[0] - x[1] * y[1]) * imp.amplitude;
                    let im = (x[0] * y[1] + x[1] * y[0]) * imp.amplitude;
                    [re, im]
                }));
            }
        }
        (times, amps, ae) = (t2, a2, e2);
    }
    (times, amps, ae)
}

/// What [`sample`] sums over.
struct Sums<'a> {
    modes: &'a [ModeBlock],
    times: &'a [f64],
    amps: &'a [f64],
    ae: &'a [[f64; 2]],
    /// States of the plant.
    n: usize,
}

/// The shaped command at the samples and the knots' state jumps per sample (pass 1 of
/// [`Lti::respond`], by the factored sums of the module docs).
fn sample(
    sums: &Sums<'_>,
    knots: &[crate::piecewise::Knot],
    q: usize,
    period: f64,
    samples: usize,
) -> SampledCommand {
    let (modes, n) = (sums.modes, sums.n);
    let nm = modes.len();
    // Per sample: the moments M₀ … M_{q−1} and, per mode, Σ Aᵢe^{−p tᵢ} of the knots landing
    // in (t_{s−1}, t_s], for one knot of `base` at a time.
    let width = q + 2 * nm;
    let mut bucket = vec![0.0; samples * width];
    let mut hit = vec![false; samples];
    let mut dw = vec![0.0; samples * q];
    let mut jump = vec![0.0; samples * n];
    let mut any_jump = vec![false; samples];
    // Per mode, the particular solution of the knot's polynomial (q + 2 coefficients): the same
    // at every sample the knot's impulses land on.
    let mut cs = vec![0.0; nm * (q + 2)];
    // e^{p(t_s − τ_k)} at a sample s the knot at τ_k reaches, as e^{p·jT} · e^{p(s_k T − τ_k)}
    // with s_k the knot's first sample and j = s − s_k: the first factor from a table shared
    // by the knots (filled as far as a knot reaches), the second once per knot and mode, each
    // (re, im) per mode. Both have σ ≤ 0 and arguments ≥ 0, so neither overflows.
    let mut table: Vec<f64> = Vec::new();
    let mut lead = vec![0.0; 2 * nm];
    for knot in knots {
        let jumps = &knot.jumps[..q.min(ORDER)];
        for (mode, c) in modes.iter().zip(cs.chunks_exact_mut(q + 2)) {
            particular(mode, jumps, c);
        }
        // Past the samples too (none of its impulses then lands on one).
        let first = sample_at(knot.time, period, usize::MAX).unwrap_or(usize::MAX);
        let delta = first as f64 * period - knot.time;
        for (mode, l) in modes.iter().zip(lead.chunks_exact_mut(2)) {
            l.copy_from_slice(&pole_exp(mode, delta));
        }
        for (i, (&t, &a)) in sums.times.iter().zip(sums.amps).enumerate() {
            let time = knot.time + t;
            let Some(s) = sample_at(time, period, samples) else {
                continue;
            };
            hit[s] = true;
            let v = s as f64 * period - time;
            let row = &mut bucket[s * width..(s + 1) * width];
            let mut power = a;
            for m in row[..q].iter_mut() {
                *m += power;
                power *= v;
            }
            for (z, e) in row[q..]
                .chunks_exact_mut(2)
                .zip(&sums.ae[i * nm..(i + 1) * nm])
            {
                z[0] += e[0];
                z[1] += e[1];
            }
        }
        for s in 0..samples {
            // Each row used is read once and emptied for the next knot.
            if !std::mem::take(&mut hit[s]) {
                continue;
            }
            let row = &bucket[s * width..(s + 1) * width];
            let (moments, z) = row.split_at(q);
            // The command: Δw_m = Σ_l J_{m+l} M_l / l!.
            for (m, d) in dw[s * q..(s + 1) * q].iter_mut().enumerate() {
                let mut f = 1.0;
                for (l, mo) in moments.iter().enumerate().take(q - m) {
                    if l > 0 {
                        f /= l as f64;
                    }
                    *d += jumps.get(m + l).copied().unwrap_or(0.0) * mo * f;
                }
            }
            let j = s - first;
            while table.len() < 2 * nm * (j + 1) {
                let v = (table.len() / (2 * nm)) as f64 * period;
                for mode in modes {
                    table.extend_from_slice(&pole_exp(mode, v));
                }
            }
            let after = &table[2 * nm * j..2 * nm * (j + 1)];
            any_jump[s] = true;
            let out = &mut jump[s * n..(s + 1) * n];
            for ((((mode, zm), c), e), l) in modes
                .iter()
                .zip(z.chunks_exact(2))
                .zip(cs.chunks_exact(q + 2))
                .zip(after.chunks_exact(2))
                .zip(lead.chunks_exact(2))
            {
                let y = c.iter().zip(moments).map(|(c, m)| c * m).sum::<f64>();
                let dy = (1..q)
                    .map(|m| m as f64 * c[m] * moments[m - 1])
                    .sum::<f64>();
                // Σ Aᵢ e^{p vᵢ} = e^{p(t_s − τ_k)} · Σ Aᵢ e^{−p tᵢ}.
                let (er, ei) = (e[0] * l[0] - e[1] * l[1], e[0] * l[1] + e[1] * l[0]);
                let (re, im) = (er * zm[0] - ei * zm[1], er * zm[1] + ei * zm[0]);
                // e^{Av} r summed: Re·r + Im·(A − σI)r/ω_d, r = −(Q(0), Q'(0)).
                let (r0, r1) = (-c[0], -c[1]);
                let zo = -mode.sigma; // ζω
                let (b0, b1) = (zo * r0 + r1, -mode.omega2 * r0 - zo * r1);
                out[mode.start] += y + re * r0 + im * b0 / mode.omega_d;
                out[mode.start + 1] += dy + re * r1 + im * b1 / mode.omega_d;
            }
            bucket[s * width..(s + 1) * width].fill(0.0);
        }
    }
    assemble(&dw, &jump, &any_jump, (q, n), period)
}

/// The command's Taylor state at every sample from what landed between samples (`dw`), and the
/// state jumps as events (the samples `any_jump` marks, n values each).
fn assemble(
    dw: &[f64],
    jump: &[f64],
    any_jump: &[bool],
    (q, n): (usize, usize),
    period: f64,
) -> SampledCommand {
    let samples = any_jump.len();
    // w at the samples: the previous sample's Taylor state shifted by one period, plus what
    // landed in between.
    let mut w = vec![0.0; samples * q];
    let mut shifted = vec![0.0; q];
    for s in 0..samples {
        if s > 0 {
            let (done, rest) = w.split_at_mut(s * q);
            super::taylor_shift(&done[(s - 1) * q..], period, &mut shifted);
            rest[..q].copy_from_slice(&shifted);
        }
        for (x, d) in w[s * q..(s + 1) * q].iter_mut().zip(&dw[s * q..]) {
            *x += d;
        }
    }
    let mut event_at = Vec::new();
    let mut event_jump = Vec::new();
    for s in (0..samples).filter(|&s| any_jump[s]) {
        event_at.push(s);
        event_jump.extend_from_slice(&jump[s * n..(s + 1) * n]);
    }
    SampledCommand {
        w,
        q,
        event_at,
        event_jump,
    }
}

/// The first sample t_s = s·`period` at or after `time` (where [`Lti::respond`] takes a knot
/// in), if there is one.
fn sample_at(time: f64, period: f64, samples: usize) -> Option<usize> {
    let mut s = (time / period).ceil().max(0.0) as usize;
    if s > 0 && ((s - 1) as f64 * period) >= time {
        s -= 1;
    }
    if (s as f64 * period) < time {
        s += 1;
    }
    (s < samples).then_some(s)
}

/// e^{p·v} as (re, im) for the pole p = σ + iω_d.
#[inline(never)]
fn pole_exp(mode: &ModeBlock, v: f64) -> [f64; 2] {
    let w = (mode.sigma * v).exp();
    let (sn, cn) = (mode.omega_d * v).sin_cos();
    [w * cn, w * sn]
}

/// The particular solution Q(v) = Σ cₘ vᵐ of y'' + 2ζω y' + ω²y = g Σₘ Jₘ vᵐ/m!, written into
/// `c` (q + 2 entries, the last two 0).
fn particular(mode: &ModeBlock, jumps: &[f64], c: &mut [f64]) {
    c.iter_mut().for_each(|x| *x = 0.0);
    let q = jumps.len();
    let mut factorial = [1.0; ORDER];
    for m in 1..q {
        factorial[m] = factorial[m - 1] * m as f64;
    }
    for m in (0..q).rev() {
        let rhs = mode.gain * jumps[m] / factorial[m]
            - (m + 2) as f64 * (m + 1) as f64 * c[m + 2]
            - mode.two_zeta_omega * (m + 1) as f64 * c[m + 1];
        c[m] = rhs / mode.omega2;
    }
}
