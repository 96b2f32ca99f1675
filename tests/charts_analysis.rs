//! The sensitivity map and damping sensitivity charts, rendered natively into SVG strings
//! through the same code the page would draw on canvas, and the map's Vtol contour.
#![cfg(not(target_arch = "wasm32"))]

use input_shaping::chart::map::{contour_segments, scale_color, COLOR_LEVELS};
use input_shaping::chart::{draw_damping_sensitivity, draw_sensitivity_map, ChartStyle};
use input_shaping::design::zero_vibration::{zv, zvd};
use input_shaping::vibration::{
    damping_sensitivity, sensitivity_map, vibration_rad, DampingSensitivityOptions, SensitivityMap,
    SensitivityMapOptions,
};
use input_shaping::Mode;
use plotters::prelude::*;
use std::f64::consts::PI;

/// The texts of an SVG, trimmed.
fn texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| t.split_once('>'))
        .map(|(_, rest)| rest.split('<').next().unwrap_or("").trim().to_string())
        .collect()
}

fn svg(draw: impl FnOnce(&DrawingArea<SVGBackend, plotters::coord::Shift>)) -> String {
    let mut out = String::new();
    {
        let area = SVGBackend::with_string(&mut out, (720, 420)).into_drawing_area();
        draw(&area);
    }
    out
}

fn hex(c: RGBColor) -> String {
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}

/// ZV for 2 Hz, ζ = 0, mapped over 1.5 … 2.5 Hz and ζ = 0 … 0.1.
fn zv_map(frequency_points: usize, damping_points: usize) -> SensitivityMap {
    let s = zv(&Mode::new(2.0, 0.0).unwrap()).unwrap();
    sensitivity_map(
        &s,
        &SensitivityMapOptions {
            from_hz: 1.5,
            to_hz: 2.5,
            frequency_points,
            damping_from: 0.0,
            damping_to: 0.1,
            damping_points,
        },
    )
    .unwrap()
}

/// Every point of the traced contour lies where V = Vtol (checked with `vibration_rad`, up to
/// the linear interpolation's error on this grid), and on the ζ = 0 edge the contour meets the
/// band edges of ZV's |cos(πf/(2f_m))| curve, f = f_m(1 ± (2/π)·asin(Vtol)) (Singhose 2009
/// Fig. 7).
#[test]
fn contour_follows_v_equals_vtol() {
    let map = zv_map(201, 101);
    let s = zv(&Mode::new(2.0, 0.0).unwrap()).unwrap();
    let segments = contour_segments(&map, 0.05);
    assert!(segments.len() > 50, "{} segments", segments.len());
    for [a, b] in &segments {
        for (f, z) in [a, b] {
            let v = vibration_rad(s.impulses(), 2.0 * PI * f, *z);
            assert!((v - 0.05).abs() < 2e-3, "V({f}, {z}) = {v}");
        }
    }
    let delta = 2.0 / PI * 0.05_f64.asin();
    for edge in [2.0 * (1.0 - delta), 2.0 * (1.0 + delta)] {
        let hit = segments
            .iter()
            .flat_map(|s| s.iter())
            .any(|&(f, z)| z == 0.0 && (f - edge).abs() < 1e-4);
        assert!(hit, "no contour point at ({edge}, 0)");
    }
    // Closed form of ZV at f_m over damping (V = ½|e^{−πζ} + e^{iπ√(1−ζ²)}|) is above 5 % from
    // ζ ≈ 0.032 on, so the contour stays below that damping.
    let z_top = segments
        .iter()
        .flat_map(|s| s.iter())
        .map(|p| p.1)
        .fold(0.0, f64::max);
    assert!(z_top > 0.03 && z_top < 0.034, "contour reaches ζ = {z_top}");
}

/// A saddle cell (high at bottom-left and top-right, low elsewhere) is resolved by the mean of
/// its corners: at mean = level the high corners are cut off, giving two segments joining the
/// edge midpoints.
#[test]
fn contour_resolves_saddles_and_ignores_bad_maps() {
    let map = SensitivityMap {
        frequency_hz: vec![0.0, 1.0],
        damping: vec![0.0, 1.0],
        vibration: vec![1.0, 0.0, 0.0, 1.0],
    };
    let mut segments = contour_segments(&map, 0.5);
    segments.sort_by(|a, b| a[0].partial_cmp(&b[0]).unwrap());
    assert_eq!(
        segments,
        vec![[(0.5, 0.0), (0.0, 0.5)], [(1.0, 0.5), (0.5, 1.0)]]
    );
    let bad = SensitivityMap {
        vibration: vec![1.0],
        ..map
    };
    assert!(contour_segments(&bad, 0.5).is_empty());
}

