//! Charts rendered natively into SVG strings through the same code the page draws on canvas.
#![cfg(not(target_arch = "wasm32"))]

use input_shaping::chart::{draw_impulses, draw_sensitivity, ChartStyle};
use input_shaping::design::zero_vibration::{zv, zvd};
use input_shaping::vibration::{sensitivity, SensitivityOptions};
use input_shaping::Mode;
use plotters::prelude::*;

/// The texts of an SVG, trimmed.
fn texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| t.split_once('>'))
        .map(|(_, rest)| rest.split('<').next().unwrap_or("").trim().to_string())
        .collect()
}

/// The font size of the first text element (the caption).
fn caption_font_size(svg: &str) -> f64 {
    svg.split("font-size=\"")
        .nth(1)
        .and_then(|r| r.split('"').next())
        .and_then(|v| v.parse().ok())
        .unwrap()
}

fn svg(draw: impl FnOnce(&DrawingArea<SVGBackend, plotters::coord::Shift>)) -> String {
    let mut out = String::new();
    {
        let area = SVGBackend::with_string(&mut out, (640, 360)).into_drawing_area();
        draw(&area);
    }
    out
}

#[test]
fn impulse_chart_draws_one_stem_and_dot_per_impulse() {
    let mode = Mode::new(2.0, 0.05).unwrap();
    let s = zvd(&mode).unwrap();
    let out = svg(|a| draw_impulses(a, &[("ZVD", &s)], &ChartStyle::default()).unwrap());
    let t = texts(&out);
    assert!(
        t.contains(&"Impulse sequence".to_string()),
        "caption: {t:?}"
    );
    assert!(
        t.contains(&"time (s)".to_string()) && t.contains(&"amplitude".to_string()),
        "axis labels: {t:?}"
    );
    // One filled circle per impulse, in the first series colour (0, 114, 178) = #0072B2.
    assert_eq!(out.matches("<circle").count(), 3, "{out}");
    assert!(out.to_uppercase().contains("#0072B2"));
}

#[test]
fn overlaid_impulse_charts_have_a_legend() {
    let mode = Mode::new(2.0, 0.0).unwrap();
    let (a, b) = (zv(&mode).unwrap(), zvd(&mode).unwrap());
    let out = svg(|area| {
        draw_impulses(area, &[("ZV", &a), ("ZVD", &b)], &ChartStyle::default()).unwrap()
    });
    assert_eq!(out.matches("<circle").count(), 5);
    let t = texts(&out);
    assert!(
        t.contains(&"ZV".to_string()) && t.contains(&"ZVD".to_string()),
        "legend labels: {t:?}"
    );
}

#[test]
fn sensitivity_chart_has_curve_vtol_and_mode_marker() {
    let mode = Mode::new(2.0, 0.0).unwrap();
    let s = zv(&mode).unwrap();
    let curve = sensitivity(
        &s,
        &SensitivityOptions {
            from_hz: 0.0,
            to_hz: 4.0,
            points: 200,
            damping: 0.0,
        },
    )
    .unwrap();
    let out = svg(|a| {
        draw_sensitivity(
            a,
            &[("ZV", &curve)],
            Some(0.05),
            &[2.0],
            &ChartStyle::default(),
        )
        .unwrap()
    });
    let t = texts(&out);
    for want in [
        "Residual vibration V(f)",
        "frequency (Hz)",
        "vibration (%)",
        "Vtol 5.000 %",
        "ZV",
    ] {
        assert!(t.contains(&want.to_string()), "{want} missing from {t:?}");
    }
    // The curve is one polyline with all 200 points.
    let longest = out
        .split("<polyline")
        .skip(1)
        .map(|p| {
            p.split("points=\"")
                .nth(1)
                .unwrap_or("")
                .split('"')
                .next()
                .unwrap_or("")
                .split(' ')
                .count()
        })
        .max()
        .unwrap();
    assert!(longest >= 200, "curve polyline has {longest} points");
}

/// `ChartStyle::colors` colours the series in order: ZV and ZVD drawn with the palette's third
/// and fourth colours (#009E73, #CC79A7) use neither of the first two.
#[test]
fn style_colors_colour_the_series_in_order() {
    let mode = Mode::new(2.0, 0.05).unwrap();
    let (a, b) = (zv(&mode).unwrap(), zvd(&mode).unwrap());
    let [c0, c1, c2, c3] = input_shaping::chart::SERIES_COLORS;
    let style = ChartStyle {
        colors: [c2, c3, c0, c1],
        ..ChartStyle::default()
    };
    let default =
        svg(|x| draw_impulses(x, &[("ZV", &a), ("ZVD", &b)], &ChartStyle::default()).unwrap())
            .to_uppercase();
    let picked =
        svg(|x| draw_impulses(x, &[("ZV", &a), ("ZVD", &b)], &style).unwrap()).to_uppercase();
    for hex in ["#0072B2", "#D55E00"] {
        assert!(default.contains(hex) && !picked.contains(hex), "{hex}");
    }
    for hex in ["#009E73", "#CC79A7"] {
        assert!(picked.contains(hex) && !default.contains(hex), "{hex}");
    }
}

#[test]
fn scale_enlarges_fonts() {
    let mode = Mode::new(2.0, 0.0).unwrap();
    let s = zv(&mode).unwrap();
    let small = svg(|a| draw_impulses(a, &[("ZV", &s)], &ChartStyle::default()).unwrap());
    let large = svg(|a| {
        draw_impulses(
            a,
            &[("ZV", &s)],
            &ChartStyle {
                scale: 2.0,
                ..ChartStyle::default()
            },
        )
        .unwrap()
    });
    let ratio = caption_font_size(&large) / caption_font_size(&small);
    assert!((ratio - 2.0).abs() < 1e-9, "caption font ratio {ratio}");
}
