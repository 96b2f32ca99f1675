//! What the papers judge a shaped move by: residual vibration after the move, settling and
//! rise time, ramp delay, deflection during the move, peak acceleration and jerk, and the
//! acceleration peak-valley count (fatigue; Veciana & Cardona 2011 §3.1).
//!
//! Signal-based metrics read the simulated [`Trajectory`], so they work for every plant,
//! including the nonlinear pendulum; command-based ones (peaks, peak-valley count) read the
//! command exactly where it is piecewise polynomial.

use crate::command::Command;
use crate::error::{finite, Result};
use crate::piecewise::{taylor_shift, Knot, Piecewise, Step, ORDER};
use crate::plant::modal::ModalPlant;
use crate::simulate::Trajectory;
use serde::Serialize;

/// Points per polynomial piece at which command-based metrics sample the command.
const PER_PIECE: usize = 64;

/// Metrics of one simulated move. Times in seconds from t = 0; percentages of the move's
/// distance. `None` (JSON `null`) when a metric does not apply (e.g. no settling for a ramp).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Metrics {
    /// When the applied command stops changing (its last knot).
    pub move_end: f64,
    /// Distance of the reference move (final minus initial base position), if it ends at rest.
    pub distance: Option<f64>,
    /// Largest |endpoint − final position| after `moveEnd`, in % of |distance| (the vibration
    /// error of Singer & Seering 1988 §2.2.1, measured on the response).
    pub residual_vibration_percent: Option<f64>,
    /// Largest |endpoint − final position| after `moveEnd` (length units).
    pub residual_amplitude: Option<f64>,
    /// Residual vibration amplitude of each mode at `moveEnd`, in % of what an unshaped step
    /// of the same distance leaves (modal plants only). For a shaped step this is exactly
    /// 100·V(ω, ζ) (Singhose 2009 eq. 11).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mode_residual_percent: Option<Vec<f64>>,
    /// Time after which the endpoint stays within 2 % of the distance around the final
    /// position (within the simulated window).
    pub settling_time2: Option<f64>,
    /// Same with a 5 % band.
    pub settling_time5: Option<f64>,
    /// Time for the endpoint to go from 10 % to 90 % of the distance (first crossings).
    pub rise_time: Option<f64>,
    /// Ramp delay τ: how far the endpoint lags the reference ramp at the end of the window,
    /// (r − y)/r' (Kamel et al. eq. 10 predicts τ = 2ζ/ω + Σ Aᵢtᵢ). Only for commands that end
    /// moving.
    pub delay: Option<f64>,
    /// Largest |deflection| while the command moves (t ≤ `moveEnd`).
    pub peak_deflection: f64,
    /// Largest |base acceleration| of the command (`null` if the velocity jumps: unbounded).
    pub peak_acceleration: Option<f64>,
    /// Largest |jerk| of the command (`null` if the acceleration jumps: unbounded).
    pub peak_jerk: Option<f64>,
    /// Number of peaks and valleys (turning points) of the command's acceleration — the
    /// fatigue count of Veciana & Cardona 2011 §3.1.
    pub acceleration_peak_valley_count: usize,
}

/// Computes the metrics of `trajectory`, the response to `applied` (the command actually sent,
/// shaped or not); distances, settling and delay refer to `reference` (the unshaped command).
pub fn metrics(trajectory: &Trajectory, applied: &Command, reference: &Command) -> Result<Metrics> {
    metrics_with(trajectory, &CommandFigures::of(applied)?, reference)
}

