//! What the papers judge a shaped move by: residual vibration after the move, settling and
//! rise time, ramp delay, deflection during the move, peak acceleration and jerk, and the
//! acceleration peak-valley count (fatigue; Veciana & Cardona 2011 §3.1).
//!
//! Signal-based metrics read the simulated [`Trajectory`], so they work for every plant,
//! including the nonlinear pendulum; command-based ones (peaks, peak-valley count) read the
//! command exactly where it is piecewise polynomial.

use crate::command::Command;
use crate::error::Result;
use crate::piecewise::{Cursor, Piecewise};
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
    let t = &trajectory.time;
    let y = &trajectory.endpoint;
    let move_end = applied.end_time();
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
    let (peak_acceleration, peak_jerk, count) = match applied {
        Command::Piecewise(p) => command_peaks(p),
        Command::Sampled(s) => sampled_peaks(s.values(), s.period()),
    };
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
        peak_acceleration,
        peak_jerk,
        acceleration_peak_valley_count: count,
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

/// Values of the `order`-th derivative of a piecewise command: 0 before it starts, each piece
/// at [`PER_PIECE`] + 1 points, and its final value. Where that derivative is linear on every
/// piece (`order` ≥ degree − 1: the acceleration of trapezoids and S-curves, shaped or not),
/// each piece is monotone and only its two ends are sampled: the interior points could not
/// change the peak |value| or the turning points [`peak_valley_count`] finds. Where it is
/// constant on every piece (`order` ≥ degree: a trapezoid's acceleration), one value per piece:
/// both ends would be the same number (the Taylor shift of order 0 adds nothing to it), and a
/// repeated value changes neither the peak nor [`peak_valley_count`]. Where it is quadratic or
/// cubic, [`sample_derivative_turns`]: the ends and the turning points of each piece.
fn sample_derivative(p: &Piecewise, order: usize) -> Vec<f64> {
    if p.degree() <= order {
        let mut out = Vec::with_capacity(p.knots().len() + 1);
        out.push(0.0);
        let mut cursor = Cursor::new(p);
        for k in p.knots() {
            cursor.seek(k.time);
            out.push(cursor.state_at(k.time)[order]);
        }
        return out;
    }
    if p.degree() <= order + 1 {
        return sample_derivative_at(p, order, 1);
    }
    if p.degree() <= order + 3 {
        return sample_derivative_turns(p, order);
    }
    sample_derivative_at(p, order, PER_PIECE)
}

/// [`sample_derivative`] where the derivative is quadratic or cubic on every piece (a
/// multi-mode pulse-convolution profile's acceleration): each piece's two ends and the points
/// inside it where the derivative turns (the roots of its own derivative, linear or quadratic:
/// closed form). Between those it is monotone, so the peak |value| is exact (dense sampling
/// only approaches it) and the turning points are the ones [`peak_valley_count`] would find.
fn sample_derivative_turns(p: &Piecewise, order: usize) -> Vec<f64> {
    let knots = p.knots();
    let mut out = Vec::with_capacity(knots.len() * 4 + 2);
    out.push(0.0);
    let mut cursor = Cursor::new(p);
    for (i, k) in knots.iter().enumerate() {
        cursor.seek(k.time);
        let s = cursor.state_at(k.time);
        out.push(s[order]);
        let Some(next) = knots.get(i + 1) else {
            continue;
        };
        let h = next.time - k.time;
        // g'(τ) = c₁ + c₂τ + c₃τ²/2 on the piece (c: the derivatives at its start).
        let c = |j: usize| s.get(order + j).copied().unwrap_or(0.0);
        let mut turns = stationary_points(c(1), c(2), 0.5 * c(3));
        turns.retain(|&tau| tau > 0.0 && tau < h);
        for tau in turns {
            out.push(cursor.state_at(k.time + tau)[order]);
        }
        out.push(cursor.state_at(next.time)[order]);
    }
    out
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
    r.sort_by(f64::total_cmp);
    r
}

/// [`sample_derivative`] with `per_piece` + 1 points per piece (`per_piece` ≥ 1).
fn sample_derivative_at(p: &Piecewise, order: usize, per_piece: usize) -> Vec<f64> {
    let knots = p.knots();
    let mut out = Vec::with_capacity(knots.len() * (per_piece + 1) + 2);
    out.push(0.0);
    let mut cursor = Cursor::new(p);
    for (i, k) in knots.iter().enumerate() {
        cursor.seek(k.time);
        match knots.get(i + 1) {
            Some(next) => {
                for j in 0..=per_piece {
                    let t = k.time + (next.time - k.time) * j as f64 / per_piece as f64;
                    out.push(cursor.state_at(t)[order]);
                }
            }
            None => out.push(cursor.state_at(k.time)[order]),
        }
    }
    out
}

/// Peak acceleration, peak jerk (None where unbounded) and acceleration peak-valley count of a
/// piecewise command.
fn command_peaks(p: &Piecewise) -> (Option<f64>, Option<f64>, usize) {
    let jumps_below = |order: usize| {
        p.knots()
            .iter()
            .any(|k| k.jumps.iter().take(order).any(|&j| j != 0.0))
    };
    let acc = sample_derivative(p, 2);
    let max_abs = |v: &[f64]| v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let peak_acc = (!jumps_below(2)).then(|| max_abs(&acc));
    let peak_jerk = (!jumps_below(3)).then(|| max_abs(&sample_derivative(p, 3)));
    (peak_acc, peak_jerk, peak_valley_count(&acc))
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
    use super::{peak_valley_count, sample_derivative, sample_derivative_at, PER_PIECE};
    use crate::command::{s_curve, trapezoid};
    use crate::design::zero_vibration::{zv, zvd};
    use crate::mode::Mode;
    use crate::piecewise::Piecewise;

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

    /// The `order`-th derivative of `p` sampled by [`sample_derivative`] against 64 points per
    /// piece (an independent computation): the same turning points; the same peak where only
    /// the pieces' ends are taken (a linear derivative), else no lower and within 1e-3 of it
    /// (the turning points are exact, dense sampling only approaches them). Returns whether
    /// the fast path took fewer points.
    fn agrees_with_dense(p: &Piecewise, order: usize) -> bool {
        let fast = sample_derivative(p, order);
        let dense = sample_derivative_at(p, order, PER_PIECE);
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
