//! MZV (Klipper's modified ZV): reproduces Klipper's formula and does what its docs claim.

mod common;

use common::{close, residual_by_superposition};
use input_shaping::design::modified::mzv;
use input_shaping::design::zero_vibration::{zv, zvd};
use input_shaping::vibration::{insensitivity, residual_vibration};
use input_shaping::{design, DesignRequest, Mode, ModeSpec, ShaperSpec};
use std::f64::consts::PI;
use wasm_bindgen_test::wasm_bindgen_test;

/// Klipper `shaper_defs.py` `get_mzv_shaper`, written out independently: amplitudes
/// [1 − 1/√2, (√2 − 1)K, (1 − 1/√2)K²] with K = exp(−0.75ζπ/√(1−ζ²)) at [0, 0.375, 0.75]·t_d,
/// t_d = 1/(f√(1−ζ²)); we return them divided by their sum.
#[wasm_bindgen_test(unsupported = test)]
fn reproduces_klippers_amplitudes_and_times() {
    for (f, z) in [(40.0, 0.1), (57.3, 0.0), (23.0, 0.05), (2.0, 0.3)] {
        let s = mzv(&Mode::new(f, z).unwrap()).unwrap();
        let df = (1.0_f64 - z * z).sqrt();
        let k = (-0.75 * z * PI / df).exp();
        let t_d = 1.0 / (f * df);
        let a = [
            1.0 - 0.5_f64.sqrt(),
            (2.0_f64.sqrt() - 1.0) * k,
            (1.0 - 0.5_f64.sqrt()) * k * k,
        ];
        let sum: f64 = a.iter().sum();
        let t = [0.0, 0.375 * t_d, 0.75 * t_d];
        assert_eq!(s.len(), 3);
        for (i, imp) in s.impulses().iter().enumerate() {
            close(imp.amplitude, a[i] / sum, 1e-15, "amplitude");
            close(imp.time, t[i], 1e-15 * t_d, "time");
        }
    }
}

/// V = 0 at the mode for every damping (library formula and superposition).
#[wasm_bindgen_test(unsupported = test)]
fn vanishes_at_the_mode_with_damping() {
    for z in [0.0, 0.01, 0.1, 0.3, 0.7] {
        let mode = Mode::new(35.0, z).unwrap();
        let s = mzv(&mode).unwrap();
        assert!(residual_vibration(&s, &mode) < 1e-12, "ζ = {z}");
        assert!(residual_by_superposition(&s, &mode) < 1e-9, "ζ = {z}");
        close(s.amplitude_sum(), 1.0, 1e-15, "sum");
    }
}

/// At ζ = 0: second zero at 5/3 f, hump 3 − 2√2 at 4/3 f, I(5 %) from the closed form
/// (≈ 0.1035), between ZV's and ZVD's.
#[wasm_bindgen_test(unsupported = test)]
fn undamped_sensitivity_shape() {
    let mode = Mode::new(1.0, 0.0).unwrap();
    let s = mzv(&mode).unwrap();
    let v = |r: f64| residual_vibration(&s, &Mode::new(r, 0.0).unwrap());
    assert!(v(5.0 / 3.0) < 1e-12, "second zero at 5/3");
    close(
        v(4.0 / 3.0),
        3.0 - 2.0 * 2.0_f64.sqrt(),
        1e-12,
        "hump at 4/3",
    );
    assert!(v(4.0 / 3.0 * 0.99) < v(4.0 / 3.0) && v(4.0 / 3.0 * 1.01) < v(4.0 / 3.0));
    let (a1, a2) = (1.0 - 0.5_f64.sqrt(), 2.0_f64.sqrt() - 1.0);
    let edge = |dv: f64| 4.0 / (3.0 * PI) * ((-a2 + dv) / (2.0 * a1)).acos();
    let width = edge(-0.05) - edge(0.05);
    close(width, 0.1035, 1e-4, "closed-form I(5 %)");
    let band = insensitivity(&s, &mode, 0.05).unwrap();
    close(band.width, width, 1e-9, "I(5 %)");
    let i_zv = insensitivity(&zv(&mode).unwrap(), &mode, 0.05)
        .unwrap()
        .width;
    let i_zvd = insensitivity(&zvd(&mode).unwrap(), &mode, 0.05)
        .unwrap()
        .width;
    assert!(i_zv < band.width && band.width < i_zvd);
    close(s.duration(), 0.75, 1e-15, "duration 0.75 T");
}

/// With damping the second zero is no longer exact but V stays small there.
#[wasm_bindgen_test(unsupported = test)]
fn second_zero_with_damping_is_approximate() {
    let mode = Mode::new(1.0, 0.1).unwrap();
    let s = mzv(&mode).unwrap();
    let v = residual_vibration(&s, &Mode::new(5.0 / 3.0, 0.1).unwrap());
    assert!(v > 1e-6 && v < 0.05, "V(5/3 f) = {v}");
}

/// `family: "mzv"`, per-mode convolution for two modes.
#[wasm_bindgen_test(unsupported = test)]
fn spec_and_two_modes() {
    let spec: ShaperSpec = serde_json::from_str(r#"{"family":"mzv"}"#).unwrap();
    assert_eq!(spec, ShaperSpec::Mzv);
    let modes = vec![
        ModeSpec {
            frequency_hz: 40.0,
            damping: 0.1,
        },
        ModeSpec {
            frequency_hz: 63.0,
            damping: 0.05,
        },
    ];
    let s = design(&DesignRequest {
        modes: modes.clone(),
        shaper: spec,
    })
    .unwrap();
    assert_eq!(s.len(), 9);
    for m in &modes {
        assert!(residual_by_superposition(&s, &Mode::from_spec(m).unwrap()) < 1e-9);
    }
}
