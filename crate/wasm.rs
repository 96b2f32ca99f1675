//! The JavaScript API: thin glue between the page and the core. Objects cross the boundary as
//! plain JSON-like values (camelCase) through serde-wasm-bindgen; every error is thrown as a JS
//! `Error` whose message starts with the offending field and whose `field` property holds it.

use crate::chart::{self, ChartStyle};
use crate::design::{self, DesignRequest, ShaperSpec};
use crate::error::Error;
use crate::mode::{Mode, ModeSpec};
use crate::shaper::{Shaper, ShaperData};
use crate::vibration::{self, SensitivityOptions};
use plotters::prelude::*;
use plotters_canvas::CanvasBackend;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;
use web_sys::HtmlCanvasElement;

/// Installs the panic hook, so that a panic (a bug) is reported on the console with its
/// message instead of an opaque `unreachable` trap.
#[wasm_bindgen(start)]
pub fn start() {
    console_error_panic_hook::set_once();
}

/// Converts a crate error into a thrown JS `Error` carrying `field` and `kind`.
fn js_error(error: Error) -> JsValue {
    let e = js_sys::Error::new(&error.to_string());
    let kind = match &error {
        Error::InvalidInput { .. } => "invalid",
        Error::TooLarge { .. } => "tooLarge",
        Error::Infeasible { .. } => "infeasible",
        Error::Parse { .. } => "parse",
        Error::Render { .. } => "render",
    };
    let _ = js_sys::Reflect::set(&e, &"kind".into(), &kind.into());
    if let Some(field) = error.field() {
        let _ = js_sys::Reflect::set(&e, &"field".into(), &field.into());
    }
    e.into()
}

/// Reads a JS value into `T`, naming the path of a bad field under `what`.
fn from_js<T: DeserializeOwned>(value: JsValue, what: &str) -> Result<T, Error> {
    if value.is_undefined() || value.is_null() {
        return Err(Error::Parse {
            field: what.to_string(),
            reason: "is missing".into(),
        });
    }
    serde_path_to_error::deserialize(serde_wasm_bindgen::Deserializer::from(value)).map_err(|e| {
        let path = e.path().to_string();
        let field = match path.as_str() {
            "." | "" | "?" => what.to_string(),
            p if what.is_empty() => p.to_string(),
            p => format!("{what}.{p}"),
        };
        Error::Parse {
            field,
            reason: e.into_inner().to_string(),
        }
    })
}

/// Writes `value` to a plain JS object (maps as objects, not `Map`).
fn to_js<T: Serialize>(value: &T) -> Result<JsValue, JsValue> {
    value
        .serialize(&serde_wasm_bindgen::Serializer::json_compatible())
        .map_err(|e| {
            js_error(Error::Render {
                reason: e.to_string(),
            })
        })
}

fn shaper_from_js(value: JsValue) -> Result<Shaper, Error> {
    let data: ShaperData = from_js(value, "shaper")?;
    Shaper::from_data(&data).map_err(|e| e.within("shaper"))
}

fn mode_from_js(value: JsValue, what: &str) -> Result<Mode, Error> {
    let spec: ModeSpec = from_js(value, what)?;
    Mode::from_spec(&spec).map_err(|e| e.within(what))
}

/// `design(spec)`: `spec = { family, modes: [{ frequencyHz, damping }], …parameters }` →
/// `{ impulses: [{ time, amplitude }], duration }`.
#[wasm_bindgen]
pub fn design(spec: JsValue) -> Result<JsValue, JsValue> {
    let request: DesignRequest = from_js(spec, "").map_err(js_error)?;
    let shaper = design::design(&request).map_err(js_error)?;
    to_js(&shaper.to_data())
}

/// `residualVibration(shaper, { frequencyHz, damping })` → V as a fraction (1 = unshaped).
#[wasm_bindgen(js_name = residualVibration)]
pub fn residual_vibration(shaper: JsValue, mode: JsValue) -> Result<f64, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let mode = mode_from_js(mode, "mode").map_err(js_error)?;
    Ok(vibration::residual_vibration(&shaper, &mode))
}

/// `sensitivity(shaper, { fromHz, toHz, points, damping })` →
/// `{ frequencyHz: number[], vibration: number[] }`.
#[wasm_bindgen]
pub fn sensitivity(shaper: JsValue, options: JsValue) -> Result<JsValue, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let options: SensitivityOptions = from_js(options, "options").map_err(js_error)?;
    let curve = vibration::sensitivity(&shaper, &options).map_err(js_error)?;
    to_js(&curve)
}

