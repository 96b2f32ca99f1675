//! The Klipper-style measured chart (crate/chart/klipper.rs) rendered natively into SVG through
//! the code the page draws on canvas.
#![cfg(not(target_arch = "wasm32"))]

use input_shaping::chart::klipper::{PSD_COLORS, SHAPER_COLORS};
use input_shaping::chart::{draw_klipper_chart, ChartStyle, KlipperChart, ShaperCurve};
use plotters::prelude::*;

fn texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| t.split_once('>'))
        .map(|(_, rest)| rest.split('<').next().unwrap_or("").trim().to_string())
        .collect()
}

fn hex(c: RGBColor) -> String {
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}

/// The points of every polyline drawn in `color` (one list per polyline).
fn polylines(svg: &str, color: RGBColor) -> Vec<Vec<(f64, f64)>> {
    let want = format!("stroke=\"{}\"", hex(color));
    svg.split("<polyline")
        .skip(1)
        .filter(|p| p.split("/>").next().unwrap_or("").contains(&want))
        .map(|p| {
            p.split("points=\"")
                .nth(1)
                .and_then(|s| s.split('"').next())
                .unwrap_or("")
                .split_whitespace()
                .filter_map(|xy| xy.split_once(','))
                .map(|(x, y)| (x.parse().unwrap(), y.parse().unwrap()))
                .collect()
        })
        .collect()
}

/// A resonance at 50 Hz on x (and a weaker one at 80 Hz on y), bins 0 … 250 Hz.
fn data() -> (Vec<f64>, [Vec<f64>; 4]) {
    let f: Vec<f64> = (0..=500).map(|k| k as f64 * 0.5).collect();
    let peak = |f: f64, at: f64, h: f64| h / (1.0 + ((f - at) / 2.0).powi(2));
    let x: Vec<f64> = f.iter().map(|&f| peak(f, 50.0, 4.0e4)).collect();
    let y: Vec<f64> = f.iter().map(|&f| peak(f, 80.0, 1.0e4)).collect();
    let z: Vec<f64> = f.iter().map(|_| 100.0).collect();
    let sum = (0..f.len()).map(|i| x[i] + y[i] + z[i]).collect();
    (f, [sum, x, y, z])
}

#[test]
fn klipper_chart_draws_the_psds_the_shapers_and_the_psd_after_the_selected_one() {
    let (f, [sum, x, y, z]) = data();
    let quarter = vec![0.25; f.len()];
    let ramp: Vec<f64> = f.iter().map(|f| (f / 100.0).min(1.0)).collect();
    let mut out = String::new();
    {
        let area = SVGBackend::with_string(&mut out, (800, 420)).into_drawing_area();
        let chart = KlipperChart {
            frequency_hz: &f,
            psd_sum: &sum,
            psd_x: Some(&x),
            psd_y: Some(&y),
            psd_z: Some(&z),
            shapers: vec![
                ShaperCurve {
                    values: &ramp,
                    color: None,
                    selected: false,
                    dotted: false,
                },
                ShaperCurve {
                    values: &quarter,
                    color: None,
                    selected: true,
                    dotted: false,
                },
            ],
            after: None,
            max_hz: None,
            title: None,
        };
        draw_klipper_chart(&area, &chart, &ChartStyle::default()).unwrap();
    }
    let t = texts(&out);
    for want in [
        "Frequency response and shapers",
        "frequency (Hz)",
        "power spectral density (×1e4)",
        "shaper vibration ratio",
        "X+Y+Z",
        "X",
        "Y",
        "Z",
        "after shaper",
        "acceptable vibrations",
    ] {
        assert!(t.iter().any(|s| s == want), "{want} missing: {t:?}");
    }
    // The frequency axis ends at Klipper's default 200 Hz (bins go to 250).
    assert!(t.iter().any(|s| s == "200"), "{t:?}");
    assert!(!t.iter().any(|s| s == "250"), "{t:?}");
    // Each PSD curve once, in Klipper's colours.
    let curve = |c| {
        polylines(&out, c)
            .into_iter()
            .max_by_key(|p| p.len())
            .unwrap()
    };
    let (s, a) = (curve(PSD_COLORS[0]), curve(PSD_COLORS[4]));
    for c in &PSD_COLORS[1..4] {
        assert!(!polylines(&out, *c).is_empty(), "{c:?} drawn");
    }
    // The PSD after the selected shaper is PSD·V = a quarter of the sum's height above the
    // axis, at every frequency: compare the peaks' heights above the axis (the 0 Hz bin's
    // 5.7e-2·peak offset of the z floor aside, the baseline is the bottom of the plot).
    let base = s.iter().map(|p| p.1).fold(f64::MIN, f64::max);
    let base_after = a.iter().map(|p| p.1).fold(f64::MIN, f64::max);
    let top_of = |p: &[(f64, f64)]| p.iter().map(|p| p.1).fold(f64::MAX, f64::min);
    // Heights above the zero line (whose pixel is found from the floor: the floor's PSD is
    // z = 100 plus the peaks' tails, small against 4e4, so both baselines sit within 1 px of
    // it, scaled by their own factor).
    let zero = {
        // The plot's bottom edge: the x-axis line is drawn at PSD 0.
        out.split("<line")
            .skip(1)
            .filter_map(|l| {
                let get = |k: &str| {
                    l.split(&format!("{k}=\""))
                        .nth(1)
                        .and_then(|v| v.split('"').next())
                        .and_then(|v| v.parse::<f64>().ok())
                };
                match (get("y1"), get("y2")) {
                    (Some(a), Some(b)) if a == b => Some(a),
                    _ => None,
                }
            })
            .fold(f64::MIN, f64::max)
    };
    assert!(
        zero >= base && zero >= base_after,
        "zero line {zero} below the curves"
    );
    let ratio = (zero - top_of(&a)) / (zero - top_of(&s));
    assert!((ratio - 0.25).abs() < 0.02, "after/sum height {ratio}");
    // Two shaper curves, dashed on the second axis (a dashed curve is many short segments);
    // the selected one is drawn last and thicker.
    let dashes =
        |c| polylines(&out, c).len() + out.matches(&format!("stroke=\"{}\"", hex(c))).count();
    assert!(dashes(SHAPER_COLORS[0]) > 20 && dashes(SHAPER_COLORS[1]) > 20);
    let first_selected = out
        .find(&format!("stroke=\"{}\"", hex(SHAPER_COLORS[1])))
        .unwrap();
    let last_other = out
        .rfind(&format!("stroke=\"{}\"", hex(SHAPER_COLORS[0])))
        .unwrap();
    assert!(
        first_selected > last_other,
        "the selected shaper is drawn over the others"
    );
    // The ramp reaches V = 1 at 100 Hz: the second axis reaches 1.
    assert!(t.iter().any(|s| s == "1.0" || s == "1"), "{t:?}");
}

