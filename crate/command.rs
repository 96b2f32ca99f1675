//! Reference commands and shaping them.
//!
//! A command is the position reference the machine's base follows: a step, a ramp, a
//! trapezoidal or triangular velocity profile (Peláez & Singhose 2002 §1), a jerk-limited
//! S-curve, an arbitrary sampled signal (e.g. a joystick; Singer & Seering 1988 Fig. 10), or a
//! pulse-convolution profile ([`crate::profile`], Veciana & Cardona 2011).
//!
//! Every analytic command is a [`Piecewise`] polynomial stored in *jump form*: a list of knots,
//! each giving the jumps of the position and its derivatives at that time, so that
//!
//! u(t) = Σ_{τⱼ ≤ t} Σₖ Jⱼₖ (t − τⱼ)ᵏ / k!.
//!
//! Shaping by an impulse sequence (Σ Aᵢ δ(t − tᵢ)) is then exact: each knot is copied to
//! τⱼ + tᵢ with its jumps times Aᵢ (Singhose 2009 Fig. 5). A [`Sampled`] signal is shaped the way
//! a controller runs it, sample by sample, by [`StreamingShaper`]: each impulse's delay tᵢ/T is
//! split into an integer part and a fraction, and the fraction is realised by linear
//! interpolation between neighbouring samples — exactly the shaped command of the linearly
//! interpolated signal, read at the samples.

use crate::error::{finite, positive, Error, Result};
use crate::profile::ProfileSpec;
use crate::shaper::Shaper;
use serde::{Deserialize, Serialize};

pub use crate::piecewise::{Knot, Piecewise, MAX_DEGREE, MAX_KNOTS, ORDER};

/// Most samples a sampled command may hold.
pub const MAX_COMMAND_SAMPLES: usize = 2_000_000;

/// How a sampled signal is read between its samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum Interpolation {
    /// Straight lines between samples (first-order hold).
    #[default]
    Linear,
    /// Each sample held until the next (zero-order hold).
    Hold,
}

/// An arbitrary command given by samples `values[k]` at t = k·`period` (k = 0, 1, …); before
/// t = 0 it is 0 and after the last sample it keeps the last value.
#[derive(Debug, Clone, PartialEq)]
pub struct Sampled {
    period: f64,
    values: Vec<f64>,
    interpolation: Interpolation,
}

impl Sampled {
    /// Validates: `period` > 0, 1 … [`MAX_COMMAND_SAMPLES`] finite values.
    pub fn new(period: f64, values: Vec<f64>, interpolation: Interpolation) -> Result<Self> {
        positive("samplePeriod", period)?;
        crate::error::count("values", values.len(), 1, MAX_COMMAND_SAMPLES)?;
        for (i, v) in values.iter().enumerate() {
            finite(&format!("values[{i}]"), *v)?;
        }
        Ok(Sampled {
            period,
            values,
            interpolation,
        })
    }

    /// Sample period in seconds.
    pub fn period(&self) -> f64 {
        self.period
    }

    /// The samples.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// How the signal is read between samples.
    pub fn interpolation(&self) -> Interpolation {
        self.interpolation
    }

    /// The signal as a piecewise polynomial (degree 1 for linear interpolation, 0 for hold).
    /// The first sample is reached from 0 by a step at t = 0.
    pub fn to_piecewise(&self) -> Result<Piecewise> {
        let t = self.period;
        let v = &self.values;
        let mut knots = Vec::with_capacity(v.len() + 1);
        let knot = |time: f64, d0: f64, d1: f64| {
            let mut jumps = [0.0; ORDER];
            jumps[0] = d0;
            jumps[1] = d1;
            Knot { time, jumps }
        };
        match self.interpolation {
            Interpolation::Hold => {
                let mut prev = 0.0;
                for (k, &x) in v.iter().enumerate() {
                    if x != prev {
                        knots.push(knot(k as f64 * t, x - prev, 0.0));
                    }
                    prev = x;
                }
            }
            Interpolation::Linear => {
                let mut slope = 0.0;
                for k in 0..v.len() {
                    let new_slope = match v.get(k + 1) {
                        Some(next) => (next - v[k]) / t,
                        None => 0.0,
                    };
                    let d0 = if k == 0 { v[0] } else { 0.0 };
                    if d0 != 0.0 || new_slope != slope {
                        knots.push(knot(k as f64 * t, d0, new_slope - slope));
                    }
                    slope = new_slope;
                }
            }
        }
        Piecewise::new(knots)
    }