/// [`metrics`] with the applied command's own figures already known (`applied`: those of the
/// command `trajectory` responds to).
pub fn metrics_with(
    trajectory: &Trajectory,
    applied: &CommandFigures,
    reference: &Command,
) -> Result<Metrics> {
    let t = &trajectory.time;
    let y = &trajectory.endpoint;
    let move_end = applied.move_end;
    let ref_pw = reference.to_piecewise()?;
    let at_rest = ref_pw.ends_at_rest();
    let final_pos = ref_pw.final_state()[0];
    let distance = at_rest.then_some(final_pos);
    let d = final_pos.abs();
    let usable = at_rest && d > 0.0;

    let residual_amplitude = if at_rest {
        t.iter()
            .zip(y)
            .filter(|(ti, _)| **ti >= move_end)
            .map(|(_, yi)| (yi - final_pos).abs())
            .reduce(f64::max)
    } else {
        None
    };
    let residual_vibration_percent = residual_amplitude.filter(|_| usable).map(|a| 100.0 * a / d);
    let settling = |band: f64| -> Option<f64> {
        if !usable {
            return None;
        }
        let last_out = y.iter().rposition(|yi| (yi - final_pos).abs() > band * d);
        match last_out {
            None => Some(0.0),
            Some(i) if i + 1 < t.len() => Some(t[i + 1]),
            Some(_) => None,
        }
    };
    let crossing = |level: f64| -> Option<f64> {
        let target = level * final_pos;
        for i in 1..y.len() {
            let (a, b) = (y[i - 1] - target, y[i] - target);
            if (a < 0.0) != (b < 0.0) || b == 0.0 {
                let f = if a == b { 1.0 } else { a / (a - b) };
                return Some(t[i - 1] + f * (t[i] - t[i - 1]));
            }
        }
        None
    };
    let rise_time = if usable {
        match (crossing(0.1), crossing(0.9)) {
            (Some(a), Some(b)) => Some(b - a),
            _ => None,
        }
    } else {
        None
    };
    let delay = match (t.last(), y.last()) {
        (Some(&te), Some(&ye)) if !at_rest => {
            let r = ref_pw.eval(te);
            (r[1] != 0.0).then(|| (r[0] - ye) / r[1])
        }
        _ => None,
    };
    let peak_deflection = t
        .iter()
        .zip(&trajectory.deflection)
        .filter(|(ti, _)| **ti <= move_end)
        .map(|(_, d)| d.abs())
        .fold(0.0, f64::max);
    Ok(Metrics {
        move_end,
        distance,
        residual_vibration_percent,
        residual_amplitude,
        mode_residual_percent: None,
        settling_time2: settling(0.02),
        settling_time5: settling(0.05),
        rise_time,
        delay,
        peak_deflection,
        peak_acceleration: applied.peak_acceleration,
        peak_jerk: applied.peak_jerk,
        acceleration_peak_valley_count: applied.acceleration_peak_valley_count,
    })
}

/// Residual vibration of each mode of `plant` when `command` ends (its last knot), in % of
/// the residual an unshaped step of the same distance leaves (D/√(1−ζ²) in the amplitude
/// measure √(e² + ((e' + ζωe)/ω_d)²), e = y − final). Computed exactly: the plant is sampled
/// at t = 0 and at the move's end. `None` if the command does not end at rest or covers no
/// distance.
pub fn mode_residual_percent(plant: &ModalPlant, command: &Piecewise) -> Result<Option<Vec<f64>>> {
    if !command.ends_at_rest() {
        return Ok(None);
    }
    let d = command.final_state()[0];
    if d == 0.0 {
        return Ok(None);
    }
    let end = command.end_time();
    let sys = plant.to_lti();
    let (period, samples) = if end > 0.0 { (end, 2) } else { (1.0, 1) };
    let r = sys.respond(command, period, samples, true)?;
    let states = r.states.unwrap_or_default();
    let n = sys.states();
    let last = &states[states.len().saturating_sub(n)..];
    Ok(Some(
        plant
            .modes()
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let (w, z, wd) = (m.omega_rad_s(), m.damping(), m.damped_omega_rad_s());
                let e = last.get(2 * i).copied().unwrap_or(0.0) - d;
                let de = last.get(2 * i + 1).copied().unwrap_or(0.0);
                let amp = (e * e + ((de + z * w * e) / wd).powi(2)).sqrt();
                100.0 * amp * (1.0 - z * z).sqrt() / d.abs()
            })
            .collect(),
    ))
}

/// What [`metrics`] reads from the applied command itself: when it ends and its peaks. The
/// page keeps these for a shaper and a command across edits of the plant, which change only
/// the response.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CommandFigures {
    /// When the command stops changing (its last knot).
    pub move_end: f64,
    /// Largest |acceleration| (`None` where the velocity jumps).
    pub peak_acceleration: Option<f64>,
    /// Largest |jerk| (`None` where the acceleration jumps).
    pub peak_jerk: Option<f64>,
    /// Turning points of the acceleration ([`peak_valley_count`]).
    pub acceleration_peak_valley_count: usize,
}

impl CommandFigures {
    /// The figures of `command`.
    pub fn of(command: &Command) -> Result<Self> {
        match command {
            Command::Piecewise(p) => {
                knot_figures(&mut p.knots().iter().copied(), p.degree()).map(|(f, _)| f)
            }
            Command::Sampled(s) => {
                let (peak_acceleration, peak_jerk, count) = sampled_peaks(s.values(), s.period());
                Ok(CommandFigures {
                    move_end: command.end_time(),
                    peak_acceleration,
                    peak_jerk,
                    acceleration_peak_valley_count: count,
                })
            }
        }
    }

