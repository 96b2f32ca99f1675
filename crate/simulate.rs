//! What a command does to a machine: [`simulate`] a plant under a command into a
//! [`Trajectory`]. Running a whole spec (design, command, plant, metrics) is
//! [`crate::scenario`]'s.

use crate::command::Command;
use crate::error::{finite, positive, Error, Result};
use crate::piecewise::Cursor;
use crate::plant::lti::LtiResponse;
use crate::plant::Plant;
use crate::shaper::{Impulse, Shaper};
use serde::Serialize;

/// Most samples one simulation may produce (memory stays bounded: ~10 signals of this length).
pub const MAX_SAMPLES: usize = 500_000;
/// Samples used when a spec gives neither `samplePeriod` nor `sampleRateHz`.
pub const DEFAULT_SAMPLES: usize = 2000;

/// The sampled response of a plant to a command.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Trajectory {
    /// Sample times in seconds, k·T (not serialised: `scenario::SimulationResult` carries one `time`
    /// for both responses).
    #[serde(skip)]
    pub time: Vec<f64>,
    /// Position of the driven base.
    pub base_position: Vec<f64>,
    /// Velocity of the base.
    pub base_velocity: Vec<f64>,
    /// Acceleration of the base.
    pub base_acceleration: Vec<f64>,
    /// Position of the endpoint (tip, payload).
    pub endpoint: Vec<f64>,
    /// Velocity of the endpoint.
    pub endpoint_velocity: Vec<f64>,
    /// Acceleration of the endpoint.
    pub endpoint_acceleration: Vec<f64>,
    /// Endpoint minus base.
    pub deflection: Vec<f64>,
    /// Swing angle in radians (pendulum only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub swing_angle: Option<Vec<f64>>,
}

/// Checks a sampling request: T > 0, duration ≥ 0, at most [`MAX_SAMPLES`] samples. Returns
/// the number of samples, ⌊duration/T⌋ + 1.
pub fn sample_count(sample_period: f64, duration: f64) -> Result<usize> {
    positive("samplePeriod", sample_period)?;
    finite("duration", duration)?;
    if duration < 0.0 {
        return Err(Error::invalid(
            "duration",
            format!("must be ≥ 0 s, got {duration}"),
        ));
    }
    let n = (duration / sample_period * (1.0 + 1e-12)).floor() + 1.0;
    if !n.is_finite() || n > MAX_SAMPLES as f64 {
        return Err(Error::TooLarge {
            field: "duration / samplePeriod".into(),
            value: n,
            limit: MAX_SAMPLES as f64,
        });
    }
    Ok(n as usize)
}

/// [`simulate`] of `command` shaped by `shaper` (the same trajectory, to rounding). On a modal
/// plant with a piecewise command it is computed from the shaper's convolution factors without
/// forming the shaped command (`Lti::respond_shaped`): Σ nₖ terms per mode instead of a knot
/// per impulse of Π nₖ; otherwise the command is shaped and simulated.
pub fn simulate_shaped(
    plant: &Plant,
    command: &Command,
    shaper: &Shaper,
    sample_period: f64,
    duration: f64,
) -> Result<Trajectory> {
    if let (Plant::Modal(m), Command::Piecewise(pw)) = (plant, command) {
        let samples = sample_count(sample_period, duration)?;
        let factors: Vec<&[Impulse]> = shaper.factors().collect();
        if let Some(r) = m
            .to_lti()
            .respond_shaped(pw, &factors, sample_period, samples)?
        {
            let time = (0..samples).map(|k| k as f64 * sample_period).collect();
            return Ok(lti_trajectory(r, time));
        }
    }
    simulate(plant, &command.shaped(shaper)?, sample_period, duration)
}

/// The trajectory of a linear plant's response sampled at `time`.
fn lti_trajectory(r: LtiResponse, time: Vec<f64>) -> Trajectory {
    let [bp, bv, ba, ep, ev, ea] = r.outputs;
    let deflection = ep.iter().zip(&bp).map(|(e, b)| e - b).collect();
    Trajectory {
        time,
        base_position: bp,
        base_velocity: bv,
        base_acceleration: ba,
        endpoint: ep,
        endpoint_velocity: ev,
        endpoint_acceleration: ea,
        deflection,
        swing_angle: None,
    }
}

/// Simulates `plant` under `command` from rest, sampled at t = k·`sample_period` for
/// `duration` seconds. Linear plants are exact at the samples (matrix exponential), the
/// pendulum is integrated adaptively.
pub fn simulate(
    plant: &Plant,
    command: &Command,
    sample_period: f64,
    duration: f64,
) -> Result<Trajectory> {
    let samples = sample_count(sample_period, duration)?;
    let pw = command.to_piecewise()?;
    let time: Vec<f64> = (0..samples).map(|k| k as f64 * sample_period).collect();
    let lti_plant = match plant {
        Plant::Modal(m) => Some(m.to_lti()),
        Plant::TwoMass(t) => Some(t.to_lti()?),
        Plant::Pendulum(_) => None,
    };
    if let Some(sys) = lti_plant {
        let r = sys.respond(&pw, sample_period, samples, false)?;
        return Ok(lti_trajectory(r, time));
    }
    let Plant::Pendulum(p) = plant else {
        return Err(Error::invalid("plant", "unsupported plant"));
    };
    let r = p.respond(&pw, sample_period, samples)?;
    let mut cursor = Cursor::new(&pw);
    let (mut bp, mut bv, mut ba) = (
        Vec::with_capacity(samples),
        Vec::with_capacity(samples),
        Vec::with_capacity(samples),
    );
    for &t in &time {
        cursor.seek(t);
        let s = cursor.state_at(t);
        bp.push(s[0]);
        bv.push(s[1]);
        ba.push(s[2]);
    }
    let deflection = r.endpoint.iter().zip(&bp).map(|(e, b)| e - b).collect();
    Ok(Trajectory {
        time,
        base_position: bp,
        base_velocity: bv,
        base_acceleration: ba,
        endpoint: r.endpoint,
        endpoint_velocity: r.endpoint_velocity,
        endpoint_acceleration: r.endpoint_acceleration,
        deflection,
        swing_angle: Some(r.angle),
    })
}
