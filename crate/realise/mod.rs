//! What a controller does to a designed shaper: its *realisation*. Firmware rounds impulse times
//! to its timer or its fixed interpolation period, rounds amplitudes, caps the number of
//! impulses, and defines the named families its own way. [`realise`] designs the ideal shaper
//! from a spec, builds what the chosen controller runs instead, and reports what changed and
//! what it costs: V at each mode and I(Vtol) before and after, the frequency the realised shaper
//! acts at, and a one-line summary.
//!
//! Per controller (sources read through the search tools, cited by file and function; the code
//! is ours):
//!
//! - **ideal**: the design itself.
//! - **klipper** (Klipper3d/klipper): the family is replaced by Klipper's own definition at the
//!   first mode (klippy/extras/shaper_defs.py, `INPUT_SHAPERS`: `zv`, `mzv`, `zvd`, fitted
//!   `ei`, `2hump_ei`, `3hump_ei`; [`crate::measure::klipper::shapers`]); Klipper has no other
//!   family and no custom shaper. Times are doubles (chelper/kin_shaper.c `init_shaper`
//!   normalises and shifts but does not round) and at most 5 pulses
//!   (`struct shaper_pulses { … pulses[5]; }`).
//! - **kalico** (KalicoCrew/kalico): its named families are the K-scaled forms
//!   ([`definitions::k_scaled`], shaper_defs.py; EI built for V = 1/20); any other design runs
//!   as `shaper_type: custom` ([`crate::firmware_limits::KALICO_CUSTOM`]: at most 25 impulses,
//!   at most 0.2 s), all modes at once.
//! - **rrf** (RepRapFirmware 3.6, src/Movement/AxisShaper.cpp `AxisShaper::Configure`):
//!   `zvd`, `zvdd`, `zvddd`, `mzv` exact, `ei2`/`ei3` fitted on the damped period
//!   ([`definitions::rrf_fitted_ei`]); anything else as `P"custom"` (at most 5 impulses,
//!   positive amplitudes). Durations are floats in step clocks: no rounding.
//! - **marlin** (classic `INPUT_SHAPING_X/Y`, Marlin/src/module/stepper.cpp): ZV only; the
//!   echo's delay is half the *undamped* period truncated to stepper timer ticks
//!   (`set_shaping_frequency`; `STEPPER_TIMER_RATE` 2 MHz on AVR and STM32, `periodS`
//!   overrides the tick), amplitudes in 1/128 from a floored cubic fit in ζ
//!   (`set_shaping_damping_ratio`).
//! - **marlinFtMotion** (Marlin/src/module/ft_motion/shaping.cpp): ZV … ZVDDD, EI, 2HEI, 3HEI
//!   (K-scaled, `vtol` as designed) and its own MZV ([`definitions::marlin_ft_mzv`]); the
//!   echo indices are `Ni[1] = LROUND(base/f/df · FTM_FS)`, `Ni[i] = i·Ni[1]`
//!   (`set_axis_shaping_N`): every delay is a multiple of the first, rounded to the trajectory
//!   period `FTM_TS` = 1/`FTM_FS` = 1 ms (Configuration_adv.h; `periodS` overrides).
//! - **prusa** (Buddy firmware, lib/Marlin/Marlin/src/feature/input_shaper/input_shaper.cpp
//!   `input_shaper::get`, input_shaper.hpp `MAX_INPUT_SHAPER_PULSES = 5`): `zv`, `zvd`, `mzv`,
//!   `ei`, `ei_2hump`, `ei_3hump` in the K-scaled forms with `vibration_reduction` = 1/vtol,
//!   computed in float (relative error ~10⁻⁷, not modelled), times not rounded.
//! - **generic**: a controller of period `periodS` (times to its multiples, Peláez & Singhose
//!   2002, [`crate::design::quantize`]), `amplitudeSteps` (amplitudes to multiples of 1/N, sum
//!   kept) and `maxImpulses` (the smallest impulses merged into their nearest neighbour in time,
//!   sum kept), each optional.
//!
//! A firmware that names families shapes one frequency per axis: a design for several modes is
//! realised at the first (said in the changes), or as a custom shaper where the firmware has one.

pub mod definitions;

