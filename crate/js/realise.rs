//! The page's realisation view (web/realise.js): `drawRealisation` draws what `realizeShaper`
//! returned for each compared shaper — V(f) designed and as the controller runs it — with
//! [`crate::chart::draw_realisation`]. In the lazily fetched module (`js-recording`), with
//! `realizeShaper`, so the page's first load does not carry the realisation code.

use super::api::{from_js, js_error};
use super::args;
use super::measure::{canvas_and_style, css_hex, options as read_options};
use crate::chart;
use crate::vibration::SensitivityCurve;
use plotters::prelude::IntoDrawingArea;
use serde::Deserialize;
use wasm_bindgen::prelude::*;

/// One compared shaper's two curves (JS: `{ label, color?, ideal, realised }`, each curve
/// `{ frequencyHz, vibration }` as `realizeShaper` returns them with `curve`).
#[derive(Deserialize, Debug)]
#[serde(rename_all = "camelCase")]
struct Entry {
    label: String,
    #[serde(default)]
    color: Option<String>,
    ideal: SensitivityCurve,
    realised: SensitivityCurve,
}

/// `drawRealisation`'s data (JS: `{ shapers, vtol?, modesHz? }`).
#[derive(Deserialize, Debug)]
#[serde(rename_all = "camelCase")]
struct Data {
    shapers: Vec<Entry>,
    #[serde(default)]
    vtol: Option<f64>,
    #[serde(default)]
    modes_hz: Vec<f64>,
}

#[derive(Deserialize, Default, Debug)]
#[serde(rename_all = "camelCase", default)]
struct DrawOptions {
    pixel_ratio: Option<f64>,
}

/// `drawRealisation(canvas, { shapers: [{ label, color?: '#rrggbb', ideal, realised }], vtol?,
/// modesHz? }, { pixelRatio? })`: each shaper's designed V(f) solid and its realised V(f)
/// dashed in its colour (the first four colours given, else the page's series colours), Vtol
/// (fraction) and the modes marked. `ideal` / `realised` are `realizeShaper`'s
/// `sensitivityIdeal` / `sensitivityRealised` (`{ frequencyHz, vibration }`).
#[wasm_bindgen(js_name = drawRealisation)]
pub fn draw_realisation(
    #[wasm_bindgen(unchecked_param_type = "HTMLCanvasElement")] canvas: JsValue,
    #[wasm_bindgen(unchecked_param_type = "RealisationChartData")] data: JsValue,
    #[wasm_bindgen(unchecked_optional_param_type = "{ pixelRatio?: number } | null")]
    options: JsValue,
) -> Result<(), JsValue> {
    let canvas = args::canvas(canvas, "canvas").map_err(js_error)?;
    let data: Data = from_js(data, "data").map_err(js_error)?;
    let o: DrawOptions = read_options(options, "options").map_err(js_error)?;
    let (backend, mut style) = canvas_and_style(canvas, o.pixel_ratio)?;
    for (slot, entry) in style.colors.iter_mut().zip(&data.shapers) {
        if let Some(c) = entry.color.as_deref().and_then(css_hex) {
            *slot = c;
        }
    }
    let curves: Vec<chart::RealisedCurves<'_>> = data
        .shapers
        .iter()
        .map(|e| (e.label.as_str(), &e.ideal, &e.realised))
        .collect();
    chart::draw_realisation(
        &backend.into_drawing_area(),
        &curves,
        data.vtol,
        &data.modes_hz,
        &style,
    )
    .map_err(js_error)
}
