//! The page's printed-corner view (issue 23 item 3): `renderCorner`, one call per frame — the
//! path planned once, printed unshaped and with each compared shaper (designed for X's modes on
//! X and for Y's on Y), the magnified tracks drawn on the canvas, the numbers returned.

use super::api::{from_js, from_js_root, js_error, to_js};
use super::args;
use crate::chart::{self, CornerTrack};
use crate::corner::CornerRinging;
use crate::design::ShaperSpec;
use crate::scenario::{CornerSetup, CornerSpec};
use plotters::prelude::IntoDrawingArea;
use serde::{Deserialize, Serialize};
use wasm_bindgen::prelude::*;

/// Most shapers compared at once.
const MAX_SHAPERS: usize = 8;

#[derive(Deserialize, Default, Debug)]
#[serde(rename_all = "camelCase", default)]
struct CornerOptions {
    pixel_ratio: Option<f64>,
    labels: Option<Vec<String>>,
}

/// One print's numbers.
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct PrintNumbers {
    label: String,
    corners: Vec<CornerRinging>,
    /// Largest peak deviation over the corners (mm).
    peak_deviation: f64,
    /// Largest ringing over the corners (mm).
    ringing: f64,
}

/// A shaper left out: why.
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct LeftOut {
    label: String,
    index: usize,
    field: Option<String>,
    message: String,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct CornerFrame {
    duration: f64,
    sample_period_s: f64,
    junction_speeds: Vec<f64>,
    unshaped: PrintNumbers,
    shapers: Vec<PrintNumbers>,
    left_out: Vec<LeftOut>,
}

fn numbers(label: String, corners: Vec<CornerRinging>) -> PrintNumbers {
    let max = |f: fn(&CornerRinging) -> f64| corners.iter().map(f).fold(0.0, f64::max);
    PrintNumbers {
        peak_deviation: max(|c| c.peak_deviation),
        ringing: max(|c| c.ringing),
        label,
        corners,
    }
}

/// `renderCorner(spec, shapers, canvas, { pixelRatio?, labels? })`: `spec` as
/// `simulateCorner` takes it (its axes' own shapers are ignored; `magnify` defaults to 50),
/// `shapers` a list of design specs (`{ family, …parameters }`, at most 8) each designed for X's
/// modes on X and Y's on Y → `{ duration, samplePeriodS, junctionSpeeds, unshaped: { label,
/// corners, peakDeviation, ringing }, shapers: [same], leftOut: [{ label, index, field,
/// message }] }`, the path and the magnified tracks drawn on `canvas` (chart::draw_corner). A
/// shaper that cannot be designed is left out (and said so); a bad spec throws, naming the field.
#[cfg(feature = "js-corner")]
#[wasm_bindgen(js_name = renderCorner, unchecked_return_type = "CornerFrame")]
pub fn render_corner(
    #[wasm_bindgen(unchecked_param_type = "CornerSpec")] spec: JsValue,
    #[wasm_bindgen(unchecked_param_type = "ShaperSpec[]")] shapers: JsValue,
    #[wasm_bindgen(unchecked_param_type = "HTMLCanvasElement")] canvas: JsValue,
    #[wasm_bindgen(unchecked_optional_param_type = "CornerOptions | null")] options: JsValue,
) -> Result<JsValue, JsValue> {
    // The canvas first, as every drawing export: without one (Node) the error names it.
    let canvas = args::canvas(canvas, "canvas").map_err(js_error)?;
    let mut spec: CornerSpec = from_js_root(spec, "spec").map_err(js_error)?;
    let specs: Vec<ShaperSpec> = from_js(shapers, "shapers").map_err(js_error)?;
    crate::error::count("shapers", specs.len(), 0, MAX_SHAPERS).map_err(js_error)?;
    let o: CornerOptions = if options.is_undefined() || options.is_null() {
        CornerOptions::default()
    } else {
        from_js(options, "options").map_err(js_error)?
    };
    spec.x.shaper = None;
    spec.x.impulses = None;
    spec.y.shaper = None;
    spec.y.impulses = None;
    spec.magnify = Some(spec.magnify.unwrap_or(50.0));
    let setup = CornerSetup::new(&spec).map_err(js_error)?;
    let label = |i: usize| {
        o.labels
            .as_ref()
            .and_then(|l| l.get(i).cloned())
            .unwrap_or_else(|| specs[i].name().to_string())
    };
    let unshaped = setup.print(None, None).map_err(js_error)?;
    let (mut prints, mut left_out) = (Vec::new(), Vec::new());
    for (i, s) in specs.iter().enumerate() {
        let done = setup
            .design_per_axis(s)
            .and_then(|[x, y]| setup.print(Some(&x), Some(&y)));
        match done {
            Ok(p) => prints.push((label(i), p)),
            Err(e) => left_out.push(LeftOut {
                label: label(i),
                index: i,
                field: e.field().map(|f| format!("shapers[{i}].{f}")),
                message: e.to_string(),
            }),
        }
    }
    let (backend, style) = super::measure::canvas_and_style(canvas, o.pixel_ratio)?;
    let mut points: Vec<[f64; 2]> = setup.plan.segments.iter().map(|s| s.start).collect();
    points.extend(setup.plan.segments.last().map(|s| s.end));
    let tracks: Vec<CornerTrack<'_>> = prints
        .iter()
        .filter_map(|(l, p)| p.drawn.as_ref().map(|d| (l.as_str(), d)))
        .collect();
    chart::draw_corner(
        &backend.into_drawing_area(),
        &points,
        unshaped.drawn.as_ref(),
        &tracks,
        spec.magnify.unwrap_or(50.0),
        &style,
    )
    .map_err(js_error)?;
    let frame = CornerFrame {
        duration: setup.plan.duration(),
        sample_period_s: setup.sample_period,
        junction_speeds: setup
            .plan
            .segments
            .iter()
            .skip(1)
            .map(|s| s.v_start)
            .collect(),
        unshaped: numbers("unshaped".into(), unshaped.print.corners),
        shapers: prints
            .into_iter()
            .map(|(l, p)| numbers(l, p.print.corners))
            .collect(),
        left_out,
    };
    to_js(&frame)
}