use crate::design::quantize::{quantize, round_times, QuantizeOptions, MAX_AMPLITUDE_STEPS};
use crate::design::{design_for, DesignRequest, ShaperSpec};
use crate::error::{positive, Error, Result};
use crate::firmware_limits::{
    KALICO_CUSTOM, RRF_MAX_DAMPING, RRF_MAX_FREQUENCY_HZ, RRF_MAX_IMPULSES, RRF_MIN_FREQUENCY_HZ,
};
use crate::measure::klipper::shapers::klipper_shaper;
use crate::mode::Mode;
use crate::shaper::{Impulse, Shaper, ShaperData};
use crate::vibration::{Insensitivity, SensitivityCurve};
use definitions::{Named, Pulses};
use serde::{Deserialize, Serialize};

mod report;
pub use report::summary_for;

/// Marlin's default stepper timer rate, Hz: `STEPPER_TIMER_RATE` is 2 MHz on AVR
/// (HAL/AVR/timers.h, F_CPU/8 at 16 MHz) and STM32 (HAL/STM32/timers.h `2000000`).
pub const MARLIN_STEPPER_TIMER_RATE_HZ: f64 = 2_000_000.0;
/// Marlin FT_MOTION's trajectory period, s: `FTM_TS` = 1/`FTM_FS`, `FTM_FS` 1000 Hz
/// (Configuration_adv.h, `FTM_FS`).
pub const MARLIN_FTM_TS_S: f64 = 0.001;
/// Klipper's largest shaper (chelper/kin_shaper.c, `struct shaper_pulses`, `pulses[5]`); also
/// Prusa's `MAX_INPUT_SHAPER_PULSES`.
pub const KLIPPER_MAX_PULSES: usize = 5;
/// Most impulses `maxImpulses` may ask for (the crate's shaper limit is larger; this keeps the
/// merge loop short).
pub const MAX_IMPULSES_OPTION: usize = 10_000;

/// The controller that runs the shaper (JS: camelCase strings).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum Controller {
    /// The design as it is.
    Ideal,
    /// Klipper (mainline).
    Klipper,
    /// Kalico (Klipper fork with custom shapers).
    Kalico,
    /// RepRapFirmware 3.6.
    Rrf,
    /// Marlin's classic ZV input shaping.
    Marlin,
    /// Marlin's FT_MOTION.
    MarlinFtMotion,
    /// Prusa's Buddy firmware.
    Prusa,
    /// A generic controller: period, amplitude steps, impulse cap.
    Generic,
}

impl Controller {
    /// The name used in messages.
    pub fn title(self) -> &'static str {
        match self {
            Controller::Ideal => "the ideal controller",
            Controller::Klipper => "Klipper",
            Controller::Kalico => "Kalico",
            Controller::Rrf => "RepRapFirmware",
            Controller::Marlin => "Marlin (classic input shaping)",
            Controller::MarlinFtMotion => "Marlin FT_MOTION",
            Controller::Prusa => "Prusa's Buddy firmware",
            Controller::Generic => "the controller",
        }
    }
}

/// Options of [`realise`] (JS: `{ firmware, periodS?, amplitudeSteps?, maxImpulses?, vtol? }`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct RealiseOptions {
    /// The controller.
    pub firmware: Controller,
    /// The controller's period, s: the tick of Marlin's stepper timer (default 0.5 µs), FT_MOTION's
    /// trajectory period (default 1 ms), the generic controller's period (default: times kept).
    /// Ignored by the other firmware.
    #[serde(default)]
    pub period_s: Option<f64>,
    /// Generic controller only: amplitudes to multiples of 1/N (default: kept).
    #[serde(default)]
    pub amplitude_steps: Option<u32>,
    /// Generic controller only: most impulses (default: no cap).
    #[serde(default)]
    pub max_impulses: Option<usize>,
    /// Tolerable vibration for I(Vtol), fraction in (0, 1); default 0.05.
    #[serde(default = "default_vtol")]
    pub vtol: f64,
    /// V(f) of both shapers over this range (at the first mode's damping), for a chart that
    /// overlays them; default: no curves.
    #[serde(default)]
    pub curve: Option<CurveRange>,
}

