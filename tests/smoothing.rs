//! Klipper-compatible smoothing and max_accel against closed forms of Klipper's definitions
//! (klippy/extras/shaper_calibrate.py `_get_shaper_smoothing`, `find_shaper_max_accel`).

use input_shaping::design::zero_vibration::zv;
use input_shaping::smoothing::{klipper_figures, max_accel, smoothing};
use input_shaping::{Mode, Shaper};
use wasm_bindgen_test::wasm_bindgen_test;

/// ZV at ζ = 0, frequency f: A = [½, ½], t = [0, 1/(2f)], centroid t_s = 1/(4f), so with
/// d = 1/(4f): offset₁₈₀ = a d²/2 and offset₉₀ = √2 · ½ (scv + a d/2) d.
fn zv_closed_form(f: f64, a: f64, scv: f64) -> f64 {
    let d = 1.0 / (4.0 * f);
    let o180 = 0.5 * a * d * d;
    let o90 = std::f64::consts::SQRT_2 * 0.5 * (scv + 0.5 * a * d) * d;
    o90.max(o180)
}

#[wasm_bindgen_test(unsupported = test)]
fn zv_smoothing_matches_closed_form() {
    for f in [20.0, 45.0, 80.0] {
        let s = zv(&Mode::new(f, 0.0).unwrap()).unwrap();
        for (a, scv) in [(5000.0, 5.0), (1000.0, 0.0), (20000.0, 5.0)] {
            let got = smoothing(&s, a, scv).unwrap();
            let want = zv_closed_form(f, a, scv);
            assert!(
                (got - want).abs() < 1e-15 * want.max(1.0),
                "f={f} a={a}: {got} vs {want}"
            );
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn max_accel_is_where_smoothing_reaches_0_12() {
    for f in [30.0, 45.0, 60.0] {
        let s = zv(&Mode::new(f, 0.1).unwrap()).unwrap();
        let a = max_accel(&s, 5.0).unwrap();
        assert!(smoothing(&s, a, 5.0).unwrap() <= 0.12);
        assert!(smoothing(&s, a + 1e-6, 5.0).unwrap() > 0.12 - 1e-12);
        // Higher frequency → shorter shaper → more acceleration allowed.
        let faster = zv(&Mode::new(f * 1.5, 0.1).unwrap()).unwrap();
        assert!(max_accel(&faster, 5.0).unwrap() > a);
    }
    // Solving the closed form for a (offset₉₀ branch, scv = 0 → both branches linear in a):
    // ZV at ζ=0 with scv=0: o90 = √2/4 · a d², o180 = a d²/2 → o180 dominates, a = 0.24/d².
    let s = zv(&Mode::new(50.0, 0.0).unwrap()).unwrap();
    let d = 1.0 / 200.0;
    assert!((max_accel(&s, 0.0).unwrap() - 0.24 / (d * d)).abs() < 1e-6);
}

#[wasm_bindgen_test(unsupported = test)]
fn degenerate_shapers() {
    let id = Shaper::identity();
    assert_eq!(smoothing(&id, 5000.0, 5.0).unwrap(), 0.0);
    assert_eq!(max_accel(&id, 5.0).unwrap(), f64::INFINITY);
    let s = zv(&Mode::new(40.0, 0.0).unwrap()).unwrap();
    assert_eq!(
        smoothing(&s, f64::NAN, 5.0).unwrap_err().field(),
        Some("accel")
    );
    assert_eq!(
        klipper_figures(&s, f64::INFINITY).unwrap_err().field(),
        Some("scv")
    );
}

#[test]
fn max_accel_of_six_mode_convolutions_is_where_smoothing_reaches_0_12() {
    // The bisection's smoothing from three sums (max_accel) against `smoothing`, which walks
    // the impulses at each acceleration (15 625 of them for ZV-D³ over six modes).
    use input_shaping::design::design_for;
    use input_shaping::ShaperSpec;
    let modes: Vec<Mode> = [1.2, 3.4, 7.9, 13.0, 21.0, 34.0]
        .iter()
        .map(|&f| Mode::new(f, 0.02).unwrap())
        .collect();
    // At scv 5 mm/s these shapers (0.5 … 2 s long) smooth by more than 0.12 mm at any
    // acceleration (max_accel 0); at scv 0 smoothing is proportional to it, so the bisection runs.
    for spec in [
        ShaperSpec::Zv,
        ShaperSpec::Zvdd,
        ShaperSpec::Zvdn { derivatives: 3 },
    ] {
        let s = design_for(&spec, &modes).unwrap();
        assert_eq!(max_accel(&s, 5.0).unwrap(), 0.0);
        assert!(smoothing(&s, 1e-9, 5.0).unwrap() > 0.12);
        let a = max_accel(&s, 0.0).unwrap();
        assert!(a > 0.0 && a.is_finite(), "{spec:?}: {a}");
        let at = smoothing(&s, a, 0.0).unwrap();
        let beyond = smoothing(&s, a * (1.0 + 1e-6), 0.0).unwrap();
        assert!(
            at <= 0.12 + 1e-12 && (at - 0.12).abs() < 1e-9,
            "{spec:?}: {at}"
        );
        assert!(beyond > 0.12, "{spec:?}: {beyond}");
    }
}
