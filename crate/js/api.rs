//! The JavaScript API: thin glue between the page and the core. Objects cross the boundary as
//! plain JSON-like values (camelCase) through serde-wasm-bindgen; every error is thrown as a JS
//! `Error` whose message starts with the offending field and whose `field` property holds it.
//!
//! Each export belongs to a Cargo feature (`js-api`, `js-playground`, `js-recording`; see
//! Cargo.toml). A build with only some of them leaves helpers unused, hence the allow there.
#![cfg_attr(not(feature = "js-api"), allow(dead_code, unused_imports))]

use super::canvas::Canvas;
use crate::chart::{self, ChartStyle};
use crate::command::{Command, CommandSpec};
use crate::design::{self, DesignRequest, ShaperSpec};
use crate::error::Error;
use crate::metrics::Metrics;
use crate::mode::{Mode, ModeSpec};
use crate::piecewise::{Knot, Piecewise, ORDER};
use crate::plant::{ModalPlant, Pendulum, PendulumSpec, Plant};
use crate::robustness::RobustnessRow;
use crate::shaper::{Shaper, ShaperData};
use crate::simulate::Trajectory;
use crate::spectrum::{SpectrumOptions, SpectrumSignal};
use crate::vibration::{self, SensitivityOptions};
use plotters::prelude::*;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::cell::RefCell;
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
pub(crate) fn from_js<T: DeserializeOwned>(value: JsValue, what: &str) -> Result<T, Error> {
    if value.is_undefined() || value.is_null() {
        return Err(Error::Parse {
            field: what.to_string(),
            reason: "is missing".into(),
        });
    }
    super::jsde::deserialize(value).map_err(|(path, e)| {
        let field = match path.as_str() {
            "." | "" | "?" => what.to_string(),
            p if what.is_empty() => p.to_string(),
            p => format!("{what}.{p}"),
        };
        Error::Parse {
            field,
            reason: e.to_string(),
        }
    })
}

/// Writes `value` to a plain JS object (maps as objects, not `Map`).
pub(crate) fn to_js<T: Serialize>(value: &T) -> Result<JsValue, JsValue> {
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
#[cfg(any(feature = "js-api", feature = "js-designer"))]
#[wasm_bindgen]
pub fn design(spec: JsValue) -> Result<JsValue, JsValue> {
    let request: DesignRequest = from_js(spec, "").map_err(js_error)?;
    #[cfg(feature = "js-api")]
    let shaper = design::design(&request).map_err(js_error)?;
    // The page's design worker's module: the solved families alone (README, *Playground*).
    #[cfg(not(feature = "js-api"))]
    let shaper = Mode::list(&request.modes)
        .and_then(|modes| design::design_solved_for(&request.shaper, &modes))
        .map_err(js_error)?;
    to_js(&shaper.to_data())
}

/// `residualVibration(shaper, { frequencyHz, damping })` → V as a fraction (1 = unshaped).
#[cfg(feature = "js-api")]
#[wasm_bindgen(js_name = residualVibration)]
pub fn residual_vibration(shaper: JsValue, mode: JsValue) -> Result<f64, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let mode = mode_from_js(mode, "mode").map_err(js_error)?;
    Ok(vibration::residual_vibration(&shaper, &mode))
}

/// `sensitivity(shaper, { fromHz, toHz, points, damping })` →
/// `{ frequencyHz: number[], vibration: number[] }`.
#[cfg(feature = "js-api")]
#[wasm_bindgen]
pub fn sensitivity(shaper: JsValue, options: JsValue) -> Result<JsValue, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let options: SensitivityOptions = from_js(options, "options").map_err(js_error)?;
    let curve = vibration::sensitivity(&shaper, &options).map_err(js_error)?;
    to_js(&curve)
}

/// `insensitivity(shaper, { frequencyHz, damping }, vtol)` → `{ lowHz, highHz, width }`, the
/// band around the mode where V ≤ vtol, width as a fraction of `frequencyHz`.
#[cfg(feature = "js-api")]
#[wasm_bindgen]
pub fn insensitivity(shaper: JsValue, mode: JsValue, vtol: f64) -> Result<JsValue, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let mode = mode_from_js(mode, "mode").map_err(js_error)?;
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
#[cfg(feature = "js-api")]
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
#[cfg(feature = "js-api")]
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
#[cfg(feature = "js-api")]
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
#[cfg(feature = "js-playground")]
#[wasm_bindgen]
pub fn families() -> Result<JsValue, JsValue> {
    to_js(&design::FAMILIES)
}

/// Most shapers the playground compares at once.
const MAX_COMPARED: usize = 4;

