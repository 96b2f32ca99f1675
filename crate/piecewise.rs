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
            // Checked inline, the error built only for a bad value (a shaped 6-mode command
            // has 62 500 knots of 10 numbers).
            if !k.time.is_finite() || k.jumps.iter().any(|j| !j.is_finite()) {
                finite("command.time", k.time)?;
                for j in k.jumps {
                    finite("command", j)?;
                }
            }
        }
        let mut sorted = knots;
        crate::sort::sort_by_f64_key(&mut sorted, |k| k.time);
        let tol = merge_tolerance(
            sorted
                .first()
                .zip(sorted.last())
                .map(|(a, b)| (a.time, b.time)),
        );
        let mut merged = Vec::with_capacity(sorted.len());
        merged.extend(MergedKnots::new(Box::new(sorted.into_iter()), tol));
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
        let n = self.shaped_len(shaper)?;
        // Knot by knot, each followed by every impulse: runs already sorted by time, which the
        // stable sort in `new` merges instead of sorting the whole (a 6-mode ZVDD shapes a
        // trapezoid into 4 runs of 4096 knots). With few knots the runs are merged here, ties
        // to the earlier run: the stable sort's order of their concatenation, so the same
        // command to the last bit, and `new` finds it sorted (no index sort, no permutation
        // of the 80-byte knots: 62 500 for a 6-mode ZV-D³).
        if self.knots.len() <= MERGED_RUNS {
            return Piecewise::new(ShapedRuns::new(&self.knots, shaper.impulses()).collect());
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

    /// The number of knots shaping by `shaper` makes before merging; errors past [`MAX_KNOTS`].
    fn shaped_len(&self, shaper: &Shaper) -> Result<usize> {
        let n = self.knots.len().saturating_mul(shaper.len());
        if n > MAX_KNOTS {
            return Err(Error::TooLarge {
                field: "command".into(),
                value: n as f64,
                limit: MAX_KNOTS as f64,
            });
        }
        Ok(n)
    }

    /// The knots of [`Piecewise::shaped`] one by one, in time order, without forming the
    /// command: the knots `shaped(shaper)` stores, merged the same way (what walks the shaped
    /// command once, like its peaks, need not hold 62 500 knots of 80 bytes). `None` for a
    /// command of more than 16 knots (shaped by a sort). The shaped command's degree is this
    /// one's unless its highest jumps cancel exactly. The knots are not checked finite: their
    /// reader checks them (an infinite product stays infinite, or becomes NaN when merged).
    pub(crate) fn shaped_knots<'a>(
        &'a self,
        shaper: &'a Shaper,
    ) -> Result<Option<MergedKnots<'a>>> {
        self.shaped_len(shaper)?;
        if self.knots.len() > MERGED_RUNS {
            return Ok(None);
        }
        let runs = ShapedRuns::new(&self.knots, shaper.impulses());
        let tol = runs.merge_tolerance();
        Ok(Some(MergedKnots::new(Box::new(runs), tol)))
    }

    /// [`Piecewise::shaped_knots`] for a command of degree ≤ 2 (jumps in position, velocity and
    /// acceleration only: trapezoids, triangles), each knot as its time and those three jumps:
    /// the same knots merged the same way, to the bit, in 32 bytes a knot instead of 80 — what
    /// the shaped command's figures walk (`CommandFigures::of_shaped`: a six-mode ZV-D³ shapes
    /// a trapezoid into 62 500 knots, and moving 80-byte knots through the merge was most of
    /// that walk's time). `None` for a higher degree or more than 16 knots. Errors as `shaped`.
    pub(crate) fn shaped_steps<'a>(
        &'a self,
        shaper: &'a Shaper,
    ) -> Result<Option<ShapedSteps<'a>>> {
        self.shaped_len(shaper)?;
        if self.knots.len() > MERGED_RUNS || self.degree > 2 {
            return Ok(None);
        }
        let runs = ShapedRuns::new(&self.knots, shaper.impulses());
        let mut steps = ShapedSteps {
            tol: runs.merge_tolerance(),
            runs,
            pending: None,
        };
        steps.pending = steps.raw();
        Ok(Some(steps))
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

/// How close knots from `first` to `last` (sorted; `None`: no knots) must be to be merged:
/// [`KNOT_MERGE`] times their span (the largest of the distance between them and their
/// magnitudes), at least 1e-15 s.
fn merge_tolerance(ends: Option<(f64, f64)>) -> f64 {
    let span = ends.map_or(0.0, |(first, last)| {
        (last - first).abs().max(first.abs()).max(last.abs())
    });
    (KNOT_MERGE * span).max(1e-15)
}

/// The knots of a command shaped by an impulse sequence, in time order, not yet merged: one run
/// per knot of the command (shifted by every impulse, sorted since addition is monotone)
/// merged, a tie going to the earlier run and, within a run, to the earlier impulse — the
/// order a stable sort gives the runs' concatenation, so the same command to the last bit.
pub(crate) struct ShapedRuns<'a> {
    runs: &'a [Knot],
    impulses: &'a [crate::shaper::Impulse],
    heads: Vec<usize>,
    left: usize,
}

