//! Running a whole scenario as written in JSON: design the shaper a spec asks for, shape the
//! command, [`simulate`] the plant under the unshaped and shaped commands and compute their
//! [`metrics`] ([`run`], the one call a page frame needs), or compute their spectra
//! ([`spectrum_for`]).
//!
//! This module sits above design, the commands, the plants and the results (simulate, metrics,
//! spectrum): it is the only one that puts them together.

use crate::command::{Command, CommandSpec};
use crate::design::{design_for, ShaperSpec};
use crate::error::{finite, positive, Error, Result};
use crate::metrics::{metrics, mode_residual_percent, Metrics};
use crate::mode::{Mode, ModeSpec};
use crate::plant::{Plant, PlantModeSpec, PlantSpec};
use crate::shaper::{Impulse, Shaper, ShaperData};
use crate::simulate::{sample_count, simulate, Trajectory, DEFAULT_SAMPLES};
use crate::spectrum::{command_spectrum, SpectrumOptions, SpectrumSignal};
use serde::{Deserialize, Serialize};

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

/// A spectrum request as written in JSON: the command, optionally a shaper (`shaper`: a design
/// `{ family, modes?, … }`, or `impulses`) and a plant (its modes are returned for marking and
/// are the default design modes), and the frequency grid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct SpectrumSpec {
    /// The reference command.
    pub command: CommandSpec,
    /// A shaper to design.
    #[serde(default)]
    pub shaper: Option<ShaperRequest>,
    /// An explicit shaper.
    #[serde(default)]
    pub impulses: Option<Vec<Impulse>>,
    /// The machine (optional).
    #[serde(default)]
    pub plant: Option<PlantSpec>,
    /// First frequency in Hz (default 0).
    #[serde(default)]
    pub from_hz: f64,
    /// Last frequency in Hz (default: 3 × the highest mode of the plant or shaper design).
    #[serde(default)]
    pub to_hz: Option<f64>,
    /// Number of frequencies (default 512).
    #[serde(default = "crate::spectrum::default_points")]
    pub points: usize,
    /// `"velocity"` (default), `"position"` or `"acceleration"`.
    #[serde(default)]
    pub signal: SpectrumSignal,
}

/// The spectra of a [`SpectrumSpec`].
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct SpectrumResult {
    /// Frequencies in Hz.
    pub frequency_hz: Vec<f64>,
    /// |U(f)| of the shaped command (of the command itself when no shaper is given).
    pub magnitude: Vec<f64>,
    /// |U(f)| of the unshaped command.
    pub unshaped: Vec<f64>,
    /// The plant's modes in Hz, or the shaper's design modes, for marking.
    pub modes_hz: Vec<f64>,
}

/// Computes the spectra a spec asks for.
pub fn spectrum_for(spec: &SpectrumSpec) -> Result<SpectrumResult> {
    let plant = match &spec.plant {
        Some(p) => Some(Plant::from_spec(p).map_err(|e| e.within("plant"))?),
        None => None,
    };
    let plant_modes = match &plant {
        Some(p) => p.modes()?,
        None => Vec::new(),
    };
    let default_modes = plant_modes.clone();
    let shaper = resolve_shaper(&spec.shaper, &spec.impulses, move || {
        if default_modes.is_empty() {
            Err(Error::invalid(
                "shaper.modes",
                "give the modes to design for (or a plant)",
            ))
        } else {
            Ok(default_modes)
        }
    })?;
    let mut modes_hz: Vec<f64> = plant_modes.iter().map(|m| m.frequency_hz()).collect();
    if modes_hz.is_empty() {
        if let Some(req) = &spec.shaper {
            modes_hz = req.modes.iter().flatten().map(|m| m.frequency_hz).collect();
        }
    }
    let to_hz = match spec.to_hz {
        Some(t) => t,
        None => {
            let top = modes_hz.iter().fold(0.0_f64, |m, f| m.max(*f));
            if top > 0.0 {
                3.0 * top
            } else {
                return Err(Error::invalid(
                    "toHz",
                    "give toHz (there is no mode to scale the axis by)",
                ));
            }
        }
    };
    let options = SpectrumOptions {
        from_hz: spec.from_hz,
        to_hz,
        points: spec.points,
        signal: spec.signal,
    };
    let command = Command::from_spec(&spec.command).map_err(|e| e.within("command"))?;
    let unshaped = command_spectrum(&command, &options)?;
    let magnitude = match &shaper {
        Some(s) => {
            command_spectrum(
                &command.shaped(s).map_err(|e| e.within("command"))?,
                &options,
            )?
            .magnitude
        }
        None => unshaped.magnitude.clone(),
    };
    Ok(SpectrumResult {
        frequency_hz: unshaped.frequency_hz,
        magnitude,
        unshaped: unshaped.magnitude,
        modes_hz,
    })
}