/// What the page shows, in one object (see [`render_playground`]).
#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct PlaygroundState {
    modes: Vec<ModeSpec>,
    /// The shapers to compare (1 … 4).
    #[serde(default)]
    shapers: Vec<ShaperSpec>,
    /// Shorthand for a single shaper (used when `shapers` is empty).
    #[serde(default)]
    shaper: Option<ShaperSpec>,
    #[serde(default)]
    view: PlaygroundView,
    /// Shapers designed elsewhere, by index into the compared shapers (`null` or missing: design
    /// it here). The page designs the solved families in a worker and hands their impulses
    /// (as `design` returns them) back with the state, so the module on the main thread needs
    /// no solver and never waits for one. Each is checked as `exportShaper` checks a shaper
    /// and used for the spec at its index, which still gives the label and the family.
    #[serde(default)]
    designed: Vec<Option<ShaperData>>,
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
    /// Square corner velocity for Klipper's figures, mm/s.
    scv: f64,
    /// Device pixel ratio the canvases were sized with.
    pixel_ratio: f64,
    /// Model mismatch of the simulation: actual frequency = model × `mismatch`.
    mismatch: f64,
    /// The reference command of the simulation (as `simulate` takes it).
    command: CommandSpec,
    /// The simulated plant, built from the (mismatched) modes.
    plant: ViewPlant,
    /// Samples of each simulated response.
    samples: usize,
    /// Simulated seconds (default: the longest shaped move + 3 periods of the slowest mode).
    duration: Option<f64>,
    /// Which compared shaper the frequency × damping map shows (index into `shapers`).
    map_shaper: usize,
    /// The colour of each compared shaper, as a position in the palette (0 … 3); default
    /// 0, 1, 2, 3. The page leaves a shaper that cannot be designed out and keeps the others'.
    series_colors: Option<Vec<usize>>,
    /// Resolution of the map.
    map_frequency_points: usize,
    map_damping_points: usize,
    /// Upper damping ratio of V(ζ) and the map (default max(0.2, 3 × the highest mode's ζ),
    /// at most 0.9).
    damping_to: Option<f64>,
    /// Points of V(ζ).
    damping_points: usize,
    /// Frequencies of the command spectrum (over the V(f) range).
    spectrum_points: usize,
}

impl Default for PlaygroundView {
    fn default() -> Self {
        PlaygroundView {
            from_hz: None,
            to_hz: None,
            points: 600,
            vtol: 0.05,
            scv: crate::smoothing::KLIPPER_SCV,
            pixel_ratio: 1.0,
            mismatch: 1.0,
            command: CommandSpec::Step {
                distance: 1.0,
                start: 0.0,
            },
            plant: ViewPlant::Modal,
            samples: 1000,
            duration: None,
            map_shaper: 0,
            series_colors: None,
            map_frequency_points: 120,
            map_damping_points: 40,
            damping_to: None,
            damping_points: 200,
            spectrum_points: 300,
        }
    }
}

crate::tagged::tagged_enum! {
    tag = "kind", rename_all = "camelCase", mirror = view_plant_serde;
    /// The playground's simulated plant: `modal` (the modes × mismatch, equal participation) or
    /// `pendulum` (a nonlinear crane pendulum whose linearised mode is the first mode × mismatch).
    #[derive(Clone, Copy)]
    enum ViewPlant {
        Modal,
        #[serde(rename_all = "camelCase")]
        Pendulum {
            /// Gravity, m/s² (default 9.81).
            #[serde(default = "default_gravity")]
            gravity: f64,
            /// Swing angle at t = 0, rad (default 0).
            #[serde(default)]
            initial_angle: f64,
        },
    }
}

// Not derived: the variants' attributes (a `#[default]` too) are copied to the serde copies
// of the enum, which derive no `Default`.
#[allow(clippy::derivable_impls)]
impl Default for ViewPlant {
    fn default() -> Self {
        ViewPlant::Modal
    }
}

fn default_gravity() -> f64 {
    9.81
}

/// Everything the page shows about one shaper.
#[derive(Serialize, Clone)]
#[serde(rename_all = "camelCase")]
struct ShaperResult {
    label: String,
    family: &'static str,
    shaper: ShaperData,
    sensitivity: vibration::SensitivityCurve,
    insensitivity: Vec<vibration::Insensitivity>,
    residual_at_modes: Vec<f64>,
    centroid_delay: Option<f64>,
    /// `None` (JS `null`) for shapers whose amplitudes sum to zero (bang-bang, on/off):
    /// Klipper's smoothing divides by that sum.
    klipper: Option<crate::smoothing::KlipperFigures>,
    /// Metrics of the shaped move on the simulated (mismatched) plant.
    simulation: Option<Metrics>,
}

