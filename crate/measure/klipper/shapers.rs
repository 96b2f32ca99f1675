//! Klipper's shaper table: the six families `calibrate_shaper` fits, as Klipper defines them.
//!
//! Read from Klipper3d/klipper `klippy/extras/shaper_defs.py` (the 2020–2026 version, commit
//! 1819369886bac3e5210674c0e9b36ae60619ce82, functions `get_zv_shaper`, `get_zvd_shaper`,
//! `get_mzv_shaper` / `get_mzv_coeffs`, `get_ei_shaper`, `get_2hump_ei_shaper`,
//! `get_3hump_ei_shaper`, table `INPUT_SHAPERS`); the code here is our own.
//!
//! These are **not** the crate's exact families ([`mod@crate::design`]): Klipper's EI, 2-hump EI
//! and 3-hump EI with damping are polynomial fits in ζ (its EI: a quadratic in ζ for the
//! amplitudes and a cubic for the middle time, with the tolerance V = 1/20 folded in; its
//! multi-hump EIs: cubics in ζ for every amplitude and time, the times scaled by the undamped
//! period 1/f, not the damped one), and its MZV places three impulses over 0.75 of the damped
//! period. ZV and ZVD are Singer & Seering's closed forms. At the default `damping_ratio` 0.1 a
//! Klipper EI therefore differs from the exact EI of the same frequency by a few 10⁻³ in
//! amplitude and time.
//!
//! The amplitudes are Klipper's, not normalised (ZV is `[1, K]`): every figure Klipper derives
//! (V, smoothing, max_accel) divides by Σ Aᵢ, and so does this crate. Call
//! [`Shaper::normalized`] for unit gain.

use crate::error::{finite, positive, Error, Result};
use crate::shaper::{Impulse, Shaper};

/// Klipper's `SHAPER_VIBRATION_REDUCTION`: a shaper is taken to cut vibration at most 20 times
/// (the EI families' tolerance is its inverse, 5 %).
pub const SHAPER_VIBRATION_REDUCTION: f64 = 20.0;
/// Klipper's `DEFAULT_DAMPING_RATIO`: the damping ratio the shapers are built for.
pub const DEFAULT_DAMPING_RATIO: f64 = 0.1;

/// One entry of Klipper's table (`InputShaperCfg`).
#[derive(Debug, Clone, Copy)]
pub struct KlipperShaperDef {
    /// Klipper's name (`zv`, `mzv`, `zvd`, `ei`, `2hump_ei`, `3hump_ei`).
    pub name: &'static str,
    /// Lowest frequency `fit_shaper` scans by default, Hz (chosen by Klipper for a projected
    /// max_accel of about 1500 mm/s²).
    pub min_freq_hz: f64,
    /// Largest `damping_ratio` Klipper's config accepts for this shaper.
    pub max_damping_ratio: f64,
    /// Amplitudes and times (s) at (frequency Hz, damping ratio).
    build: fn(f64, f64) -> (Vec<f64>, Vec<f64>),
}

impl KlipperShaperDef {
    /// Klipper's amplitudes and times (s) of this shaper at `freq_hz` and `damping_ratio`,
    /// unchecked (the caller validates; see [`klipper_shaper`]).
    pub fn amplitudes_times(&self, freq_hz: f64, damping_ratio: f64) -> (Vec<f64>, Vec<f64>) {
        (self.build)(freq_hz, damping_ratio)
    }
}

/// Klipper's table, in its order (`INPUT_SHAPERS`).
pub const KLIPPER_SHAPERS: [KlipperShaperDef; 6] = [
    KlipperShaperDef {
        name: "zv",
        min_freq_hz: 21.0,
        max_damping_ratio: 0.99,
        build: zv,
    },
    KlipperShaperDef {
        name: "mzv",
        min_freq_hz: 23.0,
        max_damping_ratio: 0.99,
        build: mzv,
    },
    KlipperShaperDef {
        name: "zvd",
        min_freq_hz: 29.0,
        max_damping_ratio: 0.99,
        build: zvd,
    },
    KlipperShaperDef {
        name: "ei",
        min_freq_hz: 29.0,
        max_damping_ratio: 0.4,
        build: ei,
    },
    KlipperShaperDef {
        name: "2hump_ei",
        min_freq_hz: 39.0,
        max_damping_ratio: 0.3,
        build: ei2,
    },
    KlipperShaperDef {
        name: "3hump_ei",
        min_freq_hz: 48.0,
        max_damping_ratio: 0.2,
        build: ei3,
    },
];

