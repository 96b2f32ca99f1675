//! The simulated move of a frame: the reference and every shaped command on the simulated
//! (mismatched) plant, their metrics, and the commands' spectra.

use super::analysis::{own_move, Analysis};
use super::state::Frame;
use crate::command::Command;
use crate::design::ShaperSpec;
use crate::error::Error;
use crate::metrics::Metrics;
use crate::mode::Mode;
use crate::piecewise::{Knot, Piecewise, ORDER};
use crate::shaper::Shaper;
use crate::simulate::Trajectory;

/// The responses of a frame.
pub(super) struct Simulation {
    /// The command each compared shaper sends.
    pub commands: Vec<Command>,
    /// The response to the reference command, and its metrics.
    pub unshaped: Trajectory,
    pub unshaped_metrics: Metrics,
    /// The response to each shaper's command (its metrics go to the shaper's result).
    pub shaped: Vec<Trajectory>,
    /// The simulated plant's modes.
    pub plant_modes: Vec<Mode>,
    pub duration: f64,
    pub sample_period: f64,
}

/// Simulates the reference and every shaped command; writes each shaped move's metrics into
/// `analysis.results`.
pub(super) fn simulate(frame: &Frame, analysis: &mut Analysis) -> Result<Simulation, Error> {
    let command = &frame.command;
    let commands = frame
        .specs
        .iter()
        .zip(&analysis.shapers)
        .map(|(spec, shaper)| shaped_command(spec, shaper, command))
        .collect::<Result<Vec<_>, _>>()?;
    let plant_modes = frame.plant.modes()?;
    let slowest = plant_modes
        .iter()
        .map(Mode::damped_period_s)
        .fold(0.0_f64, f64::max);
    let end = commands
        .iter()
        .map(Command::end_time)
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
        move_metrics(&unshaped, command, command).map_err(|e| e.within("view"))?;
    let mut shaped = Vec::with_capacity(commands.len());
    for (k, c) in commands.iter().enumerate() {
        // The reference shaped by a shaper: simulated from the shaper's convolution factors
        // (the same response to rounding, without a knot per impulse of the expanded shaper).
        let t = if own_move(&frame.specs[k]) || !matches!(command, Command::Piecewise(_)) {
            sim(c)?
        } else {
            crate::simulate::simulate_shaped(
                &frame.plant,
                command,
                &analysis.shapers[k],
                sample_period,
                duration,
            )
            .map_err(|e| e.within("view"))?
        };
        let force = c != command && analysis.shapers[k].centroid_delay().is_none();
        let reference = if force { c } else { command };
        analysis.results[k].simulation =
            Some(move_metrics(&t, c, reference).map_err(|e| e.within("view"))?);
        shaped.push(t);
    }
    Ok(Simulation {
        commands,
        unshaped,
        unshaped_metrics,
        shaped,
        plant_modes,
        duration,
        sample_period,
    })
}

/// |U(f)| of the reference command, and of each shaped command on the same grid.
pub(super) type Spectra = (crate::spectrum::Spectrum, Vec<Vec<f64>>);

/// The command spectra, if the spectrum is drawn: |U(f)| of the reference and of each shaped
/// command.
pub(super) fn command_spectra(
    frame: &Frame,
    analysis: &Analysis,
    commands: &[Command],
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
        .map(|(s, c)| match s {
            Some(s) if matches!(frame.command, Command::Piecewise(_)) => Ok(s
                .iter()
                .zip(&unshaped.magnitude)
                .map(|(a, b)| a * b)
                .collect()),
            _ => one(c).map(|s| s.magnitude),
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

/// Metrics of a simulated move. The per-mode residuals (`modeResidualPercent`) are left out:
/// the page does not show them and they cost a second simulation per move.
fn move_metrics(
    traj: &Trajectory,
    applied: &Command,
    reference: &Command,
) -> Result<Metrics, Error> {
    crate::metrics::metrics(traj, applied, reference)
}
