//! Shaper design: the spec a user writes, the table of families, and [`design`].
//!
//! A spec is a JSON-like object `{ family, modes: [{ frequencyHz, damping }], …parameters }`.
//! Each family lives in its own file and reads like the paper it comes from; adding one is a
//! function there plus a row in [`FAMILIES`] and a variant of [`ShaperSpec`].
//!
//! For several modes, single-mode families are designed per mode and convolved
//! (Singer & Seering 1988 §2.3). Every design is checked against its guarantee with an
//! independent evaluation of V before it is returned.

pub mod quantize;
pub mod sampled;
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
    /// Impulses on the controller period with a prescribed ramp delay and the least control
    /// error (Kamel, Lange & Hirzinger); parameters in [`sampled::SampledSpec`].
    Sampled(sampled::SampledSpec),
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
        name: "sampled",
        title: "Sampled (t = iT)",
        guarantee: "V = 0 at the mode with `derivatives` derivatives (default 1), impulses at \
                    t = iT, ramp delay m·T if asked, amplitude/increment bounds; least control \
                    error J_q; one mode",
        parameters: &[
            "periodS",
            "impulses",
            "delaySamples",
            "weight",
            "derivatives",
            "plantGain",
            "objective",
            "amplitudeMin",
            "amplitudeMax",
            "incrementMin",
            "incrementMax",
        ],
        source: "Kamel, Lange & Hirzinger, eqs. 4-25",
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
        ShaperSpec::Sampled(spec) => (
            sampled::design_for_modes(modes, spec)?.shaper,
            Guarantee::ZeroAtModes,
        ),
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