/// The simulation of a frame, without its samples (those are drawn, not returned).
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct SimulationSummary {
    mismatch: f64,
    plant: &'static str,
    plant_modes_hz: Vec<f64>,
    duration: f64,
    sample_period: f64,
    samples: usize,
    unshaped: Metrics,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct PlaygroundResult {
    /// One entry per compared shaper, in order.
    results: Vec<ShaperResult>,
    // The first shaper's figures, as the single-shaper page had them.
    shaper: ShaperData,
    sensitivity: vibration::SensitivityCurve,
    insensitivity: Vec<vibration::Insensitivity>,
    residual_at_modes: Vec<f64>,
    centroid_delay: Option<f64>,
    /// The simulated move: plant, window and the unshaped command's metrics.
    simulation: SimulationSummary,
    /// Singhose 2009 Fig. 11 for mode 1: every parameterless family designed for it.
    robustness: Vec<RobustnessRow>,
    /// Index of the shaper the map shows.
    map_shaper: usize,
    /// Upper damping ratio of V(ζ) and the map.
    damping_to: f64,
}

fn canvas(canvases: &JsValue, key: &str) -> Option<HtmlCanvasElement> {
    js_sys::Reflect::get(canvases, &key.into())
        .ok()
        .and_then(|c| c.dyn_into::<HtmlCanvasElement>().ok())
}

/// Labels for the compared shapers: the family's title, with the count written in for the
/// families named by one (`ZV-D³`, `4-hump EI`), numbered when still repeated.
fn labels(specs: &[ShaperSpec]) -> Vec<String> {
    let titles: Vec<String> = specs.iter().map(title).collect();
    titles
        .iter()
        .enumerate()
        .map(|(i, t)| {
            if titles.iter().filter(|u| *u == t).count() > 1 {
                format!("{t} #{}", i + 1)
            } else {
                t.clone()
            }
        })
        .collect()
}

/// A spec's family title (from [`FAMILIES`](crate::design::FAMILIES)), with the derivative or
/// hump count written in where the title leaves it as n (`ZV-Dⁿ`, `n-hump EI`).
fn title(spec: &ShaperSpec) -> String {
    let title = spec.info().map_or("shaper", |f| f.title);
    match spec {
        ShaperSpec::Zvdn { derivatives } => match title.strip_suffix('ⁿ') {
            Some(stem) => format!("{stem}{}", superscript(*derivatives)),
            None => title.to_string(),
        },
        ShaperSpec::Eihump { humps, .. } => match title.strip_prefix("n-") {
            Some(rest) => format!("{humps}-{rest}"),
            None => title.to_string(),
        },
        _ => title.to_string(),
    }
}

/// `n` in superscript digits (³, ¹²).
fn superscript(n: u32) -> String {
    const DIGITS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    n.to_string()
        .bytes()
        .map(|b| DIGITS[usize::from(b - b'0')])
        .collect()
}

/// Checks that `value` lies in `[lo, hi]` (and is finite), naming `field`.
fn within_range(field: &str, value: f64, lo: f64, hi: f64) -> Result<f64, Error> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(Error::invalid(
            field,
            format!("must be a number from {lo} to {hi}, got {value}"),
        ))
    }
}

/// Checks a count in `[lo, hi]`, naming `field`.
fn count_in(field: &str, value: usize, lo: usize, hi: usize) -> Result<usize, Error> {
    if (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(Error::invalid(
            field,
            format!("must be a whole number from {lo} to {hi}, got {value}"),
        ))
    }
}

/// The simulated plant of a frame: the modes with frequencies × `mismatch`.
fn view_plant(modes: &[Mode], view: &PlaygroundView) -> Result<Plant, Error> {
    let r = within_range("view.mismatch", view.mismatch, 0.05, 20.0)?;
    let at_mismatch = |e: Error| Error::invalid("view.mismatch", e.to_string());
    match view.plant {
        ViewPlant::Modal => {
            let actual = modes
                .iter()
                .map(|m| Mode::new(m.frequency_hz() * r, m.damping()).map_err(at_mismatch))
                .collect::<Result<Vec<_>, _>>()?;
            let share = 1.0 / actual.len() as f64;
            let participation = vec![share; actual.len()];
            Ok(Plant::Modal(
                ModalPlant::new(actual, participation).map_err(|e| e.within("view.plant"))?,
            ))
        }
        ViewPlant::Pendulum {
            gravity,
            initial_angle,
        } => {
            let mode = &modes[0];
            let omega = mode.omega_rad_s() * r;
            let spec = PendulumSpec {
                length: gravity / (omega * omega),
                gravity,
                damping: mode.damping(),
                initial_angle,
                hoist: None,
            };
            Ok(Plant::Pendulum(
                Pendulum::from_spec(&spec).map_err(|e| e.within("view.plant"))?,
            ))
        }
    }
}

/// The command a shaper sends: the reference shaped by it, or — for the force-profile families
/// (bang-bang, on/off), whose amplitudes sum to 0 — their own rest-to-rest move, with
/// acceleration `maxAcceleration` × (shaper ∗ unit step).
fn shaped_command(spec: &ShaperSpec, shaper: &Shaper, command: &Command) -> Result<Command, Error> {
    let force = match spec {
        ShaperSpec::Bangbang {
            max_acceleration, ..
        }
        | ShaperSpec::Onoff {
            max_acceleration, ..
        } => Some(*max_acceleration),
        _ => None,
    };
    match force {
        Some(a) => {
            let knots = shaper
                .impulses()
                .iter()
                .map(|imp| {
                    let mut jumps = [0.0; ORDER];
                    jumps[2] = a * imp.amplitude;
                    Knot {
                        time: imp.time,
                        jumps,
                    }
                })
                .collect();
            Ok(Command::Piecewise(Piecewise::new(knots)?))
        }
        None => command.shaped(shaper).map_err(|e| e.within("view.command")),
    }
}

/// Metrics of a simulated move. The per-mode residuals (`modeResidualPercent`) are left out:
/// the page does not show them and they cost a second simulation per move.
fn move_metrics(
    traj: &Trajectory,
    applied: &Command,
    reference: &Command,
) -> Result<Metrics, Error> {
    crate::metrics::metrics(traj, applied, reference)
}

thread_local! {
    /// The last robustness table and its key (mode 1's frequency and damping, Vtol, as bits):
    /// designing every family is the slowest part of a frame and only these inputs change it.
    static ROBUSTNESS: RefCell<Option<([u64; 2], Vec<RobustnessRow>)>> = const { RefCell::new(None) };
}