    /// Value at time `t` (interpolated as the signal says).
    pub fn eval(&self, t: f64) -> f64 {
        if t < 0.0 || self.values.is_empty() {
            return 0.0;
        }
        let x = t / self.period;
        let k = x.floor();
        let i = k as usize;
        let last = self.values.len() - 1;
        if i >= last {
            return self.values[last];
        }
        match self.interpolation {
            Interpolation::Hold => self.values[i],
            Interpolation::Linear => {
                let f = x - k;
                self.values[i] * (1.0 - f) + self.values[i + 1] * f
            }
        }
    }

    /// The signal shaped sample by sample by a [`StreamingShaper`], on the same grid, long
    /// enough to hold the whole shaped transient.
    pub fn shaped(&self, shaper: &Shaper) -> Result<Sampled> {
        let mut filter = StreamingShaper::new(shaper, self.period)?;
        let extra = filter.max_delay() + 2;
        let n = self.values.len() + extra;
        crate::error::count("values", n, 1, MAX_COMMAND_SAMPLES)?;
        let last = self.values.last().copied().unwrap_or(0.0);
        let mut input = self.values.clone();
        input.resize(n, last);
        let mut out = vec![0.0; n];
        filter.process(&input, &mut out);
        Sampled::new(self.period, out, self.interpolation)
    }
}

/// Most taps (integer delays) a streaming shaper may use.
pub const MAX_STREAMING_DELAY: usize = 10_000_000;

/// An input shaper run the way a controller runs it: one sample in, one sample out, at a fixed
/// sample period T. Impulse i (amplitude Aᵢ, time tᵢ) becomes two taps: weight Aᵢ(1 − φᵢ) at
/// delay nᵢ and Aᵢφᵢ at nᵢ + 1, where tᵢ/T = nᵢ + φᵢ — linear interpolation of the input at
/// the fractional delay. Taps at the same delay are merged. Before the first sample the input is
/// taken as 0, so a signal whose first sample is not 0 is read as rising linearly from 0 over
/// the sample period before t = 0 (start a signal at rest to avoid this).
#[derive(Debug, Clone)]
pub struct StreamingShaper {
    delays: Vec<usize>,
    weights: Vec<f64>,
    buffer: Vec<f64>,
    mask: usize,
    pos: usize,
    max_delay: usize,
}

impl StreamingShaper {
    /// Builds the filter for `shaper` at sample period `sample_period` (s). Errors if the
    /// longest delay exceeds [`MAX_STREAMING_DELAY`] samples.
    pub fn new(shaper: &Shaper, sample_period: f64) -> Result<Self> {
        positive("samplePeriod", sample_period)?;
        let mut taps: Vec<(usize, f64)> = Vec::with_capacity(2 * shaper.len());
        for imp in shaper.impulses() {
            let d = imp.time / sample_period;
            if !d.is_finite() || d > MAX_STREAMING_DELAY as f64 {
                return Err(Error::TooLarge {
                    field: "samplePeriod".into(),
                    value: d,
                    limit: MAX_STREAMING_DELAY as f64,
                });
            }
            // Snap delays within rounding of an integer so exact grids give single taps.
            let mut n = d.floor();
            let mut frac = d - n;
            if frac > 1.0 - 1e-9 {
                n += 1.0;
                frac = 0.0;
            } else if frac < 1e-9 {
                frac = 0.0;
            }
            let n = n as usize;
            taps.push((n, imp.amplitude * (1.0 - frac)));
            if frac > 0.0 {
                taps.push((n + 1, imp.amplitude * frac));
            }
        }
        crate::sort::sort_by(&mut taps, |a, b| a.0.cmp(&b.0));
        let mut delays = Vec::new();
        let mut weights: Vec<f64> = Vec::new();
        for (d, w) in taps {
            if delays.last() == Some(&d) {
                if let Some(last) = weights.last_mut() {
                    *last += w;
                }
            } else {
                delays.push(d);
                weights.push(w);
            }
        }
        let max_delay = delays.last().copied().unwrap_or(0);
        let size = (max_delay + 1).next_power_of_two();
        Ok(StreamingShaper {
            delays,
            weights,
            buffer: vec![0.0; size],
            mask: size - 1,
            pos: 0,
            max_delay,
        })
    }

