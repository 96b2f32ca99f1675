//! The impulse-sequence chart: each impulse as a stem from 0 to its amplitude at its time.

use super::{render_error, ChartStyle, Key, Legend};
use crate::error::Result;
use crate::shaper::Shaper;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Draws the impulse sequences of one or more labelled shapers (overlaid, one colour each).
pub fn draw_impulses<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    shapers: &[(&str, &Shaper)],
    style: &ChartStyle,
) -> Result<()> {
    area.fill(&WHITE).map_err(render_error)?;
    let t_max = shapers
        .iter()
        .map(|(_, s)| s.duration())
        .fold(0.0_f64, f64::max);
    let t_max = if t_max > 0.0 {
        t_max.min(super::AXIS_LIMIT)
    } else {
        1.0
    };
    let (a_min, a_max) = shapers
        .iter()
        .flat_map(|(_, s)| s.impulses().iter().map(|imp| imp.amplitude))
        .map(|a| a.clamp(-super::AXIS_LIMIT, super::AXIS_LIMIT))
        .fold((0.0_f64, 0.0_f64), |(lo, hi), a| (lo.min(a), hi.max(a)));
    let pad = 0.12 * (a_max - a_min).max(1e-9);
    let x_pad = 0.06 * t_max;
    let mut chart = super::framed(area, "Impulse sequence", 52.0, style)
        .build_cartesian_2d(-x_pad..t_max + x_pad, (a_min - pad).min(0.0)..a_max + pad)
        .map_err(render_error)?;
    super::mesh(&mut chart, "time (s)", "amplitude", style)
        .draw()
        .map_err(render_error)?;
    chart
        .draw_series(LineSeries::new(
            [(-x_pad, 0.0), (t_max + x_pad, 0.0)],
            BLACK.stroke_width(style.px(1.0)),
        ))
        .map_err(render_error)?;
    let mut keys = Legend::default();
    let n = shapers.len().max(1) as f64;
    for (k, (label, shaper)) in shapers.iter().enumerate() {
        let color = style.color(k);
        // Offset overlaid series slightly so coincident stems stay visible.
        let dx = if n > 1.0 {
            (k as f64 - (n - 1.0) / 2.0) * 0.012 * t_max
        } else {
            0.0
        };
        let stroke = color.stroke_width(style.px(2.5));
        chart
            .draw_series(shaper.impulses().iter().map(|imp| {
                PathElement::new(
                    vec![
                        (imp.time.min(t_max) + dx, 0.0),
                        (
                            imp.time.min(t_max) + dx,
                            super::clip(imp.amplitude, a_min, a_max),
                        ),
                    ],
                    stroke,
                )
            }))
            .map_err(render_error)?;
        keys.push(label.to_string(), Key::line(color.stroke_width(3)));
        let r = style.px(4.0);
        chart
            .draw_series(shaper.impulses().iter().map(|imp| {
                let at = (
                    imp.time.min(t_max) + dx,
                    super::clip(imp.amplitude, a_min, a_max),
                );
                Circle::new(at, r, color.filled())
            }))
            .map_err(render_error)?;
    }
    if shapers.len() > 1 {
        keys.draw_default(&chart, SeriesLabelPosition::UpperRight, style)?;
    }
    area.present().map_err(render_error)?;
    Ok(())
}
