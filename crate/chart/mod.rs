//! Charts, each written once against plotters' [`DrawingBackend`]: the page draws them on a
//! canvas (plotters-canvas), native tests into an SVG string they can assert on.

pub mod command;
pub mod corner;
mod curves;
pub mod damping;
pub mod impulses;
pub mod klipper;
pub mod map;
pub mod measured;
pub mod realisation;
pub mod response;
pub mod robustness;
pub mod sensitivity;
pub mod spectrum;

use crate::error::Error;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

pub use command::draw_command;
pub use corner::{draw_corner, CornerTrack};
pub use damping::draw_damping_sensitivity;
pub use impulses::draw_impulses;
pub use klipper::{draw_klipper_chart, KlipperChart, ShaperCurve};
pub use map::{draw_sensitivity_map, draw_sensitivity_map_with, MapCells};
pub use measured::draw_measured_spectrum;
pub use realisation::{draw_realisation, RealisedCurves};
pub use response::draw_response;
pub use robustness::{draw_robustness, RobustnessMark};
pub use sensitivity::draw_sensitivity;
pub use spectrum::draw_spectrum;

/// Colours of up to four overlaid series (colour-blind-safe Okabe–Ito hues).
pub const SERIES_COLORS: [RGBColor; 4] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
];

/// Look of a chart: `scale` multiplies fonts, strokes and margins (pass the device pixel ratio
/// so a chart drawn on a high-DPI canvas reads at the same size); `colors` are the overlaid
/// series' colours, in order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChartStyle {
    /// Multiplier for font sizes, stroke widths and margins (≥ 0.25).
    pub scale: f64,
    /// Colour of series k (cycling past the fourth); default [`SERIES_COLORS`]. A page that
    /// leaves a series out can keep the others' colours by listing them.
    pub colors: [RGBColor; 4],
}

impl Default for ChartStyle {
    fn default() -> Self {
        ChartStyle {
            scale: 1.0,
            colors: SERIES_COLORS,
        }
    }
}

impl ChartStyle {
    /// A length in pixels, scaled.
    pub(crate) fn px(&self, base: f64) -> u32 {
        (base * self.scale.clamp(0.25, 8.0)).round().max(1.0) as u32
    }

    /// A font size in pixels, scaled.
    pub(crate) fn font(&self, base: f64) -> f64 {
        base * self.scale.clamp(0.25, 8.0)
    }

    /// Colour of series `i`.
    pub(crate) fn color(&self, i: usize) -> RGBColor {
        self.colors[i % self.colors.len()]
    }
}

/// Largest magnitude an axis may span: plotters maps coordinates to `i32` pixels, so a value
/// far outside the axes (or a range of 10³⁰⁰) would overflow inside it.
pub(crate) const AXIS_LIMIT: f64 = 1e15;

/// A value made drawable: NaN to `lo`, everything else clamped to the axis range widened by
/// its span on each side (a line to a far point still leaves the plot, at a sane angle).
pub(crate) fn clip(v: f64, lo: f64, hi: f64) -> f64 {
    let span = (hi - lo).abs();
    if v.is_nan() {
        lo
    } else {
        v.clamp(lo - span, hi + span)
    }
}

/// `(lo, hi)` of the finite `values` (each clamped to ±[`AXIS_LIMIT`]), or `fallback` when
/// they do not span an interval.
pub(crate) fn finite_range(values: impl Iterator<Item = f64>, fallback: (f64, f64)) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .map(|v| v.clamp(-AXIS_LIMIT, AXIS_LIMIT))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo < hi {
        (lo, hi)
    } else {
        fallback
    }
}

/// A tolerable-vibration level worth drawing: finite, positive and below [`AXIS_LIMIT`].
pub(crate) fn drawable_vtol(vtol: Option<f64>) -> Option<f64> {
    vtol.filter(|v| v.is_finite() && *v > 0.0 && *v < AXIS_LIMIT)
}

/// Converts a plotters error into the crate's.
pub(crate) fn render_error<E: std::fmt::Debug>(e: E) -> Error {
    Error::Render {
        reason: format!("{e:?}"),
    }
}

