//! Firmware configuration text for a shaper per axis: Klipper's `[input_shaper]` block and
//! `SET_INPUT_SHAPER` command, the same for Klipper forks that take a `custom` shaper (Kalico),
//! RepRapFirmware's `M593`, and Marlin's `M593 X F… D…`.
//!
//! Every limit checked here is the firmware's own, read from its source (GPL: read and cited,
//! not copied); the constants and their citations live in [`crate::firmware_limits`], shared
//! with the optimiser, and are re-exported here. A shaper a firmware cannot express is an
//! [`Error`] naming the axis field, the firmware and the limit; nothing is truncated or
//! silently replaced. Values are checked *as written*: each number is formatted, read back and
//! the firmware's limit applied to what the firmware will read.
//!
//! What each firmware takes:
//! - **Klipper** (Klipper3d/klipper, klippy/extras/input_shaper.py, `InputShaperParams.__init__`
//!   and `update`): per axis x and y, `shaper_type_<axis>` one of `zv`, `mzv`, `zvd`, `ei`,
//!   `2hump_ei`, `3hump_ei` (klippy/extras/shaper_defs.py, `INPUT_SHAPERS`),
//!   `shaper_freq_<axis>` ≥ 0 (0 disables shaping, so a recommendation needs > 0) and
//!   `damping_ratio_<axis>` in [0, 1] (`minval=0., maxval=1.`; 1 itself divides by
//!   √(1 − ζ²) = 0 in every shaper of shaper_defs.py, so < 1 here). No custom shaper type.
//!   `SET_INPUT_SHAPER` takes the same as `SHAPER_TYPE_X`, `SHAPER_FREQ_X`, `DAMPING_RATIO_X`.
//!   The suggested `max_accel` is rounded as `calibrate_shaper` prints it:
//!   `round(max_accel / 100) * 100` (klippy/extras/shaper_calibrate.py, `find_best_shaper`;
//!   Python's `round`, ties to even).
//! - **Kalico** (KalicoCrew/kalico, klippy/extras/input_shaper.py, `CustomInputShaperParams`;
//!   the same format in dmbutyugin/klipper's branch, `parse_custom_shaper`): the Klipper types,
//!   and `shaper_type_<axis>: custom` with `shaper_a_<axis>` and `shaper_t_<axis>`
//!   comma-separated lists of equal length (`SHAPER_A_X=`, `SHAPER_T_X=` in the command).
//! - **RepRapFirmware 3.6** (src/Movement/AxisShaper.cpp, `AxisShaper::Configure`, and
//!   AxisShaper.h): one shaper for all axes; `M593 P"<type>" F<Hz> S<ζ>` with types `mzv`,
//!   `zvd`, `zvdd`, `zvddd`, `ei2`, `ei3` (no `zv`, no 3-impulse `ei`), or `P"custom"` with `H`
//!   (amplitudes but the last) and `T` (delays but the first) — [`super::to_rrf_m593`].
//! - **Marlin** (MarlinFirmware/Marlin, Marlin/src/gcode/feature/input_shaping/M593.cpp,
//!   `GcodeSuite::M593`; MarlinDocumentation _gcode/M593.md): ZV only, per axis
//!   `M593 X F<Hz> D<ζ>`, ζ in [0, 1], F > 0 (0 disables). What a ZV-only firmware loses
//!   against the recommended shaper is written as comment lines.

use super::gcode_number;
use crate::design::zero_vibration::zv;
use crate::error::{finite, Error, Result};
use crate::mode::{Mode, ModeSpec};
use crate::shaper::{Impulse, Shaper};
use crate::smoothing;
use crate::vibration::{insensitivity, residual_vibration};
use serde::{Deserialize, Serialize};
use std::fmt::Write;

