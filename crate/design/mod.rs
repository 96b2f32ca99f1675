//! Shaper design: the spec a user writes, the table of families, and [`design`].
//!
//! A spec is a JSON-like object `{ family, modes: [{ frequencyHz, damping }], …parameters }`.
//! Each family lives in its own file and reads like the paper it comes from; adding one is a
//! function there plus a row in [`FAMILIES`] and a variant of [`ShaperSpec`].
//!
//! For several modes, single-mode families are designed per mode and convolved
//! (Singer & Seering 1988 §2.3). Every design is checked against its guarantee with an
//! independent evaluation of V before it is returned.

pub mod direct;
pub mod specified;
pub mod zero_vibration;

use crate::error::{Error, Result};
use crate::mode::{Mode, ModeSpec};
use crate::shaper::Shaper;
use crate::vibration::residual_vibration;
use serde::{Deserialize, Serialize};

/// A family of shapers and its parameters (the `family` field selects the variant).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "family", rename_all = "lowercase")]
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
    /// Specified insensitivity: the shortest shaper with V ≤ Vtol over a band of frequencies
    /// (and dampings), sampled or guaranteed on the whole band (Singhose 2009 eq. 18).
    Si(specified::SiSpec),
    /// Several modes at once: the shortest shaper with zero vibration (and derivatives) at every
    /// mode, designed directly instead of by convolution (Singer & Seering 1988 §2.3).
    Direct(direct::DirectSpec),
}

impl ShaperSpec {
    /// The `family` string of this spec (the key of its row in [`FAMILIES`]).
    pub fn name(&self) -> &'static str {
        match self {
            ShaperSpec::Zv => "zv",
            ShaperSpec::Zvd => "zvd",
            ShaperSpec::Zvdd => "zvdd",
            ShaperSpec::Zvdn { .. } => "zvdn",
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
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DesignRequest {
    /// The modes to suppress (at least one, none repeated).
    pub modes: Vec<ModeSpec>,
    /// The family and its parameters.
    #[serde(flatten)]
    pub shaper: ShaperSpec,
}

/// One row of the family table: what the family is called and what it promises.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct FamilyInfo {
    /// The `family` string of a spec.
    pub name: &'static str,
    /// A short human name.
    pub title: &'static str,
    /// What a shaper of this family guarantees.
    pub guarantee: &'static str,
    /// Parameters besides `modes`, as written in a spec.
    pub parameters: &'static [&'static str],
    /// Where it comes from.
    pub source: &'static str,
}

/// Every family [`design`] accepts.
pub const FAMILIES: &[FamilyInfo] = &[
    FamilyInfo {
        name: "zv",
        title: "ZV",
        guarantee: "V = 0 at each mode; shortest positive shaper",
        parameters: &[],
        source: "Singer & Seering 1988 eq. 6; Singhose 2009 eqs. 14-15",
    },
    FamilyInfo {
        name: "zvd",
        title: "ZVD",
        guarantee: "V = 0 and dV/dω = 0 at each mode",
        parameters: &[],
        source: "Singer & Seering 1988 eq. 7; Singhose 2009 eq. 17",
    },
    FamilyInfo {
        name: "zvdd",
        title: "ZVDD",
        guarantee: "V = 0 and two derivatives zero at each mode",
        parameters: &[],
        source: "Singer & Seering 1988 eq. 8",
    },
    FamilyInfo {
        name: "zvdn",
        title: "ZV-Dⁿ",
        guarantee: "V = 0 and n derivatives zero at each mode",
        parameters: &["derivatives"],
        source: "Singer & Seering 1988 §2.2 (binomial form)",
    },
    FamilyInfo {
        name: "si",
        title: "SI (specified insensitivity)",
        guarantee: "V ≤ vtol over the band (whole band, verified densely) or at the sampled \
                    frequencies; shortest such shaper",
        parameters: &[
            "vtol",
            "insensitivity",
            "bandHz",
            "dampingRange",
            "sampleFrequenciesHz",
            "vtolProfile",
            "amplitudeMin",
            "amplitudeMax",
            "maxImpulses",
            "maxDuration",
        ],
        source: "Singhose 2009 eq. 18, Figs. 8-11; Pelaez & Singhose 2002 eqs. 6-7",
    },
    FamilyInfo {
        name: "direct",
        title: "Direct multi-mode ZV / ZVD",
        guarantee: "V = 0 and n derivatives zero at every mode at once; shortest such shaper",
        parameters: &["derivatives", "amplitudeMin", "amplitudeMax", "maxDuration"],
        source: "Singer & Seering 1988 §2.3; Singhose 2009 §4, Fig. 12",
    },
];

