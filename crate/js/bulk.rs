//! A shaper's impulses handed to JavaScript in bulk: the `{ time, amplitude }` objects built
//! by one small JavaScript function from a view of the module's memory, instead of by
//! serde-wasm-bindgen's serializer, which crosses the boundary five or six times per impulse
//! (an object, two keys, two numbers, two property sets). A page frame with six modes returns
//! ~20 500 impulses (ZV-D³ over six modes alone has 15 625): through serde they took ~4.5 ms
//! of the frame (docs/page-performance.md, *2026-12-07*); the builder takes ~0.2 ms.
//!
//! The function is made once with the `Function` constructor. A page whose Content Security
//! Policy forbids that (`unsafe-eval`) gets the constructor's exception, caught: the shaper is
//! then serialized by serde as before — the same value either way (test
//! `render_playground_hands_out_the_shapers_design_gives`, tests/wasm_canvas.rs).

use crate::shaper::ShaperData;
use serde::ser::{Serialize, Serializer};
use std::cell::OnceCell;
use wasm_bindgen::prelude::*;

/// The builder's body: the shaper `{ impulses, duration }`, plus `factors` when `c` has more
/// than one end, as its derived `Serialize` writes it (keys in that order, `{ time, amplitude
/// }` objects). `a` holds time, amplitude, time, amplitude, … of the impulses and then of each
/// factor (a view of the module's memory, read at once); `c` the ends of those sequences in
/// entries of `a`; `d` the duration.
const BODY: &str = "const o=(s,e)=>{const r=new Array((e-s)>>1);\
for(let i=s,j=0;i<e;i+=2)r[j++]={time:a[i],amplitude:a[i+1]};return r};\
const x={impulses:o(0,c[0]),duration:d};\
if(c.length>1)x.factors=Array.from(c.subarray(1),(e,k)=>o(c[k],e));return x";

#[wasm_bindgen]
extern "C" {
    /// A function made by the `Function` constructor.
    #[wasm_bindgen(js_name = Function)]
    #[derive(Clone)]
    type Builder;

    /// `new Function(a, c, d, body)`; its exception (a policy forbidding `eval`) caught.
    #[wasm_bindgen(constructor, js_class = "Function", catch)]
    fn make(a: &str, c: &str, d: &str, body: &str) -> Result<Builder, JsValue>;

    /// `builder.call(null, a, c, d)`, `a` and `c` passed as views of the module's memory.
    #[wasm_bindgen(method, js_name = call)]
    fn build(this: &Builder, this_arg: &JsValue, a: &[f64], c: &[u32], d: f64) -> JsValue;
}

thread_local! {
    /// The builder, or `None` where the page's policy forbids making one.
    static BUILDER: OnceCell<Option<Builder>> = const { OnceCell::new() };
}

/// A JS value that serde-wasm-bindgen's serializer hands out as it is
/// (`serde_wasm_bindgen::preserve`).
struct Preserved(JsValue);

impl Serialize for Preserved {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        serde_wasm_bindgen::preserve::serialize(&self.0, s)
    }
}

/// The derived `Serialize`, out of line (one copy for both of [`serialize_shaper`]'s uses).
#[inline(never)]
fn derived<S: Serializer>(shaper: &ShaperData, s: S) -> Result<S::Ok, S::Error> {
    shaper.serialize(s)
}

/// Serializes `shaper` (for serde-wasm-bindgen's serializer) as its derived `Serialize` does
/// — `{ impulses, duration }`, plus `factors` for a factored shaper — with the impulse arrays
/// built in bulk (module doc), or by the derived `Serialize` where no builder can be made.
/// For `#[serde(serialize_with)]` on the fields that hand shapers out every frame.
pub(crate) fn serialize_shaper<S: Serializer>(
    shaper: &ShaperData,
    s: S,
) -> Result<S::Ok, S::Error> {
    let Some(builder) = BUILDER.with(|b| {
        b.get_or_init(|| Builder::make("a", "c", "d", BODY).ok())
            .clone()
    }) else {
        return derived(shaper, s);
    };
    let factors = shaper.factors.as_deref().unwrap_or_default();
    let (mut a, mut ends) = (Vec::new(), Vec::new());
    for sequence in std::iter::once(&shaper.impulses).chain(factors) {
        for i in sequence {
            a.push(i.time);
            a.push(i.amplitude);
        }
        // Within u32: a shaper has at most 65 536 impulses, its factors fewer.
        ends.push(a.len() as u32);
    }
    Preserved(builder.build(&JsValue::NULL, &a, &ends, shaper.duration)).serialize(s)
}
