//! Piecewise polynomials in jump form, the shape every analytic command takes and plants,
//! metrics and spectra read.
//!
//! A [`Piecewise`] is a list of knots, each giving the jumps of the position and its
//! derivatives at that time, so that
//!
//! u(t) = Σ_{τⱼ ≤ t} Σₖ Jⱼₖ (t − τⱼ)ᵏ / k!.
//!
//! Shaping by an impulse sequence (Σ Aᵢ δ(t − tᵢ)) is then exact: each knot is copied to
//! τⱼ + tᵢ with its jumps times Aᵢ (Singhose 2009 Fig. 5). A `Cursor` walks one forward in
//! time; `taylor_shift` moves a Taylor state between knots.

use crate::error::{finite, Error, Result};
use crate::shaper::Shaper;

/// Highest polynomial degree of a piecewise command's position (a profile of 8 convolved
/// pulses has a position of degree 8).
pub const MAX_DEGREE: usize = 8;
/// Number of stored derivatives (position and its derivatives up to [`MAX_DEGREE`]).
pub const ORDER: usize = MAX_DEGREE + 1;
/// Most knots a piecewise command may hold (after shaping).
pub const MAX_KNOTS: usize = 200_000;

/// One knot of a piecewise command: at `time`, the position's k-th derivative jumps by
/// `jumps[k]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Knot {
    /// Time in seconds.
    pub time: f64,
    /// Jumps of the position (k = 0), velocity (1), acceleration (2), jerk (3), … .
    pub jumps: [f64; ORDER],
}

/// A piecewise-polynomial command in jump form (see the module docs). Knots are sorted by
/// time, none repeated; before the first knot the command is 0.
#[derive(Debug, Clone, PartialEq)]
pub struct Piecewise {
    knots: Vec<Knot>,
    degree: usize,
}

/// Most knots of a command that [`Piecewise::shaped`] merges as sorted runs (each step looks at
/// every run's head).
const MERGED_RUNS: usize = 16;

/// Knots closer than this (relative to the command's span, absolute floor 1e-15 s) are merged.
const KNOT_MERGE: f64 = 1e-12;

impl Piecewise {
    /// Builds a command from knots in any order; knots at the same time are merged, knots whose
    /// jumps are all zero are dropped. Errors: non-finite values, more than [`MAX_KNOTS`].
    pub fn new(knots: Vec<Knot>) -> Result<Self> {
        if knots.len() > MAX_KNOTS {
            return Err(Error::TooLarge {
                field: "command".into(),
                value: knots.len() as f64,
                limit: MAX_KNOTS as f64,
            });
        }
        for k in &knots {
            finite("command.time", k.time)?;
            for j in k.jumps {
                finite("command", j)?;
            }
        }
        let mut sorted = knots;
        crate::sort::sort_by(&mut sorted, |a, b| a.time.total_cmp(&b.time));
        let span = match (sorted.first(), sorted.last()) {
            (Some(a), Some(b)) => (b.time - a.time).abs().max(a.time.abs()).max(b.time.abs()),
            _ => 0.0,
        };
        let tol = (KNOT_MERGE * span).max(1e-15);
        let mut merged: Vec<Knot> = Vec::with_capacity(sorted.len());
        for k in sorted {
            match merged.last_mut() {
                Some(last) if k.time - last.time <= tol => {
                    for (a, b) in last.jumps.iter_mut().zip(k.jumps) {
                        *a += b;
                    }
                }
                _ => merged.push(k),
            }
        }
        merged.retain(|k| k.jumps.iter().any(|&j| j != 0.0));
        let degree = merged
            .iter()
            .filter_map(|k| k.jumps.iter().rposition(|&j| j != 0.0))
            .max()
            .unwrap_or(0);
        Ok(Piecewise {
            knots: merged,
            degree,
        })
    }

    /// The knots, sorted by time.
    pub fn knots(&self) -> &[Knot] {
        &self.knots
    }

    /// Highest derivative that jumps anywhere: the position's polynomial degree.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// Time of the first knot (0 if there is none).
    pub fn start_time(&self) -> f64 {
        self.knots.first().map_or(0.0, |k| k.time)
    }

