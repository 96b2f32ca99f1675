//! The sensitivity chart: residual vibration V (in %) against frequency, with the tolerable
//! level Vtol and the modes marked (Singhose 2009 Fig. 7).

use super::curves::{draw_vibration_curves, Axis};
use super::ChartStyle;
use crate::error::Result;
use crate::vibration::SensitivityCurve;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Draws sensitivity curves (one per labelled shaper), a horizontal line at `vtol` (fraction)
/// and a vertical marker at each frequency in `modes_hz`.
pub fn draw_sensitivity<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    curves: &[(&str, &SensitivityCurve)],
    vtol: Option<f64>,
    modes_hz: &[f64],
    style: &ChartStyle,
) -> Result<()> {
    let curves: Vec<(&str, &[f64], &[f64])> = curves
        .iter()
        .map(|(label, c)| (*label, c.frequency_hz.as_slice(), c.vibration.as_slice()))
        .collect();
    let axis = Axis {
        caption: "Residual vibration V(f)",
        x_desc: "frequency (Hz)",
    };
    draw_vibration_curves(area, &curves, vtol, modes_hz, &axis, style)
}
