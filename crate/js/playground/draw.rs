//! The drawing of a frame: every chart whose canvas the page gave, from the frame's typed
//! input, its analysis and its simulation. Nothing here computes what a chart shows.

use super::analysis::Analysis;
use super::simulation::{Simulation, Spectra};
use super::state::{Frame, ViewPlant};
use crate::chart;
use crate::error::Error;
use crate::js::canvas::Canvas;
use crate::mode::Mode;
use crate::robustness::RobustnessRow;
use crate::shaper::Shaper;
use crate::simulate::Trajectory;
use crate::vibration;
use plotters::prelude::*;
use web_sys::HtmlCanvasElement;

/// What the charts show besides the frame, its analysis and its simulation.
pub(super) struct Extras<'a> {
    pub robustness: &'a [RobustnessRow],
    pub spectra: Option<&'a Spectra>,
}

fn backend(canvas: &Option<HtmlCanvasElement>) -> Option<Canvas> {
    canvas.clone().and_then(Canvas::new)
}

/// The charts drawn from the analysis alone (impulses, V(f), V(ζ), the map, robustness).
const ANALYSIS_CHARTS: usize = 5;

/// What an analysis chart was last drawn from: the analysis' generation, the canvas (the same
/// element, at the same size) and the style.
#[derive(PartialEq)]
struct Drawn {
    generation: u64,
    canvas: HtmlCanvasElement,
    size: (u32, u32),
    scale: u64,
    colors: [(u8, u8, u8); 4],
}

thread_local! {
    /// Per analysis chart, what it shows now (`None` after a failed or partial drawing).
    static DRAWN: std::cell::RefCell<[Option<Drawn>; ANALYSIS_CHARTS]> =
        const { std::cell::RefCell::new([None, None, None, None, None]) };
}

/// The backend for analysis chart `slot` on `canvas`, or `None` when the canvas already shows
/// this analysis in this style (a mismatch, command or plant edit leaves those charts as they
/// are; a resized canvas is cleared, so its size is part of the check). `done(slot)` records
/// it once drawn.
fn analysis_backend(
    slot: usize,
    canvas: &Option<HtmlCanvasElement>,
    frame: &Frame,
    analysis: &Analysis,
) -> Option<Canvas> {
    let element = canvas.as_ref()?;
    let drawn = Drawn {
        generation: analysis.generation,
        canvas: element.clone(),
        size: (element.width(), element.height()),
        scale: frame.style.scale.to_bits(),
        colors: frame.style.colors.map(|c| (c.0, c.1, c.2)),
    };
    let same = DRAWN.with_borrow_mut(|d| {
        let same = d[slot].as_ref() == Some(&drawn);
        if !same {
            d[slot] = None;
        }
        same
    });
    if same {
        return None;
    }
    let backend = backend(canvas);
    PENDING.with_borrow_mut(|p| p[slot] = backend.is_some().then_some(drawn));
    backend
}

thread_local! {
    /// What each analysis chart is being drawn from, until the frame's drawing succeeded.
    static PENDING: std::cell::RefCell<[Option<Drawn>; ANALYSIS_CHARTS]> =
        const { std::cell::RefCell::new([None, None, None, None, None]) };
}

/// Records the analysis charts drawn in this frame (once every chart drew).
fn analysis_charts_done() {
    PENDING.with_borrow_mut(|p| {
        DRAWN.with_borrow_mut(|d| {
            for (d, p) in d.iter_mut().zip(p.iter_mut()) {
                if let Some(p) = p.take() {
                    *d = Some(p);
                }
            }
        })
    });
}

/// Draws every chart the frame has a canvas for.
pub(super) fn draw(
    frame: &Frame,
    analysis: &Analysis,
    sim: &Simulation,
    extras: &Extras<'_>,
) -> Result<(), Error> {
    PENDING.with_borrow_mut(|p| p.iter_mut().for_each(|x| *x = None));
    analysis_charts(frame, analysis)?;
    simulation_charts(frame, sim, extras.spectra)?;
    if let Some(b) = analysis_backend(4, &frame.canvases.robustness, frame, analysis) {
        let period = frame.modes[0].damped_period_s();
        let marks: Vec<chart::RobustnessMark<'_>> = analysis
            .results
            .iter()
            .map(|r| chart::RobustnessMark {
                label: r.label.as_str(),
                duration_periods: r.shaper.duration / period,
                insensitivity: r.insensitivity[0].width,
            })
            .collect();
        chart::draw_robustness(
            &b.into_drawing_area(),
            extras.robustness,
            &marks,
            frame.view.vtol,
            &frame.style,
        )?;
    }
    analysis_charts_done();
    Ok(())
}

