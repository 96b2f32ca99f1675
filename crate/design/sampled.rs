//! Sampled shapers: impulses on the controller's period, a prescribed ramp delay, and the
//! amplitudes that minimise the control error (Kamel, Lange & Hirzinger, "An Industrial-Robots
//! Suited Input Shaping Control Scheme"; equation numbers below are that paper's).
//!
//! **Times on the grid (eq. 12).** The impulses sit on the controller period T:
//! tᵢ = iT, i = 0 … n−1. With the times fixed, every condition on the shaper is linear in the
//! amplitudes A, and the design is the constrained set of linear equations C A = b of eq. 13,
//! whose rows are
//!
//! - zero vibration at the mode, eqs. 4–5: Σ Aᵢ e^{ζω tᵢ} cos(ω_d tᵢ) = 0, Σ Aᵢ e^{ζω tᵢ} sin(ω_d tᵢ) = 0;
//! - unity gain, eq. 6: Σ Aᵢ = 1;
//! - robustness, eqs. 8–9: the same sums weighted by tᵢ vanish (dV/dω = 0). The paper uses this
//!   first order; `derivatives` = k adds the rows weighted by tᵢ², …, tᵢᵏ (Singer & Seering's
//!   higher derivatives), and 0 leaves them out;
//! - the ramp delay, eqs. 10–12: τ = 2ζ/ω + Σ Aᵢ tᵢ = mT (the prediction horizon m·T of eq. 12);
//!   m = 0 is the full compensation of eq. 11, Σ Aᵢ tᵢ = −2ζ/ω. Without `delaySamples` the delay
//!   is left free.
//!
//! With the paper's first-order robustness and the delay row, C is 6 × n as in eq. 13. Rows are
//! scaled (by e^{−ζω t_{n−1}} and powers of 1/t_{n−1}) for conditioning; that does not change
//! their solution set.
//!
//! **Bounds (eq. 7).** A_min ≤ Aᵢ ≤ A_max and ΔA_min ≤ ΔAᵢ ≤ ΔA_max. The paper does not define
//! ΔAᵢ; we take the increment between consecutive amplitudes, ΔAᵢ = Aᵢ − Aᵢ₋₁, i = 1 … n−1.
//!
//! **Control error (eqs. 14–24).** For a unit step of the reference w(t) at t = mT, the shaped
//! command is u(t) = Σ Aᵢ σ(t − iT) (eq. 14), the sensor deflection y(t) = Σ Aᵢ ġ(t − iT)
//! (eq. 15) with g the impulse response of the plant K ω² / (s² + 2ζωs + ω²) (eqs. 1–2), and the
//! error e = w − u − y (eq. 16). Because C A = b cancels the vibration after the last impulse,
//! e vanishes after t_{n−1}, and the cost of eq. 17,
//!
//! J_q(A) = Aᵀ Q A + ∫₀^∞ e² dt = Aᵀ (Ψ + Q) A − 2 Aᵀ θ + (n − m − 1) T        (eq. 24)
//!
//! is a quadratic in A with θᵢ of eq. 19 and Ψ of eqs. 20–23. Q = `weight` · I.
//!
//! The text of eq. 22 (the integral of y²) is garbled in our copy: its h_{ij}(t) is integrated
//! from 0, while ġ(t − iT)ġ(t − jT) vanishes before max(i, j)T, and it divides by ζ. We derived
//! the integral again: with ġ(t) = c e^{−ζωt} cos(ω_d t + φ), c = Kω²/√(1−ζ²), φ = asin ζ, and
//! s = t − max(i, j)T, a = max(i,j)T − iT, b = max(i,j)T − jT, Λ = (n−1)T − max(i,j)T,
//!
//! ∫ ġ(t−iT) ġ(t−jT) dt = ½ c² e^{−ζω(a+b)} [cos(ω_d(a−b)) E₀ + Re(e^{iψ} (e^{pΛ} − 1)/p)],
//!
//! E₀ = (1 − e^{−2ζωΛ})/(2ζω) (= Λ at ζ = 0), p = −2ζω + 2iω_d, ψ = ω_d(a+b) + 2φ. It holds at
//! ζ = 0 too. The tests check Ψ and θ against a direct quadrature of e(t)².
//!
//! **Minimum (eq. 25).** Minimising J_q subject to C A = b is an equality-constrained QP; its
//! KKT system [[2Ψ̃, Cᵀ], [C, 0]] [A; λ] = [2θ; b], Ψ̃ = Ψ + Q, is eq. 25 written without the
//! explicit inverses (the tests check the two agree). It is solved by a fully pivoted LU.
//! When bounds (eq. 7) are given and the equality-constrained optimum breaks one of them, the
//! QP with inequalities is solved by `clarabel` (an interior-point solver), and its solution is
//! then made exact by an active-set loop: the bounds clarabel finds active are imposed as
//! equalities, the KKT system is solved again, a violated bound is added and a bound with a
//! multiplier of the wrong sign is dropped until neither happens. So the returned amplitudes
//! satisfy C A = b to rounding (V = 0 at the mode) and the bounds exactly.
//!
//! `objective: "minimumNorm"` minimises Σ Aᵢ² under the same constraints instead: the
//! "unoptimised" shaper we compare against. The paper does not say how its unoptimised shaper
//! was chosen; the minimum-norm solution of eq. 13 is our assumption.

