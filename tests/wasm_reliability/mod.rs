//! The wasm reliability checks (issue 6), shared by `tests/wasm_reliability_node.rs`
//! (`wasm-pack test --node`) and `tests/wasm_reliability_browser.rs` (headless Chromium):
//! every exported function is called with bad arguments of every JS kind — `undefined`,
//! `null`, NaN, ±Infinity, strings, booleans, BigInts, symbols, functions, arrays, objects with
//! NaN fields or unknown families, huge arrays — and each call must *throw* a JS `Error` with a
//! message and a `kind` (never trap), after which the same good call as before the errors must
//! return the same result. And a panic provoked on a test-only path (a closure that panics,
//! called from JS) must be reported on the console by the panic hook, after which the module
//! still answers.
#![allow(dead_code)]

use input_shaping::js as wasm;
use js_sys::{Array, Function, Reflect, JSON};
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;

pub fn js(text: &str) -> JsValue {
    JSON::parse(text).expect("test JSON parses")
}

fn stringify(v: &JsValue) -> String {
    JSON::stringify(v)
        .map(String::from)
        .unwrap_or_else(|_| format!("{v:?}"))
}

/// JS values of every kind, most of which no function accepts in any position.
pub fn bad_values() -> Vec<JsValue> {
    let nan_mode = js_sys::Object::new();
    Reflect::set(&nan_mode, &"frequencyHz".into(), &f64::NAN.into()).unwrap();
    Reflect::set(&nan_mode, &"damping".into(), &f64::INFINITY.into()).unwrap();
    let nan_spec = js_sys::Object::new();
    Reflect::set(&nan_spec, &"family".into(), &"ei".into()).unwrap();
    Reflect::set(&nan_spec, &"vtol".into(), &f64::NAN.into()).unwrap();
    Reflect::set(&nan_spec, &"modes".into(), &Array::of1(&nan_mode)).unwrap();
    let huge = Array::new();
    for i in 0..5000 {
        let m = js_sys::Object::new();
        Reflect::set(&m, &"frequencyHz".into(), &(1.0 + i as f64).into()).unwrap();
        huge.push(&m);
    }
    let huge_spec = js_sys::Object::new();
    Reflect::set(&huge_spec, &"family".into(), &"zv".into()).unwrap();
    Reflect::set(&huge_spec, &"modes".into(), &huge).unwrap();
    let deep = js(&format!("{}1{}", "[".repeat(500), "]".repeat(500)));
    vec![
        JsValue::UNDEFINED,
        JsValue::NULL,
        JsValue::from(f64::NAN),
        JsValue::from(f64::INFINITY),
        JsValue::from(f64::NEG_INFINITY),
        JsValue::from(-0.0),
        JsValue::from("zv"),
        JsValue::from(""),
        JsValue::from(true),
        JsValue::bigint_from_str("123456789012345678901234567890"),
        js_sys::Symbol::for_("nope").into(),
        Function::new_no_args("return 1").into(),
        Array::new().into(),
        js_sys::Object::new().into(),
        nan_mode.into(),
        nan_spec.into(),
        huge_spec.into(),
        huge.into(),
        deep,
        js(r#"{"family":"nope","modes":[{"frequencyHz":1}]}"#),
        js(r#"{"family":"zv","modes":[]}"#),
        js(r#"{"family":"zvdn","derivatives":4294967295,"modes":[{"frequencyHz":1}]}"#),
        js(r#"{"family":"si","insensitivity":1e308,"modes":[{"frequencyHz":1}]}"#),
        js(r#"{"family":"sampled","periodS":0.01,"impulses":1e300,"modes":[{"frequencyHz":1}]}"#),
        js(r#"{"impulses":[{"time":-1,"amplitude":1}]}"#),
        js(r#"{"impulses":[{"time":1e308,"amplitude":1e308},{"time":1e308,"amplitude":1e308}]}"#),
        js(r#"{"fromHz":5,"toHz":1,"points":1e12,"damping":2}"#),
        js(r#"{"kind":"modal","modes":[{"frequencyHz":-1}]}"#),
        js(r#"{"plant":{"kind":"pendulum","length":-1},"command":{"kind":"step"}}"#),
        js(
            r#"{"plant":{"kind":"vecianaTestBed"},"command":{"kind":"step"},"samplePeriod":1e-12,"duration":1e6}"#,
        ),
    ]
}

/// Checks that `r` is a thrown JS `Error` with a message and a known `kind`.
fn assert_thrown(r: Result<JsValue, JsValue>, what: &str) -> Result<(), String> {
    match r {
        Ok(v) => Err(format!(
            "{what}: returned {} instead of throwing",
            stringify(&v)
        )),
        Err(e) => {
            let err: js_sys::Error = e
                .dyn_into()
                .map_err(|e| format!("{what}: threw a non-Error {e:?}"))?;
            let message = String::from(err.message());
            if message.trim().is_empty() {
                return Err(format!("{what}: empty message"));
            }
            let kind = Reflect::get(&err, &"kind".into())
                .ok()
                .and_then(|k| k.as_string());
            match kind.as_deref() {
                Some("invalid" | "tooLarge" | "infeasible" | "parse" | "render") => Ok(()),
                other => Err(format!("{what}: kind {other:?} for {message}")),
            }
        }
    }
}

type Call = Box<dyn Fn(&[JsValue]) -> Result<JsValue, JsValue>>;

/// Every exported function with a good argument list.
fn calls() -> Vec<(&'static str, Call, Vec<JsValue>)> {
    let shaper = wasm::design(js(
        r#"{"family":"zvd","modes":[{"frequencyHz":2,"damping":0.05}]}"#,
    ))
    .expect("the good design works");
    let mode = || js(r#"{"frequencyHz":2,"damping":0.05}"#);
    vec![
        (
            "design",
            Box::new(|a: &[JsValue]| wasm::design(a[0].clone())) as Call,
            vec![js(
                r#"{"family":"ei","vtol":0.05,"modes":[{"frequencyHz":1,"damping":0.1}]}"#,
            )],
        ),
        (
            "residualVibration",
            Box::new(|a: &[JsValue]| {
                wasm::residual_vibration(a[0].clone(), a[1].clone()).map(JsValue::from)
            }),
            vec![shaper.clone(), js(r#"{"frequencyHz":2.2,"damping":0.05}"#)],
        ),
        (
            "sensitivity",
            Box::new(|a: &[JsValue]| wasm::sensitivity(a[0].clone(), a[1].clone())),
            vec![
                shaper.clone(),
                js(r#"{"fromHz":0,"toHz":4,"points":50,"damping":0.05}"#),
            ],
        ),
        (
            "insensitivity",
            Box::new(|a: &[JsValue]| wasm::insensitivity(a[0].clone(), a[1].clone(), a[2].clone())),
            vec![shaper.clone(), mode(), JsValue::from(0.05)],
        ),
        (
            "sensitivityMap",
            Box::new(|a: &[JsValue]| wasm::sensitivity_map(a[0].clone(), a[1].clone())),
            vec![
                shaper.clone(),
                js(
                    r#"{"fromHz":0,"toHz":4,"frequencyPoints":20,"dampingFrom":0,"dampingTo":0.3,"dampingPoints":5}"#,
                ),
            ],
        ),
        (
            "dampingSensitivity",
            Box::new(|a: &[JsValue]| wasm::damping_sensitivity(a[0].clone(), a[1].clone())),
            vec![
                shaper.clone(),
                js(r#"{"frequencyHz":2,"fromDamping":0,"toDamping":0.3,"points":20}"#),
            ],
        ),
        (
            "dampingInsensitivity",
            Box::new(move |a: &[JsValue]| {
                wasm::damping_insensitivity(a[0].clone(), a[1].clone(), a[2].clone())
            }),
            vec![shaper.clone(), mode(), JsValue::from(0.05)],
        ),
        (
            "robustnessTable",
            Box::new(move |a: &[JsValue]| {
                wasm::robustness_table(a[0].clone(), a[1].clone(), a[2].clone())
            }),
            vec![
                mode(),
                JsValue::from(0.05),
                js(r#"[{"family":"zv"},{"family":"ei"}]"#),
            ],
        ),
        (
            "exportShaper",
            Box::new(|a: &[JsValue]| {
                wasm::export_shaper(a[0].clone(), a[1].clone()).map(JsValue::from)
            }),
            vec![
                shaper.clone(),
                js(r#"{"format":"cFixed","amplitudeSteps":255,"tickS":1e-5}"#),
            ],
        ),
        (
            "klipperFigures",
            Box::new(|a: &[JsValue]| wasm::klipper_figures(a[0].clone(), a[1].clone())),
            vec![shaper.clone(), js(r#"{"scv":5}"#)],
        ),
        (
            "rampDelay",
            Box::new(|a: &[JsValue]| {
                wasm::ramp_delay(a[0].clone(), a[1].clone()).map(JsValue::from)
            }),
            vec![shaper.clone(), mode()],
        ),
        (
            "sampledReport",
            Box::new(|a: &[JsValue]| wasm::sampled_report(a[0].clone())),
            vec![js(
                r#"{"family":"sampled","periodS":0.012,"impulses":36,"delaySamples":17,"modes":[{"frequencyHz":4.7746,"damping":0.02}]}"#,
            )],
        ),
        (
            "quantize",
            Box::new(|a: &[JsValue]| wasm::quantize(a[0].clone(), a[1].clone(), a[2].clone())),
            vec![
                shaper.clone(),
                mode(),
                js(r#"{"amplitudeSteps":255,"tickS":0.001}"#),
            ],
        ),
        (
            "simulate",
            Box::new(|a: &[JsValue]| wasm::simulate(a[0].clone())),
            vec![js(
                r#"{"plant":{"kind":"vecianaTestBed"},"command":{"kind":"trapezoid","distance":1,"maxVelocity":1,"maxAcceleration":4},"shaper":{"family":"zvd"},"sampleRateHz":200}"#,
            )],
        ),
        (
            "spectrum",
            Box::new(|a: &[JsValue]| wasm::spectrum(a[0].clone())),
            vec![js(
                r#"{"command":{"kind":"step"},"shaper":{"family":"zvd","modes":[{"frequencyHz":1}]},"toHz":5,"points":64}"#,
            )],
        ),
    ]
}

/// Every function, every bad value in every argument position: a thrown `Error` each time, and
/// afterwards the good call gives the same answer as before.
pub fn every_error_is_thrown_and_the_module_keeps_working() -> Result<usize, String> {
    let bad = bad_values();
    let mut thrown = 0;
    for (name, call, good) in calls() {
        let before = call(&good).map_err(|e| format!("{name}: the good call failed: {e:?}"))?;
        let before = stringify(&before);
        for position in 0..good.len() {
            for (k, value) in bad.iter().enumerate() {
                let mut args = good.clone();
                args[position] = value.clone();
                let r = call(&args);
                // A few bad values are acceptable somewhere (an empty options object takes
                // the defaults; `undefined` specs mean "the default table"): those may succeed.
                match r {
                    Ok(_) => {}
                    Err(_) => {
                        assert_thrown(r, &format!("{name} arg {position} bad value {k}"))?;
                        thrown += 1;
                    }
                }
                let again = call(&good).map_err(|e| {
                    format!(
                        "{name}: the good call failed after bad value {k} in arg {position}: {e:?}"
                    )
                })?;
                if stringify(&again) != before {
                    return Err(format!(
                        "{name}: the good call changed after bad value {k} in arg {position}"
                    ));
                }
            }
        }
    }
    Ok(thrown)
}

/// The bad values that must throw wherever a spec/shaper/mode is expected (everything but the
/// two that are valid specs of something: none are).
pub fn always_throwing_for_design() -> Result<(), String> {
    for (k, v) in bad_values().into_iter().enumerate() {
        assert_thrown(wasm::design(v), &format!("design(bad value {k})"))?;
    }
    Ok(())
}

/// Provokes a panic on a test-only path — a Rust closure that panics, called from JS inside a
/// `try` — after installing the crate's panic hook (`wasm::start`, what the module runs on
/// load). The hook must write the panic message to `console.error`; the trap surfaces as a JS
/// exception; the module must still answer afterwards.
pub fn panic_reports_to_console_and_module_survives() -> Result<(), String> {
    // The test harness installs its own console-reporting hook; replace it by a silent one so
    // that only a hook installed by `wasm::start` can put the message on the console.
    std::panic::set_hook(Box::new(|_| {}));
    wasm::start();
    let record = Function::new_no_args(
        "globalThis.__panicLog = []; globalThis.__origError = console.error; \
         console.error = (...a) => { globalThis.__panicLog.push(a.map(String).join(' ')); };",
    );
    record.call0(&JsValue::NULL).map_err(|e| format!("{e:?}"))?;
    let panicking = Closure::<dyn Fn()>::new(|| {
        let v: Vec<u32> = Vec::new();
        // A genuine panic (index out of bounds), on a path only this test reaches.
        let i = v.len() + 3;
        let _ = v[i];
    });
    let call = Function::new_with_args(
        "f",
        "try { f(); return 'no exception'; } catch (e) { return String(e); }",
    );
    let outcome = call
        .call1(&JsValue::NULL, panicking.as_ref().unchecked_ref())
        .map_err(|e| format!("{e:?}"))?;
    let restore = Function::new_no_args("console.error = globalThis.__origError;");
    restore
        .call0(&JsValue::NULL)
        .map_err(|e| format!("{e:?}"))?;
    let log: Array = Reflect::get(&js_sys::global(), &"__panicLog".into())
        .map_err(|e| format!("{e:?}"))?
        .dyn_into()
        .map_err(|_| "no log".to_string())?;
    let text: Vec<String> = log.iter().filter_map(|v| v.as_string()).collect();
    let outcome = outcome.as_string().unwrap_or_default();
    if outcome == "no exception" {
        return Err("the panicking closure returned normally".into());
    }
    if !text
        .iter()
        .any(|t| t.contains("index out of bounds") && t.contains("panicked at"))
    {
        return Err(format!(
            "the panic was not reported on console.error: {text:?} (exception: {outcome})"
        ));
    }
    // The module still answers.
    let shaper = wasm::design(js(r#"{"family":"zv","modes":[{"frequencyHz":1}]}"#))
        .map_err(|e| format!("design after the panic failed: {e:?}"))?;
    let v = wasm::residual_vibration(shaper, js(r#"{"frequencyHz":1}"#))
        .map_err(|e| format!("residualVibration after the panic failed: {e:?}"))?;
    if v > 1e-12 {
        return Err(format!("wrong answer after the panic: V = {v}"));
    }
    Ok(())
}
