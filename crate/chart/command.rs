//! The command chart: position, velocity and acceleration of the reference command (grey) and
//! of each shaped command (series colours), one panel each, against time.
//!
//! The signals are those the simulation applied to the plant's base, at its samples. A step's
//! velocity and acceleration are impulses and do not show on a sampled axis (they read as 0);
//! the impulse chart shows what the shaper makes of them.

use super::{decimate, padded_range, render_error, swatch, time_series, ChartStyle, Legend};
use crate::error::Result;
use crate::simulate::Trajectory;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Draws the base position, velocity and acceleration of `unshaped` (the reference command) and
/// of each labelled shaped command, in three stacked panels sharing the time axis.
pub fn draw_command<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    unshaped: &Trajectory,
    shaped: &[(&str, &Trajectory)],
    style: &ChartStyle,
) -> Result<()> {
    area.fill(&WHITE).map_err(render_error)?;
    let (all, t_end) = time_series(("command", unshaped), shaped, style);
    let (width, _) = area.dim_in_pixel();
    let buckets = (width as usize).max(50);
    let titled = area
        .titled(
            "Command and shaped command",
            ("sans-serif", style.font(16.0)),
        )
        .map_err(render_error)?;
    let (_, h) = titled.dim_in_pixel();
    // The bottom panel also holds the time axis' title.
    let axis = style.px(20.0);
    let each = h.saturating_sub(axis) / 3;
    let (upper, lowest) = titled.split_vertically(2 * each);
    let (first, second) = upper.split_vertically(each);
    type Pick = fn(&Trajectory) -> &[f64];
    let panels: [(&DrawingArea<DB, Shift>, Pick, &str, usize); 3] = [
        (&first, |t| &t.base_position, "position", 0),
        (&second, |t| &t.base_velocity, "velocity", 1),
        (&lowest, |t| &t.base_acceleration, "acceleration", 2),
    ];
    for (panel, pick, y_desc, index) in panels {
        let last = index == 2;
        let (y_lo, y_hi) = padded_range(
            all.iter().flat_map(|(_, t, _)| pick(t).iter().copied()),
            0.08,
        );
        let mut chart = ChartBuilder::on(panel)
            .margin_left(style.px(10.0))
            .margin_right(style.px(14.0))
            .margin_top(style.px(4.0))
            .margin_bottom(style.px(2.0))
            .x_label_area_size(style.px(if last { 40.0 } else { 20.0 }))
            .y_label_area_size(style.px(60.0))
            .build_cartesian_2d(0.0..t_end, y_lo..y_hi)
            .map_err(render_error)?;
        let mut mesh = chart.configure_mesh();
        mesh.y_desc(y_desc)
            .label_style(("sans-serif", style.font(11.0)))
            .axis_desc_style(("sans-serif", style.font(12.0)))
            .light_line_style(RGBColor(238, 238, 238))
            .x_labels(6)
            .y_labels(3);
        if last {
            mesh.x_desc("time (s)");
        }
        mesh.draw().map_err(render_error)?;
        let mut keys = Legend::default();
        for (label, traj, color) in &all {
            let width = if *label == "command" { 1.5 } else { 2.0 };
            chart
                .draw_series(LineSeries::new(
                    decimate(&traj.time, pick(traj), buckets),
                    color.stroke_width(style.px(width)),
                ))
                .map_err(render_error)?;
            keys.push(*label, swatch(*color, style));
        }
        if index == 0 {
            keys.draw_compact(&chart, SeriesLabelPosition::LowerRight, style)?;
        }
    }
    area.present().map_err(render_error)?;
    Ok(())
}