use crate::error::{count, finite, Error, Result};
use crate::mode::Mode;
use crate::shaper::{Impulse, Shaper, ShaperData};
use nalgebra::{Complex, DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Most impulses a sampled shaper may have (the KKT system is dense, O(n³) to solve).
pub const MAX_IMPULSES: usize = 256;
/// Fewest impulses a sampled shaper may have: one per row of eq. 13, 3 without derivatives and
/// without a prescribed delay (2 more per derivative, 1 more with `delaySamples`).
pub const MIN_IMPULSES: usize = 3;
/// Most derivative conditions (rows weighted by tᵢ, …, tᵢᵏ) accepted.
pub const MAX_DERIVATIVES: u32 = 3;
/// The paper's weight, Q = 0.1 · I (Kamel et al. Fig. 3).
pub const DEFAULT_WEIGHT: f64 = 0.1;
/// Largest weight accepted (beyond it the control error no longer matters numerically).
pub const MAX_WEIGHT: f64 = 1e6;

/// What the amplitudes minimise.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum Objective {
    /// J_q of eq. 17: weighted amplitudes plus the integrated squared control error.
    #[default]
    ControlError,
    /// Σ Aᵢ²: the minimum-norm solution of eq. 13, our stand-in for the paper's "unoptimised"
    /// shaper.
    MinimumNorm,
}

/// Parameters of a sampled shaper, as written in a spec (`family: "sampled"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct SampledSpec {
    /// Controller period T in seconds; impulse i is at iT (eq. 12).
    pub period_s: f64,
    /// Number of impulses n (eq. 3), at most [`MAX_IMPULSES`], at least the number of
    /// constraint rows.
    pub impulses: usize,
    /// Ramp delay in periods m (eq. 12): τ = mT. 0 is full compensation (eq. 11). Omitted: the
    /// delay is free and the control error is measured against a reference step at t = 0.
    #[serde(default)]
    pub delay_samples: Option<u32>,
    /// Q = weight · I in eq. 17 (≥ 0; default 0.1, the paper's).
    #[serde(default = "default_weight")]
    pub weight: f64,
    /// Derivative conditions (eqs. 8–9 are 1, the default; 0 … [`MAX_DERIVATIVES`]).
    #[serde(default = "default_derivatives")]
    pub derivatives: u32,
    /// Static gain K of the plant in eq. 1, in s² (deflection per unit acceleration); only the
    /// control error uses it. Default 1/ω²: a mass on a spring. The paper's robot has 8e-4.
    #[serde(default)]
    pub plant_gain: Option<f64>,
    /// What the amplitudes minimise (default `controlError`).
    #[serde(default)]
    pub objective: Objective,
    /// Lower bound on every amplitude, A_min of eq. 7 (e.g. 0 for a positive shaper).
    #[serde(default)]
    pub amplitude_min: Option<f64>,
    /// Upper bound on every amplitude, A_max of eq. 7.
    #[serde(default)]
    pub amplitude_max: Option<f64>,
    /// Lower bound on Aᵢ − Aᵢ₋₁, ΔA_min of eq. 7.
    #[serde(default)]
    pub increment_min: Option<f64>,
    /// Upper bound on Aᵢ − Aᵢ₋₁, ΔA_max of eq. 7.
    #[serde(default)]
    pub increment_max: Option<f64>,
}

fn default_weight() -> f64 {
    DEFAULT_WEIGHT
}

fn default_derivatives() -> u32 {
    1
}

impl SampledSpec {
    /// A spec with the given period and impulse count and every other field at its default.
    pub fn new(period_s: f64, impulses: usize) -> Self {
        SampledSpec {
            period_s,
            impulses,
            delay_samples: None,
            weight: DEFAULT_WEIGHT,
            derivatives: 1,
            plant_gain: None,
            objective: Objective::ControlError,
            amplitude_min: None,
            amplitude_max: None,
            increment_min: None,
            increment_max: None,
        }
    }
}

/// The three parts of the cost J_q (eq. 17).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct Cost {
    /// J_q = amplitude penalty + control error.
    pub total: f64,
    /// ∫₀^∞ e²(t) dt, in s (eq. 18).
    pub control_error: f64,
    /// Aᵀ Q A.
    pub amplitude_penalty: f64,
}

/// A designed sampled shaper with its ramp delay and cost.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledDesign {
    /// The shaper. Zero amplitudes are dropped, so if the designed sequence starts with zeros
    /// the shaper starts at its first non-zero impulse, `start_s` later than the sequence.
    pub shaper: Shaper,
    /// Time of the first non-zero impulse within the designed sequence (a multiple of T).
    pub start_s: f64,
    /// τ of eq. 10 for the designed sequence (= start_s + the returned shaper's τ).
    pub ramp_delay_s: f64,
    /// J_q of eq. 17 and its parts.
    pub cost: Cost,
    /// The amplitudes on the grid, A₀ … A_{n−1} (zeros included).
    pub amplitudes: Vec<f64>,
}

/// The ramp delay τ = 2ζ/ω + Σ Aᵢtᵢ / Σ Aᵢ of a shaper on a mode (Kamel et al. eq. 10, which
/// assumes Σ Aᵢ = 1), in seconds: how far the plant's response to a slow ramp lags the
/// unshaped ramp. ω is the undamped natural frequency in rad/s.
///
/// ```
/// use input_shaping::{design::sampled::ramp_delay, design::zero_vibration::zv, Mode};
/// // Kamel et al. eq. 10: τ = 2ζ/ω + Σ Aᵢtᵢ; ZV's centroid is at K·(T_d/2)/(1 + K).
/// let mode = Mode::new(2.0, 0.1)?;
/// let k = mode.half_period_decay();
/// let tau = 2.0 * 0.1 / mode.omega_rad_s() + k * mode.damped_period_s() / 2.0 / (1.0 + k);
/// assert!((ramp_delay(&zv(&mode)?, &mode)? - tau).abs() < 1e-12);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn ramp_delay(shaper: &Shaper, mode: &Mode) -> Result<f64> {
    let centroid = shaper.centroid_delay().ok_or_else(|| {
        Error::invalid(
            "impulses",
            "the amplitudes sum to zero; the ramp delay is undefined",
        )
    })?;
    Ok(2.0 * mode.damping() / mode.omega_rad_s() + centroid)
}