fn robustness_rows(mode: &Mode, vtol: f64) -> Result<Vec<RobustnessRow>, Error> {
    // Every parameterless family designs a shaper whose impulse times scale with the mode's
    // period (at a fixed damping ratio), so the table's durations in periods and its
    // insensitivities (fractions of the frequency, and damping widths) depend on ζ and Vtol
    // only. The table is designed once per (ζ, Vtol) for a 1 Hz mode and the seconds are
    // rescaled, so editing a frequency does not redesign a dozen shapers every frame.
    let key = [mode.damping().to_bits(), vtol.to_bits()];
    let cached = ROBUSTNESS.with_borrow(|c| {
        c.as_ref()
            .filter(|(k, _)| *k == key)
            .map(|(_, r)| r.clone())
    });
    let rows = match cached {
        Some(rows) => rows,
        None => {
            let unit = Mode::new(1.0, mode.damping())?;
            // Families that cannot be designed for this mode (e.g. EI beyond its damping
            // range) are left out of the background rather than failing the frame. So is
            // `direct`: for one mode it is the ZVD shaper itself (tests/direct.rs,
            // one_mode_reproduces_zv_and_zvd_closed_forms), a second point on ZVD's, and its
            // design needs the solver, which the page's first module leaves out.
            let rows: Vec<RobustnessRow> = crate::robustness::parameterless_specs()
                .into_iter()
                .filter(|spec| !matches!(spec, ShaperSpec::Direct(_)))
                .filter_map(|spec| {
                    crate::robustness::robustness_table(std::slice::from_ref(&spec), &unit, vtol)
                        .ok()
                })
                .flatten()
                .collect();
            ROBUSTNESS.with_borrow_mut(|c| *c = Some((key, rows.clone())));
            rows
        }
    };
    let period = mode.damped_period_s();
    Ok(rows
        .into_iter()
        .map(|r| RobustnessRow {
            duration_s: r.duration_periods * period,
            ..r
        })
        .collect())
}

/// The part of a frame that depends on the designs and the analysis settings only, not on the
/// simulated plant, the mismatch or the command: what [`ANALYSIS`] keeps between frames.
#[derive(Clone)]
struct Analysis {
    shapers: Vec<Shaper>,
    /// Per shaper, everything but the simulation's metrics (`simulation` is `None`).
    results: Vec<ShaperResult>,
    /// V(ζ) of every shaper at mode 1, if the damping chart is drawn.
    damping_curves: Option<Vec<vibration::DampingSensitivityCurve>>,
    /// The map of the chosen shaper, if the map is drawn.
    map: Option<vibration::SensitivityMap>,
    /// |S(f)| of every shaper on the spectrum's grid, if the spectrum is drawn (`None` for the
    /// families that make their own move, whose spectrum is the move's).
    impulse_spectra: Option<Vec<Option<Vec<f64>>>>,
}

/// Everything [`Analysis`] is computed from.
#[derive(Clone, PartialEq)]
struct AnalysisKey {
    specs: Vec<ShaperSpec>,
    /// The impulses of the shapers designed elsewhere (`PlaygroundState::designed`).
    designed: Vec<Option<Vec<crate::shaper::Impulse>>>,
    modes: Vec<ModeSpec>,
    /// vtol, scv, the V(f) range and points, the damping range and points, the map's shaper
    /// and resolution, the spectrum's points (floats as bits).
    numbers: [u64; 11],
    /// Which of the damping, map and spectrum charts are drawn.
    charts: [bool; 3],
}

thread_local! {
    /// The last frame's [`Analysis`] and its key. Dragging the mismatch, or editing the
    /// command or the plant, changes only the simulation: the designs, I(Vtol), V(f), V(ζ),
    /// the map and |S(f)| are taken from here instead of being recomputed every frame.
    static ANALYSIS: RefCell<Option<(AnalysisKey, Analysis)>> = const { RefCell::new(None) };
}