    /// The longest delay, in samples.
    pub fn max_delay(&self) -> usize {
        self.max_delay
    }

    /// The taps as (delay in samples, weight).
    pub fn taps(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.delays
            .iter()
            .copied()
            .zip(self.weights.iter().copied())
    }

    /// Forgets the past (as if the input had always been 0).
    pub fn reset(&mut self) {
        self.buffer.iter_mut().for_each(|x| *x = 0.0);
        self.pos = 0;
    }

    /// One sample in, one out: `y[k] = Σ wⱼ x[k − dⱼ]`.
    #[inline]
    pub fn push(&mut self, x: f64) -> f64 {
        self.pos = (self.pos + 1) & self.mask;
        self.buffer[self.pos] = x;
        let mut y = 0.0;
        for (&d, &w) in self.delays.iter().zip(&self.weights) {
            y += w * self.buffer[self.pos.wrapping_sub(d) & self.mask];
        }
        y
    }

    /// Filters a block: `output[k]` = what [`push`](Self::push) would return for `input[k]`.
    /// Processes `min(input.len(), output.len())` samples; the state carries over to the next
    /// call. Works in cache-sized chunks: the history and a chunk of input are laid out in one
    /// linear buffer, then each tap is one vectorisable pass over the chunk.
    pub fn process(&mut self, input: &[f64], output: &mut [f64]) {
        const CHUNK: usize = 2048;
        let n = input.len().min(output.len());
        let (input, output) = (&input[..n], &mut output[..n]);
        let m = self.max_delay;
        if n <= 2 * (m + 1) || n < 64 {
            for (x, y) in input.iter().zip(output.iter_mut()) {
                *y = self.push(*x);
            }
            return;
        }
        // scratch = [x[k−m] … x[k−1] | chunk]: the history, oldest first, then the chunk.
        let mut scratch = vec![0.0; m + CHUNK.min(n)];
        for i in 0..m {
            scratch[m - 1 - i] = self.buffer[self.pos.wrapping_sub(i) & self.mask];
        }
        for (xin, yout) in input.chunks(CHUNK).zip(output.chunks_mut(CHUNK)) {
            let len = xin.len();
            scratch[m..m + len].copy_from_slice(xin);
            fir_chunk(&self.delays, &self.weights, &scratch, m, yout);
            scratch.copy_within(len..len + m, 0);
        }
        // Back into the ring: the last m inputs (oldest first), ending at pos.
        for &x in &scratch[..m] {
            self.pos = (self.pos + 1) & self.mask;
            self.buffer[self.pos] = x;
        }
    }
}

