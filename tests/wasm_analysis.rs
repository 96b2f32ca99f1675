//! The analysis part of the JavaScript API in wasm under Node (`wasm-pack test --node`):
//! `sensitivityMap`, `dampingSensitivity`, `dampingInsensitivity`, `robustnessTable`, with
//! plain JS objects in, typed or plain arrays out, and errors thrown with the field.
#![cfg(target_arch = "wasm32")]

use input_shaping::js as wasm;
use js_sys::{Array, Float64Array, Reflect, JSON};
use std::f64::consts::PI;
use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_test::wasm_bindgen_test;

fn js(text: &str) -> JsValue {
    JSON::parse(text).expect("test JSON parses")
}

fn get(v: &JsValue, key: &str) -> JsValue {
    Reflect::get(v, &key.into()).unwrap()
}

fn numbers(v: &JsValue) -> Vec<f64> {
    let a: Array = v.clone().dyn_into().expect("a plain array");
    a.iter().map(|x| x.as_f64().unwrap()).collect()
}

fn error_of(e: JsValue) -> (String, Option<String>, Option<String>) {
    let err: js_sys::Error = e.dyn_into().expect("a JS Error is thrown");
    (
        String::from(err.message()),
        get(&err, "field").as_string(),
        get(&err, "kind").as_string(),
    )
}

/// ZV for an undamped mode at `f_m` Hz: two equal impulses half a period apart.
fn zv(f_m: f64) -> JsValue {
    wasm::design(js(&format!(
        r#"{{"family":"zv","modes":[{{"frequencyHz":{f_m},"damping":0}}]}}"#
    )))
    .unwrap()
}

/// ZV designed for ζ_m = 0 on a plant with damping ζ, at the model frequency (Singhose 2009
/// eqs. 11, 14–15 with K = 1, t₂ = π/ω): V = ½|e^{−πζ} + e^{iπ√(1−ζ²)}|.
fn zv_undamped_design_on_damped_plant(zeta: f64) -> f64 {
    let e = (-PI * zeta).exp();
    let phi = PI * (1.0 - zeta * zeta).sqrt();
    0.5 * (e * e + 1.0 + 2.0 * e * phi.cos()).max(0.0).sqrt()
}

