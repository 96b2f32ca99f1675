//! The printed corner: an XY toolpath planned the way printer firmware plans it, each axis
//! shaped by its own shaper and driven through its own modal plant, and the nozzle's deviation
//! from the path — what a printed wall shows after a corner (issue 23, item 3).
//!
//! **Planning** ([`plan`]). Straight segments between the path's points, each a trapezoid of
//! path speed at constant acceleration `accel`, cruising at most at `velocity` (Klipper
//! docs/Kinematics.md, *Trapezoid generator*). The speed at a junction is limited the way
//! Klipper's `Move.calc_junction` (klippy/toolhead.py) limits it, by its "approximated
//! centripetal velocity": with θ the angle between the reversed incoming direction and the
//! outgoing one, s = sin(θ/2) and the junction deviation δ = scv²(√2 − 1)/accel
//! (`square_corner_velocity`; toolhead.py computes it so), v² ≤ accel·δ·s/(1 − s) and
//! v² ≤ ½·L·tan(θ/2)·accel for the segment lengths L on either side, and v ≤ `velocity`; a
//! reversal stops. A 90° corner is taken at exactly `square_corner_velocity`. The speeds are
//! then made reachable by the usual backward and forward passes over the segments.
//! Simplifications, said once: one acceleration for every segment, no `minimum_cruise_ratio`
//! (Klipper's "smoothed" look-ahead that lowers cruise speeds on short zigzags), no extruder
//! limit, moves in the plane only.
//!
//! **Motion** ([`corner`]). Each axis's position is then a piecewise quadratic in time (its
//! velocity jumps at a corner, where the path turns at the junction speed), shaped exactly by
//! the axis's shaper ([`Piecewise::shaped`]) and sent through the axis's [`ModalPlant`]
//! (exact at the samples; the nozzle is the plant's endpoint).
//!
//! **Numbers.** The deviation of a sample is its signed distance to the nearest segment of the
//! path (positive to the left of the direction of travel). For each corner: the peak |deviation|
//! while printing the wall after it, and the ringing amplitude on that wall — half the
//! peak-to-peak of the deviation from the moment every shaper has finished with the corner
//! (corner time + the longer shaper's duration) until the wall's deceleration begins (a
//! sinusoid's amplitude when that window spans a period or more; `window_s` says how long it
//! was).

use crate::error::{finite, positive, Error, Result};
use crate::piecewise::{Knot, Piecewise, ORDER};
use crate::plant::ModalPlant;
use crate::shaper::Shaper;
use crate::simulate::sample_count;
use serde::Serialize;

/// A point or a direction in the plane (mm; X, Y).
type Point = [f64; 2];

/// Most points a toolpath may have.
pub const MAX_POINTS: usize = 1000;

/// Junction cosines above this are reversals (Klipper's `calc_junction` returns there, so the
/// move starts from rest); below its negative, a straight continuation.
const STRAIGHT: f64 = 0.999_999;

/// The machine's motion limits, in mm and s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionLimits {
    /// Top speed along the path (mm/s).
    pub velocity: f64,
    /// Acceleration along the path (mm/s²).
    pub accel: f64,
    /// Klipper's `square_corner_velocity` (mm/s): the speed a 90° corner is taken at.
    pub square_corner_velocity: f64,
}

impl MotionLimits {
    fn check(&self) -> Result<()> {
        positive("velocity", self.velocity)?;
        positive("accel", self.accel)?;
        finite("squareCornerVelocity", self.square_corner_velocity)?;
        if self.square_corner_velocity < 0.0 {
            return Err(Error::invalid(
                "squareCornerVelocity",
                format!("must be ≥ 0 mm/s, got {}", self.square_corner_velocity),
            ));
        }
        Ok(())
    }

    /// Klipper's junction deviation δ = scv²(√2 − 1)/accel (toolhead.py).
    fn junction_deviation(&self) -> f64 {
        self.square_corner_velocity.powi(2) * (2f64.sqrt() - 1.0) / self.accel
    }
}