/// A validated sampled design problem: the constraint set of eq. 13 and the cost of eq. 24 for
/// one mode. Built by [`Problem::new`]; exposes its matrices so they can be checked.
#[derive(Debug, Clone)]
pub struct Problem {
    n: usize,
    period: f64,
    delay: Option<u32>,
    derivatives: u32,
    weight: f64,
    gain: f64,
    zeta: f64,
    omega: f64,
    objective: Objective,
    bounds: Bounds,
}

#[derive(Debug, Clone, Copy, Default)]
struct Bounds {
    amplitude_min: Option<f64>,
    amplitude_max: Option<f64>,
    increment_min: Option<f64>,
    increment_max: Option<f64>,
}

impl Bounds {
    fn any(&self) -> bool {
        self.amplitude_min.is_some()
            || self.amplitude_max.is_some()
            || self.increment_min.is_some()
            || self.increment_max.is_some()
    }
}

fn optional_finite(field: &str, value: Option<f64>) -> Result<Option<f64>> {
    value.map(|v| finite(field, v)).transpose()
}

/// The number of impulses: at least one per row of eq. 13 (the derivatives, within
/// [`MAX_DERIVATIVES`], and the delay add rows), at most [`MAX_IMPULSES`]; the ramp delay
/// must end within the shaper.
fn impulse_count(spec: &SampledSpec) -> Result<usize> {
    if spec.derivatives > MAX_DERIVATIVES {
        return Err(Error::TooLarge {
            field: "derivatives".into(),
            value: f64::from(spec.derivatives),
            limit: f64::from(MAX_DERIVATIVES),
        });
    }
    let rows =
        MIN_IMPULSES + 2 * spec.derivatives as usize + usize::from(spec.delay_samples.is_some());
    let n = count("impulses", spec.impulses, rows, MAX_IMPULSES).map_err(|e| match e {
        Error::InvalidInput { field, reason } => Error::InvalidInput {
            field,
            reason: format!("{reason} (one per row of eq. 13 asked for)"),
        },
        e => e,
    })?;
    if let Some(m) = spec.delay_samples {
        if m as usize > n - 1 {
            return Err(Error::invalid(
                "delaySamples",
                format!(
                    "the ramp delay must end within the shaper: at most impulses − 1 = {}, \
                     got {m}",
                    n - 1
                ),
            ));
        }
    }
    Ok(n)
}

impl Bounds {
    /// The spec's bounds: finite, each pair ordered, and the amplitude bounds leaving room for
    /// `n` impulses to sum to 1.
    fn new(spec: &SampledSpec, n: usize) -> Result<Bounds> {
        let bounds = Bounds {
            amplitude_min: optional_finite("amplitudeMin", spec.amplitude_min)?,
            amplitude_max: optional_finite("amplitudeMax", spec.amplitude_max)?,
            increment_min: optional_finite("incrementMin", spec.increment_min)?,
            increment_max: optional_finite("incrementMax", spec.increment_max)?,
        };
        if let (Some(lo), Some(hi)) = (bounds.amplitude_min, bounds.amplitude_max) {
            if lo > hi {
                return Err(Error::invalid(
                    "amplitudeMax",
                    format!("must be ≥ amplitudeMin ({lo}), got {hi}"),
                ));
            }
        }
        if let (Some(lo), Some(hi)) = (bounds.increment_min, bounds.increment_max) {
            if lo > hi {
                return Err(Error::invalid(
                    "incrementMax",
                    format!("must be ≥ incrementMin ({lo}), got {hi}"),
                ));
            }
        }
        // Σ Aᵢ = 1 needs n·A_min ≤ 1 ≤ n·A_max.
        if let Some(lo) = bounds.amplitude_min {
            if lo * n as f64 > 1.0 {
                return Err(Error::Infeasible {
                    reason: format!(
                        "{n} impulses of at least amplitudeMin = {lo} cannot sum to 1 (eq. 6)"
                    ),
                });
            }
        }
        if let Some(hi) = bounds.amplitude_max {
            if hi * (n as f64) < 1.0 {
                return Err(Error::Infeasible {
                    reason: format!(
                        "{n} impulses of at most amplitudeMax = {hi} cannot sum to 1 (eq. 6)"
                    ),
                });
            }
        }
        Ok(bounds)
    }
}