#[test]
fn map_chart_has_cells_contour_colour_bar_and_labels() {
    let map = zv_map(81, 41);
    let out = svg(|a| {
        draw_sensitivity_map(a, &map, Some(0.05), &[(2.0, 0.0)], &ChartStyle::default()).unwrap()
    });
    let t = texts(&out);
    for want in [
        "Residual vibration V(f, ζ)",
        "frequency (Hz)",
        "damping ratio ζ",
        "V (%)",
        "V = Vtol (5.000 %)",
    ] {
        assert!(t.contains(&want.to_string()), "{want} missing from {t:?}");
    }
    // Merged runs: at least one rectangle per row, fewer than one per cell.
    let rects = out.matches("<rect").count();
    assert!(rects > 41 && rects < 81 * 41, "{rects} rectangles");
    // The darkest and the brightest level are both used (V spans 0 … its maximum).
    let dark = hex(scale_color(0.5 / COLOR_LEVELS as f64));
    let bright = hex(scale_color(
        (COLOR_LEVELS as f64 - 0.5) / COLOR_LEVELS as f64,
    ));
    let upper = out.to_uppercase();
    assert!(upper.contains(&dark) && upper.contains(&bright));
    // The contour is drawn in white, one path per segment.
    let white_lines = out
        .split("<polyline")
        .skip(1)
        .filter(|p| p.to_uppercase().contains("STROKE=\"#FFFFFF\""))
        .count();
    assert!(
        white_lines >= contour_segments(&map, 0.05).len(),
        "{white_lines} white polylines"
    );
}

#[test]
fn map_chart_rejects_an_inconsistent_map() {
    let map = SensitivityMap {
        frequency_hz: vec![1.0, 2.0, 3.0],
        damping: vec![0.0, 0.1],
        vibration: vec![0.0; 5],
    };
    let mut result = None;
    svg(|a| {
        result = Some(draw_sensitivity_map(
            a,
            &map,
            None,
            &[],
            &ChartStyle::default(),
        ))
    });
    let err = result.unwrap().unwrap_err();
    assert_eq!(err.field(), Some("map.vibration"), "{err}");
    let decreasing = SensitivityMap {
        frequency_hz: vec![2.0, 1.0],
        damping: vec![0.0, 0.1],
        vibration: vec![0.0; 4],
    };
    let mut result = None;
    svg(|a| {
        result = Some(draw_sensitivity_map(
            a,
            &decreasing,
            None,
            &[],
            &ChartStyle::default(),
        ))
    });
    assert_eq!(
        result.unwrap().unwrap_err().field(),
        Some("map.frequencyHz")
    );
}

#[test]
fn damping_chart_has_curves_vtol_and_marker() {
    let mode = Mode::new(2.0, 0.1).unwrap();
    let options = DampingSensitivityOptions {
        frequency_hz: 2.0,
        from_damping: 0.0,
        to_damping: 0.4,
        points: 150,
    };
    let a = damping_sensitivity(&zv(&mode).unwrap(), &options).unwrap();
    let b = damping_sensitivity(&zvd(&mode).unwrap(), &options).unwrap();
    let out = svg(|area| {
        draw_damping_sensitivity(
            area,
            &[("ZV", &a), ("ZVD", &b)],
            Some(0.05),
            &[0.1],
            &ChartStyle::default(),
        )
        .unwrap()
    });
    let t = texts(&out);
    for want in [
        "Residual vibration V(ζ)",
        "damping ratio ζ",
        "vibration (%)",
        "Vtol 5.000 %",
        "ZV",
        "ZVD",
    ] {
        assert!(t.contains(&want.to_string()), "{want} missing from {t:?}");
    }
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
    assert!(longest >= 150, "curve polyline has {longest} points");
    // Both series colours are present (first two Okabe–Ito hues).
    let upper = out.to_uppercase();
    assert!(upper.contains("#0072B2") && upper.contains("#D55E00"));
}

/// The page's bitmap cells (`MapCells::Bitmap`): each pixel takes the colour of the cell whose
/// backend edges enclose it — the pixels `MapCells::Rectangles` fills — and pixels beyond the
/// last edge stay white. Levels: V/top quantised to 64 steps, coloured at their midpoints.
#[test]
fn map_bitmap_colours_each_pixel_by_its_cell() {
    use input_shaping::chart::map::raster_cells;
    let map = SensitivityMap {
        frequency_hz: vec![1.0, 2.0, 3.0],
        damping: vec![0.0, 0.1],
        // Row k = 0 (ζ = 0, drawn at the bottom), then row k = 1.
        vibration: vec![0.0, 0.5, 1.0, 0.25, f64::NAN, 0.75],
    };
    let (xe, ye) = ([0, 10, 20, 30], [20, 10, 0]);
    let b = raster_cells(&map, 1.0, (0, 35), (0, 20), &xe, &ye);
    assert_eq!(
        (b.origin, b.size, b.rgb.len()),
        ((0, 0), (35, 20), 35 * 20 * 3)
    );
    let px = |x: usize, y: usize| {
        let i = 3 * (y * 35 + x);
        format!("#{:02X}{:02X}{:02X}", b.rgb[i], b.rgb[i + 1], b.rgb[i + 2])
    };
    let level = |v: f64| {
        let l = ((v * COLOR_LEVELS as f64) as usize).min(COLOR_LEVELS - 1);
        hex(scale_color((l as f64 + 0.5) / COLOR_LEVELS as f64))
    };
    // Bottom row (y 10 … 19) is ζ = 0; the top row (y 0 … 9) is ζ = 0.1.
    assert_eq!(px(0, 19), level(0.0));
    assert_eq!(px(15, 10), level(0.5));
    assert_eq!(px(29, 12), level(1.0));
    assert_eq!(px(9, 0), level(0.25));
    assert_eq!(px(10, 9), level(1.0), "NaN is drawn as the top level");
    assert_eq!(px(25, 5), level(0.75));
    assert_eq!(px(30, 5), "#FFFFFF", "beyond the last edge");
    assert_eq!(px(34, 19), "#FFFFFF");
}