/// The families `calibrate_shaper` tries when none are named (`AUTOTUNE_SHAPERS`; ZVD is in
/// the table but not tried by default).
pub const AUTOTUNE_SHAPERS: [&str; 5] = ["zv", "mzv", "ei", "2hump_ei", "3hump_ei"];

/// The table entry named `name` (Klipper's `get_shaper_cfg`, without its `name(args)` syntax).
pub fn shaper_def(name: &str) -> Option<&'static KlipperShaperDef> {
    KLIPPER_SHAPERS.iter().find(|d| d.name == name)
}

/// Klipper's shaper `name` at `freq_hz` and `damping_ratio` (Klipper's `init_shaper`).
///
/// Errors: an unknown name (field `shaper`), a frequency that is not finite and positive, a
/// damping ratio outside [0, the family's `max_damping_ratio`].
pub fn klipper_shaper(name: &str, freq_hz: f64, damping_ratio: f64) -> Result<Shaper> {
    let def = shaper_def(name).ok_or_else(|| {
        Error::invalid(
            "shaper",
            format!(
                "unknown Klipper shaper '{name}' (known: {})",
                KLIPPER_SHAPERS.map(|d| d.name).join(", ")
            ),
        )
    })?;
    positive("shaperFrequencyHz", freq_hz)?;
    finite("dampingRatio", damping_ratio)?;
    if !(0.0..=def.max_damping_ratio).contains(&damping_ratio) {
        return Err(Error::invalid(
            "dampingRatio",
            format!(
                "Klipper's {name} accepts 0 … {}, got {damping_ratio}",
                def.max_damping_ratio
            ),
        ));
    }
    let (a, t) = def.amplitudes_times(freq_hz, damping_ratio);
    Shaper::new(
        a.into_iter()
            .zip(t)
            .map(|(amplitude, time)| Impulse { time, amplitude })
            .collect(),
    )
}

/// √(1 − ζ²), the damped-to-undamped frequency ratio.
fn damped(zeta: f64) -> f64 {
    (1.0 - zeta * zeta).sqrt()
}

/// ZV (Singer & Seering 1988): amplitudes 1, K with K = e^{−ζπ/√(1−ζ²)}, half a damped period
/// apart.
fn zv(f: f64, zeta: f64) -> (Vec<f64>, Vec<f64>) {
    let df = damped(zeta);
    let k = (-zeta * std::f64::consts::PI / df).exp();
    let t_d = 1.0 / (f * df);
    (vec![1.0, k], vec![0.0, 0.5 * t_d])
}

/// ZVD (Singer & Seering 1988): 1, 2K, K² at 0, T_d/2, T_d.
fn zvd(f: f64, zeta: f64) -> (Vec<f64>, Vec<f64>) {
    let df = damped(zeta);
    let k = (-zeta * std::f64::consts::PI / df).exp();
    let t_d = 1.0 / (f * df);
    (vec![1.0, 2.0 * k, k * k], vec![0.0, 0.5 * t_d, t_d])
}

/// Klipper's MZV with its defaults (n = 3 impulses over t = 0.75 damped periods): the undamped
/// amplitudes solve Σ A = 1 with a zero of the transform at the shaper frequency (Klipper's
/// `get_mzv_coeffs`, whose second zero at 5/3 f is implied), which for n = 3, t = 3/4 is
/// 1 − 1/√2, √2 − 1, 1 − 1/√2 at 0, 3/8, 3/4 of T_d; then impulse i is scaled by Kⁱ with
/// K = e^{−2tζπ/((n−1)√(1−ζ²))} = e^{−0.75ζπ/√(1−ζ²)}.
fn mzv(f: f64, zeta: f64) -> (Vec<f64>, Vec<f64>) {
    let df = damped(zeta);
    let k = (-0.75 * zeta * std::f64::consts::PI / df).exp();
    let t_d = 1.0 / (f * df);
    let a1 = 1.0 - std::f64::consts::FRAC_1_SQRT_2;
    let a2 = std::f64::consts::SQRT_2 - 1.0;
    (
        vec![a1, a2 * k, a1 * k * k],
        vec![0.0, 0.375 * t_d, 0.75 * t_d],
    )
}

