//! The exports' arguments, checked here rather than by the generated glue (issue 21 item 1).
//!
//! Every export takes its arguments as `JsValue`s: the glue passes a `JsValue` through as it is,
//! whereas for a `&str`, a number or an imported type it converts first — `passStringToWasm0` of
//! a number or an object reads out of bounds (a trap), of `null` throws the glue's own
//! `TypeError`, and a number parameter turns `"0.05"` into 0.05 and `null` into 0 before any
//! check could see them. Here each argument is read as what it must be, and anything else is
//! the documented `Error` naming the argument (`kind: "parse"`, `field: "text"`).
//!
//! Long arrays are copied into the module only after their length is checked
//! ([`MAX_ARRAY_LENGTH`]): a sparse `new Array(2 ** 32 - 1)` would otherwise ask for 32 GB.
//!
//! A build with only some of the export groups (Cargo features) leaves some readers unused.
#![cfg_attr(not(feature = "js-api"), allow(dead_code))]

use crate::error::Error;
use wasm_bindgen::{JsCast, JsValue};

/// The longest array or typed array of numbers an export copies in: the longest signal the
/// measured-data functions accept ([`crate::measure::psd::MAX_SIGNAL_LENGTH`], 2²⁶ samples,
/// 512 MB as `f64`). Longer is a `tooLarge` error naming the argument, before any copy.
pub(crate) const MAX_ARRAY_LENGTH: usize = crate::measure::psd::MAX_SIGNAL_LENGTH;

/// What `value` is, in a few words for an error message ("a number", "null", …).
pub(crate) fn describe(value: &JsValue) -> &'static str {
    if value.is_undefined() {
        "undefined"
    } else if value.is_null() {
        "null"
    } else if value.as_bool().is_some() {
        "a boolean"
    } else if value.as_f64().is_some() {
        "a number"
    } else if value.is_string() {
        "a string"
    } else if value.is_bigint() {
        "a BigInt"
    } else if value.is_symbol() {
        "a symbol"
    } else if value.is_function() {
        "a function"
    } else if js_sys::Array::is_array(value) {
        "an array"
    } else if value.is_instance_of::<js_sys::ArrayBuffer>() || js_sys::ArrayBuffer::is_view(value) {
        "binary data"
    } else {
        "an object"
    }
}

fn wrong_type(field: &str, value: &JsValue, expected: &str) -> Error {
    Error::Parse {
        field: field.to_string(),
        reason: if value.is_undefined() {
            "is missing".into()
        } else {
            format!("must be {expected}, got {}", describe(value))
        },
    }
}

/// A string argument (`text`, `chunk`).
pub(crate) fn string(value: &JsValue, field: &str) -> Result<String, Error> {
    value
        .as_string()
        .ok_or_else(|| wrong_type(field, value, "a string"))
}

/// A number argument (`vtol`): a JS number (NaN too: the function's own check names it), not a
/// string or anything `Number()` would convert.
pub(crate) fn number(value: &JsValue, field: &str) -> Result<f64, Error> {
    value
        .as_f64()
        .ok_or_else(|| wrong_type(field, value, "a number"))
}

/// A canvas argument: an `HTMLCanvasElement` (so never in Node).
#[cfg(any(
    feature = "js-playground",
    feature = "js-recording",
    feature = "js-corner"
))]
pub(crate) fn canvas(value: JsValue, field: &str) -> Result<web_sys::HtmlCanvasElement, Error> {
    value
        .dyn_into::<web_sys::HtmlCanvasElement>()
        .map_err(|v| wrong_type(field, &v, "an HTMLCanvasElement"))
}

fn too_long(field: &str, length: usize) -> Error {
    Error::TooLarge {
        field: field.to_string(),
        value: length as f64,
        limit: MAX_ARRAY_LENGTH as f64,
    }
}

/// A `Float64Array`, a `Float32Array` or an array of numbers as a `Vec<f64>`, at most
/// [`MAX_ARRAY_LENGTH`] long, naming `field[i]` for an element that is not a number. A typed
/// array on a detached buffer reads as empty (its length is 0).
pub(crate) fn f64_vec(value: &JsValue, field: &str) -> Result<Vec<f64>, Error> {
    // `instanceof` alone would take a Proxy of a typed array, whose `length` then throws.
    let view = js_sys::ArrayBuffer::is_view(value);
    if let Some(a) = value.dyn_ref::<js_sys::Float64Array>().filter(|_| view) {
        let n = a.length() as usize;
        if n > MAX_ARRAY_LENGTH {
            return Err(too_long(field, n));
        }
        // A typed array on a detached buffer has length 0, and copying from it throws.
        return Ok(if n == 0 { Vec::new() } else { a.to_vec() });
    }
    if let Some(a) = value.dyn_ref::<js_sys::Float32Array>().filter(|_| view) {
        let n = a.length() as usize;
        if n > MAX_ARRAY_LENGTH {
            return Err(too_long(field, n));
        }
        if n == 0 {
            return Ok(Vec::new());
        }
        return Ok(a.to_vec().into_iter().map(f64::from).collect());
    }
    if let Some(a) = value.dyn_ref::<js_sys::Array>() {
        let n = a.length() as usize;
        if n > MAX_ARRAY_LENGTH {
            return Err(too_long(field, n));
        }
        // Grown as read, not reserved from the length: a sparse array stops at its first hole.
        let mut out = Vec::new();
        for i in 0..n {
            let v = a.get(i as u32);
            out.push(v.as_f64().ok_or_else(|| Error::Parse {
                field: format!("{field}[{i}]"),
                reason: "must be a number".into(),
            })?);
        }
        return Ok(out);
    }
    if value.is_null() {
        return Err(wrong_type(field, &JsValue::UNDEFINED, ""));
    }
    Err(wrong_type(
        field,
        value,
        "a Float64Array or an array of numbers",
    ))
}

#[wasm_bindgen::prelude::wasm_bindgen]
extern "C" {
    /// `Object.assign(target, source)`, its exception caught (a getter or a Proxy trap of
    /// `source` may throw).
    #[wasm_bindgen(catch, js_namespace = Object, js_name = assign)]
    fn try_assign(target: &js_sys::Object, source: &JsValue) -> Result<JsValue, JsValue>;
}

/// A copy of the object `value` (its own enumerable properties), or a parse error naming
/// `field` when reading them throws.
pub(crate) fn copy_object(value: &JsValue, field: &str) -> Result<js_sys::Object, Error> {
    let copy = js_sys::Object::new();
    try_assign(&copy, value).map_err(|_| Error::Parse {
        field: field.to_string(),
        reason: "could not be read (a getter or a Proxy trap threw)".into(),
    })?;
    Ok(copy)
}
