//! Pulse-convolution command profiles (Veciana & Cardona 2011) and their B-spline form.
//!
//! A rectangular pulse of duration 1/f₀ has the spectrum |U₁(f)| = A₁|sin(πf/f₀)/(πf)| (eq. 13):
//! it is zero at f₀, 2f₀, … . By the convolution theorem, a velocity profile made by convolving
//! such pulses has zero spectral content wherever any factor does, and so does its derivative
//! (the acceleration), which is what makes a mode at f₀ stop ringing after the move (eqs. 9–12,
//! undamped modes). The families of the paper:
//!
//! - `pulse` (§2.1, Fig. 3): one pulse of 1/f₀ convolved with a final pulse — a trapezium;
//! - `triangle` (§2.3, eq. 23 with p = 1, Figs. 6–7): two pulses of 1/f₀ (a triangle, spectrum
//!   tangent to zero at f₀) and a final pulse;
//! - `robustTrapezium` (§2.3, Fig. 8): pulses of 1/(f₀ + Δf) and 1/(f₀ − Δf), widening the band
//!   of low spectral content, and a final pulse;
//! - `multiMode` (§2.4, Fig. 10): one pulse of 1/f₀ᵢ per mode, optionally one pulse of
//!   1/f_cmd for a common frequency (eq. 28) replacing the modes it covers, and a final pulse.
//!
//! The final pulse takes the rest of the requested `duration`; its height is set so the
//! velocity integrates to `distance` (each other pulse has unit area, so the area of the
//! convolution is the final pulse's area).
//!
//! In jump form the convolution of m unit-area pulses of widths w₁ … wₘ is
//! (b₁ * … * bₘ)(t) = Σ_{S ⊆ {1…m}} (−1)^{|S|} (t − σ_S)₊^{m−1} / ((m − 1)! Π wᵢ), σ_S = Σ_{i∈S} wᵢ,
//! (the inverse Laplace transform of Π (1 − e^{−s wᵢ})/(s wᵢ)), so the position (its integral) has
//! knots at every subset sum, with jumps ±distance/Π wᵢ in its m-th derivative.
//!
//! §2.5: a convolution of m pulses is a spline of degree m − 1, C^{m−2}; [`to_bspline`] gives
//! its knot vector and control polygon (eqs. 29–30 for the triangle case).

use crate::error::{finite, positive, Error, Result};
use crate::piecewise::{Cursor, Knot, Piecewise, MAX_DEGREE, ORDER};
use serde::Serialize;

/// Most pulses in one profile (the position is then a polynomial of degree [`MAX_DEGREE`]).
pub const MAX_PULSES: usize = MAX_DEGREE;

crate::tagged::tagged_enum! {
    tag = "shape", rename_all = "camelCase", mirror = profile_spec_serde;
    /// A pulse-convolution profile as written in a command spec (`{ kind: "profile", shape, … }`):
    /// a rest-to-rest move of `distance` lasting `duration` seconds.
    #[derive(Debug, Clone, PartialEq)]
    pub enum ProfileSpec {
        /// One pulse of 1/f₀ and a final pulse: a trapezoidal velocity (§2.1, Fig. 3).
        #[serde(rename_all = "camelCase")]
        Pulse {
            /// Mode frequency f₀ in Hz.
            frequency_hz: f64,
            /// Distance of the move.
            distance: f64,
            /// Total duration in seconds (≥ 1/f₀).
            duration: f64,
        },
        /// Two pulses of 1/f₀ (a triangle) and a final pulse (§2.3, eq. 23 with p = 1, Fig. 7).
        #[serde(rename_all = "camelCase")]
        Triangle {
            /// Mode frequency f₀ in Hz.
            frequency_hz: f64,
            /// Distance of the move.
            distance: f64,
            /// Total duration in seconds (≥ 2/f₀).
            duration: f64,
        },
        /// Pulses of 1/(f₀ + Δf) and 1/(f₀ − Δf) and a final pulse (§2.3, Fig. 8).
        #[serde(rename_all = "camelCase")]
        RobustTrapezium {
            /// Mode frequency f₀ in Hz.
            frequency_hz: f64,
            /// Half-width Δf of the suppressed band in Hz (0 ≤ Δf < f₀).
            delta_hz: f64,
            /// Distance of the move.
            distance: f64,
            /// Total duration in seconds (≥ 1/(f₀+Δf) + 1/(f₀−Δf)).
            duration: f64,
        },
        /// One pulse of 1/fᵢ per listed mode, one of 1/f_cmd if `commonHz` is given, and a final
        /// pulse (§2.4, eq. 28, Fig. 10).
        #[serde(rename_all = "camelCase")]
        MultiMode {
            /// Frequencies in Hz of the modes given their own pulse.
            modes_hz: Vec<f64>,
            /// A common frequency f_cmd in Hz (fᵢ ≈ integer × f_cmd) whose one pulse replaces the
            /// modes it covers (leave those out of `modesHz`).
            #[serde(default)]
            common_hz: Option<f64>,
            /// Distance of the move.
            distance: f64,
            /// Total duration in seconds (≥ the sum of the pulses).
            duration: f64,
        },
    }
}

