//! Reliability of the JS API in Node (issue 6; `wasm-pack test --node`): every exported function
//! throws a JS `Error` with a `kind` for bad input of every JS kind and keeps working for the
//! next call; a panic provoked on a test-only path is reported on the console by the panic
//! hook. The checks live in `tests/wasm_reliability/mod.rs`, shared with the Chromium run.
#![cfg(target_arch = "wasm32")]

mod wasm_reliability;

use wasm_bindgen_test::wasm_bindgen_test;

#[wasm_bindgen_test]
fn node_every_error_is_thrown_and_the_module_keeps_working() {
    let thrown = wasm_reliability::every_error_is_thrown_and_the_module_keeps_working()
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(thrown > 300, "only {thrown} calls threw");
}

#[wasm_bindgen_test]
fn node_design_throws_for_every_bad_value() {
    wasm_reliability::always_throwing_for_design().unwrap_or_else(|e| panic!("{e}"));
}

#[wasm_bindgen_test]
fn node_panic_reports_to_console_and_module_survives() {
    wasm_reliability::panic_reports_to_console_and_module_survives()
        .unwrap_or_else(|e| panic!("{e}"));
}