/// Colour of the light grid lines of most charts.
pub(crate) const LIGHT_GRID: RGBColor = RGBColor(238, 238, 238);

/// Linear coordinates on both axes, the charts' usual.
pub(crate) type Linear = Cartesian2d<RangedCoordf64, RangedCoordf64>;

/// The frame most charts share: `caption` at font 16, a 10 px margin, a 40 px x-label area
/// and a `y_labels` px y-label area (all scaled). Set more on it before building the axes.
pub(crate) fn framed<'a, 'b, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, plotters::coord::Shift>,
    caption: impl AsRef<str>,
    y_labels: f64,
    style: &ChartStyle,
) -> ChartBuilder<'a, 'b, DB> {
    let mut builder = ChartBuilder::on(area);
    builder
        .caption(caption, ("sans-serif", style.font(16.0)))
        .margin(style.px(10.0))
        .x_label_area_size(style.px(40.0))
        .y_label_area_size(style.px(y_labels));
    builder
}

/// The axes most charts share: the descriptions `x_desc` and `y_desc`, tick labels at font 12
/// and descriptions at font 13 (scaled), grid lines in [`LIGHT_GRID`]. Set more on it, then
/// `draw()`.
pub(crate) fn mesh<'a, 'b, DB: DrawingBackend>(
    chart: &'b mut ChartContext<'a, DB, Linear>,
    x_desc: &str,
    y_desc: impl Into<String>,
    style: &ChartStyle,
) -> plotters::chart::MeshStyle<'a, 'b, RangedCoordf64, RangedCoordf64, DB> {
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(x_desc)
        .y_desc(y_desc)
        .label_style(("sans-serif", style.font(12.0)))
        .axis_desc_style(("sans-serif", style.font(13.0)))
        .light_line_style(LIGHT_GRID);
    mesh
}

/// Colour of the unshaped reference in the simulation, command and spectrum charts.
pub const UNSHAPED_COLOR: RGBColor = RGBColor(110, 110, 110);

/// The smallest and largest finite values of `values` (with a little padding, and a unit range
/// around a constant), for an axis.
pub(crate) fn padded_range(values: impl Iterator<Item = f64>, pad: f64) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !(lo.is_finite() && hi.is_finite()) {
        return (-1.0, 1.0);
    }
    let span = hi - lo;
    if span <= 1e-12 * lo.abs().max(hi.abs()).max(1e-300) {
        let half = (0.5 * lo.abs()).max(1e-9);
        return (lo - half, hi + half);
    }
    (lo - pad * span, hi + pad * span)
}

/// At most about `2 × buckets` points of the polyline (x, y) that keep each bucket's smallest
/// and largest y in order (a min–max decimation: the drawn envelope is the same as with every
/// point, but a canvas draws far fewer segments). Non-finite points are dropped.
pub(crate) fn decimate(x: &[f64], y: &[f64], buckets: usize) -> Vec<(f64, f64)> {
    let n = x.len().min(y.len());
    let points = (0..n).filter(|&i| x[i].is_finite() && y[i].is_finite());
    if n <= 2 * buckets.max(1) {
        return points.map(|i| (x[i], y[i])).collect();
    }
    let per = n.div_ceil(buckets.max(1));
    let mut out = Vec::with_capacity(2 * buckets + 2);
    let mut start = 0;
    while start < n {
        let end = (start + per).min(n);
        let (mut lo, mut hi) = (None::<usize>, None::<usize>);
        for i in start..end {
            if !(x[i].is_finite() && y[i].is_finite()) {
                continue;
            }
            if lo.is_none_or(|l| y[i] < y[l]) {
                lo = Some(i);
            }
            if hi.is_none_or(|h| y[i] > y[h]) {
                hi = Some(i);
            }
        }
        match (lo, hi) {
            (Some(a), Some(b)) if a != b => {
                let (a, b) = (a.min(b), a.max(b));
                out.push((x[a], y[a]));
                out.push((x[b], y[b]));
            }
            (Some(a), _) => out.push((x[a], y[a])),
            _ => {}
        }
        start = end;
    }
    out
}

