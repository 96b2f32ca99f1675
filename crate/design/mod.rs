//! Shaper design: the spec a user writes, the table of families, and [`design`].
//!
//! A spec is a JSON-like object `{ family, modes: [{ frequencyHz, damping }], …parameters }`.
//! Each family lives in its own file and reads like the paper it comes from; adding one is a
//! function there, a variant of [`ShaperSpec`] with its name in [`ShaperSpec::name`] and its arm
//! in the dispatch below (both exhaustive matches: the compiler points at them), and a row in
//! [`FAMILIES`] (`family.rs`) with its parameters' labels, limits and defaults, from which the
//! JavaScript `families()`, the page's editors and `docs/families.md` are made.
//! `tests/families.rs` checks that every row parses to its variant and designs from its
//! defaults.
//!
//! For several modes, single-mode families are designed per mode and convolved
//! (Singer & Seering 1988 §2.3). Every design is checked against its guarantee with an
//! independent evaluation of V before it is returned.

pub mod direct;
pub mod quantize;
pub mod sampled;
mod solved;
pub mod specified;
pub mod zero_vibration;

pub mod custom;
pub(crate) mod equations;
pub mod extra_insensitive;
mod family;
pub mod modified;
pub mod negative;

use crate::error::{Error, Result};
use crate::mode::{Mode, ModeSpec};
use crate::shaper::Shaper;
use crate::solve::SolverReport;
use serde::{Deserialize, Serialize};

pub use family::{FamilyInfo, ParamDefault, ParamInfo, ParamKind, Solver, FAMILIES};