/// The frequencies of [`Realisation::sensitivity_ideal`] and `…_realised` (JS:
/// `{ fromHz, toHz, points }`), as for `sensitivity`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct CurveRange {
    /// First frequency, Hz (≥ 0).
    pub from_hz: f64,
    /// Last frequency, Hz (> `fromHz`).
    pub to_hz: f64,
    /// Evenly spaced points, 2 … [`crate::vibration::MAX_CURVE_POINTS`].
    pub points: usize,
}

fn default_vtol() -> f64 {
    0.05
}

impl RealiseOptions {
    /// Realisation by `firmware` with its defaults.
    pub fn new(firmware: Controller) -> Self {
        RealiseOptions {
            firmware,
            period_s: None,
            amplitude_steps: None,
            max_impulses: None,
            vtol: default_vtol(),
            curve: None,
        }
    }
}

/// What was changed, by kind (JS: camelCase).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "camelCase")]
pub enum ChangeKind {
    /// The family replaced by the firmware's own definition, or run as a custom shaper.
    Family,
    /// Impulse times rounded to a period.
    Times,
    /// Amplitudes rounded.
    Amplitudes,
    /// Impulses capped.
    Impulses,
    /// Only some modes shaped.
    Modes,
}

/// One change (JS: `{ kind, text }`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Change {
    /// What kind of change.
    pub kind: ChangeKind,
    /// A short sentence fragment, e.g. "times rounded to 1 ms".
    pub text: String,
}

/// V at one mode, designed and realised.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct ModeVibration {
    /// The mode's frequency, Hz.
    pub frequency_hz: f64,
    /// The mode's damping ratio.
    pub damping: f64,
    /// V of the ideal shaper at the mode.
    pub vibration_ideal: f64,
    /// V of the realised shaper at the mode.
    pub vibration_realised: f64,
}

/// The result of [`realise`].
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Realisation {
    /// The controller.
    pub firmware: Controller,
    /// The designed shaper.
    pub ideal: ShaperData,
    /// The shaper the controller runs (normalised to Σ A = 1 where the firmware normalises).
    pub realised: ShaperData,
    /// The family the controller runs (`zv`, `ei`, … in the firmware's own form, or `custom`).
    pub runs: String,
    /// What was changed, in order.
    pub changes: Vec<Change>,
    /// One line: what changed and what it costs at the mode.
    pub summary: String,
    /// V at each mode, ideal and realised.
    pub modes: Vec<ModeVibration>,
    /// The Vtol of the insensitivities.
    pub vtol: f64,
    /// I(Vtol) of the ideal shaper around the first mode.
    pub insensitivity_ideal: Insensitivity,
    /// I(Vtol) of the realised shaper around the first mode.
    pub insensitivity_realised: Insensitivity,
    /// When the realised times are the ideal ones scaled by one factor s (within 2 % of the
    /// duration) and s ≠ 1: the frequency the realised shaper acts at, f₁/s.
    pub acts_as_hz: Option<f64>,
    /// V(f) of the ideal shaper over `options.curve`, if asked.
    pub sensitivity_ideal: Option<SensitivityCurve>,
    /// V(f) of the realised shaper over `options.curve`, if asked.
    pub sensitivity_realised: Option<SensitivityCurve>,
}

/// Realises the shaper `request` designs on the controller of `options`.
///
/// ```
/// use input_shaping::realise::{realise, Controller, RealiseOptions};
/// use input_shaping::{DesignRequest, ModeSpec, ShaperSpec};
/// // A 60 Hz ZV on a 1 ms period: the half period 8.33 ms becomes 8 ms.
/// let request = DesignRequest {
///     modes: vec![ModeSpec { frequency_hz: 60.0, damping: 0.0 }],
///     shaper: ShaperSpec::Zv,
/// };
/// let mut options = RealiseOptions::new(Controller::Generic);
/// options.period_s = Some(0.001);
/// let r = realise(&request, &options)?;
/// assert!((r.acts_as_hz.unwrap() - 62.5).abs() < 1e-9);
/// assert!((r.modes[0].vibration_realised - (0.48 * std::f64::consts::PI).cos()).abs() < 1e-12);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn realise(request: &DesignRequest, options: &RealiseOptions) -> Result<Realisation> {
    check_options(options)?;
    let modes = Mode::list(&request.modes)?;
    let ideal = design_for(&request.shaper, &modes)?;
    realise_designed(request, &modes, ideal, options)
}

