//! The sensitivity map: residual vibration V over frequency × damping as a heat map, with the
//! contour V = Vtol drawn over it and the modes marked (Singhose 2009 Fig. 10, seen from above).
//!
//! Cells are coloured on a viridis-like scale quantised to [`COLOR_LEVELS`] steps; equal
//! neighbours in a row are merged into one rectangle, so a 400 × 200 map draws a few thousand
//! rectangles rather than 80 000. The contour is traced by marching squares on the grid
//! ([`contour_segments`]).

use super::{render_error, ChartStyle, Key, Legend, Linear};
use crate::error::{Error, Result};
use crate::vibration::SensitivityMap;
use plotters::coord::Shift;
use plotters::element::{Drawable, PointCollection};
use plotters::prelude::*;
use plotters_backend::DrawingErrorKind;

/// Number of distinct colours of the heat map.
pub const COLOR_LEVELS: usize = 64;

/// Anchors of the colour scale (matplotlib's viridis at 0, ⅛, …, 1), dark = little vibration.
const VIRIDIS: [(u8, u8, u8); 9] = [
    (68, 1, 84),
    (71, 44, 122),
    (59, 81, 139),
    (44, 113, 142),
    (33, 144, 141),
    (39, 173, 129),
    (92, 200, 99),
    (170, 220, 50),
    (253, 231, 37),
];

/// Colour of the V = Vtol contour and of the mode markers.
const CONTOUR_COLOR: RGBColor = RGBColor(255, 255, 255);

/// The colour of `x` ∈ [0, 1] on the scale (clamped; NaN is the bottom colour).
pub fn scale_color(x: f64) -> RGBColor {
    let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    let pos = x * (VIRIDIS.len() - 1) as f64;
    let i = (pos.floor() as usize).min(VIRIDIS.len() - 2);
    let t = pos - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |p: u8, q: u8| (f64::from(p) + t * (f64::from(q) - f64::from(p))).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// The colour level (0 … [`COLOR_LEVELS`] − 1) of vibration `v` on a scale topped at `top`.
fn level(v: f64, top: f64) -> usize {
    let x = if v.is_finite() { v / top } else { 1.0 };
    ((x.clamp(0.0, 1.0) * COLOR_LEVELS as f64) as usize).min(COLOR_LEVELS - 1)
}

/// Colour of a level (its midpoint on the scale).
fn level_color(level: usize) -> RGBColor {
    scale_color((level as f64 + 0.5) / COLOR_LEVELS as f64)
}

/// The contour V = `level` of a map as line segments ((f₁ Hz, ζ₁), (f₂ Hz, ζ₂)), by marching
/// squares: on each grid cell the crossing points on its edges are found by linear
/// interpolation and joined; a saddle cell (four crossings) is resolved by the mean of its
/// corners. Empty if the map's vectors are inconsistent.
pub fn contour_segments(map: &SensitivityMap, level: f64) -> Vec<[(f64, f64); 2]> {
    let (f, z) = (&map.frequency_hz, &map.damping);
    let mut segments = Vec::new();
    if map.vibration.len() != f.len() * z.len() {
        return segments;
    }
    let nf = f.len();
    let v = &map.vibration;
    for k in 0..z.len().saturating_sub(1) {
        for j in 0..nf.saturating_sub(1) {
            // Corners counter-clockwise from bottom-left: grid indices (j, k).
            // (In range: the length was checked above.)
            let at = [(j, k), (j + 1, k), (j + 1, k + 1), (j, k + 1)];
            let i = k * nf + j;
            let values = [v[i], v[i + 1], v[i + nf + 1], v[i + nf]];
            if values.iter().any(|x| !x.is_finite()) {
                continue;
            }
            let above = values.iter().filter(|&&x| x > level).count();
            if above == 0 || above == 4 {
                continue; // the level does not cross this cell (most cells)
            }
            let mut corners = [(0.0, 0.0, 0.0); 4];
            for ((c, &(j, k)), &value) in corners.iter_mut().zip(&at).zip(&values) {
                *c = (f[j], z[k], value);
            }
            // Crossing on edge e (from corner e to corner e+1), if the level separates them.
            let crossing = |e: usize| {
                let (p, q) = (corners[e], corners[(e + 1) % 4]);
                if (p.2 > level) == (q.2 > level) {
                    return None;
                }
                let t = (level - p.2) / (q.2 - p.2);
                Some((p.0 + t * (q.0 - p.0), p.1 + t * (q.1 - p.1)))
            };
            let mut cuts = [(0.0, 0.0); 4];
            let mut n = 0;
            for c in (0..4).filter_map(crossing) {
                cuts[n] = c;
                n += 1;
            }
            match &cuts[..n] {
                [a, b] => segments.push([*a, *b]),
                [bottom, right, top, left] => {
                    let mean = corners.iter().map(|c| c.2).sum::<f64>() / 4.0;
                    if (mean > level) == (corners[0].2 > level) {
                        // The bottom-left and top-right corners connect through the centre:
                        // cut off the other two.
                        segments.push([*bottom, *right]);
                        segments.push([*top, *left]);
                    } else {
                        segments.push([*bottom, *left]);
                        segments.push([*right, *top]);
                    }
                }
                _ => {}
            }
        }
    }
    segments
}

/// Checks that a map is drawable: at least 2 × 2 points, increasing axes, as many values as
/// grid points.
fn check_map(map: &SensitivityMap) -> Result<()> {
    let (nf, nz) = (map.frequency_hz.len(), map.damping.len());
    if nf < 2 || nz < 2 {
        return Err(Error::invalid(
            "map",
            format!("needs at least 2 frequencies and 2 damping ratios, got {nf} × {nz}"),
        ));
    }
    if map.vibration.len() != nf * nz {
        return Err(Error::invalid(
            "map.vibration",
            format!(
                "needs frequencyHz.length × damping.length = {} values, got {}",
                nf * nz,
                map.vibration.len()
            ),
        ));
    }
    let increasing =
        |v: &[f64]| v.windows(2).all(|w| w[0] < w[1]) && v.iter().all(|x| x.is_finite());
    if !increasing(&map.frequency_hz) {
        return Err(Error::invalid(
            "map.frequencyHz",
            "must be finite and increasing",
        ));
    }
    if !increasing(&map.damping) {
        return Err(Error::invalid(
            "map.damping",
            "must be finite and increasing",
        ));
    }
    Ok(())
}

/// Cell edges along an axis: midpoints between grid values, the ends at the first and last.
fn cell_edges(values: &[f64]) -> Vec<f64> {
    let mut edges = Vec::with_capacity(values.len() + 1);
    edges.extend(values.first());
    edges.extend(values.windows(2).map(|w| 0.5 * (w[0] + w[1])));
    edges.extend(values.last());
    edges
}

/// An RGB bitmap (3 bytes per pixel, row-major) drawn with its top-left corner at `origin`.
#[derive(Debug, Clone, PartialEq)]
pub struct Bitmap {
    /// Top-left corner, in the drawing area's pixels.
    pub origin: (i32, i32),
    /// Width and height in pixels.
    pub size: (u32, u32),
    /// `size.0 × size.1` pixels, 3 bytes (r, g, b) each, row by row from the top.
    pub rgb: Vec<u8>,
}

impl<'a> PointCollection<'a, (i32, i32)> for &'a Bitmap {
    type Point = &'a (i32, i32);
    type IntoIter = std::iter::Once<&'a (i32, i32)>;
    fn point_iter(self) -> Self::IntoIter {
        std::iter::once(&self.origin)
    }
}

