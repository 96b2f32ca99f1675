//! The measured frequency response as Klipper draws it (scripts/calibrate_shaper.py,
//! `plot_freq_response`): the power spectral densities of x, y, z and their sum on a linear
//! axis from 0 (Klipper: purple X+Y+Z, red X, green Y, blue Z), each candidate shaper's
//! vibration ratio V(f) on a second axis from 0 (Klipper: dashed, the selected one thicker), the
//! "acceptable vibrations" line (Klipper: light grey, max(PSD/f)·(f + 5)/33.3) and the PSD left
//! after the selected shaper, PSD·V (Klipper: cyan). The frequency axis runs from 0 to
//! `max_hz` (Klipper's `--max_freq`, default 200 Hz).
//!
//! Unlike Klipper's figure, the shapers carry no legend here: the page's table beside the
//! chart is their legend (each row has its curve's colour), and the legend inside the chart
//! names only the PSD curves.

use super::{decimate, render_error, swatch, ChartStyle, Legend, Linear};
use crate::error::{Error, Result};
use plotters::chart::DualCoordChartContext;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Colours of the shapers' curves, in order (matplotlib's default cycle, which Klipper's
/// figure uses for them).
pub const SHAPER_COLORS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Colours of the PSD curves: X+Y+Z, X, Y, Z, after the shaper, acceptable vibrations.
pub const PSD_COLORS: [RGBColor; 6] = [
    RGBColor(128, 0, 128),
    RGBColor(220, 0, 0),
    RGBColor(0, 128, 0),
    RGBColor(0, 0, 230),
    RGBColor(0, 170, 200),
    RGBColor(190, 190, 190),
];

/// Klipper's default upper end of the frequency axis, Hz (`--max_freq`).
pub const DEFAULT_MAX_HZ: f64 = 200.0;

/// Most points drawn per curve (a min–max decimation keeps each bucket's extremes).
const BUCKETS: usize = 1000;

/// One shaper's vibration ratio V(f) at the chart's frequencies.
#[derive(Debug, Clone, Copy)]
pub struct ShaperCurve<'a> {
    /// V at each frequency of the chart (0 … 1), as many values as frequencies.
    pub values: &'a [f64],
    /// Colour; `None`: the `k`-th of [`SHAPER_COLORS`] for the `k`-th curve.
    pub color: Option<RGBColor>,
    /// The selected shaper: drawn thicker, and its PSD·V drawn as "after shaper".
    pub selected: bool,
    /// Dotted rather than dashed (Klipper's smooth shapers; the page's curves read from a
    /// calibration file, as Klipper fitted them).
    pub dotted: bool,
}

/// What [`draw_klipper_chart`] draws.
#[derive(Debug, Clone, Default)]
pub struct KlipperChart<'a> {
    /// Bin frequencies, Hz, increasing.
    pub frequency_hz: &'a [f64],
    /// PSD of the sum of the axes (Klipper's `psd_xyz`), one per frequency.
    pub psd_sum: &'a [f64],
    /// PSD of x, y, z where known (a spectrum of one channel has none of them).
    pub psd_x: Option<&'a [f64]>,
    /// See `psd_x`.
    pub psd_y: Option<&'a [f64]>,
    /// See `psd_x`.
    pub psd_z: Option<&'a [f64]>,
    /// The shapers' curves.
    pub shapers: Vec<ShaperCurve<'a>>,
    /// PSD after the selected shaper; `None`: `psd_sum`·V of the selected curve, if any.
    pub after: Option<&'a [f64]>,
    /// Upper end of the frequency axis (default [`DEFAULT_MAX_HZ`], at most the last bin).
    pub max_hz: Option<f64>,
    /// Caption (default "Frequency response and shapers").
    pub title: Option<&'a str>,
}

/// The exponent of 10 the PSD axis' labels are divided by (Klipper's scientific tick format).
fn exponent(top: f64) -> i32 {
    if top.is_finite() && top > 0.0 {
        top.log10().floor() as i32
    } else {
        0
    }
}

/// Draws `chart` (see the module's documentation).
///
/// Errors: fewer than 2 frequencies, or a curve whose length is not the number of
/// frequencies (naming it).
pub fn draw_klipper_chart<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    chart: &KlipperChart<'_>,
    style: &ChartStyle,
) -> Result<()> {
    check_lengths(chart)?;
    area.fill(&WHITE).map_err(render_error)?;
    let f = chart.frequency_hz;
    let f_hi = axis_end(chart);
    let shown = f.partition_point(|&x| x <= f_hi).max(2).min(f.len());
    let fs = &f[..shown];
    let product = after_shaper(chart);
    let threshold = acceptable_vibrations(fs, chart.psd_sum);
    let curves = psd_curves(chart, shown, product.as_deref());
    let scales = Scales::new(chart, shown, f_hi, &curves, &threshold);
    let mut ctx = axes(area, chart, &scales, style)?;
    let mut keys = draw_psds(&mut ctx, fs, &curves, &threshold, scales.top, style)?;
    keys.push("acceptable vibrations", swatch(PSD_COLORS[5], style));
    draw_shapers(&mut ctx, chart, fs, scales.v_top, style)?;
    keys.draw_compact(&ctx, SeriesLabelPosition::UpperLeft, style)?;
    area.present().map_err(render_error)?;
    Ok(())
}

