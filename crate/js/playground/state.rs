//! The playground's input: the state the page sends, parsed and checked once at the boundary
//! into a [`Frame`] — the designs' specs, the modes, the view's settings and the canvases to
//! draw on, all validated — so the analysis, the simulation and the drawing take typed values
//! and never go back to the JS objects.

use crate::chart::{self, ChartStyle};
use crate::command::{Command, CommandSpec};
use crate::design::ShaperSpec;
use crate::error::Error;
use crate::mode::{Mode, ModeSpec};
use crate::plant::{ModalPlant, Pendulum, PendulumSpec, Plant, TwoMass};
use crate::shaper::{Shaper, ShaperData};
use crate::spectrum::{SpectrumOptions, SpectrumSignal};
use crate::vibration::SensitivityOptions;
use serde::Deserialize;
use wasm_bindgen::{JsCast, JsValue};
use web_sys::HtmlCanvasElement;

use super::super::api::from_js_root;

/// Most shapers the playground compares at once.
const MAX_COMPARED: usize = 4;

/// What the page shows, in one object (see `renderPlayground`).
#[derive(Debug, Deserialize)]
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

#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase", default)]
pub(super) struct PlaygroundView {
    /// Sensitivity range, Hz; defaults to 0 … 2 × the highest mode.
    pub from_hz: Option<f64>,
    pub to_hz: Option<f64>,
    pub points: usize,
    /// Tolerable vibration, fraction.
    pub vtol: f64,
    /// Square corner velocity for Klipper's figures, mm/s.
    pub scv: f64,
    /// Device pixel ratio the canvases were sized with.
    pub pixel_ratio: f64,
    /// Model mismatch of the simulation: actual frequency = model × `mismatch`.
    pub mismatch: f64,
    /// Mismatch per mode, rᵢ (0.05 … 20; missing entries 1): mode i's actual frequency is the
    /// model's × `mismatch` × rᵢ. At most one entry per mode.
    pub mode_mismatch: Vec<f64>,
    /// Actual damping ratio per mode (0 … 0.99; `null` or a missing entry: the model's). At
    /// most one entry per mode. The two-mass spring's damping is its damper's, so it does not
    /// take these.
    pub actual_damping: Vec<Option<f64>>,
    /// The reference command of the simulation (as `simulate` takes it).
    pub command: CommandSpec,
    /// The simulated plant, built from the (mismatched) modes.
    pub plant: ViewPlant,
    /// Samples of each simulated response.
    pub samples: usize,
    /// Simulated seconds (default: the longest shaped move + 3 periods of the slowest mode).
    pub duration: Option<f64>,
    /// Which compared shaper the frequency × damping map shows (index into `shapers`).
    pub map_shaper: usize,
    /// The colour of each compared shaper, as a position in the palette (0 … 3); default
    /// 0, 1, 2, 3. The page leaves a shaper that cannot be designed out and keeps the others'.
    pub series_colors: Option<Vec<usize>>,
    /// Resolution of the map.
    pub map_frequency_points: usize,
    pub map_damping_points: usize,
    /// Upper damping ratio of V(ζ) and the map (default max(0.2, 3 × the highest mode's ζ),
    /// at most 0.9).
    pub damping_to: Option<f64>,
    /// Points of V(ζ).
    pub damping_points: usize,
    /// Frequencies of the command spectrum (over the V(f) range).
    pub spectrum_points: usize,
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
            mode_mismatch: Vec::new(),
            actual_damping: Vec::new(),
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
    /// The playground's simulated plant: `modal` (the modes × mismatch, equal participation),
    /// `twoMass` (Peláez & Singhose's two-mass spring with its rigid-body mode, its frequency ×
    /// mismatch) or `pendulum` (a nonlinear crane pendulum whose linearised mode is the first
    /// mode × mismatch, optionally hoisted).
    #[derive(Debug, Clone)]
    pub(super) enum ViewPlant {
        Modal,
        /// The two-mass spring as the library takes it (SI units); the mismatch r (× mode 1's
        /// own ratio) scales its stiffness by r², so its frequency by r.
        TwoMass(TwoMass),
        #[serde(rename_all = "camelCase")]
        Pendulum {
            /// Gravity, m/s² (default 9.81).
            #[serde(default = "default_gravity")]
            gravity: f64,
            /// Swing angle at t = 0, rad (default 0).
            #[serde(default)]
            initial_angle: f64,
            /// The change of the cable length over time (a command, m), as the library's
            /// pendulum takes it (`hoist`).
            #[serde(default)]
            hoist: Option<CommandSpec>,
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

/// The canvases of a frame, each looked up once (`None`: that chart is not drawn).
pub(super) struct Canvases {
    pub impulses: Option<HtmlCanvasElement>,
    pub sensitivity: Option<HtmlCanvasElement>,
    pub damping: Option<HtmlCanvasElement>,
    pub map: Option<HtmlCanvasElement>,
    pub response: Option<HtmlCanvasElement>,
    pub command: Option<HtmlCanvasElement>,
    pub spectrum: Option<HtmlCanvasElement>,
    pub robustness: Option<HtmlCanvasElement>,
}

impl Canvases {
    fn collect(canvases: &JsValue) -> Self {
        Canvases {
            impulses: canvas(canvases, "impulses"),
            sensitivity: canvas(canvases, "sensitivity"),
            damping: canvas(canvases, "damping"),
            map: canvas(canvases, "map"),
            response: canvas(canvases, "response"),
            command: canvas(canvases, "command"),
            spectrum: canvas(canvases, "spectrum"),
            robustness: canvas(canvases, "robustness"),
        }
    }
}

/// One frame's input, parsed and checked: what the rest of the frame works from.
pub(super) struct Frame {
    /// The modes as given (the analysis cache's key) and validated.
    pub mode_specs: Vec<ModeSpec>,
    pub modes: Vec<Mode>,
    /// The compared shapers (1 … [`MAX_COMPARED`]), their labels, and those designed elsewhere.
    pub specs: Vec<ShaperSpec>,
    pub labels: Vec<String>,
    pub designed: Vec<Option<Shaper>>,
    /// The view's settings, each checked.
    pub view: PlaygroundView,
    /// V(f)'s grid (at the first mode's damping).
    pub sensitivity: SensitivityOptions,
    /// Upper damping ratio of V(ζ) and the map.
    pub damping_to: f64,
    /// The command spectrum's grid (over V(f)'s range).
    pub spectrum: SpectrumOptions,
    /// Samples of each simulated response.
    pub samples: usize,
    /// The simulated plant (the modes × mismatch) and the reference command.
    pub plant: Plant,
    pub command: Command,
    /// The charts' style (pixel ratio, series colours).
    pub style: ChartStyle,
    pub canvases: Canvases,
}

impl Frame {
    /// Reads and checks `state` and collects `canvases`. Errors name the field.
    pub(super) fn parse(state: JsValue, canvases: &JsValue) -> Result<Frame, Error> {
        let state: PlaygroundState = from_js_root(state, "state")?;
        let modes = Mode::list(&state.modes)?;
        let specs = compared(state.shapers, state.shaper)?;
        let designed = designed(&state.designed, specs.len())?;
        let view = state.view;
        let f_max = modes.iter().map(Mode::frequency_hz).fold(0.0_f64, f64::max);
        let sensitivity = SensitivityOptions {
            from_hz: view.from_hz.unwrap_or(0.0),
            to_hz: view.to_hz.unwrap_or(2.0 * f_max),
            points: view.points,
            damping: modes[0].damping(),
        };
        let z_max = modes.iter().map(Mode::damping).fold(0.0_f64, f64::max);
        let damping_to = match view.damping_to {
            Some(z) => within_range("view.dampingTo", z, 1e-3, 0.99)?,
            None => (3.0 * z_max).clamp(0.2, 0.9),
        };
        if view.map_shaper >= specs.len() {
            return Err(Error::invalid(
                "view.mapShaper",
                format!(
                    "must be one of the compared shapers, 0 … {}, got {}",
                    specs.len() - 1,
                    view.map_shaper
                ),
            ));
        }
        let colors = series_colors(view.series_colors.as_deref(), specs.len())?;
        count_in(
            "view.mapFrequencyPoints",
            view.map_frequency_points,
            2,
            1000,
        )?;
        count_in("view.mapDampingPoints", view.map_damping_points, 2, 500)?;
        count_in("view.dampingPoints", view.damping_points, 2, 5000)?;
        count_in("view.spectrumPoints", view.spectrum_points, 2, 5000)?;
        let samples = count_in("view.samples", view.samples, 50, 20_000)?;
        let spectrum = SpectrumOptions {
            from_hz: sensitivity.from_hz,
            to_hz: sensitivity.to_hz,
            points: view.spectrum_points,
            signal: SpectrumSignal::Velocity,
        };
        let plant = view_plant(&modes, &view)?;
        let command = Command::from_spec(&view.command).map_err(|e| e.within("view.command"))?;
        if let Some(d) = view.duration {
            within_range("view.duration", d, 1e-6, 1e6)?;
        }
        let style = ChartStyle {
            scale: if view.pixel_ratio.is_finite() && view.pixel_ratio > 0.0 {
                view.pixel_ratio
            } else {
                1.0
            },
            colors,
        };
        Ok(Frame {
            mode_specs: state.modes,
            labels: labels(&specs),
            modes,
            specs,
            designed,
            view,
            sensitivity,
            damping_to,
            spectrum,
            samples,
            plant,
            command,
            style,
            canvases: Canvases::collect(canvases),
        })
    }

    /// Which of the damping, map and spectrum charts are drawn (their analyses are skipped
    /// otherwise).
    pub(super) fn charts(&self) -> [bool; 3] {
        [
            self.canvases.damping.is_some(),
            self.canvases.map.is_some(),
            self.canvases.spectrum.is_some(),
        ]
    }
}

/// The compared shapers: `shapers`, or `shaper` when that is empty; 1 … [`MAX_COMPARED`].
fn compared(
    shapers: Vec<ShaperSpec>,
    shaper: Option<ShaperSpec>,
) -> Result<Vec<ShaperSpec>, Error> {
    let mut specs = shapers;
    if specs.is_empty() {
        specs.extend(shaper);
    }
    if specs.is_empty() {
        return Err(Error::invalid("shapers", "at least one shaper is required"));
    }
    if specs.len() > MAX_COMPARED {
        return Err(Error::TooLarge {
            field: "shapers".into(),
            value: specs.len() as f64,
            limit: MAX_COMPARED as f64,
        });
    }
    Ok(specs)
}

/// The shapers designed elsewhere (`designed`), each checked as `exportShaper` checks one.
fn designed(
    designed: &[Option<ShaperData>],
    compared: usize,
) -> Result<Vec<Option<Shaper>>, Error> {
    if designed.len() > compared {
        return Err(Error::invalid(
            "designed",
            format!(
                "has {} entries for {compared} compared shapers",
                designed.len()
            ),
        ));
    }
    designed
        .iter()
        .enumerate()
        .map(|(k, d)| {
            d.as_ref()
                .map(|d| Shaper::from_data(d).map_err(|e| e.within(&format!("designed[{k}]"))))
                .transpose()
        })
        .collect()
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

/// The frequency ratio of each mode (`mismatch` × its own) and its actual damping ratio, or the
/// error naming the entry.
fn mode_factors(modes: &[Mode], view: &PlaygroundView) -> Result<Vec<(f64, f64)>, Error> {
    let r = within_range("view.mismatch", view.mismatch, 0.05, 20.0)?;
    for (field, given) in [
        ("view.modeMismatch", view.mode_mismatch.len()),
        ("view.actualDamping", view.actual_damping.len()),
    ] {
        if given > modes.len() {
            return Err(Error::invalid(
                field,
                format!("has {given} entries for {} modes", modes.len()),
            ));
        }
    }
    modes
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let own = match view.mode_mismatch.get(i) {
                Some(&x) => within_range(&format!("view.modeMismatch[{i}]"), x, 0.05, 20.0)?,
                None => 1.0,
            };
            let zeta = match view.actual_damping.get(i).copied().flatten() {
                Some(z) => within_range(&format!("view.actualDamping[{i}]"), z, 0.0, 0.99)?,
                None => m.damping(),
            };
            Ok((r * own, zeta))
        })
        .collect()
}

/// The simulated plant of a frame: the modes with frequencies × `mismatch` × their own ratio
/// and their actual damping ratios.
fn view_plant(modes: &[Mode], view: &PlaygroundView) -> Result<Plant, Error> {
    let factors = mode_factors(modes, view)?;
    let actual = modes
        .iter()
        .zip(&factors)
        .enumerate()
        .map(|(i, (m, &(r, zeta)))| {
            Mode::new(m.frequency_hz() * r, zeta).map_err(|e| {
                let field = if view.mode_mismatch.get(i).is_some_and(|&x| x != 1.0) {
                    format!("view.modeMismatch[{i}]")
                } else {
                    "view.mismatch".to_string()
                };
                Error::invalid(&field, e.to_string())
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    // The two-mass spring's one mode is mode 1's: its ratio scales the spring.
    let r = factors.first().map_or(1.0, |f| f.0);
    match &view.plant {
        ViewPlant::Modal => {
            let share = 1.0 / actual.len() as f64;
            let participation = vec![share; actual.len()];
            Ok(Plant::Modal(
                ModalPlant::new(actual, participation).map_err(|e| e.within("view.plant"))?,
            ))
        }
        ViewPlant::TwoMass(given) => {
            // Checked as given first, so an error names the field the page shows.
            given.validate().map_err(|e| e.within("view.plant"))?;
            let t = TwoMass {
                stiffness: given.stiffness * r * r,
                ..*given
            };
            t.validate()
                .map_err(|e| Error::invalid("view.mismatch", e.to_string()))?;
            Ok(Plant::TwoMass(t))
        }
        ViewPlant::Pendulum {
            gravity,
            initial_angle,
            hoist,
        } => {
            let mode = &actual[0];
            let omega = mode.omega_rad_s();
            let spec = PendulumSpec {
                length: gravity / (omega * omega),
                gravity: *gravity,
                damping: mode.damping(),
                initial_angle: *initial_angle,
                hoist: hoist.clone(),
            };
            Ok(Plant::Pendulum(
                Pendulum::from_spec(&spec).map_err(|e| e.within("view.plant"))?,
            ))
        }
    }
}

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
