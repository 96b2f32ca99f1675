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
    let rec = api::parse_recording(decay_csv().into(), JsValue::UNDEFINED).unwrap();
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
    // A free decay is no sweep.
    assert!(get(&id, "sweep").is_null());
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
    p.push("time,a\n0,1\n0.5,".into()).unwrap();
    let e = p.push("x\n".into()).unwrap_err();
    let err: js_sys::Error = e.dyn_into().unwrap();
    assert_eq!(get(&err, "line").as_f64(), Some(3.0));
    assert_eq!(get(&err, "column").as_f64(), Some(2.0));
    assert_eq!(get(&err, "columnName").as_string().as_deref(), Some("a"));
    assert_eq!(get(&err, "kind").as_string().as_deref(), Some("parse"));
    assert!(String::from(err.message()).contains("line 3, column 2 (`a`)"));
    // The module keeps working after an error.
    let mut p = api::JsRecordingParser::new(JsValue::UNDEFINED).unwrap();
    p.push("time,a\n0,1\n1,2\n".into()).unwrap();
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
        Some("options.sampleRateHz")
    );
}

/// The library's own checks of an options object name the argument too (issue 21 item 1:
/// `options.sampleRateHz`, not `sampleRateHz`), in every measured-data export; errors of the
/// other arguments keep their own names.
#[wasm_bindgen_test]
fn option_errors_name_the_options_argument() {
    let field = |e: JsValue| get(&e, "field").as_string().unwrap_or_default();
    let x: Vec<f64> = (0..512).map(|i| (0.3 * i as f64).sin()).collect();
    let signal = || -> JsValue { Float64Array::from(x.as_slice()).into() };
    let e = api::fft_spectrum_js(signal(), js(r#"{"sampleRateHz":-1}"#)).unwrap_err();
    assert_eq!(field(e), "options.sampleRateHz");
    let e = api::welch_js(signal(), js(r#"{"sampleRateHz":100,"segmentLength":1}"#)).unwrap_err();
    assert_eq!(field(e), "options.segmentLength");
    let e = api::identify_modes(signal(), js(r#"{"sampleRateHz":100,"maxModes":0}"#)).unwrap_err();
    assert_eq!(field(e), "options.maxModes");
    let e = api::identify_modes(signal(), JsValue::UNDEFINED).unwrap_err();
    assert_eq!(field(e), "options.sampleRateHz");
    let bins: Vec<String> = (0..=128)
        .map(|k| format!("{}", 1.5625 * k as f64))
        .collect();
    let psd: Vec<String> = (0..=128)
        .map(|k| format!("{}", 1.0 + 100.0 / (1.0 + (k as f64 - 30.0).powi(2))))
        .collect();
    let text = format!(
        r#"{{"frequencyHz":[{}],"psd":[{}]}}"#,
        bins.join(","),
        psd.join(",")
    );
    let spectrum = || js(&text);
    let e = api::identify_modes(spectrum(), js(r#"{"maxModes":9}"#)).unwrap_err();
    assert_eq!(field(e), "options.maxModes");
    let e = api::recommend_shaper(
        spectrum(),
        JsValue::NULL,
        js(r#"{"criterion":"klipper","testDampingRatios":[5]}"#),
    );
    assert_eq!(
        e.err().map(field).as_deref(),
        Some("options.testDampingRatios[0]")
    );
    // The samples' own error keeps its name.
    let e = api::fft_spectrum_js(js("[1, \"a\", 3]"), js(r#"{"sampleRateHz":100}"#)).unwrap_err();
    assert_eq!(field(e), "signal[1]");
}

/// `firmwareConfig` across the boundary: `{ text, warnings }`, and an error's `field` naming
/// the axis (RepRapFirmware 3.6 holds at most 5 impulses, AxisShaper.h `MaxImpulses`).
#[wasm_bindgen_test]
fn firmware_config_round_trip() {
    let r = api::firmware_config_js(js(
        r#"{"firmware":"klipperCommand","axes":[{"axis":"x","family":"mzv","frequencyHz":53.8}]}"#,
    ))
    .unwrap();
    assert_eq!(
        get(&r, "text").as_string().as_deref(),
        Some("SET_INPUT_SHAPER SHAPER_TYPE_X=mzv SHAPER_FREQ_X=53.8 DAMPING_RATIO_X=0.1\n")
    );
    assert_eq!(js_sys::Array::from(&get(&r, "warnings")).length(), 0);
    let six: Vec<String> = (0..6)
        .map(|k| {
            format!(
                r#"{{"time":{},"amplitude":{}}}"#,
                0.002 * k as f64,
                1.0 / 6.0
            )
        })
        .collect();
    let e = api::firmware_config_js(js(&format!(
        r#"{{"firmware":"rrf","axes":[{{"axis":"x","family":"custom","impulses":[{}]}}]}}"#,
        six.join(",")
    )))
    .unwrap_err();
    assert_eq!(
        get(&e, "field").as_string().as_deref(),
        Some("axes[0].impulses")
    );
    let e = api::firmware_config_js(js(r#"{"firmware":"repetier","axes":[]}"#)).unwrap_err();
    assert_eq!(get(&e, "kind").as_string().as_deref(), Some("parse"));
}

/// recommendShaper with criterion 'klipper' (issue 20 item 3): a spectrum object with typed
/// arrays, no modes, Klipper's table in `klipper`; the normalisation flag read; a bad flag named.
#[wasm_bindgen_test]
fn recommend_shaper_klipper_criterion_from_js() {
    // One mode at 45 Hz, ζ 0.06, on Klipper's bins (3200 Hz, 2048 points), not normalised.
    let f: Vec<f64> = (0..=1024).map(|k| k as f64 * 3200.0 / 2048.0).collect();
    let psd: Vec<f64> = f
        .iter()
        .map(|&x| {
            let r = x / 45.0;
            1e-4 + r.powi(4) / ((1.0 - r * r).powi(2) + (0.12 * r).powi(2))
        })
        .collect();
    let spectrum = js_sys::Object::new();
    let set = |o: &js_sys::Object, k: &str, v: &JsValue| {
        Reflect::set(o, &k.into(), v).unwrap();
    };
    set(
        &spectrum,
        "frequencyHz",
        &Float64Array::from(f.as_slice()).into(),
    );
    set(&spectrum, "psd", &Float64Array::from(psd.as_slice()).into());
    let options = js(r#"{"criterion":"klipper"}"#);
    let r = api::recommend_shaper(spectrum.clone().into(), JsValue::UNDEFINED, options.clone())
        .unwrap();
    let klipper = get(&r, "klipper");
    let families: js_sys::Array = get(&klipper, "families").dyn_into().unwrap();
    assert_eq!(families.length(), 5);
    let best = families.get(get(&klipper, "best").as_f64().unwrap() as u32);
    let name = get(&best, "name").as_string().unwrap();
    let printed = get(&best, "printed");
    let freq = get(&printed, "freq").as_f64().unwrap();
    assert!((35.0..60.0).contains(&freq), "{name} {freq}");
    let ranked: js_sys::Array = get(&r, "ranked").dyn_into().unwrap();
    let rec = ranked.get(get(&r, "recommended").as_f64().unwrap() as u32);
    assert_eq!(get(&rec, "family").as_string(), Some(name));
    // Normalised twice is a different spectrum: the flag is read.
    set(&spectrum, "normalization", &"klipper".into());
    let r2 = api::recommend_shaper(spectrum.clone().into(), JsValue::NULL, options.clone());
    assert!(r2.is_ok());
    set(&spectrum, "normalization", &"twice".into());
    let e: js_sys::Error = api::recommend_shaper(spectrum.into(), JsValue::NULL, options)
        .unwrap_err()
        .dyn_into()
        .unwrap();
    let field = get(&e, "field").as_string().unwrap_or_default();
    assert!(field.starts_with("spectrum.normalization"), "{field}");
}

/// Arguments of the wrong type (issue 21 item 1): the documented `Error` naming the argument,
/// checked in Rust (the glue no longer converts a `text` or a `chunk` first: a number there
/// read out of bounds, `null` threw the glue's `TypeError`).
#[wasm_bindgen_test]
fn arguments_of_the_wrong_type_name_the_argument() {
    let field_and_kind = |e: JsValue| {
        let e: js_sys::Error = e.dyn_into().expect("an Error");
        (
            get(&e, "field").as_string().unwrap_or_default(),
            get(&e, "kind").as_string().unwrap_or_default(),
            String::from(e.message()),
        )
    };
    for bad in [
        JsValue::from(123),
        JsValue::NULL,
        JsValue::UNDEFINED,
        js_sys::Object::new().into(),
        js("[1, 2]"),
    ] {
        let (field, kind, message) =
            field_and_kind(api::parse_recording(bad.clone(), JsValue::UNDEFINED).unwrap_err());
        assert_eq!(
            (field.as_str(), kind.as_str()),
            ("text", "parse"),
            "{message}"
        );
        let mut p = api::JsRecordingParser::new(JsValue::UNDEFINED).unwrap();
        let (field, kind, message) = field_and_kind(p.push(bad).unwrap_err());
        assert_eq!(
            (field.as_str(), kind.as_str()),
            ("chunk", "parse"),
            "{message}"
        );
    }
    let (_, _, message) =
        field_and_kind(api::parse_recording(JsValue::from(1), JsValue::NULL).unwrap_err());
    assert_eq!(message, "text: must be a string, got a number");
    let (_, _, message) =
        field_and_kind(api::parse_recording(JsValue::NULL, JsValue::NULL).unwrap_err());
    assert_eq!(message, "text: must be a string, got null");
    let (_, _, message) =
        field_and_kind(api::parse_recording(JsValue::UNDEFINED, JsValue::NULL).unwrap_err());
    assert_eq!(message, "text: is missing");
    // Not a canvas (and there is none in Node): named `canvas`.
    let spectrum = js(r#"{"frequencyHz":[0,1,2],"psd":[1,1,1]}"#);
    for bad in [
        JsValue::from(1),
        JsValue::NULL,
        js_sys::Object::new().into(),
    ] {
        let e = api::draw_klipper_chart(bad.clone(), spectrum.clone(), JsValue::UNDEFINED);
        assert_eq!(field_and_kind(e.unwrap_err()).0, "canvas");
    }
    // An array is length-checked before it is copied: a sparse one of 2^32 - 1 elements.
    let huge = js_sys::Array::new_with_length(u32::MAX);
    let e = api::welch_js(huge.into(), js(r#"{"sampleRateHz":100}"#)).unwrap_err();
    assert_eq!(
        field_and_kind(e).1,
        "tooLarge",
        "the 2^26-sample limit, before any copy"
    );
    // A typed array on a detached buffer reads as empty: too short, not a TypeError.
    let detached = js_sys::Float32Array::new_with_length(8);
    let buffer = detached.buffer();
    let options = js_sys::Object::new();
    js_sys::Reflect::set(&options, &"transfer".into(), &js_sys::Array::of1(&buffer)).unwrap();
    js_sys::Function::new_with_args("b, o", "structuredClone(b, o)")
        .call2(&JsValue::NULL, &buffer, &options)
        .unwrap();
    assert_eq!(detached.length(), 0, "the buffer is detached");
    let (field, kind, message) =
        field_and_kind(api::welch_js(detached.into(), js(r#"{"sampleRateHz":100}"#)).unwrap_err());
    assert_eq!(
        (field.as_str(), kind.as_str()),
        ("signal", "invalid"),
        "{message}"
    );
}

/// A raw sweep recording (tests/data/klipper, generated by benches/reference/sweep_testset.py:
/// 38 -> 56 Hz at 2 Hz/s, one mode at 47.3 Hz, zeta 0.08, per its manifest.json): identifyModes
/// passes on the sweep it read from the data, and the mode fitted on it.
#[wasm_bindgen_test]
fn identify_modes_reports_the_sweep_of_a_raw_recording() {
    let text = include_str!("data/klipper/raw_data_x_single47z08.csv");
    let rec = api::parse_recording(text.into(), JsValue::UNDEFINED).unwrap();
    let id = api::identify_modes(rec, js(r#"{"channel":"accel_x"}"#)).unwrap();
    let sweep = get(&id, "sweep");
    assert!(!sweep.is_null(), "no sweep reported");
    let band: js_sys::Array = get(&sweep, "bandHz").dyn_into().unwrap();
    let (lo, hi) = (band.get(0).as_f64().unwrap(), band.get(1).as_f64().unwrap());
    assert!(
        (lo - 38.0).abs() < 6.0 && (hi - 56.0).abs() < 3.0,
        "{lo} {hi}"
    );
    let rate = get(&sweep, "rateHzPerS").as_f64().unwrap();
    assert!((rate - 2.0).abs() < 0.1, "{rate}");
    assert_eq!(get(&sweep, "law").as_string().as_deref(), Some("linear"));
    let modes: js_sys::Array = get(&id, "modes").dyn_into().unwrap();
    let found: Vec<f64> = modes
        .iter()
        .map(|m| get(&m, "frequencyHz").as_f64().unwrap())
        .collect();
    assert!(found.iter().any(|f| (f - 47.3).abs() < 0.473), "{found:?}");
}
