//! The measured-spectrum chart rendered natively into SVG through the code the page draws on
//! canvas.
#![cfg(not(target_arch = "wasm32"))]

use input_shaping::chart::measured::PSD_TITLES;
use input_shaping::chart::{draw_measured_spectrum, ChartStyle};
use plotters::prelude::*;

fn texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| t.split_once('>'))
        .map(|(_, rest)| rest.split('<').next().unwrap_or("").trim().to_string())
        .collect()
}

#[test]
fn spectrum_chart_marks_and_labels_each_peak() {
    let f: Vec<f64> = (0..5000).map(|k| k as f64 * 0.05).collect();
    let p: Vec<f64> = f
        .iter()
        .map(|&x| {
            1.0 / (1.0 + ((x - 40.0) / 0.8).powi(2))
                + 0.5 / (1.0 + ((x - 90.0) / 2.0).powi(2))
                + 1e-4
        })
        .collect();
    let peaks = vec![(40.0, "40.0 Hz".to_string()), (90.0, "90.0 Hz".to_string())];
    let mut out = String::new();
    {
        let area = SVGBackend::with_string(&mut out, (640, 360)).into_drawing_area();
        draw_measured_spectrum(
            &area,
            &f,
            &p,
            &peaks,
            Some(150.0),
            PSD_TITLES,
            &ChartStyle::default(),
        )
        .unwrap();
    }
    let t = texts(&out);
    for want in [
        "Measured spectrum (Welch PSD)",
        "frequency (Hz)",
        "PSD (dB)",
        "40.0 Hz",
        "90.0 Hz",
    ] {
        assert!(t.iter().any(|s| s == want), "{want} missing: {t:?}");
    }
    assert_eq!(out.matches("<circle").count(), 2, "one marker per peak");
    // The curve is reduced to at most MAX_DRAWN_POINTS points: 3000 bins ≤ 150 Hz → 1500.
    let n = out
        .split("points=\"")
        .skip(1)
        .map(|p| p.split('"').next().unwrap_or("").split_whitespace().count())
        .max()
        .unwrap_or(0);
    assert!(n > 1000 && n <= 2000, "{n} points");
}

#[test]
fn spectrum_chart_takes_its_titles() {
    let mut out = String::new();
    {
        let area = SVGBackend::with_string(&mut out, (320, 200)).into_drawing_area();
        draw_measured_spectrum(
            &area,
            &[0.0, 1.0, 2.0],
            &[1.0, 2.0, 1.0],
            &[],
            None,
            ("FFT", "|X|² (dB)"),
            &ChartStyle::default(),
        )
        .unwrap();
    }
    let t = texts(&out);
    assert!(
        t.contains(&"FFT".to_string()) && t.contains(&"|X|² (dB)".to_string()),
        "{t:?}"
    );
}

#[test]
fn spectrum_chart_rejects_mismatched_data() {
    let mut out = String::new();
    let area = SVGBackend::with_string(&mut out, (100, 100)).into_drawing_area();
    assert!(draw_measured_spectrum(
        &area,
        &[1.0, 2.0],
        &[1.0],
        &[],
        None,
        PSD_TITLES,
        &ChartStyle::default()
    )
    .is_err());
}
