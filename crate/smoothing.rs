//! Klipper-compatible smoothing and maximum acceleration of a shaper.
//!
//! Klipper's `calibrate_shaper` reports, for each shaper, a "smoothing" figure (the positional
//! offset in mm that the shaper introduces at a 90° or 180° corner at a given acceleration) and a
//! suggested `max_accel` (the acceleration at which smoothing reaches 0.12 mm). Printer users
//! compare shapers with these numbers, so we compute them with Klipper's own definitions
//! (klippy/extras/shaper_calibrate.py, `_get_shaper_smoothing`, `find_shaper_max_accel`,
//! `_bisect`, mainline Klipper3d/klipper), including its defaults: accel = 5000 mm/s²,
//! square corner velocity scv = 5 mm/s, target smoothing 0.12 mm.
//!
//! With Aᵢ, tᵢ the shaper, D = Σ Aᵢ and t_s = Σ Aᵢtᵢ / D its centroid:
//! - offset₉₀ = √2/D · Σ_{tᵢ ≥ t_s} Aᵢ (scv + a/2 (tᵢ − t_s)) (tᵢ − t_s)
//! - offset₁₈₀ = 1/D · Σ Aᵢ a/2 (tᵢ − t_s)²
//! - smoothing = max(offset₉₀, offset₁₈₀)

use crate::error::{finite, Error, Result};
use crate::shaper::Shaper;
use serde::{Deserialize, Serialize};

/// Klipper's default acceleration for the reported smoothing, mm/s².
pub const KLIPPER_ACCEL: f64 = 5000.0;
/// Klipper's default square corner velocity, mm/s.
pub const KLIPPER_SCV: f64 = 5.0;
/// Klipper's target smoothing for the suggested maximum acceleration, mm.
pub const KLIPPER_TARGET_SMOOTHING: f64 = 0.12;

/// Klipper's smoothing figures of a shaper.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct KlipperFigures {
    /// Smoothing in mm at [`KLIPPER_ACCEL`] and the given scv.
    pub smoothing: f64,
    /// Suggested maximum acceleration in mm/s² (smoothing = 0.12 mm); 0 if even a tiny
    /// acceleration exceeds it.
    pub max_accel: f64,
}

/// Smoothing (mm) of `shaper` at acceleration `accel` (mm/s²) and square corner velocity `scv`
/// (mm/s), as Klipper's `_get_shaper_smoothing`. Times are in seconds.
///
/// ```
/// use input_shaping::{design::zero_vibration::zv, smoothing::smoothing, Mode};
/// // Smoothing grows with the acceleration: Klipper's trade-off of a longer shaper.
/// let shaper = zv(&Mode::new(40.0, 0.1)?)?;
/// let (low, high) = (smoothing(&shaper, 3000.0, 5.0)?, smoothing(&shaper, 6000.0, 5.0)?);
/// assert!(0.0 < low && low < high);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn smoothing(shaper: &Shaper, accel: f64, scv: f64) -> Result<f64> {
    in_range("accel", accel)?;
    Moments::of(shaper, scv)?.checked_smoothing(accel)
}

/// Largest acceleration or square corner velocity accepted (mm/s², mm/s).
pub const MAX_FIGURE_INPUT: f64 = 1e12;

/// Checks that an acceleration or velocity is finite and in [0, [`MAX_FIGURE_INPUT`]].
fn in_range(field: &str, value: f64) -> Result<f64> {
    finite(field, value)?;
    if !(0.0..=MAX_FIGURE_INPUT).contains(&value) {
        return Err(Error::invalid(
            field,
            format!("must lie between 0 and {MAX_FIGURE_INPUT:e}, got {value}"),
        ));
    }
    Ok(value)
}