impl Problem {
    /// Validates `spec` for `mode`. Errors name the spec field (`periodS`, `impulses`,
    /// `delaySamples`, `weight`, `derivatives`, `plantGain`, `amplitudeMin`, …).
    pub fn new(mode: &Mode, spec: &SampledSpec) -> Result<Problem> {
        let period = finite("periodS", spec.period_s)?;
        if period <= 0.0 {
            return Err(Error::invalid(
                "periodS",
                format!("must be greater than 0 s, got {period}"),
            ));
        }
        let n = impulse_count(spec)?;
        let weight = finite("weight", spec.weight)?;
        if weight < 0.0 {
            return Err(Error::invalid(
                "weight",
                format!("must be ≥ 0, got {weight}"),
            ));
        }
        if weight > MAX_WEIGHT {
            return Err(Error::TooLarge {
                field: "weight".into(),
                value: weight,
                limit: MAX_WEIGHT,
            });
        }
        let omega = mode.omega_rad_s();
        let gain = match spec.plant_gain {
            Some(k) => {
                finite("plantGain", k)?;
                if k < 0.0 {
                    return Err(Error::invalid("plantGain", format!("must be ≥ 0, got {k}")));
                }
                k
            }
            None => 1.0 / (omega * omega),
        };
        Ok(Problem {
            n,
            period,
            delay: spec.delay_samples,
            derivatives: spec.derivatives,
            weight,
            gain,
            zeta: mode.damping(),
            omega,
            objective: spec.objective,
            bounds: Bounds::new(spec, n)?,
        })
    }

    /// Number of impulses n.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Always false: a problem has at least three impulses.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The impulse times tᵢ = iT (eq. 12).
    pub fn times(&self) -> Vec<f64> {
        (0..self.n).map(|i| i as f64 * self.period).collect()
    }

    fn omega_d(&self) -> f64 {
        self.omega * (1.0 - self.zeta * self.zeta).sqrt()
    }

    fn sigma(&self) -> f64 {
        self.zeta * self.omega
    }

    /// The constraint set C A = b of eq. 13 (rows scaled for conditioning): vibration (4, 5),
    /// sum (6), derivatives (8, 9, …), delay (10–12) if asked for.
    pub fn constraints(&self) -> (DMatrix<f64>, DVector<f64>) {
        let n = self.n;
        let last = (n - 1) as f64 * self.period;
        let (wd, sigma) = (self.omega_d(), self.sigma());
        let rows = 3 + 2 * self.derivatives as usize + usize::from(self.delay.is_some());
        let mut c = DMatrix::zeros(rows, n);
        let mut b = DVector::zeros(rows);
        for i in 0..n {
            let t = i as f64 * self.period;
            let decay = (-sigma * (last - t)).exp();
            let (sin, cos) = (wd * t).sin_cos();
            c[(0, i)] = decay * cos;
            c[(1, i)] = decay * sin;
            c[(2, i)] = 1.0;
            let r = t / last;
            for k in 1..=self.derivatives as usize {
                let w = decay * r.powi(k as i32);
                c[(1 + 2 * k, i)] = w * cos;
                c[(2 + 2 * k, i)] = w * sin;
            }
            if self.delay.is_some() {
                c[(rows - 1, i)] = i as f64;
            }
        }
        b[2] = 1.0;
        if let Some(m) = self.delay {
            // Σ Aᵢ i T = mT − 2ζ/ω (eq. 10 with τ = mT), divided by T.
            b[rows - 1] = f64::from(m) - 2.0 * self.zeta / (self.omega * self.period);
        }
        (c, b)
    }

    /// The plant's impulse response g(t) of eq. 2 (t ≥ 0).
    fn g(&self, t: f64) -> f64 {
        let wd = self.omega_d();
        self.gain * self.omega / (1.0 - self.zeta * self.zeta).sqrt()
            * (-self.sigma() * t).exp()
            * (wd * t).sin()
    }

    /// The reference step's sample m: the delay if one is prescribed, else 0.
    fn reference_sample(&self) -> usize {
        self.delay.map_or(0, |m| m as usize)
    }

    /// Ψ (eqs. 20–23), θ (eq. 19) and the constant (n − m − 1)T of eq. 24, so that
    /// ∫₀^∞ e² dt = Aᵀ Ψ A − 2 Aᵀ θ + constant.
    pub fn cost_terms(&self) -> (DMatrix<f64>, DVector<f64>, f64) {
        let n = self.n;
        let t = self.period;
        let last = (n - 1) as f64 * t;
        let (wd, sigma) = (self.omega_d(), self.sigma());
        let c = self.gain * self.omega * self.omega / (1.0 - self.zeta * self.zeta).sqrt();
        let phi = self.zeta.asin();
        let p = Complex::new(-2.0 * sigma, 2.0 * wd);
        let mut psi = DMatrix::zeros(n, n);
        for i in 0..n {
            for j in i..n {
                let start = j as f64 * t; // max(i, j)T
                let span = last - start;
                // a = max(i,j)T − iT, b = max(i,j)T − jT = 0 (j ≥ i).
                let a = start - i as f64 * t;
                let b = 0.0;
                // ∫ ġ(t − iT) + ∫ ġ(t − jT) over [max(i,j)T, (n−1)T] (eqs. 19, 21).
                let drift =
                    self.g(last - i as f64 * t) - self.g(a) + self.g(last - start) - self.g(b);
                let e0 = if sigma > 0.0 {
                    -(-2.0 * sigma * span).exp_m1() / (2.0 * sigma)
                } else {
                    span
                };
                let psi_phase = wd * (a + b) + 2.0 * phi;
                let osc = (Complex::from_polar(1.0, psi_phase) * ((p * span).exp() - 1.0) / p).re;
                let deflection =
                    0.5 * c * c * (-sigma * (a + b)).exp() * ((wd * (a - b)).cos() * e0 + osc);
                let value = span + drift + deflection;
                psi[(i, j)] = value;
                psi[(j, i)] = value;
            }
        }
        let m = self.reference_sample();
        let theta = DVector::from_fn(n, |i, _| {
            let from = i.max(m) as f64 * t;
            (last - from) + self.g(last - i as f64 * t) - self.g((m.saturating_sub(i)) as f64 * t)
        });
        let constant = (n - 1 - m) as f64 * t;
        (psi, theta, constant)
    }

