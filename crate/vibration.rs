//! Residual vibration V(ω, ζ) of a shaper, and what is built on it: sensitivity curves and the
//! insensitivity band.
//!
//! [`vibration_rad`] is the one implementation of Singhose 2009 eq. 11; every curve, chart,
//! metric and design check calls it.

use crate::error::{count, finite, positive, Error, Result};
use crate::mode::Mode;
use crate::shaper::{Impulse, Shaper};
use serde::{Deserialize, Serialize};

/// Most points a sensitivity curve may have.
pub const MAX_CURVE_POINTS: usize = 100_000;

/// Residual vibration of an impulse sequence on a mode of undamped natural frequency `omega`
/// (rad/s) and damping ratio `zeta`, relative to the vibration a single unit impulse leaves
/// (Singhose 2009 eqs. 7–11):
///
/// V = e^{−ζω t_n} √(C² + S²),  C = Σ Aᵢ e^{ζω tᵢ} cos(ω_d tᵢ),  S = Σ Aᵢ e^{ζω tᵢ} sin(ω_d tᵢ).
///
/// The exponentials are evaluated as e^{−ζω(t_n − tᵢ)} so nothing overflows. `omega ≥ 0` and
/// `0 ≤ zeta < 1` are the caller's to ensure; with ω = 0 the result is |Σ Aᵢ|.
pub fn vibration_rad(impulses: &[Impulse], omega: f64, zeta: f64) -> f64 {
    let [c, s] = vibration_moment(impulses, omega, zeta, 0);
    c.hypot(s)
}

/// The k-th time moment of the vibration phasor of eq. 11:
///
/// M_k = e^{−ζω t_n} Σ Aᵢ tᵢᵏ e^{ζω tᵢ} (cos ω_d tᵢ, sin ω_d tᵢ),  so V = |M₀|.
///
/// With p = ζω + iω_d, the vibration sum is W(ω) = Σ Aᵢ e^{p tᵢ} and
/// dᵏW/dωᵏ = (ζ + i√(1−ζ²))ᵏ Σ Aᵢ tᵢᵏ e^{p tᵢ}: M₀ = … = M_n = 0 is exactly "zero vibration and n
/// zero frequency derivatives" at (ω, ζ) (Singer & Seering 1988 §2.2; Singhose 2009 eq. 16).
/// The multi-mode direct designs impose these as linear equalities. `t_n` is the last impulse's
/// time, as in [`vibration_rad`].
pub fn vibration_moment(impulses: &[Impulse], omega: f64, zeta: f64, k: u32) -> [f64; 2] {
    let t_n = impulses.last().map_or(0.0, |imp| imp.time);
    let (mut c, mut s) = (0.0, 0.0);
    for imp in impulses {
        let [pc, ps] = impulse_phasor(imp.time, t_n, omega, zeta);
        let w = if k == 0 {
            imp.amplitude
        } else {
            imp.amplitude * imp.time.powi(k as i32)
        };
        c += w * pc;
        s += w * ps;
    }
    [c, s]
}

/// The contribution of a unit impulse at `time` to the vibration phasor of eq. 11 when the last
/// impulse of the sequence is at `t_n`: e^{−ζω(t_n − t)} (cos ω_d t, sin ω_d t). V is the length
/// of Σ Aᵢ · phasor(tᵢ), so once the times are fixed V is the norm of a vector linear in the
/// amplitudes (what the convex design programs of [`crate::solve`] use).
pub fn impulse_phasor(time: f64, t_n: f64, omega: f64, zeta: f64) -> [f64; 2] {
    let omega_d = omega * (1.0 - zeta * zeta).sqrt();
    let e = (-zeta * omega * (t_n - time)).exp();
    let (sin, cos) = (omega_d * time).sin_cos();
    [e * cos, e * sin]
}

/// Residual vibration V of `shaper` on `mode` (fraction: 0 = none, 1 = as much as unshaped).
pub fn residual_vibration(shaper: &Shaper, mode: &Mode) -> f64 {
    vibration_rad(shaper.impulses(), mode.omega_rad_s(), mode.damping())
}

/// Options of a sensitivity curve V(f) at a fixed damping ratio.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct SensitivityOptions {
    /// First frequency in Hz (≥ 0).
    pub from_hz: f64,
    /// Last frequency in Hz (> `from_hz`).
    pub to_hz: f64,
    /// Number of evenly spaced frequencies, 2 … [`MAX_CURVE_POINTS`].
    pub points: usize,
    /// Damping ratio of the plant the curve is evaluated on, 0 ≤ ζ < 1.
    #[serde(default)]
    pub damping: f64,
}

/// A sensitivity curve: V at evenly spaced frequencies.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct SensitivityCurve {
    /// Frequencies in Hz.
    pub frequency_hz: Vec<f64>,
    /// Residual vibration (fraction) at each frequency.
    pub vibration: Vec<f64>,
}

/// Evenly spaced values from `from` to `to` inclusive (`n ≥ 2`).
pub(crate) fn linspace(from: f64, to: f64, n: usize) -> impl Iterator<Item = f64> {
    let step = (to - from) / (n.max(2) - 1) as f64;
    (0..n).map(move |i| {
        if i + 1 == n {
            to
        } else {
            from + step * i as f64
        }
    })
}