/// What a designed shaper promises, checked by [`verify`] before it is returned.
#[derive(Debug, Clone, PartialEq)]
#[allow(dead_code)] // AtMost and Valid are for the solved and custom families being added
pub(crate) enum Guarantee {
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
pub fn design(request: &DesignRequest) -> Result<Shaper> {
    let modes = Mode::list(&request.modes)?;
    design_for(&request.shaper, &modes)
}

/// Designs a shaper of family `spec` for already validated modes.
pub fn design_for(spec: &ShaperSpec, modes: &[Mode]) -> Result<Shaper> {
    if modes.is_empty() {
        return Err(Error::invalid("modes", "at least one mode is required"));
    }
    let (shaper, guarantee) = match spec {
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
        ShaperSpec::Si(si) => specified::si(si, modes)?,
        ShaperSpec::Direct(d) => direct::direct(d, modes)?,
    };
    verify(&shaper, modes, &guarantee)?;
    Ok(shaper)
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
        Guarantee::Valid => {}
        Guarantee::WithinTolerance { points, tolerance } => {
            for &(f, z, vtol) in points {
                let v = crate::vibration::vibration_rad(
                    shaper.impulses(),
                    2.0 * std::f64::consts::PI * f,
                    z,
                );
                if v.is_nan() || v > vtol * (1.0 + tolerance) {
                    return Err(Error::Infeasible {
                        reason: format!(
                            "the designed shaper leaves V = {:.4} % at {f} Hz, ζ = {z}, above \
                             Vtol = {:.4} %",
                            v * 100.0,
                            vtol * 100.0
                        ),
                    });
                }
            }
        }
        Guarantee::ZeroDerivativesAtModes { derivatives } => {
            let t_n = shaper.duration().max(f64::MIN_POSITIVE);
            for (i, mode) in modes.iter().enumerate() {
                for k in 0..=*derivatives {
                    let [c, s] = crate::vibration::vibration_moment(
                        shaper.impulses(),
                        mode.omega_rad_s(),
                        mode.damping(),
                        k,
                    );
                    let m = c.hypot(s) / t_n.powi(k as i32);
                    if m.is_nan() || m > ZERO_VIBRATION_TOLERANCE {
                        return Err(Error::Infeasible {
                            reason: format!(
                                "the designed shaper leaves a vibration moment of order {k} of \
                                 {m:.3e} at modes[{i}] ({} Hz, ζ = {})",
                                mode.frequency_hz(),
                                mode.damping()
                            ),
                        });
                    }
                }
            }
        }
        Guarantee::AtMost {
            vtol,
            points,
            tolerance,
        } => {
            for &(f, z) in points {
                let v = crate::vibration::vibration_rad(
                    shaper.impulses(),
                    2.0 * std::f64::consts::PI * f,
                    z,
                );
                if v.is_nan() || v > vtol + tolerance {
                    return Err(Error::Infeasible {
                        reason: format!(
                            "the designed shaper leaves V = {:.4} % at {f} Hz, ζ = {z}, above \
                             Vtol = {:.4} %",
                            v * 100.0,
                            vtol * 100.0
                        ),
                    });
                }
            }
        }
        Guarantee::ZeroAtModes => {
            for (i, mode) in modes.iter().enumerate() {
                let v = residual_vibration(shaper, mode);
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
        }
    }
    Ok(())
}