/// The checks of `options` that do not depend on the design: `vtol` in (0, 1), `periodS`
/// positive, `amplitudeSteps` in 1 … 2²⁴, `maxImpulses` in 1 … [`MAX_IMPULSES_OPTION`]. Errors
/// name the option.
pub fn check_options(options: &RealiseOptions) -> Result<()> {
    crate::vibration::tolerable_vibration(options.vtol)?;
    if let Some(c) = options.curve {
        // The same checks `sensitivity` makes, on a one-impulse shaper.
        crate::vibration::sensitivity(&Shaper::identity(), &sensitivity_options(c, 0.0))
            .map_err(|e| e.within("curve"))?;
    }
    if let Some(p) = options.period_s {
        positive("periodS", p)?;
    }
    if let Some(steps) = options.amplitude_steps {
        if steps == 0 {
            return Err(Error::invalid(
                "amplitudeSteps",
                "must be at least 1, got 0",
            ));
        }
        if steps > MAX_AMPLITUDE_STEPS {
            return Err(Error::TooLarge {
                field: "amplitudeSteps".into(),
                value: f64::from(steps),
                limit: f64::from(MAX_AMPLITUDE_STEPS),
            });
        }
    }
    match options.max_impulses {
        Some(0) => Err(Error::invalid("maxImpulses", "must be at least 1, got 0")),
        Some(max) if max > MAX_IMPULSES_OPTION => Err(Error::TooLarge {
            field: "maxImpulses".into(),
            value: max as f64,
            limit: MAX_IMPULSES_OPTION as f64,
        }),
        _ => Ok(()),
    }
}

/// [`realise`] of an already designed `ideal` for `request`'s validated `modes` (non-empty).
/// Every error here comes from the options or the firmware's limits (fields `firmware`,
/// `periodS`, `amplitudeSteps`, `maxImpulses`).
pub fn realise_designed(
    request: &DesignRequest,
    modes: &[Mode],
    ideal: Shaper,
    options: &RealiseOptions,
) -> Result<Realisation> {
    check_options(options)?;
    if modes.is_empty() {
        return Err(Error::invalid("modes", "at least one mode is needed"));
    }
    let mut changes = Vec::new();
    let (realised, runs) = match options.firmware {
        Controller::Ideal => (ideal.clone(), request.shaper.name().to_string()),
        Controller::Generic => (
            generic(&ideal, options, &mut changes)?,
            request.shaper.name().to_string(),
        ),
        firmware => on_firmware(
            firmware,
            &request.shaper,
            modes,
            &ideal,
            options,
            &mut changes,
        )?,
    };
    report::build(request, modes, ideal, realised, runs, changes, options)
}

/// `sensitivity`'s options for a curve range at damping `zeta`.
pub(crate) fn sensitivity_options(
    c: CurveRange,
    zeta: f64,
) -> crate::vibration::SensitivityOptions {
    crate::vibration::SensitivityOptions {
        from_hz: c.from_hz,
        to_hz: c.to_hz,
        points: c.points,
        damping: zeta,
    }
}

/// The named family of `spec`, if firmware could run it by name.
pub fn named(spec: &ShaperSpec) -> Option<Named> {
    Some(match spec {
        ShaperSpec::Zv => Named::Zv,
        ShaperSpec::Zvd => Named::Zvd,
        ShaperSpec::Zvdd => Named::Zvdd,
        ShaperSpec::Zvdn { derivatives: 0 } => Named::Zv,
        ShaperSpec::Zvdn { derivatives: 1 } => Named::Zvd,
        ShaperSpec::Zvdn { derivatives: 2 } => Named::Zvdd,
        ShaperSpec::Zvdn { derivatives: 3 } => Named::Zvddd,
        ShaperSpec::Mzv => Named::Mzv,
        ShaperSpec::Ei { vtol } | ShaperSpec::Eihump { humps: 1, vtol } => Named::Ei(*vtol),
        ShaperSpec::Ei2 { vtol } | ShaperSpec::Eihump { humps: 2, vtol } => Named::Ei2(*vtol),
        ShaperSpec::Ei3 { vtol } | ShaperSpec::Eihump { humps: 3, vtol } => Named::Ei3(*vtol),
        _ => return None,
    })
}

