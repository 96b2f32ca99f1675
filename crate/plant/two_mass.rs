//! The two-mass spring of Peláez & Singhose 2002 §3 (Fig. 9): a driven mass M₁ (the base, z)
//! joined by a spring K (and optionally a damper c) to a tip mass M₂ (the endpoint, y):
//!
//! −K(y − z) = M₂ÿ (eq. 12),  F − K(z − y) = M₁z̈ (eq. 13),
//!
//! in state space with x = (y, ẏ, z, ż) (eqs. 14–17). Its eigenvalues are 0, 0 (the rigid-body
//! mode: both masses moving together) and ±jω with ω = √(K(M₁ + M₂)/(M₁M₂)) (eq. 18; the
//! printed text lost the j).
//!
//! Driven by a position command u, the force is the one that carries the whole machine along
//! it, F = (M₁ + M₂)ü: the centre of mass then follows u exactly and the flexible mode rings
//! around it. A velocity jump in u is a force impulse (handled exactly); a position jump would
//! need an infinite impulse and is rejected.

use super::lti::{self, Lti};
use crate::error::{finite, positive, Error, Result};
use crate::mode::Mode;
use crate::piecewise::ORDER;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// The parameters of a two-mass spring, as written in a plant spec (SI units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct TwoMass {
    /// Driven mass M₁ (kg).
    pub base_mass: f64,
    /// Tip mass M₂ (kg).
    pub tip_mass: f64,
    /// Spring stiffness K (N/m).
    pub stiffness: f64,
    /// Damper c between the masses (N·s/m, default 0).
    #[serde(default)]
    pub damping_coefficient: f64,
}

impl TwoMass {
    /// Checks the parameters: masses and stiffness > 0, damper ≥ 0 and below critical (the
    /// flexible mode must stay underdamped).
    pub fn validate(&self) -> Result<()> {
        positive("baseMass", self.base_mass)?;
        positive("tipMass", self.tip_mass)?;
        positive("stiffness", self.stiffness)?;
        finite("dampingCoefficient", self.damping_coefficient)?;
        if self.damping_coefficient < 0.0 {
            return Err(Error::invalid(
                "dampingCoefficient",
                format!("must be ≥ 0, got {}", self.damping_coefficient),
            ));
        }
        let z = self.damping_ratio();
        if !(0.0..1.0).contains(&z) {
            return Err(Error::invalid(
                "dampingCoefficient",
                format!("gives a damping ratio ζ = {z}; the flexible mode must have ζ < 1"),
            ));
        }
        Ok(())
    }

    /// ω = √(K(M₁ + M₂)/(M₁M₂)) in rad/s (eq. 18).
    pub fn omega_rad_s(&self) -> f64 {
        (self.stiffness * (self.base_mass + self.tip_mass) / (self.base_mass * self.tip_mass))
            .sqrt()
    }

    /// Damping ratio of the flexible mode: 2ζω = c(1/M₁ + 1/M₂).
    pub fn damping_ratio(&self) -> f64 {
        self.damping_coefficient * (1.0 / self.base_mass + 1.0 / self.tip_mass)
            / (2.0 * self.omega_rad_s())
    }

    /// The flexible mode (frequency from eq. 18, damping from the damper).
    pub fn mode(&self) -> Result<Mode> {
        self.validate()?;
        Mode::new(
            self.omega_rad_s() / (2.0 * std::f64::consts::PI),
            self.damping_ratio(),
        )
    }

    /// The state matrix of eq. 16 (with the damper added), x = (y, ẏ, z, ż).
    pub fn state_matrix(&self) -> DMatrix<f64> {
        let (m1, m2, k, c) = (
            self.base_mass,
            self.tip_mass,
            self.stiffness,
            self.damping_coefficient,
        );
        DMatrix::from_row_slice(
            4,
            4,
            &[
                0.0,
                1.0,
                0.0,
                0.0,
                -k / m2,
                -c / m2,
                k / m2,
                c / m2,
                0.0,
                0.0,
                0.0,
                1.0,
                k / m1,
                c / m1,
                -k / m1,
                -c / m1,
            ],
        )
    }

    /// The plant as a state space driven by F = (M₁ + M₂)ü; base = z (M₁), endpoint = y (M₂).
    pub fn to_lti(&self) -> Result<Lti> {
        self.validate()?;
        let a = self.state_matrix();
        let gain = (self.base_mass + self.tip_mass) / self.base_mass;
        let mut e = DMatrix::zeros(4, ORDER);
        e[(3, 2)] = gain;
        let mut c = DMatrix::zeros(lti::OUTPUTS, 4);
        let mut d = DMatrix::zeros(lti::OUTPUTS, ORDER);
        c[(lti::BASE_POSITION, 2)] = 1.0;
        c[(lti::BASE_VELOCITY, 3)] = 1.0;
        for j in 0..4 {
            c[(lti::BASE_ACCELERATION, j)] = a[(3, j)];
            c[(lti::ENDPOINT_ACCELERATION, j)] = a[(1, j)];
        }
        d[(lti::BASE_ACCELERATION, 2)] = gain;
        c[(lti::ENDPOINT, 0)] = 1.0;
        c[(lti::ENDPOINT_VELOCITY, 1)] = 1.0;
        Ok(Lti {
            a,
            e,
            c,
            d,
            blocks: vec![(0, 4)],
        })
    }
}

/// Natural frequency (rad/s) of the rotary version (Fig. 8): a shaft of inertia J driving an
/// arm of length L with tip mass M₂ through a torsional stiffness K_t (N·m/rad):
/// ω = √(K_t(J + M₂L²)/(J M₂ L²)) (eq. 19: eq. 18 with M₁ → J/L² and K → K_t/L²).
pub fn rotary_omega_rad_s(
    shaft_inertia: f64,
    tip_mass: f64,
    arm_length: f64,
    torsional_stiffness: f64,
) -> Result<f64> {
    let j = positive("shaftInertia", shaft_inertia)?;
    let m = positive("tipMass", tip_mass)?;
    let l = positive("armLength", arm_length)?;
    let k = positive("torsionalStiffness", torsional_stiffness)?;
    Ok((k * (j + m * l * l) / (j * m * l * l)).sqrt())
}

/// Tip stiffness of a cantilever arm, K = 3EI/L³ (eq. 20), in N/m.
pub fn cantilever_stiffness(youngs_modulus: f64, area_moment: f64, arm_length: f64) -> Result<f64> {
    let e = positive("youngsModulus", youngs_modulus)?;
    let i = positive("areaMoment", area_moment)?;
    let l = positive("armLength", arm_length)?;
    Ok(3.0 * e * i / (l * l * l))
}

/// Natural frequency (rad/s) of the flexible arm (eq. 21), ω = √(3EI(J + M₂L²)/(J M₂ L³)).
///
/// Reconstructed: the paper prints L⁵ in the denominator, which is what substituting the tip
/// (translational) stiffness 3EI/L³ of eq. 20 into eq. 19's torsional K gives; eq. 19 needs the
/// torsional stiffness K_t = K L² = 3EI/L, and then the power is L³ (dimensionally 1/s²).
pub fn arm_omega_rad_s(
    youngs_modulus: f64,
    area_moment: f64,
    arm_length: f64,
    shaft_inertia: f64,
    tip_mass: f64,
) -> Result<f64> {
    let k = cantilever_stiffness(youngs_modulus, area_moment, arm_length)?;
    rotary_omega_rad_s(
        shaft_inertia,
        tip_mass,
        arm_length,
        k * arm_length * arm_length,
    )
}
