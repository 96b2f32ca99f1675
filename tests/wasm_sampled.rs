//! The JS API of the sampled family and of quantisation, in wasm under Node: `design`,
//! `sampledReport`, `rampDelay`, `quantize` with plain objects in and out and errors naming
//! their field.
#![cfg(target_arch = "wasm32")]

use input_shaping::js as wasm;
use js_sys::{Reflect, JSON};
use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_test::wasm_bindgen_test;

fn js(text: &str) -> JsValue {
    JSON::parse(text).expect("test JSON parses")
}

fn get(v: &JsValue, key: &str) -> JsValue {
    Reflect::get(v, &key.into()).unwrap()
}

fn num(v: &JsValue, key: &str) -> f64 {
    get(v, key).as_f64().unwrap_or(f64::NAN)
}

fn field(e: JsValue) -> Option<String> {
    let err: js_sys::Error = e.dyn_into().expect("a JS Error is thrown");
    get(&err, "field").as_string()
}

/// Kamel et al. §6 setting through JS: 30 rad/s = 4.7746… Hz.
const PAPER: &str = r#"{"family":"sampled","modes":[{"frequencyHz":4.774648292756860,"damping":0.02}],
    "periodS":0.012,"impulses":36,"delaySamples":17,"weight":0.1,"plantGain":0.0008}"#;

#[wasm_bindgen_test]
fn sampled_design_and_report() {
    let shaper = wasm::design(js(PAPER)).unwrap();
    let impulses: js_sys::Array = get(&shaper, "impulses").dyn_into().unwrap();
    assert_eq!(impulses.length(), 36);
    let mode = js(r#"{"frequencyHz":4.774648292756860,"damping":0.02}"#);
    let v = wasm::residual_vibration(shaper.clone(), mode.clone()).unwrap();
    assert!(v < 1e-12);
    let tau = wasm::ramp_delay(shaper.clone(), mode.clone()).unwrap();
    assert!((tau - 17.0 * 0.012).abs() < 1e-12, "τ = mT, got {tau}");

    let report = wasm::sampled_report(js(PAPER)).unwrap();
    assert!((num(&report, "rampDelay") - 0.204).abs() < 1e-12);
    assert_eq!(num(&report, "startTime"), 0.0);
    let reduction = num(&report, "costReduction");
    assert!((reduction - 0.3701).abs() < 1e-4, "{reduction}");
    let cost = get(&report, "cost");
    assert!((num(&cost, "total") - 0.021536).abs() < 2e-6);
    assert!(num(&get(&report, "baselineCost"), "controlError") > num(&cost, "controlError"));

    let bad = wasm::sampled_report(js(
        r#"{"family":"zvd","modes":[{"frequencyHz":2,"damping":0}]}"#,
    ))
    .unwrap_err();
    assert_eq!(field(bad).as_deref(), Some("family"));
    let bad = wasm::design(js(
        r#"{"family":"sampled","modes":[{"frequencyHz":2}],"periodS":-1,"impulses":10}"#,
    ))
    .unwrap_err();
    assert_eq!(field(bad).as_deref(), Some("periodS"));
}

#[wasm_bindgen_test]
fn quantize_reproduces_pelaez_singhose_equation_8() {
    let shaper = js(
        r#"{"impulses":[{"time":0,"amplitude":0.156},{"time":0.9767,"amplitude":0.344},
            {"time":1.9383,"amplitude":0.344},{"time":2.9151,"amplitude":0.156}]}"#,
    );
    let mode = js(r#"{"frequencyHz":0.5,"damping":0.002}"#);
    let report = wasm::quantize(
        shaper.clone(),
        mode.clone(),
        js(r#"{"amplitudeSteps":255,"tickS":0.001,"method":"updateTime","rampS":3.2}"#),
    )
    .unwrap();
    let impulses: js_sys::Array = get(&report, "impulses").dyn_into().unwrap();
    for (i, want) in [0.1569, 0.3451, 0.3346, 0.1287].iter().enumerate() {
        let a = num(&impulses.get(i as u32), "amplitude");
        assert!((a - want).abs() < 5e-5, "A{i} = {a}");
    }
    assert!((num(&report, "amplitudeSum") - 0.9653).abs() < 5e-5);
    assert!(num(&report, "vibrationAfter") > num(&report, "vibrationBefore"));
    let width = num(&get(&report, "insensitivityAfter"), "width");
    assert!(width > 0.6 && width < 0.7, "{width}");
    // The report is itself a shaper the other functions accept.
    assert!(wasm::residual_vibration(report, mode.clone()).unwrap() > 0.01);

    let bad = wasm::quantize(shaper, mode, js(r#"{"amplitudeSteps":0}"#)).unwrap_err();
    assert_eq!(field(bad).as_deref(), Some("options.amplitudeSteps"));
}