/// The designs and their analyses for a frame, from [`ANALYSIS`] when nothing they depend on
/// changed. Errors carry the same fields as when computed directly (they are never cached).
#[allow(clippy::too_many_arguments)]
fn analysis(
    specs: &[ShaperSpec],
    designed: &[Option<Shaper>],
    labels: &[String],
    mode_specs: &[ModeSpec],
    modes: &[Mode],
    view: &PlaygroundView,
    options: &SensitivityOptions,
    damping_to: f64,
    spectrum_options: &SpectrumOptions,
    charts: [bool; 3],
) -> Result<Analysis, JsValue> {
    let key = AnalysisKey {
        specs: specs.to_vec(),
        designed: designed
            .iter()
            .map(|d| d.as_ref().map(|s| s.impulses().to_vec()))
            .collect(),
        modes: mode_specs.to_vec(),
        numbers: [
            view.vtol.to_bits(),
            view.scv.to_bits(),
            options.from_hz.to_bits(),
            options.to_hz.to_bits(),
            options.points as u64,
            damping_to.to_bits(),
            view.damping_points as u64,
            view.map_shaper as u64,
            view.map_frequency_points as u64,
            view.map_damping_points as u64,
            spectrum_options.points as u64,
        ],
        charts,
    };
    let cached = ANALYSIS.with_borrow(|c| {
        c.as_ref()
            .filter(|(k, _)| *k == key)
            .map(|(_, a)| a.clone())
    });
    if let Some(a) = cached {
        return Ok(a);
    }
    let in_view = |e: Error| js_error(e.within("view"));
    let mut results = Vec::with_capacity(specs.len());
    let mut shapers = Vec::with_capacity(specs.len());
    for (k, spec) in specs.iter().enumerate() {
        let at = |e: Error| js_error(e.within(&format!("shapers[{k}]")));
        let shaper = match designed.get(k) {
            Some(Some(shaper)) => shaper.clone(),
            _ => design::design_for(spec, modes).map_err(at)?,
        };
        let curve = vibration::sensitivity(&shaper, options).map_err(in_view)?;
        let insensitivity = modes
            .iter()
            .map(|m| vibration::insensitivity(&shaper, m, view.vtol))
            .collect::<Result<Vec<_>, _>>()
            .map_err(in_view)?;
        let klipper = match shaper.centroid_delay() {
            Some(_) => Some(crate::smoothing::klipper_figures(&shaper, view.scv).map_err(in_view)?),
            None => None,
        };
        results.push(ShaperResult {
            label: labels[k].clone(),
            family: spec.name(),
            shaper: shaper.to_data(),
            sensitivity: curve,
            insensitivity,
            residual_at_modes: modes
                .iter()
                .map(|m| vibration::residual_vibration(&shaper, m))
                .collect(),
            centroid_delay: shaper.centroid_delay(),
            klipper,
            simulation: None,
        });
        shapers.push(shaper);
    }
    let [damping_chart, map_chart, spectrum_chart] = charts;
    let damping_curves = match damping_chart {
        true => Some(
            shapers
                .iter()
                .map(|s| {
                    vibration::damping_sensitivity(
                        s,
                        &vibration::DampingSensitivityOptions {
                            frequency_hz: modes[0].frequency_hz(),
                            from_damping: 0.0,
                            to_damping: damping_to,
                            points: view.damping_points,
                        },
                    )
                })
                .collect::<Result<Vec<_>, _>>()
                .map_err(in_view)?,
        ),
        false => None,
    };
    let map = match map_chart {
        true => Some(
            vibration::sensitivity_map(
                &shapers[view.map_shaper],
                &vibration::SensitivityMapOptions {
                    from_hz: options.from_hz,
                    to_hz: options.to_hz,
                    frequency_points: view.map_frequency_points,
                    damping_from: 0.0,
                    damping_to,
                    damping_points: view.map_damping_points,
                },
            )
            .map_err(in_view)?,
        ),
        false => None,
    };
    let impulse_spectra = match spectrum_chart {
        true => Some(
            specs
                .iter()
                .zip(&shapers)
                .map(|(spec, shaper)| {
                    let own_move =
                        matches!(spec, ShaperSpec::Bangbang { .. } | ShaperSpec::Onoff { .. });
                    if own_move {
                        return Ok(None);
                    }
                    crate::spectrum::impulse_spectrum(shaper, spectrum_options)
                        .map(|s| Some(s.magnitude))
                })
                .collect::<Result<Vec<_>, _>>()
                .map_err(in_view)?,
        ),
        false => None,
    };
    let a = Analysis {
        shapers,
        results,
        damping_curves,
        map,
        impulse_spectra,
    };
    ANALYSIS.with_borrow_mut(|c| *c = Some((key, a.clone())));
    Ok(a)
}

#[cfg(feature = "js-playground")]
/// The charts' colours for `view.seriesColors` (one palette position per compared shaper, each
/// used once), or the palette in order.
fn series_colors(
    slots: Option<&[usize]>,
    shapers: usize,
) -> Result<[plotters::style::RGBColor; 4], Error> {
    let palette = chart::SERIES_COLORS;
    let Some(slots) = slots else {
        return Ok(palette);
    };
    let field = "view.seriesColors";
    if slots.len() != shapers {
        return Err(Error::invalid(
            field,
            format!(
                "give one colour per compared shaper: {shapers}, got {}",
                slots.len()
            ),
        ));
    }
    let mut colors = palette;
    for (k, &slot) in slots.iter().enumerate() {
        if slot >= palette.len() {
            return Err(Error::invalid(
                format!("{field}[{k}]"),
                format!(
                    "must be a palette position, 0 … {}, got {slot}",
                    palette.len() - 1
                ),
            ));
        }
        if slots[..k].contains(&slot) {
            return Err(Error::invalid(
                format!("{field}[{k}]"),
                format!("colour {slot} is already another shaper's"),
            ));
        }
        colors[k] = palette[slot];
    }
    Ok(colors)
}