/// A shaper from amplitudes and times.
fn from_pulses((amplitudes, times): Pulses) -> Result<Shaper> {
    Shaper::new(
        amplitudes
            .into_iter()
            .zip(times)
            .map(|(amplitude, time)| Impulse { time, amplitude })
            .collect(),
    )
}

/// Normalised to Σ A = 1 (what every firmware here runs).
fn unit(shaper: Shaper) -> Result<Shaper> {
    shaper.normalized()
}

/// The named firmware's realisation.
fn on_firmware(
    firmware: Controller,
    spec: &ShaperSpec,
    modes: &[Mode],
    ideal: &Shaper,
    options: &RealiseOptions,
    changes: &mut Vec<Change>,
) -> Result<(Shaper, String)> {
    let family = named(spec);
    let has_custom = matches!(firmware, Controller::Kalico | Controller::Rrf);
    // Several modes: a firmware with custom shapers runs the convolved design as it is.
    if has_custom && (modes.len() > 1 || family.is_none()) {
        return custom(firmware, ideal, changes).map(|s| (s, "custom".into()));
    }
    let family = family.ok_or_else(|| no_family(firmware, spec))?;
    let mode = &modes[0];
    if modes.len() > 1 {
        changes.push(Change {
            kind: ChangeKind::Modes,
            text: format!(
                "{} shapes one frequency per axis: only the {} Hz mode",
                firmware.title(),
                fmt_hz(mode.frequency_hz())
            ),
        });
    }
    let (f, zeta) = (mode.frequency_hz(), mode.damping());
    match firmware {
        Controller::Klipper => klipper(family, spec, f, zeta, changes),
        Controller::Kalico | Controller::Prusa => {
            k_scaled_firmware(firmware, family, spec, f, zeta, changes)
        }
        Controller::Rrf => rrf(family, spec, f, zeta, ideal, changes),
        Controller::Marlin => marlin(family, f, zeta, options, changes),
        Controller::MarlinFtMotion => marlin_ft(family, spec, f, zeta, options, changes),
        Controller::Ideal | Controller::Generic => Ok((ideal.clone(), spec.name().to_string())),
    }
}

/// The error for a family a firmware does not define (and cannot take as custom).
fn no_family(firmware: Controller, spec: &ShaperSpec) -> Error {
    let known = match firmware {
        Controller::Klipper => "zv, mzv, zvd, ei, ei2, ei3",
        Controller::Prusa => "zv, mzv, zvd, ei, ei2, ei3",
        Controller::MarlinFtMotion => "zv, zvd, zvdd, zvdn up to 3 derivatives, mzv, ei, ei2, ei3",
        _ => "its named families",
    };
    Error::invalid(
        "firmware",
        format!(
            "{} has no '{}' shaper and takes no custom shaper (it runs {known}); Kalico and \
             RepRapFirmware take custom shapers",
            firmware.title(),
            spec.name()
        ),
    )
}

/// A note that the family was replaced by the firmware's own definition.
fn family_change(firmware: Controller, family: Named, how: &str) -> Change {
    Change {
        kind: ChangeKind::Family,
        text: format!(
            "{} replaced by {}'s own {}{how}",
            family.name().to_uppercase(),
            firmware.title(),
            family.name().to_uppercase()
        ),
    }
}

/// Klipper: its table at (f, ζ); its EI families are fitted for V = 5 %.
fn klipper(
    family: Named,
    spec: &ShaperSpec,
    f: f64,
    zeta: f64,
    changes: &mut Vec<Change>,
) -> Result<(Shaper, String)> {
    let name = family
        .klipper_name()
        .ok_or_else(|| no_family(Controller::Klipper, spec))?;
    let shaper = klipper_shaper(name, f, zeta).map_err(|e| match e {
        Error::InvalidInput { reason, .. } => Error::invalid("firmware", reason),
        other => other,
    })?;
    match family {
        Named::Ei(v) | Named::Ei2(v) | Named::Ei3(v) => changes.push(family_change(
            Controller::Klipper,
            family,
            &format!(
                " (a polynomial fit in ζ{})",
                if (v - 0.05).abs() > 1e-12 {
                    ", built for V = 5 %"
                } else {
                    ""
                }
            ),
        )),
        Named::Mzv => {} // the crate's MZV is Klipper's (crate::design::modified).
        _ => {}
    }
    Ok((unit(shaper)?, name.to_string()))
}

