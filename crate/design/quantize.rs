//! Integer realisation of a shaper: amplitudes on an integer resolution (e.g. the 255 steps of an
//! 8-bit PWM) and times on a timer tick, after Peláez & Singhose, "Implementation of Input
//! Shaping on Flexible Machines with Integer Controllers" (IFAC 2002; equation numbers are that
//! paper's). It is a transform applied to any designed shaper, with a report of what rounding
//! cost: V at the mode and the insensitivity I(Vtol) before and after.
//!
//! Two methods:
//!
//! - `largestRemainder` (default; ours, not the paper's): each amplitude becomes kᵢ/N with N =
//!   `amplitudeSteps` and integers kᵢ ∈ {⌊N Aᵢ⌋, ⌈N Aᵢ⌉} whose sum is exactly round(N Σ Aᵢ)
//!   (= N for a unity-gain shaper): the floors are taken and the missing units go to the largest
//!   remainders (Hamilton's method; ties to the earlier impulse). The sum is kept exactly.
//!
//! - `updateTime` (the paper's, eqs. 2–5): the shaped velocity ramp is built by adding one PWM
//!   step every *update time*. While the cumulative amplitude Sₖ = A₁ + … + Aₖ is in force, the
//!   ramp climbs at Sₖ times its nominal slope, so one PWM step takes c/Sₖ ticks, where
//!   c = `rampS` / (`amplitudeSteps` · `tickS`) is the ticks per step of the unshaped ramp
//!   (eq. 4). Rounding that update time to whole ticks (eq. 5) realises the level
//!   S′ₖ = c / round(c/Sₖ), and the realised amplitudes are A′ₖ = S′ₖ − S′ₖ₋₁. The sum is *not*
//!   kept: the paper's eq. 8 sums to 0.9653. A negative level uses |Sₖ| and keeps its sign; a
//!   level that would need more than one step per tick (round(c/|Sₖ|) = 0) is an error.
//!
//! The paper does not state c. Its eq. 8 (the SI shaper of its eq. 7 realised on a 1 ms timer
//! with 255 PWM steps) pins c to [12.5485, 12.5495] ticks, i.e. a 3.2 s unshaped ramp
//! (c = 3200/255); the tests reproduce eq. 8 from eq. 7 with that value.
//!
//! In both methods times are rounded to the nearest multiple of `tickS` first (impulses landing
//! on the same tick merge), then the amplitudes are rounded. Impulses whose amplitude rounds to 0
//! are dropped; if the first one is, the shaper starts at the next (V does not depend on a shift).

use crate::error::{finite, positive, Error, Result};
use crate::mode::Mode;
use crate::shaper::{Impulse, Shaper, ShaperData};
use crate::vibration::{insensitivity, residual_vibration, Insensitivity};
use serde::{Deserialize, Serialize};

/// Largest amplitude resolution accepted (2²⁴: integers stay exact in f64 products).
pub const MAX_AMPLITUDE_STEPS: u32 = 1 << 24;
/// Most ticks a shaper may span (times stay exact multiples of the tick).
const MAX_TICKS: f64 = 1e12;

/// How amplitudes are rounded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum QuantizeMethod {
    /// Multiples of 1/`amplitudeSteps`, sum kept exactly (largest remainder).
    #[default]
    LargestRemainder,
    /// The paper's eqs. 4–5: cumulative levels realised by whole-tick PWM update times.
    UpdateTime,
}

/// Options of [`quantize`], as written in JS (`{ amplitudeSteps, tickS, method, rampS, vtol }`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct QuantizeOptions {
    /// Amplitude resolution N (e.g. 255 for an 8-bit PWM), 1 … [`MAX_AMPLITUDE_STEPS`].
    pub amplitude_steps: u32,
    /// Timer tick in seconds; times are rounded to its multiples. Omitted: times are kept
    /// (required by `updateTime`).
    #[serde(default)]
    pub tick_s: Option<f64>,
    /// Rounding method (default `largestRemainder`).
    #[serde(default)]
    pub method: QuantizeMethod,
    /// `updateTime` only: duration in seconds of the unshaped ramp over all `amplitudeSteps`
    /// (sets c = rampS / (amplitudeSteps · tickS), eq. 4).
    #[serde(default)]
    pub ramp_s: Option<f64>,
    /// Tolerable vibration for the report's insensitivity, fraction in (0, 1); default 0.05.
    #[serde(default = "default_vtol")]
    pub vtol: f64,
}