/// One straight segment of a planned path: a trapezoid of path speed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Segment {
    /// Start point (mm).
    pub start: [f64; 2],
    /// End point (mm).
    pub end: [f64; 2],
    /// Unit direction.
    pub direction: [f64; 2],
    /// Length (mm).
    pub length: f64,
    /// Path speed at the start (mm/s).
    pub v_start: f64,
    /// Top speed reached on the segment (mm/s).
    pub v_cruise: f64,
    /// Path speed at the end (mm/s).
    pub v_end: f64,
    /// Start time (s).
    pub t_start: f64,
    /// Duration of the acceleration (s).
    pub t_accel: f64,
    /// Duration of the cruise (s).
    pub t_cruise: f64,
    /// Duration of the deceleration (s).
    pub t_decel: f64,
}

impl Segment {
    /// End time (s).
    pub fn t_end(&self) -> f64 {
        self.t_start + self.t_accel + self.t_cruise + self.t_decel
    }

    /// Time the deceleration begins (s).
    pub fn t_decel_start(&self) -> f64 {
        self.t_start + self.t_accel + self.t_cruise
    }
}

/// A planned toolpath: its segments, from rest to rest.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Plan {
    /// The segments in order.
    pub segments: Vec<Segment>,
    /// Acceleration along the path (mm/s²).
    pub accel: f64,
}

/// The largest junction speed² between a segment of direction `a` and length `la` and the next,
/// of direction `b` and length `lb` (Klipper's `Move.calc_junction`; the cruise limit is
/// applied by the caller).
fn junction_v2(a: [f64; 2], la: f64, b: [f64; 2], lb: f64, limits: &MotionLimits) -> f64 {
    let cos_theta = -(a[0] * b[0] + a[1] * b[1]);
    if cos_theta > STRAIGHT {
        return 0.0;
    }
    let cos_theta = cos_theta.max(-STRAIGHT);
    let s = (0.5 * (1.0 - cos_theta)).sqrt();
    let r = limits.junction_deviation() * s / (1.0 - s);
    let tan = s / (0.5 * (1.0 + cos_theta)).sqrt();
    let centripetal = |l: f64| 0.5 * l * tan * limits.accel;
    (r * limits.accel).min(centripetal(la)).min(centripetal(lb))
}

/// Plans `points` (mm; consecutive repeats are skipped) under `limits`: junction speeds by
/// Klipper's rule, made reachable by a backward and a forward pass, then one trapezoid per
/// segment.
///
/// ```
/// use input_shaping::corner::{plan, MotionLimits};
/// // A 90° corner is taken at exactly square_corner_velocity (its definition in Klipper).
/// let limits = MotionLimits { velocity: 300.0, accel: 5000.0, square_corner_velocity: 5.0 };
/// let p = plan(&[[0.0, 0.0], [100.0, 0.0], [100.0, 100.0]], &limits)?;
/// assert!((p.segments[1].v_start - 5.0).abs() < 1e-9);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn plan(points: &[[f64; 2]], limits: &MotionLimits) -> Result<Plan> {
    limits.check()?;
    crate::error::count("points", points.len(), 2, MAX_POINTS)?;
    for (i, p) in points.iter().enumerate() {
        finite(&format!("points[{i}][0]"), p[0])?;
        finite(&format!("points[{i}][1]"), p[1])?;
    }
    // (start, end, unit direction, length) of each segment of non-zero length.
    let mut geometry: Vec<(Point, Point, Point, f64)> = Vec::new();
    for w in points.windows(2) {
        let d = [w[1][0] - w[0][0], w[1][1] - w[0][1]];
        let length = d[0].hypot(d[1]);
        if length > 0.0 {
            geometry.push((w[0], w[1], [d[0] / length, d[1] / length], length));
        }
    }
    if geometry.is_empty() {
        return Err(Error::invalid("points", "the path has no length"));
    }
    let n = geometry.len();
    let a = limits.accel;
    let vmax2 = limits.velocity * limits.velocity;
    // Junction limits: v²[i] at the start of segment i (0 at the start and the end).
    let mut v2 = vec![0.0; n + 1];
    for i in 1..n {
        let (_, _, da, la) = geometry[i - 1];
        let (_, _, db, lb) = geometry[i];
        v2[i] = junction_v2(da, la, db, lb, limits).min(vmax2);
    }
    for i in (0..n).rev() {
        v2[i] = v2[i].min(v2[i + 1] + 2.0 * a * geometry[i].3);
    }
    for i in 0..n {
        v2[i + 1] = v2[i + 1].min(v2[i] + 2.0 * a * geometry[i].3);
    }
    let mut t = 0.0;
    let segments = geometry
        .iter()
        .enumerate()
        .map(|(i, &(start, end, direction, length))| {
            let (vs, ve) = (v2[i].sqrt(), v2[i + 1].sqrt());
            let peak2 = vmax2.min(0.5 * (2.0 * a * length + v2[i] + v2[i + 1]));
            let vc = peak2.sqrt().max(vs).max(ve);
            let (da, dd) = (
                (vc * vc - v2[i]) / (2.0 * a),
                (vc * vc - v2[i + 1]) / (2.0 * a),
            );
            let seg = Segment {
                start,
                end,
                direction,
                length,
                v_start: vs,
                v_cruise: vc,
                v_end: ve,
                t_start: t,
                t_accel: (vc - vs) / a,
                t_cruise: ((length - da - dd) / vc).max(0.0),
                t_decel: (vc - ve) / a,
            };
            t = seg.t_end();
            seg
        })
        .collect();
    Ok(Plan { segments, accel: a })
}

