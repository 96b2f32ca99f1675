//! The command spectrum |U(f)|: where a command puts its energy, and whether it is zero at the
//! machine's modes (Veciana & Cardona 2011 §2: zero content at f₀ means no residual vibration
//! of an undamped mode at f₀; Singhose 2009: a shaper's spectrum is its V(ω, 0) curve).
//!
//! - impulse trains (shapers): U(f) = Σ Aᵢ e^{−i2πf tᵢ}, exactly;
//! - piecewise polynomials, from the jump form: the k-th-derivative jump J at τ contributes
//!   J e^{−iωτ}(iω)^{r−k−1} to the spectrum of the r-th derivative (r = 0 position, 1 velocity,
//!   2 acceleration). Where that sum cancels badly (ωT < 2 for a signal that starts and ends
//!   at zero) the integral is taken instead by Gauss–Legendre quadrature on each polynomial
//!   piece, exact up to rounding;
//! - sampled signals: the exact transform of the interpolated signal, evaluated at each
//!   requested frequency by Horner's rule on the samples (a DTFT times the interpolation
//!   kernel), O(samples × points), capped.
//!
//! The default signal is the **velocity**: it is compactly supported for rest-to-rest moves,
//! and a step's velocity is a Dirac, so a shaped step's spectrum is the shaper's own.

use crate::command::{Command, Sampled};
use crate::error::{count, Error, Result};
use crate::piecewise::{taylor_shift, Cursor, Piecewise};
use crate::shaper::Shaper;
use crate::vibration::{frequency_range, linspace, shaper_on_grid};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Most frequencies in one spectrum.
pub const MAX_SPECTRUM_POINTS: usize = 100_000;
/// Most (samples × frequencies) products for sampled signals (and 16 × knots × frequencies
/// for piecewise ones).
pub const MAX_SAMPLED_WORK: f64 = 2e8;

/// Which signal's spectrum: the command (position), its velocity or its acceleration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum SpectrumSignal {
    /// The position command u.
    Position,
    /// Its velocity u' (default).
    #[default]
    Velocity,
    /// Its acceleration u''.
    Acceleration,
}

impl SpectrumSignal {
    fn order(self) -> i32 {
        match self {
            SpectrumSignal::Position => 0,
            SpectrumSignal::Velocity => 1,
            SpectrumSignal::Acceleration => 2,
        }
    }
}

/// Frequencies at which to evaluate a spectrum.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct SpectrumOptions {
    /// First frequency in Hz (≥ 0, default 0).
    #[serde(default)]
    pub from_hz: f64,
    /// Last frequency in Hz.
    pub to_hz: f64,
    /// Number of evenly spaced frequencies, 2 … [`MAX_SPECTRUM_POINTS`] (default 512).
    #[serde(default = "default_points")]
    pub points: usize,
    /// `"velocity"` (default), `"position"` or `"acceleration"`.
    #[serde(default)]
    pub signal: SpectrumSignal,
}

pub(crate) fn default_points() -> usize {
    512
}

/// |U(f)| at evenly spaced frequencies. Magnitudes are in (signal units)·s; where the
/// transform is infinite (a position that does not return to 0, at f = 0) the value is +∞.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Spectrum {
    /// Frequencies in Hz.
    pub frequency_hz: Vec<f64>,
    /// Magnitudes |U(f)|.
    pub magnitude: Vec<f64>,
}

fn grid(options: &SpectrumOptions) -> Result<Vec<f64>> {
    frequency_range(options.from_hz, options.to_hz)?;
    count("points", options.points, 2, MAX_SPECTRUM_POINTS)?;
    Ok(linspace(options.from_hz, options.to_hz, options.points).collect())
}

/// |Σ Aᵢ e^{−i2πf tᵢ}| of a shaper (the spectrum of the shaped step's velocity per unit
/// distance). `options.signal` is ignored.
///
/// This is V(f, ζ = 0) of Singhose 2009 eq. 11, √(C² + S²) with no damping factor (the sign
/// of the phase does not change the modulus), so it is evaluated on the grid by
/// [`vibration_on_grid`](crate::vibration::vibration_on_grid)'s recurrence: a complex
/// multiplication per impulse and frequency instead of a sine and a cosine (per impulse of each
/// convolution factor, see [`Shaper`]).
pub fn impulse_spectrum(shaper: &Shaper, options: &SpectrumOptions) -> Result<Spectrum> {
    let f = grid(options)?;
    let step = (options.to_hz - options.from_hz) / (options.points - 1) as f64;
    let mut magnitude = Vec::with_capacity(f.len());
    shaper_on_grid(shaper, options.from_hz, step, f.len(), 0.0, &mut magnitude);
    Ok(Spectrum {
        frequency_hz: f,
        magnitude,
    })
}

/// Complex number as (re, im).
type C = (f64, f64);

