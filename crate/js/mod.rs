//! Everything that exists only for JavaScript (wasm32 only): the exports the page and the
//! library's `pkg/` call, and what only they need.
//!
//! - [`api`]: the JavaScript API (`design`, `residualVibration`, `sensitivity`, …, the page's
//!   `renderPlayground` and `exportShaper`);
//! - [`measure`]: its measured-data part (`parseRecording`, `welch`, `identifyModes`,
//!   `recommendShaper`, `drawSpectrum`, …);
//! - [`realise`]: the page's realisation view's chart (`drawRealisation`);
//! - `corner`: the page's printed-corner view, `renderCorner` (feature `js-corner`);
//! - [`playground`]: the page's frame, `renderPlayground`, in its stages;
//! - `bulk`: a shaper's impulses built as JS objects in bulk (the page's frame hands out
//!   ~20 000 of them with six modes);
//! - `args`: the exports' arguments checked as what they must be (a string, a number, a
//!   canvas, an array of numbers), whatever JS passes;
//! - `jsde`: the reader of JS values (serde, with the path of the failing field);
//! - `canvas`: the page's drawing backend (plotters on a 2-D canvas context).
//!
//! Every export is also re-exported here, so `input_shaping::js::design` is the Rust path of
//! the JS `design`.

pub mod api;
pub(crate) mod args;
#[cfg(feature = "js-playground")]
pub(crate) mod bulk;
pub(crate) mod canvas;
#[cfg(feature = "js-corner")]
pub mod corner;
pub(crate) mod jsde;
pub mod measure;
#[cfg(feature = "js-playground")]
pub mod playground;
#[cfg(any(feature = "js-api", feature = "js-recording"))]
pub mod realise;

// A build with only some of the export groups (Cargo features) may find one of them empty.
#[allow(unused_imports)]
pub use api::*;
#[cfg(feature = "js-corner")]
pub use corner::render_corner;
#[allow(unused_imports)]
pub use measure::*;
#[cfg(feature = "js-playground")]
pub use playground::render_playground;
#[cfg(any(feature = "js-api", feature = "js-recording"))]
pub use realise::*;

// The TypeScript types the exports' signatures name (`unchecked_param_type`,
// `unchecked_return_type`), appended to the `.d.ts` of every module: the hand-written ones of
// the arguments and results, and the family specs generated from the family table
// (`tests/families.rs` checks `families.d.ts` against `FAMILIES`). A custom section of the
// compiled module that wasm-bindgen removes: the shipped wasm is the same.
#[wasm_bindgen::prelude::wasm_bindgen(typescript_custom_section)]
const TYPES: &str = include_str!("types.d.ts");
#[wasm_bindgen::prelude::wasm_bindgen(typescript_custom_section)]
const FAMILY_SPECS: &str = include_str!("families.d.ts");