/// The impulses, V(f), V(ζ) and the map.
fn analysis_charts(frame: &Frame, analysis: &Analysis) -> Result<(), Error> {
    let (modes, style, vtol) = (&frame.modes, &frame.style, Some(frame.view.vtol));
    let named = |i: usize| frame.labels[i].as_str();
    if let Some(b) = analysis_backend(0, &frame.canvases.impulses, frame, analysis) {
        let series: Vec<(&str, &Shaper)> = analysis
            .shapers
            .iter()
            .enumerate()
            .map(|(i, s)| (named(i), s))
            .collect();
        chart::draw_impulses(&b.into_drawing_area(), &series, style)?;
    }
    if let Some(b) = analysis_backend(1, &frame.canvases.sensitivity, frame, analysis) {
        let series: Vec<(&str, &vibration::SensitivityCurve)> = analysis
            .results
            .iter()
            .map(|r| (r.label.as_str(), &r.sensitivity))
            .collect();
        let modes_hz: Vec<f64> = modes.iter().map(Mode::frequency_hz).collect();
        chart::draw_sensitivity(&b.into_drawing_area(), &series, vtol, &modes_hz, style)?;
    }
    if let (Some(b), Some(curves)) = (
        analysis_backend(2, &frame.canvases.damping, frame, analysis),
        &analysis.damping_curves,
    ) {
        let series: Vec<(&str, &vibration::DampingSensitivityCurve)> = curves
            .iter()
            .enumerate()
            .map(|(i, c)| (named(i), c))
            .collect();
        let zetas: Vec<f64> = modes.iter().map(Mode::damping).collect();
        chart::draw_damping_sensitivity(&b.into_drawing_area(), &series, vtol, &zetas, style)?;
    }
    if let (Some(b), Some(map)) = (
        analysis_backend(3, &frame.canvases.map, frame, analysis),
        &analysis.map,
    ) {
        let marks: Vec<(f64, f64)> = modes
            .iter()
            .map(|m| (m.frequency_hz(), m.damping()))
            .collect();
        chart::draw_sensitivity_map_with(
            &b.into_drawing_area(),
            map,
            vtol,
            &marks,
            style,
            chart::MapCells::Bitmap,
        )?;
    }
    Ok(())
}

/// The response, the command and its spectrum.
fn simulation_charts(
    frame: &Frame,
    sim: &Simulation,
    spectra: Option<&Spectra>,
) -> Result<(), Error> {
    let style = &frame.style;
    let named = |i: usize| frame.labels[i].as_str();
    let traj_series: Vec<(&str, &Trajectory)> = sim
        .shaped
        .iter()
        .enumerate()
        .map(|(i, t)| (named(i), t))
        .collect();
    if let Some(b) = backend(&frame.canvases.response) {
        let plant_name = match frame.view.plant {
            ViewPlant::Modal => "",
            ViewPlant::TwoMass(_) => ", two-mass spring",
            ViewPlant::Pendulum { hoist: None, .. } => ", nonlinear pendulum",
            ViewPlant::Pendulum { hoist: Some(_), .. } => ", nonlinear pendulum, hoisted",
        };
        let round = |x: f64| (x * 1e4).round() / 1e4;
        let caption = if frame.view.mode_mismatch.is_empty() && frame.view.actual_damping.is_empty()
        {
            format!(
                "Simulated response (actual f = model × {}{plant_name})",
                round(frame.view.mismatch)
            )
        } else {
            // Per-mode mismatch: the actual modes themselves (their ζ in the page's note).
            let modes: Vec<String> = sim
                .plant_modes
                .iter()
                .map(|m| round(m.frequency_hz()).to_string())
                .collect();
            format!(
                "Simulated response (actual modes {} Hz{plant_name})",
                modes.join(", ")
            )
        };
        chart::draw_response(
            &b.into_drawing_area(),
            &sim.unshaped,
            &traj_series,
            &caption,
            style,
        )?;
    }
    if let Some(b) = backend(&frame.canvases.command) {
        chart::draw_command(&b.into_drawing_area(), &sim.unshaped, &traj_series, style)?;
    }
    if let (Some(b), Some((u, shaped))) = (backend(&frame.canvases.spectrum), spectra) {
        let series: Vec<(&str, &[f64])> = shaped
            .iter()
            .enumerate()
            .map(|(i, s)| (named(i), s.as_slice()))
            .collect();
        let modes_hz: Vec<f64> = frame.modes.iter().map(Mode::frequency_hz).collect();
        let actual_hz: Vec<f64> = sim.plant_modes.iter().map(Mode::frequency_hz).collect();
        chart::draw_spectrum(
            &b.into_drawing_area(),
            &u.frequency_hz,
            &u.magnitude,
            &series,
            &modes_hz,
            &actual_hz,
            style,
        )?;
    }
    Ok(())
}