    /// The figures of `reference` shaped by `shaper`: those of `Command::Piecewise(reference
    /// .shaped(shaper)?)`, the same numbers to the last bit, read from its knots as they are
    /// merged (`Piecewise::shaped_knots`) instead of from the formed command where the
    /// reference has few knots (a six-mode ZV-D³ shapes a trapezoid into 62 500 knots). Errors
    /// as `shaped` does (too many knots, a non-finite product).
    pub fn of_shaped(reference: &Piecewise, shaper: &crate::shaper::Shaper) -> Result<Self> {
        if let Some(steps) = reference.shaped_steps(shaper)? {
            return step_figures(steps, reference.degree());
        }
        let Some(mut knots) = reference.shaped_knots(shaper)? else {
            return CommandFigures::of(&Command::Piecewise(reference.shaped(shaper)?));
        };
        let degree = reference.degree();
        let (figures, seen) = knot_figures(&mut knots, degree)?;
        // The shaped degree is the reference's unless its highest jumps all cancel: then the
        // walk is taken again at the degree the command has (as `shaped` would store it).
        if seen < degree {
            if let Some(mut again) = reference.shaped_knots(shaper)? {
                return knot_figures(&mut again, seen).map(|(f, _)| f);
            }
        }
        Ok(figures)
    }
}

/// [`knot_figures`] of a command of degree at most `degree` ≤ 2 given as its [`Step`]s (sorted,
/// merged), taken again at the degree the steps have when that is lower (as
/// [`CommandFigures::of_shaped`] does): the same numbers to the bit, by the same arithmetic on
/// what the walk reads of it. The acceleration is constant between knots, so its samples are
/// its value after each knot (a Taylor shift of the acceleration alone is the identity:
/// `0.0 + a`), the jerk's are 0, and each is unbounded where a lower derivative jumps.
fn step_figures(steps: impl Iterator<Item = Step>, degree: usize) -> Result<CommandFigures> {
    let mut acceleration = vec![0.0];
    let (mut end, mut seen, mut first, mut a) = (0.0, 0, true, 0.0);
    let (mut unbounded_acceleration, mut unbounded_jerk) = (false, false);
    for (time, j) in steps {
        if !time.is_finite() || j.iter().any(|x| !x.is_finite()) {
            finite("command.time", time)?;
            for x in j {
                finite("command", x)?;
            }
        }
        if let Some(top) = j.iter().rposition(|&x| x != 0.0) {
            seen = seen.max(top);
        }
        unbounded_acceleration |= j[0] != 0.0 || j[1] != 0.0;
        unbounded_jerk |= j.iter().any(|&x| x != 0.0);
        a = if first { 0.0 } else { 0.0 + a } + j[2];
        first = false;
        end = time;
        acceleration.push(if degree == 2 { a } else { 0.0 });
    }
    if seen < degree {
        // Walked again at the lower degree: an acceleration of 0 throughout.
        acceleration.iter_mut().for_each(|x| *x = 0.0);
    }
    let max_abs = |v: &[f64]| v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    Ok(CommandFigures {
        move_end: end,
        peak_acceleration: (!unbounded_acceleration).then(|| max_abs(&acceleration)),
        peak_jerk: (!unbounded_jerk).then_some(0.0),
        acceleration_peak_valley_count: peak_valley_count(&acceleration),
    })
}

/// The figures of a piecewise command given as its knots (sorted, merged) and a bound on its
/// degree, and the degree the knots have (the highest order that jumps; 0 for none).
fn knot_figures(
    knots: &mut dyn Iterator<Item = Knot>,
    degree: usize,
) -> Result<(CommandFigures, usize)> {
    let w = walk(knots, degree, &[2, 3], Sampling::ByDegree)?;
    let max_abs = |v: &[f64]| v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let figures = CommandFigures {
        move_end: w.end,
        peak_acceleration: (!w.unbounded[0]).then(|| max_abs(&w.samples[0])),
        peak_jerk: (!w.unbounded[1]).then(|| max_abs(&w.samples[1])),
        acceleration_peak_valley_count: peak_valley_count(&w.samples[0]),
    };
    Ok((figures, w.degree))
}

/// Peaks of the `order`-th derivative of a piecewise command are read from its values at
/// these points of each piece (`Piece::sample`): 0 before it starts, then per piece
/// - where the derivative is constant on every piece (`order` ≥ degree: a trapezoid's
///   acceleration), one value: both ends would be the same number, and a repeated value changes
///   neither the peak nor [`peak_valley_count`];
/// - where it is linear (`order` = degree − 1: the acceleration of S-curves, shaped or not),
///   the two ends: each piece is monotone, so the interior could not change the peak |value|
///   or the turning points;
/// - where it is quadratic or cubic, the ends and the points inside where it turns (the roots
///   of its own derivative, linear or quadratic: closed form); between those it is monotone, so
///   the peak |value| is exact (dense sampling only approaches it) and the turning points are
///   the ones [`peak_valley_count`] would find;
/// - else [`PER_PIECE`] + 1 evenly spaced points; the last knot gives one value.
#[derive(Clone, Copy)]
enum Sampling {
    /// The rule above, by degree.
    ByDegree,
    /// `n` + 1 evenly spaced points per piece whatever the degree (`n` ≥ 1).
    #[cfg_attr(not(test), allow(dead_code))]
    Dense(usize),
}