/// Checks a frequency range `from_hz` … `to_hz` (0 ≤ from < to, finite).
pub(crate) fn frequency_range(from_hz: f64, to_hz: f64) -> Result<()> {
    finite("fromHz", from_hz)?;
    finite("toHz", to_hz)?;
    if from_hz < 0.0 {
        return Err(Error::invalid(
            "fromHz",
            format!("must be ≥ 0 Hz, got {from_hz}"),
        ));
    }
    if to_hz <= from_hz {
        return Err(Error::invalid(
            "toHz",
            format!("must be greater than fromHz ({from_hz} Hz), got {to_hz}"),
        ));
    }
    if to_hz > crate::mode::MAX_FREQUENCY_HZ {
        return Err(Error::invalid(
            "toHz",
            format!(
                "must be at most {} Hz, got {to_hz}",
                crate::mode::MAX_FREQUENCY_HZ
            ),
        ));
    }
    Ok(())
}

/// Checks a damping ratio 0 ≤ ζ < 1 given in field `field`.
pub(crate) fn damping_ratio(field: &str, zeta: f64) -> Result<f64> {
    finite(field, zeta)?;
    if (0.0..1.0).contains(&zeta) {
        Ok(zeta)
    } else {
        Err(Error::invalid(
            field,
            format!("damping ratio must satisfy 0 ≤ ζ < 1, got {zeta}"),
        ))
    }
}

/// The sensitivity curve V(f) of `shaper` over a frequency range at one damping ratio
/// (Singhose 2009 Fig. 7).
pub fn sensitivity(shaper: &Shaper, options: &SensitivityOptions) -> Result<SensitivityCurve> {
    frequency_range(options.from_hz, options.to_hz)?;
    count("points", options.points, 2, MAX_CURVE_POINTS)?;
    let zeta = damping_ratio("damping", options.damping)?;
    let frequency_hz: Vec<f64> = linspace(options.from_hz, options.to_hz, options.points).collect();
    let vibration = frequency_hz
        .iter()
        .map(|&f| vibration_rad(shaper.impulses(), 2.0 * std::f64::consts::PI * f, zeta))
        .collect();
    Ok(SensitivityCurve {
        frequency_hz,
        vibration,
    })
}

/// The insensitivity band of a shaper around a mode: the contiguous range of frequencies
/// containing the mode's frequency where V ≤ Vtol.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct Insensitivity {
    /// Lower band edge in Hz.
    pub low_hz: f64,
    /// Upper band edge in Hz.
    pub high_hz: f64,
    /// Band width as a fraction of the mode's frequency, I = (high − low)/f (Singhose 2009
    /// §3.1). 0 when V exceeds Vtol at the mode itself.
    pub width: f64,
}

/// Relative slack on Vtol when tracing a band, so that EI humps designed to touch Vtol exactly
/// do not split the band through rounding.
const VTOL_SLACK: f64 = 1e-9;
/// Upper band edges are searched up to this multiple of the mode's frequency.
const MAX_BAND_RATIO: f64 = 50.0;

/// Frequency insensitivity I(Vtol) of `shaper` at `mode` (damping held at the mode's): the
/// band edges are bracketed by a scan fine enough for the shaper's duration and refined by
/// bisection to machine precision.
pub fn insensitivity(shaper: &Shaper, mode: &Mode, vtol: f64) -> Result<Insensitivity> {
    positive("vtol", vtol)?;
    if vtol >= 1.0 {
        return Err(Error::invalid(
            "vtol",
            format!("tolerable vibration must be below 1 (100 %), got {vtol}"),
        ));
    }
    let f_m = mode.frequency_hz();
    let zeta = mode.damping();
    let threshold = vtol * (1.0 + VTOL_SLACK) + 1e-14;
    let excess =
        |f: f64| vibration_rad(shaper.impulses(), 2.0 * std::f64::consts::PI * f, zeta) - threshold;
    if excess(f_m) > 0.0 {
        return Ok(Insensitivity {
            low_hz: f_m,
            high_hz: f_m,
            width: 0.0,
        });
    }
    // V oscillates in f with period ~1/duration; sample it at least 40 times per period.
    let step = (0.0025 * f_m).min(1.0 / (40.0 * shaper.duration().max(f64::MIN_POSITIVE)));
    // At most ~2·10⁶ evaluations per side, whatever the inputs (coarser scan beyond that).
    let edge = |direction: f64, limit: f64| -> f64 {
        let step = step.max((limit - f_m).abs() / 2e6);
        let mut inside = f_m;
        loop {
            let next = inside + direction * step;
            let beyond = if direction > 0.0 {
                next >= limit
            } else {
                next <= limit
            };
            if beyond {
                return if excess(limit) > 0.0 {
                    bisect(&excess, inside, limit)
                } else {
                    limit
                };
            }
            if excess(next) > 0.0 {
                return bisect(&excess, inside, next);
            }
            inside = next;
        }
    };
    let high_hz = edge(1.0, f_m * MAX_BAND_RATIO);
    let low_hz = edge(-1.0, 0.0);
    Ok(Insensitivity {
        low_hz,
        high_hz,
        width: (high_hz - low_hz) / f_m,
    })
}

/// Bisection for the crossing of `g` between `inside` (g ≤ 0) and `outside` (g > 0).
fn bisect(g: &impl Fn(f64) -> f64, mut inside: f64, mut outside: f64) -> f64 {
    for _ in 0..200 {
        let mid = 0.5 * (inside + outside);
        if mid == inside || mid == outside {
            break;
        }
        if g(mid) > 0.0 {
            outside = mid;
        } else {
            inside = mid;
        }
    }
    0.5 * (inside + outside)
}
