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
///
/// ```
/// use input_shaping::{design::zero_vibration::zv, vibration::residual_vibration, Mode};
/// let mode = Mode::new(10.0, 0.0)?; // undamped: K = 1, so [1, 1]/2 at [0, T/2]
/// let shaper = zv(&mode)?;
/// let i = shaper.impulses();
/// assert_eq!(i.len(), 2);
/// assert!((i[0].amplitude - 0.5).abs() < 1e-12 && (i[1].amplitude - 0.5).abs() < 1e-12);
/// assert!((i[1].time - 0.05).abs() < 1e-12);
/// assert!(residual_vibration(&shaper, &mode) < 1e-12);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn zv(mode: &Mode) -> Result<Shaper> {
    zv_dn(mode, 0)
}

/// ZVD shaper (Singhose 2009 eq. 17): [1, 2K, K²]/(1+K)² at [0, T_d/2, T_d].
///
/// ```
/// use input_shaping::{design::zero_vibration::zvd, Mode};
/// let mode = Mode::new(2.0, 0.1)?;
/// let k = (-0.1 * std::f64::consts::PI / (1.0_f64 - 0.01).sqrt()).exp();
/// let shaper = zvd(&mode)?;
/// let a: Vec<f64> = shaper.impulses().iter().map(|i| i.amplitude).collect();
/// let expected = [1.0, 2.0 * k, k * k].map(|x| x / ((1.0 + k) * (1.0 + k)));
/// assert!(a.iter().zip(expected).all(|(a, e)| (a - e).abs() < 1e-12));
/// assert!((shaper.duration() - mode.damped_period_s()).abs() < 1e-12);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn zvd(mode: &Mode) -> Result<Shaper> {
    zv_dn(mode, 1)
}

/// ZVDD shaper (Singer & Seering 1988 eq. 8): [1, 3K, 3K², K³]/(1+K)³ at i·T_d/2.
///
/// ```
/// use input_shaping::{design::zero_vibration::zvdd, Mode};
/// let shaper = zvdd(&Mode::new(1.0, 0.0)?)?; // undamped: [1, 3, 3, 1]/8 every half period
/// let a: Vec<f64> = shaper.impulses().iter().map(|i| i.amplitude).collect();
/// assert!(a.iter().zip([1.0, 3.0, 3.0, 1.0]).all(|(a, e)| (a - e / 8.0).abs() < 1e-12));
/// assert!((shaper.duration() - 1.5).abs() < 1e-12);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn zvdd(mode: &Mode) -> Result<Shaper> {
    zv_dn(mode, 2)
}

/// ZV-Dⁿ: zero vibration and `derivatives` zero derivatives at the mode; binomial amplitudes in
/// K, impulses every half damped period.
///
/// ```
/// use input_shaping::{design::zero_vibration::zv_dn, vibration::residual_vibration, Mode};
/// let mode = Mode::new(1.0, 0.0)?;
/// let shaper = zv_dn(&mode, 3)?; // 5 impulses, binomial [1, 4, 6, 4, 1]/16
/// assert_eq!(shaper.len(), 5);
/// assert!((shaper.impulses()[2].amplitude - 6.0 / 16.0).abs() < 1e-12);
/// // Undamped, V(f) = |cos(πf/2f₀)|⁴: four zero derivatives flatten it at the mode.
/// let off = Mode::new(1.1, 0.0)?;
/// let v = (0.55 * std::f64::consts::PI).cos().abs().powi(4);
/// assert!((residual_vibration(&shaper, &off) - v).abs() < 1e-12);
/// # Ok::<(), input_shaping::Error>(())
/// ```
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