    /// J_q (eq. 24) of an amplitude set on this problem's grid.
    pub fn cost(&self, amplitudes: &[f64]) -> Result<Cost> {
        if amplitudes.len() != self.n {
            return Err(Error::invalid(
                "amplitudes",
                format!("expected {} amplitudes, got {}", self.n, amplitudes.len()),
            ));
        }
        let (psi, theta, constant) = self.cost_terms();
        let a = DVector::from_column_slice(amplitudes);
        let control_error = (a.transpose() * &psi * &a)[(0, 0)] - 2.0 * a.dot(&theta) + constant;
        let amplitude_penalty = self.weight * a.dot(&a);
        // The minimum-norm objective never forms the cost matrices, so an absurd plant gain
        // first shows here (∞ − ∞ = NaN).
        if !(control_error.is_finite() && amplitude_penalty.is_finite()) {
            return Err(Error::invalid(
                "plantGain",
                "the cost overflows: the plant gain is too large for this mode",
            ));
        }
        Ok(Cost {
            total: control_error + amplitude_penalty,
            control_error,
            amplitude_penalty,
        })
    }

    /// The quadratic ½ Aᵀ H A − fᵀ A the objective minimises.
    fn quadratic(&self) -> (DMatrix<f64>, DVector<f64>) {
        match self.objective {
            Objective::ControlError => {
                let (psi, theta, _) = self.cost_terms();
                let h = (psi + DMatrix::identity(self.n, self.n) * self.weight) * 2.0;
                (h, theta * 2.0)
            }
            Objective::MinimumNorm => (
                DMatrix::identity(self.n, self.n) * 2.0,
                DVector::zeros(self.n),
            ),
        }
    }

    /// The bounds of eq. 7 as rows G A ≤ h.
    fn inequalities(&self) -> (DMatrix<f64>, DVector<f64>) {
        let n = self.n;
        let mut rows: Vec<(Vec<(usize, f64)>, f64)> = Vec::new();
        for i in 0..n {
            if let Some(hi) = self.bounds.amplitude_max {
                rows.push((vec![(i, 1.0)], hi));
            }
            if let Some(lo) = self.bounds.amplitude_min {
                rows.push((vec![(i, -1.0)], -lo));
            }
        }
        for i in 1..n {
            if let Some(hi) = self.bounds.increment_max {
                rows.push((vec![(i, 1.0), (i - 1, -1.0)], hi));
            }
            if let Some(lo) = self.bounds.increment_min {
                rows.push((vec![(i, -1.0), (i - 1, 1.0)], -lo));
            }
        }
        let mut g = DMatrix::zeros(rows.len(), n);
        let mut h = DVector::zeros(rows.len());
        for (r, (entries, rhs)) in rows.into_iter().enumerate() {
            for (col, v) in entries {
                g[(r, col)] = v;
            }
            h[r] = rhs;
        }
        (g, h)
    }

    /// The amplitudes A₀ … A_{n−1} minimising the objective subject to eq. 13 and the bounds.
    pub fn solve(&self) -> Result<Vec<f64>> {
        let (h, f) = self.quadratic();
        if h.iter().chain(f.iter()).any(|v| !v.is_finite()) {
            return Err(Error::invalid(
                "plantGain",
                "the cost overflows: the plant gain is too large for this mode",
            ));
        }
        let (c, b) = self.constraints();
        let x = equality_qp(&h, &f, &c, &b).ok_or_else(|| Error::Infeasible {
            reason: "the constraints of eq. 13 are singular for this mode and period (is the \
                     mode's half period a multiple of periodS, or too short for the impulses?); \
                     change periodS or impulses, or increase weight"
                .into(),
        })?;
        let mut x = x.0;
        if self.bounds.any() {
            let (g, hb) = self.inequalities();
            if max_violation(&g, &hb, &x) > BOUND_TOLERANCE {
                x = bounded_qp(&h, &f, &c, &b, &g, &hb)?;
            }
        }
        Ok(x.iter().copied().collect())
    }
}

/// Bounds of eq. 7 may be exceeded by at most this much (rounding of the final solve).
const BOUND_TOLERANCE: f64 = 1e-9;
/// Most working-set changes of the active-set loop.
#[cfg(feature = "solver")]
const MAX_ACTIVE_SET_STEPS: usize = 60;

fn max_violation(g: &DMatrix<f64>, h: &DVector<f64>, x: &DVector<f64>) -> f64 {
    (g * x - h).iter().fold(0.0_f64, |m, &v| m.max(v))
}

