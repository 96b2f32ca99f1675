//! The JavaScript API: thin glue between the page and the core. Objects cross the boundary as
//! plain JSON-like values (camelCase) through serde-wasm-bindgen; every error is thrown as a JS
//! `Error` whose message starts with the offending field and whose `field` property holds it.
//!
//! Each export belongs to a Cargo feature (`js-api`, `js-playground`, `js-recording`; see
//! Cargo.toml). A build with only some of them leaves helpers unused, hence the allow there.
#![cfg_attr(not(feature = "js-api"), allow(dead_code, unused_imports))]

use crate::design::{self, DesignRequest, ShaperSpec};
use crate::error::Error;
use crate::mode::{Mode, ModeSpec};
use crate::shaper::{Shaper, ShaperData};
use crate::vibration::{self, SensitivityOptions};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use wasm_bindgen::prelude::*;

/// Installs the panic hook, so that a panic (a bug) is reported on the console with its
/// message instead of an opaque `unreachable` trap.
#[wasm_bindgen(start)]
pub fn start() {
    console_error_panic_hook::set_once();
}

/// Converts a crate error into a thrown JS `Error` carrying `field` and `kind`.
pub(crate) fn js_error(error: Error) -> JsValue {
    let e = js_sys::Error::new(&error.to_string());
    let kind = match &error {
        Error::InvalidInput { .. } => "invalid",
        Error::TooLarge { .. } => "tooLarge",
        Error::Infeasible { .. } => "infeasible",
        Error::Parse { .. } => "parse",
        Error::Render { .. } => "render",
        Error::Unavailable { .. } => "unavailable",
    };
    let _ = js_sys::Reflect::set(&e, &"kind".into(), &kind.into());
    if let Some(field) = error.field() {
        let _ = js_sys::Reflect::set(&e, &"field".into(), &field.into());
    }
    e.into()
}

/// Reads a JS value into `T`, naming the path of a bad field under `what`.
pub(crate) fn from_js<T: DeserializeOwned + std::fmt::Debug>(
    value: JsValue,
    what: &str,
) -> Result<T, Error> {
    read(value, what, what)
}

/// Reads a spec (the one argument of `design`, `simulate`, …, the playground's `state`) into
/// `T`: its fields are named from its root (`family`, `modes[0].damping`), the value itself
/// `root` (`spec: is missing`).
pub(crate) fn from_js_root<T: DeserializeOwned + std::fmt::Debug>(
    value: JsValue,
    root: &str,
) -> Result<T, Error> {
    read(value, "", root)
}

/// Reads `value`, naming a field inside it `prefix.path` and the value itself `root`.
fn read<T: DeserializeOwned + std::fmt::Debug>(
    value: JsValue,
    prefix: &str,
    root: &str,
) -> Result<T, Error> {
    if value.is_undefined() || value.is_null() {
        return Err(Error::Parse {
            field: root.to_string(),
            reason: "is missing".into(),
        });
    }
    super::jsde::deserialize(value).map_err(|(path, e)| {
        let field = match path.as_str() {
            "." | "" | "?" => root.to_string(),
            p if prefix.is_empty() => p.to_string(),
            p => format!("{prefix}.{p}"),
        };
        Error::Parse {
            field,
            reason: e.to_string(),
        }
    })
}

/// Writes `value` to a plain JS object (maps as objects, not `Map`).
pub(crate) fn to_js<T: Serialize>(value: &T) -> Result<JsValue, JsValue> {
    serialized(value).map_err(js_error)
}