    /// Time of the last knot: after it the command is a single polynomial (the move has ended
    /// if that polynomial is constant).
    pub fn end_time(&self) -> f64 {
        self.knots.last().map_or(0.0, |k| k.time)
    }

    /// The derivatives u, u', u'', … just after the last knot.
    pub fn final_state(&self) -> [f64; ORDER] {
        let mut c = Cursor::new(self);
        c.seek(self.end_time());
        c.state_at(self.end_time())
    }

    /// True when the command ends at rest: all derivatives of order ≥ 1 vanish after the last
    /// knot (to rounding, relative to the largest jump).
    pub fn ends_at_rest(&self) -> bool {
        let scale = self
            .knots
            .iter()
            .flat_map(|k| k.jumps.iter().skip(1))
            .fold(0.0_f64, |m, j| m.max(j.abs()));
        let end = self.final_state();
        end.iter()
            .skip(1)
            .all(|d| d.abs() <= 1e-9 * scale.max(f64::MIN_POSITIVE))
    }

    /// u and its first three derivatives (position, velocity, acceleration, jerk) at `t`.
    pub fn eval(&self, t: f64) -> [f64; 4] {
        let mut c = Cursor::new(self);
        c.seek(t);
        let s = c.state_at(t);
        [s[0], s[1], s[2], s[3]]
    }

    /// The command convolved with `shaper` (exact): every knot copied to τ + tᵢ with its jumps
    /// scaled by Aᵢ. Errors when the result would exceed [`MAX_KNOTS`].
    pub fn shaped(&self, shaper: &Shaper) -> Result<Piecewise> {
        let n = self.knots.len().saturating_mul(shaper.len());
        if n > MAX_KNOTS {
            return Err(Error::TooLarge {
                field: "command".into(),
                value: n as f64,
                limit: MAX_KNOTS as f64,
            });
        }
        // Knot by knot, each followed by every impulse: runs already sorted by time, which the
        // stable sort in `new` merges instead of sorting the whole (a 6-mode ZVDD shapes a
        // trapezoid into 4 runs of 4096 knots). With few knots the runs are merged here, ties
        // to the earlier run: the stable sort's order of their concatenation, so the same
        // command to the last bit, and `new` finds it sorted (no index sort, no permutation
        // of the 80-byte knots: 62 500 for a 6-mode ZV-D³).
        if self.knots.len() <= MERGED_RUNS {
            return Piecewise::new(self.shaped_runs_merged(shaper.impulses(), n));
        }
        let mut knots = Vec::with_capacity(n);
        for k in &self.knots {
            for imp in shaper.impulses() {
                let mut jumps = k.jumps;
                for j in &mut jumps {
                    *j *= imp.amplitude;
                }
                knots.push(Knot {
                    time: k.time + imp.time,
                    jumps,
                });
            }
        }
        Piecewise::new(knots)
    }

    /// The `n` knots of [`Piecewise::shaped`] in time order: the runs (one per knot, shifted by
    /// every impulse, each sorted since addition is monotone) merged, a tie going to the
    /// earlier run and, within a run, to the earlier impulse.
    fn shaped_runs_merged(&self, impulses: &[crate::shaper::Impulse], n: usize) -> Vec<Knot> {
        let mut heads = vec![0_usize; self.knots.len()];
        let mut knots = Vec::with_capacity(n);
        loop {
            let mut best: Option<(usize, f64)> = None;
            for (r, k) in self.knots.iter().enumerate() {
                if let Some(imp) = impulses.get(heads[r]) {
                    let t = k.time + imp.time;
                    if best.is_none_or(|(_, b)| t.total_cmp(&b).is_lt()) {
                        best = Some((r, t));
                    }
                }
            }
            let Some((r, time)) = best else {
                return knots;
            };
            let amplitude = impulses[heads[r]].amplitude;
            heads[r] += 1;
            let mut jumps = self.knots[r].jumps;
            for j in &mut jumps {
                *j *= amplitude;
            }
            knots.push(Knot { time, jumps });
        }
    }