/// Solves min ½xᵀHx − fᵀx subject to E x = d through its KKT system; returns x and the
/// multipliers ν (H x + Eᵀ ν = f), or `None` if the system is singular.
fn equality_qp(
    h: &DMatrix<f64>,
    f: &DVector<f64>,
    e: &DMatrix<f64>,
    d: &DVector<f64>,
) -> Option<(DVector<f64>, DVector<f64>)> {
    let (n, r) = (h.nrows(), e.nrows());
    let mut kkt = DMatrix::zeros(n + r, n + r);
    kkt.view_mut((0, 0), (n, n)).copy_from(h);
    kkt.view_mut((0, n), (n, r)).copy_from(&e.transpose());
    kkt.view_mut((n, 0), (r, n)).copy_from(e);
    let mut rhs = DVector::zeros(n + r);
    rhs.rows_mut(0, n).copy_from(f);
    rhs.rows_mut(n, r).copy_from(d);
    let lu = kkt.clone().full_piv_lu();
    let u = lu.u();
    let diag = u.diagonal();
    let largest = diag.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let smallest = diag.iter().fold(f64::INFINITY, |m, v| m.min(v.abs()));
    if largest.is_nan() || largest <= 0.0 || smallest <= 1e-13 * largest {
        return None;
    }
    let mut z = lu.solve(&rhs)?;
    // Iterative refinement: with large amplitudes that cancel (fine grid, prescribed delay),
    // one solve leaves the constraints off by ~10⁻⁹ (Σ A = 1 − 3·10⁻⁹ on cases the long
    // property run found); a few corrections from the residual bring them to rounding.
    for _ in 0..3 {
        let r = &rhs - &kkt * &z;
        if r.amax() == 0.0 {
            break;
        }
        match lu.solve(&r) {
            Some(dz) if dz.iter().all(|v| v.is_finite()) => z += dz,
            _ => break,
        }
    }
    if z.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let residual = (&kkt * &z - &rhs).amax();
    let scale = 1.0 + rhs.amax() + kkt.amax() * z.amax();
    if residual > 1e-9 * scale {
        return None;
    }
    Some((z.rows(0, n).into_owned(), z.rows(n, r).into_owned()))
}

/// Without the solver (Cargo feature `solver`): active bounds need the QP below.
#[cfg(not(feature = "solver"))]
fn bounded_qp(
    _: &DMatrix<f64>,
    _: &DVector<f64>,
    _: &DMatrix<f64>,
    _: &DVector<f64>,
    _: &DMatrix<f64>,
    _: &DVector<f64>,
) -> Result<DVector<f64>> {
    Err(Error::solver_left_out())
}

/// The QP with the bounds: clarabel finds the optimum and which bounds are active; the
/// active-set loop then solves the KKT system with those bounds as equalities, so the result
/// satisfies eq. 13 to rounding.
#[cfg(feature = "solver")]
fn bounded_qp(
    h: &DMatrix<f64>,
    f: &DVector<f64>,
    c: &DMatrix<f64>,
    b: &DVector<f64>,
    g: &DMatrix<f64>,
    hb: &DVector<f64>,
) -> Result<DVector<f64>> {
    let x0 = interior_point_qp(h, f, c, b, g, hb)?;
    if let Some(x) = active_set(h, f, c, b, g, hb, &x0) {
        return Ok(x);
    }
    // The loop did not settle (degenerate bounds): project clarabel's point onto C x = b and
    // accept it if the bounds still hold.
    let cct = c * c.transpose();
    let correction = cct
        .lu()
        .solve(&(c * &x0 - b))
        .map(|y| c.transpose() * y)
        .ok_or_else(|| Error::Infeasible {
            reason: "the constraints of eq. 13 are singular".into(),
        })?;
    let x = x0 - correction;
    if max_violation(g, hb, &x) <= 1e-7 {
        Ok(x)
    } else {
        Err(Error::Infeasible {
            reason: "the bounded QP could not be solved to the accuracy eq. 13 needs".into(),
        })
    }
}

/// Clarabel's solution of min ½xᵀHx − fᵀx subject to C x = b, G x ≤ hb (an interior point,
/// accurate to the solver's tolerance); an error if it is infeasible or the solver stops.
#[cfg(feature = "solver")]
fn interior_point_qp(
    h: &DMatrix<f64>,
    f: &DVector<f64>,
    c: &DMatrix<f64>,
    b: &DVector<f64>,
    g: &DMatrix<f64>,
    hb: &DVector<f64>,
) -> Result<DVector<f64>> {
    use clarabel::solver::{
        DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
    };
    let n = h.nrows();
    let (r, p) = (c.nrows(), g.nrows());
    let upper = csc(n, n, |i, j| if i <= j { h[(i, j)] } else { 0.0 });
    let stacked = csc(
        r + p,
        n,
        |i, j| if i < r { c[(i, j)] } else { g[(i - r, j)] },
    );
    let q: Vec<f64> = f.iter().map(|v| -v).collect();
    let rhs: Vec<f64> = b.iter().chain(hb.iter()).copied().collect();
    let cones = [
        SupportedConeT::ZeroConeT(r),
        SupportedConeT::NonnegativeConeT(p),
    ];
    let settings = DefaultSettings {
        verbose: false,
        max_iter: 200,
        ..DefaultSettings::default()
    };
    let mut solver =
        DefaultSolver::new(&upper, &q, &stacked, &rhs, &cones, settings).map_err(|e| {
            Error::Infeasible {
                reason: format!("the bounded QP could not be set up: {e}"),
            }
        })?;
    solver.solve();
    match solver.solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => {}
        SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
            return Err(Error::Infeasible {
                reason: "no amplitudes satisfy eq. 13 within amplitudeMin/amplitudeMax/\
                         incrementMin/incrementMax; loosen the bounds or add impulses"
                    .into(),
            })
        }
        status => {
            return Err(Error::Infeasible {
                reason: format!("the bounded QP solver stopped with status {status:?}"),
            })
        }
    }
    Ok(DVector::from_column_slice(&solver.solution.x))
}

