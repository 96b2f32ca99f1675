//! Zero-vibration shapers with zero derivatives: ZV, ZVD, ZVDD and ZV-Dⁿ, in closed form with
//! damping.
//!
//! Singer & Seering 1988 eqs. 6–8 (Singhose 2009 eqs. 14–17): with
//! K = exp(−ζπ/√(1−ζ²)) and the damped period T_d = 2π/(ω√(1−ζ²)), the shaper that cancels
//! vibration at the mode and makes the first n derivatives of V with respect to frequency
//! vanish there has n + 2 impulses
//!
//! Aᵢ = C(n+1, i) Kⁱ / (1 + K)ⁿ⁺¹,  tᵢ = i T_d / 2,  i = 0 … n+1,
//!
//! i.e. the ZV shaper [1, K]/(1+K) convolved with itself n + 1 times. ZV (n = 0) lasts half a
//! damped period, ZVD (n = 1) one, ZVDD (n = 2) one and a half.

use crate::error::{Error, Result};
use crate::mode::Mode;
use crate::shaper::{Impulse, Shaper};

/// Largest number of derivative constraints accepted by [`zv_dn`].
pub const MAX_DERIVATIVES: u32 = 30;

/// ZV shaper (Singhose 2009 eqs. 14–15): two impulses [1, K]/(1+K) at [0, T_d/2].
pub fn zv(mode: &Mode) -> Result<Shaper> {
    zv_dn(mode, 0)
}

/// ZVD shaper (Singhose 2009 eq. 17): [1, 2K, K²]/(1+K)² at [0, T_d/2, T_d].
pub fn zvd(mode: &Mode) -> Result<Shaper> {
    zv_dn(mode, 1)
}

/// ZVDD shaper (Singer & Seering 1988 eq. 8): [1, 3K, 3K², K³]/(1+K)³ at i·T_d/2.
pub fn zvdd(mode: &Mode) -> Result<Shaper> {
    zv_dn(mode, 2)
}

/// ZV-Dⁿ: zero vibration and `derivatives` zero derivatives at the mode; binomial amplitudes in
/// K, impulses every half damped period.
pub fn zv_dn(mode: &Mode, derivatives: u32) -> Result<Shaper> {
    if derivatives > MAX_DERIVATIVES {
        return Err(Error::TooLarge {
            field: "derivatives".into(),
            value: derivatives as f64,
            limit: MAX_DERIVATIVES as f64,
        });
    }
    let k = mode.half_period_decay();
    let half = mode.damped_period_s() / 2.0;
    let n = derivatives as usize + 1;
    let norm = (1.0 + k).powi(n as i32);
    let mut binomial = 1.0_f64;
    let impulses = (0..=n)
        .map(|i| {
            if i > 0 {
                binomial = binomial * (n + 1 - i) as f64 / i as f64;
            }
            Impulse {
                time: i as f64 * half,
                amplitude: binomial * k.powi(i as i32) / norm,
            }
        })
        .collect();
    Shaper::new(impulses)
}