fn default_vtol() -> f64 {
    0.05
}

impl QuantizeOptions {
    /// Largest-remainder rounding to `amplitude_steps`, times kept, Vtol 5 %.
    pub fn new(amplitude_steps: u32) -> Self {
        QuantizeOptions {
            amplitude_steps,
            tick_s: None,
            method: QuantizeMethod::LargestRemainder,
            ramp_s: None,
            vtol: default_vtol(),
        }
    }
}

/// The rounded shaper and what rounding cost at one mode.
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct QuantizeReport {
    /// The rounded shaper, `{ impulses, duration }`.
    #[serde(flatten)]
    pub shaper: ShaperData,
    /// Σ A of the rounded shaper (1 for `largestRemainder` on a unity-gain shaper).
    pub amplitude_sum: f64,
    /// Vtol used for the insensitivities.
    pub vtol: f64,
    /// V at the mode before rounding.
    pub vibration_before: f64,
    /// V at the mode after rounding.
    pub vibration_after: f64,
    /// I(Vtol) around the mode before rounding.
    pub insensitivity_before: Insensitivity,
    /// I(Vtol) around the mode after rounding.
    pub insensitivity_after: Insensitivity,
}

/// Rounds `shaper`'s times to the tick and its amplitudes to the resolution of `options`.
///
/// ```
/// use input_shaping::design::quantize::{quantize, QuantizeOptions};
/// use input_shaping::{design::zero_vibration::zvd, Mode};
/// // Amplitudes in steps of 1/255 (an 8-bit PWM) that still sum to exactly 255/255.
/// let rounded = quantize(&zvd(&Mode::new(2.0, 0.05)?)?, &QuantizeOptions::new(255))?;
/// let steps: Vec<f64> = rounded.impulses().iter().map(|i| i.amplitude * 255.0).collect();
/// assert!(steps.iter().all(|k| (k - k.round()).abs() < 1e-9));
/// assert!((steps.iter().sum::<f64>() - 255.0).abs() < 1e-9);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn quantize(shaper: &Shaper, options: &QuantizeOptions) -> Result<Shaper> {
    if options.amplitude_steps == 0 {
        return Err(Error::invalid(
            "amplitudeSteps",
            "must be at least 1, got 0",
        ));
    }
    if options.amplitude_steps > MAX_AMPLITUDE_STEPS {
        return Err(Error::TooLarge {
            field: "amplitudeSteps".into(),
            value: f64::from(options.amplitude_steps),
            limit: f64::from(MAX_AMPLITUDE_STEPS),
        });
    }
    let on_grid = match options.tick_s {
        Some(tick) => round_times(shaper, positive("tickS", tick)?)?,
        None => shaper.clone(),
    };
    let steps = f64::from(options.amplitude_steps);
    let amplitudes: Vec<f64> = on_grid.impulses().iter().map(|i| i.amplitude).collect();
    let rounded = match options.method {
        QuantizeMethod::LargestRemainder => largest_remainder(&amplitudes, steps),
        QuantizeMethod::UpdateTime => {
            let tick = options.tick_s.ok_or_else(|| {
                Error::invalid("tickS", "the updateTime method needs the timer tick")
            })?;
            let ramp = options.ramp_s.ok_or_else(|| {
                Error::invalid(
                    "rampS",
                    "the updateTime method needs the unshaped ramp's duration",
                )
            })?;
            let c = positive("rampS", ramp)? / (steps * tick);
            if !c.is_finite() || c > MAX_TICKS {
                return Err(Error::invalid(
                    "rampS",
                    format!("gives {c} ticks per PWM step; at most {MAX_TICKS}"),
                ));
            }
            update_time(&amplitudes, c)?
        }
    };
    let impulses: Vec<Impulse> = on_grid
        .impulses()
        .iter()
        .zip(rounded)
        .map(|(imp, amplitude)| Impulse {
            time: imp.time,
            amplitude,
        })
        .collect();
    if impulses.iter().all(|i| i.amplitude == 0.0) {
        return Err(Error::invalid(
            "amplitudeSteps",
            format!(
                "{} steps are too coarse: every amplitude rounds to 0",
                options.amplitude_steps
            ),
        ));
    }
    Shaper::new(impulses)
}