/// Klipper's suggested maximum acceleration: the largest `accel` with smoothing ≤ 0.12 mm,
/// found by Klipper's own bisection (`_bisect`, to 1e-8 mm/s²), bounded to 4096 steps.
///
/// A shaper of zero duration (a single impulse) never smooths: its maximum acceleration is
/// unbounded and `f64::INFINITY` is returned (`null` in JS). The search stops at
/// [`MAX_FIGURE_INPUT`] (10¹² mm/s²), which is returned if smoothing is still below target there.
///
/// ```
/// use input_shaping::{design::modified::mzv, smoothing::{max_accel, smoothing}, Mode};
/// // The largest acceleration whose smoothing is Klipper's 0.12 mm.
/// let shaper = mzv(&Mode::new(50.0, 0.1)?)?;
/// let accel = max_accel(&shaper, 5.0)?;
/// assert!((smoothing(&shaper, accel, 5.0)? - 0.12).abs() < 1e-6);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn max_accel(shaper: &Shaper, scv: f64) -> Result<f64> {
    if shaper.duration() == 0.0 {
        in_range("scv", scv)?;
        return Ok(f64::INFINITY);
    }
    // Smoothing is linear in the acceleration on each side of the centroid (see
    // [`smoothing`]): three sums over the impulses, formed once, serve every step of the
    // bisection (~60), where each step walked the impulses (15 625 for ZV-D³ over six modes).
    let moments = Moments::of(shaper, scv)?;
    let ok =
        |a: f64| -> Result<bool> { Ok(moments.checked_smoothing(a)? <= KLIPPER_TARGET_SMOOTHING) };
    if !ok(1e-9)? {
        return Ok(0.0);
    }
    let (mut left, mut right) = (1.0_f64, 1.0_f64);
    let mut steps = 0;
    while !ok(left)? && steps < 4096 {
        right = left;
        left *= 0.5;
        steps += 1;
    }
    if right == left {
        while ok(right)? && steps < 4096 {
            if right >= MAX_FIGURE_INPUT {
                // Smoothing stays below target up to the largest acceleration accepted.
                return Ok(MAX_FIGURE_INPUT);
            }
            right = (right * 2.0).min(MAX_FIGURE_INPUT);
            steps += 1;
        }
    }
    while right - left > 1e-8 && steps < 4096 {
        let middle = 0.5 * (left + right);
        if ok(middle)? {
            left = middle;
        } else {
            right = middle;
        }
        steps += 1;
    }
    Ok(left)
}

/// The sums behind [`smoothing`], with the acceleration factored out: with dt = t − t_s,
/// o90 = scv·Σ_{t≥t_s} A dt + a/2·Σ_{t≥t_s} A dt², o180 = a/2·Σ A dt². Smoothing is linear in
/// the acceleration on each side of that split, so one pass over the impulses serves every
/// acceleration (the bisection of [`max_accel`] takes ~60).
struct Moments {
    sum: f64,
    scv: f64,
    late1: f64,
    late2: f64,
    all2: f64,
}

impl Moments {
    fn of(shaper: &Shaper, scv: f64) -> Result<Self> {
        in_range("scv", scv)?;
        let sum = shaper.amplitude_sum();
        let ts = shaper.centroid_delay().ok_or_else(|| {
            Error::invalid(
                "impulses",
                "the amplitudes sum to zero; smoothing is undefined",
            )
        })?;
        let (mut late1, mut late2, mut all2) = (0.0, 0.0, 0.0);
        for imp in shaper.impulses() {
            let dt = imp.time - ts;
            if imp.time >= ts {
                late1 += imp.amplitude * dt;
                late2 += imp.amplitude * dt * dt;
            }
            all2 += imp.amplitude * dt * dt;
        }
        Ok(Moments {
            sum,
            scv,
            late1,
            late2,
            all2,
        })
    }

    /// [`smoothing`] at acceleration `a`: max(√2·o90, o180) / Σ A, or an error if it overflows.
    fn checked_smoothing(&self, a: f64) -> Result<f64> {
        let half = 0.5 * a;
        let o90 = self.scv * self.late1 + half * self.late2;
        let smoothing =
            (o90 * std::f64::consts::SQRT_2 / self.sum).max(half * self.all2 / self.sum);
        if smoothing.is_finite() {
            Ok(smoothing)
        } else {
            Err(Error::invalid(
                "impulses",
                format!("smoothing overflows ({smoothing}) for this shaper at {a} mm/s²"),
            ))
        }
    }
}

/// Both figures at Klipper's defaults (accel 5000 mm/s² for smoothing), with `scv` in mm/s.
///
/// ```
/// use input_shaping::{design::zero_vibration::zvd, smoothing::*, Mode};
/// let shaper = zvd(&Mode::new(45.0, 0.1)?)?;
/// let figures = klipper_figures(&shaper, 5.0)?;
/// assert_eq!(figures.smoothing, smoothing(&shaper, KLIPPER_ACCEL, 5.0)?);
/// assert_eq!(figures.max_accel, max_accel(&shaper, 5.0)?);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn klipper_figures(shaper: &Shaper, scv: f64) -> Result<KlipperFigures> {
    Ok(KlipperFigures {
        smoothing: smoothing(shaper, KLIPPER_ACCEL, scv)?,
        max_accel: max_accel(shaper, scv)?,
    })
}