/// [`to_js`] with the error as the crate's.
pub(crate) fn serialized<T: Serialize>(value: &T) -> Result<JsValue, Error> {
    value
        .serialize(&serde_wasm_bindgen::Serializer::json_compatible())
        .map_err(|e| Error::Render {
            reason: e.to_string(),
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

/// `design(spec)`'s result: the shaper's wire form ([`ShaperData`]'s keys, in its order) and,
/// for `si` and `direct`, the solver's report.
#[cfg(any(feature = "js-api", feature = "js-designer"))]
#[derive(Serialize)]
struct DesignedOut {
    impulses: Vec<crate::shaper::Impulse>,
    duration: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    factors: Option<Vec<Vec<crate::shaper::Impulse>>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    solver: Option<crate::solve::SolverReport>,
}

/// `design(spec)`: `spec = { family, modes: [{ frequencyHz, damping }], …parameters }` →
/// `{ impulses: [{ time, amplitude }], duration }`, plus `solver: { polished, rounds,
/// programs }` for the families the optimisation solver designs (`si`, `direct`).
#[cfg(any(feature = "js-api", feature = "js-designer"))]
#[wasm_bindgen(unchecked_return_type = "Shaper")]
pub fn design(
    #[wasm_bindgen(unchecked_param_type = "DesignSpec")] spec: JsValue,
) -> Result<JsValue, JsValue> {
    let request: DesignRequest = from_js_root(spec, "spec").map_err(js_error)?;
    #[cfg(feature = "js-api")]
    let designed = design::design_report(&request).map_err(js_error)?;
    // The page's design worker's module: the solved families alone (README, *Playground*).
    #[cfg(not(feature = "js-api"))]
    let designed = Mode::list(&request.modes)
        .and_then(|modes| design::design_solved_report(&request.shaper, &modes))
        .map_err(js_error)?;
    let ShaperData {
        impulses,
        duration,
        factors,
    } = designed.shaper.to_data();
    to_js(&DesignedOut {
        impulses,
        duration,
        factors,
        solver: designed.solver,
    })
}

/// `residualVibration(shaper, { frequencyHz, damping })` → V as a fraction (1 = unshaped).
#[cfg(feature = "js-api")]
#[wasm_bindgen(js_name = residualVibration)]
pub fn residual_vibration(
    #[wasm_bindgen(unchecked_param_type = "ShaperInput")] shaper: JsValue,
    #[wasm_bindgen(unchecked_param_type = "ModeSpec")] mode: JsValue,
) -> Result<f64, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let mode = mode_from_js(mode, "mode").map_err(js_error)?;
    Ok(vibration::residual_vibration(&shaper, &mode))
}

/// `sensitivity(shaper, { fromHz, toHz, points, damping })` →
/// `{ frequencyHz: number[], vibration: number[] }`.
#[cfg(feature = "js-api")]
#[wasm_bindgen(unchecked_return_type = "SensitivityCurve")]
pub fn sensitivity(
    #[wasm_bindgen(unchecked_param_type = "ShaperInput")] shaper: JsValue,
    #[wasm_bindgen(unchecked_param_type = "SensitivityOptions")] options: JsValue,
) -> Result<JsValue, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let options: SensitivityOptions = from_js(options, "options").map_err(js_error)?;
    let curve = vibration::sensitivity(&shaper, &options).map_err(js_error)?;
    to_js(&curve)
}

/// `insensitivity(shaper, { frequencyHz, damping }, vtol)` → `{ lowHz, highHz, width }`, the
/// band around the mode where V ≤ vtol, width as a fraction of `frequencyHz`.
#[cfg(feature = "js-api")]
#[wasm_bindgen(unchecked_return_type = "Insensitivity")]
pub fn insensitivity(
    #[wasm_bindgen(unchecked_param_type = "ShaperInput")] shaper: JsValue,
    #[wasm_bindgen(unchecked_param_type = "ModeSpec")] mode: JsValue,
    #[wasm_bindgen(unchecked_param_type = "number")] vtol: JsValue,
) -> Result<JsValue, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let mode = mode_from_js(mode, "mode").map_err(js_error)?;
    let vtol = super::args::number(&vtol, "vtol").map_err(js_error)?;
    let band = vibration::insensitivity(&shaper, &mode, vtol).map_err(js_error)?;
    to_js(&band)
}

