//! The JavaScript API round trip, in wasm under Node (`wasm-pack test --node`): plain JS objects
//! in and out, thrown `Error`s naming the field, and the module still working after an error.
#![cfg(target_arch = "wasm32")]

use input_shaping::wasm;
use js_sys::{Reflect, JSON};
use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_test::wasm_bindgen_test;

fn js(text: &str) -> JsValue {
    JSON::parse(text).expect("test JSON parses")
}

fn get(v: &JsValue, key: &str) -> JsValue {
    Reflect::get(v, &key.into()).unwrap()
}

fn error_message(e: JsValue) -> (String, Option<String>) {
    let err: js_sys::Error = e.dyn_into().expect("a JS Error is thrown");
    (String::from(err.message()), get(&err, "field").as_string())
}

#[wasm_bindgen_test]
fn design_returns_plain_objects_matching_the_closed_form() {
    let shaper = wasm::design(js(
        r#"{"family":"zvd","modes":[{"frequencyHz":2,"damping":0.1}]}"#,
    ))
    .unwrap();
    let impulses: js_sys::Array = get(&shaper, "impulses").dyn_into().unwrap();
    assert_eq!(impulses.length(), 3);
    let k = (-0.1 * std::f64::consts::PI / (1.0f64 - 0.01).sqrt()).exp();
    let a0 = get(&impulses.get(0), "amplitude").as_f64().unwrap();
    assert!((a0 - 1.0 / ((1.0 + k) * (1.0 + k))).abs() < 1e-15);
    let td = 1.0 / (2.0 * (1.0f64 - 0.01).sqrt());
    let duration = get(&shaper, "duration").as_f64().unwrap();
    assert!((duration - td).abs() < 1e-14);

    let v =
        wasm::residual_vibration(shaper.clone(), js(r#"{"frequencyHz":2,"damping":0.1}"#)).unwrap();
    assert!(v < 1e-12);
    let curve = wasm::sensitivity(
        shaper.clone(),
        js(r#"{"fromHz":0,"toHz":4,"points":5,"damping":0.1}"#),
    )
    .unwrap();
    let f: js_sys::Array = get(&curve, "frequencyHz").dyn_into().unwrap();
    let vib: js_sys::Array = get(&curve, "vibration").dyn_into().unwrap();
    assert_eq!(f.length(), 5);
    assert_eq!(f.get(2).as_f64(), Some(2.0));
    assert!(vib.get(2).as_f64().unwrap() < 1e-12);
    assert!(
        (vib.get(0).as_f64().unwrap() - 1.0).abs() < 1e-12,
        "V(0) = |ΣA| = 1"
    );
}

#[wasm_bindgen_test]
fn insensitivity_of_zv_at_zero_damping() {
    let shaper = wasm::design(js(
        r#"{"family":"zv","modes":[{"frequencyHz":1,"damping":0}]}"#,
    ))
    .unwrap();
    let band = wasm::insensitivity(shaper, js(r#"{"frequencyHz":1,"damping":0}"#), 0.05).unwrap();
    let width = get(&band, "width").as_f64().unwrap();
    // Singhose 2009 Fig. 7: I(5 %) of ZV = 0.06 (exactly 2 − 4·acos(0.05)/π = 0.0637).
    assert!((width - 0.063_688_53).abs() < 1e-7, "{width}");
}

#[wasm_bindgen_test]
fn errors_are_thrown_with_the_field_and_the_module_keeps_working() {
    let cases = [
        (
            r#"{"family":"zv","modes":[{"frequencyHz":-1,"damping":0}]}"#,
            "modes[0].frequencyHz",
        ),
        (
            r#"{"family":"zv","modes":[{"frequencyHz":1,"damping":1.5}]}"#,
            "modes[0].damping",
        ),
        (r#"{"family":"zv","modes":[]}"#, "modes"),
        (
            r#"{"family":"zv","modes":[{"frequencyHz":"abc"}]}"#,
            "modes[0].frequencyHz",
        ),
        (r#"{"family":"nope","modes":[{"frequencyHz":1}]}"#, ""),
        (
            r#"{"family":"zvdn","modes":[{"frequencyHz":1}],"derivatives":99}"#,
            "derivatives",
        ),
    ];
    for (spec, field) in cases {
        let (message, got) = error_message(wasm::design(js(spec)).unwrap_err());
        if field.is_empty() {
            assert!(
                message.contains("nope") && message.contains("zvd"),
                "{message}"
            );
        } else {
            assert_eq!(got.as_deref(), Some(field), "{spec}: {message}");
            assert!(message.starts_with(field), "{message}");
        }
    }
    let (message, field) = error_message(wasm::design(JsValue::UNDEFINED).unwrap_err());
    assert!(message.contains("missing"), "{message} {field:?}");
    let (message, _) = error_message(
        wasm::sensitivity(
            js(r#"{"impulses":[{"time":0,"amplitude":1}]}"#),
            js(r#"{"fromHz":0,"toHz":1,"points":1e12}"#),
        )
        .unwrap_err(),
    );
    assert!(message.contains("points"), "{message}");
    // Still working after the errors.
    assert!(wasm::design(js(r#"{"family":"zv","modes":[{"frequencyHz":3}]}"#)).is_ok());
}

/// The robust families cross the JS boundary with their camelCase parameters.
#[wasm_bindgen_test]
fn robust_families_through_js() {
    for (spec, n) in [
        (
            r#"{"family":"ei","modes":[{"frequencyHz":2,"damping":0.1}]}"#,
            3,
        ),
        (
            r#"{"family":"eihump","humps":3,"vtol":0.05,"modes":[{"frequencyHz":2}]}"#,
            5,
        ),
        (
            r#"{"family":"mzv","modes":[{"frequencyHz":40,"damping":0.1}]}"#,
            3,
        ),
        (
            r#"{"family":"umei","vtol":0.05,"modes":[{"frequencyHz":2}]}"#,
            5,
        ),
        (
            r#"{"family":"bangbang","distance":0.2,"maxAcceleration":3,"modes":[{"frequencyHz":2,"damping":0.05}]}"#,
            5,
        ),
        (
            r#"{"family":"onoff","distance":0.2,"maxAcceleration":3,"coastTime":0.3,"modes":[{"frequencyHz":2}]}"#,
            8,
        ),
        (
            r#"{"family":"custom","impulses":[{"time":0,"amplitude":1},{"time":0.1,"amplitude":3}],"normalize":true,"modes":[{"frequencyHz":2}]}"#,
            2,
        ),
    ] {
        let shaper = wasm::design(js(spec)).unwrap();
        let impulses: js_sys::Array = get(&shaper, "impulses").dyn_into().unwrap();
        assert_eq!(impulses.length(), n, "{spec}");
    }
    let (message, field) = error_message(
        wasm::design(js(
            r#"{"family":"ei3","modes":[{"frequencyHz":2,"damping":0.6}]}"#,
        ))
        .unwrap_err(),
    );
    assert_eq!(field.as_deref(), Some("modes[0].damping"), "{message}");
}