crate::tagged::tagged_enum! {
    tag = "family", rename_all = "lowercase", mirror = shaper_spec_serde;
    /// A family of shapers and its parameters (the `family` field selects the variant).
    #[derive(Debug, Clone, PartialEq)]
    pub enum ShaperSpec {
        /// Zero vibration: 2 impulses, ½ damped period (Singhose 2009 eqs. 14–15).
        Zv,
        /// Zero vibration and derivative: 3 impulses, 1 period (Singhose 2009 eq. 17).
        Zvd,
        /// Zero vibration and two derivatives: 4 impulses, 1½ periods (Singer & Seering 1988).
        Zvdd,
        /// Zero vibration and `derivatives` derivatives: n + 2 impulses, (n+1)/2 periods.
        Zvdn {
            /// Number of zero derivatives n (0 = ZV, 1 = ZVD, …), at most
            /// [`zero_vibration::MAX_DERIVATIVES`].
            derivatives: u32,
        },
        /// Impulses on the controller period with a prescribed ramp delay and the least control
        /// error (Kamel, Lange & Hirzinger); parameters in [`sampled::SampledSpec`].
        Sampled(sampled::SampledSpec),
        /// Extra-insensitive: V = `vtol` with zero slope at the mode (a hump), zeros either side;
        /// 3 impulses, about 1 period (Singhose 2009 §3.1, Fig. 7), solved exactly with damping.
        Ei {
            /// Height of the hump, fraction (default 0.05 = 5 %), 0.001 … 0.5.
            #[serde(default = "default_vtol")]
            vtol: f64,
        },
        /// Two-hump EI: humps of height `vtol` either side of the mode, V = 0 at the mode;
        /// 4 impulses, about 1½ periods.
        Ei2 {
            /// Height of the humps, fraction (default 0.05).
            #[serde(default = "default_vtol")]
            vtol: f64,
        },
        /// Three-hump EI: the middle hump at the mode; 5 impulses, about 2 periods.
        Ei3 {
            /// Height of the humps, fraction (default 0.05).
            #[serde(default = "default_vtol")]
            vtol: f64,
        },
        /// n-hump EI: `humps` humps of height `vtol`, n + 2 impulses, about (n+1)/2 periods.
        Eihump {
            /// Number of humps n, 1 … [`extra_insensitive::MAX_HUMPS`] (1 = EI).
            humps: u32,
            /// Height of the humps, fraction (default 0.05).
            #[serde(default = "default_vtol")]
            vtol: f64,
        },
        /// Klipper's modified ZV: 3 impulses over 0.75 damped period, V = 0 at the mode and near
        /// 5/3 of it (Klipper shaper_defs.py).
        Mzv,
        /// Unity-magnitude ZV: [1, −1, 1], V = 0 at the mode; T/3 long at ζ = 0
        /// (Singhose 2009 §5).
        Umzv,
        /// Unity-magnitude ZVD: [1, −1, 1, −1, 1], V = 0 and dV/dω = 0 at the mode.
        Umzvd,
        /// Unity-magnitude EI: [1, −1, 1, −1, 1], a hump V = `vtol` at the mode.
        Umei {
            /// Height of the hump, fraction (default 0.05).
            #[serde(default = "default_vtol")]
            vtol: f64,
        },
        /// Time-optimal rest-to-rest move of one flexible mode plus rigid body: [1, −2, 2, −2, 1],
        /// amplitudes sum to 0 — convolve with a step of height `maxAcceleration` (Singhose 2009
        /// Fig. 13).
        #[serde(rename_all = "camelCase")]
        Bangbang {
            /// Move distance (any length unit).
            distance: f64,
            /// Actuator acceleration limit (same length unit per s²).
            max_acceleration: f64,
        },
        /// Fuel-efficient on/off move: [1, −1, 1, −1, −1, 1, −1, 1] with a coast (Singhose 2009
        /// Fig. 14); amplitudes sum to 0, applied like `bangbang`.
        #[serde(rename_all = "camelCase")]
        Onoff {
            /// Move distance (any length unit).
            distance: f64,
            /// Actuator acceleration limit (same length unit per s²).
            max_acceleration: f64,
            /// Time with the actuator off between accelerating and decelerating, s (> 0).
            coast_time: f64,
        },
        /// Your own impulses `[{ time, amplitude }]`, validated; the modes are not used.
        Custom {
            /// The impulses, any order (merged when at the same time, shifted to start at 0).
            impulses: Vec<crate::shaper::Impulse>,
            /// Divide the amplitudes by their sum (default false).
            #[serde(default)]
            normalize: bool,
        },
        /// Specified insensitivity: the shortest shaper with V ≤ Vtol over a band of frequencies
        /// (and dampings), sampled or guaranteed on the whole band (Singhose 2009 eq. 18).
        Si(specified::SiSpec),
        /// Several modes at once: the shortest shaper with zero vibration (and derivatives) at every
        /// mode, designed directly instead of by convolution (Singer & Seering 1988 §2.3).
        Direct(direct::DirectSpec),
    }
}

fn default_vtol() -> f64 {
    extra_insensitive::DEFAULT_VTOL
}

impl ShaperSpec {
    /// The `family` string of this spec (the key of its row in [`FAMILIES`]).
    pub fn name(&self) -> &'static str {
        match self {
            ShaperSpec::Zv => "zv",
            ShaperSpec::Zvd => "zvd",
            ShaperSpec::Zvdd => "zvdd",
            ShaperSpec::Zvdn { .. } => "zvdn",
            ShaperSpec::Sampled(_) => "sampled",
            ShaperSpec::Ei { .. } => "ei",
            ShaperSpec::Ei2 { .. } => "ei2",
            ShaperSpec::Ei3 { .. } => "ei3",
            ShaperSpec::Eihump { .. } => "eihump",
            ShaperSpec::Mzv => "mzv",
            ShaperSpec::Umzv => "umzv",
            ShaperSpec::Umzvd => "umzvd",
            ShaperSpec::Umei { .. } => "umei",
            ShaperSpec::Bangbang { .. } => "bangbang",
            ShaperSpec::Onoff { .. } => "onoff",
            ShaperSpec::Custom { .. } => "custom",
            ShaperSpec::Si(_) => "si",
            ShaperSpec::Direct(_) => "direct",
        }
    }

    /// The row of [`FAMILIES`] describing this spec's family.
    pub fn info(&self) -> Option<&'static FamilyInfo> {
        FAMILIES.iter().find(|f| f.name == self.name())
    }
}