/// Sets `object[key] = value`, reporting a failure as a render error.
pub(crate) fn set(object: &js_sys::Object, key: &str, value: &JsValue) -> Result<(), JsValue> {
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
#[cfg(feature = "js-api")]
#[wasm_bindgen(js_name = sensitivityMap, unchecked_return_type = "SensitivityMap")]
pub fn sensitivity_map(
    #[wasm_bindgen(unchecked_param_type = "ShaperInput")] shaper: JsValue,
    #[wasm_bindgen(unchecked_param_type = "SensitivityMapOptions")] options: JsValue,
) -> Result<JsValue, JsValue> {
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
#[cfg(feature = "js-api")]
#[wasm_bindgen(js_name = dampingSensitivity, unchecked_return_type = "DampingSensitivityCurve")]
pub fn damping_sensitivity(
    #[wasm_bindgen(unchecked_param_type = "ShaperInput")] shaper: JsValue,
    #[wasm_bindgen(unchecked_param_type = "DampingSensitivityOptions")] options: JsValue,
) -> Result<JsValue, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let options: vibration::DampingSensitivityOptions =
        from_js(options, "options").map_err(js_error)?;
    let curve = vibration::damping_sensitivity(&shaper, &options).map_err(js_error)?;
    to_js(&curve)
}

/// `dampingInsensitivity(shaper, { frequencyHz, damping }, vtol)` →
/// `{ lowDamping, highDamping, width }`: the band of damping ratios around the mode's where
/// V ≤ vtol at the mode's frequency; `width = highDamping − lowDamping`.
#[cfg(feature = "js-api")]
#[wasm_bindgen(js_name = dampingInsensitivity, unchecked_return_type = "DampingInsensitivity")]
pub fn damping_insensitivity(
    #[wasm_bindgen(unchecked_param_type = "ShaperInput")] shaper: JsValue,
    #[wasm_bindgen(unchecked_param_type = "ModeSpec")] mode: JsValue,
    #[wasm_bindgen(unchecked_param_type = "number")] vtol: JsValue,
) -> Result<JsValue, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let mode = mode_from_js(mode, "mode").map_err(js_error)?;
    let vtol = super::args::number(&vtol, "vtol").map_err(js_error)?;
    let band = vibration::damping_insensitivity(&shaper, &mode, vtol).map_err(js_error)?;
    to_js(&band)
}

/// `robustnessTable({ frequencyHz, damping }, vtol, specs?)` → `[{ spec, title, impulses,
/// durationS, durationPeriods, insensitivity, dampingInsensitivity }]`: each family designed for
/// the mode, its duration in periods and its insensitivities (Singhose 2009 Fig. 11).
/// `specs` is an array of `{ family, …parameters }`; without it, every family that needs no
/// parameters.
#[cfg(feature = "js-api")]
#[wasm_bindgen(js_name = robustnessTable, unchecked_return_type = "RobustnessRow[]")]
pub fn robustness_table(
    #[wasm_bindgen(unchecked_param_type = "ModeSpec")] mode: JsValue,
    #[wasm_bindgen(unchecked_param_type = "number")] vtol: JsValue,
    #[wasm_bindgen(unchecked_optional_param_type = "ShaperSpec[] | null")] specs: JsValue,
) -> Result<JsValue, JsValue> {
    let mode = mode_from_js(mode, "mode").map_err(js_error)?;
    let vtol = super::args::number(&vtol, "vtol").map_err(js_error)?;
    let specs: Vec<ShaperSpec> = if specs.is_undefined() || specs.is_null() {
        crate::robustness::parameterless_specs()
    } else {
        from_js(specs, "specs").map_err(js_error)?
    };
    let rows = crate::robustness::robustness_table(&specs, &mode, vtol).map_err(js_error)?;
    to_js(&rows)
}

/// `families()` → the table of shaper families: `[{ name, title, guarantee, parameters, source }]`.
#[cfg(feature = "js-playground")]
#[wasm_bindgen(unchecked_return_type = "FamilyInfo[]")]
pub fn families() -> Result<JsValue, JsValue> {
    to_js(&design::FAMILIES)
}

/// Options of [`export_shaper`].
#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
struct ExportOptions {
    /// `"csv"`, `"json"`, `"c"` or `"rrf"`.
    format: String,
    /// C identifier prefix for `"c"` (default `shaper`).
    #[serde(default)]
    name: Option<String>,
    /// First-line comment for `"c"` and `"cFixed"`.
    #[serde(default)]
    comment: Option<String>,
    /// `"cFixed"`: amplitude resolution (e.g. 255 for 8-bit PWM; default 65535).
    #[serde(default)]
    amplitude_steps: Option<u32>,
    /// `"cFixed"`: timer tick in seconds (default 1e-5).
    #[serde(default)]
    tick_s: Option<f64>,
}

