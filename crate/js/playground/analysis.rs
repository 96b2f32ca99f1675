//! The part of a frame that depends only on the designs and the analysis settings: the
//! designs, V(f), I(Vtol), Klipper's figures, V(ζ), the map and |S(f)|, kept between frames
//! ([`ANALYSIS`]), and the robustness table (kept per damping ratio and Vtol).

use super::state::Frame;
use crate::design::{self, ShaperSpec};
use crate::error::Error;
use crate::mode::{Mode, ModeSpec};
use crate::robustness::RobustnessRow;
use crate::shaper::{Shaper, ShaperData};
use crate::vibration;
use serde::Serialize;
use std::cell::RefCell;
use std::rc::Rc;

/// Everything the page shows about one shaper but the simulated move's metrics (the frame's
/// result adds those: `ResultOut` in `mod.rs`).
pub(super) struct ShaperResult {
    pub label: String,
    pub family: &'static str,
    pub shaper: ShaperData,
    pub sensitivity: vibration::SensitivityCurve,
    pub insensitivity: Vec<vibration::Insensitivity>,
    pub residual_at_modes: Vec<f64>,
    pub centroid_delay: Option<f64>,
    /// `None` (JS `null`) for shapers whose amplitudes sum to zero (bang-bang, on/off):
    /// Klipper's smoothing divides by that sum.
    pub klipper: Option<crate::smoothing::KlipperFigures>,
    /// A `sampled` shaper's cost report (Kamel, Lange & Hirzinger; `sampledReport` without the
    /// impulses); `None` for the other families and for a sampled shaper designed elsewhere (an
    /// amplitude or increment bound: its minimum-norm baseline needs the solver).
    pub sampled: Option<SampledFigures>,
}

/// The cost report of a `sampled` shaper on the page: `sampledReport`'s figures.
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct SampledFigures {
    /// τ of eq. 10, s.
    pub ramp_delay: f64,
    /// J_q (eq. 17) of the design.
    pub cost: design::sampled::Cost,
    /// J_q of the minimum-norm amplitudes under the same constraints.
    pub baseline_cost: design::sampled::Cost,
    /// 1 − cost.total / baselineCost.total.
    pub cost_reduction: f64,
}

/// The part of a frame that depends on the designs and the analysis settings only, not on the
/// simulated plant, the mismatch or the command: what [`ANALYSIS`] keeps between frames, shared
/// with the frames that take it (never copied: a six-mode frame's shapers hold ~20 000
/// impulses, twice).
pub(super) struct Analysis {
    /// Which computation this is (a counter): the same number on every frame that takes it
    /// from [`ANALYSIS`], so the charts drawn from it alone need not be drawn again.
    pub generation: u64,
    pub shapers: Vec<Shaper>,
    /// Per shaper, everything but the simulation's metrics.
    pub results: Vec<ShaperResult>,
    /// V(ζ) of every shaper at mode 1, if the damping chart is drawn.
    pub damping_curves: Option<Vec<vibration::DampingSensitivityCurve>>,
    /// The map of the chosen shaper, if the map is drawn.
    pub map: Option<vibration::SensitivityMap>,
    /// |S(f)| of every shaper on the spectrum's grid, if the spectrum is drawn (`None` for the
    /// families that make their own move, whose spectrum is the move's).
    pub impulse_spectra: Option<Vec<Option<Vec<f64>>>>,
}

/// Everything [`Analysis`] is computed from.
#[derive(Clone, PartialEq)]
struct AnalysisKey {
    specs: Vec<ShaperSpec>,
    /// The impulses of the shapers designed elsewhere (`PlaygroundState::designed`).
    designed: Vec<Option<Vec<crate::shaper::Impulse>>>,
    modes: Vec<ModeSpec>,
    /// vtol, scv, the V(f) range and points, the damping range and points, the map's shaper
    /// and resolution, the spectrum's points (floats as bits).
    numbers: [u64; 11],
    /// Which of the damping, map and spectrum charts are drawn.
    charts: [bool; 3],
}

