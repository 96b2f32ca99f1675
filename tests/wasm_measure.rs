//! The measured-data JS API round trip, in wasm under Node: typed arrays out, recording errors
//! with `line` / `column`, identify → recommend with plain objects.
#![cfg(target_arch = "wasm32")]

use input_shaping::js as api;
use js_sys::{Float64Array, Reflect, JSON};
use std::f64::consts::PI;
use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_test::wasm_bindgen_test;

fn js(text: &str) -> JsValue {
    JSON::parse(text).expect("test JSON parses")
}

fn get(v: &JsValue, key: &str) -> JsValue {
    Reflect::get(v, &key.into()).unwrap()
}

fn decay_csv() -> String {
    let mut s = String::from("#time,accel_x,accel_y,accel_z\n");
    let mut state = 88172645463325252u64;
    let mut noise = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for k in 0..20_000 {
        let t = k as f64 / 1000.0;
        let x = if t < 1.0 {
            0.0
        } else {
            let w = 2.0 * PI * 40.0;
            (-0.02 * w * (t - 1.0)).exp() * (w * (t - 1.0)).sin()
        } + 0.002 * noise();
        s.push_str(&format!("{t:.6},{x:.6},0.000000,1.000000\n"));
    }
    s
}

#[wasm_bindgen_test]
fn parse_identify_recommend_round_trip() {
    let rec = api::parse_recording(&decay_csv(), JsValue::UNDEFINED).unwrap();
    assert_eq!(get(&rec, "format").as_string().as_deref(), Some("klipper"));
    assert_eq!(get(&rec, "rows").as_f64(), Some(20_000.0));
    let channels: js_sys::Array = get(&rec, "channels").dyn_into().unwrap();
    assert_eq!(channels.length(), 3);
    assert!(get(&channels.get(0), "values").is_instance_of::<Float64Array>());
    // A channel by index reads the same channel as by name; anything else names the field.
    let by_index = api::identify_modes(rec.clone(), js(r#"{"channel":0}"#)).unwrap();
    assert_eq!(
        get(&by_index, "channel").as_string().as_deref(),
        Some("accel_x")
    );
    for bad in ["-1", "1.5", "true"] {
        let e = api::identify_modes(rec.clone(), js(&format!(r#"{{"channel":{bad}}}"#)));
        let e: js_sys::Error = e.unwrap_err().dyn_into().unwrap();
        let message = String::from(e.message());
        assert_eq!(
            get(&e, "field").as_string().as_deref(),
            Some("options.channel"),
            "{message}"
        );
        assert!(message.contains("channel index"), "{bad}: {message}");
    }
    let id = api::identify_modes(rec, js(r#"{"channel":"accel_x"}"#)).unwrap();
    assert_eq!(get(&id, "channel").as_string().as_deref(), Some("accel_x"));
    let modes: js_sys::Array = get(&id, "modes").dyn_into().unwrap();
    assert_eq!(modes.length(), 1);
    let f = get(&modes.get(0), "frequencyHz").as_f64().unwrap();
    let z = get(&modes.get(0), "damping").as_f64().unwrap();
    assert!(
        (f - 40.0).abs() < 0.4 && (z - 0.02).abs() < 0.003,
        "{f} {z}"
    );
    let spectrum = get(&id, "spectrum");
    assert!(get(&spectrum, "psd").is_instance_of::<Float64Array>());
    let r = api::recommend_shaper(spectrum, get(&id, "modes"), JsValue::UNDEFINED).unwrap();
    let ranked: js_sys::Array = get(&r, "ranked").dyn_into().unwrap();
    assert_eq!(ranked.length(), 6);
}

#[wasm_bindgen_test]
fn chunked_parser_and_errors_with_line_and_column() {
    let mut p = api::JsRecordingParser::new(JsValue::UNDEFINED).unwrap();
    p.push("time,a\n0,1\n0.5,").unwrap();
    let e = p.push("x\n").unwrap_err();
    let err: js_sys::Error = e.dyn_into().unwrap();
    assert_eq!(get(&err, "line").as_f64(), Some(3.0));
    assert_eq!(get(&err, "column").as_f64(), Some(2.0));
    assert_eq!(get(&err, "columnName").as_string().as_deref(), Some("a"));
    assert_eq!(get(&err, "kind").as_string().as_deref(), Some("parse"));
    assert!(String::from(err.message()).contains("line 3, column 2 (`a`)"));
    // The module keeps working after an error.
    let mut p = api::JsRecordingParser::new(JsValue::UNDEFINED).unwrap();
    p.push("time,a\n0,1\n1,2\n").unwrap();
    assert_eq!(p.rows(), 2.0);
    assert!(p.finish().is_ok());
    assert!(p.finish().is_err(), "finish twice is an error, not a panic");
}

#[wasm_bindgen_test]
fn welch_accepts_typed_and_plain_arrays_and_names_bad_fields() {
    let x: Vec<f64> = (0..4096).map(|i| (i as f64 * 0.3).sin()).collect();
    let typed = Float64Array::from(x.as_slice());
    let a = api::welch_js(typed.into(), js(r#"{"sampleRateHz":100}"#)).unwrap();
    assert_eq!(get(&a, "segmentLength").as_f64(), Some(256.0));
    let plain = js(&format!(
        "[{}]",
        x.iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>()
            .join(",")
    ));
    let b = api::welch_js(plain, js(r#"{"sampleRateHz":100}"#)).unwrap();
    let (pa, pb): (Float64Array, Float64Array) = (
        get(&a, "psd").dyn_into().unwrap(),
        get(&b, "psd").dyn_into().unwrap(),
    );
    assert_eq!(pa.to_vec(), pb.to_vec());
    let k = api::welch_js(
        Float64Array::from(x.as_slice()).into(),
        js(r#"{"preset":"klipper","sampleRateHz":3200}"#),
    )
    .unwrap();
    assert_eq!(get(&k, "segmentLength").as_f64(), Some(2048.0));
    let e = api::welch_js(js("[1, \"a\", 3]"), js(r#"{"sampleRateHz":100}"#)).unwrap_err();
    assert_eq!(get(&e, "field").as_string().as_deref(), Some("signal[1]"));
    let e = api::welch_js(
        Float64Array::from(x.as_slice()).into(),
        js(r#"{"sampleRateHz":-1}"#),
    )
    .unwrap_err();
    assert_eq!(
        get(&e, "field").as_string().as_deref(),
        Some("sampleRateHz")
    );
}