/// Durations of the pulses a spec asks for, before the final pulse; validated.
pub fn pulse_durations(spec: &ProfileSpec) -> Result<Vec<f64>> {
    let hz = |field: &str, f: f64| -> Result<f64> {
        positive(field, f)?;
        if f > crate::mode::MAX_FREQUENCY_HZ {
            return Err(Error::invalid(
                field,
                format!(
                    "must be at most {} Hz, got {f}",
                    crate::mode::MAX_FREQUENCY_HZ
                ),
            ));
        }
        Ok(1.0 / f)
    };
    Ok(match spec {
        ProfileSpec::Pulse { frequency_hz, .. } => vec![hz("frequencyHz", *frequency_hz)?],
        ProfileSpec::Triangle { frequency_hz, .. } => {
            let w = hz("frequencyHz", *frequency_hz)?;
            vec![w, w]
        }
        ProfileSpec::RobustTrapezium {
            frequency_hz,
            delta_hz,
            ..
        } => {
            let f = *frequency_hz;
            hz("frequencyHz", f)?;
            finite("deltaHz", *delta_hz)?;
            if !(0.0..f).contains(delta_hz) {
                return Err(Error::invalid(
                    "deltaHz",
                    format!("must satisfy 0 ≤ Δf < frequencyHz ({f} Hz), got {delta_hz}"),
                ));
            }
            vec![1.0 / (f + delta_hz), 1.0 / (f - delta_hz)]
        }
        ProfileSpec::MultiMode {
            modes_hz,
            common_hz,
            ..
        } => {
            let mut w = Vec::new();
            for (i, f) in modes_hz.iter().enumerate() {
                w.push(hz(&format!("modesHz[{i}]"), *f)?);
            }
            if let Some(f) = common_hz {
                w.push(hz("commonHz", *f)?);
            }
            if w.is_empty() {
                return Err(Error::invalid(
                    "modesHz",
                    "give at least one mode frequency or commonHz",
                ));
            }
            w
        }
    })
}

/// The position command of a profile spec (its velocity is the pulse convolution).
pub fn from_spec(spec: &ProfileSpec) -> Result<Piecewise> {
    let (distance, duration) = match spec {
        ProfileSpec::Pulse {
            distance, duration, ..
        }
        | ProfileSpec::Triangle {
            distance, duration, ..
        }
        | ProfileSpec::RobustTrapezium {
            distance, duration, ..
        }
        | ProfileSpec::MultiMode {
            distance, duration, ..
        } => (*distance, *duration),
    };
    let mut widths = pulse_durations(spec)?;
    finite("distance", distance)?;
    finite("duration", duration)?;
    let used: f64 = widths.iter().sum();
    // Rounding slack so that duration = Σ widths exactly gives a zero-length final pulse.
    let last = duration - used;
    if last < -1e-12 * used {
        return Err(Error::invalid(
            "duration",
            format!(
                "must be at least the sum of the pulses, {used} s, got {duration} (the final \
                 pulse takes the rest)"
            ),
        ));
    }
    widths.push(last.max(0.0));
    position_from_pulses(&widths, distance)
}

/// Most zeros [`spectrum_zeros`] lists.
pub const MAX_ZEROS: usize = 10_000;

/// A frequency where a profile's spectrum is zero.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct SpectrumZero {
    /// The frequency in Hz.
    pub frequency_hz: f64,
    /// How many of the pulses vanish there: the zero's order (2 for the triangle's at f₀, where
    /// the spectrum is tangent to zero).
    pub order: usize,
    /// True when the final pulse (the rest of `duration`) is one of them; a zero of the final
    /// pulse alone moves with `duration`, not with the modes.
    pub final_pulse: bool,
}