/// Klipper's default damping ratio (klippy/extras/shaper_defs.py, `DEFAULT_DAMPING_RATIO`).
pub const KLIPPER_DEFAULT_DAMPING: f64 = 0.1;
pub use crate::firmware_limits::{
    KALICO_MAX_DURATION_S, KALICO_MAX_IMPULSES, KALICO_MIN_ABS_AMPLITUDE, KALICO_MIN_AMPLITUDE_SUM,
    KALICO_MIN_DURATION_S, RRF_MAX_DAMPING, RRF_MAX_FREQUENCY_HZ, RRF_MAX_IMPULSES,
    RRF_MIN_FREQUENCY_HZ,
};
/// Marlin sizes its shaping buffer for `SHAPING_MIN_FREQ`, by default the lower of the built-in
/// `SHAPING_FREQ_X`/`_Y`, 40 Hz in the shipped Configuration_adv.h; below it shaping loses
/// effect at speed (Configuration_adv.h comments). A warning, not an error: builds differ.
pub const MARLIN_DEFAULT_MIN_FREQ_HZ: f64 = 40.0;
/// Tolerable vibration for the bands reported to Marlin users (5 %, Klipper's and Singhose's).
const BAND_VTOL: f64 = 0.05;

/// The firmware (and form) of [`firmware_config`]; JS names in camelCase.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum Firmware {
    /// Klipper's `[input_shaper]` block ([`klipper_config`]).
    Klipper,
    /// Klipper's `SET_INPUT_SHAPER` command ([`klipper_command`]).
    KlipperCommand,
    /// Kalico's `[input_shaper]` block, custom shapers included ([`kalico_config`]).
    Kalico,
    /// Kalico's `SET_INPUT_SHAPER` command ([`kalico_command`]).
    KalicoCommand,
    /// RepRapFirmware 3.6 `M593` ([`rrf_config`]).
    Rrf,
    /// Marlin's ZV `M593` ([`marlin_config`]).
    Marlin,
}

/// One axis's shaper (JS: `{ axis, family, frequencyHz, damping, impulses, maxAccel, modes }`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct AxisShaper {
    /// `x` or `y` (Marlin also `z`), case-insensitive.
    pub axis: String,
    /// Klipper's type name (`zv`, `mzv`, `zvd`, `ei`, `2hump_ei`, `3hump_ei`), RRF's extra
    /// `zvdd`, `zvddd`, or `custom` (the `impulses` as they are).
    pub family: String,
    /// The shaper's frequency, Hz (required for a named family and for Marlin).
    #[serde(default)]
    pub frequency_hz: Option<f64>,
    /// The shaper's damping ratio (default 0.1, Klipper's).
    #[serde(default = "default_damping")]
    pub damping: f64,
    /// The shaper's impulses: required for `custom`; for a named family, used for the suggested
    /// `max_accel` and Marlin's comparison.
    #[serde(default)]
    pub impulses: Option<Vec<Impulse>>,
    /// Suggested max acceleration, mm/s² (default: Klipper's, from `impulses` at scv 5 mm/s).
    #[serde(default)]
    pub max_accel: Option<f64>,
    /// The axis's modes, for Marlin's comparison of ZV with the recommendation.
    #[serde(default)]
    pub modes: Vec<ModeSpec>,
}

fn default_damping() -> f64 {
    KLIPPER_DEFAULT_DAMPING
}

impl AxisShaper {
    /// A named family at a frequency and damping, nothing else.
    pub fn named(axis: &str, family: &str, frequency_hz: f64, damping: f64) -> Self {
        AxisShaper {
            axis: axis.into(),
            family: family.into(),
            frequency_hz: Some(frequency_hz),
            damping,
            impulses: None,
            max_accel: None,
            modes: Vec::new(),
        }
    }

    /// A `custom` shaper of the given impulses.
    pub fn custom(axis: &str, shaper: &Shaper) -> Self {
        AxisShaper {
            axis: axis.into(),
            family: "custom".into(),
            frequency_hz: None,
            damping: KLIPPER_DEFAULT_DAMPING,
            impulses: Some(shaper.impulses().to_vec()),
            max_accel: None,
            modes: Vec::new(),
        }
    }
}

/// The text to paste and what the user should know about it (JS: `{ text, warnings }`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FirmwareConfig {
    /// Config or G-code text, newline-terminated lines.
    pub text: String,
    /// Caveats (a family replaced by ZV, a damping beyond the family's fitted range, …).
    pub warnings: Vec<String>,
}