/// Samples of derivatives of a piecewise command walked knot by knot.
struct Walked {
    /// Per requested order, its samples.
    samples: Vec<Vec<f64>>,
    /// Per requested order, whether a lower derivative jumps somewhere (it is unbounded).
    unbounded: Vec<bool>,
    /// The last knot's time (0 for none).
    end: f64,
    /// The highest order that jumps (0 for no knots).
    degree: usize,
}

/// Walks `knots` (sorted, merged, of degree at most `degree`) and samples the derivatives of
/// `orders` by `sampling`, keeping the Taylor state at the last knot passed as `Cursor` does
/// (the same arithmetic, so the same bits). Errors: a non-finite knot, as `Piecewise::new`.
fn walk(
    knots: &mut dyn Iterator<Item = Knot>,
    degree: usize,
    orders: &[usize],
    sampling: Sampling,
) -> Result<Walked> {
    let mut w = Walked {
        samples: orders.iter().map(|_| vec![0.0]).collect(),
        unbounded: vec![false; orders.len()],
        end: 0.0,
        degree: 0,
    };
    let mut anchor = [0.0; ORDER];
    let mut first = true;
    let mut next = knots.next();
    while let Some(k) = next {
        next = knots.next();
        if !k.time.is_finite() || k.jumps.iter().any(|j| !j.is_finite()) {
            finite("command.time", k.time)?;
            for j in k.jumps {
                finite("command", j)?;
            }
        }
        if let Some(top) = k.jumps.iter().rposition(|&j| j != 0.0) {
            w.degree = w.degree.max(top);
        }
        for (u, &order) in w.unbounded.iter_mut().zip(orders) {
            *u |= k.jumps[..order].iter().any(|&j| j != 0.0);
        }
        let mut s = if first {
            [0.0; ORDER]
        } else {
            taylor_shift(&anchor, degree, k.time - w.end)
        };
        for (a, j) in s.iter_mut().zip(k.jumps) {
            *a += j;
        }
        anchor = s;
        first = false;
        w.end = k.time;
        let piece = Piece {
            state: &anchor,
            start: k.time,
            end: next.as_ref().map(|n| n.time),
            degree,
        };
        for (out, &order) in w.samples.iter_mut().zip(orders) {
            piece.sample(order, sampling, out);
        }
    }
    Ok(w)
}

/// One piece of a walked command: the Taylor state just after its knot at `start`, up to the
/// next knot at `end` (`None` after the last).
struct Piece<'a> {
    state: &'a [f64; ORDER],
    start: f64,
    end: Option<f64>,
    degree: usize,
}

impl Piece<'_> {
    /// The `order`-th derivative at `t` in the piece.
    fn at(&self, t: f64, order: usize) -> f64 {
        taylor_shift(self.state, self.degree, t - self.start)[order]
    }

    /// Pushes the samples of the `order`-th derivative on this piece ([`Sampling`]).
    fn sample(&self, order: usize, sampling: Sampling, out: &mut Vec<f64>) {
        let per_piece = match sampling {
            Sampling::Dense(n) => n,
            Sampling::ByDegree if self.degree <= order => {
                // The Taylor shift by 0 of the state's highest entry, or 0 above it.
                out.push(
                    self.state
                        .get(order)
                        .filter(|_| order == self.degree)
                        .map_or(0.0, |&v| v),
                );
                return;
            }
            Sampling::ByDegree if self.degree <= order + 1 => 1,
            Sampling::ByDegree if self.degree <= order + 3 => {
                out.push(self.at(self.start, order));
                let Some(end) = self.end else {
                    return;
                };
                // g'(τ) = c₁ + c₂τ + c₃τ²/2 on the piece (c: the derivatives at its start).
                let s = taylor_shift(self.state, self.degree, 0.0);
                let c = |j: usize| s.get(order + j).copied().unwrap_or(0.0);
                let h = end - self.start;
                let mut turns = stationary_points(c(1), c(2), 0.5 * c(3));
                turns.retain(|&tau| tau > 0.0 && tau < h);
                for tau in turns {
                    out.push(self.at(self.start + tau, order));
                }
                out.push(self.at(end, order));
                return;
            }
            Sampling::ByDegree => PER_PIECE,
        };
        match self.end {
            Some(end) => {
                for j in 0..=per_piece {
                    let t = self.start + (end - self.start) * j as f64 / per_piece as f64;
                    out.push(self.at(t, order));
                }
            }
            None => out.push(self.at(self.start, order)),
        }
    }
}