/// The zeros of a profile's spectrum |U(f)| (of its velocity, and so of its acceleration) in
/// (0, `up_to_hz`], in increasing order. Closed form: a unit-area pulse of width w has the
/// spectrum |sin(πfw)/(πfw)| (Veciana & Cardona 2011 eq. 13, with f₀ = 1/w), zero at f = k/w,
/// k = 1, 2, …; the velocity is the convolution of the pulses, its spectrum their product
/// (eqs. 9–12), zero wherever one factor is. Zeros of several pulses within 10⁻⁹ (relative)
/// are one zero of higher `order`. A zero-width final pulse (a Dirac) has none. Errors: a bad
/// spec (as [`from_spec`]), `upToHz` not positive, more than [`MAX_ZEROS`] zeros (`tooLarge`).
pub fn spectrum_zeros(spec: &ProfileSpec, up_to_hz: f64) -> Result<Vec<SpectrumZero>> {
    // Validated as from_spec validates it (the same errors); the final pulse takes the rest.
    from_spec(spec)?;
    let duration = match spec {
        ProfileSpec::Pulse { duration, .. }
        | ProfileSpec::Triangle { duration, .. }
        | ProfileSpec::RobustTrapezium { duration, .. }
        | ProfileSpec::MultiMode { duration, .. } => *duration,
    };
    let mut widths = pulse_durations(spec)?;
    widths.push((duration - widths.iter().sum::<f64>()).max(0.0));
    positive("upToHz", up_to_hz)?;
    let last = widths.len() - 1;
    let count: f64 = widths.iter().map(|w| (up_to_hz * w).floor()).sum();
    if count > MAX_ZEROS as f64 {
        return Err(Error::TooLarge {
            field: "upToHz".into(),
            value: count,
            limit: MAX_ZEROS as f64,
        });
    }
    let mut all: Vec<(f64, bool)> = Vec::with_capacity(count as usize);
    for (i, &w) in widths.iter().enumerate() {
        let mut k = 1.0;
        while w > 0.0 && k / w <= up_to_hz * (1.0 + 1e-12) {
            all.push((k / w, i == last));
            k += 1.0;
        }
    }
    all.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut zeros: Vec<SpectrumZero> = Vec::new();
    for (f, fin) in all {
        match zeros.last_mut() {
            Some(z) if (f - z.frequency_hz).abs() <= 1e-9 * f => {
                z.order += 1;
                z.final_pulse |= fin;
            }
            _ => zeros.push(SpectrumZero {
                frequency_hz: f,
                order: 1,
                final_pulse: fin,
            }),
        }
    }
    Ok(zeros)
}

/// The position command whose velocity is the convolution of pulses of the given widths (s),
/// all of unit area but the product scaled so the move covers `distance`. Zero widths are
/// Dirac pulses (the identity of convolution). At most [`MAX_PULSES`] non-zero widths.
pub fn position_from_pulses(widths: &[f64], distance: f64) -> Result<Piecewise> {
    finite("distance", distance)?;
    let mut w = Vec::new();
    for (i, &x) in widths.iter().enumerate() {
        finite(&format!("pulses[{i}]"), x)?;
        if x < 0.0 {
            return Err(Error::invalid(
                format!("pulses[{i}]"),
                format!("a pulse duration must be ≥ 0 s, got {x}"),
            ));
        }
        if x > 0.0 {
            w.push(x);
        }
    }
    if w.len() > MAX_PULSES {
        return Err(Error::TooLarge {
            field: "pulses".into(),
            value: w.len() as f64,
            limit: MAX_PULSES as f64,
        });
    }
    let m = w.len();
    let scale = distance / w.iter().product::<f64>();
    let mut knots = Vec::with_capacity(1 << m);
    for subset in 0u32..(1u32 << m) {
        let sigma: f64 = (0..m)
            .filter(|i| subset & (1 << i) != 0)
            .map(|i| w[i])
            .sum();
        let sign = if subset.count_ones() % 2 == 0 {
            1.0
        } else {
            -1.0
        };
        let mut jumps = [0.0; ORDER];
        jumps[m] = sign * scale;
        knots.push(Knot { time: sigma, jumps });
    }
    Piecewise::new(knots)
}

/// A B-spline function of one variable: `degree` p, a clamped knot vector in de Boor's
/// convention (p + 1 equal knots at each end; length = control points + p + 1) and the
/// control polygon ordinates.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct BSpline {
    /// Polynomial degree p.
    pub degree: usize,
    /// Full knot vector (de Boor convention).
    pub knots: Vec<f64>,
    /// Control polygon ordinates dᵢ.
    pub control: Vec<f64>,
}