/// A named family: its Klipper name, whether Klipper has it, its RRF name, the largest damping
/// ratio Klipper's calibration uses it at (shaper_defs.py, `INPUT_SHAPERS.max_damping_ratio`;
/// beyond it the fitted EI expansions are extrapolated), and its Marlin FT_MOTION mode
/// (MarlinDocumentation _gcode/M493.md, `S`).
struct Family {
    name: &'static str,
    klipper: bool,
    rrf: Option<&'static str>,
    max_damping: f64,
    ft_motion: Option<u8>,
}

const FAMILIES: [Family; 8] = [
    Family {
        name: "zv",
        klipper: true,
        rrf: None,
        max_damping: 0.99,
        ft_motion: Some(10),
    },
    Family {
        name: "mzv",
        klipper: true,
        rrf: Some("mzv"),
        max_damping: 0.99,
        ft_motion: Some(15),
    },
    Family {
        name: "zvd",
        klipper: true,
        rrf: Some("zvd"),
        max_damping: 0.99,
        ft_motion: Some(11),
    },
    Family {
        name: "zvdd",
        klipper: false,
        rrf: Some("zvdd"),
        max_damping: 0.99,
        ft_motion: None,
    },
    Family {
        name: "zvddd",
        klipper: false,
        rrf: Some("zvddd"),
        max_damping: 0.99,
        ft_motion: None,
    },
    Family {
        name: "ei",
        klipper: true,
        rrf: None,
        max_damping: 0.4,
        ft_motion: Some(12),
    },
    Family {
        name: "2hump_ei",
        klipper: true,
        rrf: Some("ei2"),
        max_damping: 0.3,
        ft_motion: Some(13),
    },
    Family {
        name: "3hump_ei",
        klipper: true,
        rrf: Some("ei3"),
        max_damping: 0.2,
        ft_motion: Some(14),
    },
];

const KLIPPER_TYPES: &str = "zv, mzv, zvd, ei, 2hump_ei, 3hump_ei";
const RRF_TYPES: &str = "mzv, zvd, zvdd, zvddd, ei2 (2hump_ei), ei3 (3hump_ei), custom";

/// An axis after validation.
struct Axis {
    name: String,
    /// `None` for `custom`.
    family: Option<&'static Family>,
    frequency: Option<f64>,
    damping: f64,
    shaper: Option<Shaper>,
    max_accel: Option<f64>,
    modes: Vec<Mode>,
}

impl Axis {
    fn family_name(&self) -> &'static str {
        self.family.map_or("custom", |f| f.name)
    }

    /// The frequency, which a named family always has after [`check`].
    fn freq(&self, field: &str, firmware: &str) -> Result<f64> {
        self.frequency.ok_or_else(|| {
            Error::invalid(
                format!("{field}.frequencyHz"),
                format!("{firmware} needs the shaper's frequency"),
            )
        })
    }

    /// The custom shaper's impulses, required for `custom`.
    fn custom_shaper(&self, field: &str) -> Result<&Shaper> {
        self.shaper.as_ref().ok_or_else(|| {
            Error::invalid(
                format!("{field}.impulses"),
                "a custom shaper needs its impulses",
            )
        })
    }

    /// The suggested max acceleration: given, or Klipper's from the impulses.
    fn suggested_max_accel(&self) -> Option<f64> {
        self.max_accel.or_else(|| {
            let s = self.shaper.as_ref()?;
            smoothing::max_accel(s, smoothing::KLIPPER_SCV)
                .ok()
                .filter(|a| a.is_finite())
        })
    }
}

/// The named family of `a` (`None` for `custom`), or an error naming `field.family`.
fn family_of(a: &AxisShaper, field: &str) -> Result<Option<&'static Family>> {
    let family_name = a.family.to_ascii_lowercase();
    if family_name == "custom" {
        return Ok(None);
    }
    FAMILIES
        .iter()
        .find(|f| f.name == family_name)
        .map(Some)
        .ok_or_else(|| {
            Error::invalid(
                format!("{field}.family"),
                format!(
                    "unknown shaper family {:?}; expected {KLIPPER_TYPES}, zvdd, zvddd or custom",
                    a.family
                ),
            )
        })
}