/// `renderPlayground(state, canvases)`: everything one frame of the page needs, in one call.
///
/// `state = { modes, shapers: [{ family, …parameters }] (1 … 4; or `shaper` for one),
/// designed?: [shaper | null] (shapers designed elsewhere, by index),
/// view: { fromHz, toHz, points, vtol, scv, pixelRatio, mismatch, command, plant, samples,
/// duration, mapShaper, seriesColors, mapFrequencyPoints, mapDampingPoints, dampingTo, dampingPoints,
/// spectrumPoints } }` (README, "JavaScript API"); `canvases = { impulses?, sensitivity?,
/// damping?, map?, response?, command?, spectrum?, robustness? }` (HTMLCanvasElements).
/// Designs every shaper, computes its sensitivity curve (at the first mode's damping),
/// insensitivity and residual vibration at each mode and Klipper's smoothing figures, simulates
/// the unshaped and every shaped move on the plant with the mismatched modes, and draws the
/// charts overlaid. Returns `{ results: [{ label, family, shaper, sensitivity, insensitivity,
/// residualAtModes, centroidDelay, klipper: { smoothing, maxAccel }, simulation }],
/// simulation: { mismatch, plant, plantModesHz, duration, samplePeriod, samples, unshaped },
/// robustness, mapShaper, dampingTo, …the first result's fields }`. Errors name the field
/// (`shapers[1].vtol`, `modes[0].damping`, `view.vtol`, `view.mismatch`,
/// `view.command.maxVelocity`). Nothing is drawn unless everything computed, so a bad input
/// leaves the last good charts on screen.
#[cfg(feature = "js-playground")]
#[wasm_bindgen(js_name = renderPlayground)]
pub fn render_playground(state: JsValue, canvases: JsValue) -> Result<JsValue, JsValue> {
    let state: PlaygroundState = from_js(state, "").map_err(js_error)?;
    let modes = Mode::list(&state.modes).map_err(js_error)?;
    let mut specs = state.shapers;
    if specs.is_empty() {
        specs.extend(state.shaper);
    }
    if specs.is_empty() {
        return Err(js_error(Error::invalid(
            "shapers",
            "at least one shaper is required",
        )));
    }
    if specs.len() > MAX_COMPARED {
        return Err(js_error(Error::TooLarge {
            field: "shapers".into(),
            value: specs.len() as f64,
            limit: MAX_COMPARED as f64,
        }));
    }
    if state.designed.len() > specs.len() {
        return Err(js_error(Error::invalid(
            "designed",
            format!(
                "has {} entries for {} compared shapers",
                state.designed.len(),
                specs.len()
            ),
        )));
    }
    let designed = state
        .designed
        .iter()
        .enumerate()
        .map(|(k, d)| {
            d.as_ref()
                .map(|d| Shaper::from_data(d).map_err(|e| e.within(&format!("designed[{k}]"))))
                .transpose()
        })
        .collect::<Result<Vec<Option<Shaper>>, Error>>()
        .map_err(js_error)?;
    let view = &state.view;
    let f_max = modes.iter().map(Mode::frequency_hz).fold(0.0_f64, f64::max);
    let options = SensitivityOptions {
        from_hz: view.from_hz.unwrap_or(0.0),
        to_hz: view.to_hz.unwrap_or(2.0 * f_max),
        points: view.points,
        damping: modes[0].damping(),
    };
    // The view's analysis settings.
    let z_max = modes.iter().map(Mode::damping).fold(0.0_f64, f64::max);
    let damping_to = match view.damping_to {
        Some(z) => within_range("view.dampingTo", z, 1e-3, 0.99).map_err(js_error)?,
        None => (3.0 * z_max).clamp(0.2, 0.9),
    };
    if view.map_shaper >= specs.len() {
        return Err(js_error(Error::invalid(
            "view.mapShaper",
            format!(
                "must be one of the compared shapers, 0 … {}, got {}",
                specs.len() - 1,
                view.map_shaper
            ),
        )));
    }
    let colors = series_colors(view.series_colors.as_deref(), specs.len()).map_err(js_error)?;
    count_in(
        "view.mapFrequencyPoints",
        view.map_frequency_points,
        2,
        1000,
    )
    .map_err(js_error)?;
    count_in("view.mapDampingPoints", view.map_damping_points, 2, 500).map_err(js_error)?;
    count_in("view.dampingPoints", view.damping_points, 2, 5000).map_err(js_error)?;
    count_in("view.spectrumPoints", view.spectrum_points, 2, 5000).map_err(js_error)?;
    let samples = count_in("view.samples", view.samples, 50, 20_000).map_err(js_error)?;
    let spectrum_options = SpectrumOptions {
        from_hz: options.from_hz,
        to_hz: options.to_hz,
        points: view.spectrum_points,
        signal: SpectrumSignal::Velocity,
    };
    let labels = labels(&specs);
    let charts = [
        canvas(&canvases, "damping").is_some(),
        canvas(&canvases, "map").is_some(),
        canvas(&canvases, "spectrum").is_some(),
    ];
    let Analysis {
        shapers,
        mut results,
        damping_curves,
        map,
        impulse_spectra,
    } = analysis(
        &specs,
        &designed,
        &labels,
        &state.modes,
        &modes,
        view,
        &options,
        damping_to,
        &spectrum_options,
        charts,
    )?;

    // The simulated move on the mismatched plant.
    let plant = view_plant(&modes, view).map_err(js_error)?;
    let command =
        Command::from_spec(&view.command).map_err(|e| js_error(e.within("view.command")))?;
    let commands = specs
        .iter()
        .zip(&shapers)
        .map(|(spec, shaper)| shaped_command(spec, shaper, &command))
        .collect::<Result<Vec<_>, _>>()
        .map_err(js_error)?;
    let plant_modes = plant.modes().map_err(js_error)?;
    let slowest = plant_modes
        .iter()
        .map(Mode::damped_period_s)
        .fold(0.0_f64, f64::max);
    let end = commands
        .iter()
        .map(Command::end_time)
        .fold(command.end_time(), f64::max);
    let duration = match view.duration {
        Some(d) => within_range("view.duration", d, 1e-6, 1e6).map_err(js_error)?,
        None => (end + 3.0 * slowest).max(1e-3),
    };
    let sample_period = duration / (samples - 1) as f64;
    let sim = |c: &Command| {
        crate::simulate::simulate(&plant, c, sample_period, duration)
            .map_err(|e| js_error(e.within("view")))
    };
    let unshaped = sim(&command)?;
    let unshaped_metrics =
        move_metrics(&unshaped, &command, &command).map_err(|e| js_error(e.within("view")))?;
    let mut trajectories = Vec::with_capacity(commands.len());
    for (k, c) in commands.iter().enumerate() {
        let t = sim(c)?;
        let force = c != &command && shapers[k].centroid_delay().is_none();
        let reference = if force { c } else { &command };
        results[k].simulation =
            Some(move_metrics(&t, c, reference).map_err(|e| js_error(e.within("view")))?);
        trajectories.push(t);
    }
    let robustness =
        robustness_rows(&modes[0], view.vtol).map_err(|e| js_error(e.within("view")))?;

    let style = ChartStyle {
        scale: if view.pixel_ratio.is_finite() && view.pixel_ratio > 0.0 {
            view.pixel_ratio
        } else {
            1.0
        },
        colors,
    };
    let backend = |key: &str| canvas(&canvases, key).and_then(Canvas::new);
    let spectra = match &impulse_spectra {
        Some(impulse_spectra) => {
            let one = |c: &Command| {
                crate::spectrum::command_spectrum(c, &spectrum_options)
                    .map_err(|e| js_error(e.within("view")))
            };
            let unshaped = one(&command)?;
            // A piecewise command shaped by a shaper is their convolution, so its transform is
            // the product: |U_s(f)| = |S(f)|·|U(f)| exactly, at O(impulses) per frequency
            // instead of O(knots). Force-profile moves and sampled commands (shaped by the
            // streaming filter) are transformed directly.
            let shaped = impulse_spectra
                .iter()
                .zip(&commands)
                .map(|(s, c)| match s {
                    Some(s) if matches!(command, Command::Piecewise(_)) => Ok(s
                        .iter()
                        .zip(&unshaped.magnitude)
                        .map(|(a, b)| a * b)
                        .collect()),
                    _ => one(c).map(|s| s.magnitude),
                })
                .collect::<Result<Vec<Vec<f64>>, JsValue>>()?;
            Some((unshaped, shaped))
        }
        None => None,
    };

    let modes_hz: Vec<f64> = modes.iter().map(Mode::frequency_hz).collect();
    let actual_hz: Vec<f64> = plant_modes.iter().map(Mode::frequency_hz).collect();
    let named = |i: usize| labels[i].as_str();
    if let Some(b) = backend("impulses") {
        let series: Vec<(&str, &Shaper)> = (0..shapers.len())
            .map(|i| (named(i), &shapers[i]))
            .collect();
        chart::draw_impulses(&b.into_drawing_area(), &series, &style).map_err(js_error)?;
    }
    if let Some(b) = backend("sensitivity") {
        let series: Vec<(&str, &vibration::SensitivityCurve)> = results
            .iter()
            .map(|r| (r.label.as_str(), &r.sensitivity))
            .collect();
        chart::draw_sensitivity(
            &b.into_drawing_area(),
            &series,
            Some(view.vtol),
            &modes_hz,
            &style,
        )
        .map_err(js_error)?;
    }
    if let (Some(b), Some(curves)) = (backend("damping"), &damping_curves) {
        let series: Vec<(&str, &vibration::DampingSensitivityCurve)> = curves
            .iter()
            .enumerate()
            .map(|(i, c)| (named(i), c))
            .collect();
        let zetas: Vec<f64> = modes.iter().map(Mode::damping).collect();
        chart::draw_damping_sensitivity(
            &b.into_drawing_area(),
            &series,
            Some(view.vtol),
            &zetas,
            &style,
        )
        .map_err(js_error)?;
    }
    if let (Some(b), Some(map)) = (backend("map"), &map) {
        let marks: Vec<(f64, f64)> = modes
            .iter()
            .map(|m| (m.frequency_hz(), m.damping()))
            .collect();
        chart::draw_sensitivity_map_with(
            &b.into_drawing_area(),
            map,
            Some(view.vtol),
            &marks,
            &style,
            chart::MapCells::Bitmap,
        )
        .map_err(js_error)?;
    }
    let traj_series: Vec<(&str, &Trajectory)> = trajectories
        .iter()
        .enumerate()
        .map(|(i, t)| (named(i), t))
        .collect();
    if let Some(b) = backend("response") {
        let plant_name = match view.plant {
            ViewPlant::Modal => "",
            ViewPlant::Pendulum { .. } => ", nonlinear pendulum",
        };
        let caption = format!(
            "Simulated response (actual f = model × {}{plant_name})",
            (view.mismatch * 1e4).round() / 1e4
        );
        chart::draw_response(
            &b.into_drawing_area(),
            &unshaped,
            &traj_series,
            &caption,
            &style,
        )
        .map_err(js_error)?;
    }
    if let Some(b) = backend("command") {
        chart::draw_command(&b.into_drawing_area(), &unshaped, &traj_series, &style)
            .map_err(js_error)?;
    }
    if let (Some(b), Some((u, shaped))) = (backend("spectrum"), &spectra) {
        let series: Vec<(&str, &[f64])> = shaped
            .iter()
            .enumerate()
            .map(|(i, s)| (named(i), s.as_slice()))
            .collect();
        chart::draw_spectrum(
            &b.into_drawing_area(),
            &u.frequency_hz,
            &u.magnitude,
            &series,
            &modes_hz,
            &actual_hz,
            &style,
        )
        .map_err(js_error)?;
    }
    if let Some(b) = backend("robustness") {
        let period = modes[0].damped_period_s();
        let marks: Vec<chart::RobustnessMark<'_>> = results
            .iter()
            .map(|r| chart::RobustnessMark {
                label: r.label.as_str(),
                duration_periods: r.shaper.duration / period,
                insensitivity: r.insensitivity[0].width,
            })
            .collect();
        chart::draw_robustness(
            &b.into_drawing_area(),
            &robustness,
            &marks,
            view.vtol,
            &style,
        )
        .map_err(js_error)?;
    }
    let first = &results[0];
    let result = PlaygroundResult {
        shaper: first.shaper.clone(),
        sensitivity: first.sensitivity.clone(),
        insensitivity: first.insensitivity.clone(),
        residual_at_modes: first.residual_at_modes.clone(),
        centroid_delay: first.centroid_delay,
        simulation: SimulationSummary {
            mismatch: view.mismatch,
            plant: match view.plant {
                ViewPlant::Modal => "modal",
                ViewPlant::Pendulum { .. } => "pendulum",
            },
            plant_modes_hz: actual_hz,
            duration,
            sample_period,
            samples,
            unshaped: unshaped_metrics,
        },
        robustness,
        map_shaper: view.map_shaper,
        damping_to,
        results,
    };
    to_js(&result)
}

