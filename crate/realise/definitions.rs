//! The shaper families as each firmware defines them, read from its source (GPL: read and cited,
//! never copied; the code is ours). Every function returns amplitudes (not normalised; V divides
//! by Σ A) and times in seconds, first at 0.
//!
//! Notation: f the shaper frequency (Hz), ζ its damping ratio, d = √(1 − ζ²),
//! K = e^{−ζπ/d} (the decay over half a damped period), T_d = 1/(f d).
//!
//! Three sets of definitions are in use:
//! - **Klipper's current table** (Klipper3d/klipper klippy/extras/shaper_defs.py, 2020–2026,
//!   commit 1819369): EI, 2-hump and 3-hump EI are polynomial fits in ζ; implemented in
//!   [`crate::measure::klipper::shapers`] and reused from there.
//! - **The K-scaled forms** of Klipper's earlier shaper_defs.py (2020–2023), which Kalico
//!   keeps (KalicoCrew/kalico klippy/extras/shaper_defs.py, `get_ei_shaper`,
//!   `get_2hump_ei_shaper`, `get_3hump_ei_shaper`, commit 1bb4236), Prusa's Buddy firmware
//!   ported (prusa3d/Prusa-Firmware-Buddy lib/Marlin/Marlin/src/feature/input_shaper/
//!   input_shaper.cpp, `input_shaper::get`) and Marlin's FT_MOTION uses
//!   (Marlin/src/module/ft_motion/shaping.cpp, `AxisShaping::set_axis_shaping_A`): the
//!   undamped EI amplitudes (Singhose 2009) multiplied by powers of K, at multiples of T_d/2.
//!   They are [`k_scaled`].
//! - **RepRapFirmware's** (src/Movement/AxisShaper.cpp, `AxisShaper::Configure`): ZVD, ZVDD,
//!   ZVDDD binomial, MZV as Klipper's, and EI2/EI3 with Klipper's fitted coefficients but the
//!   times scaled by the *damped* period and the last amplitude 1 − Σ of the others
//!   ([`rrf_fitted_ei`]).

use crate::measure::klipper::shapers::shaper_def;
use std::f64::consts::{FRAC_1_SQRT_2, PI, SQRT_2};

/// A family a firmware names (the crate's `zv`, `zvd`, `zvdd`, `zvdn` up to 3 derivatives,
/// `mzv`, `ei`/`ei2`/`ei3` and `eihump` up to 3 humps).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Named {
    /// Zero vibration, 2 impulses.
    Zv,
    /// ZVD, 3 impulses.
    Zvd,
    /// ZVDD, 4 impulses.
    Zvdd,
    /// ZVDDD, 5 impulses.
    Zvddd,
    /// Klipper's modified ZV, 3 impulses over 0.75 T_d.
    Mzv,
    /// EI with hump height `vtol`.
    Ei(f64),
    /// Two-hump EI.
    Ei2(f64),
    /// Three-hump EI.
    Ei3(f64),
}

impl Named {
    /// The crate's family name (`zv`, …, `ei3`).
    pub fn name(self) -> &'static str {
        match self {
            Named::Zv => "zv",
            Named::Zvd => "zvd",
            Named::Zvdd => "zvdd",
            Named::Zvddd => "zvddd",
            Named::Mzv => "mzv",
            Named::Ei(_) => "ei",
            Named::Ei2(_) => "ei2",
            Named::Ei3(_) => "ei3",
        }
    }

    /// The EI families' hump height, if any.
    pub fn vtol(self) -> Option<f64> {
        match self {
            Named::Ei(v) | Named::Ei2(v) | Named::Ei3(v) => Some(v),
            _ => None,
        }
    }

    /// Klipper's name (`klippy/extras/shaper_defs.py`, `INPUT_SHAPERS`), if Klipper has it.
    pub fn klipper_name(self) -> Option<&'static str> {
        match self {
            Named::Zv => Some("zv"),
            Named::Zvd => Some("zvd"),
            Named::Mzv => Some("mzv"),
            Named::Ei(_) => Some("ei"),
            Named::Ei2(_) => Some("2hump_ei"),
            Named::Ei3(_) => Some("3hump_ei"),
            Named::Zvdd | Named::Zvddd => None,
        }
    }
}

/// Amplitudes and times (s).
pub type Pulses = (Vec<f64>, Vec<f64>);