/// The segment [`simplify_polyline`] is growing from its last vertex: the point it would end
/// at, that point's distance from the vertex, and the cone (its clockwise and counter-clockwise
/// edges) of directions from the vertex passing within the tolerance of every point since.
#[derive(Clone, Copy)]
#[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))] // Used by the page's canvas only.
struct Sleeve {
    end: (i32, i32),
    length: f64,
    cw: (f64, f64),
    ccw: (f64, f64),
}

/// The vertices of the polyline `points` (pixel coordinates) a drawing needs: each dropped
/// point lies within `tolerance` pixels of the segment that replaces it, so with a tolerance
/// below the line's width the drawing looks the same (written to `out`, cleared first). A
/// series decimated to two points per pixel column is mostly straight at that scale: a
/// trapezoid's velocity and acceleration are straight pieces, a smooth curve is straight over
/// a few pixels.
///
/// One pass, "sleeve fitting" (Zhao & Saalfeld 1997): from the last vertex kept, the
/// directions that pass within `tolerance` of every point since form a cone; a point whose
/// direction leaves the cone, or that is nearer the vertex than the point before it, ends the
/// segment at the point before it. The first and last points are always kept.
#[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))] // Used by the page's canvas only.
pub(crate) fn simplify_polyline(
    points: impl IntoIterator<Item = (i32, i32)>,
    tolerance: f64,
    out: &mut Vec<(i32, i32)>,
) {
    out.clear();
    let mut points = points.into_iter();
    let Some(first) = points.next() else {
        return;
    };
    out.push(first);
    let cross = |a: (f64, f64), b: (f64, f64)| a.0 * b.1 - a.1 * b.0;
    let mut anchor = first;
    let mut candidate: Option<Sleeve> = None;
    let mut last = first;
    for p in points {
        // A point repeated (two samples in one pixel) changes nothing: it is the candidate's
        // end, or within the tolerance of the anchor, either way as it was the first time.
        if p == last {
            continue;
        }
        last = p;
        loop {
            let d = (f64::from(p.0 - anchor.0), f64::from(p.1 - anchor.1));
            // Not `hypot`: wasm has no hardware for it, and libm's (with a software fma) was
            // ~8 % of a page update. Pixel differences are integers far below 2^26, so the sum
            // of squares is exact and its square root correctly rounded.
            let length = (d.0 * d.0 + d.1 * d.1).sqrt();
            if length <= tolerance && candidate.is_none() {
                break; // Within the tolerance of the anchor itself.
            }
            // The cone of directions passing within `tolerance` of p: d turned by ±asin(ε/|d|).
            let sin = (tolerance / length).min(1.0);
            let cos = (1.0 - sin * sin).sqrt();
            let cw = (d.0 * cos + d.1 * sin, d.1 * cos - d.0 * sin);
            let ccw = (d.0 * cos - d.1 * sin, d.1 * cos + d.0 * sin);
            match candidate {
                None => {
                    candidate = Some(Sleeve {
                        end: p,
                        length,
                        cw,
                        ccw,
                    });
                    break;
                }
                Some(c) => {
                    let inside = cross(c.cw, d) >= 0.0 && cross(d, c.ccw) >= 0.0;
                    if inside && length >= c.length {
                        candidate = Some(Sleeve {
                            end: p,
                            length,
                            cw: if cross(c.cw, cw) > 0.0 { cw } else { c.cw },
                            ccw: if cross(c.ccw, ccw) < 0.0 { ccw } else { c.ccw },
                        });
                        break;
                    }
                    // p cannot share the segment: end it at the candidate, start from there.
                    out.push(c.end);
                    anchor = c.end;
                    candidate = None;
                }
            }
        }
    }
    if out.last() != Some(&last) {
        out.push(last);
    }
}

