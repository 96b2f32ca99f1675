//! The measured spectrum: a power spectral density in dB against frequency, with the detected
//! peaks (identified modes) marked and labelled.

use super::{render_error, ChartStyle, Linear};
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
    let points = drawn_points(frequency_hz, psd, f_hi);
    let (y_lo, y_hi) = db_range(&points);
    // The plot's vertical range: a margin below, twice as much above for the peaks' labels.
    let pad = 0.08 * (y_hi - y_lo).max(1.0);
    let (bottom, top) = (y_lo - pad, y_hi + 2.0 * pad);
    let mut chart = super::framed(area, titles.0, 56.0, style)
        .build_cartesian_2d(f_lo..f_hi, bottom..top)
        .map_err(render_error)?;
    super::mesh(&mut chart, "frequency (Hz)", titles.1, style)
        .draw()
        .map_err(render_error)?;
    let color = style.color(0);
    chart
        .draw_series(LineSeries::new(
            points.iter().map(|&(f, v)| (f, v.max(bottom))),
            color.stroke_width(style.px(1.5)),
        ))
        .map_err(render_error)?;
    let level = |f: f64| {
        let i = frequency_hz.partition_point(|&x| x < f).min(psd.len() - 1);
        let lo = i.saturating_sub(2);
        let hi = (i + 3).min(psd.len());
        psd[lo..hi].iter().copied().fold(0.0, f64::max)
    };
    for (f, label) in peaks.iter().filter(|(f, _)| (f_lo..=f_hi).contains(f)) {
        let y = db(level(*f)).max(bottom);
        let label_y = y_hi + 1.5 * pad;
        draw_peak(&mut chart, *f, y, (bottom, top), label, label_y, style)?;
    }
    area.present().map_err(render_error)?;
    Ok(())
}

/// A PSD in dB.
fn db(p: f64) -> f64 {
    10.0 * p.max(1e-300).log10()
}

/// The points drawn, (frequency, dB) up to `f_hi`: at most [`MAX_DRAWN_POINTS`], each the
/// largest of its bucket (at the bucket's middle frequency), so no peak is lost.
fn drawn_points(frequency_hz: &[f64], psd: &[f64], f_hi: f64) -> Vec<(f64, f64)> {
    let shown: Vec<(f64, f64)> = frequency_hz
        .iter()
        .zip(psd)
        .filter(|(f, p)| **f <= f_hi && p.is_finite())
        .map(|(&f, &p)| (f, db(p)))
        .collect();
    let bucket = shown.len().div_ceil(MAX_DRAWN_POINTS).max(1);
    shown
        .chunks(bucket)
        .filter_map(|c| {
            c.iter()
                .copied()
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(_, v)| (c[c.len() / 2].0, v))
        })
        .collect()
}

/// The dB range of `points`, at most 120 dB below the top (so a zero bin does not flatten
/// the chart); (−1, 1) without points.
fn db_range(points: &[(f64, f64)]) -> (f64, f64) {
    let (mut y_lo, mut y_hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.1), hi.max(p.1))
        });
    if !(y_lo.is_finite() && y_hi.is_finite()) {
        (y_lo, y_hi) = (-1.0, 1.0);
    }
    y_lo = y_lo.max(y_hi - 120.0);
    (y_lo, y_hi)
}

/// A peak at `f`: a vertical line over `span` (bottom, top), a ring at level `y` (dB) and
/// `label` at height `label_y`.
fn draw_peak<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Linear>,
    f: f64,
    y: f64,
    span: (f64, f64),
    label: &str,
    label_y: f64,
    style: &ChartStyle,
) -> Result<()> {
    let mark = RGBColor(213, 94, 0);
    chart
        .draw_series(LineSeries::new(
            [(f, span.0), (f, span.1)],
            mark.mix(0.5).stroke_width(style.px(1.0)),
        ))
        .map_err(render_error)?;
    chart
        .draw_series(std::iter::once(Circle::new(
            (f, y),
            style.px(5.0),
            mark.stroke_width(style.px(2.0)),
        )))
        .map_err(render_error)?;
    chart
        .draw_series(std::iter::once(Text::new(
            label.to_string(),
            (f, label_y),
            ("sans-serif", style.font(12.0)).into_font().color(&mark),
        )))
        .map_err(render_error)?;
    Ok(())
}