#[wasm_bindgen_test]
fn sensitivity_map_is_row_major_typed_and_matches_closed_form_and_sensitivity() {
    let shaper = zv(2.0);
    let map = wasm::sensitivity_map(
        shaper.clone(),
        js(r#"{"fromHz":0,"toHz":6,"frequencyPoints":61,"dampingFrom":0,"dampingTo":0.3,"dampingPoints":4}"#),
    )
    .unwrap();
    let f = numbers(&get(&map, "frequencyHz"));
    let z = numbers(&get(&map, "damping"));
    let v: Float64Array = get(&map, "vibration").dyn_into().expect("a Float64Array");
    let v = v.to_vec();
    assert_eq!((f.len(), z.len(), v.len()), (61, 4, 244));
    // Row ζ = 0: |cos(πf/(2f_m))| (Singhose 2009 eqs. 11, 14–15).
    for (j, &fj) in f.iter().enumerate() {
        assert!(
            (v[j] - (PI * fj / 4.0).cos().abs()).abs() < 1e-12,
            "f = {fj}"
        );
    }
    // Each row equals `sensitivity` at that damping; at f_m it follows the closed form.
    for (k, &zeta) in z.iter().enumerate() {
        let curve = wasm::sensitivity(
            shaper.clone(),
            js(&format!(
                r#"{{"fromHz":0,"toHz":6,"points":61,"damping":{zeta}}}"#
            )),
        )
        .unwrap();
        let expected = numbers(&get(&curve, "vibration"));
        for (j, want) in expected.iter().enumerate() {
            assert!((v[k * 61 + j] - want).abs() < 1e-12, "ζ = {zeta}, j = {j}");
        }
        let at_model = v[k * 61 + 20];
        assert!((at_model - zv_undamped_design_on_damped_plant(zeta)).abs() < 1e-12);
    }
}

#[wasm_bindgen_test]
fn damping_curve_and_band_match_the_closed_form() {
    let shaper = zv(1.0);
    let curve = wasm::damping_sensitivity(
        shaper.clone(),
        js(r#"{"frequencyHz":1,"fromDamping":0,"toDamping":0.5,"points":11}"#),
    )
    .unwrap();
    let z = numbers(&get(&curve, "damping"));
    let v = numbers(&get(&curve, "vibration"));
    assert_eq!(z.len(), 11);
    for (zeta, v) in z.iter().zip(&v) {
        assert!((v - zv_undamped_design_on_damped_plant(*zeta)).abs() < 1e-12);
    }
    let band =
        wasm::damping_insensitivity(shaper, js(r#"{"frequencyHz":1,"damping":0}"#), 0.05.into())
            .unwrap();
    let (lo, hi) = (
        get(&band, "lowDamping").as_f64().unwrap(),
        get(&band, "highDamping").as_f64().unwrap(),
    );
    assert_eq!(lo, 0.0);
    // The upper edge is where the closed form reaches 5 %.
    assert!(
        (zv_undamped_design_on_damped_plant(hi) - 0.05).abs() < 1e-10,
        "{hi}"
    );
    assert_eq!(get(&band, "width").as_f64(), Some(hi - lo));
}

/// Singhose 2009 Fig. 11 at ζ = 0: ZV-Dⁿ lasts (n+1)/2 periods and I(5 %) =
/// (4/π)·asin(0.05^{1/(n+1)}) since V = |cos(πf/(2f_m))|ⁿ⁺¹.
#[wasm_bindgen_test]
fn robustness_table_defaults_to_parameterless_families_and_takes_specs() {
    let rows: Array = wasm::robustness_table(
        js(r#"{"frequencyHz":2,"damping":0}"#),
        0.05.into(),
        JsValue::UNDEFINED,
    )
    .unwrap()
    .dyn_into()
    .unwrap();
    let families: Vec<String> = rows
        .iter()
        .map(|r| get(&get(&r, "spec"), "family").as_string().unwrap())
        .collect();
    for (n, name) in ["zv", "zvd", "zvdd"].iter().enumerate() {
        let i = families.iter().position(|f| f == name).expect(name);
        let row = rows.get(i as u32);
        let periods = get(&row, "durationPeriods").as_f64().unwrap();
        assert!((periods - (n as f64 + 1.0) / 2.0).abs() < 1e-12, "{name}");
        let width = get(&row, "insensitivity").as_f64().unwrap();
        let expected = 4.0 / PI * 0.05_f64.powf(1.0 / (n as f64 + 1.0)).asin();
        assert!((width - expected).abs() < 1e-8, "{name}: {width}");
        assert!(get(&row, "dampingInsensitivity").as_f64().unwrap() > 0.0);
    }
    assert!(!families.iter().any(|f| f == "zvdn"));

    let rows: Array = wasm::robustness_table(
        js(r#"{"frequencyHz":2,"damping":0}"#),
        0.05.into(),
        js(r#"[{"family":"zvdn","derivatives":3}]"#),
    )
    .unwrap()
    .dyn_into()
    .unwrap();
    assert_eq!(rows.length(), 1);
    let row = rows.get(0);
    assert_eq!(get(&get(&row, "spec"), "derivatives").as_f64(), Some(3.0));
    assert_eq!(get(&row, "impulses").as_f64(), Some(5.0));
    assert!((get(&row, "durationPeriods").as_f64().unwrap() - 2.0).abs() < 1e-12);
    let expected = 4.0 / PI * 0.05_f64.powf(0.25).asin();
    assert!((get(&row, "insensitivity").as_f64().unwrap() - expected).abs() < 1e-8);
}

#[wasm_bindgen_test]
fn analysis_errors_are_thrown_with_field_and_kind_and_the_module_keeps_working() {
    let shaper = zv(1.0);
    let (message, field, kind) = error_of(
        wasm::sensitivity_map(
            shaper.clone(),
            js(r#"{"fromHz":0,"toHz":6,"frequencyPoints":5000,"dampingFrom":0,"dampingTo":0.3,"dampingPoints":4}"#),
        )
        .unwrap_err(),
    );
    assert_eq!(field.as_deref(), Some("frequencyPoints"), "{message}");
    assert_eq!(kind.as_deref(), Some("tooLarge"));
    let (message, field, _) = error_of(
        wasm::sensitivity_map(
            shaper.clone(),
            js(r#"{"fromHz":0,"toHz":6,"frequencyPoints":50,"dampingFrom":0.5,"dampingTo":0.3,"dampingPoints":4}"#),
        )
        .unwrap_err(),
    );
    assert_eq!(field.as_deref(), Some("dampingTo"), "{message}");
    let (message, field, kind) = error_of(
        wasm::sensitivity_map(shaper.clone(), js(r#"{"fromHz":0,"toHz":6}"#)).unwrap_err(),
    );
    assert!(message.contains("frequencyPoints"), "{message}");
    assert_eq!(kind.as_deref(), Some("parse"), "{field:?}");
    let (message, field, _) = error_of(
        wasm::damping_sensitivity(
            shaper.clone(),
            js(r#"{"frequencyHz":-1,"fromDamping":0,"toDamping":0.5,"points":11}"#),
        )
        .unwrap_err(),
    );
    assert_eq!(field.as_deref(), Some("frequencyHz"), "{message}");
    let (message, field, _) = error_of(
        wasm::damping_insensitivity(shaper.clone(), js(r#"{"frequencyHz":1}"#), 2.0.into())
            .unwrap_err(),
    );
    assert_eq!(field.as_deref(), Some("vtol"), "{message}");
    let (message, field, _) = error_of(
        wasm::robustness_table(
            js(r#"{"frequencyHz":1}"#),
            0.05.into(),
            js(r#"[{"family":"zv"},{"family":"zvdn","derivatives":99}]"#),
        )
        .unwrap_err(),
    );
    assert_eq!(field.as_deref(), Some("specs[1].derivatives"), "{message}");
    let (message, _, kind) = error_of(
        wasm::robustness_table(
            js(r#"{"frequencyHz":1}"#),
            0.05.into(),
            js(r#"[{"family":"nope"}]"#),
        )
        .unwrap_err(),
    );
    assert_eq!(kind.as_deref(), Some("parse"), "{message}");
    // Still working.
    assert!(wasm::damping_insensitivity(shaper, js(r#"{"frequencyHz":1}"#), 0.05.into()).is_ok());
}
