//! The simulated move of a frame: the reference and every shaped command on the simulated
//! (mismatched) plant, their metrics, and the commands' spectra.

use super::analysis::{own_move, Analysis};
use super::state::Frame;
use crate::command::Command;
use crate::design::ShaperSpec;
use crate::error::Error;
use crate::metrics::{CommandFigures, Metrics};
use crate::mode::Mode;
use crate::piecewise::{Knot, Piecewise, ORDER};
use crate::shaper::Shaper;
use crate::simulate::Trajectory;
use std::cell::RefCell;

/// The responses of a frame.
pub(super) struct Simulation {
    /// The command each compared shaper sends, where it is formed ([`formed`]).
    pub commands: Vec<Option<Command>>,
    /// The response to the reference command, and its metrics.
    pub unshaped: Trajectory,
    pub unshaped_metrics: Metrics,
    /// The response to each shaper's command, and its metrics.
    pub shaped: Vec<Trajectory>,
    pub shaped_metrics: Vec<Metrics>,
    /// The simulated plant's modes.
    pub plant_modes: Vec<Mode>,
    pub duration: f64,
    pub sample_period: f64,
}

/// Simulates the reference and every shaped command, with each move's metrics.
pub(super) fn simulate(frame: &Frame, analysis: &Analysis) -> Result<Simulation, Error> {
    let command = &frame.command;
    let commands = frame
        .specs
        .iter()
        .zip(&analysis.shapers)
        .map(|(spec, shaper)| formed(spec, command).then(|| shaped_command(spec, shaper, command)))
        .map(Option::transpose)
        .collect::<Result<Vec<_>, _>>()?;
    let figures = command_figures(frame, analysis, &commands)?;
    let plant_modes = frame.plant.modes()?;
    let slowest = plant_modes
        .iter()
        .map(Mode::damped_period_s)
        .fold(0.0_f64, f64::max);
    let end = figures
        .iter()
        .map(|f| f.move_end)
        .fold(command.end_time(), f64::max);
    // Checked in range when the frame was read.
    let duration = match frame.view.duration {
        Some(d) => d,
        None => (end + 3.0 * slowest).max(1e-3),
    };
    let sample_period = duration / (frame.samples - 1) as f64;
    let sim = |c: &Command| {
        crate::simulate::simulate(&frame.plant, c, sample_period, duration)
            .map_err(|e| e.within("view"))
    };
    let unshaped = sim(command)?;
    let unshaped_metrics =
        crate::metrics::metrics(&unshaped, command, command).map_err(|e| e.within("view"))?;
    let mut shaped = Vec::with_capacity(commands.len());
    let mut shaped_metrics = Vec::with_capacity(commands.len());
    for (k, c) in commands.iter().enumerate() {
        // The reference shaped by a shaper: simulated from the shaper's convolution factors
        // (the same response to rounding, without a knot per impulse of the expanded shaper).
        let t = match c {
            Some(c) => sim(c)?,
            None => crate::simulate::simulate_shaped(
                &frame.plant,
                command,
                &analysis.shapers[k],
                sample_period,
                duration,
            )
            .map_err(|e| e.within("view"))?,
        };
        // A shaper whose amplitudes sum to 0 (the force-profile moves, or such a custom
        // shaper) moves to somewhere else than the reference: its own command is its reference.
        let zero_sum = analysis.shapers[k].centroid_delay().is_none();
        let own = match c {
            Some(c) if zero_sum => Some(c.clone()),
            None if zero_sum => Some(shaped_command(
                &frame.specs[k],
                &analysis.shapers[k],
                command,
            )?),
            _ => None,
        };
        shaped_metrics.push(
            crate::metrics::metrics_with(&t, &figures[k], own.as_ref().unwrap_or(command))
                .map_err(|e| e.within("view"))?,
        );
        shaped.push(t);
    }
    Ok(Simulation {
        commands,
        unshaped,
        unshaped_metrics,
        shaped,
        shaped_metrics,
        plant_modes,
        duration,
        sample_period,
    })
}

/// Whether the command a shaper sends is formed: for the families that make their own move,
/// and for a sampled reference (shaped by the streaming filter). A piecewise reference shaped
/// by a shaper is not: its response comes from the shaper's factors, its figures from its
/// knots as they are merged, its spectrum from the product |S(f)|·|U(f)|.
fn formed(spec: &ShaperSpec, command: &Command) -> bool {
    own_move(spec) || !matches!(command, Command::Piecewise(_))
}