fn cmul(a: C, b: C) -> C {
    (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
}

/// (iω)^n for integer n (ω ≠ 0 when n < 0).
fn i_omega_pow(w: f64, n: i32) -> C {
    let m = w.powi(n);
    match n.rem_euclid(4) {
        0 => (m, 0.0),
        1 => (0.0, m),
        2 => (-m, 0.0),
        _ => (0.0, -m),
    }
}

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on Pₙ).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// Spectrum of a piecewise-polynomial command's position, velocity or acceleration.
pub fn piecewise_spectrum(p: &Piecewise, options: &SpectrumOptions) -> Result<Spectrum> {
    let f = grid(options)?;
    let work = 16.0 * p.knots().len() as f64 * f.len() as f64;
    if work > MAX_SAMPLED_WORK {
        return Err(Error::TooLarge {
            field: "points".into(),
            value: work,
            limit: MAX_SAMPLED_WORK,
        });
    }
    let r = options.signal.order();
    let span = p.end_time() - p.start_time();
    let final_state = p.final_state();
    // The r-th derivative returns to 0 after the move: its transform is an ordinary integral.
    let compact = final_state
        .iter()
        .skip(r as usize)
        .all(|v| v.abs() <= 1e-12 * final_state.iter().fold(1e-300_f64, |m, x| m.max(x.abs())));
    let nodes = gauss_legendre(16);
    // Taylor state at the start of each piece.
    let mut pieces = Vec::with_capacity(p.knots().len());
    let mut cursor = Cursor::new(p);
    for k in p.knots() {
        cursor.seek(k.time);
        pieces.push((k.time, cursor.state_at(k.time)));
    }
    let deg = p.degree();
    let magnitude = f
        .iter()
        .map(|&fi| {
            let w = 2.0 * PI * fi;
            let mut sum: C = (0.0, 0.0);
            if compact && w * span < 2.0 {
                // Dirac terms (k ≥ r: jumps below order r become Diracs in the r-th derivative).
                for k in p.knots() {
                    let rot = ((w * k.time).cos(), -(w * k.time).sin());
                    for (order, &j) in k.jumps.iter().enumerate().take(r as usize) {
                        let t = cmul(rot, i_omega_pow(w, r - order as i32 - 1));
                        sum.0 += j * t.0;
                        sum.1 += j * t.1;
                    }
                }
                for (i, (t0, s)) in pieces.iter().enumerate() {
                    let Some((t1, _)) = pieces.get(i + 1) else {
                        break;
                    };
                    let half = 0.5 * (t1 - t0);
                    for &(x, wt) in &nodes {
                        let t = t0 + half * (x + 1.0);
                        let g = taylor_shift(s, deg, t - t0)[r as usize];
                        sum.0 += half * wt * g * (w * t).cos();
                        sum.1 -= half * wt * g * (w * t).sin();
                    }
                }
            } else {
                if w == 0.0 {
                    return f64::INFINITY;
                }
                for k in p.knots() {
                    let rot = ((w * k.time).cos(), -(w * k.time).sin());
                    for (order, &j) in k.jumps.iter().enumerate() {
                        if j != 0.0 {
                            let t = cmul(rot, i_omega_pow(w, r - order as i32 - 1));
                            sum.0 += j * t.0;
                            sum.1 += j * t.1;
                        }
                    }
                }
            }
            crate::vibration::magnitude(sum.0, sum.1)
        })
        .collect();
    Ok(Spectrum {
        frequency_hz: f,
        magnitude,
    })
}

/// Spectrum of a sampled command read with its interpolation (exact transform of the
/// interpolated signal). Errors when samples × points exceeds [`MAX_SAMPLED_WORK`].
pub fn sampled_spectrum(s: &Sampled, options: &SpectrumOptions) -> Result<Spectrum> {
    let f = grid(options)?;
    let x = s.values();
    let work = x.len() as f64 * f.len() as f64;
    if work > MAX_SAMPLED_WORK {
        return Err(Error::TooLarge {
            field: "points".into(),
            value: work,
            limit: MAX_SAMPLED_WORK,
        });
    }
    let period = s.period();
    let r = options.signal.order();
    // Velocity as Diracs (hold: the steps) or as constant slopes on each interval (linear);
    // coefficient c_k at t = kT.
    let linear = s.interpolation() == crate::command::Interpolation::Linear;
    let coeffs: Vec<f64> = if linear {
        x.windows(2).map(|w| (w[1] - w[0]) / period).collect()
    } else {
        let mut prev = 0.0;
        x.iter()
            .map(|&v| {
                let d = v - prev;
                prev = v;
                d
            })
            .collect()
    };
    let first = x.first().copied().unwrap_or(0.0);
    let last = x.last().copied().unwrap_or(0.0);
    let magnitude = f
        .iter()
        .map(|&fi| {
            let w = 2.0 * PI * fi;
            let z = ((w * period).cos(), -(w * period).sin());
            // Horner: Σ c_k z^k.
            let mut acc: C = (0.0, 0.0);
            for &c in coeffs.iter().rev() {
                acc = cmul(acc, z);
                acc.0 += c;
            }
            let mut vel = if linear {
                // Each slope lasts one period: kernel (1 − e^{−iωT})/(iω) → T as ω → 0.
                let kernel = if w * period < 1e-8 {
                    (period, 0.0)
                } else {
                    let num = (1.0 - z.0, -z.1);
                    cmul(num, i_omega_pow(w, -1))
                };
                let mut v = cmul(acc, kernel);
                v.0 += first;
                v
            } else {
                acc
            };
            if r != 1 && w == 0.0 {
                if r == 2 {
                    return 0.0;
                }
                // Position at f = 0: its integral (trapezoidal = exact for linear, ends at 0).
                if last != 0.0 {
                    return f64::INFINITY;
                }
                let sum: f64 = x.iter().sum();
                return (sum * period).abs();
            }
            if r != 1 {
                vel = cmul(vel, i_omega_pow(w, r - 1));
            }
            crate::vibration::magnitude(vel.0, vel.1)
        })
        .collect();
    Ok(Spectrum {
        frequency_hz: f,
        magnitude,
    })
}

/// Spectrum of any command.
pub fn command_spectrum(c: &Command, options: &SpectrumOptions) -> Result<Spectrum> {
    match c {
        Command::Piecewise(p) => piecewise_spectrum(p, options),
        Command::Sampled(s) => sampled_spectrum(s, options),
    }
}