impl Plan {
    /// Time the path ends (s).
    pub fn duration(&self) -> f64 {
        self.segments.last().map_or(0.0, Segment::t_end)
    }

    /// Position of `axis` (0: X, 1: Y) against time, exact: the start as a position jump at
    /// t = 0, the velocity jumps at the corners and the acceleration jumps of the trapezoids.
    pub fn axis_command(&self, axis: usize) -> Result<Piecewise> {
        if axis > 1 {
            return Err(Error::invalid("axis", "must be 0 (X) or 1 (Y)"));
        }
        let mut knots = Vec::new();
        let mut push = |time: f64, order: usize, value: f64| {
            if value != 0.0 {
                let mut jumps = [0.0; ORDER];
                jumps[order] = value;
                knots.push(Knot { time, jumps });
            }
        };
        push(0.0, 0, self.segments[0].start[axis]);
        // The axis's velocity and acceleration just before the time reached.
        let (mut velocity, mut acceleration) = (0.0, 0.0);
        for s in &self.segments {
            let d = s.direction[axis];
            push(s.t_start, 1, s.v_start * d - velocity);
            let mut t = s.t_start;
            for (duration, path_accel) in [
                (s.t_accel, self.accel),
                (s.t_cruise, 0.0),
                (s.t_decel, -self.accel),
            ] {
                if duration > 0.0 {
                    push(t, 2, path_accel * d - acceleration);
                    acceleration = path_accel * d;
                    t += duration;
                }
            }
            velocity = s.v_end * d;
        }
        push(self.duration(), 2, -acceleration);
        Piecewise::new(knots)
    }
}

/// One axis of the machine: its plant and the shaper its firmware runs (`None`: unshaped).
#[derive(Debug, Clone, Copy)]
pub struct Axis<'a> {
    /// The axis's modes (the nozzle is the plant's endpoint).
    pub plant: &'a ModalPlant,
    /// The axis's shaper.
    pub shaper: Option<&'a Shaper>,
}

/// What a wall shows after one corner.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct CornerRinging {
    /// Time the path turns (s).
    pub time: f64,
    /// Largest |deviation| while printing the wall after the corner (mm).
    pub peak_deviation: f64,
    /// Half the peak-to-peak of the deviation on that wall once the shapers are done with the
    /// corner, until the wall decelerates (mm; 0 when there is no such window).
    pub ringing: f64,
    /// Length of that window (s).
    pub window_s: f64,
}

/// The simulated print of a path.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Print {
    /// Sample times (s).
    pub time: Vec<f64>,
    /// Nozzle position (mm), X and Y.
    pub nozzle: [Vec<f64>; 2],
    /// Signed distance of the nozzle to the nearest segment (mm; positive on the left).
    pub deviation: Vec<f64>,
    /// One entry per corner (junction between two segments).
    pub corners: Vec<CornerRinging>,
}

