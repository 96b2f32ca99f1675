//! Reliability of the JS API in headless Chromium (issue 6; `wasm-pack test --headless
//! --chrome`): the same checks as `tests/wasm_reliability_node.rs`, plus `renderPlayground`
//! with real canvases — bad states throw, and the next good frame draws and answers as before.
#![cfg(target_arch = "wasm32")]

mod wasm_reliability;

use input_shaping::js as wasm;
use wasm_bindgen::JsCast;
use wasm_bindgen_test::{wasm_bindgen_test, wasm_bindgen_test_configure};
use wasm_reliability::js;

wasm_bindgen_test_configure!(run_in_browser);

#[wasm_bindgen_test]
fn browser_every_error_is_thrown_and_the_module_keeps_working() {
    let thrown = wasm_reliability::every_error_is_thrown_and_the_module_keeps_working()
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(thrown > 300, "only {thrown} calls threw");
}

#[wasm_bindgen_test]
fn browser_panic_reports_to_console_and_module_survives() {
    wasm_reliability::panic_reports_to_console_and_module_survives()
        .unwrap_or_else(|e| panic!("{e}"));
}

fn canvases() -> (wasm_bindgen::JsValue, web_sys::HtmlCanvasElement) {
    let document = web_sys::window().unwrap().document().unwrap();
    let canvas: web_sys::HtmlCanvasElement = document
        .create_element("canvas")
        .unwrap()
        .dyn_into()
        .unwrap();
    canvas.set_width(400);
    canvas.set_height(240);
    let object = js_sys::Object::new();
    js_sys::Reflect::set(&object, &"impulses".into(), &canvas).unwrap();
    let sensitivity: web_sys::HtmlCanvasElement = document
        .create_element("canvas")
        .unwrap()
        .dyn_into()
        .unwrap();
    sensitivity.set_width(400);
    sensitivity.set_height(240);
    js_sys::Reflect::set(&object, &"sensitivity".into(), &sensitivity).unwrap();
    (object.into(), canvas)
}

/// Sum of the canvas' pixel bytes: changes when anything is drawn.
fn checksum(canvas: &web_sys::HtmlCanvasElement) -> u64 {
    let ctx: web_sys::CanvasRenderingContext2d = canvas
        .get_context("2d")
        .unwrap()
        .unwrap()
        .dyn_into()
        .unwrap();
    let data = ctx
        .get_image_data(0.0, 0.0, canvas.width() as f64, canvas.height() as f64)
        .unwrap()
        .data();
    data.iter().map(|&b| b as u64).sum()
}

#[wasm_bindgen_test]
fn render_playground_survives_bad_states() {
    let (targets, canvas) = canvases();
    let good = js(
        r#"{"modes":[{"frequencyHz":2,"damping":0.05}],"shapers":[{"family":"zvd"},{"family":"ei","vtol":0.05}],"view":{"vtol":0.05}}"#,
    );
    let first = wasm::render_playground(good.clone(), targets.clone()).expect("good frame");
    let drawn = checksum(&canvas);
    assert!(drawn > 0);
    let mut bad = wasm_reliability::bad_values();
    bad.push(js(r#"{"modes":[{"frequencyHz":2}],"shapers":[]}"#));
    bad.push(js(r#"{"modes":[{"frequencyHz":2}],"shapers":[{"family":"zv"},{"family":"zv"},{"family":"zv"},{"family":"zv"},{"family":"zv"}]}"#));
    bad.push(js(
        r#"{"modes":[{"frequencyHz":2}],"shaper":{"family":"zv"},"view":{"points":1e12}}"#,
    ));
    bad.push(js(r#"{"modes":[{"frequencyHz":2}],"shaper":{"family":"zv"},"view":{"vtol":-1,"pixelRatio":1e308}}"#));
    for (k, state) in bad.into_iter().enumerate() {
        let r = wasm::render_playground(state, targets.clone());
        let err = r.expect_err(&format!("bad state {k} must throw"));
        let err: js_sys::Error = err.dyn_into().expect("a JS Error");
        assert!(!String::from(err.message()).is_empty());
        // Nothing drawn for a bad state: the last good charts stay.
        assert_eq!(checksum(&canvas), drawn, "bad state {k} changed the canvas");
        let again =
            wasm::render_playground(good.clone(), targets.clone()).expect("good frame again");
        assert_eq!(
            js_sys::JSON::stringify(&again).unwrap().as_string(),
            js_sys::JSON::stringify(&first).unwrap().as_string(),
            "the good frame changed after bad state {k}"
        );
    }
}