/// Options of [`export_shaper`].
#[derive(Deserialize)]
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
pub fn export_shaper(shaper: JsValue, options: JsValue) -> Result<String, JsValue> {
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
#[wasm_bindgen(js_name = klipperFigures)]
pub fn klipper_figures(shaper: JsValue, options: JsValue) -> Result<JsValue, JsValue> {
    #[derive(Deserialize)]
    struct Options {
        #[serde(default = "default_scv")]
        scv: f64,
    }
    fn default_scv() -> f64 {
        crate::smoothing::KLIPPER_SCV
    }
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let options: Options = if options.is_undefined() {
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
pub fn ramp_delay(shaper: JsValue, mode: JsValue) -> Result<f64, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let mode = mode_from_js(mode, "mode").map_err(js_error)?;
    design::sampled::ramp_delay(&shaper, &mode).map_err(|e| js_error(e.within("shaper")))
}

/// `sampledReport(spec)`, `spec.family = "sampled"` → `{ impulses, duration, startTime,
/// rampDelay, cost: { total, controlError, amplitudePenalty }, baselineCost, costReduction }`:
/// the design `design(spec)` returns plus its ramp delay (eq. 10) and cost J_q (eq. 17), and the
/// cost of the minimum-norm shaper under the same constraints.
#[cfg(feature = "js-api")]
#[wasm_bindgen(js_name = sampledReport)]
pub fn sampled_report(spec: JsValue) -> Result<JsValue, JsValue> {
    let request: DesignRequest = from_js(spec, "").map_err(js_error)?;
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
#[wasm_bindgen]
pub fn quantize(shaper: JsValue, mode: JsValue, options: JsValue) -> Result<JsValue, JsValue> {
    let shaper = shaper_from_js(shaper).map_err(js_error)?;
    let mode = mode_from_js(mode, "mode").map_err(js_error)?;
    let options: design::quantize::QuantizeOptions =
        from_js(options, "options").map_err(js_error)?;
    let report = design::quantize::quantize_with_report(&shaper, &mode, &options)
        .map_err(|e| js_error(e.within("options")))?;
    to_js(&report)
}

/// `simulate(spec)`: `spec = { plant, command, shaper? | impulses?, duration?, samplePeriod? |
/// sampleRateHz? }` → `{ time, unshaped: { basePosition, baseVelocity, baseAcceleration,
/// endpoint, endpointVelocity, endpointAcceleration, deflection, swingAngle?, metrics },
/// shaped (same, or null), shaper, modesHz, samplePeriod }`. See the README for every field.
#[cfg(feature = "js-api")]
#[wasm_bindgen]
pub fn simulate(spec: JsValue) -> Result<JsValue, JsValue> {
    let spec: crate::scenario::SimulationSpec = from_js(spec, "").map_err(js_error)?;
    let result = crate::scenario::run(&spec).map_err(js_error)?;
    to_js(&result)
}

/// `spectrum(spec)`: `spec = { command, shaper? | impulses?, plant?, fromHz?, toHz?, points?,
/// signal? }` → `{ frequencyHz, magnitude, unshaped, modesHz }` (|U(f)| of the shaped and the
/// unshaped command's velocity by default).
#[cfg(feature = "js-api")]
#[wasm_bindgen]
pub fn spectrum(spec: JsValue) -> Result<JsValue, JsValue> {
    let spec: crate::scenario::SpectrumSpec = from_js(spec, "").map_err(js_error)?;
    let result = crate::scenario::spectrum_for(&spec).map_err(js_error)?;
    to_js(&result)
}