/// One chunk of the block filter: `y[k] = Σⱼ wⱼ · scratch[m − dⱼ + k]` for k < `y.len()`, where
/// `scratch` holds the `m` samples of history followed by the chunk. Picks the widest vector
/// instructions the processor has (AVX2 where present, detected at run time); every variant
/// adds the same products in the same order, so the results are bit-identical.
fn fir_chunk(delays: &[usize], weights: &[f64], scratch: &[f64], m: usize, y: &mut [f64]) {
    #[cfg(all(target_arch = "x86_64", not(target_feature = "avx2")))]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor supports AVX2 (checked just above), the only requirement of a
        // `#[target_feature(enable = "avx2")]` function; the function itself is safe code.
        unsafe { fir_chunk_avx2(delays, weights, scratch, m, y) };
        return;
    }
    fir_chunk_generic(delays, weights, scratch, m, y);
}

#[cfg(all(target_arch = "x86_64", not(target_feature = "avx2")))]
#[target_feature(enable = "avx2")]
fn fir_chunk_avx2(delays: &[usize], weights: &[f64], scratch: &[f64], m: usize, y: &mut [f64]) {
    fir_chunk_generic(delays, weights, scratch, m, y);
}

/// The portable kernel. Register blocking: `LANES` outputs are accumulated over all taps before
/// they are stored, so each tap costs one load per sample (not a load and a store of y too);
/// each tap's source is sliced once per block, so the inner loop has no bounds checks.
#[inline(always)]
fn fir_chunk_generic(delays: &[usize], weights: &[f64], scratch: &[f64], m: usize, y: &mut [f64]) {
    const LANES: usize = 16;
    let len = y.len();
    let blocked = len - len % LANES;
    for (b, yb) in y[..blocked].chunks_exact_mut(LANES).enumerate() {
        let k = b * LANES;
        let mut acc = [0.0; LANES];
        for (&d, &w) in delays.iter().zip(weights) {
            let src = &scratch[m - d + k..m - d + k + LANES];
            for (a, x) in acc.iter_mut().zip(src) {
                *a += w * x;
            }
        }
        yb.copy_from_slice(&acc);
    }
    for (k, yk) in y.iter_mut().enumerate().skip(blocked) {
        *yk = delays
            .iter()
            .zip(weights)
            .map(|(&d, &w)| w * scratch[m - d + k])
            .sum();
    }
}

crate::tagged::tagged_enum! {
    tag = "kind", rename_all = "camelCase", mirror = command_spec_serde;
    /// A command as written in a spec (`{ kind, … }`). Times in seconds, distances in the
    /// machine's length unit (metres, radians, …), velocities per second.
    #[derive(Debug, Clone, PartialEq)]
    pub enum CommandSpec {
        /// A step of `distance` at `start`.
        Step {
            /// Height of the step (default 1).
            #[serde(default = "one")]
            distance: f64,
            /// Time of the step in seconds (default 0).
            #[serde(default)]
            start: f64,
        },
        /// A ramp of `slope` per second from `start` on (never ends).
        Ramp {
            /// Slope, units per second (default 1).
            #[serde(default = "one")]
            slope: f64,
            /// Start time in seconds (default 0).
            #[serde(default)]
            start: f64,
        },
        /// Trapezoidal velocity profile; triangular when the move is too short to reach
        /// `maxVelocity` (Peláez & Singhose 2002 §1).
        #[serde(rename_all = "camelCase")]
        Trapezoid {
            /// Distance to travel (may be negative).
            distance: f64,
            /// Velocity limit (> 0).
            max_velocity: f64,
            /// Acceleration limit (> 0).
            max_acceleration: f64,
            /// Start time in seconds (default 0).
            #[serde(default)]
            start: f64,
        },
        /// Jerk-limited (seven-segment) S-curve.
        #[serde(rename_all = "camelCase")]
        SCurve {
            /// Distance to travel (may be negative).
            distance: f64,
            /// Velocity limit (> 0).
            max_velocity: f64,
            /// Acceleration limit (> 0).
            max_acceleration: f64,
            /// Jerk limit (> 0).
            max_jerk: f64,
            /// Start time in seconds (default 0).
            #[serde(default)]
            start: f64,
        },
        /// An arbitrary sampled signal (e.g. a joystick), `values[k]` at t = k·`samplePeriod`.
        #[serde(rename_all = "camelCase")]
        Sampled {
            /// Sample period in seconds.
            sample_period: f64,
            /// The samples.
            values: Vec<f64>,
            /// `"linear"` (default) or `"hold"`.
            #[serde(default)]
            interpolation: Interpolation,
        },
        /// A pulse-convolution profile (Veciana & Cardona 2011), see [`ProfileSpec`].
        Profile(ProfileSpec),
    }
}