/// The series of a time chart: `reference` (label, trajectory) in grey, then each labelled
/// shaped trajectory in the series colours; and the end of the time axis (the latest finite
/// last sample time, or 1 s if there is none).
pub(crate) fn time_series<'a>(
    reference: (&'a str, &'a crate::simulate::Trajectory),
    shaped: &[(&'a str, &'a crate::simulate::Trajectory)],
    style: &ChartStyle,
) -> (
    Vec<(&'a str, &'a crate::simulate::Trajectory, RGBColor)>,
    f64,
) {
    let all: Vec<_> = std::iter::once((reference.0, reference.1, UNSHAPED_COLOR))
        .chain(
            shaped
                .iter()
                .enumerate()
                .map(|(k, (l, t))| (*l, *t, style.color(k))),
        )
        .collect();
    let t_end = all
        .iter()
        .filter_map(|(_, t, _)| t.time.last().copied())
        .filter(|t| t.is_finite())
        .fold(0.0_f64, f64::max);
    (all, if t_end > 0.0 { t_end } else { 1.0 })
}

/// What a legend entry shows before its label, drawn centred on the label's line.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Key {
    /// A horizontal line `len` pixels long.
    Line { len: i32, style: ShapeStyle },
    /// A circle `dx` pixels right of the key area's left edge.
    Dot {
        dx: i32,
        radius: i32,
        style: ShapeStyle,
    },
}

impl Key {
    /// A 16-pixel line in `style` (the unscaled keys of the analysis charts).
    pub(crate) fn line(style: ShapeStyle) -> Key {
        Key::Line { len: 16, style }
    }
}

/// A swatch key: a short thick line of `color`, scaled.
pub(crate) fn swatch(color: RGBColor, style: &ChartStyle) -> Key {
    Key::Line {
        len: style.px(16.0) as i32,
        style: color.stroke_width(style.px(3.0)),
    }
}

/// A chart's legend: labelled keys in a framed box in a corner of the plotting area.
///
/// Drawn here rather than by plotters' series labels, which measure every label through the
/// font layer — on the web a `<span>` appended to the page and read back, a forced layout per
/// label per frame. This measures through the drawing backend instead (the canvas backend
/// asks the 2-D context's `measureText`; the SVG backend estimates), with plotters' layout:
/// lines 1.25 font sizes apart, `margin` inside the frame, the keys in a column `key_area`
/// wide, 5 px from the plotting area's edges.
#[derive(Debug, Default)]
pub(crate) struct Legend {
    entries: Vec<(String, Key)>,
}

impl Legend {
    /// Adds an entry.
    pub(crate) fn push(&mut self, label: impl Into<String>, key: Key) {
        self.entries.push((label.into(), key));
    }

    /// Draws the legend on `chart`'s plotting area: font `font_px`, `margin` and `key_area`
    /// in pixels. Nothing is drawn without entries.
    pub(crate) fn draw<DB: DrawingBackend, CT: plotters::coord::CoordTranslate>(
        &self,
        chart: &ChartContext<'_, DB, CT>,
        position: SeriesLabelPosition,
        font_px: f64,
        margin: i32,
        key_area: i32,
    ) -> crate::error::Result<()> {
        if self.entries.is_empty() {
            return Ok(());
        }
        let area = chart.plotting_area().strip_coord_spec();
        let font: TextStyle = ("sans-serif", font_px).into_font().into();
        let line = font_px * 1.25;
        let mut sizes = Vec::with_capacity(self.entries.len());
        let (mut w, mut h) = (0, 0);
        for (k, (label, _)) in self.entries.iter().enumerate() {
            let (tw, th) = area
                .estimate_text_size(label, &font)
                .map_err(render_error)?;
            let y = (k as f64 * line).round() as i32;
            w = w.max(tw as i32);
            h = h.max(y + th as i32);
            sizes.push((y, th as i32));
        }
        let (w, h) = (w + key_area + 2 * margin, h + 2 * margin);
        let (aw, ah) = area.dim_in_pixel();
        let (aw, ah) = (aw as i32, ah as i32);
        use SeriesLabelPosition::*;
        let x0 = match position {
            UpperLeft | MiddleLeft | LowerLeft => 5,
            UpperMiddle | MiddleMiddle | LowerMiddle => (aw - w) / 2,
            UpperRight | MiddleRight | LowerRight => aw - w - 5,
            Coordinate(x, _) => x,
        };
        let y0 = match position {
            UpperLeft | UpperMiddle | UpperRight => 5,
            MiddleLeft | MiddleMiddle | MiddleRight => (ah - h) / 2,
            LowerLeft | LowerMiddle | LowerRight => ah - h - 5,
            Coordinate(_, y) => y,
        };
        let frame = [(x0, y0), (x0 + w, y0 + h)];
        area.draw(&Rectangle::new(frame, WHITE.mix(0.85).filled()))
            .map_err(render_error)?;
        area.draw(&Rectangle::new(frame, RGBColor(180, 180, 180)))
            .map_err(render_error)?;
        for ((label, key), (dy, th)) in self.entries.iter().zip(sizes) {
            let top = y0 + margin + dy;
            area.draw(&Text::new(
                label.as_str(),
                (x0 + key_area + margin, top),
                &font,
            ))
            .map_err(render_error)?;
            let (x, y) = (x0 + margin, top + th / 2);
            match *key {
                Key::Line { len, style } => area
                    .draw(&PathElement::new(vec![(x, y), (x + len, y)], style))
                    .map_err(render_error)?,
                Key::Dot { dx, radius, style } => area
                    .draw(&Circle::new((x + dx, y), radius, style))
                    .map_err(render_error)?,
            }
        }
        Ok(())
    }