/// A complete design request: the modes and the family with its parameters.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DesignRequest {
    /// The modes to suppress (at least one, none repeated).
    pub modes: Vec<ModeSpec>,
    /// The family and its parameters.
    #[serde(flatten)]
    pub shaper: ShaperSpec,
}

/// `{ modes, family, …parameters }`: from a JS object the modes and the spec are read from the
/// same object (`crate/tagged.rs`); from anything else through serde's `flatten`.
impl<'de> Deserialize<'de> for DesignRequest {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        #[derive(Deserialize)]
        struct Modes {
            modes: Vec<ModeSpec>,
        }
        #[derive(Deserialize)]
        struct DesignRequest {
            modes: Vec<ModeSpec>,
            #[serde(flatten)]
            shaper: ShaperSpec,
        }
        let (Modes { modes }, shaper) =
            crate::tagged::deserialize_flat(d, "struct DesignRequest", |d| {
                let DesignRequest { modes, shaper } = DesignRequest::deserialize(d)?;
                Ok((Modes { modes }, shaper))
            })?;
        Ok(Self { modes, shaper })
    }
}

/// What a designed shaper promises, checked by [`verify`] before it is returned.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Guarantee {
    /// V = 0 (to rounding) at every listed (frequency in Hz, damping ratio) point.
    ZeroAt(Vec<(f64, f64)>),
    /// Every one of these.
    All(Vec<Guarantee>),
    /// Amplitudes are acceleration steps of a rigid body that starts at rest: it ends at rest
    /// (Σ Aᵢ = 0, Σ Aᵢ(t_n − tᵢ) = 0) having travelled ½ Σ Aᵢ(t_n − tᵢ)² = `travel`
    /// (distance / maxAcceleration, s²).
    RestToRest {
        /// Distance over acceleration limit, s².
        travel: f64,
    },
    /// V = 0 at every mode (to rounding).
    ZeroAtModes,
    /// V ≤ `vtol` (to `tolerance`) at every listed (frequency in Hz, damping ratio) point.
    AtMost {
        /// Tolerable vibration, fraction.
        vtol: f64,
        /// Points where the bound must hold.
        points: Vec<(f64, f64)>,
        /// Allowed excess over `vtol` from rounding and solver tolerance.
        tolerance: f64,
    },
    /// Nothing beyond a valid impulse sequence (e.g. a user's custom shaper).
    Valid,
    /// V ≤ Vtol·(1 + `tolerance`) at every listed (frequency in Hz, damping ratio, Vtol) point
    /// (each point its own Vtol, for frequency-weighted designs).
    WithinTolerance {
        /// Points where the bound must hold.
        points: Vec<(f64, f64, f64)>,
        /// Allowed relative excess over each Vtol (rounding and solver tolerance).
        tolerance: f64,
    },
    /// V = 0 and its first `derivatives` frequency derivatives zero at every mode (the moments
    /// M₀ … M_n of [`crate::vibration::vibration_moment`], scaled by t_nᵏ, vanish).
    ZeroDerivativesAtModes {
        /// Number of zero derivatives.
        derivatives: u32,
    },
}

/// Largest V accepted as "zero" when checking a zero-vibration guarantee.
const ZERO_VIBRATION_TOLERANCE: f64 = 1e-9;

/// Designs the shaper a request asks for.
///
/// ```
/// use input_shaping::{design, DesignRequest, ModeSpec, ShaperSpec};
/// let request = DesignRequest {
///     modes: vec![ModeSpec { frequency_hz: 2.0, damping: 0.05 }],
///     shaper: ShaperSpec::Zvd,
/// };
/// let shaper = design(&request)?; // the ZVD shaper, checked against its guarantee
/// assert_eq!(shaper.len(), 3);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn design(request: &DesignRequest) -> Result<Shaper> {
    let modes = Mode::list(&request.modes)?;
    design_for(&request.shaper, &modes)
}

