//! A nonlinear pendulum: the payload of an overhead crane hanging on a cable of length ℓ(t)
//! from a trolley at position r(t) (the command), with swing angle θ:
//!
//! ℓθ'' + 2ℓ'θ' + r'' cos θ + g sin θ = 0  (+ 2ζω₀ℓθ' if a swing damping ζ is given),
//!
//! the Euler–Lagrange equation of the payload with r and ℓ prescribed. Large angles are kept
//! (no small-angle approximation); hoisting changes ℓ(t) during the move. It is integrated with
//! the adaptive Dormand–Prince 5(4) Runge–Kutta method, stopping at every sample and at every
//! knot of the commands. For small swings and a fixed cable it reduces to the modal plant
//! y'' + ω²y = ω²r with y = r + ℓθ and ω = √(g/ℓ) (tested).
//!
//! A velocity jump Δv of the trolley is an impulse: ℓθ' + r' cos θ is continuous, so θ' jumps
//! by −Δv cos θ/ℓ. A position jump (or a jump of the cable length) has no finite limit and is
//! rejected.

use crate::command::{Command, CommandSpec};
use crate::error::{finite, positive, Error, Result};
use crate::mode::Mode;
use crate::piecewise::{Cursor, Piecewise};
use serde::{Deserialize, Serialize};

/// Most Runge–Kutta steps one simulation may take.
pub const MAX_STEPS: usize = 2_000_000;
/// Shortest cable accepted during hoisting, as a fraction of the initial length.
pub const MIN_LENGTH_FRACTION: f64 = 0.01;
/// Relative tolerance of the integrator.
const RTOL: f64 = 1e-10;
/// Absolute tolerance of the integrator (radians, radians per second).
const ATOL: f64 = 1e-12;

/// A pendulum plant as written in a spec.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct PendulumSpec {
    /// Cable length ℓ₀ in metres at t = 0.
    pub length: f64,
    /// Gravity in m/s² (default 9.81).
    #[serde(default = "gravity")]
    pub gravity: f64,
    /// Viscous damping of the swing as a ratio of ω₀ = √(g/ℓ₀) (default 0).
    #[serde(default)]
    pub damping: f64,
    /// Swing angle at t = 0 in radians (default 0), released at rest.
    #[serde(default)]
    pub initial_angle: f64,
    /// Change of the cable length over time (added to `length`), e.g. a trapezoid for hoisting;
    /// must be continuous in position.
    #[serde(default)]
    pub hoist: Option<CommandSpec>,
}

fn gravity() -> f64 {
    9.81
}

/// A validated pendulum.
#[derive(Debug, Clone, PartialEq)]
pub struct Pendulum {
    length: f64,
    gravity: f64,
    damping: f64,
    initial_angle: f64,
    hoist: Option<Piecewise>,
}

/// Samples of a pendulum simulation.
#[derive(Debug, Clone, PartialEq)]
pub struct PendulumResponse {
    /// Swing angle θ (rad).
    pub angle: Vec<f64>,
    /// Payload horizontal position r + ℓ sin θ.
    pub endpoint: Vec<f64>,
    /// Payload horizontal velocity.
    pub endpoint_velocity: Vec<f64>,
    /// Payload horizontal acceleration.
    pub endpoint_acceleration: Vec<f64>,
    /// Cable length ℓ (m).
    pub length: Vec<f64>,
    /// Runge–Kutta steps taken.
    pub steps: usize,
}

