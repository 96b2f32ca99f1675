//! What a command does to a machine: [`simulate`] a plant under a command, and [`run`] a whole
//! spec (plant, command, shaper, duration) into the unshaped and shaped responses and their
//! metrics — the one call a page frame needs.

use crate::command::{Command, CommandSpec, Cursor};
use crate::design::{design_for, ShaperSpec};
use crate::error::{finite, positive, Error, Result};
use crate::metrics::{metrics, mode_residual_percent, Metrics};
use crate::mode::{Mode, ModeSpec};
use crate::plant::{Plant, PlantSpec};
use crate::shaper::{Impulse, Shaper, ShaperData};
use serde::{Deserialize, Serialize};

/// Most samples one simulation may produce (memory stays bounded: ~10 signals of this length).
pub const MAX_SAMPLES: usize = 500_000;
/// Samples used when a spec gives neither `samplePeriod` nor `sampleRateHz`.
pub const DEFAULT_SAMPLES: usize = 2000;

/// The sampled response of a plant to a command.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Trajectory {
    /// Sample times in seconds, k·T (not serialised: [`SimulationResult`] carries one `time`
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
        let [bp, bv, ba, ep, ev, ea] = r.outputs;
        let deflection = ep.iter().zip(&bp).map(|(e, b)| e - b).collect();
        return Ok(Trajectory {
            time,
            base_position: bp,
            base_velocity: bv,
            base_acceleration: ba,
            endpoint: ep,
            endpoint_velocity: ev,
            endpoint_acceleration: ea,
            deflection,
            swing_angle: None,
        });
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

/// The shaper of a simulation spec: a family and its parameters, designed for `modes` (or, if
/// `modes` is left out, for the plant's own modes).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShaperRequest {
    /// The modes the shaper is designed for (the model); default: the plant's.
    #[serde(default)]
    pub modes: Option<Vec<ModeSpec>>,
    /// The family and its parameters (as `design` takes them).
    #[serde(flatten)]
    pub shaper: ShaperSpec,
}

/// `{ modes?, family, …parameters }`, read as [`crate::DesignRequest`] is.
impl<'de> Deserialize<'de> for ShaperRequest {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        #[derive(Deserialize)]
        struct Modes {
            #[serde(default)]
            modes: Option<Vec<ModeSpec>>,
        }
        #[derive(Deserialize)]
        struct ShaperRequest {
            #[serde(default)]
            modes: Option<Vec<ModeSpec>>,
            #[serde(flatten)]
            shaper: ShaperSpec,
        }
        let (Modes { modes }, shaper) =
            crate::tagged::deserialize_flat(d, "struct ShaperRequest", |d| {
                let ShaperRequest { modes, shaper } = ShaperRequest::deserialize(d)?;
                Ok((Modes { modes }, shaper))
            })?;
        Ok(Self { modes, shaper })
    }
}

/// Everything a simulation needs, as written in JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct SimulationSpec {
    /// The machine.
    pub plant: PlantSpec,
    /// The reference command (unshaped).
    pub command: CommandSpec,
    /// A shaper to design (`{ family, modes?, … }`); give this or `impulses`, or neither.
    #[serde(default)]
    pub shaper: Option<ShaperRequest>,
    /// An explicit shaper (`[{ time, amplitude }]`).
    #[serde(default)]
    pub impulses: Option<Vec<Impulse>>,
    /// Simulated time in seconds (default: until the shaped move has ended plus three periods
    /// of the slowest mode).
    #[serde(default)]
    pub duration: Option<f64>,
    /// Sample period in seconds (or give `sampleRateHz`; default: `duration`/1999, i.e. 2000
    /// samples).
    #[serde(default)]
    pub sample_period: Option<f64>,
    /// Sample rate in Hz (alternative to `samplePeriod`).
    #[serde(default)]
    pub sample_rate_hz: Option<f64>,
}

/// One simulated response with its metrics.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Response {
    /// The signals.
    #[serde(flatten)]
    pub trajectory: Trajectory,
    /// What the papers judge shapers by.
    pub metrics: Metrics,
}

/// The result of [`run`].
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct SimulationResult {
    /// Sample times in seconds (the same for both responses).
    pub time: Vec<f64>,
    /// Response to the unshaped command.
    pub unshaped: Response,
    /// Response to the shaped command (when a shaper was given).
    pub shaped: Option<Response>,
    /// The shaper used.
    pub shaper: Option<ShaperData>,
    /// The plant's modes in Hz (the pendulum's linearised), for marking charts.
    pub modes_hz: Vec<f64>,
    /// Sample period used, in seconds.
    pub sample_period: f64,
}