/// The frequency of `a`: finite and > 0 when given, required for a named family.
fn frequency_of(a: &AxisShaper, family: Option<&Family>, field: &str) -> Result<Option<f64>> {
    match (a.frequency_hz, family) {
        (Some(f), _) => {
            finite(&format!("{field}.frequencyHz"), f)?;
            if f <= 0.0 {
                return Err(Error::invalid(
                    format!("{field}.frequencyHz"),
                    format!("must be greater than 0 Hz (0 turns shaping off), got {f}"),
                ));
            }
            Ok(Some(f))
        }
        (None, Some(fam)) => Err(Error::invalid(
            format!("{field}.frequencyHz"),
            format!("the {} shaper needs its frequency", fam.name),
        )),
        (None, None) => Ok(None),
    }
}

/// Validates the axes; `allowed` are the firmware's axis names.
fn check(axes: &[AxisShaper], allowed: &[&str], firmware: &str) -> Result<Vec<Axis>> {
    if axes.is_empty() {
        return Err(Error::invalid("axes", "give at least one axis"));
    }
    let mut out: Vec<Axis> = Vec::with_capacity(axes.len());
    for (i, a) in axes.iter().enumerate() {
        let field = format!("axes[{i}]");
        let name = a.axis.to_ascii_lowercase();
        if !allowed.contains(&name.as_str()) {
            return Err(Error::invalid(
                format!("{field}.axis"),
                format!(
                    "{firmware} shapes axes {} only, got {:?}",
                    allowed.join(", "),
                    a.axis
                ),
            ));
        }
        if out.iter().any(|o| o.name == name) {
            return Err(Error::invalid(
                format!("{field}.axis"),
                format!("axis {name} is given twice"),
            ));
        }
        let family = family_of(a, &field)?;
        let frequency = frequency_of(a, family, &field)?;
        finite(&format!("{field}.damping"), a.damping)?;
        if !(0.0..1.0).contains(&a.damping) {
            return Err(Error::invalid(
                format!("{field}.damping"),
                format!("must lie in [0, 1), got {}", a.damping),
            ));
        }
        let shaper = match &a.impulses {
            Some(imps) => Some(Shaper::new(imps.clone()).map_err(|e| e.within(&field))?),
            None => None,
        };
        if let Some(m) = a.max_accel {
            finite(&format!("{field}.maxAccel"), m)?;
            if m < 0.0 {
                return Err(Error::invalid(
                    format!("{field}.maxAccel"),
                    format!("must be at least 0 mm/s², got {m}"),
                ));
            }
        }
        let modes = a
            .modes
            .iter()
            .enumerate()
            .map(|(k, m)| {
                Mode::new(m.frequency_hz, m.damping)
                    .map_err(|e| e.within(&format!("{field}.modes[{k}]")))
            })
            .collect::<Result<Vec<_>>>()?;
        out.push(Axis {
            name,
            family,
            frequency,
            damping: a.damping,
            shaper,
            max_accel: a.max_accel,
            modes,
        });
    }
    Ok(out)
}