/// Kalico or Prusa: the K-scaled forms (Kalico fixes V = 1/20; Prusa takes
/// `vibration_reduction`, here 1/vtol as designed).
fn k_scaled_firmware(
    firmware: Controller,
    family: Named,
    spec: &ShaperSpec,
    f: f64,
    zeta: f64,
    changes: &mut Vec<Change>,
) -> Result<(Shaper, String)> {
    if matches!(family, Named::Zvdd | Named::Zvddd) {
        return Err(no_family(firmware, spec));
    }
    let family = match (firmware, family) {
        (Controller::Kalico, Named::Ei(_)) => Named::Ei(0.05),
        (Controller::Kalico, Named::Ei2(_)) => Named::Ei2(0.05),
        (Controller::Kalico, Named::Ei3(_)) => Named::Ei3(0.05),
        (_, other) => other,
    };
    if let Some(v) = family.vtol() {
        let fixed = firmware == Controller::Kalico && named(spec).and_then(Named::vtol) != Some(v);
        changes.push(family_change(
            firmware,
            family,
            if fixed {
                " (undamped EI amplitudes times powers of K, built for V = 5 %)"
            } else {
                " (undamped EI amplitudes times powers of K)"
            },
        ));
    }
    let shaper = unit(from_pulses(definitions::k_scaled(family, f, zeta))?)?;
    Ok((
        shaper,
        family.klipper_name().unwrap_or(family.name()).to_string(),
    ))
}

/// RepRapFirmware 3.6: its named families, range checks on F and S.
fn rrf(
    family: Named,
    spec: &ShaperSpec,
    f: f64,
    zeta: f64,
    ideal: &Shaper,
    changes: &mut Vec<Change>,
) -> Result<(Shaper, String)> {
    let pulses = match family {
        Named::Zvd => definitions::binomial(2, f, zeta),
        Named::Zvdd => definitions::binomial(3, f, zeta),
        Named::Zvddd => definitions::binomial(4, f, zeta),
        Named::Mzv => definitions::mzv(f, zeta),
        Named::Ei2(_) | Named::Ei3(_) => {
            changes.push(family_change(
                Controller::Rrf,
                family,
                " (Klipper's fit in ζ on the damped period, built for V = 5 %)",
            ));
            definitions::rrf_fitted_ei(
                if matches!(family, Named::Ei2(_)) {
                    2
                } else {
                    3
                },
                f,
                zeta,
            )
        }
        // RRF 3.6 has no zv nor 3-impulse ei: they run as custom.
        Named::Zv | Named::Ei(_) => {
            let _ = spec;
            return custom(Controller::Rrf, ideal, changes).map(|s| (s, "custom".into()));
        }
    };
    if !(RRF_MIN_FREQUENCY_HZ..=RRF_MAX_FREQUENCY_HZ).contains(&f) {
        return Err(Error::invalid(
            "firmware",
            format!(
                "RepRapFirmware's M593 F takes {RRF_MIN_FREQUENCY_HZ:.2} … {RRF_MAX_FREQUENCY_HZ} Hz, \
                 the mode is at {f} Hz"
            ),
        ));
    }
    if zeta > RRF_MAX_DAMPING {
        return Err(Error::invalid(
            "firmware",
            format!(
                "RepRapFirmware's M593 S takes 0 … {RRF_MAX_DAMPING}, the mode's damping is {zeta}"
            ),
        ));
    }
    let name = match family {
        Named::Ei2(_) => "ei2",
        Named::Ei3(_) => "ei3",
        other => other.name(),
    };
    Ok((unit(from_pulses(pulses)?)?, name.to_string()))
}

