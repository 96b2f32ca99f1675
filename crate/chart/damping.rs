//! The damping sensitivity chart: residual vibration V (in %) against the plant's damping ratio
//! at a fixed frequency, with the tolerable level Vtol and the modelled damping marked.

use super::curves::{draw_vibration_curves, Axis};
use super::ChartStyle;
use crate::error::Result;
use crate::vibration::DampingSensitivityCurve;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Draws damping sensitivity curves (one per labelled shaper), a horizontal line at `vtol`
/// (fraction) and a vertical marker at each damping ratio in `modes_damping`.
pub fn draw_damping_sensitivity<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    curves: &[(&str, &DampingSensitivityCurve)],
    vtol: Option<f64>,
    modes_damping: &[f64],
    style: &ChartStyle,
) -> Result<()> {
    let curves: Vec<(&str, &[f64], &[f64])> = curves
        .iter()
        .map(|(label, c)| (*label, c.damping.as_slice(), c.vibration.as_slice()))
        .collect();
    let axis = Axis {
        caption: "Residual vibration V(ζ)",
        x_desc: "damping ratio ζ",
    };
    draw_vibration_curves(area, &curves, vtol, modes_damping, &axis, style)
}