fn one() -> f64 {
    1.0
}

/// A command ready to shape and simulate.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Exact piecewise polynomial (step, ramp, trapezoid, S-curve, profile, or a sampled signal
    /// read exactly).
    Piecewise(Piecewise),
    /// Samples on a grid, shaped by a streaming filter.
    Sampled(Sampled),
}

impl Command {
    /// Builds the command a spec describes.
    pub fn from_spec(spec: &CommandSpec) -> Result<Command> {
        Ok(match spec {
            CommandSpec::Step { distance, start } => Command::Piecewise(step(*distance, *start)?),
            CommandSpec::Ramp { slope, start } => Command::Piecewise(ramp(*slope, *start)?),
            CommandSpec::Trapezoid {
                distance,
                max_velocity,
                max_acceleration,
                start,
            } => Command::Piecewise(trapezoid(
                *distance,
                *max_velocity,
                *max_acceleration,
                *start,
            )?),
            CommandSpec::SCurve {
                distance,
                max_velocity,
                max_acceleration,
                max_jerk,
                start,
            } => Command::Piecewise(s_curve(
                *distance,
                *max_velocity,
                *max_acceleration,
                *max_jerk,
                *start,
            )?),
            CommandSpec::Sampled {
                sample_period,
                values,
                interpolation,
            } => Command::Sampled(Sampled::new(
                *sample_period,
                values.clone(),
                *interpolation,
            )?),
            CommandSpec::Profile(p) => Command::Piecewise(crate::profile::from_spec(p)?),
        })
    }

    /// The command shaped by `shaper`: exact convolution for piecewise commands, the streaming
    /// filter for sampled ones.
    pub fn shaped(&self, shaper: &Shaper) -> Result<Command> {
        Ok(match self {
            Command::Piecewise(p) => Command::Piecewise(p.shaped(shaper)?),
            Command::Sampled(s) => Command::Sampled(s.shaped(shaper)?),
        })
    }

    /// The command as a piecewise polynomial (sampled signals read as they interpolate).
    pub fn to_piecewise(&self) -> Result<Piecewise> {
        match self {
            Command::Piecewise(p) => Ok(p.clone()),
            Command::Sampled(s) => s.to_piecewise(),
        }
    }

    /// When the command stops changing (its last knot, or its last sample that differs from
    /// the final value).
    pub fn end_time(&self) -> f64 {
        match self {
            Command::Piecewise(p) => p.end_time(),
            Command::Sampled(s) => {
                let last = s.values.last().copied().unwrap_or(0.0);
                let k = s
                    .values
                    .iter()
                    .rposition(|&v| v != last)
                    .map_or(0, |k| k + 1);
                k as f64 * s.period
            }
        }
    }
}

fn knot(time: f64, order: usize, value: f64) -> Knot {
    let mut jumps = [0.0; ORDER];
    if let Some(j) = jumps.get_mut(order) {
        *j = value;
    }
    Knot { time, jumps }
}

fn start_time(start: f64) -> Result<f64> {
    finite("start", start)?;
    if start < 0.0 {
        return Err(Error::invalid(
            "start",
            format!("must be ≥ 0 s, got {start}"),
        ));
    }
    Ok(start)
}

/// A step of `distance` at time `start`.
pub fn step(distance: f64, start: f64) -> Result<Piecewise> {
    finite("distance", distance)?;
    Piecewise::new(vec![knot(start_time(start)?, 0, distance)])
}