/// At least 2 frequencies, and every curve as long as the frequencies (the error names it).
fn check_lengths(chart: &KlipperChart<'_>) -> Result<()> {
    let n = chart.frequency_hz.len();
    if n < 2 {
        return Err(Error::invalid(
            "frequencyHz",
            "needs at least 2 frequencies",
        ));
    }
    let check = |name: &str, v: &[f64]| {
        if v.len() == n {
            Ok(())
        } else {
            Err(Error::invalid(
                name,
                format!("has {} values for {n} frequencies", v.len()),
            ))
        }
    };
    check("psdSum", chart.psd_sum)?;
    for (name, v) in [
        ("psdX", chart.psd_x),
        ("psdY", chart.psd_y),
        ("psdZ", chart.psd_z),
        ("after", chart.after),
    ] {
        if let Some(v) = v {
            check(name, v)?;
        }
    }
    for (k, s) in chart.shapers.iter().enumerate() {
        check(&format!("shapers[{k}].values"), s.values)?;
    }
    Ok(())
}

/// The upper end of the frequency axis: `max_hz` (default [`DEFAULT_MAX_HZ`]), at most the
/// last bin.
fn axis_end(chart: &KlipperChart<'_>) -> f64 {
    let f = chart.frequency_hz;
    let last = f[f.len() - 1];
    chart
        .max_hz
        .filter(|m| m.is_finite() && *m > 0.0)
        .unwrap_or(DEFAULT_MAX_HZ)
        .min(if last.is_finite() && last > 0.0 {
            last
        } else {
            1.0
        })
}

/// The PSD left after the selected shaper (Klipper: psd · best_shaper_vals): `after` if given,
/// else the sum's PSD times the selected curve, if any.
fn after_shaper(chart: &KlipperChart<'_>) -> Option<Vec<f64>> {
    chart.after.map(|a| a.to_vec()).or_else(|| {
        chart.shapers.iter().find(|s| s.selected).map(|s| {
            chart
                .psd_sum
                .iter()
                .zip(s.values)
                .map(|(p, v)| p * v)
                .collect()
        })
    })
}

/// Klipper's "acceptable vibrations" at `fs`: max over f > 0 of PSD/f, times (f + 5)/33.3.
fn acceptable_vibrations(fs: &[f64], psd_sum: &[f64]) -> Vec<f64> {
    let slope = fs
        .iter()
        .zip(psd_sum)
        .filter(|(f, p)| **f > 0.0 && p.is_finite())
        .map(|(f, p)| p / f)
        .fold(0.0_f64, f64::max);
    fs.iter().map(|f| slope * (f + 5.0) / 33.3).collect()
}

/// A PSD curve: label, values over the shown frequencies, colour, stroke width.
type PsdCurve<'a> = (&'a str, &'a [f64], RGBColor, f64);

/// The PSD curves over the first `shown` frequencies: the sum, x, y, z where known, and the
/// PSD after the selected shaper (`product`) if any.
fn psd_curves<'a>(
    chart: &KlipperChart<'a>,
    shown: usize,
    product: Option<&'a [f64]>,
) -> Vec<PsdCurve<'a>> {
    // The sum wider than the axes: on one axis's test it is nearly that axis's curve, drawn
    // over it, and still shows as a purple border.
    let mut curves: Vec<PsdCurve<'a>> =
        vec![("X+Y+Z", &chart.psd_sum[..shown], PSD_COLORS[0], 3.0)];
    for (label, v, color) in [
        ("X", chart.psd_x, PSD_COLORS[1]),
        ("Y", chart.psd_y, PSD_COLORS[2]),
        ("Z", chart.psd_z, PSD_COLORS[3]),
    ] {
        if let Some(v) = v {
            curves.push((label, &v[..shown], color, 1.2));
        }
    }
    if let Some(a) = product {
        curves.push(("after shaper", &a[..shown], PSD_COLORS[4], 1.5));
    }
    curves
}

/// The ranges of the chart's axes.
struct Scales {
    /// Upper end of the frequency axis, Hz.
    f_hi: f64,
    /// Top of the PSD axis.
    top: f64,
    /// The exponent of 10 the PSD labels are divided by.
    exponent: i32,
    /// Top of the vibration-ratio axis.
    v_top: f64,
}