impl<DB: DrawingBackend> Drawable<DB> for Bitmap {
    fn draw<I: Iterator<Item = (i32, i32)>>(
        &self,
        mut points: I,
        backend: &mut DB,
        _: (u32, u32),
    ) -> std::result::Result<(), DrawingErrorKind<DB::ErrorType>> {
        match points.next() {
            Some(at) if self.rgb.len() == 3 * self.size.0 as usize * self.size.1 as usize => {
                backend.blit_bitmap(at, self.size, &self.rgb)
            }
            _ => Ok(()),
        }
    }
}

/// The map's cells as a bitmap of the plotting area `x` × `y` (backend pixel ranges, end
/// excluded), origin at the area's top-left. `xe` are the backend x of the cell edges along
/// frequency (increasing) and `ye` the backend y of the edges along damping (decreasing: ζ grows
/// upwards). Pixel (px, py) takes the colour of the cell whose edges enclose it,
/// `xe[j] ≤ px < xe[j + 1]` and `ye[k + 1] ≤ py < ye[k]` — the pixels the rectangles of
/// [`MapCells::Rectangles`] cover; pixels outside every cell stay white.
pub fn raster_cells(
    map: &SensitivityMap,
    top: f64,
    x: (i32, i32),
    y: (i32, i32),
    xe: &[i32],
    ye: &[i32],
) -> Bitmap {
    let (w, h) = ((x.1 - x.0).max(0) as usize, (y.1 - y.0).max(0) as usize);
    let nf = map.frequency_hz.len();
    let palette: Vec<RGBColor> = (0..COLOR_LEVELS).map(level_color).collect();
    let cell = |edges: &[i32], p: i32, rising: bool| -> Option<usize> {
        (0..edges.len().saturating_sub(1)).find(|&j| {
            let (a, b) = (edges[j], edges[j + 1]);
            if rising {
                a <= p && p < b
            } else {
                b <= p && p < a
            }
        })
    };
    let columns: Vec<Option<usize>> = (x.0..x.1).map(|p| cell(xe, p, true)).collect();
    let mut rgb = vec![255; 3 * w * h];
    let stride = 3 * w;
    // Each row of cells is coloured once; the further pixel rows it covers are copies.
    let mut last_row: Option<(usize, usize)> = None; // (cell row, its first pixel row)
    for (i, py) in (y.0..y.1).enumerate() {
        let Some(k) = cell(ye, py, false) else {
            continue;
        };
        let start = i * stride;
        if let Some((_, from)) = last_row.filter(|&(row, _)| row == k) {
            rgb.copy_within(from..from + stride, start);
            continue;
        }
        let values = map.vibration.get(k * nf..(k + 1) * nf).unwrap_or(&[]);
        let colors: Vec<RGBColor> = values.iter().map(|&v| palette[level(v, top)]).collect();
        for (px, col) in rgb[start..start + stride].chunks_exact_mut(3).zip(&columns) {
            if let Some(&RGBColor(r, g, b)) = col.and_then(|j| colors.get(j)) {
                px[0] = r;
                px[1] = g;
                px[2] = b;
            }
        }
        last_row = Some((k, start));
    }
    Bitmap {
        origin: (0, 0),
        size: (w as u32, h as u32),
        rgb,
    }
}