    /// [`Self::draw`] with the compact layout of the simulation charts (font 12, margin 6,
    /// key column 22, scaled).
    pub(crate) fn draw_compact<DB: DrawingBackend, CT: plotters::coord::CoordTranslate>(
        &self,
        chart: &ChartContext<'_, DB, CT>,
        position: SeriesLabelPosition,
        style: &ChartStyle,
    ) -> crate::error::Result<()> {
        self.draw(
            chart,
            position,
            style.font(12.0),
            style.px(6.0) as i32,
            style.px(22.0) as i32,
        )
    }

    /// [`Self::draw`] with plotters' default layout (margin 10, key column 30) at font 12,
    /// scaled.
    pub(crate) fn draw_default<DB: DrawingBackend, CT: plotters::coord::CoordTranslate>(
        &self,
        chart: &ChartContext<'_, DB, CT>,
        position: SeriesLabelPosition,
        style: &ChartStyle,
    ) -> crate::error::Result<()> {
        self.draw(chart, position, style.font(12.0), 10, 30)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn decimation_keeps_each_buckets_extremes() {
        let x: Vec<f64> = (0..10_000).map(|i| i as f64).collect();
        let y: Vec<f64> = x
            .iter()
            .map(|t| (t * 0.37).sin() * (1.0 + t / 1e4))
            .collect();
        let d = decimate(&x, &y, 100);
        assert!(d.len() <= 202, "{}", d.len());
        let max = y.iter().copied().fold(f64::MIN, f64::max);
        let min = y.iter().copied().fold(f64::MAX, f64::min);
        assert!(d.iter().any(|p| p.1 == max) && d.iter().any(|p| p.1 == min));
        assert!(d.windows(2).all(|w| w[0].0 < w[1].0), "in order");
        // Short series pass through untouched (non-finite points dropped).
        assert_eq!(
            decimate(&[0.0, 1.0, 2.0], &[1.0, f64::NAN, 3.0], 100),
            vec![(0.0, 1.0), (2.0, 3.0)]
        );
    }

    /// Distance from `p` to the segment a–b.
    fn distance(p: (i32, i32), a: (i32, i32), b: (i32, i32)) -> f64 {
        let (px, py) = (f64::from(p.0 - a.0), f64::from(p.1 - a.1));
        let (dx, dy) = (f64::from(b.0 - a.0), f64::from(b.1 - a.1));
        let len2 = dx * dx + dy * dy;
        let t = if len2 > 0.0 {
            ((px * dx + py * dy) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (px - t * dx).hypot(py - t * dy)
    }

    /// Polylines of every kind: straight lines, a staircase, a sine sampled at two points per
    /// pixel, noise, vertical jumps and points going back (with a repeat), one point, none.
    fn test_curves() -> Vec<Vec<(i32, i32)>> {
        let mut seed = 12345_u64;
        // A linear congruential generator (Knuth's MMIX constants): repeatable noise.
        let mut noise = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 33) % 7) as i32 - 3
        };
        vec![
            (0..400).map(|x| (x, 100)).collect(),
            (0..400).map(|x| (x, 3 * x / 7)).collect(),
            (0..400).map(|x| (x, (x / 40) * 10)).collect(),
            (0..800)
                .map(|i| (i / 2, (120.0 * (f64::from(i) * 0.02).sin()) as i32))
                .collect(),
            (0..400).map(|x| (x, 50 + noise())).collect(),
            vec![
                (0, 0),
                (10, 0),
                (10, 50),
                (10, -50),
                (20, 0),
                (5, 0),
                (30, 1),
                (30, 1),
            ],
            vec![(7, 7)],
            vec![],
        ]
    }