/// A custom shaper on Kalico or RRF: the ideal impulses normalised, capped to the firmware's
/// count, checked against its other limits.
fn custom(firmware: Controller, ideal: &Shaper, changes: &mut Vec<Change>) -> Result<Shaper> {
    let max = if firmware == Controller::Rrf {
        RRF_MAX_IMPULSES
    } else {
        KALICO_CUSTOM.max_impulses
    };
    changes.push(Change {
        kind: ChangeKind::Family,
        text: format!("run as {}'s custom shaper", firmware.title()),
    });
    let shaper = cap_impulses(&unit(ideal.clone())?, max, firmware.title(), changes)?;
    if firmware == Controller::Rrf && shaper.impulses().iter().any(|i| i.amplitude < 0.0) {
        return Err(Error::invalid(
            "firmware",
            "RepRapFirmware's custom shaper takes positive amplitudes only",
        ));
    }
    if shaper.duration() > KALICO_CUSTOM.max_duration_s {
        return Err(Error::invalid(
            "firmware",
            format!(
                "{} refuses a custom shaper longer than {} s; this one lasts {:.4} s",
                firmware.title(),
                KALICO_CUSTOM.max_duration_s,
                shaper.duration()
            ),
        ));
    }
    Ok(shaper)
}

/// Marlin classic: ZV at f, delay ⌊(rate/2)/f⌋ ticks, amplitudes factor1/128, factor2/128.
fn marlin(
    family: Named,
    f: f64,
    zeta: f64,
    options: &RealiseOptions,
    changes: &mut Vec<Change>,
) -> Result<(Shaper, String)> {
    let tick = positive(
        "periodS",
        options
            .period_s
            .unwrap_or(1.0 / MARLIN_STEPPER_TIMER_RATE_HZ),
    )?;
    if family != Named::Zv {
        changes.push(Change {
            kind: ChangeKind::Family,
            text: format!(
                "{} replaced by Marlin's ZV (its only shaper)",
                family.name().to_uppercase()
            ),
        });
    }
    let ticks = definitions::marlin_zv_delay_ticks(1.0 / tick, f);
    if ticks < 1.0 {
        return Err(Error::invalid(
            "periodS",
            format!("a {tick} s tick cannot delay half a period of {f} Hz"),
        ));
    }
    changes.push(Change {
        kind: ChangeKind::Times,
        text: format!(
            "delay = half the undamped period truncated to {} ticks",
            fmt_duration(tick)
        ),
    });
    let (f1, f2) = definitions::marlin_zv_factors(zeta);
    changes.push(Change {
        kind: ChangeKind::Amplitudes,
        text: format!("amplitudes {f1}/128 and {f2}/128"),
    });
    let shaper = Shaper::new(vec![
        Impulse {
            time: 0.0,
            amplitude: f64::from(f1) / 128.0,
        },
        Impulse {
            time: ticks * tick,
            amplitude: f64::from(f2) / 128.0,
        },
    ])?;
    Ok((shaper, "zv".into()))
}

/// Marlin FT_MOTION: its families, echo indices multiples of round(base·T_d / FTM_TS).
fn marlin_ft(
    family: Named,
    spec: &ShaperSpec,
    f: f64,
    zeta: f64,
    options: &RealiseOptions,
    changes: &mut Vec<Change>,
) -> Result<(Shaper, String)> {
    let period = positive("periodS", options.period_s.unwrap_or(MARLIN_FTM_TS_S))?;
    let (amplitudes, times) = match family {
        Named::Mzv => {
            changes.push(family_change(
                Controller::MarlinFtMotion,
                family,
                " (K per 0.375 period: off the mode when damped)",
            ));
            definitions::marlin_ft_mzv(f, zeta)
        }
        other => {
            if other.vtol().is_some() {
                changes.push(family_change(
                    Controller::MarlinFtMotion,
                    other,
                    " (undamped EI amplitudes times powers of K)",
                ));
            }
            definitions::k_scaled(other, f, zeta)
        }
    };
    let _ = spec;
    let step = times.get(1).copied().unwrap_or(0.0);
    let n1 = (step / period).round();
    if !n1.is_finite() || n1 * (times.len() as f64) > 1e9 {
        return Err(Error::invalid(
            "periodS",
            format!("{period} s is too fine for {f} Hz"),
        ));
    }
    changes.push(Change {
        kind: ChangeKind::Times,
        text: format!("times rounded to {}", fmt_duration(period)),
    });
    let shaper = Shaper::new(
        amplitudes
            .iter()
            .enumerate()
            .map(|(i, &amplitude)| Impulse {
                time: i as f64 * n1 * period,
                amplitude,
            })
            .collect(),
    )?;
    let name = match family {
        Named::Ei2(_) => "2hei".to_string(),
        Named::Ei3(_) => "3hei".to_string(),
        other => other.name().to_string(),
    };
    Ok((unit(shaper)?, name))
}