/// Prints `plan` on the machine `axes` (X, Y), sampled every `sample_period` s until `settle`
/// s after the path ends.
///
/// ```
/// use input_shaping::corner::{corner, plan, square, Axis, MotionLimits};
/// use input_shaping::design::zero_vibration::zvd;
/// use input_shaping::plant::ModalPlant;
/// use input_shaping::Mode;
/// let limits = MotionLimits { velocity: 150.0, accel: 3000.0, square_corner_velocity: 5.0 };
/// let p = plan(&square(40.0)?, &limits)?;
/// let (x, y) = (Mode::new(42.0, 0.05)?, Mode::new(55.0, 0.05)?);
/// let (px, py) = (ModalPlant::new(vec![x], vec![1.0])?, ModalPlant::new(vec![y], vec![1.0])?);
/// let (sx, sy) = (zvd(&x)?, zvd(&y)?);
/// let run = |sx, sy| corner(&p, [Axis { plant: &px, shaper: sx }, Axis { plant: &py, shaper: sy }], 2e-4, 0.1);
/// let (plain, shaped) = (run(None, None)?, run(Some(&sx), Some(&sy))?);
/// // Exact shapers on exact modes: no ringing left on any wall.
/// for (a, b) in plain.corners.iter().zip(&shaped.corners) {
///     assert!(a.ringing > 1e-3 && b.ringing < 1e-9, "{} → {}", a.ringing, b.ringing);
/// }
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn corner(plan: &Plan, axes: [Axis<'_>; 2], sample_period: f64, settle: f64) -> Result<Print> {
    finite("settle", settle)?;
    let duration = plan.duration() + settle.max(0.0);
    let samples = sample_count(sample_period, duration)?;
    let mut nozzle: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
    for (k, axis) in axes.iter().enumerate() {
        let command = plan.axis_command(k)?;
        let command = match axis.shaper {
            Some(s) => command.shaped(s)?,
            None => command,
        };
        let response = axis
            .plant
            .to_lti()
            .respond(&command, sample_period, samples, false)?;
        nozzle[k] = response.outputs[crate::plant::lti::ENDPOINT].clone();
    }
    let time: Vec<f64> = (0..samples).map(|i| i as f64 * sample_period).collect();
    let deviation: Vec<f64> = (0..samples)
        .map(|i| nearest_signed_distance(&plan.segments, [nozzle[0][i], nozzle[1][i]]))
        .collect();
    let lag = axes
        .iter()
        .filter_map(|a| a.shaper.map(Shaper::duration))
        .fold(0.0, f64::max);
    let corners = (1..plan.segments.len())
        .map(|k| ringing_after(&plan.segments[k], &time, &nozzle, lag))
        .collect();
    Ok(Print {
        time,
        nozzle,
        deviation,
        corners,
    })
}

/// Signed distance from `p` to a segment, positive on the left of its direction.
fn signed_distance(s: &Segment, p: [f64; 2]) -> f64 {
    let rel = [p[0] - s.start[0], p[1] - s.start[1]];
    let along = (rel[0] * s.direction[0] + rel[1] * s.direction[1]).clamp(0.0, s.length);
    let foot = [
        s.start[0] + along * s.direction[0],
        s.start[1] + along * s.direction[1],
    ];
    let off = [p[0] - foot[0], p[1] - foot[1]];
    let cross = s.direction[0] * rel[1] - s.direction[1] * rel[0];
    off[0].hypot(off[1]).copysign(cross)
}

/// The point of the path nearest to `p` (the foot on the nearest segment).
fn nearest_foot(segments: &[Segment], p: [f64; 2]) -> [f64; 2] {
    let mut best = (f64::INFINITY, p);
    for s in segments {
        let rel = [p[0] - s.start[0], p[1] - s.start[1]];
        let along = (rel[0] * s.direction[0] + rel[1] * s.direction[1]).clamp(0.0, s.length);
        let foot = [
            s.start[0] + along * s.direction[0],
            s.start[1] + along * s.direction[1],
        ];
        let d = (p[0] - foot[0]).hypot(p[1] - foot[1]);
        if d < best.0 {
            best = (d, foot);
        }
    }
    best.1
}

impl Print {
    /// The nozzle's track as a print would show it with the deviation magnified: each sample's
    /// nearest point on the path plus `factor` times the nozzle's offset from it (mm; X, Y).
    /// `factor` 1 is the nozzle itself.
    pub fn magnified(&self, plan: &Plan, factor: f64) -> Result<[Vec<f64>; 2]> {
        finite("magnify", factor)?;
        let n = self.time.len();
        let (mut xs, mut ys) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for i in 0..n {
            let p = [self.nozzle[0][i], self.nozzle[1][i]];
            let foot = nearest_foot(&plan.segments, p);
            xs.push(foot[0] + factor * (p[0] - foot[0]));
            ys.push(foot[1] + factor * (p[1] - foot[1]));
        }
        Ok([xs, ys])
    }
}

fn nearest_signed_distance(segments: &[Segment], p: [f64; 2]) -> f64 {
    segments
        .iter()
        .map(|s| signed_distance(s, p))
        .fold(
            f64::INFINITY,
            |best, d| if d.abs() < best.abs() { d } else { best },
        )
}

/// The wall printed along `wall` after the corner at its start: peak |deviation| over the
/// wall's time, and the ringing in the window after the shapers' `lag`.
fn ringing_after(wall: &Segment, time: &[f64], nozzle: &[Vec<f64>; 2], lag: f64) -> CornerRinging {
    let across = |i: usize| {
        let rel = [nozzle[0][i] - wall.start[0], nozzle[1][i] - wall.start[1]];
        wall.direction[0] * rel[1] - wall.direction[1] * rel[0]
    };
    let (t0, t1) = (wall.t_start, wall.t_end());
    let (w0, w1) = (t0 + lag, wall.t_decel_start());
    let mut peak = 0.0_f64;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (i, &t) in time.iter().enumerate() {
        if t < t0 || t > t1 {
            continue;
        }
        let d = across(i);
        peak = peak.max(d.abs());
        if t >= w0 && t <= w1 {
            lo = lo.min(d);
            hi = hi.max(d);
        }
    }
    CornerRinging {
        time: t0,
        peak_deviation: peak,
        ringing: if hi >= lo { 0.5 * (hi - lo) } else { 0.0 },
        window_s: (w1 - w0).max(0.0),
    }
}

/// A square of side `side` (mm) from the origin, counter-clockwise, back to the start.
pub fn square(side: f64) -> Result<Vec<[f64; 2]>> {
    positive("sideMm", side)?;
    Ok(vec![
        [0.0, 0.0],
        [side, 0.0],
        [side, side],
        [0.0, side],
        [0.0, 0.0],
    ])
}

/// Klipper's ringing tower's outline (docs/Resonance_Compensation.md prints
/// docs/prints/ringing_tower.stl, "the ringing test model"): an L of two walls, each `side` mm
/// long (120 in the model) and `thickness` mm thick (8), standing on the X and Y axes, so that
/// each wall rings with one axis. A slicer's outer perimeter of it is this closed polygon:
/// from the origin along +X, around the end of the X wall, back along the inner face to the
/// inner (concave) corner, up the inner face of the Y wall, around its end and down its outer
/// face to the origin — five convex 90° corners and one concave. Read off the model's vertices
/// at z = 0 (its footprint spans 0…120 mm in X and Y; the inner faces are at x = 8 and
/// y = 8); the model's notches on the inner faces, its X and Y marks and its 0.15 mm smoothing
/// gap, there to make ringing and smoothing visible on a print, are left out.
pub fn ringing_tower(side: f64, thickness: f64) -> Result<Vec<[f64; 2]>> {
    positive("sideMm", side)?;
    positive("thicknessMm", thickness)?;
    if thickness >= side {
        return Err(Error::invalid(
            "thicknessMm",
            format!("must be less than sideMm ({side} mm), got {thickness}"),
        ));
    }
    let (l, w) = (side, thickness);
    Ok(vec![
        [0.0, 0.0],
        [l, 0.0],
        [l, w],
        [w, w],
        [w, l],
        [0.0, l],
        [0.0, 0.0],
    ])
}