thread_local! {
    /// The last frame's [`Analysis`] and its key. Dragging the mismatch, or editing the
    /// command or the plant, changes only the simulation: the designs, I(Vtol), V(f), V(ζ),
    /// the map and |S(f)| are taken from here instead of being recomputed every frame.
    static ANALYSIS: RefCell<Option<(AnalysisKey, Rc<Analysis>)>> = const { RefCell::new(None) };
    /// The last [`Analysis::generation`] handed out.
    static GENERATION: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// The designs and their analyses for a frame, from [`ANALYSIS`] when nothing they depend on
/// changed. Errors carry the same fields as when computed directly (they are never cached).
pub(super) fn analysis(frame: &Frame) -> Result<Rc<Analysis>, Error> {
    let key = AnalysisKey::of(frame);
    let cached = ANALYSIS.with_borrow(|c| {
        c.as_ref()
            .filter(|(k, _)| *k == key)
            .map(|(_, a)| Rc::clone(a))
    });
    if let Some(a) = cached {
        return Ok(a);
    }
    let (shapers, results) = designs(frame)?;
    let [damping_chart, map_chart, spectrum_chart] = frame.charts();
    let in_view = |e: Error| e.within("view");
    let generation = GENERATION.get() + 1;
    GENERATION.set(generation);
    let a = Rc::new(Analysis {
        generation,
        damping_curves: damping_chart
            .then(|| damping_curves(frame, &shapers))
            .transpose()
            .map_err(in_view)?,
        map: map_chart
            .then(|| map(frame, &shapers))
            .transpose()
            .map_err(in_view)?,
        impulse_spectra: spectrum_chart
            .then(|| impulse_spectra(frame, &shapers))
            .transpose()
            .map_err(in_view)?,
        shapers,
        results,
    });
    ANALYSIS.with_borrow_mut(|c| *c = Some((key, Rc::clone(&a))));
    Ok(a)
}

impl AnalysisKey {
    fn of(frame: &Frame) -> Self {
        let view = &frame.view;
        let options = &frame.sensitivity;
        AnalysisKey {
            specs: frame.specs.clone(),
            designed: frame
                .designed
                .iter()
                .map(|d| d.as_ref().map(|s| s.impulses().to_vec()))
                .collect(),
            modes: frame.mode_specs.clone(),
            numbers: [
                view.vtol.to_bits(),
                view.scv.to_bits(),
                options.from_hz.to_bits(),
                options.to_hz.to_bits(),
                options.points as u64,
                frame.damping_to.to_bits(),
                view.damping_points as u64,
                view.map_shaper as u64,
                view.map_frequency_points as u64,
                view.map_damping_points as u64,
                frame.spectrum.points as u64,
            ],
            charts: frame.charts(),
        }
    }
}

/// Every compared shaper, designed here or taken as designed elsewhere, with its figures (all
/// but the simulation's metrics).
fn designs(frame: &Frame) -> Result<(Vec<Shaper>, Vec<ShaperResult>), Error> {
    let (modes, view) = (&frame.modes, &frame.view);
    let in_view = |e: Error| e.within("view");
    let mut results = Vec::with_capacity(frame.specs.len());
    let mut shapers = Vec::with_capacity(frame.specs.len());
    for (k, spec) in frame.specs.iter().enumerate() {
        let at = |e: Error| e.within(&format!("shapers[{k}]"));
        let elsewhere = frame.designed.get(k).cloned().flatten();
        let shaper = match &elsewhere {
            Some(shaper) => shaper.clone(),
            None => design::design_for(spec, modes).map_err(at)?,
        };
        let sampled = match (spec, &elsewhere) {
            (ShaperSpec::Sampled(s), None) => {
                let r = design::sampled::report(modes, s).map_err(at)?;
                Some(SampledFigures {
                    ramp_delay: r.ramp_delay,
                    cost: r.cost,
                    baseline_cost: r.baseline_cost,
                    cost_reduction: r.cost_reduction,
                })
            }
            _ => None,
        };
        let curve = vibration::sensitivity(&shaper, &frame.sensitivity).map_err(in_view)?;
        let insensitivity =
            vibration::insensitivities(&shaper, modes, view.vtol).map_err(in_view)?;
        let klipper = match shaper.centroid_delay() {
            Some(_) => Some(crate::smoothing::klipper_figures(&shaper, view.scv).map_err(in_view)?),
            None => None,
        };
        results.push(ShaperResult {
            label: frame.labels[k].clone(),
            family: spec.name(),
            shaper: shaper.to_data(),
            sensitivity: curve,
            insensitivity,
            residual_at_modes: modes
                .iter()
                .map(|m| vibration::residual_vibration(&shaper, m))
                .collect(),
            centroid_delay: shaper.centroid_delay(),
            klipper,
            sampled,
        });
        shapers.push(shaper);
    }
    Ok((shapers, results))
}

/// V(ζ) of every shaper at mode 1.
fn damping_curves(
    frame: &Frame,
    shapers: &[Shaper],
) -> Result<Vec<vibration::DampingSensitivityCurve>, Error> {
    shapers
        .iter()
        .map(|s| {
            vibration::damping_sensitivity(
                s,
                &vibration::DampingSensitivityOptions {
                    frequency_hz: frame.modes[0].frequency_hz(),
                    from_damping: 0.0,
                    to_damping: frame.damping_to,
                    points: frame.view.damping_points,
                },
            )
        })
        .collect()
}

/// The frequency × damping map of the chosen shaper.
fn map(frame: &Frame, shapers: &[Shaper]) -> Result<vibration::SensitivityMap, Error> {
    vibration::sensitivity_map(
        &shapers[frame.view.map_shaper],
        &vibration::SensitivityMapOptions {
            from_hz: frame.sensitivity.from_hz,
            to_hz: frame.sensitivity.to_hz,
            frequency_points: frame.view.map_frequency_points,
            damping_from: 0.0,
            damping_to: frame.damping_to,
            damping_points: frame.view.map_damping_points,
        },
    )
}

/// |S(f)| of every shaper on the spectrum's grid (`None` for the families that make their own
/// move, whose spectrum is the move's).
fn impulse_spectra(frame: &Frame, shapers: &[Shaper]) -> Result<Vec<Option<Vec<f64>>>, Error> {
    frame
        .specs
        .iter()
        .zip(shapers)
        .map(|(spec, shaper)| {
            if own_move(spec) {
                return Ok(None);
            }
            crate::spectrum::impulse_spectrum(shaper, &frame.spectrum).map(|s| Some(s.magnitude))
        })
        .collect()
}

/// Whether a family makes its own move (bang-bang, on/off: a force profile, not a shaper of
/// the reference command).
pub(super) fn own_move(spec: &ShaperSpec) -> bool {
    matches!(spec, ShaperSpec::Bangbang { .. } | ShaperSpec::Onoff { .. })
}

thread_local! {
    /// The last robustness table and its key (mode 1's frequency and damping, Vtol, as bits):
    /// designing every family is the slowest part of a frame and only these inputs change it.
    static ROBUSTNESS: RefCell<Option<([u64; 2], Vec<RobustnessRow>)>> = const { RefCell::new(None) };
}

pub(super) fn robustness_rows(mode: &Mode, vtol: f64) -> Result<Vec<RobustnessRow>, Error> {
    // Every parameterless family designs a shaper whose impulse times scale with the mode's
    // period (at a fixed damping ratio), so the table's durations in periods and its
    // insensitivities (fractions of the frequency, and damping widths) depend on ζ and Vtol
    // only. The table is designed once per (ζ, Vtol) for a 1 Hz mode and the seconds are
    // rescaled, so editing a frequency does not redesign a dozen shapers every frame.
    let key = [mode.damping().to_bits(), vtol.to_bits()];
    let cached = ROBUSTNESS.with_borrow(|c| {
        c.as_ref()
            .filter(|(k, _)| *k == key)
            .map(|(_, r)| r.clone())
    });
    let rows = match cached {
        Some(rows) => rows,
        None => {
            let unit = Mode::new(1.0, mode.damping())?;
            // Families that cannot be designed for this mode (e.g. EI beyond its damping
            // range) are left out of the background rather than failing the frame. So is
            // `direct`: for one mode it is the ZVD shaper itself (tests/direct.rs,
            // one_mode_reproduces_zv_and_zvd_closed_forms), a second point on ZVD's, and its
            // design needs the solver, which the page's first module leaves out.
            let rows: Vec<RobustnessRow> = crate::robustness::parameterless_specs()
                .into_iter()
                .filter(|spec| !matches!(spec, ShaperSpec::Direct(_)))
                .filter_map(|spec| {
                    crate::robustness::robustness_table(std::slice::from_ref(&spec), &unit, vtol)
                        .ok()
                })
                .flatten()
                .collect();
            ROBUSTNESS.with_borrow_mut(|c| *c = Some((key, rows.clone())));
            rows
        }
    };
    let period = mode.damped_period_s();
    Ok(rows
        .into_iter()
        .map(|r| RobustnessRow {
            duration_s: r.duration_periods * period,
            ..r
        })
        .collect())
}