/// `insensitivity(shaper, { frequencyHz, damping }, vtol)` → `{ lowHz, highHz, width }`, the
/// band around the mode where V ≤ vtol, width as a fraction of `frequencyHz`.
#[wasm_bindgen]
pub fn insensitivity(shaper: JsValue, mode: JsValue, vtol: f64) -> Result<JsValue, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let mode = mode_from_js(mode, "mode").map_err(js_error)?;
    let band = vibration::insensitivity(&shaper, &mode, vtol).map_err(js_error)?;
    to_js(&band)
}

/// Sets `object[key] = value`, reporting a failure as a render error.
fn set(object: &js_sys::Object, key: &str, value: &JsValue) -> Result<(), JsValue> {
    js_sys::Reflect::set(object, &key.into(), value)
        .map(|_| ())
        .map_err(|_| {
            js_error(Error::Render {
                reason: format!("could not set `{key}` on the result"),
            })
        })
}

/// `sensitivityMap(shaper, { fromHz, toHz, frequencyPoints, dampingFrom, dampingTo,
/// dampingPoints })` → `{ frequencyHz: number[], damping: number[], vibration: Float64Array }`:
/// V on the frequency × damping grid, `vibration` row-major with one row per damping value
/// (`vibration[k * frequencyHz.length + j]` is V at `damping[k]`, `frequencyHz[j]`). The grid
/// is returned as a typed array because copying it is far cheaper than building a JS array.
#[wasm_bindgen(js_name = sensitivityMap)]
pub fn sensitivity_map(shaper: JsValue, options: JsValue) -> Result<JsValue, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let options: vibration::SensitivityMapOptions =
        from_js(options, "options").map_err(js_error)?;
    let map = vibration::sensitivity_map(&shaper, &options).map_err(js_error)?;
    let out = js_sys::Object::new();
    set(&out, "frequencyHz", &to_js(&map.frequency_hz)?)?;
    set(&out, "damping", &to_js(&map.damping)?)?;
    let vibration = js_sys::Float64Array::from(map.vibration.as_slice());
    set(&out, "vibration", &vibration)?;
    Ok(out.into())
}

/// `dampingSensitivity(shaper, { frequencyHz, fromDamping, toDamping, points })` →
/// `{ damping: number[], vibration: number[] }`: V over damping ratios at one frequency.
#[wasm_bindgen(js_name = dampingSensitivity)]
pub fn damping_sensitivity(shaper: JsValue, options: JsValue) -> Result<JsValue, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let options: vibration::DampingSensitivityOptions =
        from_js(options, "options").map_err(js_error)?;
    let curve = vibration::damping_sensitivity(&shaper, &options).map_err(js_error)?;
    to_js(&curve)
}

/// `dampingInsensitivity(shaper, { frequencyHz, damping }, vtol)` →
/// `{ lowDamping, highDamping, width }`: the band of damping ratios around the mode's where
/// V ≤ vtol at the mode's frequency; `width = highDamping − lowDamping`.
#[wasm_bindgen(js_name = dampingInsensitivity)]
pub fn damping_insensitivity(
    shaper: JsValue,
    mode: JsValue,
    vtol: f64,
) -> Result<JsValue, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let mode = mode_from_js(mode, "mode").map_err(js_error)?;
    let band = vibration::damping_insensitivity(&shaper, &mode, vtol).map_err(js_error)?;
    to_js(&band)
}

/// `robustnessTable({ frequencyHz, damping }, vtol, specs?)` → `[{ spec, title, impulses,
/// durationS, durationPeriods, insensitivity, dampingInsensitivity }]`: each family designed for
/// the mode, its duration in periods and its insensitivities (Singhose 2009 Fig. 11).
/// `specs` is an array of `{ family, …parameters }`; without it, every family that needs no
/// parameters.
#[wasm_bindgen(js_name = robustnessTable)]
pub fn robustness_table(mode: JsValue, vtol: f64, specs: JsValue) -> Result<JsValue, JsValue> {
    let mode = mode_from_js(mode, "mode").map_err(js_error)?;
    let specs: Vec<ShaperSpec> = if specs.is_undefined() || specs.is_null() {
        crate::robustness::parameterless_specs()
    } else {
        from_js(specs, "specs").map_err(js_error)?
    };
    let rows = crate::robustness::robustness_table(&specs, &mode, vtol).map_err(js_error)?;
    to_js(&rows)
}

/// `families()` → the table of shaper families: `[{ name, title, guarantee, parameters, source }]`.
#[wasm_bindgen]
pub fn families() -> Result<JsValue, JsValue> {
    to_js(&design::FAMILIES)
}