thread_local! {
    /// The shaped commands' own figures (end, peaks) of the last frame, with the analysis
    /// ([`Analysis::generation`]) and the reference command they are of: an edit of the plant,
    /// the mismatch or the window changes the responses only, and a six-mode ZV-D³'s
    /// trapezoid has 62 500 knots to walk.
    static FIGURES: RefCell<Option<(u64, Command, Vec<CommandFigures>)>> = const { RefCell::new(None) };
}

/// The figures of every shaper's command, from [`FIGURES`] when the designs and the reference
/// are the last frame's.
fn command_figures(
    frame: &Frame,
    analysis: &Analysis,
    commands: &[Option<Command>],
) -> Result<Vec<CommandFigures>, Error> {
    let key = analysis.generation;
    let cached = FIGURES.with_borrow(|c| {
        c.as_ref()
            .filter(|(g, reference, _)| *g == key && *reference == frame.command)
            .map(|(_, _, f)| f.clone())
    });
    if let Some(f) = cached {
        return Ok(f);
    }
    let figures = commands
        .iter()
        .zip(&analysis.shapers)
        .map(|(c, shaper)| {
            let f = match (c, &frame.command) {
                (Some(c), _) => CommandFigures::of(c),
                (None, Command::Piecewise(p)) => CommandFigures::of_shaped(p, shaper),
                (None, reference) => reference
                    .shaped(shaper)
                    .and_then(|c| CommandFigures::of(&c)),
            };
            f.map_err(|e| e.within("view.command"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    FIGURES.with_borrow_mut(|c| *c = Some((key, frame.command.clone(), figures.clone())));
    Ok(figures)
}

/// |U(f)| of the reference command, and of each shaped command on the same grid.
pub(super) type Spectra = (crate::spectrum::Spectrum, Vec<Vec<f64>>);

/// The command spectra, if the spectrum is drawn: |U(f)| of the reference and of each shaped
/// command.
pub(super) fn command_spectra(
    frame: &Frame,
    analysis: &Analysis,
    commands: &[Option<Command>],
) -> Result<Option<Spectra>, Error> {
    let Some(impulse_spectra) = &analysis.impulse_spectra else {
        return Ok(None);
    };
    let one = |c: &Command| {
        crate::spectrum::command_spectrum(c, &frame.spectrum).map_err(|e| e.within("view"))
    };
    let unshaped = one(&frame.command)?;
    // A piecewise command shaped by a shaper is their convolution, so its transform is the
    // product: |U_s(f)| = |S(f)|·|U(f)| exactly, at O(impulses) per frequency instead of
    // O(knots). Force-profile moves and sampled commands (shaped by the streaming filter) are
    // transformed directly.
    let shaped = impulse_spectra
        .iter()
        .zip(commands)
        .enumerate()
        .map(|(k, (s, c))| match (s, c) {
            (Some(s), _) if matches!(frame.command, Command::Piecewise(_)) => Ok(s
                .iter()
                .zip(&unshaped.magnitude)
                .map(|(a, b)| a * b)
                .collect()),
            (_, Some(c)) => one(c).map(|s| s.magnitude),
            // Not formed for the simulation: formed here.
            (_, None) => shaped_command(&frame.specs[k], &analysis.shapers[k], &frame.command)
                .and_then(|c| one(&c))
                .map(|s| s.magnitude),
        })
        .collect::<Result<Vec<Vec<f64>>, Error>>()?;
    Ok(Some((unshaped, shaped)))
}

/// The command a shaper sends: the reference shaped by it, or — for the force-profile families
/// (bang-bang, on/off), whose amplitudes sum to 0 — their own rest-to-rest move, with
/// acceleration `maxAcceleration` × (shaper ∗ unit step).
fn shaped_command(spec: &ShaperSpec, shaper: &Shaper, command: &Command) -> Result<Command, Error> {
    let force = match spec {
        ShaperSpec::Bangbang {
            max_acceleration, ..
        }
        | ShaperSpec::Onoff {
            max_acceleration, ..
        } => Some(*max_acceleration),
        _ => None,
    };
    match force {
        Some(a) => {
            let knots = shaper
                .impulses()
                .iter()
                .map(|imp| {
                    let mut jumps = [0.0; ORDER];
                    jumps[2] = a * imp.amplitude;
                    Knot {
                        time: imp.time,
                        jumps,
                    }
                })
                .collect();
            Ok(Command::Piecewise(Piecewise::new(knots)?))
        }
        None => command.shaped(shaper).map_err(|e| e.within("view.command")),
    }
}