/// A designed shaper with how the optimisation solver reached it ([`design_report`]).
#[derive(Debug, Clone)]
pub struct Designed {
    /// The shaper, as [`design`] returns it.
    pub shaper: Shaper,
    /// For a family the solver designs (`si`, `direct`): whether its polish converged, its
    /// rounds and programs. `None` for the other families (closed forms, and `sampled`, whose
    /// own report is [`sampled::design_for_modes`]'s).
    pub solver: Option<SolverReport>,
}

/// [`design`] with the solver's report ([`Designed::solver`]): whether an `si` or `direct`
/// shaper was polished (exact, locally optimal) or is the grid solution (up to a grid step
/// longer, with the grid's many impulses).
///
/// ```
/// use input_shaping::design::{design_report, specified::SiSpec};
/// use input_shaping::{DesignRequest, ModeSpec, ShaperSpec};
/// let request = DesignRequest {
///     modes: vec![ModeSpec { frequency_hz: 2.0, damping: 0.05 }],
///     shaper: ShaperSpec::Si(SiSpec { insensitivity: Some(0.3), ..SiSpec::default() }),
/// };
/// let designed = design_report(&request)?;
/// assert!(designed.solver.is_some_and(|r| r.polished));
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn design_report(request: &DesignRequest) -> Result<Designed> {
    let modes = Mode::list(&request.modes)?;
    reported(&request.shaper, &modes, any_family)
}

/// Designs a shaper of family `spec` for already validated modes.
///
/// ```
/// use input_shaping::{design::design_for, vibration::residual_vibration, Mode, ShaperSpec};
/// // With several modes, the per-mode shapers convolved: V = 0 at each.
/// let modes = [Mode::new(2.0, 0.05)?, Mode::new(7.0, 0.02)?];
/// let shaper = design_for(&ShaperSpec::Zv, &modes)?;
/// assert_eq!(shaper.len(), 4);
/// assert!(modes.iter().all(|m| residual_vibration(&shaper, m) < 1e-12));
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn design_for(spec: &ShaperSpec, modes: &[Mode]) -> Result<Shaper> {
    checked(spec, modes, any_family)
}

/// [`design_for`] for the solved families only (`si`, `direct`, `sampled`), the ones the
/// optimisation solver designs: a module that calls this and not [`design_for`] leaves the
/// other families' code out (the page's design worker, Cargo feature `js-designer`). Another
/// family is refused at `family`.
///
/// ```
/// use input_shaping::design::{design_solved_for, direct::DirectSpec};
/// use input_shaping::{Mode, ShaperSpec};
/// let modes = [Mode::new(2.0, 0.05)?];
/// assert!(design_solved_for(&ShaperSpec::Direct(DirectSpec::default()), &modes).is_ok());
/// assert!(design_solved_for(&ShaperSpec::Zv, &modes).is_err()); // not a solved family
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn design_solved_for(spec: &ShaperSpec, modes: &[Mode]) -> Result<Shaper> {
    checked(spec, modes, solved_family)
}

/// [`design_solved_for`] with the solver's report, as [`design_report`] gives it.
pub fn design_solved_report(spec: &ShaperSpec, modes: &[Mode]) -> Result<Designed> {
    reported(spec, modes, solved_family)
}

/// A family's design for modes, with what it guarantees ([`any_family`], [`solved_family`]).
type Family = fn(&ShaperSpec, &[Mode]) -> Result<(Shaper, Guarantee)>;

/// The design of `family` for `modes` (at least one), with its guarantee verified.
fn checked(spec: &ShaperSpec, modes: &[Mode], family: Family) -> Result<Shaper> {
    if modes.is_empty() {
        return Err(Error::invalid("modes", "at least one mode is required"));
    }
    let (shaper, guarantee) = family(spec, modes)?;
    verify(&shaper, modes, &guarantee)?;
    Ok(shaper)
}

/// [`checked`] with the solver's report for `si` and `direct` (their designs are asked for
/// here, the others through `family`). A path of its own, so that the page's first module,
/// which designs through [`design_for`] and never reports, does not carry it.
fn reported(spec: &ShaperSpec, modes: &[Mode], family: Family) -> Result<Designed> {
    if modes.is_empty() {
        return Err(Error::invalid("modes", "at least one mode is required"));
    }
    let Some(solved) = reporting(spec, modes) else {
        return checked(spec, modes, family).map(|shaper| Designed {
            shaper,
            solver: None,
        });
    };
    let (shaper, guarantee, report) = solved?;
    verify(&shaper, modes, &guarantee)?;
    Ok(Designed {
        shaper,
        solver: Some(report),
    })
}

