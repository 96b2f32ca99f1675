//! The printed-corner chart: the XY toolpath and the nozzle's track along it with the deviation
//! magnified, as a printed wall would show it, unshaped (grey) against each shaper (in its
//! colour) ([`crate::corner`], [`crate::corner::Print::magnified`]). Equal scales on X and Y, so a
//! corner looks like a corner.

use super::{render_error, swatch, ChartStyle, Legend, UNSHAPED_COLOR};
use crate::error::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

/// One drawn track: its label and its points (mm; X, Y), e.g. a print's `magnified` track.
pub type CornerTrack<'a> = (&'a str, &'a [Vec<f64>; 2]);

/// Colour of the nominal path.
pub const PATH_COLOR: RGBColor = RGBColor(200, 200, 200);

/// Draws the path `points` (mm) as a wide light-grey band, then the `unshaped` track in grey and
/// each of `tracks` in its series colour, on equal X and Y scales; `magnify` is named in the
/// caption. Non-finite points are dropped.
pub fn draw_corner<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    points: &[[f64; 2]],
    unshaped: Option<&[Vec<f64>; 2]>,
    tracks: &[CornerTrack<'_>],
    magnify: f64,
    style: &ChartStyle,
) -> Result<()> {
    area.fill(&WHITE).map_err(render_error)?;
    let all = || {
        points
            .iter()
            .map(|p| (p[0], p[1]))
            .chain(unshaped.into_iter().flat_map(pairs))
            .chain(tracks.iter().flat_map(|(_, t)| pairs(t)))
    };
    // Clamped to ±AXIS_LIMIT: a track magnified beyond reason still gets an axis plotters can map.
    let limit = |v: f64| v.clamp(-super::AXIS_LIMIT, super::AXIS_LIMIT);
    let (x_lo, x_hi) = super::padded_range(all().map(|p| limit(p.0)), 0.04);
    let (y_lo, y_hi) = super::padded_range(all().map(|p| limit(p.1)), 0.04);
    // Equal mm per pixel on both axes: widen the axis whose span per pixel is smaller.
    let (w, h) = area.dim_in_pixel();
    let (label_x, label_y) = (
        style.px(52.0) + 2 * style.px(10.0),
        style.px(40.0) + 2 * style.px(10.0),
    );
    let plot_w = (w.saturating_sub(label_x)).max(1) as f64;
    let plot_h = (h.saturating_sub(label_y + style.px(24.0))).max(1) as f64;
    let per_px = ((x_hi - x_lo) / plot_w).max((y_hi - y_lo) / plot_h);
    let widen = |lo: f64, hi: f64, px: f64| {
        let mid = 0.5 * (lo + hi);
        (mid - 0.5 * per_px * px, mid + 0.5 * per_px * px)
    };
    let (x_lo, x_hi) = widen(x_lo, x_hi, plot_w);
    let (y_lo, y_hi) = widen(y_lo, y_hi, plot_h);
    let caption = format!("nozzle track, deviation ×{}", fmt_factor(magnify));
    let mut chart = super::framed(area, caption, 52.0, style)
        .build_cartesian_2d(x_lo..x_hi, y_lo..y_hi)
        .map_err(render_error)?;
    super::mesh(&mut chart, "X (mm)", "Y (mm)", style)
        .draw()
        .map_err(render_error)?;
    let clip = |(x, y): (f64, f64)| (super::clip(x, x_lo, x_hi), super::clip(y, y_lo, y_hi));
    chart
        .draw_series(LineSeries::new(
            points.iter().map(|p| clip((p[0], p[1]))),
            PATH_COLOR.stroke_width(style.px(6.0)),
        ))
        .map_err(render_error)?;
    let mut keys = Legend::default();
    keys.push("path", swatch(PATH_COLOR, style));
    if let Some(t) = unshaped {
        chart
            .draw_series(LineSeries::new(
                pairs(t).map(clip),
                UNSHAPED_COLOR.stroke_width(style.px(1.5)),
            ))
            .map_err(render_error)?;
        keys.push("unshaped", swatch(UNSHAPED_COLOR, style));
    }
    for (k, (label, t)) in tracks.iter().enumerate() {
        let color = style.color(k);
        chart
            .draw_series(LineSeries::new(
                pairs(t).map(clip),
                color.stroke_width(style.px(1.5)),
            ))
            .map_err(render_error)?;
        keys.push(label.to_string(), swatch(color, style));
    }
    keys.draw_default(&chart, SeriesLabelPosition::UpperRight, style)?;
    area.present().map_err(render_error)?;
    Ok(())
}

fn pairs(t: &[Vec<f64>; 2]) -> impl Iterator<Item = (f64, f64)> + '_ {
    t[0].iter()
        .zip(&t[1])
        .map(|(&x, &y)| (x, y))
        .filter(|(x, y)| x.is_finite() && y.is_finite())
}

fn fmt_factor(m: f64) -> String {
    if m.is_finite() && m == m.round() && m.abs() < 1e9 {
        format!("{}", m as i64)
    } else {
        format!("{m:.3}")
    }
}