/// Klipper's damped EI (`get_ei_shaper`, V = 1/20): amplitudes quadratic and the middle time
/// cubic in ζ, with coefficients linear or quadratic in V; times in damped periods.
fn ei(f: f64, zeta: f64) -> (Vec<f64>, Vec<f64>) {
    let v = 1.0 / SHAPER_VIBRATION_REDUCTION;
    let df = damped(zeta);
    let t_d = 1.0 / (f * df);
    let z = zeta;
    // Horner's rule in ζ, as Klipper evaluates them.
    let a1 = (0.24968 + 0.24961 * v) + ((0.80008 + 1.23328 * v) + (0.49599 + 3.17316 * v) * z) * z;
    let a3 = (0.25149 + 0.21474 * v) + ((-0.83249 + 1.41498 * v) + (0.85181 - 4.90094 * v) * z) * z;
    let a2 = 1.0 - a1 - a3;
    let t2 = 0.4999
        + ((0.46159 + 8.57843 * v) * v
            + ((4.26169 - 108.644 * v) * v + (1.75601 + 336.989 * v) * v * z) * z)
            * z;
    (vec![a1, a2, a3], vec![0.0, t2 * t_d, t_d])
}

/// Cubic c₀ + c₁ζ + c₂ζ² + c₃ζ³ by Horner's rule (Klipper's `_get_shaper_from_expansion_coeffs`
/// evaluates the same way).
fn cubic(c: &[f64; 4], z: f64) -> f64 {
    ((c[3] * z + c[2]) * z + c[1]) * z + c[0]
}

/// A multi-hump EI from Klipper's expansion coefficients: time i = cubic(tᵢ, ζ)/f (undamped
/// period), amplitude i = cubic(aᵢ, ζ).
fn from_expansion<const N: usize>(
    f: f64,
    zeta: f64,
    t: &[[f64; 4]; N],
    a: &[[f64; 4]; N],
) -> (Vec<f64>, Vec<f64>) {
    let tau = 1.0 / f;
    (
        a.iter().map(|c| cubic(c, zeta)).collect(),
        t.iter().map(|c| cubic(c, zeta) * tau).collect(),
    )
}

/// Klipper's 2-hump EI (`get_2hump_ei_shaper`): the coefficients of its table.
fn ei2(f: f64, zeta: f64) -> (Vec<f64>, Vec<f64>) {
    const T: [[f64; 4]; 4] = [
        [0.0, 0.0, 0.0, 0.0],
        [0.49890, 0.16270, -0.54262, 6.16180],
        [0.99748, 0.18382, -1.58270, 8.17120],
        [1.49920, -0.09297, -0.28338, 1.85710],
    ];
    const A: [[f64; 4]; 4] = [
        [0.16054, 0.76699, 2.26560, -1.22750],
        [0.33911, 0.45081, -2.58080, 1.73650],
        [0.34089, -0.61533, -0.68765, 0.42261],
        [0.15997, -0.60246, 1.00280, -0.93145],
    ];
    from_expansion(f, zeta, &T, &A)
}

/// Klipper's 3-hump EI (`get_3hump_ei_shaper`): the coefficients of its table.
fn ei3(f: f64, zeta: f64) -> (Vec<f64>, Vec<f64>) {
    const T: [[f64; 4]; 5] = [
        [0.0, 0.0, 0.0, 0.0],
        [0.49974, 0.23834, 0.44559, 12.4720],
        [0.99849, 0.29808, -2.36460, 23.3990],
        [1.49870, 0.10306, -2.01390, 17.0320],
        [1.99960, -0.28231, 0.61536, 5.40450],
    ];
    const A: [[f64; 4]; 5] = [
        [0.11275, 0.76632, 3.29160, -1.44380],
        [0.23698, 0.61164, -2.57850, 4.85220],
        [0.30008, -0.19062, -2.14560, 0.13744],
        [0.23775, -0.73297, 0.46885, -2.08650],
        [0.11244, -0.45439, 0.96382, -1.46000],
    ];
    from_expansion(f, zeta, &T, &A)
}