crate::tagged::tagged_enum! {
    tag = "kind", rename_all = "camelCase", mirror = path_spec_serde;
    /// A toolpath as written in a corner spec (`{ kind, … }`; mm).
    #[derive(Debug, Clone, PartialEq)]
    pub enum PathSpec {
        /// `{ kind: "square", sideMm }`: a square from the origin, counter-clockwise
        /// ([`crate::corner::square`]).
        #[serde(rename_all = "camelCase")]
        Square {
            /// Side (mm, > 0).
            side_mm: f64,
        },
        /// `{ kind: "ringingTower", sideMm?, thicknessMm? }`: the outline of Klipper's ringing
        /// test model, an L of two walls (default 120 mm long, 8 mm thick;
        /// [`crate::corner::ringing_tower`]).
        #[serde(rename_all = "camelCase")]
        RingingTower {
            /// Length of each wall (mm, default 120).
            #[serde(default = "tower_side")]
            side_mm: f64,
            /// Thickness of each wall (mm, default 8, less than `sideMm`).
            #[serde(default = "tower_thickness")]
            thickness_mm: f64,
        },
    }
}

fn tower_side() -> f64 {
    120.0
}

fn tower_thickness() -> f64 {
    8.0
}

fn klipper_scv() -> f64 {
    5.0
}

impl PathSpec {
    /// The path's points (mm); errors name `sideMm`, `thicknessMm`.
    pub fn points(&self) -> Result<Vec<[f64; 2]>> {
        match *self {
            PathSpec::Square { side_mm } => crate::corner::square(side_mm),
            PathSpec::RingingTower {
                side_mm,
                thickness_mm,
            } => crate::corner::ringing_tower(side_mm, thickness_mm),
        }
    }
}

/// One axis of a corner spec: its modes and, optionally, its shaper.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct CornerAxisSpec {
    /// The axis's modes (`[{ frequencyHz, damping?, participation? }]`).
    pub modes: Vec<PlantModeSpec>,
    /// The shaper to design (`{ family, modes?, … }`; default modes: the axis's); or give
    /// `impulses`, or neither (the axis runs unshaped in the shaped print too).
    #[serde(default)]
    pub shaper: Option<ShaperRequest>,
    /// An explicit shaper (`[{ time, amplitude }]`).
    #[serde(default)]
    pub impulses: Option<Vec<Impulse>>,
}

/// Everything [`corner_for`] needs, as written in JSON (mm, s).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct CornerSpec {
    /// The toolpath.
    pub path: PathSpec,
    /// Top speed along the path (mm/s).
    pub velocity: f64,
    /// Acceleration along the path (mm/s²).
    pub accel: f64,
    /// Klipper's `square_corner_velocity` (mm/s, default 5 as in Klipper).
    #[serde(default = "klipper_scv")]
    pub square_corner_velocity: f64,
    /// The X axis.
    pub x: CornerAxisSpec,
    /// The Y axis.
    pub y: CornerAxisSpec,
    /// Sample period (s); default: a 25th of the fastest mode's period, at most 1 ms, made
    /// longer if the print would need more than [`CORNER_SAMPLES`] samples.
    #[serde(default)]
    pub sample_period_s: Option<f64>,
    /// Time simulated after the path ends (s, default 0.05).
    #[serde(default)]
    pub settle_s: Option<f64>,
    /// When given, each print also carries its track with the deviation magnified this many
    /// times (`drawn`, [`crate::corner::Print::magnified`]).
    #[serde(default)]
    pub magnify: Option<f64>,
}

/// Most samples the default sample period of a corner spec gives.
pub const CORNER_SAMPLES: usize = 20_000;

/// One simulated print, as [`corner_for`] returns it.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct PrintResult {
    /// Times, nozzle, deviation and the corners' numbers.
    #[serde(flatten)]
    pub print: crate::corner::Print,
    /// The track with the deviation magnified `magnify` times (mm; X, Y), when asked for.
    pub drawn: Option<[Vec<f64>; 2]>,
}

/// The result of [`corner_for`].
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct CornerResult {
    /// The planned segments (junction speeds, trapezoid times).
    pub segments: Vec<crate::corner::Segment>,
    /// Time the path ends (s).
    pub duration: f64,
    /// Sample period used (s).
    pub sample_period_s: f64,
    /// The print with both axes unshaped.
    pub unshaped: PrintResult,
    /// The print with each axis shaped by its shaper (when either axis has one).
    pub shaped: Option<PrintResult>,
    /// X's shaper.
    pub shaper_x: Option<ShaperData>,
    /// Y's shaper.
    pub shaper_y: Option<ShaperData>,
}