/// The active-set loop from clarabel's point `x0`: the bounds nearly active there form the
/// working set; the equality QP with them is solved exactly, a violated bound is added, a
/// bound with a multiplier of the wrong sign dropped, until neither happens (at most
/// [`MAX_ACTIVE_SET_STEPS`] times). `None` if it does not settle.
#[cfg(feature = "solver")]
fn active_set(
    h: &DMatrix<f64>,
    f: &DVector<f64>,
    c: &DMatrix<f64>,
    b: &DVector<f64>,
    g: &DMatrix<f64>,
    hb: &DVector<f64>,
    x0: &DVector<f64>,
) -> Option<DVector<f64>> {
    let n = h.nrows();
    let (r, p) = (c.nrows(), g.nrows());
    let slack = hb - g * x0;
    let mut working: Vec<usize> = (0..p)
        .filter(|&j| slack[j] <= 1e-6 * (1.0 + hb[j].abs()))
        .collect();
    for _ in 0..MAX_ACTIVE_SET_STEPS {
        let mut e = DMatrix::zeros(r + working.len(), n);
        let mut d = DVector::zeros(r + working.len());
        e.view_mut((0, 0), (r, n)).copy_from(c);
        d.rows_mut(0, r).copy_from(b);
        for (k, &j) in working.iter().enumerate() {
            e.row_mut(r + k).copy_from(&g.row(j));
            d[r + k] = hb[j];
        }
        let (x, nu) = equality_qp(h, f, &e, &d)?;
        let gx = g * &x;
        let worst = (0..p)
            .filter(|j| !working.contains(j))
            .map(|j| (gx[j] - hb[j], j))
            .fold((0.0, usize::MAX), |m, v| if v.0 > m.0 { v } else { m });
        if worst.0 > BOUND_TOLERANCE {
            working.push(worst.1);
            continue;
        }
        let scale = 1e-10 * (1.0 + nu.amax());
        let wrong = (0..working.len())
            .map(|k| (nu[r + k], k))
            .fold((0.0, usize::MAX), |m, v| if v.0 < m.0 { v } else { m });
        if wrong.0 < -scale {
            working.remove(wrong.1);
            continue;
        }
        // An active amplitude bound holds to rounding; make it exact (a zero stays a zero).
        let mut x = x;
        for &j in &working {
            let row = g.row(j);
            let mut entries = row.iter().enumerate().filter(|(_, v)| **v != 0.0);
            if let (Some((i, &coefficient)), None) = (entries.next(), entries.next()) {
                x[i] = hb[j] / coefficient;
            }
        }
        return Some(x);
    }
    None
}

/// A column-compressed matrix from a dense generator, skipping zeros.
#[cfg(feature = "solver")]
fn csc(
    rows: usize,
    cols: usize,
    value: impl Fn(usize, usize) -> f64,
) -> clarabel::algebra::CscMatrix<f64> {
    let mut colptr = Vec::with_capacity(cols + 1);
    let mut rowval = Vec::new();
    let mut nzval = Vec::new();
    colptr.push(0);
    for j in 0..cols {
        for i in 0..rows {
            let v = value(i, j);
            if v != 0.0 {
                rowval.push(i);
                nzval.push(v);
            }
        }
        colptr.push(rowval.len());
    }
    clarabel::algebra::CscMatrix::new(rows, cols, colptr, rowval, nzval)
}

/// Designs the sampled shaper `spec` describes for one mode, and checks what it promises:
/// V = 0 at the mode, times on the grid, Σ A = 1, the ramp delay mT if asked, the bounds.
///
/// ```
/// use input_shaping::design::sampled::{design, SampledSpec};
/// use input_shaping::{vibration::residual_vibration, Mode};
/// // A shaper on a 10 ms controller period (Kamel et al.): 40 samples for a 2 Hz mode.
/// let mode = Mode::new(2.0, 0.05)?;
/// let d = design(&mode, &SampledSpec::new(0.01, 40))?;
/// assert!(d.shaper.impulses().iter().all(|i| (i.time / 0.01 - (i.time / 0.01).round()).abs() < 1e-9));
/// assert!((d.shaper.amplitude_sum() - 1.0).abs() < 1e-9);
/// assert!(residual_vibration(&d.shaper, &mode) < 1e-9);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn design(mode: &Mode, spec: &SampledSpec) -> Result<SampledDesign> {
    let problem = Problem::new(mode, spec)?;
    let amplitudes = problem.solve()?;
    let cost = problem.cost(&amplitudes)?;
    let impulses: Vec<Impulse> = amplitudes
        .iter()
        .enumerate()
        .map(|(i, &a)| Impulse {
            time: i as f64 * problem.period,
            amplitude: a,
        })
        .collect();
    let start = amplitudes.iter().position(|&a| a != 0.0).unwrap_or(0);
    let shaper = Shaper::new(impulses)?;
    let start_s = start as f64 * problem.period;
    let ramp_delay_s = start_s + ramp_delay(&shaper, mode)?;
    check(&problem, &shaper, start_s, ramp_delay_s, mode)?;
    Ok(SampledDesign {
        shaper,
        start_s,
        ramp_delay_s,
        cost,
        amplitudes,
    })
}

/// Designs for a list of modes: the sampled family designs for exactly one.
///
/// ```
/// use input_shaping::design::sampled::{design_for_modes, SampledSpec};
/// use input_shaping::Mode;
/// let spec = SampledSpec::new(0.01, 40);
/// assert!(design_for_modes(&[Mode::new(2.0, 0.05)?], &spec).is_ok());
/// // The sampled family designs for one mode: a second is refused.
/// assert!(design_for_modes(&[Mode::new(2.0, 0.05)?, Mode::new(5.0, 0.05)?], &spec).is_err());
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn design_for_modes(modes: &[Mode], spec: &SampledSpec) -> Result<SampledDesign> {
    match modes {
        [mode] => design(mode, spec),
        _ => Err(Error::invalid(
            "modes",
            format!(
                "the sampled family designs for exactly one mode (its cost is that mode's \
                 deflection), got {}",
                modes.len()
            ),
        )),
    }
}