/// Draws the heat map of `map` (x: frequency in Hz, y: damping ratio), the contour V = `vtol`
/// (fraction) in white, a white cross at each mode `(frequency Hz, damping)` in `modes`, and a
/// colour bar of V in % on the right. The colour scale runs from 0 to the largest V of the map
/// (at least `vtol`).
pub fn draw_sensitivity_map<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    map: &SensitivityMap,
    vtol: Option<f64>,
    modes: &[(f64, f64)],
    style: &ChartStyle,
) -> Result<()> {
    draw_sensitivity_map_with(area, map, vtol, modes, style, MapCells::Rectangles)
}

/// How [`draw_sensitivity_map_with`] draws the map's cells.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MapCells {
    /// One filled rectangle per run of equal colour in a row: vector output (SVG).
    Rectangles,
    /// One bitmap of the plotting area, blitted at once — the same cells, pixel for pixel, in
    /// one backend call instead of thousands (the page's canvas backend writes it with
    /// `putImageData`; a backend without a bitmap operation draws it pixel by pixel).
    Bitmap,
}

/// [`draw_sensitivity_map`], choosing how the cells are drawn.
pub fn draw_sensitivity_map_with<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    map: &SensitivityMap,
    vtol: Option<f64>,
    modes: &[(f64, f64)],
    style: &ChartStyle,
    cells: MapCells,
) -> Result<()> {
    check_map(map)?;
    area.fill(&WHITE).map_err(render_error)?;
    let vtol = super::drawable_vtol(vtol);
    let top = map
        .vibration
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(vtol.unwrap_or(0.0), f64::max)
        .clamp(1e-3, super::AXIS_LIMIT);
    let (width, _) = area.dim_in_pixel();
    let bar_width = style.px(78.0).min(width / 3);
    let (main, bar) = area.split_horizontally(width.saturating_sub(bar_width).max(1));

    let (f, z) = (&map.frequency_hz, &map.damping);
    let (f_lo, f_hi, z_lo, z_hi) = (f[0], f[f.len() - 1], z[0], z[z.len() - 1]);
    let mut chart = super::framed(&main, "Residual vibration V(f, ζ)", 52.0, style)
        .build_cartesian_2d(f_lo..f_hi, z_lo..z_hi)
        .map_err(render_error)?;
    // The cells first, the axes and their labels after: a canvas' `putImageData` writes the
    // pixels at once, so whatever was drawn before it is rasterised inside the update (the
    // labels: most of the bitmap's cost); drawn after, they are rasterised with the frame.
    // The axes and labels lie in the label areas, beside the cells.
    draw_cells(&mut chart, map, top, cells)?;
    super::mesh(&mut chart, "frequency (Hz)", "damping ratio ζ", style)
        .disable_mesh()
        .draw()
        .map_err(render_error)?;
    draw_contour_and_modes(&mut chart, map, vtol, modes, style)?;
    draw_color_bar(&bar, top, vtol, style)?;
    area.present().map_err(render_error)?;
    Ok(())
}