    /// Every input point lies within the tolerance of the simplified polyline's segment that
    /// replaced it, checked point by point (brute force) on curves of every kind
    /// ([`test_curves`]). Straight pieces shrink to their ends.
    #[wasm_bindgen_test(unsupported = test)]
    fn simplified_polylines_stay_within_the_tolerance() {
        let curves = test_curves();
        let mut out = Vec::new();
        for (k, curve) in curves.iter().enumerate() {
            for tolerance in [0.25, 0.5, 2.0] {
                simplify_polyline(curve.iter().copied(), tolerance, &mut out);
                assert_eq!(out.first(), curve.first(), "curve {k}: first point kept");
                assert_eq!(out.last(), curve.last(), "curve {k}: last point kept");
                // Walk the input along the output: each output vertex is an input point, in
                // order, and the points between two vertices are near their segment.
                let mut j = 0;
                for (i, &p) in curve.iter().enumerate() {
                    if j + 1 < out.len() && p == out[j + 1] && i > 0 {
                        j += 1;
                        continue;
                    }
                    let b = out.get(j + 1).copied().unwrap_or(out[j]);
                    let d = distance(p, out[j], b);
                    assert!(
                        d <= tolerance + 1e-9,
                        "curve {k}, point {i} {p:?}: {d} px off"
                    );
                }
                assert_eq!(
                    j + 1,
                    out.len().max(1),
                    "curve {k}: every vertex met in order"
                );
            }
        }
        simplify_polyline(curves[0].iter().copied(), 0.5, &mut out);
        assert_eq!(out, [(0, 100), (399, 100)], "a straight line is its ends");
        simplify_polyline(curves[2].iter().copied(), 0.5, &mut out);
        assert!(
            out.len() <= 2 * 10 + 2,
            "a staircase is its corners: {}",
            out.len()
        );
    }

    /// Repeated points (two samples in one pixel, a quarter of a 4-shaper frame's points) are
    /// skipped: the same vertices as with each point once, wherever the repeats fall.
    #[wasm_bindgen_test(unsupported = test)]
    fn repeated_points_change_no_vertex() {
        let (mut once, mut repeated) = (Vec::new(), Vec::new());
        for curve in test_curves() {
            for tolerance in [0.25, 2.0] {
                simplify_polyline(curve.iter().copied(), tolerance, &mut once);
                for times in [2, 3] {
                    // Every point `times` times, and every third point once more.
                    let repeats = curve.iter().enumerate().flat_map(|(i, &p)| {
                        std::iter::repeat_n(p, times + usize::from(i % 3 == 0))
                    });
                    simplify_polyline(repeats, tolerance, &mut repeated);
                    assert_eq!(repeated, once, "tolerance {tolerance}, each point {times}×");
                }
            }
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn padded_range_handles_constants_and_nothing() {
        assert_eq!(padded_range([1.0, 3.0].into_iter(), 0.5), (0.0, 4.0));
        let (lo, hi) = padded_range([2.0, 2.0].into_iter(), 0.1);
        assert!(lo < 2.0 && hi > 2.0);
        assert_eq!(padded_range([f64::NAN].into_iter(), 0.1), (-1.0, 1.0));
    }
}
