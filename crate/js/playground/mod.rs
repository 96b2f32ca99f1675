//! The playground frame (`renderPlayground`): one call draws everything a page frame shows.
//! In four stages, each in its file:
//!
//! 1. `state`: the state the page sends, parsed and checked once into a typed `Frame`
//!    (the canvases collected once too);
//! 2. `analysis`: the designs and everything that depends only on them and the analysis
//!    settings, kept between frames;
//! 3. `simulation`: the unshaped and shaped moves on the simulated plant, their metrics and
//!    spectra;
//! 4. `draw`: the charts.
//!
//! Nothing is drawn unless everything computed, so a bad input leaves the last good charts on
//! screen.

mod analysis;
mod draw;
mod simulation;
mod state;

use super::api::{js_error, serialized};
use crate::error::Error;
use crate::metrics::Metrics;
use crate::mode::Mode;
use crate::robustness::RobustnessRow;
use crate::shaper::ShaperData;
use crate::vibration;
use serde::Serialize;
use state::{Frame, ViewPlant};
use wasm_bindgen::prelude::*;

/// The simulation of a frame, without its samples (those are drawn, not returned).
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct SimulationSummary {
    mismatch: f64,
    plant: &'static str,
    plant_modes_hz: Vec<f64>,
    /// The simulated plant's damping ratios (the model's unless `view.actualDamping` gives them).
    plant_damping: Vec<f64>,
    duration: f64,
    sample_period: f64,
    samples: usize,
    unshaped: Metrics,
}

/// One shaper's entry of the result: its analysis (kept between frames) and its move's metrics
/// (this frame's), the keys in the order they always had.
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct ResultOut<'a> {
    label: &'a str,
    family: &'static str,
    #[serde(serialize_with = "crate::js::bulk::serialize_shaper")]
    shaper: &'a ShaperData,
    sensitivity: &'a vibration::SensitivityCurve,
    insensitivity: &'a [vibration::Insensitivity],
    residual_at_modes: &'a [f64],
    centroid_delay: Option<f64>,
    klipper: &'a Option<crate::smoothing::KlipperFigures>,
    /// Metrics of the shaped move on the simulated (mismatched) plant.
    simulation: &'a Metrics,
    sampled: &'a Option<analysis::SampledFigures>,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct PlaygroundResult<'a> {
    /// One entry per compared shaper, in order.
    results: Vec<ResultOut<'a>>,
    // The first shaper's figures, as the single-shaper page had them.
    #[serde(serialize_with = "crate::js::bulk::serialize_shaper")]
    shaper: &'a ShaperData,
    sensitivity: &'a vibration::SensitivityCurve,
    insensitivity: &'a [vibration::Insensitivity],
    residual_at_modes: &'a [f64],
    centroid_delay: Option<f64>,
    /// The simulated move: plant, window and the unshaped command's metrics.
    simulation: SimulationSummary,
    /// Singhose 2009 Fig. 11 for mode 1: every parameterless family designed for it.
    robustness: Vec<RobustnessRow>,
    /// Index of the shaper the map shows.
    map_shaper: usize,
    /// Upper damping ratio of V(ζ) and the map.
    damping_to: f64,
}

/// `renderPlayground(state, canvases)`: everything one frame of the page needs, in one call.
///
/// `state = { modes, shapers: [{ family, …parameters }] (1 … 4; or `shaper` for one),
/// designed?: [shaper | null] (shapers designed elsewhere, by index),
/// view: { fromHz, toHz, points, vtol, scv, pixelRatio, mismatch, modeMismatch, actualDamping,
/// command, plant, samples,
/// duration, mapShaper, seriesColors, mapFrequencyPoints, mapDampingPoints, dampingTo, dampingPoints,
/// spectrumPoints } }` (README, "JavaScript API"); `canvases = { impulses?, sensitivity?,
/// damping?, map?, response?, command?, spectrum?, robustness? }` (HTMLCanvasElements).
/// Designs every shaper, computes its sensitivity curve (at the first mode's damping),
/// insensitivity and residual vibration at each mode and Klipper's smoothing figures, simulates
/// the unshaped and every shaped move on the plant with the mismatched modes, and draws the
/// charts overlaid. Returns `{ results: [{ label, family, shaper, sensitivity, insensitivity,
/// residualAtModes, centroidDelay, klipper: { smoothing, maxAccel }, simulation }],
/// simulation: { mismatch, plant, plantModesHz, plantDamping, duration, samplePeriod, samples,
/// unshaped },
/// robustness, mapShaper, dampingTo, …the first result's fields }`. Errors name the field
/// (`shapers[1].vtol`, `modes[0].damping`, `view.vtol`, `view.mismatch`, `view.modeMismatch[1]`,
/// `view.command.maxVelocity`). Nothing is drawn unless everything computed, so a bad input
/// leaves the last good charts on screen.
#[wasm_bindgen(js_name = renderPlayground, unchecked_return_type = "PlaygroundResult")]
pub fn render_playground(
    #[wasm_bindgen(unchecked_param_type = "PlaygroundState")] state: JsValue,
    #[wasm_bindgen(unchecked_optional_param_type = "PlaygroundCanvases | null")] canvases: JsValue,
) -> Result<JsValue, JsValue> {
    frame(state, &canvases).map_err(js_error)
}

/// One frame: read, analyse, simulate, draw, report.
fn frame(state: JsValue, canvases: &JsValue) -> Result<JsValue, Error> {
    let frame = Frame::parse(state, canvases)?;
    let analysis = analysis::analysis(&frame)?;
    let sim = simulation::simulate(&frame, &analysis)?;
    let robustness = analysis::robustness_rows(&frame.modes[0], frame.view.vtol)
        .map_err(|e| e.within("view"))?;
    let spectra = simulation::command_spectra(&frame, &analysis, &sim.commands)?;
    draw::draw(
        &frame,
        &analysis,
        &sim,
        &draw::Extras {
            robustness: &robustness,
            spectra: spectra.as_ref(),
        },
    )?;
    let results: Vec<ResultOut<'_>> = analysis
        .results
        .iter()
        .zip(&sim.shaped_metrics)
        .map(|(r, m)| ResultOut {
            label: &r.label,
            family: r.family,
            shaper: &r.shaper,
            sensitivity: &r.sensitivity,
            insensitivity: &r.insensitivity,
            residual_at_modes: &r.residual_at_modes,
            centroid_delay: r.centroid_delay,
            klipper: &r.klipper,
            simulation: m,
            sampled: &r.sampled,
        })
        .collect();
    let first = &analysis.results[0];
    serialized(&PlaygroundResult {
        shaper: &first.shaper,
        sensitivity: &first.sensitivity,
        insensitivity: &first.insensitivity,
        residual_at_modes: &first.residual_at_modes,
        centroid_delay: first.centroid_delay,
        simulation: SimulationSummary {
            mismatch: frame.view.mismatch,
            plant: match frame.view.plant {
                ViewPlant::Modal => "modal",
                ViewPlant::TwoMass(_) => "twoMass",
                ViewPlant::Pendulum { .. } => "pendulum",
            },
            plant_modes_hz: sim.plant_modes.iter().map(Mode::frequency_hz).collect(),
            plant_damping: sim.plant_modes.iter().map(Mode::damping).collect(),
            duration: sim.duration,
            sample_period: sim.sample_period,
            samples: frame.samples,
            unshaped: sim.unshaped_metrics,
        },
        robustness,
        map_shaper: frame.view.map_shaper,
        damping_to: frame.damping_to,
        results,
    })
}