impl Pendulum {
    /// Validates a spec.
    pub fn from_spec(spec: &PendulumSpec) -> Result<Self> {
        let length = positive("length", spec.length)?;
        let gravity = positive("gravity", spec.gravity)?;
        let damping = crate::vibration::damping_ratio("damping", spec.damping)?;
        finite("initialAngle", spec.initial_angle)?;
        if spec.initial_angle.abs() >= std::f64::consts::PI {
            return Err(Error::invalid(
                "initialAngle",
                format!("must lie in (−π, π) rad, got {}", spec.initial_angle),
            ));
        }
        let hoist = match &spec.hoist {
            None => None,
            Some(h) => Some(
                Command::from_spec(h)
                    .and_then(|c| c.to_piecewise())
                    .map_err(|e| e.within("hoist"))?,
            ),
        };
        if let Some(h) = &hoist {
            if h.knots().iter().any(|k| k.jumps[0] != 0.0) {
                return Err(Error::invalid(
                    "hoist",
                    "the cable length cannot jump; use a ramp, trapezoid, S-curve or profile",
                ));
            }
        }
        Ok(Pendulum {
            length,
            gravity,
            damping,
            initial_angle: spec.initial_angle,
            hoist,
        })
    }

    /// The linearised swing mode at the initial length: ω₀ = √(g/ℓ₀), the spec's damping.
    pub fn mode(&self) -> Result<Mode> {
        Mode::new(
            (self.gravity / self.length).sqrt() / (2.0 * std::f64::consts::PI),
            self.damping,
        )
    }

    /// Integrates the swing for the trolley command `command`, sampled at t = k·`sample_period`.
    pub fn respond(
        &self,
        command: &Piecewise,
        sample_period: f64,
        samples: usize,
    ) -> Result<PendulumResponse> {
        if let Some(k) = command.knots().iter().find(|k| k.jumps[0] != 0.0) {
            return Err(Error::invalid(
                "command",
                format!(
                    "the trolley position jumps at t = {} s, which a pendulum cannot follow; use \
                     a ramp, trapezoid, S-curve or profile (or the modal plant for steps)",
                    k.time
                ),
            ));
        }
        let empty = Piecewise::new(Vec::new())?;
        let hoist = self.hoist.as_ref().unwrap_or(&empty);
        let t_end = samples.saturating_sub(1) as f64 * sample_period;
        self.check_cable(hoist, t_end)?;
        let mut swing = Swing::new(self, command, hoist, sample_period);
        let mut out = PendulumResponse {
            angle: Vec::with_capacity(samples),
            endpoint: Vec::with_capacity(samples),
            endpoint_velocity: Vec::with_capacity(samples),
            endpoint_acceleration: Vec::with_capacity(samples),
            length: Vec::with_capacity(samples),
            steps: 0,
        };
        for k in 0..samples {
            swing.advance_to(k as f64 * sample_period)?;
            swing.record(&mut out);
        }
        out.steps = swing.steps;
        Ok(out)
    }