/// `exportShaper(shaper, { format, name?, comment?, amplitudeSteps?, tickS? })` → the export
/// as a string: `"csv"` (`time_s,amplitude` rows), `"json"` (as `design` returns), `"c"`
/// (float arrays `<name>_time_s`, `<name>_amplitude`), `"cFixed"` (integer amplitudes in
/// 1/`amplitudeSteps` and times in ticks of `tickS`), `"rrf"` (RepRapFirmware 3.6+
/// `M593 P"custom"` line).
#[cfg(feature = "js-playground")]
#[wasm_bindgen(js_name = exportShaper)]
pub fn export_shaper(
    #[wasm_bindgen(unchecked_param_type = "ShaperInput")] shaper: JsValue,
    #[wasm_bindgen(unchecked_param_type = "ExportOptions")] options: JsValue,
) -> Result<String, JsValue> {
    use crate::export;
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let options: ExportOptions = from_js(options, "options").map_err(js_error)?;
    match options.format.as_str() {
        "csv" => Ok(export::to_csv(&shaper)),
        "json" => Ok(export::to_json(&shaper)),
        "c" => export::to_c_float(
            &shaper,
            options.name.as_deref().unwrap_or("shaper"),
            options.comment.as_deref().unwrap_or("input shaper"),
        )
        .map_err(|e| js_error(e.within("options"))),
        "cFixed" => export::to_c_fixed(
            &shaper,
            options.name.as_deref().unwrap_or("shaper"),
            options.comment.as_deref().unwrap_or("input shaper"),
            options.amplitude_steps.unwrap_or(65535),
            options.tick_s.unwrap_or(1e-5),
        )
        .map_err(|e| js_error(e.within("options"))),
        "rrf" => export::to_rrf_m593(&shaper).map_err(|e| js_error(e.within("shaper"))),
        other => Err(js_error(Error::invalid(
            "options.format",
            format!("unknown export format {other:?}; expected csv, json, c, cFixed or rrf"),
        ))),
    }
}

/// `klipperFigures(shaper, { scv })` → `{ smoothing, maxAccel }` with Klipper's definitions
/// (smoothing in mm at 5000 mm/s², suggested max acceleration in mm/s² at 0.12 mm smoothing;
/// `scv` is the square corner velocity in mm/s, default 5). `maxAccel` is `null` for a single
/// impulse (unbounded).
#[cfg(feature = "js-api")]
#[wasm_bindgen(js_name = klipperFigures, unchecked_return_type = "KlipperFigures")]
pub fn klipper_figures(
    #[wasm_bindgen(unchecked_param_type = "ShaperInput")] shaper: JsValue,
    #[wasm_bindgen(unchecked_optional_param_type = "KlipperFiguresOptions | null")]
    options: JsValue,
) -> Result<JsValue, JsValue> {
    #[derive(Debug, Deserialize)]
    struct Options {
        #[serde(default = "default_scv")]
        scv: f64,
    }
    fn default_scv() -> f64 {
        crate::smoothing::KLIPPER_SCV
    }
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let options: Options = if options.is_undefined() || options.is_null() {
        Options { scv: default_scv() }
    } else {
        from_js(options, "options").map_err(js_error)?
    };
    let figures = crate::smoothing::klipper_figures(&shaper, options.scv)
        .map_err(|e| js_error(e.within("options")))?;
    to_js(&figures)
}

/// `rampDelay(shaper, { frequencyHz, damping })` → τ = 2ζ/ω + Σ Aᵢtᵢ / Σ Aᵢ in seconds, the lag
/// of the plant's response to a slow ramp (Kamel, Lange & Hirzinger eq. 10).
#[cfg(feature = "js-api")]
#[wasm_bindgen(js_name = rampDelay)]
pub fn ramp_delay(
    #[wasm_bindgen(unchecked_param_type = "ShaperInput")] shaper: JsValue,
    #[wasm_bindgen(unchecked_param_type = "ModeSpec")] mode: JsValue,
) -> Result<f64, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let mode = mode_from_js(mode, "mode").map_err(js_error)?;
    design::sampled::ramp_delay(&shaper, &mode).map_err(|e| js_error(e.within("shaper")))
}

/// `sampledReport(spec)`, `spec.family = "sampled"` → `{ impulses, duration, startTime,
/// rampDelay, cost: { total, controlError, amplitudePenalty }, baselineCost, costReduction }`:
/// the design `design(spec)` returns plus its ramp delay (eq. 10) and cost J_q (eq. 17), and the
/// cost of the minimum-norm shaper under the same constraints.
#[cfg(any(feature = "js-api", feature = "js-designer"))]
#[wasm_bindgen(js_name = sampledReport, unchecked_return_type = "SampledReport")]
pub fn sampled_report(
    #[wasm_bindgen(unchecked_param_type = "SampledDesignSpec")] spec: JsValue,
) -> Result<JsValue, JsValue> {
    let request: DesignRequest = from_js_root(spec, "spec").map_err(js_error)?;
    let ShaperSpec::Sampled(sampled) = &request.shaper else {
        return Err(js_error(Error::invalid(
            "family",
            format!(
                "sampledReport needs family \"sampled\", got \"{}\"",
                request.shaper.name()
            ),
        )));
    };
    let modes = Mode::list(&request.modes).map_err(js_error)?;
    let report = design::sampled::report(&modes, sampled).map_err(js_error)?;
    to_js(&report)
}