    /// The derivative of the command (its jumps moved one order down; the position jumps
    /// become impulses, which are dropped — use only for commands with continuous position).
    pub fn derivative(&self) -> Result<Piecewise> {
        Piecewise::new(
            self.knots
                .iter()
                .map(|k| {
                    let mut jumps = [0.0; ORDER];
                    jumps[..ORDER - 1].copy_from_slice(&k.jumps[1..]);
                    Knot {
                        time: k.time,
                        jumps,
                    }
                })
                .collect(),
        )
    }

    /// The integral of the command from −∞ (its jumps moved one order up). Errors if a jump of
    /// the highest stored order would be lost.
    pub fn integral(&self) -> Result<Piecewise> {
        if self.degree >= MAX_DEGREE {
            return Err(Error::TooLarge {
                field: "command".into(),
                value: (self.degree + 1) as f64,
                limit: MAX_DEGREE as f64,
            });
        }
        Piecewise::new(
            self.knots
                .iter()
                .map(|k| {
                    let mut jumps = [0.0; ORDER];
                    jumps[1..].copy_from_slice(&k.jumps[..ORDER - 1]);
                    Knot {
                        time: k.time,
                        jumps,
                    }
                })
                .collect(),
        )
    }
}

/// Shifts a Taylor state (u, u', u'', …, degree `deg`) forward by `h` seconds, exactly for a
/// polynomial of that degree: uₖ(t + h) = Σ_{m ≥ k} uₘ(t) hᵐ⁻ᵏ/(m − k)!.
pub(crate) fn taylor_shift(state: &[f64; ORDER], deg: usize, h: f64) -> [f64; ORDER] {
    let mut out = [0.0; ORDER];
    let deg = deg.min(MAX_DEGREE);
    for (k, o) in out.iter_mut().enumerate().take(deg + 1) {
        let mut sum = 0.0;
        let mut pw = 1.0; // h^{m-k}/(m-k)!
        for (i, s) in state[k..=deg].iter().enumerate() {
            if i > 0 {
                pw *= h / i as f64;
            }
            sum += s * pw;
        }
        *o = sum;
    }
    out
}

/// Walks a piecewise command forward in time, keeping the Taylor state at the last knot
/// passed (an *anchor*), so that values between knots are computed from the nearest knot
/// rather than accumulated.
#[derive(Debug, Clone)]
pub(crate) struct Cursor<'a> {
    pw: &'a Piecewise,
    next: usize,
    anchor_time: f64,
    anchor: [f64; ORDER],
}

impl<'a> Cursor<'a> {
    pub(crate) fn new(pw: &'a Piecewise) -> Self {
        Cursor {
            pw,
            next: 0,
            anchor_time: pw.start_time(),
            anchor: [0.0; ORDER],
        }
    }

    /// Index of the next knot not yet passed.
    pub(crate) fn next_index(&self) -> usize {
        self.next
    }

    /// Passes every knot at time ≤ `t` (knots at exactly `t` are included: the command is
    /// right-continuous).
    pub(crate) fn seek(&mut self, t: f64) {
        while let Some(k) = self.pw.knots.get(self.next) {
            if k.time > t {
                break;
            }
            self.pass_next();
        }
    }

    /// Passes the next knot.
    pub(crate) fn pass_next(&mut self) {
        if let Some(k) = self.pw.knots.get(self.next) {
            let mut s = taylor_shift(&self.anchor, self.pw.degree, k.time - self.anchor_time);
            for (a, j) in s.iter_mut().zip(k.jumps) {
                *a += j;
            }
            self.anchor = s;
            self.anchor_time = k.time;
            self.next += 1;
        }
    }

    /// The Taylor state at `t` (≥ the anchor's time, before the next knot).
    pub(crate) fn state_at(&self, t: f64) -> [f64; ORDER] {
        if self.next == 0 {
            return [0.0; ORDER];
        }
        taylor_shift(&self.anchor, self.pw.degree, t - self.anchor_time)
    }
}