/// The real roots of a + bτ + cτ², in increasing order (none for a constant).
fn stationary_points(a: f64, b: f64, c: f64) -> Vec<f64> {
    if c == 0.0 {
        return if b == 0.0 { Vec::new() } else { vec![-a / b] };
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return Vec::new();
    }
    // The root of larger magnitude first, without cancellation; the other from the product.
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    let mut r = if q == 0.0 {
        vec![0.0]
    } else {
        vec![q / c, a / q]
    };
    crate::sort::sort_by(&mut r, f64::total_cmp);
    r
}

/// The samples of the `order`-th derivative of `p` by `sampling` (tests: the rule against
/// dense sampling).
#[cfg(test)]
fn sample_derivative(p: &Piecewise, order: usize, sampling: Sampling) -> Vec<f64> {
    let w = walk(
        &mut p.knots().iter().copied(),
        p.degree(),
        &[order],
        sampling,
    )
    .unwrap();
    w.samples.into_iter().next().unwrap()
}

/// Peaks from finite differences of a sampled command.
fn sampled_peaks(x: &[f64], period: f64) -> (Option<f64>, Option<f64>, usize) {
    let mut padded = Vec::with_capacity(x.len() + 4);
    padded.push(0.0);
    padded.extend_from_slice(x);
    let last = x.last().copied().unwrap_or(0.0);
    padded.extend([last, last]);
    let acc: Vec<f64> = padded
        .windows(3)
        .map(|w| (w[2] - 2.0 * w[1] + w[0]) / (period * period))
        .collect();
    let jerk: Vec<f64> = acc.windows(2).map(|w| (w[1] - w[0]) / period).collect();
    let max_abs = |v: &[f64]| v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    (
        Some(max_abs(&acc)),
        Some(max_abs(&jerk)),
        peak_valley_count(&acc),
    )
}

/// Number of turning points (peaks and valleys) of a sequence, ignoring changes smaller than
/// 10⁻⁹ of its largest magnitude (so plateaus and rounding count once or not at all). The first
/// and last values are not turning points.
pub fn peak_valley_count(x: &[f64]) -> usize {
    let scale = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    if scale == 0.0 {
        return 0;
    }
    let h = 1e-9 * scale;
    let mut count = 0;
    let mut direction = 0i8; // +1 rising, −1 falling, 0 unknown
    let mut extreme = x[0];
    for &v in &x[1..] {
        match direction {
            0 => {
                if v > extreme + h {
                    direction = 1;
                    extreme = v;
                } else if v < extreme - h {
                    direction = -1;
                    extreme = v;
                }
            }
            1 => {
                if v > extreme {
                    extreme = v;
                } else if v < extreme - h {
                    count += 1;
                    direction = -1;
                    extreme = v;
                }
            }
            _ => {
                if v < extreme {
                    extreme = v;
                } else if v > extreme + h {
                    count += 1;
                    direction = 1;
                    extreme = v;
                }
            }
        }
    }
    count
}

#[cfg(test)]
mod tests {
    use super::{
        knot_figures, peak_valley_count, sample_derivative, step_figures, CommandFigures, Sampling,
        PER_PIECE,
    };
    use crate::command::Command;
    use crate::command::{s_curve, trapezoid};
    use crate::design::zero_vibration::{zv, zvd};
    use crate::mode::Mode;
    use crate::piecewise::Cursor;
    use crate::piecewise::{Knot, Piecewise, ORDER};

    /// `bases`, and each shaped by ZV and ZVD at every frequency of `freqs` (ζ 0.05):
    /// overlapping impulse responses make pieces of every slope.
    fn with_shaped(bases: Vec<Piecewise>, freqs: &[f64]) -> Vec<Piecewise> {
        let mut out = bases.clone();
        for &f in freqs {
            let mode = Mode::new(f, 0.05).unwrap();
            for base in &bases {
                out.push(base.shaped(&zv(&mode).unwrap()).unwrap());
                out.push(base.shaped(&zvd(&mode).unwrap()).unwrap());
            }
        }
        out
    }

    /// The `order`-th derivative of `p` at 64 points per piece, read by the crate's `Cursor`
    /// (the reader plants and spectra use), not by the metrics' own walk.
    fn dense_by_cursor(p: &Piecewise, order: usize) -> Vec<f64> {
        let knots = p.knots();
        let mut out = vec![0.0];
        let mut cursor = Cursor::new(p);
        for (i, k) in knots.iter().enumerate() {
            cursor.seek(k.time);
            match knots.get(i + 1) {
                Some(next) => {
                    for j in 0..=PER_PIECE {
                        let t = k.time + (next.time - k.time) * j as f64 / PER_PIECE as f64;
                        out.push(cursor.state_at(t)[order]);
                    }
                }
                None => out.push(cursor.state_at(k.time)[order]),
            }
        }
        out
    }