/// √(1 − ζ²) and K = e^{−ζπ/√(1−ζ²)}.
fn d_and_k(zeta: f64) -> (f64, f64) {
    let d = (1.0 - zeta * zeta).sqrt();
    (d, (-zeta * PI / d).exp())
}

/// The binomial ZV-Dⁿ amplitudes C(n, i)·Kⁱ at i·T_d/2 (Singer & Seering 1988), n = 1 … 4 —
/// Marlin FT_MOTION's ZV … ZVDDD (`set_axis_shaping_A`), RRF's ZVD … ZVDDD and Klipper's ZV,
/// ZVD.
pub fn binomial(n: usize, f: f64, zeta: f64) -> Pulses {
    let (d, k) = d_and_k(zeta);
    let half = 0.5 / (f * d);
    let mut c = 1.0;
    let mut amplitudes = Vec::with_capacity(n + 1);
    for i in 0..=n {
        amplitudes.push(c * k.powi(i as i32));
        c = c * (n - i) as f64 / (i + 1) as f64;
    }
    (amplitudes, (0..=n).map(|i| i as f64 * half).collect())
}

/// Klipper's MZV (shaper_defs.py `get_mzv_shaper` at n = 3, t = 0.75), also Kalico's, Prusa's
/// and RRF's: 1 − 1/√2, (√2 − 1)K_m, (1 − 1/√2)K_m² at 0, 0.375 T_d, 0.75 T_d, with
/// K_m = e^{−0.75ζπ/d} (the decay over 0.375 T_d).
pub fn mzv(f: f64, zeta: f64) -> Pulses {
    let (d, _) = d_and_k(zeta);
    let km = (-0.75 * zeta * PI / d).exp();
    let a1 = 1.0 - FRAC_1_SQRT_2;
    let t_d = 1.0 / (f * d);
    (
        vec![a1, (SQRT_2 - 1.0) * km, a1 * km * km],
        vec![0.0, 0.375 * t_d, 0.75 * t_d],
    )
}

/// Marlin FT_MOTION's MZV (shaping.cpp, `set_axis_shaping_A`, case `ftMotionShaper_MZV`):
/// 1, √2·K, K² at 0, 0.375 T_d, 0.75 T_d — the undamped ratios of Klipper's MZV, but scaled by
/// the decay over *half* a damped period K where the impulses are 0.375 T_d apart, so with
/// damping its zero leaves the mode (V ≠ 0 at ζ > 0 even with exact times).
pub fn marlin_ft_mzv(f: f64, zeta: f64) -> Pulses {
    let (d, k) = d_and_k(zeta);
    let t_d = 1.0 / (f * d);
    (
        vec![1.0, SQRT_2 * k, k * k],
        vec![0.0, 0.375 * t_d, 0.75 * t_d],
    )
}

/// The K-scaled EI forms (Kalico `get_ei_shaper` …, Prusa `input_shaper::get`, Marlin
/// `set_axis_shaping_A`): `humps` = 1, 2, 3 with hump height `vtol`, impulses at multiples of
/// T_d/2.
///
/// - EI: ¼(1+V), ½(1−V)K, ¼(1+V)K².
/// - 2-hump: X = (V²(√(1−V²)+1))^{1/3}, a₁ = (3X² + 2X + 3V²)/(16X), a₂ = (½ − a₁)K,
///   a₃ = a₂K, a₄ = a₁K³.
/// - 3-hump: a₁ = (1 + 3V + 2√(2(V+1)V))/16, a₂ = ¼(1−V)K, a₃ = (½(1+V) − 2a₁)K², a₄ = a₂K²,
///   a₅ = a₁K⁴.
pub fn k_scaled_ei(humps: usize, f: f64, zeta: f64, vtol: f64) -> Pulses {
    let (d, k) = d_and_k(zeta);
    let half = 0.5 / (f * d);
    let v = vtol;
    let amplitudes = match humps {
        1 => {
            let a1 = 0.25 * (1.0 + v);
            vec![a1, 0.5 * (1.0 - v) * k, a1 * k * k]
        }
        2 => {
            let v2 = v * v;
            let x = (v2 * ((1.0 - v2).sqrt() + 1.0)).cbrt();
            let a1 = (3.0 * x * x + 2.0 * x + 3.0 * v2) / (16.0 * x);
            let a2 = (0.5 - a1) * k;
            vec![a1, a2, a2 * k, a1 * k.powi(3)]
        }
        _ => {
            let k2 = k * k;
            let a1 = 0.0625 * (1.0 + 3.0 * v + 2.0 * (2.0 * (v + 1.0) * v).sqrt());
            let a2 = 0.25 * (1.0 - v) * k;
            vec![
                a1,
                a2,
                (0.5 * (1.0 + v) - 2.0 * a1) * k2,
                a2 * k2,
                a1 * k2 * k2,
            ]
        }
    };
    let n = amplitudes.len();
    (amplitudes, (0..n).map(|i| i as f64 * half).collect())
}