#[test]
fn klipper_chart_without_axes_or_shapers_and_given_after_curve() {
    let (f, [sum, ..]) = data();
    let after: Vec<f64> = sum.iter().map(|p| 0.5 * p).collect();
    let mut out = String::new();
    {
        let area = SVGBackend::with_string(&mut out, (500, 300)).into_drawing_area();
        let chart = KlipperChart {
            frequency_hz: &f,
            psd_sum: &sum,
            after: Some(&after),
            max_hz: Some(120.0),
            title: Some("resonances_x.csv"),
            ..KlipperChart::default()
        };
        draw_klipper_chart(&area, &chart, &ChartStyle::default()).unwrap();
    }
    let t = texts(&out);
    assert!(t.iter().any(|s| s == "resonances_x.csv"), "{t:?}");
    assert!(t.iter().any(|s| s == "after shaper"), "{t:?}");
    assert!(
        !t.iter().any(|s| s == "X"),
        "no X curve without psdX: {t:?}"
    );
    assert!(polylines(&out, PSD_COLORS[1]).is_empty());
}

#[test]
fn klipper_chart_refuses_curves_of_the_wrong_length() {
    let (f, [sum, x, ..]) = data();
    let short = vec![0.5; 3];
    let mut out = String::new();
    let area = SVGBackend::with_string(&mut out, (300, 200)).into_drawing_area();
    let err = |chart: KlipperChart| {
        draw_klipper_chart(&area, &chart, &ChartStyle::default())
            .unwrap_err()
            .to_string()
    };
    let e = err(KlipperChart {
        frequency_hz: &f,
        psd_sum: &sum[..10],
        ..Default::default()
    });
    assert!(
        e.contains("psdSum") && e.contains("10 values for 501"),
        "{e}"
    );
    let e = err(KlipperChart {
        frequency_hz: &f,
        psd_sum: &sum,
        psd_x: Some(&x),
        shapers: vec![ShaperCurve {
            values: &short,
            color: None,
            selected: true,
            dotted: false,
        }],
        ..Default::default()
    });
    assert!(e.contains("shapers[0].values"), "{e}");
    let e = err(KlipperChart {
        frequency_hz: &f[..1],
        psd_sum: &sum[..1],
        ..Default::default()
    });
    assert!(e.contains("frequencyHz"), "{e}");
}