impl Scales {
    /// The axes' ranges for the PSD `curves` and `threshold` and the shapers' values over the
    /// first `shown` frequencies.
    fn new(
        chart: &KlipperChart<'_>,
        shown: usize,
        f_hi: f64,
        curves: &[PsdCurve<'_>],
        threshold: &[f64],
    ) -> Scales {
        let top = curves
            .iter()
            .flat_map(|c| c.1.iter().copied())
            .chain(threshold.iter().copied())
            .filter(|v| v.is_finite())
            .fold(0.0_f64, f64::max)
            .min(super::AXIS_LIMIT);
        let top = if top > 0.0 { 1.05 * top } else { 1.0 };
        let v_top = chart
            .shapers
            .iter()
            .flat_map(|s| s.values[..shown].iter().copied())
            .filter(|v| v.is_finite())
            .fold(1.0_f64, f64::max)
            .min(10.0)
            * 1.05;
        Scales {
            f_hi,
            top,
            exponent: exponent(top),
            v_top,
        }
    }
}

/// The caption and both vertical axes: PSD on the left (labels in units of 10^exponent),
/// the shapers' vibration ratio on the right.
fn axes<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    chart: &KlipperChart<'_>,
    scales: &Scales,
    style: &ChartStyle,
) -> Result<DualCoordChartContext<'a, DB, Linear, Linear>> {
    let (f_hi, top, e) = (scales.f_hi, scales.top, scales.exponent);
    let mut ctx = super::framed(
        area,
        chart.title.unwrap_or("Frequency response and shapers"),
        56.0,
        style,
    )
    .right_y_label_area_size(style.px(50.0))
    .build_cartesian_2d(0.0..f_hi, 0.0..top)
    .map_err(render_error)?
    .set_secondary_coord(0.0..f_hi, 0.0..scales.v_top);
    let scale = 10f64.powi(e);
    let y_label = |v: &f64| {
        let x = v / scale;
        let r = (x * 100.0).round() / 100.0;
        format!("{r}")
    };
    let y_desc = if e == 0 {
        "power spectral density".to_string()
    } else {
        format!("power spectral density (×1e{e})")
    };
    super::mesh(&mut ctx, "frequency (Hz)", y_desc, style)
        .y_label_formatter(&y_label)
        .x_label_formatter(&|f| format!("{f:.0}"))
        .bold_line_style(RGBColor(200, 200, 200))
        .draw()
        .map_err(render_error)?;
    ctx.configure_secondary_axes()
        .y_desc("shaper vibration ratio")
        .label_style(("sans-serif", style.font(12.0)))
        .axis_desc_style(("sans-serif", style.font(13.0)))
        .draw()
        .map_err(render_error)?;
    Ok(ctx)
}

/// The acceptable-vibrations line, then the PSD curves (decimated, clipped to `top`); the
/// legend of the curves.
fn draw_psds<DB: DrawingBackend>(
    ctx: &mut DualCoordChartContext<'_, DB, Linear, Linear>,
    fs: &[f64],
    curves: &[PsdCurve<'_>],
    threshold: &[f64],
    top: f64,
    style: &ChartStyle,
) -> Result<Legend> {
    let y_clip = |v: f64| super::clip(v, 0.0, top);
    ctx.draw_series(LineSeries::new(
        fs.iter().zip(threshold).map(|(&f, &v)| (f, y_clip(v))),
        PSD_COLORS[5].stroke_width(style.px(1.5)),
    ))
    .map_err(render_error)?;
    let mut keys = Legend::default();
    for (label, values, color, width) in curves {
        let points = decimate(fs, values, BUCKETS);
        ctx.draw_series(LineSeries::new(
            points.into_iter().map(|(f, v)| (f, y_clip(v))),
            color.stroke_width(style.px(*width)),
        ))
        .map_err(render_error)?;
        keys.push(*label, swatch(*color, style));
    }
    Ok(keys)
}

/// The shapers' curves on the secondary axis, dashed (dotted for smooth shapers), the
/// selected one thicker and last, over the others.
fn draw_shapers<DB: DrawingBackend>(
    ctx: &mut DualCoordChartContext<'_, DB, Linear, Linear>,
    chart: &KlipperChart<'_>,
    fs: &[f64],
    v_top: f64,
    style: &ChartStyle,
) -> Result<()> {
    let v_clip = |v: f64| super::clip(v, 0.0, v_top);
    let mut order: Vec<usize> = (0..chart.shapers.len()).collect();
    order.sort_by_key(|&k| chart.shapers[k].selected);
    for k in order {
        let s = &chart.shapers[k];
        let color = s.color.unwrap_or(SHAPER_COLORS[k % SHAPER_COLORS.len()]);
        let points: Vec<(f64, f64)> = decimate(fs, &s.values[..fs.len()], BUCKETS)
            .into_iter()
            .map(|(f, v)| (f, v_clip(v)))
            .collect();
        let (dash, gap, width) = match (s.selected, s.dotted) {
            (true, _) => (10.0, 4.0, 2.5),
            (false, true) => (2.0, 3.0, 1.5),
            (false, false) => (6.0, 4.0, 1.5),
        };
        ctx.draw_secondary_series(DashedLineSeries::new(
            points,
            style.px(dash),
            style.px(gap),
            color.stroke_width(style.px(width)),
        ))
        .map_err(render_error)?;
    }
    Ok(())
}