/// Independent checks of the returned shaper (evaluated from its impulses, not from the
/// solver's matrices).
fn check(
    problem: &Problem,
    shaper: &Shaper,
    start_s: f64,
    ramp_delay_s: f64,
    mode: &Mode,
) -> Result<()> {
    let fail = |what: String| {
        Err(Error::Infeasible {
            reason: format!("the sampled design failed its own check: {what}"),
        })
    };
    let magnitude: f64 = shaper.impulses().iter().map(|i| i.amplitude.abs()).sum();
    super::verify(shaper, &[*mode], &super::Guarantee::ZeroAtModes).map_err(|e| {
        if magnitude > 100.0 {
            Error::Infeasible {
                reason: format!(
                    "the constraints need amplitudes with Σ|Aᵢ| = {magnitude:.3e}, too large \
                     to cancel the vibration in floating point; add impulses, lengthen \
                     delaySamples or raise weight"
                ),
            }
        } else {
            e
        }
    })?;
    let sum = shaper.amplitude_sum();
    if (sum - 1.0).abs() > 1e-9 * magnitude.max(1.0) {
        return fail(format!("Σ A = {sum}, not 1"));
    }
    let t = problem.period;
    let mut grid = Vec::with_capacity(shaper.len());
    for imp in shaper.impulses() {
        let k = (start_s + imp.time) / t;
        if (k - k.round()).abs() > 1e-9 * k.max(1.0) {
            return fail(format!("impulse at {} s is off the {t} s grid", imp.time));
        }
        grid.push((k.round() as usize, imp.amplitude));
    }
    if let Some(m) = problem.delay {
        let target = f64::from(m) * t;
        let scale = t * magnitude.max(1.0) * problem.n as f64;
        if (ramp_delay_s - target).abs() > 1e-9 * scale {
            return fail(format!(
                "ramp delay {ramp_delay_s} s, not {m} periods = {target} s"
            ));
        }
    }
    let amplitude_at = |i: usize| grid.iter().find(|(k, _)| *k == i).map_or(0.0, |&(_, a)| a);
    let bounds = problem.bounds;
    let tol = 1e-7;
    for i in 0..problem.n {
        let a = amplitude_at(i);
        if bounds.amplitude_min.is_some_and(|lo| a < lo - tol)
            || bounds.amplitude_max.is_some_and(|hi| a > hi + tol)
        {
            return fail(format!("A{i} = {a} breaks amplitudeMin/amplitudeMax"));
        }
        if i > 0 {
            let d = a - amplitude_at(i - 1);
            if bounds.increment_min.is_some_and(|lo| d < lo - tol)
                || bounds.increment_max.is_some_and(|hi| d > hi + tol)
            {
                return fail(format!(
                    "A{i} − A{} = {d} breaks incrementMin/incrementMax",
                    i - 1
                ));
            }
        }
    }
    Ok(())
}

/// What [`report`] returns: the shaper in its wire form plus the ramp delay and the cost, and
/// the cost of the minimum-norm shaper under the same constraints for comparison.
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct SampledReport {
    /// `{ impulses, duration }`, as `design` returns it.
    #[serde(flatten)]
    pub shaper: ShaperData,
    /// Time of the first non-zero impulse within the designed sequence, s.
    pub start_time: f64,
    /// τ of eq. 10, s.
    pub ramp_delay: f64,
    /// J_q (eq. 17) of the design.
    pub cost: Cost,
    /// J_q (same Q, same reference) of the minimum-norm amplitudes under the same constraints.
    pub baseline_cost: Cost,
    /// 1 − cost.total / baselineCost.total (Kamel et al. §6 report up to 0.35).
    pub cost_reduction: f64,
}

/// Designs and reports: the design of `spec` and, for comparison, the minimum-norm design with
/// the same constraints, both costed with the spec's Q and reference.
///
/// ```
/// use input_shaping::design::sampled::{report, SampledSpec};
/// use input_shaping::Mode;
/// let r = report(&[Mode::new(2.0, 0.05)?], &SampledSpec::new(0.01, 40))?;
/// // The designed amplitudes cost no more than the minimum-norm ones under the same constraints.
/// assert!(r.cost.total <= r.baseline_cost.total * (1.0 + 1e-9));
/// assert!((r.cost_reduction - (1.0 - r.cost.total / r.baseline_cost.total)).abs() < 1e-12);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn report(modes: &[Mode], spec: &SampledSpec) -> Result<SampledReport> {
    let designed = design_for_modes(modes, spec)?;
    let baseline_spec = SampledSpec {
        objective: Objective::MinimumNorm,
        ..spec.clone()
    };
    let baseline = design_for_modes(modes, &baseline_spec)?;
    let mode = modes
        .first()
        .ok_or_else(|| Error::invalid("modes", "at least one mode is required"))?;
    let problem = Problem::new(mode, spec)?;
    let baseline_cost = problem.cost(&baseline.amplitudes)?;
    Ok(SampledReport {
        shaper: designed.shaper.to_data(),
        start_time: designed.start_s,
        ramp_delay: designed.ramp_delay_s,
        cost: designed.cost,
        baseline_cost,
        cost_reduction: 1.0 - designed.cost.total / baseline_cost.total,
    })
}
