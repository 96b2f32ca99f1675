//! Multi-mode shapers designed directly: the ZV (or ZVD, ZV-Dⁿ) constraints of every mode
//! solved simultaneously for the shortest shaper.
//!
//! Singer & Seering 1988 §2.3: convolving single-mode shapers suppresses every mode, but
//! "the sequence can be shortened" by imposing all the constraints at once — for two modes,
//! five impulses instead of nine for ZVD. Singhose 2009 §4 and Fig. 12: the direct two-mode ZVD
//! shaper is shorter than the convolved one at every mode ratio.
//!
//! Constraints, for every mode j and k = 0 … `derivatives` (Singhose 2009 eqs. 11, 12, 16):
//!
//! Σᵢ Aᵢ tᵢᵏ e^{ζⱼωⱼtᵢ} cos(ω_dⱼ tᵢ) = 0,  Σᵢ Aᵢ tᵢᵏ e^{ζⱼωⱼtᵢ} sin(ω_dⱼ tᵢ) = 0,  Σ Aᵢ = 1,
//!
//! i.e. V and its first `derivatives` frequency derivatives vanish at every mode (see
//! [`crate::vibration::vibration_moment`]); amplitudes within `amplitudeMin` … `amplitudeMax`
//! (default 0 … 1; a negative `amplitudeMin` allows negative shapers); t_n minimal.
//!
//! Design: [`crate::solve::minimum_duration`] — on a fine time grid these are linear equalities
//! in the amplitudes, so the shortest grid-feasible duration is found by bisection over linear
//! programs; the few impulses used are then polished by Newton's method, so the equalities
//! hold to rounding.

use crate::design::{DesignRequest, Guarantee, ShaperSpec};
use crate::error::{Error, Result};
use crate::mode::Mode;
use crate::shaper::Shaper;
use crate::solve::{self, Problem, SolverReport, ZeroVibration};
use serde::{Deserialize, Serialize};

/// Largest `derivatives` accepted by the direct design: the solver's limit.
pub const MAX_DIRECT_DERIVATIVES: u32 = solve::MAX_ZERO_DERIVATIVES;
/// Most modes a direct design takes at once.
pub const MAX_DIRECT_MODES: usize = 8;

fn default_derivatives() -> u32 {
    1
}

fn default_amplitude_max() -> f64 {
    1.0
}

/// Parameters of a direct multi-mode design (`family: "direct"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct DirectSpec {
    /// Zero derivatives at every mode: 0 = ZV, 1 = ZVD (default), 2 = ZVDD, … up to
    /// [`MAX_DIRECT_DERIVATIVES`].
    #[serde(default = "default_derivatives")]
    pub derivatives: u32,
    /// Smallest amplitude (default 0; negative allows negative impulses).
    #[serde(default)]
    pub amplitude_min: f64,
    /// Largest amplitude (default 1).
    #[serde(default = "default_amplitude_max")]
    pub amplitude_max: f64,
    /// Longest duration accepted, seconds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_duration: Option<f64>,
}

impl Default for DirectSpec {
    fn default() -> Self {
        DirectSpec {
            derivatives: default_derivatives(),
            amplitude_min: 0.0,
            amplitude_max: default_amplitude_max(),
            max_duration: None,
        }
    }
}

impl DirectSpec {
    /// A design request for these parameters (a convenience for Rust callers and tests).
    pub fn request(self, modes: Vec<crate::mode::ModeSpec>) -> DesignRequest {
        DesignRequest {
            modes,
            shaper: ShaperSpec::Direct(self),
        }
    }
}

/// Designs the direct multi-mode shaper; returns it with its guarantee.
pub(crate) fn direct(
    spec: &DirectSpec,
    modes: &[Mode],
) -> Result<(Shaper, Guarantee, SolverReport)> {
    if spec.derivatives > MAX_DIRECT_DERIVATIVES {
        return Err(Error::TooLarge {
            field: "derivatives".into(),
            value: f64::from(spec.derivatives),
            limit: f64::from(MAX_DIRECT_DERIVATIVES),
        });
    }
    crate::error::count("modes", modes.len(), 1, MAX_DIRECT_MODES)?;
    super::solved::check_bounds(spec.amplitude_min, spec.amplitude_max, spec.max_duration)?;
    let problem = Problem {
        zeros: modes
            .iter()
            .map(|m| ZeroVibration {
                frequency_hz: m.frequency_hz(),
                damping: m.damping(),
                derivatives: spec.derivatives,
            })
            .collect(),
        limits: Vec::new(),
        bands: Vec::new(),
        amplitude_min: spec.amplitude_min,
        amplitude_max: spec.amplitude_max,
        max_duration: spec.max_duration,
    };
    let design = solve::minimum_duration(&problem)?;
    let report = design.report();
    Ok((
        design.shaper,
        Guarantee::ZeroDerivativesAtModes {
            derivatives: spec.derivatives,
        },
        report,
    ))
}

/// Designs the shortest shaper with zero vibration and `spec.derivatives` zero derivatives at
/// every mode at once (see the module docs), checked against that guarantee.
///
/// ```
/// use input_shaping::design::direct::{direct_multi_mode, DirectSpec};
/// use input_shaping::{vibration::residual_vibration, Mode};
/// // One shaper with ZVD's constraints at two modes at once (DirectSpec's default).
/// let modes = [Mode::new(1.2, 0.012)?, Mode::new(3.4, 0.013)?];
/// let shaper = direct_multi_mode(&DirectSpec::default(), &modes)?;
/// assert!((shaper.amplitude_sum() - 1.0).abs() < 1e-9);
/// assert!(modes.iter().all(|m| residual_vibration(&shaper, m) < 1e-6));
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn direct_multi_mode(spec: &DirectSpec, modes: &[Mode]) -> Result<Shaper> {
    let (shaper, guarantee, _) = direct(spec, modes)?;
    crate::design::verify(&shaper, modes, &guarantee)?;
    Ok(shaper)
}