impl<'a> ShapedRuns<'a> {
    fn new(runs: &'a [Knot], impulses: &'a [crate::shaper::Impulse]) -> Self {
        ShapedRuns {
            runs,
            impulses,
            heads: vec![0; runs.len()],
            left: runs.len() * impulses.len(),
        }
    }

    /// The earliest knot's time (the impulses are sorted by time).
    fn first_time(&self) -> Option<f64> {
        let t0 = self.impulses.first()?.time;
        self.runs.iter().map(|k| k.time + t0).reduce(f64::min)
    }

    /// The latest knot's time.
    fn last_time(&self) -> Option<f64> {
        let t1 = self.impulses.last()?.time;
        self.runs.iter().map(|k| k.time + t1).reduce(f64::max)
    }

    /// [`merge_tolerance`] of the knots the runs give.
    fn merge_tolerance(&self) -> f64 {
        merge_tolerance(self.first_time().zip(self.last_time()))
    }
}

impl Iterator for ShapedRuns<'_> {
    type Item = Knot;

    fn next(&mut self) -> Option<Knot> {
        let mut best: Option<(usize, f64)> = None;
        for (r, k) in self.runs.iter().enumerate() {
            if let Some(imp) = self.impulses.get(self.heads[r]) {
                let t = k.time + imp.time;
                if best.is_none_or(|(_, b)| t.total_cmp(&b).is_lt()) {
                    best = Some((r, t));
                }
            }
        }
        let (r, time) = best?;
        let amplitude = self.impulses[self.heads[r]].amplitude;
        self.heads[r] += 1;
        self.left -= 1;
        let mut jumps = self.runs[r].jumps;
        for j in &mut jumps {
            *j *= amplitude;
        }
        Some(Knot { time, jumps })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.left, Some(self.left))
    }
}

/// A knot of a command of degree ≤ 2: its time and its jumps in position, velocity and
/// acceleration.
pub(crate) type Step = (f64, [f64; 3]);

/// The knots of [`Piecewise::shaped_steps`]: [`ShapedRuns`] merged as [`MergedKnots`] merges
/// them, on [`Step`]s — the same merging (into the first knot within the tolerance, jumps
/// summed in order) and the same knots dropped (all jumps zero: above acceleration they are
/// zero in a command of degree ≤ 2).
pub(crate) struct ShapedSteps<'a> {
    runs: ShapedRuns<'a>,
    tol: f64,
    pending: Option<Step>,
}

impl ShapedSteps<'_> {
    /// The next knot before merging.
    fn raw(&mut self) -> Option<Step> {
        let k = self.runs.next()?;
        Some((k.time, [k.jumps[0], k.jumps[1], k.jumps[2]]))
    }
}

impl Iterator for ShapedSteps<'_> {
    type Item = Step;

    fn next(&mut self) -> Option<Step> {
        loop {
            let (time, mut jumps) = self.pending.take()?;
            loop {
                match self.raw() {
                    Some((t, j)) if t - time <= self.tol => {
                        for (a, b) in jumps.iter_mut().zip(j) {
                            *a += b;
                        }
                    }
                    next => {
                        self.pending = next;
                        break;
                    }
                }
            }
            if jumps.iter().any(|&j| j != 0.0) {
                return Some((time, jumps));
            }
        }
    }
}

/// Knots in time order with the knots closer than [`KNOT_MERGE`] × `span` (floor 1e-15 s)
/// merged into the first of them (jumps summed in order) and the knots whose jumps are all
/// zero dropped: what a [`Piecewise`] keeps. Over a boxed iterator: one copy in the module for
/// both of its sources (a command's sorted knots, a shaped command's runs).
pub(crate) struct MergedKnots<'a> {
    sorted: Box<dyn Iterator<Item = Knot> + 'a>,
    tol: f64,
    pending: Option<Knot>,
}

impl<'a> MergedKnots<'a> {
    fn new(mut sorted: Box<dyn Iterator<Item = Knot> + 'a>, tol: f64) -> Self {
        let pending = sorted.next();
        MergedKnots {
            sorted,
            tol,
            pending,
        }
    }
}

impl Iterator for MergedKnots<'_> {
    type Item = Knot;

    fn next(&mut self) -> Option<Knot> {
        loop {
            let mut out = self.pending.take()?;
            loop {
                match self.sorted.next() {
                    Some(k) if k.time - out.time <= self.tol => {
                        for (a, b) in out.jumps.iter_mut().zip(k.jumps) {
                            *a += b;
                        }
                    }
                    next => {
                        self.pending = next;
                        break;
                    }
                }
            }
            if out.jumps.iter().any(|&j| j != 0.0) {
                return Some(out);
            }
        }
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
