//! The robustness chart: insensitivity I(Vtol) against shaper duration, one grey point per
//! family designed for the mode (Singhose 2009 Fig. 11), and the compared shapers marked in
//! their series colours.
//!
//! Family names are placed beside their points, moved above, below or to the left when they
//! would overlap a name already placed (a greedy search in pixel space).

use super::{render_error, ChartStyle, Key, Legend, Linear};
use crate::error::Result;
use crate::robustness::RobustnessRow;
use plotters::coord::Shift;
use plotters::prelude::*;

/// A compared shaper's point on the robustness chart.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RobustnessMark<'a> {
    /// Legend label.
    pub label: &'a str,
    /// Duration in damped periods of the mode.
    pub duration_periods: f64,
    /// Insensitivity I(Vtol) at the mode (fraction of its frequency).
    pub insensitivity: f64,
}

/// A placed label's box in pixels: (left, top, right, bottom).
type Box2 = (i32, i32, i32, i32);

fn overlaps(a: Box2, b: Box2) -> bool {
    a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3
}

/// Draws the `families` table (grey points, named) and the `marks` (rings in the series
/// colours, with a legend), for tolerable vibration `vtol` (fraction, shown in the caption).
pub fn draw_robustness<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    families: &[RobustnessRow],
    marks: &[RobustnessMark<'_>],
    vtol: f64,
    style: &ChartStyle,
) -> Result<()> {
    area.fill(&WHITE).map_err(render_error)?;
    let mut chart = axes(area, families, marks, vtol, style)?;
    let dot = style.px(3.5);
    chart
        .draw_series(
            families
                .iter()
                .filter(valid)
                .map(|r| Circle::new((r.duration_periods, r.insensitivity), dot, GREY.filled())),
        )
        .map_err(render_error)?;
    let mut keys = Legend::default();
    keys.push(
        "families (for mode 1)",
        Key::Dot {
            dx: 8,
            radius: dot as i32,
            style: GREY.filled(),
        },
    );
    let font_px = style.font(11.0);
    let font = ("sans-serif", font_px)
        .into_font()
        .color(&RGBColor(70, 70, 70));
    for (text, pos) in place_names(&chart, families, marks, dot as i32 + 1, font_px, style) {
        area.draw(&Text::new(text, pos, font.clone()))
            .map_err(render_error)?;
    }
    draw_marks(&mut chart, marks, &mut keys, style)?;
    // Upper left: short, very insensitive shapers do not exist, so no point hides there.
    keys.draw_compact(&chart, SeriesLabelPosition::UpperLeft, style)?;
    area.present().map_err(render_error)?;
    Ok(())
}

/// Colour of the families' points.
const GREY: RGBColor = RGBColor(120, 120, 120);

/// A family's point is drawable.
fn valid(r: &&RobustnessRow) -> bool {
    r.duration_periods.is_finite() && r.insensitivity.is_finite()
}

/// The caption and axes, spanning every finite point of `families` and `marks` with a margin.
fn axes<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    families: &[RobustnessRow],
    marks: &[RobustnessMark<'_>],
    vtol: f64,
    style: &ChartStyle,
) -> Result<ChartContext<'a, DB, Linear>> {
    let points = || {
        families
            .iter()
            .map(|r| (r.duration_periods, r.insensitivity))
            .chain(marks.iter().map(|m| (m.duration_periods, m.insensitivity)))
            .filter(|(d, i)| d.is_finite() && i.is_finite())
    };
    let d_max = points().map(|p| p.0).fold(0.0_f64, f64::max);
    let i_max = points().map(|p| p.1).fold(0.0_f64, f64::max);
    let d_max = if d_max > 0.0 { d_max * 1.12 } else { 1.0 };
    let i_max = if i_max > 0.0 { i_max * 1.15 } else { 1.0 };
    let caption = format!(
        "Robustness vs duration (I at Vtol {} %)",
        (vtol * 100.0 * 1000.0).round() / 1000.0
    );
    let mut chart = super::framed(area, caption, 60.0, style)
        .margin_right(style.px(16.0))
        .build_cartesian_2d(0.0..d_max, 0.0..i_max)
        .map_err(render_error)?;
    super::mesh(
        &mut chart,
        "duration (damped periods of mode 1)",
        "insensitivity I(Vtol)",
        style,
    )
    .draw()
    .map_err(render_error)?;
    Ok(chart)
}

