//! Shaper recommendation over a measured spectrum (issue 7).

mod common;

use common::residual_by_superposition;
use input_shaping::design::zero_vibration::zv;
use input_shaping::measure::identify::{identify, IdentifyOptions};
use input_shaping::measure::recommend::{
    recommend, remaining_vibration, Criterion, MeasuredMode, MeasuredSpectrum, RecommendOptions,
};
use input_shaping::{Error, Mode};
use std::f64::consts::PI;
use wasm_bindgen_test::wasm_bindgen_test;

/// |H|² of an acceleration response with modes (f, ζ, g), on 0 … 200 Hz.
fn spectrum(modes: &[(f64, f64, f64)]) -> MeasuredSpectrum {
    let frequency_hz: Vec<f64> = (0..=1000).map(|k| k as f64 * 0.2).collect();
    let psd = frequency_hz
        .iter()
        .map(|&f| {
            let w = 2.0 * PI * f;
            let (mut re, mut im) = (0.0, 0.0);
            for &(fm, z, g) in modes {
                let wn = 2.0 * PI * fm;
                let (a, b) = (wn * wn - w * w, 2.0 * z * wn * w);
                let d = a * a + b * b;
                re += g * w * w * a / d;
                im -= g * w * w * b / d;
            }
            re * re + im * im + 1e-3
        })
        .collect();
    MeasuredSpectrum {
        frequency_hz,
        psd,
        ..MeasuredSpectrum::default()
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn remaining_vibration_is_klippers_formula() {
    // Klipper's _estimate_remaining_vibrations, with V from the time response (tests/common)
    // instead of the library's formula.
    let s = spectrum(&[(40.0, 0.05, 1.0)]);
    let shaper = zv(&Mode::new(42.0, 0.1).unwrap()).unwrap();
    for zeta in [0.0, 0.05, 0.15] {
        let p_max = s.psd.iter().copied().fold(0.0, f64::max);
        let thr = p_max / 20.0;
        let (mut rem, mut all) = (0.0, 0.0);
        for (&f, &p) in s.frequency_hz.iter().zip(&s.psd) {
            let v = if f == 0.0 {
                1.0
            } else {
                residual_by_superposition(&shaper, &Mode::new(f, zeta).unwrap())
            };
            rem += (v * p - thr).max(0.0);
            all += (p - thr).max(0.0);
        }
        let want = rem / all;
        let got = remaining_vibration(&shaper, &s.frequency_hz, &s.psd, zeta, 1.0);
        assert!((got - want).abs() < 1e-9, "ζ {zeta}: {got} vs {want}");
    }
}

fn measured(f: f64, z: f64) -> MeasuredMode {
    MeasuredMode {
        frequency_hz: f,
        damping: z,
        frequency_uncertainty_hz: 0.01 * f,
        damping_uncertainty: 0.1 * z,
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn recommendation_is_deterministic_and_ranked() {
    let s = spectrum(&[(35.0, 0.05, 1.0), (80.0, 0.08, 0.7)]);
    let modes = [measured(35.0, 0.05), measured(80.0, 0.08)];
    let options = RecommendOptions::default();
    let a = recommend(&s, &modes, &options).unwrap();
    let b = recommend(&s, &modes, &options).unwrap();
    assert_eq!(
        serde_json::to_string(&a).unwrap(),
        serde_json::to_string(&b).unwrap()
    );
    // Six families for both modes and for the dominant one.
    assert_eq!(a.ranked.len(), 12);
    assert_eq!(a.recommended, 0);
    let best = &a.ranked[0];
    assert!(best.acceptable, "{:?}", best.label);
    for c in a.ranked.iter().filter(|c| c.acceptable) {
        assert!(best.duration_s <= c.duration_s + 1e-12);
        assert!(c.remaining_vibration >= c.nominal_remaining_vibration - 1e-12);
        assert!(c.smoothing.unwrap() > 0.0 && c.max_accel.unwrap() > 0.0);
    }
    // The worst case covers ζ ± 2σ of each mode.
    assert!(a.damping_tested.contains(&0.04) && a.damping_tested.contains(&(0.08 + 0.016)));
    assert_eq!(a.frequency_factors, vec![0.98, 1.0, 1.02]);
}

#[wasm_bindgen_test(unsupported = test)]
fn klipper_criterion_ranks_by_score() {
    let s = spectrum(&[(50.0, 0.1, 1.0)]);
    let r = recommend(
        &s,
        &[measured(50.0, 0.1)],
        &RecommendOptions {
            criterion: Criterion::Klipper,
            ..RecommendOptions::default()
        },
    )
    .unwrap();
    let scores: Vec<f64> = r.ranked.iter().map(|c| c.klipper_score.unwrap()).collect();
    assert!(scores.windows(2).all(|w| w[0] <= w[1]), "{scores:?}");
    for c in &r.ranked {
        let v = c.remaining_vibration;
        let want = c.smoothing.unwrap() * (v.powf(1.5) + 0.2 * v + 0.01);
        assert!((c.klipper_score.unwrap() - want).abs() < 1e-12);
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn recommendation_from_identified_modes() {
    // A synthetic two-mode spectrum → identify → recommend: every step of the page's flow.
    let fs = 1000.0;
    let mut state = 7u64;
    let mut noise = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let x: Vec<f64> = (0..40_000)
        .map(|i| {
            let t = i as f64 / fs;
            let decay = |f: f64, z: f64, a: f64| {
                let w = 2.0 * PI * f;
                if t < 1.0 {
                    0.0
                } else {
                    a * (-z * w * (t - 1.0)).exp() * (w * (1.0 - z * z).sqrt() * (t - 1.0)).sin()
                }
            };
            decay(30.0, 0.02, 1.0) + decay(70.0, 0.05, 0.8) + 0.01 * noise()
        })
        .collect();
    let id = identify(&x, &IdentifyOptions::new(fs)).unwrap();
    assert_eq!(id.modes.len(), 2);
    let modes: Vec<MeasuredMode> = id
        .modes
        .iter()
        .map(|m| MeasuredMode {
            frequency_hz: m.frequency_hz,
            damping: m.damping,
            frequency_uncertainty_hz: m.frequency_uncertainty_hz,
            damping_uncertainty: m.damping_uncertainty,
        })
        .collect();
    let spectrum = MeasuredSpectrum {
        frequency_hz: id.spectrum.frequency_hz.clone(),
        psd: id.spectrum.psd.clone(),
        ..MeasuredSpectrum::default()
    };
    let r = recommend(&spectrum, &modes, &RecommendOptions::default()).unwrap();
    assert!(r.ranked[r.recommended].remaining_vibration < 0.05);
}

#[wasm_bindgen_test(unsupported = test)]
fn bad_recommendation_inputs_name_the_field() {
    let s = spectrum(&[(50.0, 0.1, 1.0)]);
    let m = [measured(50.0, 0.1)];
    let field = |e: Error| e.field().unwrap_or("").to_string();
    let mut bad = s.clone();
    bad.psd[3] = f64::NAN;
    assert_eq!(
        field(recommend(&bad, &m, &RecommendOptions::default()).unwrap_err()),
        "spectrum.psd[3]"
    );
    let mut bad = s.clone();
    bad.psd.pop();
    assert_eq!(
        field(recommend(&bad, &m, &RecommendOptions::default()).unwrap_err()),
        "spectrum.frequencyHz"
    );
    assert_eq!(
        field(recommend(&s, &[], &RecommendOptions::default()).unwrap_err()),
        "modes"
    );
    assert_eq!(
        field(recommend(&s, &[measured(50.0, 1.5)], &RecommendOptions::default()).unwrap_err()),
        "modes[0].damping"
    );
    // A family that cannot be designed for the modes is skipped, not fatal.
    let r = recommend(&s, &[measured(50.0, 0.6)], &RecommendOptions::default()).unwrap();
    assert!(
        r.skipped.iter().any(|k| k.label.starts_with("Two-hump EI")),
        "{:?}",
        r.skipped
    );
    assert!(!r.ranked.is_empty());
    let o = RecommendOptions {
        max_remaining_vibration: 0.0,
        ..RecommendOptions::default()
    };
    assert_eq!(
        field(recommend(&s, &m, &o).unwrap_err()),
        "maxRemainingVibration"
    );
}