/// Any family's design and what it guarantees (the solved ones through [`solved_family`]).
fn any_family(spec: &ShaperSpec, modes: &[Mode]) -> Result<(Shaper, Guarantee)> {
    Ok(match spec {
        ShaperSpec::Zv => (per_mode(modes, zero_vibration::zv)?, Guarantee::ZeroAtModes),
        ShaperSpec::Zvd => (
            per_mode(modes, zero_vibration::zvd)?,
            Guarantee::ZeroAtModes,
        ),
        ShaperSpec::Zvdd => (
            per_mode(modes, zero_vibration::zvdd)?,
            Guarantee::ZeroAtModes,
        ),
        ShaperSpec::Zvdn { derivatives } => (
            // Checked here so the error names the spec's field, not a mode's.
            if *derivatives > zero_vibration::MAX_DERIVATIVES {
                return Err(Error::TooLarge {
                    field: "derivatives".into(),
                    value: f64::from(*derivatives),
                    limit: f64::from(zero_vibration::MAX_DERIVATIVES),
                });
            } else {
                per_mode(modes, |m| zero_vibration::zv_dn(m, *derivatives))?
            },
            Guarantee::ZeroAtModes,
        ),
        ShaperSpec::Sampled(_) | ShaperSpec::Si(_) | ShaperSpec::Direct(_) => {
            return solved_family(spec, modes)
        }
        ShaperSpec::Ei { vtol } => extra_insensitive::for_modes(modes, 1, *vtol)?,
        ShaperSpec::Ei2 { vtol } => extra_insensitive::for_modes(modes, 2, *vtol)?,
        ShaperSpec::Ei3 { vtol } => extra_insensitive::for_modes(modes, 3, *vtol)?,
        ShaperSpec::Eihump { humps, vtol } => extra_insensitive::for_modes(modes, *humps, *vtol)?,
        ShaperSpec::Mzv => (per_mode(modes, modified::mzv)?, Guarantee::ZeroAtModes),
        ShaperSpec::Umzv => (per_mode(modes, negative::um_zv)?, Guarantee::ZeroAtModes),
        ShaperSpec::Umzvd => (per_mode(modes, negative::um_zvd)?, Guarantee::ZeroAtModes),
        ShaperSpec::Umei { vtol } => negative::um_ei_for_modes(modes, *vtol)?,
        ShaperSpec::Bangbang {
            distance,
            max_acceleration,
        } => {
            let mode = negative::single_mode(modes, "bangbang")?;
            let shaper = negative::bang_bang(mode, *distance, *max_acceleration)
                .map_err(|e| within_mode(e, 0))?;
            (
                shaper,
                Guarantee::All(vec![
                    Guarantee::ZeroAtModes,
                    Guarantee::RestToRest {
                        travel: distance / max_acceleration,
                    },
                ]),
            )
        }
        ShaperSpec::Custom {
            impulses,
            normalize,
        } => (custom::custom(impulses, *normalize)?, Guarantee::Valid),
        ShaperSpec::Onoff {
            distance,
            max_acceleration,
            coast_time,
        } => {
            let mode = negative::single_mode(modes, "onoff")?;
            let shaper = negative::on_off(mode, *distance, *max_acceleration, *coast_time)
                .map_err(|e| within_mode(e, 0))?;
            (
                shaper,
                Guarantee::All(vec![
                    Guarantee::ZeroAtModes,
                    Guarantee::RestToRest {
                        travel: distance / max_acceleration,
                    },
                ]),
            )
        }
    })
}