/// The map's cells on a scale topped at `top`, as rectangles or as one bitmap (`cells`).
fn draw_cells<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Linear>,
    map: &SensitivityMap,
    top: f64,
    cells: MapCells,
) -> Result<()> {
    let (f, z) = (&map.frequency_hz, &map.damping);
    let (f_lo, z_lo) = (f[0], z[0]);
    let (fe, ze) = (cell_edges(f), cell_edges(z));
    match cells {
        MapCells::Rectangles => {
            // Runs of equal colour along a row merged into one rectangle.
            let mut rects = Vec::new();
            for (k, row) in map.vibration.chunks_exact(f.len()).enumerate() {
                let (y0, y1) = (ze[k], ze[k + 1]);
                let mut start = 0;
                while start < row.len() {
                    let lv = level(row[start], top);
                    let mut end = start + 1;
                    while end < row.len() && level(row[end], top) == lv {
                        end += 1;
                    }
                    rects.push(Rectangle::new(
                        [(fe[start], y0), (fe[end], y1)],
                        level_color(lv).filled(),
                    ));
                    start = end;
                }
            }
            chart.draw_series(rects).map_err(render_error)?;
        }
        MapCells::Bitmap => {
            let (xr, yr) = chart.plotting_area().get_pixel_range();
            let xe: Vec<i32> = fe
                .iter()
                .map(|&v| chart.backend_coord(&(v, z_lo)).0)
                .collect();
            let ye: Vec<i32> = ze
                .iter()
                .map(|&v| chart.backend_coord(&(f_lo, v)).1)
                .collect();
            let bitmap = raster_cells(map, top, (xr.start, xr.end), (yr.start, yr.end), &xe, &ye);
            chart
                .plotting_area()
                .strip_coord_spec()
                .draw(&bitmap)
                .map_err(render_error)?;
        }
    }
    Ok(())
}

/// Over the cells: the contour V = `vtol` (with its legend, if any) and a cross at each mode
/// inside the map.
fn draw_contour_and_modes<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Linear>,
    map: &SensitivityMap,
    vtol: Option<f64>,
    modes: &[(f64, f64)],
    style: &ChartStyle,
) -> Result<()> {
    let (f, z) = (&map.frequency_hz, &map.damping);
    let (f_lo, f_hi, z_lo, z_hi) = (f[0], f[f.len() - 1], z[0], z[z.len() - 1]);
    let mut keys = Legend::default();
    if let Some(vtol) = vtol {
        let line = CONTOUR_COLOR.stroke_width(style.px(2.0));
        chart
            .draw_series(
                contour_segments(map, vtol)
                    .into_iter()
                    .map(|[a, b]| PathElement::new(vec![a, b], line)),
            )
            .map_err(render_error)?;
        keys.push(format!("V = Vtol ({:.3} %)", vtol * 100.0), Key::line(line));
    }
    let inside =
        |&&(mf, mz): &&(f64, f64)| (f_lo..=f_hi).contains(&mf) && (z_lo..=z_hi).contains(&mz);
    let size = style.px(6.0) as i32;
    chart
        .draw_series(
            modes.iter().filter(inside).map(|&(mf, mz)| {
                Cross::new((mf, mz), size, CONTOUR_COLOR.stroke_width(style.px(2.0)))
            }),
        )
        .map_err(render_error)?;
    if vtol.is_some() {
        keys.draw_default(chart, SeriesLabelPosition::UpperRight, style)?;
    }
    Ok(())
}

/// The colour bar in `bar`: the levels stacked from 0 to `top`, labelled in %, with `vtol`
/// marked.
fn draw_color_bar<DB: DrawingBackend>(
    bar: &DrawingArea<DB, Shift>,
    top: f64,
    vtol: Option<f64>,
    style: &ChartStyle,
) -> Result<()> {
    let top_pct = top * 100.0;
    let mut bar_chart = ChartBuilder::on(bar)
        .margin_top(style.px(36.0))
        .margin_bottom(style.px(50.0))
        .margin_right(style.px(4.0))
        .y_label_area_size(style.px(48.0))
        .build_cartesian_2d(0.0..1.0, 0.0..top_pct)
        .map_err(render_error)?;
    bar_chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc("V (%)")
        .label_style(("sans-serif", style.font(11.0)))
        .axis_desc_style(("sans-serif", style.font(12.0)))
        .draw()
        .map_err(render_error)?;
    bar_chart
        .draw_series((0..COLOR_LEVELS).map(|lv| {
            let y0 = top_pct * lv as f64 / COLOR_LEVELS as f64;
            let y1 = top_pct * (lv + 1) as f64 / COLOR_LEVELS as f64;
            Rectangle::new([(0.0, y0), (1.0, y1)], level_color(lv).filled())
        }))
        .map_err(render_error)?;
    if let Some(vtol) = vtol {
        bar_chart
            .draw_series(LineSeries::new(
                [(0.0, vtol * 100.0), (1.0, vtol * 100.0)],
                CONTOUR_COLOR.stroke_width(style.px(2.0)),
            ))
            .map_err(render_error)?;
    }
    Ok(())
}
