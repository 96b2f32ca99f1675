//! A vibration mode of the machine: natural frequency and damping ratio.
//!
//! Each mode is the second-order system y'' + 2ζω y' + ω² y = ω² u. A [`Mode`] can only be
//! built through [`Mode::new`], which rejects values no shaper can be designed for, so the rest
//! of the crate trusts it.

use crate::error::{finite, Error, Result};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Smallest natural frequency accepted, in Hz (a period of about 32 years).
pub const MIN_FREQUENCY_HZ: f64 = 1e-9;
/// Largest natural frequency accepted, in Hz.
pub const MAX_FREQUENCY_HZ: f64 = 1e9;
/// Most modes a list may hold (a spec with more is refused: checking a list for repeats, and
/// every design on it, grows with its length).
pub const MAX_MODES: usize = 64;

/// A validated vibration mode: `0 < frequency_hz` (within [`MIN_FREQUENCY_HZ`],
/// [`MAX_FREQUENCY_HZ`]) and `0 ≤ damping < 1`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Mode {
    frequency_hz: f64,
    damping: f64,
}

/// The wire form of a mode, as written in a spec (`{ frequencyHz, damping }`), before
/// validation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct ModeSpec {
    /// Undamped natural frequency in Hz.
    pub frequency_hz: f64,
    /// Damping ratio ζ, dimensionless, 0 ≤ ζ < 1.
    #[serde(default)]
    pub damping: f64,
}

impl Mode {
    /// Builds a mode from its undamped natural frequency in Hz and its damping ratio.
    ///
    /// Errors name the field (`frequencyHz` or `damping`) and say what is allowed.
    pub fn new(frequency_hz: f64, damping: f64) -> Result<Self> {
        finite("frequencyHz", frequency_hz)?;
        if frequency_hz <= 0.0 {
            return Err(Error::invalid(
                "frequencyHz",
                format!("must be greater than 0 Hz, got {frequency_hz}"),
            ));
        }
        if !(MIN_FREQUENCY_HZ..=MAX_FREQUENCY_HZ).contains(&frequency_hz) {
            return Err(Error::invalid(
                "frequencyHz",
                format!(
                    "must lie between {MIN_FREQUENCY_HZ} and {MAX_FREQUENCY_HZ} Hz, got {frequency_hz}"
                ),
            ));
        }
        finite("damping", damping)?;
        if !(0.0..1.0).contains(&damping) {
            return Err(Error::invalid(
                "damping",
                format!("damping ratio must satisfy 0 ≤ ζ < 1 (underdamped), got {damping}"),
            ));
        }
        Ok(Mode {
            frequency_hz,
            damping,
        })
    }

    /// Validates a wire-form mode.
    pub fn from_spec(spec: &ModeSpec) -> Result<Self> {
        Mode::new(spec.frequency_hz, spec.damping)
    }

    /// Validates a list of modes; errors are prefixed `modes[i]`. An empty list and a mode given
    /// twice are rejected.
    pub fn list(specs: &[ModeSpec]) -> Result<Vec<Mode>> {
        if specs.is_empty() {
            return Err(Error::invalid("modes", "at least one mode is required"));
        }
        crate::error::count("modes", specs.len(), 1, MAX_MODES)?;
        let mut modes = Vec::with_capacity(specs.len());
        for (i, spec) in specs.iter().enumerate() {
            let mode = Mode::from_spec(spec).map_err(|e| e.within(&format!("modes[{i}]")))?;
            if let Some(j) = modes.iter().position(|m: &Mode| *m == mode) {
                return Err(Error::invalid(
                    format!("modes[{i}]"),
                    format!(
                        "duplicates modes[{j}] ({} Hz, ζ = {})",
                        mode.frequency_hz, mode.damping
                    ),
                ));
            }
            modes.push(mode);
        }
        Ok(modes)
    }

    /// Undamped natural frequency in Hz.
    pub fn frequency_hz(&self) -> f64 {
        self.frequency_hz
    }

    /// Damping ratio ζ.
    pub fn damping(&self) -> f64 {
        self.damping
    }

    /// Undamped natural frequency ω in rad/s.
    pub fn omega_rad_s(&self) -> f64 {
        2.0 * PI * self.frequency_hz
    }

    /// Damped natural frequency ω_d = ω√(1−ζ²) in rad/s.
    pub fn damped_omega_rad_s(&self) -> f64 {
        self.omega_rad_s() * (1.0 - self.damping * self.damping).sqrt()
    }

    /// Damped period T_d = 2π/ω_d in seconds.
    pub fn damped_period_s(&self) -> f64 {
        2.0 * PI / self.damped_omega_rad_s()
    }

    /// K = exp(−ζπ/√(1−ζ²)), the decay of the damped oscillation over half a damped period
    /// (Singer & Seering 1988 eq. 6; Singhose 2009 eq. 15).
    pub fn half_period_decay(&self) -> f64 {
        let z = self.damping;
        (-z * PI / (1.0 - z * z).sqrt()).exp()
    }

    /// The same mode at another frequency (used for mismatch and frequency sampling).
    pub fn with_frequency_hz(&self, frequency_hz: f64) -> Result<Self> {
        Mode::new(frequency_hz, self.damping)
    }
}