/// The solved families' designs (`sampled`, `si`, `direct`) and what they guarantee; any other
/// family is refused at `family`.
fn solved_family(spec: &ShaperSpec, modes: &[Mode]) -> Result<(Shaper, Guarantee)> {
    if let Some(solved) = reporting(spec, modes) {
        return solved.map(|(shaper, guarantee, _)| (shaper, guarantee));
    }
    match spec {
        ShaperSpec::Sampled(spec) => Ok((
            sampled::design_for_modes(modes, spec)?.shaper,
            Guarantee::ZeroAtModes,
        )),
        other => Err(Error::invalid(
            "family",
            format!(
                "\"{}\" is not designed by the optimisation solver (only si, direct and sampled are)",
                other.name()
            ),
        )),
    }
}

/// The solved families whose design reports how the solver reached it (`si`, `direct`): their
/// design, guarantee and [`SolverReport`]; None for any other family.
fn reporting(
    spec: &ShaperSpec,
    modes: &[Mode],
) -> Option<Result<(Shaper, Guarantee, SolverReport)>> {
    match spec {
        ShaperSpec::Si(si) => Some(specified::si(si, modes)),
        ShaperSpec::Direct(d) => Some(direct::direct(d, modes)),
        _ => None,
    }
}

/// Prefixes an error about a mode's own field (`damping`, `frequencyHz`) from the design for
/// `modes[i]` with that path; errors about the spec's parameters keep their names.
fn within_mode(e: Error, i: usize) -> Error {
    match e.field() {
        Some("damping" | "frequencyHz") => e.within(&format!("modes[{i}]")),
        _ => e,
    }
}

/// Designs a single-mode shaper for each mode and convolves them.
fn per_mode(modes: &[Mode], single: impl Fn(&Mode) -> Result<Shaper>) -> Result<Shaper> {
    let mut shaper = Shaper::identity();
    for (i, mode) in modes.iter().enumerate() {
        let s = single(mode).map_err(|e| e.within(&format!("modes[{i}]")))?;
        shaper = shaper.convolve(&s)?;
    }
    Ok(shaper)
}

/// Evaluates the shaper independently of how it was designed and refuses to return one that
/// breaks its promise.
pub(crate) fn verify(shaper: &Shaper, modes: &[Mode], guarantee: &Guarantee) -> Result<()> {
    match guarantee {
        Guarantee::Valid => Ok(()),
        Guarantee::All(all) => all.iter().try_for_each(|g| verify(shaper, modes, g)),
        Guarantee::RestToRest { travel } => verify_rest_to_rest(shaper, *travel),
        Guarantee::ZeroAt(points) => points
            .iter()
            .try_for_each(|&(f, z)| verify_zero_at(shaper, f, z)),
        Guarantee::AtMost {
            vtol,
            points,
            tolerance,
        } => points
            .iter()
            .try_for_each(|&(f, z)| verify_at_most(shaper, f, z, *vtol, vtol + tolerance)),
        Guarantee::WithinTolerance { points, tolerance } => {
            points.iter().try_for_each(|&(f, z, vtol)| {
                verify_at_most(shaper, f, z, vtol, vtol * (1.0 + tolerance))
            })
        }
        Guarantee::ZeroDerivativesAtModes { derivatives } => {
            verify_zero_moments(shaper, modes, *derivatives)
        }
        Guarantee::ZeroAtModes => verify_zero_at_modes(shaper, modes),
    }
}

/// V at (`f` Hz, ζ = `z`), from the impulses themselves.
fn vibration_at(shaper: &Shaper, f: f64, z: f64) -> f64 {
    crate::vibration::vibration_rad(shaper.impulses(), 2.0 * std::f64::consts::PI * f, z)
}