    /// The cable must stay long enough over the whole window [0, `t_end`] (checked before
    /// integrating, densely on every polynomial piece of the hoist).
    fn check_cable(&self, hoist: &Piecewise, t_end: f64) -> Result<()> {
        let mut checks: Vec<f64> = (0..=256).map(|i| t_end * i as f64 / 256.0).collect();
        let hk = hoist.knots();
        for (i, k) in hk.iter().enumerate() {
            let next = hk.get(i + 1).map_or(t_end.max(k.time), |n| n.time);
            checks.extend((0..=16).map(|j| k.time + (next - k.time) * j as f64 / 16.0));
        }
        for t in checks.into_iter().filter(|t| *t <= t_end) {
            let len = self.length + hoist.eval(t)[0];
            if len.is_nan() || len < MIN_LENGTH_FRACTION * self.length {
                return Err(Error::invalid(
                    "hoist",
                    format!(
                        "the cable length reaches {len} m at t = {t} s; it must stay above {} m \
                         ({} % of length)",
                        MIN_LENGTH_FRACTION * self.length,
                        MIN_LENGTH_FRACTION * 100.0
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// The integration of a swing: the cursors on the trolley command and the hoist, the state
/// y = (θ, θ') at time t, the adaptive step size and the steps taken.
struct Swing<'a> {
    command: &'a Piecewise,
    hoist: &'a Piecewise,
    trolley: Cursor<'a>,
    cable: Cursor<'a>,
    /// Gravity, m/s².
    g: f64,
    /// Cable length without the hoist, m.
    l0: f64,
    /// Damping coefficient 2ζω₀, 1/s.
    c_damp: f64,
    y: [f64; 2],
    t: f64,
    h: f64,
    steps: usize,
}

impl<'a> Swing<'a> {
    /// At rest at t = 0 at the pendulum's initial angle; the first step a hundredth of a
    /// radian of the linear swing (at most a sample period).
    fn new(
        p: &Pendulum,
        command: &'a Piecewise,
        hoist: &'a Piecewise,
        sample_period: f64,
    ) -> Swing<'a> {
        let w0 = (p.gravity / p.length).sqrt();
        Swing {
            command,
            hoist,
            trolley: Cursor::new(command),
            cable: Cursor::new(hoist),
            g: p.gravity,
            l0: p.length,
            c_damp: 2.0 * p.damping * w0,
            y: [p.initial_angle, 0.0],
            t: 0.0,
            h: (0.01 / w0).min(sample_period.max(1e-9)),
            steps: 0,
        }
    }

    /// Integrates up to `target`, stopping at every knot of the command and the hoist.
    fn advance_to(&mut self, target: f64) -> Result<()> {
        let (command, hoist): (&'a Piecewise, &'a Piecewise) = (self.command, self.hoist);
        let (tk, hk) = (command.knots(), hoist.knots());
        loop {
            // Apply every knot at the current time: a jump in the trolley's velocity kicks
            // the swing's rate.
            while let Some(kn) = tk
                .get(self.trolley.next_index())
                .filter(|kn| kn.time <= self.t)
            {
                let l = self.l0 + self.cable.state_at(self.t)[0];
                self.y[1] -= kn.jumps[1] * self.y[0].cos() / l;
                self.trolley.pass_next();
            }
            while hk
                .get(self.cable.next_index())
                .is_some_and(|kn| kn.time <= self.t)
            {
                self.cable.pass_next();
            }
            if self.t >= target {
                return Ok(());
            }
            let next_knot = [
                tk.get(self.trolley.next_index())
                    .map_or(f64::INFINITY, |k| k.time),
                hk.get(self.cable.next_index())
                    .map_or(f64::INFINITY, |k| k.time),
            ];
            self.integrate_to(target.min(next_knot[0]).min(next_knot[1]))?;
        }
    }

    /// Dormand–Prince steps with error control up to `stop`, with no knot before it.
    fn integrate_to(&mut self, stop: f64) -> Result<()> {
        let (g, l0, c_damp) = (self.g, self.l0, self.c_damp);
        let (ts, rs) = (self.t, self.trolley.state_at(self.t));
        let ls = self.cable.state_at(self.t);
        let (rdeg, ldeg) = (self.command.degree(), self.hoist.degree());
        let rhs = |tt: f64, s: &[f64; 2]| -> Result<[f64; 2]> {
            let r = crate::piecewise::taylor_shift(&rs, rdeg, tt - ts);
            let l = crate::piecewise::taylor_shift(&ls, ldeg, tt - ts);
            let len = l0 + l[0];
            if len.is_nan() || len <= 0.0 {
                return Err(Error::invalid(
                    "hoist",
                    format!("the cable length reaches {len} m at t = {tt} s; it must stay > 0"),
                ));
            }
            let acc =
                -(g * s[0].sin() + r[2] * s[0].cos() + 2.0 * l[1] * s[1]) / len - c_damp * s[1];
            Ok([s[1], acc])
        };
        while self.t < stop {
            self.steps += 1;
            if self.steps > MAX_STEPS {
                return Err(Error::TooLarge {
                    field: "duration".into(),
                    value: self.steps as f64,
                    limit: MAX_STEPS as f64,
                });
            }
            let (t, y) = (self.t, self.y);
            let hh = self.h.min(stop - t);
            let (ynew, err) = dopri_step(&rhs, t, &y, hh)?;
            let sc = |i: usize| ATOL + RTOL * y[i].abs().max(ynew[i].abs());
            let e = (err[0] / sc(0)).abs().max((err[1] / sc(1)).abs());
            if e <= 1.0 || hh < 1e-12 {
                self.t = if hh == stop - t { stop } else { t + hh };
                self.y = ynew;
            }
            let factor = if e == 0.0 {
                5.0
            } else {
                (0.9 * e.powf(-0.2)).clamp(0.2, 5.0)
            };
            self.h = (hh * factor).max(1e-12);
            if !self.y[0].is_finite() || !self.y[1].is_finite() {
                return Err(Error::invalid(
                    "plant",
                    "the pendulum's swing diverged (check the command and the hoist)",
                ));
            }
        }
        Ok(())
    }

    /// Appends the sample at the current time: angle, cable length and the payload's
    /// horizontal position, velocity and acceleration.
    fn record(&self, out: &mut PendulumResponse) {
        let (g, c_damp, y) = (self.g, self.c_damp, self.y);
        let r = self.trolley.state_at(self.t);
        let l = self.cable.state_at(self.t);
        let len = self.l0 + l[0];
        let (s, c) = y[0].sin_cos();
        let th_dd = -(g * s + r[2] * c + 2.0 * l[1] * y[1]) / len - c_damp * y[1];
        out.angle.push(y[0]);
        out.length.push(len);
        out.endpoint.push(r[0] + len * s);
        out.endpoint_velocity.push(r[1] + l[1] * s + len * c * y[1]);
        out.endpoint_acceleration
            .push(r[2] + l[2] * s + 2.0 * l[1] * c * y[1] + len * (c * th_dd - s * y[1] * y[1]));
    }
}

/// One Dormand–Prince 5(4) step: the 5th-order solution and the difference to the 4th-order one.
fn dopri_step(
    f: &impl Fn(f64, &[f64; 2]) -> Result<[f64; 2]>,
    t: f64,
    y: &[f64; 2],
    h: f64,
) -> Result<([f64; 2], [f64; 2])> {
    const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
    const A: [[f64; 6]; 7] = [
        [0.0; 6],
        [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
        [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
        [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
        [
            19372.0 / 6561.0,
            -25360.0 / 2187.0,
            64448.0 / 6561.0,
            -212.0 / 729.0,
            0.0,
            0.0,
        ],
        [
            9017.0 / 3168.0,
            -355.0 / 33.0,
            46732.0 / 5247.0,
            49.0 / 176.0,
            -5103.0 / 18656.0,
            0.0,
        ],
        [
            35.0 / 384.0,
            0.0,
            500.0 / 1113.0,
            125.0 / 192.0,
            -2187.0 / 6784.0,
            11.0 / 84.0,
        ],
    ];
    const B5: [f64; 7] = [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
        0.0,
    ];
    const B4: [f64; 7] = [
        5179.0 / 57600.0,
        0.0,
        7571.0 / 16695.0,
        393.0 / 640.0,
        -92097.0 / 339200.0,
        187.0 / 2100.0,
        1.0 / 40.0,
    ];
    let mut k = [[0.0; 2]; 7];
    for s in 0..7 {
        let mut ys = *y;
        for (j, kj) in k.iter().enumerate().take(s) {
            for i in 0..2 {
                ys[i] += h * A[s][j] * kj[i];
            }
        }
        k[s] = f(t + C[s] * h, &ys)?;
    }
    let mut y5 = *y;
    let mut err = [0.0; 2];
    for s in 0..7 {
        for i in 0..2 {
            y5[i] += h * B5[s] * k[s][i];
            err[i] += h * (B5[s] - B4[s]) * k[s][i];
        }
    }
    Ok((y5, err))
}