/// A family in the K-scaled set (Kalico, Prusa; Marlin FT_MOTION except its MZV): ZV … ZVDDD
/// binomial, MZV Klipper's, EIs [`k_scaled_ei`].
pub fn k_scaled(named: Named, f: f64, zeta: f64) -> Pulses {
    match named {
        Named::Zv => binomial(1, f, zeta),
        Named::Zvd => binomial(2, f, zeta),
        Named::Zvdd => binomial(3, f, zeta),
        Named::Zvddd => binomial(4, f, zeta),
        Named::Mzv => mzv(f, zeta),
        Named::Ei(v) => k_scaled_ei(1, f, zeta, v),
        Named::Ei2(v) => k_scaled_ei(2, f, zeta, v),
        Named::Ei3(v) => k_scaled_ei(3, f, zeta, v),
    }
}

/// RRF's EI2 (`humps` = 2) or EI3 (3) (AxisShaper.cpp, `AxisShaper::Configure`, cases `ei2`,
/// `ei3`): Klipper's fitted coefficients, but RRF multiplies the fitted times by the damped
/// period `StepClockRate/dampedFrequency` where Klipper uses 1/f, and stores cumulative
/// coefficients for all impulses but the last, whose amplitude is therefore 1 − Σ of the
/// others (Klipper normalises the fitted ones instead).
pub fn rrf_fitted_ei(humps: usize, f: f64, zeta: f64) -> Pulses {
    let name = if humps == 2 { "2hump_ei" } else { "3hump_ei" };
    let (mut amplitudes, times) = match shaper_def(name) {
        Some(def) => def.amplitudes_times(f, zeta),
        None => return (vec![1.0], vec![0.0]),
    };
    let d = (1.0 - zeta * zeta).sqrt();
    let n = amplitudes.len();
    let others: f64 = amplitudes[..n - 1].iter().sum();
    amplitudes[n - 1] = 1.0 - others;
    (amplitudes, times.iter().map(|t| t / d).collect())
}

/// Marlin's classic ZV amplitudes in 1/128 (Marlin/src/module/stepper.cpp,
/// `Stepper::set_shaping_damping_ratio`): the echo gets `factor2` = ⌊64.44056192 −
/// 99.02008832ζ − 7.58095488ζ² + 43.073216ζ³⌋ (a cubic fit of 128·K/(1+K)), 64 at ζ ≤ 0 and 0
/// at ζ ≥ 1; the step itself `factor1` = 128 − factor2.
pub fn marlin_zv_factors(zeta: f64) -> (u32, u32) {
    let factor2 = if zeta <= 0.0 {
        64.0
    } else if zeta >= 1.0 {
        0.0
    } else {
        // Marlin's literals are doubles, so the sum is formed in double precision and stored
        // in a float between terms; the f32 storage moves the sum by < 1e-5, which matters only
        // within that distance of an integer.
        let fit = 64.440_561_92 - 99.020_088_32 * zeta - 7.580_954_88 * zeta * zeta
            + 43.073_216 * zeta * zeta * zeta;
        fit.floor()
    };
    let factor2 = factor2.clamp(0.0, 128.0) as u32;
    (128 - factor2, factor2)
}

/// Marlin's classic ZV delay in stepper timer ticks (stepper.cpp,
/// `Stepper::set_shaping_frequency`): `float(uint32_t(STEPPER_TIMER_RATE) / 2) / freq`
/// converted to the integer `shaping_time_t`, i.e. truncated — half the *undamped* period
/// (the damping ratio does not enter the delay).
pub fn marlin_zv_delay_ticks(timer_rate_hz: f64, f: f64) -> f64 {
    ((timer_rate_hz / 2.0).floor() / f).trunc()
}