/// The generic controller: cap, then times, then amplitudes.
fn generic(ideal: &Shaper, options: &RealiseOptions, changes: &mut Vec<Change>) -> Result<Shaper> {
    let mut shaper = ideal.clone();
    if let Some(max) = options.max_impulses {
        shaper = cap_impulses(&shaper, max, "the controller", changes)?;
    }
    let period = options
        .period_s
        .map(|p| positive("periodS", p))
        .transpose()?;
    if let Some(steps) = options.amplitude_steps {
        // Peláez & Singhose's rounding: times to the period, then amplitudes to 1/N, Σ kept.
        let mut q = QuantizeOptions::new(steps);
        q.tick_s = period;
        shaper = quantize(&shaper, &q).map_err(|e| rename_field(e, "tickS", "periodS"))?;
    } else if let Some(period) = period {
        shaper = round_times(&shaper, period).map_err(|e| rename_field(e, "tickS", "periodS"))?;
    }
    if let Some(period) = period {
        changes.push(Change {
            kind: ChangeKind::Times,
            text: format!("times rounded to {}", fmt_duration(period)),
        });
    }
    if let Some(steps) = options.amplitude_steps {
        changes.push(Change {
            kind: ChangeKind::Amplitudes,
            text: format!("amplitudes rounded to {steps} steps"),
        });
    }
    Ok(shaper)
}

fn rename_field(e: Error, from: &str, to: &str) -> Error {
    match e {
        Error::InvalidInput { field, reason } if field == from => Error::invalid(to, reason),
        other => other,
    }
}

/// At most `max` impulses: repeatedly the impulse of smallest |A| is added to its nearest
/// neighbour in time (Σ A kept).
fn cap_impulses(
    shaper: &Shaper,
    max: usize,
    who: &str,
    changes: &mut Vec<Change>,
) -> Result<Shaper> {
    let mut impulses = shaper.impulses().to_vec();
    let before = impulses.len();
    if before <= max {
        return Ok(shaper.clone());
    }
    while impulses.len() > max {
        let k = (0..impulses.len())
            .min_by(|&i, &j| {
                impulses[i]
                    .amplitude
                    .abs()
                    .total_cmp(&impulses[j].amplitude.abs())
            })
            .unwrap_or(0);
        let gone = impulses.remove(k);
        let nearest = (0..impulses.len())
            .min_by(|&i, &j| {
                (impulses[i].time - gone.time)
                    .abs()
                    .total_cmp(&(impulses[j].time - gone.time).abs())
            })
            .unwrap_or(0);
        impulses[nearest].amplitude += gone.amplitude;
    }
    changes.push(Change {
        kind: ChangeKind::Impulses,
        text: format!(
            "impulses capped at {who}'s {max} (from {before}; the smallest merged into their \
             nearest neighbours)"
        ),
    });
    Shaper::new(impulses)
}

/// A frequency for text: at most one decimal, trailing zeros dropped.
pub(crate) fn fmt_hz(f: f64) -> String {
    trim(format!("{f:.1}"))
}

/// A duration for text in s, ms or µs with at most 3 significant decimals.
pub(crate) fn fmt_duration(t: f64) -> String {
    if t >= 1.0 {
        format!("{} s", trim(format!("{t:.3}")))
    } else if t >= 1e-3 {
        format!("{} ms", trim(format!("{:.3}", t * 1e3)))
    } else {
        format!("{} µs", trim(format!("{:.3}", t * 1e6)))
    }
}

fn trim(s: String) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}
