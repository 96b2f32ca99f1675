//! The damping sensitivity chart: residual vibration V (in %) against the plant's damping ratio
//! at a fixed frequency, with the tolerable level Vtol and the modelled damping marked.

use super::{render_error, ChartStyle, Key, Legend};
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
    area.fill(&WHITE).map_err(render_error)?;
    let (z_lo, z_hi) = super::finite_range(
        curves.iter().flat_map(|(_, c)| c.damping.iter().copied()),
        (0.0, 1.0),
    );
    let vtol = super::drawable_vtol(vtol);
    let v_max = curves
        .iter()
        .flat_map(|(_, c)| c.vibration.iter().copied())
        .filter(|v| v.is_finite())
        .fold(vtol.unwrap_or(0.0), f64::max)
        .clamp(1e-3, super::AXIS_LIMIT)
        * 100.0
        * 1.06;
    let mut chart = ChartBuilder::on(area)
        .caption("Residual vibration V(ζ)", ("sans-serif", style.font(16.0)))
        .margin(style.px(10.0))
        .x_label_area_size(style.px(40.0))
        .y_label_area_size(style.px(52.0))
        .build_cartesian_2d(z_lo..z_hi, 0.0..v_max)
        .map_err(render_error)?;
    chart
        .configure_mesh()
        .x_desc("damping ratio ζ")
        .y_desc("vibration (%)")
        .label_style(("sans-serif", style.font(12.0)))
        .axis_desc_style(("sans-serif", style.font(13.0)))
        .light_line_style(RGBColor(238, 238, 238))
        .draw()
        .map_err(render_error)?;
    let marker = RGBColor(120, 120, 120);
    for &z in modes_damping.iter().filter(|z| (z_lo..=z_hi).contains(*z)) {
        chart
            .draw_series(LineSeries::new(
                [(z, 0.0), (z, v_max)],
                marker.stroke_width(style.px(1.0)),
            ))
            .map_err(render_error)?;
    }
    let mut keys = Legend::default();
    if let Some(vtol) = vtol {
        let red = RGBColor(200, 30, 30);
        chart
            .draw_series(LineSeries::new(
                [(z_lo, vtol * 100.0), (z_hi, vtol * 100.0)],
                red.stroke_width(style.px(1.0)),
            ))
            .map_err(render_error)?;
        keys.push(
            format!("Vtol {:.3} %", vtol * 100.0),
            Key::line(red.stroke_width(2)),
        );
    }
    for (k, (label, curve)) in curves.iter().enumerate() {
        let color = style.color(k);
        chart
            .draw_series(LineSeries::new(
                curve
                    .damping
                    .iter()
                    .zip(&curve.vibration)
                    .filter(|(z, v)| z.is_finite() && v.is_finite())
                    .map(|(&z, &v)| {
                        (
                            super::clip(z, z_lo, z_hi),
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
