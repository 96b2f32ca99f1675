//! The measured spectrum: a power spectral density in dB against frequency, with the detected
//! peaks (identified modes) marked and labelled.

use super::{render_error, ChartStyle};
use crate::error::{Error, Result};
use plotters::coord::Shift;
use plotters::prelude::*;

/// Most points drawn: longer spectra are reduced to the maximum of each bucket, so a peak is
/// never lost between pixels.
pub const MAX_DRAWN_POINTS: usize = 2000;

/// Caption and y-axis label of a Welch PSD.
pub const PSD_TITLES: (&str, &str) = ("Measured spectrum (Welch PSD)", "PSD (dB)");

/// Draws `psd` (linear units²/Hz, drawn as 10·log₁₀) against `frequency_hz` up to `max_hz`
/// (all of it if `None`), and a marker with a label at each `(frequency, label)` of `peaks`.
/// `titles` = (caption, y-axis label); the default is [`PSD_TITLES`].
///
/// Errors: `frequency_hz` and `psd` of different lengths or empty.
pub fn draw_measured_spectrum<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    frequency_hz: &[f64],
    psd: &[f64],
    peaks: &[(f64, String)],
    max_hz: Option<f64>,
    titles: (&str, &str),
    style: &ChartStyle,
) -> Result<()> {
    if frequency_hz.len() != psd.len() || psd.is_empty() {
        return Err(Error::invalid(
            "spectrum",
            format!(
                "frequencyHz ({}) and psd ({}) must have the same, non-zero length",
                frequency_hz.len(),
                psd.len()
            ),
        ));
    }
    area.fill(&WHITE).map_err(render_error)?;
    let last = frequency_hz[frequency_hz.len() - 1];
    let f_hi = max_hz
        .filter(|f| f.is_finite() && *f > 0.0)
        .unwrap_or(last)
        .min(last)
        .max(1e-9);
    let f_lo = frequency_hz[0].min(f_hi * 0.999);
    let db = |p: f64| 10.0 * p.max(1e-300).log10();
    let shown: Vec<(f64, f64)> = frequency_hz
        .iter()
        .zip(psd)
        .filter(|(f, p)| **f <= f_hi && p.is_finite())
        .map(|(&f, &p)| (f, db(p)))
        .collect();
    let bucket = shown.len().div_ceil(MAX_DRAWN_POINTS).max(1);
    let points: Vec<(f64, f64)> = shown
        .chunks(bucket)
        .filter_map(|c| {
            c.iter()
                .copied()
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(_, v)| (c[c.len() / 2].0, v))
        })
        .collect();
    let (mut y_lo, mut y_hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.1), hi.max(p.1))
        });
    if !(y_lo.is_finite() && y_hi.is_finite()) {
        (y_lo, y_hi) = (-1.0, 1.0);
    }
    // At most 120 dB below the top, so a zero bin does not flatten the chart.
    y_lo = y_lo.max(y_hi - 120.0);
    let pad = 0.08 * (y_hi - y_lo).max(1.0);
    let mut chart = ChartBuilder::on(area)
        .caption(titles.0, ("sans-serif", style.font(16.0)))
        .margin(style.px(10.0))
        .x_label_area_size(style.px(40.0))
        .y_label_area_size(style.px(56.0))
        .build_cartesian_2d(f_lo..f_hi, (y_lo - pad)..(y_hi + 2.0 * pad))
        .map_err(render_error)?;
    chart
        .configure_mesh()
        .x_desc("frequency (Hz)")
        .y_desc(titles.1)
        .label_style(("sans-serif", style.font(12.0)))
        .axis_desc_style(("sans-serif", style.font(13.0)))
        .light_line_style(RGBColor(238, 238, 238))
        .draw()
        .map_err(render_error)?;
    let color = style.color(0);
    chart
        .draw_series(LineSeries::new(
            points.iter().map(|&(f, v)| (f, v.max(y_lo - pad))),
            color.stroke_width(style.px(1.5)),
        ))
        .map_err(render_error)?;
    let mark = RGBColor(213, 94, 0);
    let level = |f: f64| {
        let i = frequency_hz.partition_point(|&x| x < f).min(psd.len() - 1);
        let lo = i.saturating_sub(2);
        let hi = (i + 3).min(psd.len());
        psd[lo..hi].iter().copied().fold(0.0, f64::max)
    };
    for (f, label) in peaks.iter().filter(|(f, _)| (f_lo..=f_hi).contains(f)) {
        let y = db(level(*f)).max(y_lo - pad);
        chart
            .draw_series(LineSeries::new(
                [(*f, y_lo - pad), (*f, y_hi + 2.0 * pad)],
                mark.mix(0.5).stroke_width(style.px(1.0)),
            ))
            .map_err(render_error)?;
        chart
            .draw_series(std::iter::once(Circle::new(
                (*f, y),
                style.px(5.0),
                mark.stroke_width(style.px(2.0)),
            )))
            .map_err(render_error)?;
        chart
            .draw_series(std::iter::once(Text::new(
                label.clone(),
                (*f, y_hi + 1.5 * pad),
                ("sans-serif", style.font(12.0)).into_font().color(&mark),
            )))
            .map_err(render_error)?;
    }
    area.present().map_err(render_error)?;
    Ok(())
}
