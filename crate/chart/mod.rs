//! Charts, each written once against plotters' [`DrawingBackend`]: the page draws them on a
//! canvas (plotters-canvas), native tests into an SVG string they can assert on.

pub mod damping;
pub mod impulses;
pub mod map;
pub mod sensitivity;

use crate::error::Error;
use plotters::prelude::*;

pub use damping::draw_damping_sensitivity;
pub use impulses::draw_impulses;
pub use map::draw_sensitivity_map;
pub use sensitivity::draw_sensitivity;

/// Colours of up to four overlaid series (colour-blind-safe Okabe–Ito hues).
pub const SERIES_COLORS: [RGBColor; 4] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
];

/// Look of a chart: `scale` multiplies fonts, strokes and margins (pass the device pixel ratio
/// so a chart drawn on a high-DPI canvas reads at the same size).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChartStyle {
    /// Multiplier for font sizes, stroke widths and margins (≥ 0.25).
    pub scale: f64,
}

impl Default for ChartStyle {
    fn default() -> Self {
        ChartStyle { scale: 1.0 }
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
        SERIES_COLORS[i % SERIES_COLORS.len()]
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