impl BSpline {
    /// The knot vector in Farin's convention (as printed in Veciana & Cardona 2011 eq. 29):
    /// the de Boor vector without its first and last knot.
    pub fn farin_knots(&self) -> &[f64] {
        let n = self.knots.len();
        if n < 2 {
            &self.knots
        } else {
            &self.knots[1..n - 1]
        }
    }

    /// Value at `t` by de Boor's algorithm (0 outside the knot span).
    pub fn eval(&self, t: f64) -> f64 {
        let p = self.degree;
        let u = &self.knots;
        let n = self.control.len();
        if n == 0 || u.len() != n + p + 1 || t < u[p] || t > u[n] {
            return 0.0;
        }
        // Span k with u[k] ≤ t < u[k+1], p ≤ k ≤ n − 1 (t = end uses the last span).
        let mut k = p;
        while k + 1 < n && u[k + 1] <= t {
            k += 1;
        }
        let mut d: Vec<f64> = (0..=p).map(|j| self.control[j + k - p]).collect();
        for r in 1..=p {
            for j in (r..=p).rev() {
                let i = j + k - p;
                let den = u[i + p + 1 - r] - u[i];
                let alpha = if den > 0.0 { (t - u[i]) / den } else { 0.0 };
                d[j] = (1.0 - alpha) * d[j - 1] + alpha * d[j];
            }
        }
        d[p]
    }
}

/// The B-spline form of a piecewise-polynomial function (e.g. a profile's velocity,
/// `profile.derivative()`): knots at its breakpoints with multiplicity p − (continuity), ends
/// clamped, control points from the blossom of the polynomial pieces (the de Boor–Fix dual
/// functional: dᵢ = Pⱼ(uᵢ₊₁, …, uᵢ₊ₚ) for any piece j in the support of Nᵢ), so the result is
/// exact up to rounding. Veciana & Cardona 2011 §2.5, eqs. 29–30.
pub fn to_bspline(f: &Piecewise) -> Result<BSpline> {
    let p = f.degree();
    let breaks = f.knots();
    if breaks.len() < 2 {
        return Err(Error::invalid(
            "command",
            "a B-spline needs a function with at least two breakpoints",
        ));
    }
    let mut u = Vec::new();
    let last = breaks.len() - 1;
    for (i, k) in breaks.iter().enumerate() {
        let mult = if i == 0 || i == last {
            p + 1
        } else {
            let lowest = k.jumps.iter().position(|&j| j != 0.0).unwrap_or(p);
            p + 1 - lowest.min(p)
        };
        u.extend(std::iter::repeat_n(k.time, mult));
    }
    let n = u.len() - p - 1;
    // Taylor state of the piece starting at each breakpoint (right limits).
    let mut pieces = Vec::with_capacity(breaks.len());
    let mut cursor = Cursor::new(f);
    for k in breaks {
        cursor.seek(k.time);
        pieces.push((k.time, cursor.state_at(k.time)));
    }
    let mut control = Vec::with_capacity(n);
    for i in 0..n {
        // A non-empty interval [u_j, u_{j+1}) with i ≤ j ≤ i + p.
        let j = (i..=i + p)
            .find(|&j| j + 1 < u.len() && u[j] < u[j + 1])
            .ok_or_else(|| Error::invalid("command", "degenerate knot vector"))?;
        let piece = pieces
            .iter()
            .rev()
            .find(|(t, _)| *t <= u[j])
            .map(|(t, s)| (*t, *s))
            .unwrap_or((u[j], [0.0; ORDER]));
        control.push(blossom(&piece.1, p, &u[i + 1..=i + p], piece.0));
    }
    Ok(BSpline {
        degree: p,
        knots: u,
        control,
    })
}

/// The blossom (polar form) of the degree-p polynomial with Taylor state `s` at `a`
/// (q(t) = Σ sₖ (t − a)ᵏ/k!) at the arguments `x`: Σₖ (sₖ/k!) eₖ(x − a)/C(p, k), with eₖ the
/// elementary symmetric polynomials.
fn blossom(s: &[f64; ORDER], p: usize, x: &[f64], a: f64) -> f64 {
    let mut e = vec![0.0; p + 1];
    e[0] = 1.0;
    for &xi in x {
        let y = xi - a;
        for k in (1..=p).rev() {
            e[k] += e[k - 1] * y;
        }
    }
    let mut sum = 0.0;
    let mut fact = 1.0;
    let mut binom = 1.0;
    for k in 0..=p {
        if k > 0 {
            fact *= k as f64;
            binom = binom * (p + 1 - k) as f64 / k as f64;
        }
        sum += s[k] / fact * e[k] / binom;
    }
    sum
}
