//! MZV, the "modified ZV" shaper of Klipper (3D-printer firmware), reproduced exactly.
//!
//! Source: Klipper's `klippy/extras/shaper_defs.py`, `get_mzv_shaper` (Dmitry Butyugin,
//! 2020–2021), re-derived here from its published formula rather than copied:
//!
//! K = exp(−0.75 ζπ/√(1−ζ²)),  a₁ = 1 − 1/√2,  a₂ = (√2 − 1)K,  a₃ = a₁K²,
//! t = [0, 0.375, 0.75]·T_d,  T_d = 1/(f√(1−ζ²)),
//!
//! normalised here so the amplitudes sum to 1 (Klipper normalises when it applies a shaper).
//!
//! ## What it guarantees (worked out here; Klipper's docs say only "modified ZV")
//! K is the decay over τ = 3T_d/8, the spacing of the impulses, so the damped impulse vectors
//! Aᵢ e^{ζω tᵢ} e^{iω_d tᵢ} = aᵢ e^{i·3πi/4} are those of the undamped shaper. At ζ = 0,
//! V(r) = |a₂ + 2a₁ cos(3πr/4)| with r = f/f_m, and cos(3π/4) = −1/√2 = −a₂/(2a₁), so:
//!
//! - **V = 0 at the mode**, exactly, for every ζ (the vector sum closes at ω_m);
//! - a **second zero at 5/3 of the mode** (3πr/4 = 5π/4), exact at ζ = 0, close to it with
//!   damping — Klipper's later generalisation (`get_mzv_coeffs`) places its zeros the same way;
//! - between them a hump of 3 − 2√2 ≈ 17.2 % at 4/3 of the mode (ζ = 0);
//! - duration 0.75 T_d, between ZV (0.5) and ZVD (1);
//! - I(5 %) = (4/3π)[arccos((−a₂ − 0.05)/2a₁) − arccos((−a₂ + 0.05)/2a₁)] ≈ 0.1035 at ζ = 0:
//!   more robust than ZV (0.064), much less than ZVD (0.287). No derivative of V vanishes at
//!   the mode; the robustness comes from the nearby second zero.

use crate::error::Result;
use crate::mode::Mode;
use crate::shaper::{Impulse, Shaper};
use std::f64::consts::{PI, SQRT_2};

/// Klipper's MZV shaper for `mode`, normalised to Σ Aᵢ = 1 (module docs).
///
/// ```
/// use input_shaping::{design::modified::mzv, vibration::residual_vibration, Mode};
/// let mode = Mode::new(40.0, 0.0)?;
/// let shaper = mzv(&mode)?;
/// // Undamped: [1 − 1/√2, √2 − 1, 1 − 1/√2] at [0, 0.375, 0.75]·T, zeros at f and 5f/3.
/// let a1 = 1.0 - std::f64::consts::FRAC_1_SQRT_2;
/// assert!((shaper.impulses()[0].amplitude - a1).abs() < 1e-12);
/// assert!((shaper.duration() - 0.75 / 40.0).abs() < 1e-12);
/// assert!(residual_vibration(&shaper, &mode) < 1e-12);
/// assert!(residual_vibration(&shaper, &Mode::new(40.0 * 5.0 / 3.0, 0.0)?) < 1e-12);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn mzv(mode: &Mode) -> Result<Shaper> {
    let z = mode.damping();
    let df = (1.0 - z * z).sqrt();
    let k = (-0.75 * z * PI / df).exp();
    let t_d = mode.damped_period_s();
    let a1 = 1.0 - 1.0 / SQRT_2;
    let a2 = (SQRT_2 - 1.0) * k;
    let a3 = a1 * k * k;
    let sum = a1 + a2 + a3;
    Shaper::new(
        [(0.0, a1), (0.375, a2), (0.75, a3)]
            .iter()
            .map(|&(t, a)| Impulse {
                time: t * t_d,
                amplitude: a / sum,
            })
            .collect(),
    )
}