/// `x` with at most `decimals` decimals, trailing zeros trimmed, and the value it reads back as.
fn fixed(x: f64, decimals: usize) -> (String, f64) {
    let s = format!("{x:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    let back = s.parse().unwrap_or(f64::NAN);
    (if s == "-0" { "0".into() } else { s }, back)
}

/// Frequency as Klipper reports it (`%.3f`, input_shaper.py `get_status`), checked > 0.
fn klipper_freq(f: f64, field: &str) -> Result<String> {
    let (s, back) = fixed(f, 3);
    if back > 0.0 {
        Ok(s)
    } else {
        Err(Error::invalid(
            format!("{field}.frequencyHz"),
            format!("{f} Hz is written as {s}, which turns shaping off"),
        ))
    }
}

/// Damping as Klipper reports it (`%.6f`).
fn klipper_damping(z: f64) -> String {
    fixed(z, 6).0
}

/// Klipper's rounding of the suggested max_accel (`round(max_accel / 100.) * 100.`).
pub fn klipper_rounded_max_accel(max_accel: f64) -> f64 {
    (max_accel / 100.0).round_ties_even() * 100.0
}

/// Warns when ζ exceeds the family's fitted range.
fn damping_warning(axis: &Axis, warnings: &mut Vec<String>) {
    if let Some(f) = axis.family {
        if axis.damping > f.max_damping {
            warnings.push(format!(
                "{}: damping {} is above {}, the largest Klipper's calibration uses {} at \
                 (shaper_defs.py)",
                axis.name, axis.damping, f.max_damping, f.name
            ));
        }
    }
}

/// The custom amplitudes and times as Kalico will read them, checked against its limits.
fn kalico_lists(shaper: &Shaper, field: &str) -> Result<(String, String)> {
    let imps = shaper.impulses();
    let lim = |what: &str, reason: String| -> Result<(String, String)> {
        Err(Error::invalid(
            format!("{field}.impulses{what}"),
            format!(
                "Kalico's custom shaper {reason} (klippy/extras/input_shaper.py, kin_shaper.c)"
            ),
        ))
    };
    if imps.len() > KALICO_MAX_IMPULSES {
        return lim(
            "",
            format!(
                "takes at most {KALICO_MAX_IMPULSES} impulses, this one has {}",
                imps.len()
            ),
        );
    }
    let a: Vec<String> = imps.iter().map(|i| gcode_number(i.amplitude)).collect();
    let t: Vec<String> = imps.iter().map(|i| gcode_number(i.time)).collect();
    let back =
        |v: &[String]| -> Vec<f64> { v.iter().map(|s| s.parse().unwrap_or(f64::NAN)).collect() };
    let (av, tv) = (back(&a), back(&t));
    if let Some(k) = av.iter().position(|x| x.abs() < KALICO_MIN_ABS_AMPLITUDE) {
        return lim(
            &format!("[{k}].amplitude"),
            format!(
                "takes amplitudes of magnitude ≥ {KALICO_MIN_ABS_AMPLITUDE}, got {}",
                a[k]
            ),
        );
    }
    let sum: f64 = av.iter().sum();
    if sum < KALICO_MIN_AMPLITUDE_SUM {
        return lim(
            "",
            format!("needs amplitudes summing to ≥ {KALICO_MIN_AMPLITUDE_SUM}, got {sum}"),
        );
    }
    if let Some(k) = tv.windows(2).position(|w| w[1] < w[0]) {
        return lim(
            &format!("[{}].time", k + 1),
            "needs increasing times".into(),
        );
    }
    let dur = tv[tv.len() - 1] - tv[0];
    if tv.len() > 1 && dur < KALICO_MIN_DURATION_S {
        return lim(
            "",
            format!("lasts at least {KALICO_MIN_DURATION_S} s, this one {dur} s"),
        );
    }
    if dur > KALICO_MAX_DURATION_S {
        return lim(
            "",
            format!("lasts at most {KALICO_MAX_DURATION_S} s, this one {dur} s"),
        );
    }
    Ok((a.join(", "), t.join(", ")))
}

/// The `[input_shaper]` block for Klipper or (`kalico`) Kalico.
fn block(axes: &[AxisShaper], kalico: bool) -> Result<FirmwareConfig> {
    let fw = if kalico { "Kalico" } else { "Klipper" };
    let checked = check(axes, &["x", "y"], fw)?;
    let mut text = String::from("[input_shaper]\n");
    let mut warnings = Vec::new();
    for (i, a) in checked.iter().enumerate() {
        let field = format!("axes[{i}]");
        let n = &a.name;
        match a.family {
            Some(f) if f.klipper => {
                let _ = writeln!(text, "shaper_type_{n}: {}", f.name);
                let _ = writeln!(
                    text,
                    "shaper_freq_{n}: {}",
                    klipper_freq(a.freq(&field, fw)?, &field)?
                );
                let _ = writeln!(text, "damping_ratio_{n}: {}", klipper_damping(a.damping));
                damping_warning(a, &mut warnings);
            }
            Some(f) => return Err(no_type(&field, fw, f.name)),
            None if kalico => {
                let (sa, st) = kalico_lists(a.custom_shaper(&field)?, &field)?;
                let _ = writeln!(text, "shaper_type_{n}: custom");
                let _ = writeln!(text, "shaper_a_{n}: {sa}");
                let _ = writeln!(text, "shaper_t_{n}: {st}");
            }
            None => return Err(no_custom(&field)),
        }
    }
    max_accel_comments(&checked, &mut text);
    Ok(FirmwareConfig { text, warnings })
}

fn no_type(field: &str, fw: &str, family: &str) -> Error {
    Error::invalid(
        format!("{field}.family"),
        format!(
            "{fw} has no {family} shaper (its types: {KLIPPER_TYPES}; shaper_defs.py \
             INPUT_SHAPERS); send it as family custom with its impulses to Kalico"
        ),
    )
}

fn no_custom(field: &str) -> Error {
    Error::invalid(
        format!("{field}.family"),
        format!(
            "mainline Klipper has no custom shaper type (its types: {KLIPPER_TYPES}); use \
             firmware kalico"
        ),
    )
}

/// `# max_accel` comments, rounded as `calibrate_shaper` prints them, and the lower of the axes.
fn max_accel_comments(axes: &[Axis], text: &mut String) {
    let mut lowest: Option<f64> = None;
    for a in axes {
        if let Some(m) = a.suggested_max_accel() {
            let r = klipper_rounded_max_accel(m);
            let _ = writeln!(
                text,
                "# {}: {} suggests max_accel <= {r} mm/sec^2 (0.12 mm smoothing)",
                a.name,
                a.family_name()
            );
            lowest = Some(lowest.map_or(r, |l: f64| l.min(r)));
        }
    }
    if let Some(l) = lowest {
        let _ = writeln!(text, "# in [printer]: max_accel: {l}");
    }
}

/// The `SET_INPUT_SHAPER` parameters of the axes.
fn command(axes: &[AxisShaper], kalico: bool) -> Result<FirmwareConfig> {
    let fw = if kalico { "Kalico" } else { "Klipper" };
    let checked = check(axes, &["x", "y"], fw)?;
    let mut text = String::from("SET_INPUT_SHAPER");
    let mut warnings = Vec::new();
    for (i, a) in checked.iter().enumerate() {
        let field = format!("axes[{i}]");
        let n = a.name.to_ascii_uppercase();
        match a.family {
            Some(f) if f.klipper => {
                let freq = klipper_freq(a.freq(&field, fw)?, &field)?;
                let _ = write!(
                    text,
                    " SHAPER_TYPE_{n}={} SHAPER_FREQ_{n}={freq} DAMPING_RATIO_{n}={}",
                    f.name,
                    klipper_damping(a.damping)
                );
                damping_warning(a, &mut warnings);
            }
            Some(f) => return Err(no_type(&field, fw, f.name)),
            None if kalico => {
                let (sa, st) = kalico_lists(a.custom_shaper(&field)?, &field)?;
                let _ = write!(
                    text,
                    " SHAPER_TYPE_{n}=custom SHAPER_A_{n}={} SHAPER_T_{n}={}",
                    sa.replace(' ', ""),
                    st.replace(' ', "")
                );
            }
            None => return Err(no_custom(&field)),
        }
    }
    text.push('\n');
    Ok(FirmwareConfig { text, warnings })
}

/// Klipper's `[input_shaper]` block for axes x and y, with the suggested `max_accel` as
/// comments (`calibrate_shaper`'s rounding) when known.
pub fn klipper_config(axes: &[AxisShaper]) -> Result<FirmwareConfig> {
    block(axes, false)
}

/// Klipper's `SET_INPUT_SHAPER` command for axes x and y, on one line.
pub fn klipper_command(axes: &[AxisShaper]) -> Result<FirmwareConfig> {
    command(axes, false)
}

/// Kalico's `[input_shaper]` block: Klipper's types, or `custom` with `shaper_a_<axis>` and
/// `shaper_t_<axis>` within Kalico's limits (the `KALICO_*` constants).
pub fn kalico_config(axes: &[AxisShaper]) -> Result<FirmwareConfig> {
    block(axes, true)
}

/// Kalico's `SET_INPUT_SHAPER` command (custom: `SHAPER_A_X=…,… SHAPER_T_X=…,…`).
pub fn kalico_command(axes: &[AxisShaper]) -> Result<FirmwareConfig> {
    command(axes, true)
}

/// RepRapFirmware 3.6's `M593`. RRF runs one shaper for all axes (M593 has no axis
/// parameter), so every axis given must have the same shaper. A named family is written
/// `M593 P"<type>" F<Hz> S<ζ>` with F in [[`RRF_MIN_FREQUENCY_HZ`], [`RRF_MAX_FREQUENCY_HZ`]]
/// and S ≤ 0.99; `custom` as [`super::to_rrf_m593`] (at most [`RRF_MAX_IMPULSES`] impulses).
///
/// RRF times `ei2`/`ei3` by the damped period 1/(F√(1 − ζ²)) where Klipper's `2hump_ei` and
/// `3hump_ei` use the undamped 1/f (shaper_defs.py, `_get_shaper_from_expansion_coeffs`;
/// AxisShaper.cpp, `case InputShaperType::ei2`): F = f/√(1 − ζ²) runs Klipper's shaper at f,
/// and is what is written (with a comment saying so).
pub fn rrf_config(axes: &[AxisShaper]) -> Result<FirmwareConfig> {
    let checked = check(axes, &["x", "y", "z"], "RepRapFirmware")?;
    let first = &axes[0];
    if let Some(i) = axes.iter().position(|a| {
        !a.family.eq_ignore_ascii_case(&first.family)
            || a.frequency_hz != first.frequency_hz
            || a.damping != first.damping
            || a.impulses != first.impulses
    }) {
        return Err(Error::invalid(
            format!("axes[{i}]"),
            "RepRapFirmware runs one input shaper for all axes (M593 has no axis parameter); \
             these axes differ: choose one shaper",
        ));
    }
    let a = &checked[0];
    let field = "axes[0]";
    let mut text = String::new();
    match a.family {
        None => {
            let shaper = a.custom_shaper(field)?;
            text = super::to_rrf_m593(shaper).map_err(|e| e.within(field))?;
            text.push('\n');
        }
        Some(f) => {
            let rrf = f.rrf.ok_or_else(|| {
                Error::invalid(
                    format!("{field}.family"),
                    format!(
                        "RepRapFirmware has no {} shaper (its types: {RRF_TYPES}); send it as \
                         family custom with its impulses",
                        f.name
                    ),
                )
            })?;
            let z = a.damping;
            if z > RRF_MAX_DAMPING {
                return Err(Error::invalid(
                    format!("{field}.damping"),
                    format!("RepRapFirmware takes S in [0, {RRF_MAX_DAMPING}], got {z}"),
                ));
            }
            let mut f_hz = a.freq(field, "RepRapFirmware")?;
            let ei = f.name.ends_with("hump_ei");
            if ei {
                f_hz /= (1.0 - z * z).sqrt();
            }
            let (fs, back) = fixed(f_hz, 3);
            if !(RRF_MIN_FREQUENCY_HZ..=RRF_MAX_FREQUENCY_HZ).contains(&back) {
                return Err(Error::invalid(
                    format!("{field}.frequencyHz"),
                    format!(
                        "RepRapFirmware takes F in [{RRF_MIN_FREQUENCY_HZ:.2}, \
                         {RRF_MAX_FREQUENCY_HZ}] Hz (AxisShaper.cpp), got {fs}"
                    ),
                ));
            }
            if ei {
                let _ = writeln!(
                    text,
                    "; {rrf} runs on the damped period: F = f/sqrt(1 - S^2) gives Klipper's {} at \
                     {} Hz",
                    f.name,
                    fixed(a.frequency.unwrap_or(0.0), 3).0
                );
            }
            let _ = writeln!(text, "M593 P\"{rrf}\" F{fs} S{}", fixed(z, 6).0);
        }
    }
    Ok(FirmwareConfig {
        text,
        warnings: Vec::new(),
    })
}

/// Percent with one decimal.
fn pct(v: f64) -> String {
    format!("{:.1} %", 100.0 * v)
}

/// Marlin's `M593 <axis> F<Hz> D<ζ>` per axis (x, y, z). Marlin's input shaper is ZV only: a
/// ZV at the axis's frequency and damping is written, and when the recommendation is another
/// family, comment lines say what ZV loses — the residual vibration of both at each mode given,
/// and the frequency band where each keeps it under 5 % (damping held) — and a warning says so.
pub fn marlin_config(axes: &[AxisShaper]) -> Result<FirmwareConfig> {
    let checked = check(axes, &["x", "y", "z"], "Marlin")?;
    let mut text = String::new();
    let mut warnings = Vec::new();
    for (i, a) in checked.iter().enumerate() {
        let field = format!("axes[{i}]");
        let f = a.freq(&field, "Marlin's M593 (a ZV frequency)")?;
        let (fs, back) = fixed(f, 3);
        if back <= 0.0 {
            return Err(Error::invalid(
                format!("{field}.frequencyHz"),
                format!("{f} Hz is written as F{fs}, which turns Marlin's shaping off"),
            ));
        }
        let design = Mode::new(back, a.damping).map_err(|e| e.within(&field))?;
        let zv_shaper = zv(&design).map_err(|e| e.within(&field))?;
        let name = a.family_name();
        let n = &a.name;
        if name != "zv" {
            warnings.push(format!(
                "{n}: Marlin's M593 runs ZV only; {name} was recommended"
            ));
            let _ = writeln!(
                text,
                "; {n}: Marlin runs ZV only; the recommendation is {name}"
            );
            for m in &a.modes {
                let vz = residual_vibration(&zv_shaper, m);
                let _ = write!(
                    text,
                    "; {n}: at the mode {} Hz (damping {}) ZV leaves {}",
                    fixed(m.frequency_hz(), 2).0,
                    fixed(m.damping(), 3).0,
                    pct(vz)
                );
                if let Some(s) = &a.shaper {
                    let _ = write!(text, ", {name} {}", pct(residual_vibration(s, m)));
                }
                text.push('\n');
            }
            let band = |s: &Shaper| {
                insensitivity(s, &design, BAND_VTOL)
                    .ok()
                    .filter(|b| b.width > 0.0)
                    .map(|b| format!("{}-{} Hz", fixed(b.low_hz, 1).0, fixed(b.high_hz, 1).0))
            };
            if let Some(bz) = band(&zv_shaper) {
                let _ = write!(
                    text,
                    "; {n}: vibration <= 5 % at damping {}: ZV over {bz}",
                    fixed(a.damping, 3).0
                );
                if let Some(br) = a.shaper.as_ref().and_then(band) {
                    let _ = write!(text, ", {name} over {br}");
                }
                text.push('\n');
            }
            if let Some(s) = a.family.and_then(|f| f.ft_motion) {
                let _ = writeln!(
                    text,
                    "; {n}: Marlin builds with FT_MOTION have {name} as M493 S{s} (experimental; \
                     not checked here)"
                );
            }
        }
        if back < MARLIN_DEFAULT_MIN_FREQ_HZ {
            warnings.push(format!(
                "{n}: {fs} Hz is below Marlin's default SHAPING_MIN_FREQ ({MARLIN_DEFAULT_MIN_FREQ_HZ} \
                 Hz unless the build sets it lower); shaping loses effect at speed"
            ));
        }
        let _ = writeln!(
            text,
            "M593 {} F{fs} D{}",
            n.to_ascii_uppercase(),
            fixed(a.damping, 6).0
        );
    }
    Ok(FirmwareConfig { text, warnings })
}

/// The config of `firmware` for `axes`.
pub fn firmware_config(firmware: Firmware, axes: &[AxisShaper]) -> Result<FirmwareConfig> {
    match firmware {
        Firmware::Klipper => klipper_config(axes),
        Firmware::KlipperCommand => klipper_command(axes),
        Firmware::Kalico => kalico_config(axes),
        Firmware::KalicoCommand => kalico_command(axes),
        Firmware::Rrf => rrf_config(axes),
        Firmware::Marlin => marlin_config(axes),
    }
}