/// A ramp of `slope` units per second starting at `start`.
pub fn ramp(slope: f64, start: f64) -> Result<Piecewise> {
    finite("slope", slope)?;
    Piecewise::new(vec![knot(start_time(start)?, 1, slope)])
}

/// Trapezoidal velocity profile over `distance` with velocity and acceleration limits.
/// When the move is too short to reach `max_velocity` (|distance| < v²/a) the profile is
/// triangular with peak velocity √(|distance|·a) (Peláez & Singhose 2002 §1).
pub fn trapezoid(
    distance: f64,
    max_velocity: f64,
    max_acceleration: f64,
    start: f64,
) -> Result<Piecewise> {
    finite("distance", distance)?;
    let v = positive("maxVelocity", max_velocity)?;
    let a = positive("maxAcceleration", max_acceleration)?;
    let t0 = start_time(start)?;
    let d = distance.abs();
    let sign = distance.signum();
    if d == 0.0 {
        return Piecewise::new(Vec::new());
    }
    let (v_peak, cruise) = if d < v * v / a {
        ((d * a).sqrt(), 0.0)
    } else {
        (v, (d - v * v / a) / v)
    };
    let ta = v_peak / a;
    Piecewise::new(vec![
        knot(t0, 2, sign * a),
        knot(t0 + ta, 2, -sign * a),
        knot(t0 + ta + cruise, 2, -sign * a),
        knot(t0 + 2.0 * ta + cruise, 2, sign * a),
    ])
}

/// Jerk-limited seven-segment S-curve over `distance`. The acceleration ramps at ±`max_jerk`;
/// when `max_acceleration` cannot be reached before `max_velocity` (v < a²/j) the peak
/// acceleration is √(v·j), and when the move is too short to reach `max_velocity` the peak
/// velocity is lowered so that the accelerating and decelerating halves meet.
pub fn s_curve(
    distance: f64,
    max_velocity: f64,
    max_acceleration: f64,
    max_jerk: f64,
    start: f64,
) -> Result<Piecewise> {
    finite("distance", distance)?;
    let v = positive("maxVelocity", max_velocity)?;
    let a = positive("maxAcceleration", max_acceleration)?;
    let j = positive("maxJerk", max_jerk)?;
    let t0 = start_time(start)?;
    let d = distance.abs();
    let sign = distance.signum();
    if d == 0.0 {
        return Piecewise::new(Vec::new());
    }
    // Time to accelerate from 0 to w (and the distance it takes is w·T(w)/2 by symmetry).
    let accel_time = |w: f64| {
        if w >= a * a / j {
            w / a + a / j
        } else {
            2.0 * (w / j).sqrt()
        }
    };
    let mut v_peak = v;
    if v * accel_time(v) > d {
        // Solve w·T(w) = d for the reachable peak velocity.
        let w1 = 0.5 * a * (-a / j + (a * a / (j * j) + 4.0 * d / a).sqrt());
        v_peak = if w1 >= a * a / j {
            w1
        } else {
            (d * j.sqrt() / 2.0).powf(2.0 / 3.0)
        };
    }
    let (tj, ta) = if v_peak >= a * a / j {
        (a / j, v_peak / a - a / j)
    } else {
        ((v_peak / j).sqrt(), 0.0)
    };
    let cruise = ((d - v_peak * (2.0 * tj + ta)) / v_peak).max(0.0);
    let t_acc = 2.0 * tj + ta;
    let t1 = t0 + t_acc + cruise;
    let js = sign * j;
    Piecewise::new(vec![
        knot(t0, 3, js),
        knot(t0 + tj, 3, -js),
        knot(t0 + tj + ta, 3, -js),
        knot(t0 + t_acc, 3, js),
        knot(t1, 3, -js),
        knot(t1 + tj, 3, js),
        knot(t1 + tj + ta, 3, js),
        knot(t1 + t_acc, 3, -js),
    ])
}