/// What the page shows, in one object (see [`render_playground`]).
#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct PlaygroundState {
    modes: Vec<ModeSpec>,
    shaper: ShaperSpec,
    #[serde(default)]
    view: PlaygroundView,
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase", default)]
struct PlaygroundView {
    /// Sensitivity range, Hz; defaults to 0 … 2 × the highest mode.
    from_hz: Option<f64>,
    to_hz: Option<f64>,
    points: usize,
    /// Tolerable vibration, fraction.
    vtol: f64,
    /// Device pixel ratio the canvases were sized with.
    pixel_ratio: f64,
}

impl Default for PlaygroundView {
    fn default() -> Self {
        PlaygroundView {
            from_hz: None,
            to_hz: None,
            points: 600,
            vtol: 0.05,
            pixel_ratio: 1.0,
        }
    }
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct PlaygroundResult {
    shaper: ShaperData,
    sensitivity: vibration::SensitivityCurve,
    insensitivity: Vec<vibration::Insensitivity>,
    residual_at_modes: Vec<f64>,
    centroid_delay: Option<f64>,
}

fn canvas(canvases: &JsValue, key: &str) -> Option<HtmlCanvasElement> {
    js_sys::Reflect::get(canvases, &key.into())
        .ok()
        .and_then(|c| c.dyn_into::<HtmlCanvasElement>().ok())
}

/// `renderPlayground(state, canvases)`: everything one frame of the page needs, in one call.
///
/// `state = { modes, shaper: { family, …parameters }, view: { fromHz, toHz, points, vtol,
/// pixelRatio } }`; `canvases = { impulses?, sensitivity? }` (HTMLCanvasElements). Designs the
/// shaper, computes its sensitivity curve (at the first mode's damping), insensitivity and
/// residual vibration at each mode, draws the charts, and returns `{ shaper, sensitivity,
/// insensitivity: [{ lowHz, highHz, width }], residualAtModes, centroidDelay }`. Nothing is
/// drawn unless everything computed, so a bad input leaves the last good charts on screen.
#[wasm_bindgen(js_name = renderPlayground)]
pub fn render_playground(state: JsValue, canvases: JsValue) -> Result<JsValue, JsValue> {
    let state: PlaygroundState = from_js(state, "").map_err(js_error)?;
    let modes = Mode::list(&state.modes).map_err(js_error)?;
    let shaper =
        design::design_for(&state.shaper, &modes).map_err(|e| js_error(e.within("shaper")))?;
    let view = &state.view;
    let f_max = modes.iter().map(Mode::frequency_hz).fold(0.0_f64, f64::max);
    let options = SensitivityOptions {
        from_hz: view.from_hz.unwrap_or(0.0),
        to_hz: view.to_hz.unwrap_or(2.0 * f_max),
        points: view.points,
        damping: modes[0].damping(),
    };
    let curve =
        vibration::sensitivity(&shaper, &options).map_err(|e| js_error(e.within("view")))?;
    let insensitivity = modes
        .iter()
        .map(|m| vibration::insensitivity(&shaper, m, view.vtol))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| js_error(e.within("view")))?;
    let residual_at_modes = modes
        .iter()
        .map(|m| vibration::residual_vibration(&shaper, m))
        .collect();
    let style = ChartStyle {
        scale: if view.pixel_ratio.is_finite() && view.pixel_ratio > 0.0 {
            view.pixel_ratio
        } else {
            1.0
        },
    };
    let label = state.shaper.info().map_or("shaper", |f| f.title);
    if let Some(c) = canvas(&canvases, "impulses") {
        if let Some(backend) = CanvasBackend::with_canvas_object(c) {
            chart::draw_impulses(&backend.into_drawing_area(), &[(label, &shaper)], &style)
                .map_err(js_error)?;
        }
    }
    if let Some(c) = canvas(&canvases, "sensitivity") {
        if let Some(backend) = CanvasBackend::with_canvas_object(c) {
            let modes_hz: Vec<f64> = modes.iter().map(Mode::frequency_hz).collect();
            chart::draw_sensitivity(
                &backend.into_drawing_area(),
                &[(label, &curve)],
                Some(view.vtol),
                &modes_hz,
                &style,
            )
            .map_err(js_error)?;
        }
    }
    to_js(&PlaygroundResult {
        shaper: shaper.to_data(),
        sensitivity: curve,
        insensitivity,
        residual_at_modes,
        centroid_delay: shaper.centroid_delay(),
    })
}
