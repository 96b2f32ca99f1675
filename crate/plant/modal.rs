//! Modal plant: rigid-body motion of the base plus flexible modes, each
//! yᵢ'' + 2ζᵢωᵢ yᵢ' + ωᵢ² yᵢ = ωᵢ² u (the model every shaper here is designed for; Singhose 2009
//! eq. 1), summed at the endpoint with participation factors.
//!
//! The base follows the command exactly (an ideal servo: base position = u). The endpoint is
//! e = p₀u + Σ pᵢyᵢ with p₀ = 1 − Σ pᵢ, so that it comes to rest where the command does; the
//! deflection is e − u.

use super::lti::{self, Lti};
use crate::error::{finite, Error, Result};
use crate::mode::{Mode, ModeSpec};
use crate::piecewise::ORDER;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// Most modes a modal plant may have.
pub const MAX_MODES: usize = 64;

/// A mode of a plant with its participation factor at the endpoint.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct PlantModeSpec {
    /// Undamped natural frequency in Hz.
    pub frequency_hz: f64,
    /// Damping ratio ζ, 0 ≤ ζ < 1.
    #[serde(default)]
    pub damping: f64,
    /// Share of the endpoint motion carried by this mode (default: 1/number of modes).
    #[serde(default)]
    pub participation: Option<f64>,
}

/// A validated modal plant.
#[derive(Debug, Clone, PartialEq)]
pub struct ModalPlant {
    modes: Vec<Mode>,
    participation: Vec<f64>,
}

impl ModalPlant {
    /// Builds a plant from modes and participation factors (finite; they need not sum to 1:
    /// the rest, 1 − Σ pᵢ, is carried rigidly by the base).
    pub fn new(modes: Vec<Mode>, participation: Vec<f64>) -> Result<Self> {
        if modes.is_empty() {
            return Err(Error::invalid("modes", "at least one mode is required"));
        }
        crate::error::count("modes", modes.len(), 1, MAX_MODES)?;
        if participation.len() != modes.len() {
            return Err(Error::invalid(
                "modes",
                "one participation factor per mode is required",
            ));
        }
        for (i, p) in participation.iter().enumerate() {
            finite(&format!("modes[{i}].participation"), *p)?;
        }
        Ok(ModalPlant {
            modes,
            participation,
        })
    }

    /// Validates a spec's modes (`modes[i].frequencyHz`, `modes[i].damping`,
    /// `modes[i].participation`).
    pub fn from_spec(specs: &[PlantModeSpec]) -> Result<Self> {
        if specs.is_empty() {
            return Err(Error::invalid("modes", "at least one mode is required"));
        }
        crate::error::count("modes", specs.len(), 1, MAX_MODES)?;
        let n = specs.len() as f64;
        let mut modes = Vec::with_capacity(specs.len());
        let mut part = Vec::with_capacity(specs.len());
        for (i, s) in specs.iter().enumerate() {
            modes.push(
                Mode::from_spec(&ModeSpec {
                    frequency_hz: s.frequency_hz,
                    damping: s.damping,
                })
                .map_err(|e| e.within(&format!("modes[{i}]")))?,
            );
            part.push(s.participation.unwrap_or(1.0 / n));
        }
        ModalPlant::new(modes, part)
    }

    /// The two-mode test bed of Veciana & Cardona 2011 §4: 1.2 Hz with ζ = 0.012 and 3.4 Hz
    /// with ζ = 0.013. The paper does not give the modes' participation at the measured inertia;
    /// they are taken equal (½ each).
    pub fn veciana_test_bed() -> Result<Self> {
        ModalPlant::new(
            vec![Mode::new(1.2, 0.012)?, Mode::new(3.4, 0.013)?],
            vec![0.5, 0.5],
        )
    }

    /// The modes.
    pub fn modes(&self) -> &[Mode] {
        &self.modes
    }

    /// Participation factors, one per mode.
    pub fn participation(&self) -> &[f64] {
        &self.participation
    }

    /// The plant as a state space: states (yᵢ, yᵢ') per mode, one block each.
    pub fn to_lti(&self) -> Lti {
        let n = 2 * self.modes.len();
        let mut a = DMatrix::zeros(n, n);
        let mut e = DMatrix::zeros(n, ORDER);
        let mut c = DMatrix::zeros(lti::OUTPUTS, n);
        let mut d = DMatrix::zeros(lti::OUTPUTS, ORDER);
        d[(lti::BASE_POSITION, 0)] = 1.0;
        d[(lti::BASE_VELOCITY, 1)] = 1.0;
        d[(lti::BASE_ACCELERATION, 2)] = 1.0;
        let rigid = 1.0 - self.participation.iter().sum::<f64>();
        d[(lti::ENDPOINT, 0)] = rigid;
        d[(lti::ENDPOINT_VELOCITY, 1)] = rigid;
        d[(lti::ENDPOINT_ACCELERATION, 2)] = rigid;
        let mut blocks = Vec::with_capacity(self.modes.len());
        for (i, (mode, &p)) in self.modes.iter().zip(&self.participation).enumerate() {
            let w = mode.omega_rad_s();
            let z = mode.damping();
            let (y, v) = (2 * i, 2 * i + 1);
            a[(y, v)] = 1.0;
            a[(v, y)] = -w * w;
            a[(v, v)] = -2.0 * z * w;
            e[(v, 0)] = w * w;
            c[(lti::ENDPOINT, y)] = p;
            c[(lti::ENDPOINT_VELOCITY, v)] = p;
            c[(lti::ENDPOINT_ACCELERATION, y)] = -p * w * w;
            c[(lti::ENDPOINT_ACCELERATION, v)] = -p * 2.0 * z * w;
            d[(lti::ENDPOINT_ACCELERATION, 0)] += p * w * w;
            blocks.push((y, 2));
        }
        Lti { a, e, c, d, blocks }
    }
}