    /// The `order`-th derivative of `p` sampled by [`sample_derivative`] against 64 points per
    /// piece (an independent computation): the same turning points; the same peak where only
    /// the pieces' ends are taken (a linear derivative), else no lower and within 1e-3 of it
    /// (the turning points are exact, dense sampling only approaches them). Returns whether
    /// the fast path took fewer points.
    fn agrees_with_dense(p: &Piecewise, order: usize) -> bool {
        let fast = sample_derivative(p, order, Sampling::ByDegree);
        let dense = dense_by_cursor(p, order);
        assert_eq!(
            dense,
            sample_derivative(p, order, Sampling::Dense(PER_PIECE)),
            "the walk's dense sampling is the cursor's"
        );
        let peak = |v: &[f64]| v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let (a, b) = (peak(&fast), peak(&dense));
        let what = format!("degree {}, order {order}: {a} vs {b}", p.degree());
        if p.degree() <= order + 1 {
            assert!((a - b).abs() <= 1e-12 * b.max(1.0), "{what}");
        } else {
            assert!(a >= b * (1.0 - 1e-12) && a <= b * (1.0 + 1e-3), "{what}");
        }
        assert_eq!(
            peak_valley_count(&fast),
            peak_valley_count(&dense),
            "{what}"
        );
        fast.len() < dense.len()
    }

    /// Where a derivative is linear on every piece (trapezoids and S-curves, unshaped and
    /// shaped), sampling only the pieces' ends gives the peak and the turning points of the
    /// dense sampling.
    #[test]
    fn piece_ends_give_the_dense_peaks_and_turning_points_where_the_derivative_is_linear() {
        let commands = with_shaped(
            vec![
                trapezoid(1.0, 0.8, 2.0, 0.0).unwrap(),
                s_curve(1.0, 0.8, 2.0, 20.0, 0.0).unwrap(),
                s_curve(1.0, 0.5, 100.0, 22.2, 0.1).unwrap(),
            ],
            &[0.7, 1.0, 2.3, 9.0],
        );
        let mut sparse_used = 0;
        for p in &commands {
            for order in 1..=3 {
                if agrees_with_dense(p, order) && p.degree() <= order + 1 {
                    sparse_used += 1;
                }
            }
        }
        assert!(sparse_used >= 20, "the sparse path ran {sparse_used} times");
    }

    /// Where a derivative is quadratic or cubic on every piece (the acceleration of a
    /// multi-mode pulse-convolution profile, position of degree 4 or 5, unshaped and shaped),
    /// the pieces' ends and turning points give the dense sampling's turning points and a
    /// peak no lower than its.
    #[test]
    fn turning_points_give_the_dense_peaks_where_the_derivative_is_quadratic_or_cubic() {
        use crate::profile::{from_spec, ProfileSpec};
        let profile = |modes: &[f64]| {
            let spec: ProfileSpec = serde_json::from_str(&format!(
                r#"{{"shape":"multiMode","modesHz":{modes:?},"distance":1,"duration":2}}"#
            ))
            .unwrap();
            from_spec(&spec).unwrap()
        };
        let commands = with_shaped(
            vec![profile(&[1.2, 3.4, 7.9]), profile(&[1.2, 2.1, 3.4, 7.9])],
            &[0.7, 2.3, 9.0],
        );
        let mut turns_used = 0;
        for p in &commands {
            for order in 1..=3 {
                if agrees_with_dense(p, order) && (2..=3).contains(&(p.degree() - order)) {
                    turns_used += 1;
                }
            }
        }
        assert!(
            turns_used >= 20,
            "the turning-point path ran {turns_used} times"
        );
    }

