//! What the two residual-vibration charts share: V (in %) against one variable (frequency,
//! damping ratio), one curve per shaper, with the tolerable level Vtol and the modes marked.

use super::{render_error, ChartStyle, Key, Legend};
use crate::error::Result;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

/// The chart's words: its caption and its x axis.
pub(super) struct Axis {
    pub caption: &'static str,
    pub x_desc: &'static str,
}

/// Draws curves (label, x, V as a fraction), a horizontal line at `vtol` (fraction) and a
/// vertical marker at each x in `marks`. Here `f` names the x variable, whichever it is.
pub(super) fn draw_vibration_curves<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    curves: &[(&str, &[f64], &[f64])],
    vtol: Option<f64>,
    marks: &[f64],
    axis: &Axis,
    style: &ChartStyle,
) -> Result<()> {
    area.fill(&WHITE).map_err(render_error)?;
    let (f_lo, f_hi) = super::finite_range(
        curves.iter().flat_map(|(_, x, _)| x.iter().copied()),
        (0.0, 1.0),
    );
    let vtol = super::drawable_vtol(vtol);
    let v_max = v_axis_max(curves.iter().flat_map(|(_, _, v)| v.iter().copied()), vtol);
    let mut chart = super::framed(area, axis.caption, 52.0, style)
        .build_cartesian_2d(f_lo..f_hi, 0.0..v_max)
        .map_err(render_error)?;
    super::mesh(&mut chart, axis.x_desc, "vibration (%)", style)
        .draw()
        .map_err(render_error)?;
    let mut keys = marks_and_vtol(&mut chart, marks, vtol, (f_lo, f_hi), v_max, style)?;
    for (k, (label, x, v)) in curves.iter().enumerate() {
        let color = style.color(k);
        chart
            .draw_series(LineSeries::new(
                x.iter()
                    .zip(v.iter())
                    .filter(|(f, v)| f.is_finite() && v.is_finite())
                    .map(|(&f, &v)| {
                        (
                            super::clip(f, f_lo, f_hi),
                            super::clip(v * 100.0, 0.0, v_max),
                        )
                    }),
                color.stroke_width(style.px(2.0)),
            ))
            .map_err(render_error)?;
        keys.push(label.to_string(), Key::line(color.stroke_width(3)));
    }
    keys.draw_default(&chart, SeriesLabelPosition::UpperRight, style)?;
    area.present().map_err(render_error)?;
    Ok(())
}

/// The top of a vibration axis in %: the largest finite V (fraction) or Vtol, 6 % headroom.
pub(super) fn v_axis_max(vibrations: impl Iterator<Item = f64>, vtol: Option<f64>) -> f64 {
    vibrations
        .filter(|v| v.is_finite())
        .fold(vtol.unwrap_or(0.0), f64::max)
        .clamp(1e-3, super::AXIS_LIMIT)
        * 100.0
        * 1.06
}

/// A grey vertical marker at each x in `marks` within `(f_lo, f_hi)` and a red line at `vtol`
/// (fraction) on a V (%) chart; returns the legend with Vtol's key.
pub(super) fn marks_and_vtol<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    marks: &[f64],
    vtol: Option<f64>,
    (f_lo, f_hi): (f64, f64),
    v_max: f64,
    style: &ChartStyle,
) -> Result<Legend> {
    let marker = RGBColor(120, 120, 120);
    for &f in marks.iter().filter(|f| (f_lo..=f_hi).contains(*f)) {
        chart
            .draw_series(LineSeries::new(
                [(f, 0.0), (f, v_max)],
                marker.stroke_width(style.px(1.0)),
            ))
            .map_err(render_error)?;
    }
    let mut keys = Legend::default();
    if let Some(vtol) = vtol {
        let red = RGBColor(200, 30, 30);
        chart
            .draw_series(LineSeries::new(
                [(f_lo, vtol * 100.0), (f_hi, vtol * 100.0)],
                red.stroke_width(style.px(1.0)),
            ))
            .map_err(render_error)?;
        keys.push(
            format!("Vtol {:.3} %", vtol * 100.0),
            Key::line(red.stroke_width(2)),
        );
    }
    Ok(keys)
}