/// A move that ends at rest (Σ A = 0, final velocity 0) having travelled `travel`.
fn verify_rest_to_rest(shaper: &Shaper, travel: f64) -> Result<()> {
    let imps = shaper.impulses();
    let t_n = shaper.duration();
    let total: f64 = imps.iter().map(|i| i.amplitude.abs()).sum();
    let sum: f64 = imps.iter().map(|i| i.amplitude).sum();
    let velocity: f64 = imps.iter().map(|i| i.amplitude * (t_n - i.time)).sum();
    let position: f64 = imps
        .iter()
        .map(|i| 0.5 * i.amplitude * (t_n - i.time).powi(2))
        .sum();
    let ok = sum.abs() <= 1e-12 * total
        && velocity.abs() <= 1e-9 * total * t_n
        && (position - travel).abs() <= 1e-9 * travel;
    if !ok {
        return Err(Error::Infeasible {
            reason: format!(
                "the designed move does not end at rest at the requested distance \
                 (Σ A = {sum:.3e}, final velocity {velocity:.3e}, travel {position} \
                 instead of {travel})"
            ),
        });
    }
    Ok(())
}

/// V vanishes (to [`ZERO_VIBRATION_TOLERANCE`]) at (`f` Hz, ζ = `z`).
fn verify_zero_at(shaper: &Shaper, f: f64, z: f64) -> Result<()> {
    let v = vibration_at(shaper, f, z);
    if v.is_nan() || v > ZERO_VIBRATION_TOLERANCE {
        return Err(Error::Infeasible {
            reason: format!(
                "the designed shaper leaves V = {v:.3e} at {f} Hz, ζ = {z}, where it should \
                 vanish"
            ),
        });
    }
    Ok(())
}

/// V ≤ `limit` at (`f` Hz, ζ = `z`), the error naming the tolerable level `vtol`.
fn verify_at_most(shaper: &Shaper, f: f64, z: f64, vtol: f64, limit: f64) -> Result<()> {
    let v = vibration_at(shaper, f, z);
    if v.is_nan() || v > limit {
        return Err(Error::Infeasible {
            reason: format!(
                "the designed shaper leaves V = {:.4} % at {f} Hz, ζ = {z}, above Vtol = {:.4} %",
                v * 100.0,
                vtol * 100.0
            ),
        });
    }
    Ok(())
}

/// The vibration moments of orders 0 … `derivatives` vanish at every mode (each scaled by
/// the duration to its order).
fn verify_zero_moments(shaper: &Shaper, modes: &[Mode], derivatives: u32) -> Result<()> {
    let t_n = shaper.duration().max(f64::MIN_POSITIVE);
    for (i, mode) in modes.iter().enumerate() {
        for k in 0..=derivatives {
            let [c, s] = crate::vibration::vibration_moment(
                shaper.impulses(),
                mode.omega_rad_s(),
                mode.damping(),
                k,
            );
            let m = crate::vibration::magnitude(c, s) / t_n.powi(k as i32);
            if m.is_nan() || m > ZERO_VIBRATION_TOLERANCE {
                return Err(Error::Infeasible {
                    reason: format!(
                        "the designed shaper leaves a vibration moment of order {k} of {m:.3e} \
                         at modes[{i}] ({} Hz, ζ = {})",
                        mode.frequency_hz(),
                        mode.damping()
                    ),
                });
            }
        }
    }
    Ok(())
}

/// V vanishes at every mode, from the impulses themselves (not the convolution factors the
/// design used) — except for a factored shaper (more than [`crate::shaper::MAX_IMPULSES`]
/// impulses, see [`Shaper`]), whose impulses are formed only when asked for: its V is the
/// product of its factors' V, each evaluated from that factor's impulses.
fn verify_zero_at_modes(shaper: &Shaper, modes: &[Mode]) -> Result<()> {
    for (i, mode) in modes.iter().enumerate() {
        let (w, z) = (mode.omega_rad_s(), mode.damping());
        let v = if shaper.is_factored() {
            shaper
                .factors()
                .map(|f| crate::vibration::vibration_rad(f, w, z))
                .product()
        } else {
            crate::vibration::vibration_rad(shaper.impulses(), w, z)
        };
        if v.is_nan() || v > ZERO_VIBRATION_TOLERANCE {
            return Err(Error::Infeasible {
                reason: format!(
                    "the designed shaper leaves V = {v:.3e} at modes[{i}] ({} Hz, ζ = {}): \
                     the mode is too close to the numerical limits",
                    mode.frequency_hz(),
                    mode.damping()
                ),
            });
        }
    }
    Ok(())
}
