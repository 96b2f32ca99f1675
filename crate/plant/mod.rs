//! Plant models: what the shaped command drives.
//!
//! - [`modal`]: rigid-body motion plus flexible modes y'' + 2ζωy' + ω²y = ω²u, summed with
//!   participation factors (the model the shapers are designed for), including the two-mode
//!   test bed of Veciana & Cardona 2011 §4;
//! - [`two_mass`]: the two-mass spring of Peláez & Singhose 2002 in state space, with its
//!   rigid-body mode;
//! - [`pendulum`]: a nonlinear crane pendulum with large swing angles and optional hoisting;
//! - [`lti`]: the exact (matrix-exponential) simulation every linear plant shares.
//!
//! Model mismatch is expressed by giving the plant different parameters from the modes the
//! shaper was designed for.

pub mod lti;
pub mod modal;
pub mod pendulum;
pub mod two_mass;

use crate::error::Result;
use crate::mode::Mode;

pub use modal::{ModalPlant, PlantModeSpec};
pub use pendulum::{Pendulum, PendulumSpec};
pub use two_mass::TwoMass;

crate::tagged::tagged_enum! {
    tag = "kind", rename_all = "camelCase", mirror = plant_spec_serde;
    /// A plant as written in a spec (`{ kind, … }`).
    #[derive(Debug, Clone, PartialEq)]
    pub enum PlantSpec {
        /// `{ kind: "modal", modes: [{ frequencyHz, damping, participation? }] }`.
        Modal {
            /// The flexible modes.
            modes: Vec<PlantModeSpec>,
        },
        /// `{ kind: "twoMass", baseMass, tipMass, stiffness, dampingCoefficient? }` (SI units).
        TwoMass(TwoMass),
        /// `{ kind: "pendulum", length, gravity?, damping?, initialAngle?, hoist? }`.
        Pendulum(PendulumSpec),
        /// `{ kind: "vecianaTestBed" }`: 1.2 Hz (ζ 0.012) and 3.4 Hz (ζ 0.013), equal
        /// participation.
        VecianaTestBed,
    }
}

/// A validated plant.
#[derive(Debug, Clone, PartialEq)]
pub enum Plant {
    /// Modal LTI plant.
    Modal(ModalPlant),
    /// Two-mass spring.
    TwoMass(TwoMass),
    /// Nonlinear pendulum.
    Pendulum(Pendulum),
}

impl Plant {
    /// Validates a spec; errors name the field (`modes[0].damping`, `baseMass`, `length`).
    pub fn from_spec(spec: &PlantSpec) -> Result<Plant> {
        Ok(match spec {
            PlantSpec::Modal { modes } => Plant::Modal(ModalPlant::from_spec(modes)?),
            PlantSpec::TwoMass(t) => {
                t.validate()?;
                Plant::TwoMass(*t)
            }
            PlantSpec::Pendulum(p) => Plant::Pendulum(Pendulum::from_spec(p)?),
            PlantSpec::VecianaTestBed => Plant::Modal(ModalPlant::veciana_test_bed()?),
        })
    }

    /// The plant's vibration modes as a shaper designer would model them (the pendulum's
    /// linearised at its initial length).
    pub fn modes(&self) -> Result<Vec<Mode>> {
        match self {
            Plant::Modal(m) => Ok(m.modes().to_vec()),
            Plant::TwoMass(t) => Ok(vec![t.mode()?]),
            Plant::Pendulum(p) => Ok(vec![p.mode()?]),
        }
    }
}