/// Quantises and reports V at `mode` and I(`options.vtol`) before and after.
///
/// ```
/// use input_shaping::design::quantize::{quantize_with_report, QuantizeOptions};
/// use input_shaping::{design::zero_vibration::zvd, Mode};
/// let mode = Mode::new(2.0, 0.05)?;
/// let report = quantize_with_report(&zvd(&mode)?, &mode, &QuantizeOptions::new(16))?;
/// assert!(report.vibration_before < 1e-12); // ZVD cancels the mode; rounding costs a little
/// assert!(report.vibration_after > 0.0 && report.vibration_after < 0.05);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn quantize_with_report(
    shaper: &Shaper,
    mode: &Mode,
    options: &QuantizeOptions,
) -> Result<QuantizeReport> {
    let vtol = finite("vtol", options.vtol)?;
    let insensitivity_before = insensitivity(shaper, mode, vtol)?;
    let rounded = quantize(shaper, options)?;
    let insensitivity_after = insensitivity(&rounded, mode, vtol)?;
    Ok(QuantizeReport {
        amplitude_sum: rounded.amplitude_sum(),
        vtol,
        vibration_before: residual_vibration(shaper, mode),
        vibration_after: residual_vibration(&rounded, mode),
        insensitivity_before,
        insensitivity_after,
        shaper: rounded.to_data(),
    })
}

/// Times to the nearest multiple of `tick` (impulses on the same tick merge); errors name
/// `tickS`.
pub(crate) fn round_times(shaper: &Shaper, tick: f64) -> Result<Shaper> {
    if shaper.duration() / tick > MAX_TICKS {
        return Err(Error::invalid(
            "tickS",
            format!(
                "{tick} s is too fine for a {} s shaper (more than {MAX_TICKS} ticks)",
                shaper.duration()
            ),
        ));
    }
    Shaper::new(
        shaper
            .impulses()
            .iter()
            .map(|imp| Impulse {
                time: (imp.time / tick).round() * tick,
                amplitude: imp.amplitude,
            })
            .collect(),
    )
}

/// Hamilton's largest-remainder rounding of `amplitudes` to multiples of 1/`steps`, keeping the
/// integer sum at round(steps · Σ amplitudes).
fn largest_remainder(amplitudes: &[f64], steps: f64) -> Vec<f64> {
    let scaled: Vec<f64> = amplitudes.iter().map(|a| a * steps).collect();
    let mut units: Vec<f64> = scaled.iter().map(|x| x.floor()).collect();
    let target = scaled.iter().sum::<f64>().round();
    let missing = (target - units.iter().sum::<f64>()).max(0.0) as usize;
    let mut order: Vec<usize> = (0..scaled.len()).collect();
    // Largest remainder first; ties to the earlier impulse (stable sort).
    crate::sort::sort_indices(&mut order, &|i, j| {
        (scaled[j] - units[j]).total_cmp(&(scaled[i] - units[i]))
    });
    for &i in order.iter().take(missing) {
        units[i] += 1.0;
    }
    units.iter().map(|k| k / steps).collect()
}

/// Peláez & Singhose eqs. 4–5: the cumulative levels Sₖ realised as c / round(c / Sₖ).
fn update_time(amplitudes: &[f64], c: f64) -> Result<Vec<f64>> {
    let mut level = 0.0;
    let mut realised_before = 0.0;
    let mut out = Vec::with_capacity(amplitudes.len());
    for (k, a) in amplitudes.iter().enumerate() {
        level += a;
        let realised = if level == 0.0 {
            0.0
        } else {
            let ticks = (c / level.abs()).round();
            if ticks < 1.0 {
                return Err(Error::Infeasible {
                    reason: format!(
                        "after impulse {k} the ramp needs a PWM step every {:.3} ticks; the \
                         timer gives at most one per tick (raise rampS)",
                        c / level.abs()
                    ),
                });
            }
            level.signum() * c / ticks
        };
        out.push(realised - realised_before);
        realised_before = realised;
    }
    Ok(out)
}