/// Where the families' names go (text, top-left pixel), avoiding each other, the plot's
/// edges, the points (of radius `r` pixels) and the marks' rings; a name that fits nowhere is
/// left out.
fn place_names<DB: DrawingBackend>(
    chart: &ChartContext<'_, DB, Linear>,
    families: &[RobustnessRow],
    marks: &[RobustnessMark<'_>],
    r: i32,
    font_px: f64,
    style: &ChartStyle,
) -> Vec<(String, (i32, i32))> {
    let (x_range, y_range) = (chart.x_range(), chart.y_range());
    let to_px = |p: (f64, f64)| chart.backend_coord(&p);
    let (left, top) = to_px((x_range.start, y_range.end));
    let (right, bottom) = to_px((x_range.end, y_range.start));
    let mut taken: Vec<Box2> = families
        .iter()
        .filter(valid)
        .map(|row| {
            let (x, y) = to_px((row.duration_periods, row.insensitivity));
            (x - r, y - r, x + r, y + r)
        })
        .collect();
    // The rings of the compared shapers, drawn later, must not hide a name either.
    taken.extend(
        marks
            .iter()
            .filter(|m| m.duration_periods.is_finite() && m.insensitivity.is_finite())
            .enumerate()
            .map(|(k, m)| {
                let (x, y) = to_px((m.duration_periods, m.insensitivity));
                let ring = style.px(7.0 + 2.0 * k as f64) as i32 + 2;
                (x - ring, y - ring, x + ring, y + ring)
            }),
    );
    let mut labels = Vec::new();
    for row in families.iter().filter(valid) {
        let (x, y) = to_px((row.duration_periods, row.insensitivity));
        let w = (0.56 * font_px * row.title.chars().count() as f64).ceil() as i32;
        let h = font_px.ceil() as i32;
        let gap = r + 2;
        let candidates = [
            (x + gap, y - h / 2),
            (x - w / 2, y - gap - h),
            (x - w / 2, y + gap),
            (x - gap - w, y - h / 2),
            (x + gap, y - h - gap / 2),
            (x + gap, y + gap / 2),
        ];
        let fits = |&(lx, ly): &(i32, i32)| {
            let b = (lx, ly, lx + w, ly + h);
            b.0 >= left
                && b.2 <= right
                && b.1 >= top
                && b.3 <= bottom
                && !taken.iter().any(|t| overlaps(*t, b))
        };
        if let Some(&(lx, ly)) = candidates.iter().find(|c| fits(c)) {
            taken.push((lx, ly, lx + w, ly + h));
            labels.push((row.title.clone(), (lx, ly)));
        }
    }
    labels
}

/// The compared shapers' rings in the series colours (growing, so coinciding ones stay
/// visible), each with a legend entry.
fn draw_marks<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Linear>,
    marks: &[RobustnessMark<'_>],
    keys: &mut Legend,
    style: &ChartStyle,
) -> Result<()> {
    for (k, m) in marks.iter().enumerate() {
        if !(m.duration_periods.is_finite() && m.insensitivity.is_finite()) {
            continue;
        }
        let color = style.color(k);
        let ring = style.px(7.0 + 2.0 * k as f64);
        let width = style.px(2.5);
        chart
            .draw_series(std::iter::once(Circle::new(
                (m.duration_periods, m.insensitivity),
                ring,
                color.stroke_width(width),
            )))
            .map_err(render_error)?;
        keys.push(
            m.label,
            Key::Dot {
                dx: 8,
                radius: ring.min(8) as i32,
                style: color.stroke_width(width),
            },
        );
    }
    Ok(())
}