/// A corner spec made ready to print: the plan, the axes' plants and shapers, the sampling.
pub struct CornerSetup {
    /// The planned path.
    pub plan: crate::corner::Plan,
    /// X's and Y's plants.
    pub plants: [crate::plant::ModalPlant; 2],
    /// X's and Y's shapers from the spec.
    pub shapers: [Option<Shaper>; 2],
    /// Sample period (s).
    pub sample_period: f64,
    /// Time simulated after the path ends (s).
    pub settle: f64,
    /// The magnification of the drawn track, if asked for.
    pub magnify: Option<f64>,
}

impl CornerSetup {
    /// Validates and plans `spec` (errors named from its root) and designs its shapers.
    pub fn new(spec: &CornerSpec) -> Result<Self> {
        use crate::corner::{plan, MotionLimits};
        use crate::plant::ModalPlant;
        let points = spec.path.points().map_err(|e| e.within("path"))?;
        let limits = MotionLimits {
            velocity: spec.velocity,
            accel: spec.accel,
            square_corner_velocity: spec.square_corner_velocity,
        };
        let planned = plan(&points, &limits)?;
        let axis = |a: &CornerAxisSpec, name: &str| -> Result<(ModalPlant, Option<Shaper>)> {
            let plant = ModalPlant::from_spec(&a.modes).map_err(|e| e.within(name))?;
            let shaper = resolve_shaper(&a.shaper, &a.impulses, || Ok(plant.modes().to_vec()))
                .map_err(|e| e.within(name))?;
            Ok((plant, shaper))
        };
        let (px, sx) = axis(&spec.x, "x")?;
        let (py, sy) = axis(&spec.y, "y")?;
        let settle = spec.settle_s.unwrap_or(0.05);
        finite("settleS", settle)?;
        if settle < 0.0 {
            return Err(Error::invalid(
                "settleS",
                format!("must be ≥ 0 s, got {settle}"),
            ));
        }
        let total = planned.duration() + settle;
        let sample_period = match spec.sample_period_s {
            Some(t) => positive("samplePeriodS", t)?,
            None => {
                let fastest = px
                    .modes()
                    .iter()
                    .chain(py.modes())
                    .map(Mode::frequency_hz)
                    .fold(0.0_f64, f64::max);
                (1.0 / (25.0 * fastest))
                    .min(1e-3)
                    .max(total / (CORNER_SAMPLES - 1) as f64)
            }
        };
        sample_count(sample_period, total).map_err(|e| match e {
            Error::TooLarge { value, limit, .. } => Error::TooLarge {
                field: "samplePeriodS".into(),
                value,
                limit,
            },
            other => other,
        })?;
        let magnify = spec.magnify.map(|m| positive("magnify", m)).transpose()?;
        Ok(CornerSetup {
            plan: planned,
            plants: [px, py],
            shapers: [sx, sy],
            sample_period,
            settle,
            magnify,
        })
    }

    /// The print with X shaped by `x` and Y by `y` (`None`: unshaped).
    pub fn print(&self, x: Option<&Shaper>, y: Option<&Shaper>) -> Result<PrintResult> {
        use crate::corner::{corner, Axis};
        let axes = [
            Axis {
                plant: &self.plants[0],
                shaper: x,
            },
            Axis {
                plant: &self.plants[1],
                shaper: y,
            },
        ];
        let print = corner(&self.plan, axes, self.sample_period, self.settle)?;
        let drawn = self
            .magnify
            .map(|m| print.magnified(&self.plan, m))
            .transpose()?;
        Ok(PrintResult { print, drawn })
    }

    /// The shaper `spec` designed for X's modes and for Y's (errors named `x.…`, `y.…`).
    pub fn design_per_axis(&self, spec: &ShaperSpec) -> Result<[Shaper; 2]> {
        let x = design_for(spec, self.plants[0].modes()).map_err(|e| e.within("x"))?;
        let y = design_for(spec, self.plants[1].modes()).map_err(|e| e.within("y"))?;
        Ok([x, y])
    }
}

/// Plans a corner spec's path, designs each axis's shaper, and prints the path unshaped and
/// shaped ([`crate::corner`]). Errors name the field from the spec's root (`path.sideMm`,
/// `x.modes[0].frequencyHz`, `y.shaper.family`, `squareCornerVelocity`).
pub fn corner_for(spec: &CornerSpec) -> Result<CornerResult> {
    let setup = CornerSetup::new(spec)?;
    let [sx, sy] = &setup.shapers;
    let unshaped = setup.print(None, None)?;
    let shaped = if sx.is_some() || sy.is_some() {
        Some(setup.print(sx.as_ref(), sy.as_ref())?)
    } else {
        None
    };
    Ok(CornerResult {
        duration: setup.plan.duration(),
        sample_period_s: setup.sample_period,
        unshaped,
        shaped,
        shaper_x: sx.as_ref().map(Shaper::to_data),
        shaper_y: sy.as_ref().map(Shaper::to_data),
        segments: setup.plan.segments,
    })
}