    /// A command's figures read from its knots as they are merged (`of_shaped`) are those of
    /// the formed shaped command, to the last bit: trapezoids, S-curves and profiles (degree 2
    /// to 5) shaped by ZV, ZVD and factored ZV-D³ over up to six modes (a 62 500-knot command),
    /// a reference of more than 16 knots (formed by a sort), and two impulses that cancel a
    /// knot of the trapezoid (merged to nothing). Too many knots: the same error.
    #[test]
    fn figures_of_a_shaped_command_are_the_formed_commands_to_the_bit() {
        use crate::design::{design, DesignRequest, ShaperSpec};
        use crate::mode::ModeSpec;
        use crate::profile::{from_spec, ProfileSpec};
        use crate::shaper::{Impulse, Shaper};
        let profile: ProfileSpec = serde_json::from_str(
            r#"{"shape":"multiMode","modesHz":[1.2,3.4,7.9],"distance":1,"duration":2}"#,
        )
        .unwrap();
        let references = [
            trapezoid(1.0, 0.75, 8.0, 0.0).unwrap(),
            s_curve(1.0, 0.8, 2.0, 20.0, 0.0).unwrap(),
            from_spec(&profile).unwrap(),
            // Already shaped twice: 36 knots.
            trapezoid(1.0, 0.75, 8.0, 0.0)
                .unwrap()
                .shaped(&zvd(&Mode::new(5.0, 0.1).unwrap()).unwrap())
                .unwrap()
                .shaped(&zvd(&Mode::new(9.0, 0.1).unwrap()).unwrap())
                .unwrap(),
        ];
        assert!(
            references[3].knots().len() > 16,
            "a reference formed by the sort"
        );
        let zvd3 = |modes: &[f64]| {
            let modes = modes
                .iter()
                .map(|&f| ModeSpec {
                    frequency_hz: f,
                    damping: 0.02,
                })
                .collect();
            let shaper = ShaperSpec::Zvdn { derivatives: 3 };
            design(&DesignRequest { modes, shaper }).unwrap()
        };
        let mode = Mode::new(1.2, 0.02).unwrap();
        // The trapezoid accelerates for 0.09375 s: impulses that far apart, of equal size,
        // cancel its jump there (a knot merged to nothing and dropped).
        let cancelling = Shaper::new(vec![
            Impulse {
                time: 0.0,
                amplitude: 0.5,
            },
            Impulse {
                time: 0.09375,
                amplitude: 0.5,
            },
        ])
        .unwrap();
        let shapers = [
            zv(&mode).unwrap(),
            zvd(&mode).unwrap(),
            zvd3(&[1.2, 3.4, 7.9]),
            zvd3(&[1.2, 3.4, 7.9, 13.0, 21.0, 34.0]),
            cancelling,
        ];
        assert_eq!(shapers[3].len(), 15_625);
        assert!(
            references[0].shaped(&shapers[4]).unwrap().knots().len() < 8,
            "a knot of the trapezoid shaped by the two impulses cancels"
        );
        let mut checked = 0;
        for r in &references {
            for s in &shapers {
                let formed = match r.shaped(s) {
                    Ok(p) => p,
                    Err(e) => {
                        assert_eq!(CommandFigures::of_shaped(r, s).unwrap_err(), e);
                        continue;
                    }
                };
                let want = CommandFigures::of(&Command::Piecewise(formed)).unwrap();
                let got = CommandFigures::of_shaped(r, s).unwrap();
                assert_eq!(format!("{got:?}"), format!("{want:?}"));
                checked += 1;
            }
        }
        assert!(checked >= 18, "{checked} compared");
        let too_many = shapers[3].len() * references[3].knots().len();
        assert!(too_many > crate::piecewise::MAX_KNOTS, "one error compared");
    }

