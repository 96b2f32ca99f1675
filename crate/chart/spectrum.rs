//! The command spectrum chart: |U(f)| of the unshaped command (grey) and of each shaped command
//! (series colours), with the model's modes marked by solid lines and the actual (mismatched)
//! modes by dashed ones — a shaped command should have (almost) no content at the modes
//! (Veciana & Cardona 2011 §2).

use super::{render_error, swatch, ChartStyle, Legend, Linear, UNSHAPED_COLOR};
use crate::error::{Error, Result};
use plotters::coord::Shift;
use plotters::prelude::*;

/// Draws `unshaped` and each labelled `shaped` magnitude against `frequency_hz` (all the same
/// length), a solid marker at each of `modes_hz` (the model) and a dashed one at each of
/// `actual_hz` (the plant, when it differs). The magnitudes are those of the command's
/// velocity (the page's choice: compactly supported for rest-to-rest moves, and a shaped
/// step's is the shaper's own spectrum). Non-finite magnitudes are skipped.
pub fn draw_spectrum<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    frequency_hz: &[f64],
    unshaped: &[f64],
    shaped: &[(&str, &[f64])],
    modes_hz: &[f64],
    actual_hz: &[f64],
    style: &ChartStyle,
) -> Result<()> {
    let n = frequency_hz.len();
    if n < 2 || unshaped.len() != n || shaped.iter().any(|(_, m)| m.len() != n) {
        return Err(Error::invalid(
            "spectrum",
            "needs at least 2 frequencies and one magnitude per frequency in every series",
        ));
    }
    area.fill(&WHITE).map_err(render_error)?;
    let (f_lo, f_hi) = (frequency_hz[0], frequency_hz[n - 1]);
    let (f_lo, f_hi) = if f_lo < f_hi {
        (f_lo, f_hi)
    } else {
        (0.0, 1.0)
    };
    let top = std::iter::once(unshaped)
        .chain(shaped.iter().map(|(_, m)| *m))
        .flat_map(|m| m.iter().copied())
        .filter(|v| v.is_finite())
        .fold(0.0_f64, f64::max);
    let top = if top > 0.0 { top * 1.08 } else { 1.0 };
    let mut chart = super::framed(area, "Command spectrum |U(f)| (velocity)", 60.0, style)
        .margin_right(style.px(14.0))
        .build_cartesian_2d(f_lo..f_hi, 0.0..top)
        .map_err(render_error)?;
    super::mesh(&mut chart, "frequency (Hz)", "|U(f)|", style)
        .draw()
        .map_err(render_error)?;
    let mut keys = Legend::default();
    draw_mode_markers(&mut chart, modes_hz, actual_hz, &mut keys, style)?;
    let all = std::iter::once(("unshaped", unshaped, UNSHAPED_COLOR)).chain(
        shaped
            .iter()
            .enumerate()
            .map(|(k, (l, m))| (*l, *m, style.color(k))),
    );
    for (label, magnitude, color) in all {
        chart
            .draw_series(LineSeries::new(
                frequency_hz
                    .iter()
                    .zip(magnitude)
                    .filter(|(_, v)| v.is_finite())
                    .map(|(&f, &v)| (f, v)),
                color.stroke_width(style.px(if label == "unshaped" { 1.5 } else { 2.0 })),
            ))
            .map_err(render_error)?;
        keys.push(label, swatch(color, style));
    }
    keys.draw_compact(&chart, SeriesLabelPosition::UpperRight, style)?;
    area.present().map_err(render_error)?;
    Ok(())
}

/// Full-height markers within the frequency axis: solid grey at `modes_hz` (the model),
/// dashed red at each of `actual_hz` that is not a model mode; one legend entry for each kind
/// drawn.
fn draw_mode_markers<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Linear>,
    modes_hz: &[f64],
    actual_hz: &[f64],
    keys: &mut Legend,
    style: &ChartStyle,
) -> Result<()> {
    let (x_range, y_range) = (chart.x_range(), chart.y_range());
    let (f_lo, f_hi, top) = (x_range.start, x_range.end, y_range.end);
    let marker = RGBColor(90, 90, 90);
    let inside = |f: &&f64| (f_lo..=f_hi).contains(*f);
    let mut first = true;
    for &f in modes_hz.iter().filter(inside) {
        chart
            .draw_series(LineSeries::new(
                [(f, 0.0), (f, top)],
                marker.stroke_width(style.px(1.0)),
            ))
            .map_err(render_error)?;
        if std::mem::take(&mut first) {
            keys.push("model modes", swatch(marker, style));
        }
    }
    let actual = RGBColor(200, 30, 30);
    let differs = |a: f64| !modes_hz.iter().any(|m| (m - a).abs() <= 1e-9 * m.abs());
    let mut first = true;
    for &f in actual_hz.iter().filter(inside).filter(|a| differs(**a)) {
        chart
            .draw_series(DashedLineSeries::new(
                [(f, 0.0), (f, top)],
                style.px(6.0),
                style.px(4.0),
                actual.stroke_width(style.px(1.5)),
            ))
            .map_err(render_error)?;
        if std::mem::take(&mut first) {
            keys.push("actual modes", swatch(actual, style));
        }
    }
    Ok(())
}
