//! Helpers shared by the integration tests: an evaluation of residual vibration that does not
//! use the library's formula, by superposing the oscillator's impulse responses in time.
#![allow(dead_code)]

use input_shaping::{Mode, Shaper};

/// Residual vibration amplitude after the last impulse, relative to a single unit impulse,
/// computed from the time response: y(t) = Σ Aᵢ e^{−ζω(t−tᵢ)} sin(ω_d(t−tᵢ)) (the response of
/// y'' + 2ζωy' + ω²y = impulse, up to a constant). At t = t_n the free oscillation has
/// amplitude √(y² + ((y' + ζωy)/ω_d)²); the single unit impulse's is 1 at t = 0.
pub fn residual_by_superposition(shaper: &Shaper, mode: &Mode) -> f64 {
    let w = mode.omega_rad_s();
    let z = mode.damping();
    let wd = mode.damped_omega_rad_s();
    let t = shaper.duration();
    let (mut y, mut dy) = (0.0, 0.0);
    for imp in shaper.impulses() {
        let tau = t - imp.time;
        let e = (-z * w * tau).exp();
        y += imp.amplitude * e * (wd * tau).sin();
        dy += imp.amplitude * e * (wd * (wd * tau).cos() - z * w * (wd * tau).sin());
    }
    (y * y + ((dy + z * w * y) / wd).powi(2)).sqrt()
}

/// Asserts `a ≈ b` within `tol`, with a message.
pub fn close(a: f64, b: f64, tol: f64, what: &str) {
    assert!(
        (a - b).abs() <= tol,
        "{what}: got {a}, expected {b} (tolerance {tol})"
    );
}

/// Kamel, Lange & Hirzinger §6 / Fig. 3: ω = 30 rad/s, D = 0.02.
pub fn kamel_mode() -> Mode {
    Mode::new(30.0 / (2.0 * std::f64::consts::PI), 0.02).unwrap()
}

/// Kamel, Lange & Hirzinger §6 / Fig. 3: K = 8·10⁻⁴, T = 12 ms, n = 36, m = 17, Q = 0.1·I.
pub fn kamel_spec() -> input_shaping::design::sampled::SampledSpec {
    input_shaping::design::sampled::SampledSpec {
        delay_samples: Some(17),
        plant_gain: Some(8e-4),
        ..input_shaping::design::sampled::SampledSpec::new(0.012, 36)
    }
}

/// xorshift64* and Box–Muller: deterministic noise without a dependency (the same sequence on
/// every machine and in wasm).
pub struct Rng(pub u64);

impl Rng {
    /// Uniform on (0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// Standard normal.
    pub fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }
}
