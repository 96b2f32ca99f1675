//! The JavaScript API round trip, in wasm under Node (`wasm-pack test --node`): plain JS objects
//! in and out, thrown `Error`s naming the field, and the module still working after an error.
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
    let band =
        wasm::insensitivity(shaper, js(r#"{"frequencyHz":1,"damping":0}"#), 0.05.into()).unwrap();
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

/// Tagged specs (`family`, `kind`, `shape`) are read from the JS object itself, tag first
/// (crate/tagged.rs), so a bad field inside one is named to the field, not only to the spec.
#[wasm_bindgen_test]
fn errors_inside_tagged_specs_name_the_field() {
    let modes = r#""modes":[{"frequencyHz":1,"damping":0.05}]"#;
    let design_cases = [
        (format!(r#"{{"family":"ei","vtol":"x",{modes}}}"#), "vtol"),
        (
            format!(r#"{{"family":"zvdn","derivatives":1.5,{modes}}}"#),
            "derivatives",
        ),
        (
            format!(r#"{{"family":"custom","impulses":[{{"time":0,"amplitude":"x"}}],{modes}}}"#),
            "impulses[0].amplitude",
        ),
        (
            format!(r#"{{"family":"sampled","periodS":"a",{modes}}}"#),
            "periodS",
        ),
        (format!(r#"{{"family":3,{modes}}}"#), "family"),
        (format!(r#"{{"family":"nope",{modes}}}"#), "family"),
    ];
    for (spec, field) in &design_cases {
        let (message, got) = error_message(wasm::design(js(spec)).unwrap_err());
        assert_eq!(got.as_deref(), Some(*field), "{spec}: {message}");
    }
    // The tag missing, or the spec not an object: the spec itself is at fault, named `spec`
    // (issue 21: every error names the argument).
    let (message, got) = error_message(wasm::design(js(&format!("{{{modes}}}"))).unwrap_err());
    assert_eq!(got.as_deref(), Some("spec"), "{message}");
    assert!(message.contains("missing field `family`"), "{message}");
    let (message, got) = error_message(wasm::design(js(r#""zv""#)).unwrap_err());
    assert!(message.contains("invalid type: string"), "{message}");
    assert_eq!(got.as_deref(), Some("spec"), "{message}");
    let (message, got) = error_message(wasm::design(JsValue::NULL).unwrap_err());
    assert_eq!(
        (message.as_str(), got.as_deref()),
        ("spec: is missing", Some("spec"))
    );

    let plant = r#""plant":{"kind":"modal","modes":[{"frequencyHz":1,"damping":0.05}]}"#;
    let simulate_cases = [
        (
            format!(r#"{{{plant},"command":{{"kind":"profile","shape":"nope"}}}}"#),
            "command.shape",
        ),
        (
            format!(
                r#"{{{plant},"command":{{"kind":"trapezoid","distance":1,"maxVelocity":"a","maxAcceleration":1}}}}"#
            ),
            "command.maxVelocity",
        ),
        (
            format!(
                r#"{{{plant},"command":{{"kind":"step"}},"shaper":{{"family":"ei","vtol":"q"}}}}"#
            ),
            "shaper.vtol",
        ),
        (
            r#"{"plant":{"kind":"nope"},"command":{"kind":"step"}}"#.to_string(),
            "plant.kind",
        ),
        (
            format!(r#"{{{plant},"command":{{"distance":1}}}}"#),
            "command",
        ),
    ];
    for (spec, field) in &simulate_cases {
        let (message, got) = error_message(wasm::simulate(js(spec)).unwrap_err());
        assert_eq!(got.as_deref(), Some(*field), "{spec}: {message}");
    }
    // The same spec reads as before once it is right: EI has 3 impulses (Singhose 2009 §3.1).
    let shaper = wasm::design(js(&format!(r#"{{"family":"ei","vtol":0.05,{modes}}}"#))).unwrap();
    assert_eq!(
        get(&shaper, "impulses")
            .unchecked_into::<js_sys::Array>()
            .length(),
        3
    );
}

#[wasm_bindgen_test]
fn exports_and_klipper_figures() {
    let shaper = wasm::design(js(
        r#"{"family":"zv","modes":[{"frequencyHz":2,"damping":0}]}"#,
    ))
    .unwrap();
    let csv = wasm::export_shaper(shaper.clone(), js(r#"{"format":"csv"}"#)).unwrap();
    assert_eq!(csv, "time_s,amplitude\n0,0.5\n0.25,0.5\n");
    let rrf = wasm::export_shaper(shaper.clone(), js(r#"{"format":"rrf"}"#)).unwrap();
    assert_eq!(rrf, "M593 P\"custom\" H0.5 T0.25");
    let (message, field) =
        error_message(wasm::export_shaper(shaper.clone(), js(r#"{"format":"xml"}"#)).unwrap_err());
    assert_eq!(field.as_deref(), Some("options.format"), "{message}");
    let (_, field) = error_message(
        wasm::export_shaper(shaper.clone(), js(r#"{"format":"c","name":"9x"}"#)).unwrap_err(),
    );
    assert_eq!(field.as_deref(), Some("options.name"));
    let figures = wasm::klipper_figures(shaper, JsValue::UNDEFINED).unwrap();
    // ZV at 2 Hz, ζ = 0: d = 1/8 s; offset₁₈₀ = 5000·d²/2 = 39.0625 mm dominates offset₉₀.
    let smoothing = get(&figures, "smoothing").as_f64().unwrap();
    assert!((smoothing - 39.0625).abs() < 1e-9, "{smoothing}");
    // At scv = 5 mm/s even a vanishing acceleration leaves offset₉₀ = √2·½·5·d = 0.44 mm > 0.12,
    // so Klipper's find_shaper_max_accel returns 0 (its `_bisect` starts with func(1e-9)).
    assert_eq!(get(&figures, "maxAccel").as_f64(), Some(0.0));
}

#[wasm_bindgen_test]
fn simulate_returns_both_responses_in_one_call() {
    let r = wasm::simulate(js(r#"{
        "plant": {"kind":"modal","modes":[{"frequencyHz":1.1,"damping":0}]},
        "command": {"kind":"step","distance":2},
        "shaper": {"family":"zv","modes":[{"frequencyHz":1,"damping":0}]},
        "duration": 4, "sampleRateHz": 500 }"#))
    .unwrap();
    let time: js_sys::Array = get(&r, "time").dyn_into().unwrap();
    assert_eq!(time.length(), 2001);
    let shaped = get(&r, "shaped");
    let endpoint: js_sys::Array = get(&shaped, "endpoint").dyn_into().unwrap();
    assert_eq!(endpoint.length(), 2001);
    let metrics = get(&shaped, "metrics");
    let prv: js_sys::Array = get(&metrics, "modeResidualPercent").dyn_into().unwrap();
    // V of ZV(1 Hz) at 1.1 Hz, undamped: |cos(π·1.1/2)| = 0.1564…
    let v = (std::f64::consts::PI * 1.1 / 2.0).cos().abs();
    assert!((prv.get(0).as_f64().unwrap() - 100.0 * v).abs() < 1e-9);
    assert!(get(&get(&r, "unshaped"), "deflection").is_array());
    // Undamped and 15.6 % residual: it never settles within 2 % (null), but it has a residual.
    assert!(get(&metrics, "settlingTime2").is_null());
    assert!(get(&metrics, "residualVibrationPercent").as_f64().unwrap() > 15.0);
    let (message, field) = error_message(
        wasm::simulate(js(
            r#"{"plant":{"kind":"modal","modes":[{"frequencyHz":1}]},
            "command":{"kind":"step"},"samplePeriod":-1}"#,
        ))
        .unwrap_err(),
    );
    assert_eq!(field.as_deref(), Some("samplePeriod"), "{message}");
    let (message, _) = error_message(
        wasm::simulate(js(
            r#"{"plant":{"kind":"modal","modes":[{"frequencyHz":1}]},
            "command":{"kind":"step"},"duration":1e9,"samplePeriod":1}"#,
        ))
        .unwrap_err(),
    );
    assert!(message.contains("at most 500000"), "{message}");
}

#[wasm_bindgen_test]
fn spectrum_of_a_shaped_step_is_zero_at_the_mode() {
    let r = wasm::spectrum(js(r#"{
        "command": {"kind":"step"},
        "shaper": {"family":"zv","modes":[{"frequencyHz":2,"damping":0}]},
        "fromHz": 0, "toHz": 4, "points": 5 }"#))
    .unwrap();
    let m: js_sys::Array = get(&r, "magnitude").dyn_into().unwrap();
    let u: js_sys::Array = get(&r, "unshaped").dyn_into().unwrap();
    assert!(m.get(2).as_f64().unwrap() < 1e-12, "zero at 2 Hz");
    assert!(
        (u.get(2).as_f64().unwrap() - 1.0).abs() < 1e-12,
        "a step's velocity is δ"
    );
    let modes: js_sys::Array = get(&r, "modesHz").dyn_into().unwrap();
    assert_eq!(modes.get(0).as_f64(), Some(2.0));
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

/// `simulateCorner` through the JS boundary returns what `scenario::corner_for` computes in
/// Rust, number for number, and names a bad field from the spec's root.
#[wasm_bindgen_test]
fn simulate_corner_is_the_rust_result() {
    let text = r#"{"path":{"kind":"ringingTower","sideMm":40,"thicknessMm":4},
        "velocity":100,"accel":3000,"squareCornerVelocity":5,
        "x":{"modes":[{"frequencyHz":42,"damping":0.06}],"shaper":{"family":"mzv"}},
        "y":{"modes":[{"frequencyHz":55,"damping":0.05}],"shaper":{"family":"zv"}},
        "magnify":20}"#;
    let r = wasm::simulate_corner(js(text)).unwrap();
    let spec: input_shaping::scenario::CornerSpec = serde_json::from_str(text).unwrap();
    let rust = input_shaping::scenario::corner_for(&spec).unwrap();
    let expected = js(&serde_json::to_string(&rust).unwrap());
    assert_eq!(
        JSON::stringify(&r).unwrap(),
        JSON::stringify(&expected).unwrap()
    );
    let corners: js_sys::Array = get(&get(&r, "shaped"), "corners").dyn_into().unwrap();
    assert_eq!(corners.length(), 5);
    for (bad, field) in [
        (r#""path":{"kind":"square","sideMm":-1}"#, "path.sideMm"),
        (
            r#""path":{"kind":"ringingTower","thicknessMm":200}"#,
            "path.thicknessMm",
        ),
    ] {
        let spec = format!(
            r#"{{{bad},"velocity":100,"accel":3000,"x":{{"modes":[{{"frequencyHz":42}}]}},"y":{{"modes":[{{"frequencyHz":55}}]}}}}"#
        );
        let (message, got) = error_message(wasm::simulate_corner(js(&spec)).unwrap_err());
        assert_eq!(got.as_deref(), Some(field), "{message}");
    }
    let (message, got) = error_message(
        wasm::simulate_corner(js(r#"{"path":{"kind":"square","sideMm":10},"velocity":100,"accel":3000,
            "x":{"modes":[{"frequencyHz":-42}]},"y":{"modes":[{"frequencyHz":55}],"shaper":{"family":"zv"}}}"#))
        .unwrap_err(),
    );
    assert_eq!(got.as_deref(), Some("x.modes[0].frequencyHz"), "{message}");
}
