//! The simulated response chart: the plant's endpoint under the unshaped command against the
//! shaped ones (top panel), and the deflection endpoint − base, where the vibration shows at
//! full scale (bottom panel).

use super::{decimate, padded_range, render_error, swatch, time_series, ChartStyle, Legend};
use crate::error::Result;
use crate::simulate::Trajectory;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Draws the endpoint position and the deflection (endpoint − base) of `unshaped` (grey) and of
/// each labelled shaped response (series colours) against time, under `caption` (e.g. the
/// mismatch "actual frequency = model × 1.2"). All trajectories should share the time axis of
/// `unshaped`; each is drawn against its own `time`.
pub fn draw_response<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    unshaped: &Trajectory,
    shaped: &[(&str, &Trajectory)],
    caption: &str,
    style: &ChartStyle,
) -> Result<()> {
    area.fill(&WHITE).map_err(render_error)?;
    let (all, t_end) = time_series(("unshaped", unshaped), shaped, style);
    let (width, _) = area.dim_in_pixel();
    let buckets = (width as usize).max(50);
    let titled = area
        .titled(caption, ("sans-serif", style.font(16.0)))
        .map_err(render_error)?;
    let (_, h) = titled.dim_in_pixel();
    let (top, bottom) = titled.split_vertically((f64::from(h) * 0.56).round() as u32);
    type Pick = fn(&Trajectory) -> &[f64];
    let panels: [(&DrawingArea<DB, Shift>, Pick, &str, bool); 2] = [
        (&top, |t| &t.endpoint, "endpoint", true),
        (&bottom, |t| &t.deflection, "deflection", false),
    ];
    for (panel, pick, y_desc, legend) in panels {
        let (y_lo, y_hi) = padded_range(
            all.iter().flat_map(|(_, t, _)| pick(t).iter().copied()),
            0.06,
        );
        let mut chart = ChartBuilder::on(panel)
            .margin_left(style.px(10.0))
            .margin_right(style.px(14.0))
            .margin_top(style.px(4.0))
            .margin_bottom(style.px(4.0))
            .x_label_area_size(style.px(if legend { 22.0 } else { 38.0 }))
            .y_label_area_size(style.px(60.0))
            .build_cartesian_2d(0.0..t_end, y_lo..y_hi)
            .map_err(render_error)?;
        let mut mesh = chart.configure_mesh();
        mesh.y_desc(y_desc)
            .label_style(("sans-serif", style.font(12.0)))
            .axis_desc_style(("sans-serif", style.font(13.0)))
            .light_line_style(RGBColor(238, 238, 238))
            .x_labels(6)
            .y_labels(6);
        if !legend {
            mesh.x_desc("time (s)");
        }
        mesh.draw().map_err(render_error)?;
        let mut keys = Legend::default();
        for (label, traj, color) in &all {
            let width = if *label == "unshaped" { 1.5 } else { 2.0 };
            chart
                .draw_series(LineSeries::new(
                    decimate(&traj.time, pick(traj), buckets),
                    color.stroke_width(style.px(width)),
                ))
                .map_err(render_error)?;
            keys.push(*label, swatch(*color, style));
        }
        if legend {
            keys.draw_compact(&chart, SeriesLabelPosition::LowerRight, style)?;
        }
    }
    area.present().map_err(render_error)?;
    Ok(())
}