/// `quantize(shaper, { frequencyHz, damping }, { amplitudeSteps, tickS?, method?, rampS?,
/// vtol? })` → `{ impulses, duration, amplitudeSum, vtol, vibrationBefore, vibrationAfter,
/// insensitivityBefore, insensitivityAfter }`: the shaper rounded for an integer controller
/// (Peláez & Singhose 2002) and what rounding cost at the mode.
#[cfg(feature = "js-api")]
#[wasm_bindgen(unchecked_return_type = "QuantizeReport")]
pub fn quantize(
    #[wasm_bindgen(unchecked_param_type = "ShaperInput")] shaper: JsValue,
    #[wasm_bindgen(unchecked_param_type = "ModeSpec")] mode: JsValue,
    #[wasm_bindgen(unchecked_param_type = "QuantizeOptions")] options: JsValue,
) -> Result<JsValue, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let mode = mode_from_js(mode, "mode").map_err(js_error)?;
    let options: design::quantize::QuantizeOptions =
        from_js(options, "options").map_err(js_error)?;
    let report = design::quantize::quantize_with_report(&shaper, &mode, &options)
        .map_err(|e| js_error(e.within("options")))?;
    to_js(&report)
}

/// `realizeShaper(spec, { firmware, periodS?, amplitudeSteps?, maxImpulses?, vtol? })` →
/// `{ firmware, ideal, realised, runs, changes: [{ kind, text }], summary, modes:
/// [{ frequencyHz, damping, vibrationIdeal, vibrationRealised }], vtol, insensitivityIdeal,
/// insensitivityRealised, actsAsHz }`: the shaper `spec` designs as the controller runs it
/// (crate::realise). Errors in the options (and a firmware that cannot run the design) name
/// `options.<field>`; errors in the spec name its fields from the root. Also in the page's
/// lazily fetched module (`js-recording`), for its realisation view (web/realise.js).
#[cfg(any(feature = "js-api", feature = "js-recording"))]
#[wasm_bindgen(js_name = realizeShaper, unchecked_return_type = "Realization")]
pub fn realize_shaper(
    #[wasm_bindgen(unchecked_param_type = "DesignSpec")] spec: JsValue,
    #[wasm_bindgen(unchecked_param_type = "RealizeOptions")] options: JsValue,
) -> Result<JsValue, JsValue> {
    let request: DesignRequest = from_js_root(spec, "spec").map_err(js_error)?;
    let options: crate::realise::RealiseOptions = from_js(options, "options").map_err(js_error)?;
    let in_options = |e: Error| js_error(e.within("options"));
    crate::realise::check_options(&options).map_err(in_options)?;
    let modes = Mode::list(&request.modes).map_err(js_error)?;
    let ideal = design::design_for(&request.shaper, &modes).map_err(js_error)?;
    let result =
        crate::realise::realise_designed(&request, &modes, ideal, &options).map_err(in_options)?;
    to_js(&result)
}

/// `simulate(spec)`: `spec = { plant, command, shaper? | impulses?, duration?, samplePeriod? |
/// sampleRateHz? }` → `{ time, unshaped: { basePosition, baseVelocity, baseAcceleration,
/// endpoint, endpointVelocity, endpointAcceleration, deflection, swingAngle?, metrics },
/// shaped (same, or null), shaper, modesHz, samplePeriod }`. See the README for every field.
#[cfg(feature = "js-api")]
#[wasm_bindgen(unchecked_return_type = "SimulationResult")]
pub fn simulate(
    #[wasm_bindgen(unchecked_param_type = "SimulationSpec")] spec: JsValue,
) -> Result<JsValue, JsValue> {
    let spec: crate::scenario::SimulationSpec = from_js_root(spec, "spec").map_err(js_error)?;
    let result = crate::scenario::run(&spec).map_err(js_error)?;
    to_js(&result)
}