    /// The narrow path for commands of degree ≤ 2 (`Piecewise::shaped_steps`, `step_figures`)
    /// against the general one (`shaped_knots` walked by `knot_figures`, again at the degree
    /// seen when lower), to the bit: the same knots (time and the three jumps) and the same
    /// figures, for a trapezoid, a triangle, a delayed negative trapezoid, a ramp, a step and a
    /// command without knots, shaped by ZV, ZVD, six-mode ZV-D³, a unity-magnitude negative shaper, two impulses that
    /// cancel a knot, impulses that land on the trapezoid's own knots (merged across runs), and
    /// a zero-sum pair; a product that overflows: the same error.
    #[test]
    fn figures_of_low_degree_commands_take_the_narrow_path_to_the_same_bits() {
        use crate::command::{ramp, step};
        use crate::design::{design, DesignRequest, ShaperSpec};
        use crate::mode::ModeSpec;
        use crate::shaper::{Impulse, Shaper};
        let general = |r: &Piecewise, s: &Shaper| {
            let d = r.degree();
            let (f, seen) = knot_figures(&mut r.shaped_knots(s).unwrap().unwrap(), d).unwrap();
            if seen < d {
                knot_figures(&mut r.shaped_knots(s).unwrap().unwrap(), seen)
                    .unwrap()
                    .0
            } else {
                f
            }
        };
        let bits = |t: f64, j: &[f64]| {
            (
                t.to_bits(),
                j.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            )
        };
        let mut references = vec![
            trapezoid(1.0, 0.75, 8.0, 0.0).unwrap(),
            trapezoid(0.01, 0.75, 8.0, 0.0).unwrap(), // triangular
            trapezoid(-2.0, 0.3, 3.0, 0.25).unwrap(),
            ramp(0.5, 0.1).unwrap(),
            step(1.0, 0.0).unwrap(),
        ];
        assert!(references[1].knots().len() == 3, "a triangle");
        references.push(Piecewise::new(Vec::new()).unwrap());
        let impulses = |v: &[(f64, f64)]| {
            Shaper::new(
                v.iter()
                    .map(|&(time, amplitude)| Impulse { time, amplitude })
                    .collect(),
            )
            .unwrap()
        };
        let modes = |f: &[f64]| {
            f.iter()
                .map(|&f| ModeSpec {
                    frequency_hz: f,
                    damping: 0.02,
                })
                .collect()
        };
        let designed = |spec: ShaperSpec, f: &[f64]| {
            design(&DesignRequest {
                modes: modes(f),
                shaper: spec,
            })
            .unwrap()
        };
        let six = [1.2, 3.4, 7.9, 13.0, 21.0, 34.0];
        let shapers = [
            designed(ShaperSpec::Zv, &[2.0]),
            designed(ShaperSpec::Zvd, &[1.2, 3.4]),
            designed(ShaperSpec::Zvdn { derivatives: 3 }, &six),
            designed(ShaperSpec::Umzv, &[3.0]),
            // Half of each jump at 0 and 0.09375 s: the trapezoid's first two knots' sum cancels.
            impulses(&[(0.0, 0.5), (0.09375, 0.5)]),
            // At the trapezoid's own knots (0, t_a, t_a + t_c, 2t_a + t_c with t_a = v/a =
            // 0.75/8 = 0.09375 s and t_c = (d − v²/a)/v = 1.2395833… s): knots of different
            // runs on the same time, merged.
            impulses(&[
                (0.0, 0.25),
                (0.09375, 0.25),
                (1.3333333333333333, 0.25),
                (1.4270833333333333, 0.25),
            ]),
            // Amplitudes summing to zero (a force-profile move's kind).
            impulses(&[(0.0, 1.0), (0.2, -1.0)]),
        ];
        let mut compared = 0;
        for r in &references {
            for s in &shapers {
                let steps: Vec<_> = r.shaped_steps(s).unwrap().expect("degree ≤ 2").collect();
                let knots: Vec<_> = r.shaped_knots(s).unwrap().unwrap().collect();
                assert_eq!(
                    steps.iter().map(|(t, j)| bits(*t, j)).collect::<Vec<_>>(),
                    knots
                        .iter()
                        .map(|k| bits(k.time, &k.jumps[..3]))
                        .collect::<Vec<_>>(),
                );
                assert!(knots.iter().all(|k| k.jumps[3..].iter().all(|&j| j == 0.0)));
                let narrow = step_figures(r.shaped_steps(s).unwrap().unwrap(), r.degree()).unwrap();
                assert_eq!(format!("{narrow:?}"), format!("{:?}", general(r, s)));
                assert_eq!(
                    format!("{:?}", CommandFigures::of_shaped(r, s).unwrap()),
                    format!("{narrow:?}")
                );
                compared += 1;
            }
        }
        assert_eq!(compared, 42);
        let merged = trapezoid(1.0, 0.75, 8.0, 0.0)
            .unwrap()
            .shaped_steps(&shapers[5])
            .unwrap()
            .unwrap()
            .count();
        assert!(merged < 16, "knots of different runs merged: {merged}");
        // Overflow: the same error either way.
        let jump = |time: f64, value: f64| {
            let mut jumps = [0.0; ORDER];
            jumps[2] = value;
            Knot { time, jumps }
        };
        let huge = Piecewise::new(vec![jump(0.0, 1e300), jump(1.0, -1e300)]).unwrap();
        let big = impulses(&[(0.0, 1e12), (1.0, -1e12 + 1.0)]);
        let got = CommandFigures::of_shaped(&huge, &big);
        let walked = knot_figures(&mut huge.shaped_knots(&big).unwrap().unwrap(), 2);
        assert!(got.is_err(), "{got:?}");
        assert_eq!(got.unwrap_err(), walked.unwrap_err());
        assert_eq!(
            CommandFigures::of_shaped(&huge, &big).unwrap_err(),
            huge.shaped(&big).unwrap_err()
        );
    }

    /// The roots of a + bτ + cτ², against the closed form.
    #[test]
    fn stationary_points_are_the_roots() {
        use super::stationary_points;
        assert_eq!(stationary_points(-6.0, 1.0, 1.0), vec![-3.0, 2.0]);
        assert_eq!(stationary_points(2.0, -4.0, 0.0), vec![0.5]);
        assert!(stationary_points(1.0, 0.0, 1.0).is_empty());
        assert!(stationary_points(1.0, 0.0, 0.0).is_empty());
        let r = stationary_points(1e-8, -1.0, 1e-8); // roots ≈ 1e-8 and 1e8, no cancellation
        assert!(
            (r[0] - 1e-8).abs() < 1e-20 && (r[1] - 1e8).abs() < 1e-4,
            "{r:?}"
        );
    }
}