/// The shaper a spec asks for (if any), validated and designed.
pub fn spec_shaper(spec: &SimulationSpec, plant: &Plant) -> Result<Option<Shaper>> {
    resolve_shaper(&spec.shaper, &spec.impulses, || plant.modes())
}

/// A shaper from a `shaper` design request or explicit `impulses` (at most one of them);
/// `default_modes` supplies the modes when the request leaves them out.
pub fn resolve_shaper(
    shaper: &Option<ShaperRequest>,
    impulses: &Option<Vec<Impulse>>,
    default_modes: impl FnOnce() -> Result<Vec<Mode>>,
) -> Result<Option<Shaper>> {
    match (shaper, impulses) {
        (Some(_), Some(_)) => Err(Error::invalid(
            "impulses",
            "give either shaper (a design) or impulses (an explicit shaper), not both",
        )),
        (None, None) => Ok(None),
        (None, Some(imp)) => Ok(Some(Shaper::new(imp.clone()).map_err(|e| match e {
            Error::InvalidInput { field, reason } if field.starts_with("impulses") => {
                Error::InvalidInput { field, reason }
            }
            other => other.within("impulses"),
        })?)),
        (Some(req), None) => {
            let modes = match &req.modes {
                Some(m) => Mode::list(m).map_err(|e| e.within("shaper"))?,
                None => default_modes()?,
            };
            design_for(&req.shaper, &modes)
                .map(Some)
                .map_err(|e| e.within("shaper"))
        }
    }
}

/// Runs a spec: designs the shaper, simulates the unshaped and (if a shaper is given) the
/// shaped command on the plant, and computes the metrics of both.
pub fn run(spec: &SimulationSpec) -> Result<SimulationResult> {
    let plant = Plant::from_spec(&spec.plant).map_err(|e| e.within("plant"))?;
    let command = Command::from_spec(&spec.command).map_err(|e| e.within("command"))?;
    let shaper = spec_shaper(spec, &plant)?;
    let shaped = match &shaper {
        Some(s) => Some(command.shaped(s).map_err(|e| e.within("command"))?),
        None => None,
    };
    let modes = plant.modes()?;
    let slowest = modes
        .iter()
        .map(Mode::damped_period_s)
        .fold(0.0_f64, f64::max);
    let end = shaped
        .as_ref()
        .map_or(command.end_time(), |c| c.end_time().max(command.end_time()));
    let duration = match spec.duration {
        Some(d) => d,
        None => (end + 3.0 * slowest).max(1e-3),
    };
    finite("duration", duration)?;
    if duration <= 0.0 {
        return Err(Error::invalid(
            "duration",
            format!("must be greater than 0 s, got {duration}"),
        ));
    }
    let sample_period = match (spec.sample_period, spec.sample_rate_hz) {
        (Some(_), Some(_)) => {
            return Err(Error::invalid(
                "sampleRateHz",
                "give samplePeriod or sampleRateHz, not both",
            ))
        }
        (Some(t), None) => positive("samplePeriod", t)?,
        (None, Some(f)) => 1.0 / positive("sampleRateHz", f)?,
        (None, None) => duration / (DEFAULT_SAMPLES - 1) as f64,
    };
    sample_count(sample_period, duration)?;
    let unshaped_traj = simulate(&plant, &command, sample_period, duration)?;
    let with_modes = |mut m: Metrics, c: &Command| -> Result<Metrics> {
        if let Plant::Modal(mp) = &plant {
            m.mode_residual_percent = mode_residual_percent(mp, &c.to_piecewise()?)?;
        }
        Ok(m)
    };
    let unshaped_metrics = with_modes(metrics(&unshaped_traj, &command, &command)?, &command)?;
    let shaped_resp = match &shaped {
        Some(c) => {
            let t = simulate(&plant, c, sample_period, duration)?;
            let m = with_modes(metrics(&t, c, &command)?, c)?;
            Some(Response {
                trajectory: t,
                metrics: m,
            })
        }
        None => None,
    };
    let time = unshaped_traj.time.clone();
    Ok(SimulationResult {
        time,
        unshaped: Response {
            trajectory: unshaped_traj,
            metrics: unshaped_metrics,
        },
        shaped: shaped_resp,
        shaper: shaper.map(|s| s.to_data()),
        modes_hz: modes.iter().map(Mode::frequency_hz).collect(),
        sample_period,
    })
}