/// `spectrum(spec)`: `spec = { command, shaper? | impulses?, plant?, fromHz?, toHz?, points?,
/// signal? }` → `{ frequencyHz, magnitude, unshaped, modesHz }` (|U(f)| of the shaped and the
/// unshaped command's velocity by default).
#[cfg(feature = "js-api")]
#[wasm_bindgen(unchecked_return_type = "SpectrumResult")]
pub fn spectrum(
    #[wasm_bindgen(unchecked_param_type = "SpectrumSpec")] spec: JsValue,
) -> Result<JsValue, JsValue> {
    let spec: crate::scenario::SpectrumSpec = from_js_root(spec, "spec").map_err(js_error)?;
    let result = crate::scenario::spectrum_for(&spec).map_err(js_error)?;
    to_js(&result)
}

/// A profile's spectrum and its zeros (`profileSpectrum`).
#[cfg(any(feature = "js-api", feature = "js-recording"))]
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct ProfileSpectrum {
    frequency_hz: Vec<f64>,
    magnitude: Vec<f64>,
    zeros: Vec<crate::profile::SpectrumZero>,
}

/// `profileSpectrum(command, { fromHz?, toHz, points?, signal? })` → `{ frequencyHz, magnitude,
/// zeros: [{ frequencyHz, order, finalPulse }] }`: |U(f)| of a pulse-convolution profile
/// (`command = { kind: "profile", shape, … }`; as `spectrum` computes it, of the velocity by
/// default) and the frequencies in (0, toHz] where it is zero, in closed form
/// (crate::profile::spectrum_zeros: Veciana & Cardona 2011 eq. 13 for each pulse, their product
/// by eqs. 9–12); `order` counts the pulses vanishing there, `finalPulse` says the final pulse
/// is one of them. Errors name `command.<field>` (another kind: `command.kind`) or
/// `options.<field>`. Also in the page's lazily fetched module (`js-recording`), for its
/// profile view (web/command_view.js).
#[cfg(any(feature = "js-api", feature = "js-recording"))]
#[wasm_bindgen(js_name = profileSpectrum, unchecked_return_type = "ProfileSpectrum")]
pub fn profile_spectrum(
    #[wasm_bindgen(unchecked_param_type = "CommandSpec")] command: JsValue,
    #[wasm_bindgen(unchecked_param_type = "SpectrumOptions")] options: JsValue,
) -> Result<JsValue, JsValue> {
    let spec: crate::command::CommandSpec = from_js(command, "command").map_err(js_error)?;
    let crate::command::CommandSpec::Profile(profile) = spec else {
        return Err(js_error(Error::invalid(
            "command.kind",
            "the spectrum zeros are known in closed form for a profile command only (kind: \"profile\")",
        )));
    };
    let options: crate::spectrum::SpectrumOptions =
        from_js(options, "options").map_err(js_error)?;
    let position =
        crate::profile::from_spec(&profile).map_err(|e| js_error(e.within("command")))?;
    let u = crate::spectrum::piecewise_spectrum(&position, &options)
        .map_err(|e| js_error(e.within("options")))?;
    let zeros = crate::profile::spectrum_zeros(&profile, options.to_hz).map_err(|e| {
        js_error(match e {
            Error::TooLarge { value, limit, .. } => Error::TooLarge {
                field: "options.toHz".into(),
                value,
                limit,
            },
            e => e.within("command"),
        })
    })?;
    to_js(&ProfileSpectrum {
        frequency_hz: u.frequency_hz,
        magnitude: u.magnitude,
        zeros,
    })
}

/// `simulateCorner(spec)`: `spec = { path: { kind: "square", sideMm } | { kind:
/// "ringingTower", sideMm?, thicknessMm? }, velocity, accel, squareCornerVelocity?, x: { modes,
/// shaper? | impulses? }, y: (same), samplePeriodS?, settleS?, magnify? }` → `{ segments,
/// duration, samplePeriodS, unshaped: { time, nozzle: [x, y], deviation, corners: [{ time,
/// peakDeviation, ringing, windowS }], drawn }, shaped (same, or null), shaperX, shaperY }`:
/// the path planned with Klipper's junction rule and printed unshaped and with each axis's
/// shaper (crate::corner, crate::scenario::corner_for).
#[cfg(feature = "js-api")]
#[wasm_bindgen(js_name = simulateCorner, unchecked_return_type = "CornerResult")]
pub fn simulate_corner(
    #[wasm_bindgen(unchecked_param_type = "CornerSpec")] spec: JsValue,
) -> Result<JsValue, JsValue> {
    let spec: crate::scenario::CornerSpec = from_js_root(spec, "spec").map_err(js_error)?;
    let result = crate::scenario::corner_for(&spec).map_err(js_error)?;
    to_js(&result)
}
