//! Residual vibration V(ω, ζ) of a shaper, and what is built on it: sensitivity curves over
//! frequency and over damping, the frequency × damping map, and insensitivity bands.
//!
//! [`vibration_rad`] is the one implementation of Singhose 2009 eq. 11; every curve, chart,
//! metric and design check calls it. The one fast path, [`sensitivity_map`], evaluates the same
//! per-impulse term on a grid by recurrence and is tested point by point against it.
//!
//! A shaper that is a convolution (the multi-mode designs) is analysed through its factors: V of
//! a convolution is the product of the factors' V, so a curve of a three-mode ZVD costs 9
//! impulse terms per point instead of 27 (see [`Shaper`]; tested against the impulses).
//! Design checks still evaluate the impulses themselves.

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
///
/// ```
/// use input_shaping::{vibration::vibration_rad, Impulse};
/// let zv = [Impulse { time: 0.0, amplitude: 0.5 }, Impulse { time: 0.5, amplitude: 0.5 }];
/// let omega = 2.0 * std::f64::consts::PI * 0.8; // 0.8 Hz on a ZV for 1 Hz: |cos(0.4π)|
/// assert!((vibration_rad(&zv, omega, 0.0) - (0.4 * std::f64::consts::PI).cos()).abs() < 1e-12);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn vibration_rad(impulses: &[Impulse], omega: f64, zeta: f64) -> f64 {
    let [c, s] = vibration_moment(impulses, omega, zeta, 0);
    magnitude(c, s)
}

/// √(c² + s²), as `c.hypot(s)` but without its cost in wasm: wasm has no fused multiply-add,
/// and the libm `hypot` Rust links there emulates one in software (in the page's six-mode
/// profile `hypot` and its `fma` took 0.7 ms an update, in the `si` design's 3 %). Where
/// neither square can overflow or lose its last bits to underflow (|c|, |s| between 2⁻⁴⁰⁰
/// and 2⁴⁰⁰: every vibration phasor of a shaper) the plain formula, within an ulp or two of
/// `hypot`; elsewhere `hypot` itself.
#[inline(never)]
pub(crate) fn magnitude(c: f64, s: f64) -> f64 {
    const BIG: f64 = 2.582_249_878_086_908_6e120; // 2^400
    const SMALL: f64 = 1.0 / BIG;
    let m = c.abs().max(s.abs());
    if m < BIG && (m > SMALL || m == 0.0) {
        (c * c + s * s).sqrt()
    } else {
        c.hypot(s)
    }
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
///
/// ```
/// use input_shaping::vibration::vibration_moment;
/// use input_shaping::Impulse;
/// // ZVD ([1, 2, 1]/4 every half period, undamped) has V = 0 and dV/dω = 0 at its mode:
/// // its moments M₀ and M₁ vanish there, M₂ does not.
/// let zvd = [(0.0, 0.25), (0.5, 0.5), (1.0, 0.25)].map(|(time, amplitude)| Impulse { time, amplitude });
/// let omega = 2.0 * std::f64::consts::PI;
/// let norm = |[c, s]: [f64; 2]| c.hypot(s);
/// assert!(norm(vibration_moment(&zvd, omega, 0.0, 0)) < 1e-12);
/// assert!(norm(vibration_moment(&zvd, omega, 0.0, 1)) < 1e-12);
/// assert!(norm(vibration_moment(&zvd, omega, 0.0, 2)) > 0.1);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn vibration_moment(impulses: &[Impulse], omega: f64, zeta: f64, k: u32) -> [f64; 2] {
    let t_n = impulses.last().map_or(0.0, |imp| imp.time);
    let damped = (1.0 - zeta * zeta).sqrt();
    let (mut c, mut s) = (0.0, 0.0);
    for imp in impulses {
        let w = if k == 0 {
            imp.amplitude
        } else {
            imp.amplitude * imp.time.powi(k as i32)
        };
        let (re, im) = term(w, imp.time, t_n, omega, zeta, damped);
        c += re;
        s += im;
    }
    [c, s]
}

/// The moments M₀ … M_`k_max` of [`vibration_moment`] in one pass over the impulses: each
/// impulse's exponential and sine/cosine are computed once for every order (the polish of
/// [`crate::solve`] needs M₀ and M₁ at every active point, and all orders at every zero).
/// The arithmetic per order is that of [`vibration_moment`], so the numbers are the same to the
/// last bit.
pub(crate) fn vibration_moments(
    impulses: &[Impulse],
    omega: f64,
    zeta: f64,
    k_max: u32,
) -> Vec<[f64; 2]> {
    let t_n = impulses.last().map_or(0.0, |imp| imp.time);
    let damped = (1.0 - zeta * zeta).sqrt();
    moments_of_factors(
        impulses,
        |i| moment_factor(impulses[i].time, t_n, omega, zeta, damped),
        k_max,
    )
}

/// One impulse's factors in [`vibration_moments`] at time `time` (the last impulse at `t_n`,
/// `damped` = √(1 − ζ²)): [e^{−ζω(t_n − t)}, sin ω_d t, cos ω_d t].
#[inline]
pub(crate) fn moment_factor(time: f64, t_n: f64, omega: f64, zeta: f64, damped: f64) -> [f64; 3] {
    let decay = (-(zeta * omega) * (t_n - time)).exp();
    let (sin, cos) = sin_cos(omega * damped * time);
    [decay, sin, cos]
}

/// (sin x, cos x). In wasm, `f64::sin_cos` is libm's `sin` and `cos` one after the other, each
/// reducing x modulo π/2 itself; libm's `sincos` reduces once and runs the same kernels — the
/// same bits (test `sincos_is_sin_and_cos`, run in wasm) in 8–9 % less time for a three-mode
/// `si` design (issue 24). Only where the solver is built: the page's size-tuned module keeps the
/// two calls it already carries. Natively `sin_cos` is the platform's `sincos` already.
#[inline]
pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
    #[cfg(all(target_arch = "wasm32", feature = "solver"))]
    {
        libm::sincos(x)
    }
    #[cfg(not(all(target_arch = "wasm32", feature = "solver")))]
    {
        x.sin_cos()
    }
}

/// The moments M₀ … M_`k_max` of [`vibration_moments`] from each impulse's factors
/// ([`moment_factor`]; `factor(i)` for impulse i), summed in the impulses' order: the polish's
/// Jacobian keeps the factors of the impulses a column does not move.
#[inline]
pub(crate) fn moments_of_factors(
    impulses: &[Impulse],
    factor: impl Fn(usize) -> [f64; 3],
    k_max: u32,
) -> Vec<[f64; 2]> {
    let mut sums = vec![[0.0, 0.0]; k_max as usize + 1];
    for (i, imp) in impulses.iter().enumerate() {
        let [decay, sin, cos] = factor(i);
        for (k, sum) in sums.iter_mut().enumerate() {
            let a = if k == 0 {
                imp.amplitude
            } else {
                imp.amplitude * imp.time.powi(k as i32)
            };
            let w = a * decay;
            sum[0] += w * cos;
            sum[1] += w * sin;
        }
    }
    sums
}

/// The contribution of a unit impulse at `time` to the vibration phasor of eq. 11 when the last
/// impulse of the sequence is at `t_n`: e^{−ζω(t_n − t)} (cos ω_d t, sin ω_d t). V is the length
/// of Σ Aᵢ · phasor(tᵢ), so once the times are fixed V is the norm of a vector linear in the
/// amplitudes (what the convex design programs of [`crate::solve`] use).
///
/// ```
/// use input_shaping::vibration::{impulse_phasor, vibration_rad};
/// use input_shaping::Impulse;
/// // V is the length of Σ Aᵢ · phasor(tᵢ).
/// let impulses = [Impulse { time: 0.0, amplitude: 0.6 }, Impulse { time: 0.3, amplitude: 0.4 }];
/// let (omega, zeta, tn) = (7.0, 0.05, 0.3);
/// let [c, s] = impulses.iter().fold([0.0, 0.0], |[c, s], i| {
///     let [pc, ps] = impulse_phasor(i.time, tn, omega, zeta);
///     [c + i.amplitude * pc, s + i.amplitude * ps]
/// });
/// assert!((c.hypot(s) - vibration_rad(&impulses, omega, zeta)).abs() < 1e-12);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn impulse_phasor(time: f64, t_n: f64, omega: f64, zeta: f64) -> [f64; 2] {
    let (c, s) = term(1.0, time, t_n, omega, zeta, (1.0 - zeta * zeta).sqrt());
    [c, s]
}

/// One impulse's contribution to eq. 11, already multiplied by the factor e^{−ζω t_n}:
/// A e^{−ζω(t_n − t)} (cos ω_d t, sin ω_d t), with ω_d = ω·`damped` and `damped` = √(1−ζ²).
///
/// As a function of ω (ζ fixed) this is A·exp(ω·(−ζ(t_n − t) + i√(1−ζ²) t)): an exponential
/// in ω, so on evenly spaced frequencies it is a geometric sequence. [`sensitivity_map`] uses
/// that to step along a row with one complex multiplication per impulse instead of an `exp`
/// and a `sin_cos`.
#[inline]
fn term(amplitude: f64, time: f64, t_n: f64, omega: f64, zeta: f64, damped: f64) -> (f64, f64) {
    let [decay, sin, cos] = moment_factor(time, t_n, omega, zeta, damped);
    let w = amplitude * decay;
    (w * cos, w * sin)
}

/// Residual vibration V of `shaper` on `mode` (fraction: 0 = none, 1 = as much as unshaped).
///
/// ```
/// use input_shaping::{design::zero_vibration::zv, vibration::residual_vibration, Mode};
/// // Undamped ZV: V(f) = |cos(πf/2f₀)| (Singhose 2009 eq. 11 with [1/2, 1/2] at [0, T/2]).
/// let shaper = zv(&Mode::new(1.0, 0.0)?)?;
/// let v = residual_vibration(&shaper, &Mode::new(1.1, 0.0)?);
/// assert!((v - (0.55 * std::f64::consts::PI).cos().abs()).abs() < 1e-12);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn residual_vibration(shaper: &Shaper, mode: &Mode) -> f64 {
    shaper_vibration(shaper, mode.omega_rad_s(), mode.damping())
}

/// V of `shaper` at (`omega`, `zeta`): [`vibration_rad`] of its impulses, or the product of its
/// convolution factors' (the same number to rounding, for Σ nₖ instead of Π nₖ terms; see
/// [`Shaper`]).
pub(crate) fn shaper_vibration(shaper: &Shaper, omega: f64, zeta: f64) -> f64 {
    shaper
        .factors()
        .map(|f| vibration_rad(f, omega, zeta))
        .product()
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
///
/// ```
/// use input_shaping::vibration::{sensitivity, SensitivityOptions};
/// use input_shaping::{design::zero_vibration::zv, Mode};
/// let shaper = zv(&Mode::new(1.0, 0.0)?)?;
/// let options = SensitivityOptions { from_hz: 0.0, to_hz: 2.0, points: 21, damping: 0.0 };
/// let curve = sensitivity(&shaper, &options)?;
/// for (f, v) in curve.frequency_hz.iter().zip(&curve.vibration) {
///     assert!((v - (std::f64::consts::FRAC_PI_2 * f).cos().abs()).abs() < 1e-12);
/// }
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn sensitivity(shaper: &Shaper, options: &SensitivityOptions) -> Result<SensitivityCurve> {
    frequency_range(options.from_hz, options.to_hz)?;
    count("points", options.points, 2, MAX_CURVE_POINTS)?;
    let zeta = damping_ratio("damping", options.damping)?;
    let frequency_hz: Vec<f64> = linspace(options.from_hz, options.to_hz, options.points).collect();
    let step = (options.to_hz - options.from_hz) / (options.points - 1) as f64;
    let mut vibration = Vec::with_capacity(options.points);
    shaper_on_grid(
        shaper,
        options.from_hz,
        step,
        options.points,
        zeta,
        &mut vibration,
    );
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
/// Most impulse evaluations spent tracing one side of a band (bounds the time for long
/// shapers: ~0.1 s in the browser).
const MAX_SCAN_WORK: f64 = 2e7;
/// Frequencies evaluated per batch while tracing a band.
const SCAN_CHUNK: usize = 256;

/// Frequency insensitivity I(Vtol) of `shaper` at `mode` (damping held at the mode's): the
/// band edges are bracketed by a scan fine enough for the shaper's duration and refined to
/// machine precision by the ITP method (Oliveira & Takahashi 2020: about 10 evaluations of
/// eq. 11 per edge, never more than bisection + 3).
///
/// The upper edge's scan stops early where V is bounded below Vtol for good: with damping,
/// |W| ≤ Σ|Aᵢ| e^{−ζω(t_n − tᵢ)}, which only falls as ω grows, so once the product of the
/// factors' bounds is under Vtol no frequency above can leave the band (a product of six
/// factors gets there within tens of hertz, where a scan to 50 × f took ~10⁵ points). The
/// result is [`insensitivity_full_scan`]'s bit for bit: its scan would find nothing there.
///
/// ```
/// use input_shaping::{design::zero_vibration::zv, vibration::insensitivity, Mode};
/// // Undamped ZV: V = |cos(πr/2)| ≤ Vtol for |r − 1| ≤ 2·asin(Vtol)/π, so I = 4·asin(Vtol)/π.
/// let mode = Mode::new(1.0, 0.0)?;
/// let band = insensitivity(&zv(&mode)?, &mode, 0.05)?;
/// let half = 2.0 * 0.05_f64.asin() / std::f64::consts::PI;
/// assert!((band.low_hz - (1.0 - half)).abs() < 1e-9 && (band.high_hz - (1.0 + half)).abs() < 1e-9);
/// assert!((band.width - 2.0 * half).abs() < 1e-9);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn insensitivity(shaper: &Shaper, mode: &Mode, vtol: f64) -> Result<Insensitivity> {
    // One mode's joint scan is its own (one code path in the page's module).
    let bands = insensitivities(shaper, std::slice::from_ref(mode), vtol)?;
    Ok(bands[0])
}

/// [`insensitivity`] as it was computed before the decay bound: every upper edge scanned to its
/// crossing or to 50 × f. Kept as the reference the faster scans are tested against
/// (`tests/factored.rs`) and for benchmarks; the same band, slower.
pub fn insensitivity_full_scan(shaper: &Shaper, mode: &Mode, vtol: f64) -> Result<Insensitivity> {
    tolerable_vibration(vtol)?;
    Ok(BandScan::new(shaper, mode.damping(), vtol, false).band(mode.frequency_hz()))
}

/// [`insensitivity`] at each of `modes`, the bands scanned jointly: the band around a mode is
/// the connected part of {f : V(f) ≤ Vtol} holding it, so a mode inside a band already traced
/// at the same damping has that band — its lower edge, and its upper edge up to its own limit of
/// 50 × f (the scan resumes from the other mode's limit when that was reached). A product of
/// factors often stays under Vtol across several modes (issue 24's six modes: one band from
/// ~2.3 Hz up for modes 2 … 6), which each mode's own scan would walk again. A band is shared
/// only between modes whose own scans are fine enough to see every crossing (40 points per
/// period of V's oscillation, not coarsened by the work bound); the others are scanned alone.
/// The same bands as [`insensitivity`] mode by mode, up to the refinement's last bits (tested).
pub fn insensitivities(shaper: &Shaper, modes: &[Mode], vtol: f64) -> Result<Vec<Insensitivity>> {
    tolerable_vibration(vtol)?;
    let mut bands: Vec<Insensitivity> = Vec::with_capacity(modes.len());
    for (j, mode) in modes.iter().enumerate() {
        let (f_m, zeta) = (mode.frequency_hz(), mode.damping());
        let scan = BandScan::new(shaper, zeta, vtol, true);
        // Only scans at their resolved steps are shared: a scan coarsened to bound its work
        // may step over a crossing that another mode's grid sees, and each mode's band must
        // stay the one its own scan finds.
        let shared = modes[..j].iter().zip(&bands).find(|(other, b)| {
            other.damping() == zeta
                && b.low_hz < f_m
                && f_m < b.high_hz
                && scan.resolved(other.frequency_hz())
                && scan.resolved(f_m)
        });
        let band = match shared {
            Some((other, b)) if scan.excess(f_m) <= 0.0 => {
                let (limit_i, limit) =
                    (other.frequency_hz() * MAX_BAND_RATIO, f_m * MAX_BAND_RATIO);
                let high_hz = if b.high_hz < limit_i || limit <= limit_i {
                    // A crossing above both modes, or this mode's limit inside the band.
                    b.high_hz.min(limit)
                } else {
                    scan.edge(f_m, limit_i, 1.0, limit)
                };
                Insensitivity {
                    low_hz: b.low_hz,
                    high_hz,
                    width: (high_hz - b.low_hz) / f_m,
                }
            }
            _ => scan.band(f_m),
        };
        bands.push(band);
    }
    Ok(bands)
}

/// The scan of [`insensitivity`]'s band edges for one shaper, damping ratio and Vtol.
struct BandScan<'a> {
    shaper: &'a Shaper,
    zeta: f64,
    /// Vtol with its slack: V above this is outside the band.
    threshold: f64,
    /// Whether the upper scans may end on the decay bound (damping, and not the full scan).
    bounded: bool,
}

impl<'a> BandScan<'a> {
    fn new(shaper: &'a Shaper, zeta: f64, vtol: f64, bounded: bool) -> Self {
        BandScan {
            shaper,
            zeta,
            threshold: vtol * (1.0 + VTOL_SLACK) + 1e-14,
            bounded: bounded && zeta > 0.0,
        }
    }

    /// V(f) − threshold.
    fn excess(&self, f: f64) -> f64 {
        shaper_vibration(self.shaper, 2.0 * std::f64::consts::PI * f, self.zeta) - self.threshold
    }

    /// Whether V ≤ threshold at every frequency ≥ `f`: Π over the factors of
    /// Σ|Aᵢ| e^{−ζω(t_n − tᵢ)} (each factor's |W| at ω and above, since the terms only decay as
    /// ω grows) is under it, with room for rounding.
    fn under_for_good(&self, f: f64) -> bool {
        if !self.bounded {
            return false;
        }
        let zw = self.zeta * 2.0 * std::f64::consts::PI * f;
        let bound: f64 = self
            .shaper
            .factors()
            .map(|imps| {
                let t_n = imps.last().map_or(0.0, |imp| imp.time);
                imps.iter()
                    .map(|imp| imp.amplitude.abs() * (-zw * (t_n - imp.time)).exp())
                    .sum::<f64>()
            })
            .product();
        bound * (1.0 + 1e-12) <= self.threshold
    }

    /// The band around `f_m`.
    fn band(&self, f_m: f64) -> Insensitivity {
        if self.excess(f_m) > 0.0 {
            return Insensitivity {
                low_hz: f_m,
                high_hz: f_m,
                width: 0.0,
            };
        }
        let high_hz = self.edge(f_m, f_m, 1.0, f_m * MAX_BAND_RATIO);
        let low_hz = self.edge(f_m, f_m, -1.0, 0.0);
        Insensitivity {
            low_hz,
            high_hz,
            width: (high_hz - low_hz) / f_m,
        }
    }

    /// The step of the scan from the mode at `f_m` towards `limit`, and whether it is the
    /// resolved one (at least 40 points per period of V's oscillation and 400 per f_m, not
    /// coarsened to bound the work).
    fn step(&self, f_m: f64, limit: f64) -> (f64, bool) {
        let per_period = 1.0 / (40.0 * self.shaper.duration().max(f64::MIN_POSITIVE));
        let span = (limit - f_m).abs();
        let resolved = (0.0025 * f_m).min(per_period);
        let step = resolved
            .max(span * self.shaper.expanded_len() as f64 / MAX_SCAN_WORK)
            .max(span / 2e6);
        (step, step == resolved)
    }

    /// Whether both of the scans of the band around `f_m` run at their resolved steps.
    fn resolved(&self, f_m: f64) -> bool {
        self.step(f_m, f_m * MAX_BAND_RATIO).1 && self.step(f_m, 0.0).1
    }

    /// The band's edge from `start` (inside) towards `limit` for the mode at `f_m`: the first
    /// crossing, refined, or `limit`. Out of line: called from two places, inlined it costs the
    /// page's module its size twice.
    #[inline(never)]
    fn edge(&self, f_m: f64, start: f64, direction: f64, limit: f64) -> f64 {
        let excess = |f: f64| self.excess(f);
        // V oscillates in f with period ~1/duration; sample it at least 40 times per period, but
        // spend at most MAX_SCAN_WORK impulse-evaluations per side (coarser beyond that). The
        // impulses counted are the expanded shaper's (Π nₖ for a factored one), as before
        // shapers were kept factored, though a convolution is evaluated from its Σ nₖ factor
        // impulses: counting those instead (a finer step, the same work bound) made I(Vtol) at
        // issue 24's six modes take 70 ms for ZVDD and 87 ms for ZV-D³ natively (2026-12-04,
        // docs/page-performance.md), the bands of modes 2 … 6 reaching their 50 × f limits.
        let h = direction * self.step(f_m, limit).0;
        let mut rows = Rows::new(self.shaper, h);
        let mut values = Vec::with_capacity(SCAN_CHUNK);
        let mut inside = start;
        loop {
            if direction > 0.0 && self.under_for_good(inside) {
                return limit;
            }
            let remaining = ((limit - inside) / h).floor().max(0.0) as usize;
            let n = remaining.min(SCAN_CHUNK);
            if n == 0 {
                return if excess(limit) > 0.0 {
                    refine_crossing(&excess, inside, limit)
                } else {
                    limit
                };
            }
            rows.fill(inside + h, self.zeta, &mut values, n);
            if let Some(k) = values.iter().position(|&v| v > self.threshold) {
                let outside = inside + h * (k + 1) as f64;
                return refine_crossing(&excess, inside + h * k as f64, outside);
            }
            inside += h * n as f64;
        }
    }
}

/// Walks from `start` (where `excess ≤ 0`) towards `limit` in steps of `step` and returns the
/// first crossing of `excess` above 0, refined by [`refine_crossing`], or `limit` if there is
/// none. At most ~`max_steps` evaluations whatever the inputs (the step is coarsened beyond
/// that).
fn band_edge(
    excess: &impl Fn(f64) -> f64,
    start: f64,
    limit: f64,
    step: f64,
    max_steps: f64,
) -> f64 {
    let direction = if limit >= start { 1.0 } else { -1.0 };
    let step = step.max((limit - start).abs() / max_steps);
    let mut inside = start;
    // The step bound above makes this at most ~max_steps rounds; the cap only guards rounding.
    for _ in 0..(max_steps as usize).saturating_add(100) {
        let next = inside + direction * step;
        let beyond = if direction > 0.0 {
            next >= limit
        } else {
            next <= limit
        };
        if beyond {
            return if excess(limit) > 0.0 {
                refine_crossing(excess, inside, limit)
            } else {
                limit
            };
        }
        if excess(next) > 0.0 {
            return refine_crossing(excess, inside, next);
        }
        inside = next;
    }
    inside
}

/// Checks a tolerable vibration level 0 < `vtol` < 1 (field `vtol`).
pub(crate) fn tolerable_vibration(vtol: f64) -> Result<f64> {
    positive("vtol", vtol)?;
    if vtol >= 1.0 {
        return Err(Error::invalid(
            "vtol",
            format!("tolerable vibration must be below 1 (100 %), got {vtol}"),
        ));
    }
    Ok(vtol)
}

/// The crossing of `g` between `inside` (g ≤ 0) and `outside` (g > 0), to machine precision:
/// the midpoint of a bracket shrunk to at most 2ε·max(|inside|, |outside|) (ε the machine
/// epsilon), so within about one unit in the last place of the crossing.
///
/// The steps are the ITP method (Oliveira & Takahashi, ACM TOMS 47(1), 2020: interpolate,
/// truncate, project; κ₁ = 0.2 / |outside − inside|, κ₂ = 2, n₀ = 1): a false-position point
/// nudged towards the midpoint and kept within the distance from it that still guarantees
/// bisection's step count plus one. On a smooth crossing that is about 10 evaluations of `g`
/// where bisection takes ~50, and never more than bisection + 3 (the 3: both ends are
/// evaluated, and n₀). The steps stay at least ε·max(|inside|, |outside|) inside the bracket, so an
/// exact zero of `g` on the inside does not stall the outside end. A NaN of `g` counts as
/// inside, as it does for plain bisection (false position is then not used).
fn refine_crossing(g: &impl Fn(f64) -> f64, inside: f64, outside: f64) -> f64 {
    // [a, b] with a < b; `b_outside` says which end is outside (g > 0).
    let b_outside = inside <= outside;
    let (mut a, mut b) = if b_outside {
        (inside, outside)
    } else {
        (outside, inside)
    };
    let (mut ga, mut gb) = (g(a), g(b));
    let eps = f64::EPSILON * a.abs().max(b.abs()).max(f64::MIN_POSITIVE);
    // Bisection's step count to the tolerance, plus n₀ = 1 (the bracket's width is at most
    // 2^2098 times eps, so this fits an i32).
    let n_max = ((b - a) / (2.0 * eps)).log2().ceil().clamp(0.0, 4096.0) as i32 + 1;
    let kappa1 = 0.2 / (b - a);
    for j in 0..200 {
        let mid = 0.5 * (a + b);
        if b - a <= 2.0 * eps || mid == a || mid == b {
            break;
        }
        let x = if ga.is_finite() && gb.is_finite() && (ga > 0.0) != (gb > 0.0) {
            let delta = kappa1 * (b - a) * (b - a);
            let falsi = (b * ga - a * gb) / (ga - gb);
            let toward = if mid >= falsi { 1.0 } else { -1.0 };
            let truncated = if delta <= (mid - falsi).abs() {
                falsi + toward * delta
            } else {
                mid
            };
            let radius = (eps * 2f64.powi(n_max - j) - 0.5 * (b - a)).max(0.0);
            if (truncated - mid).abs() <= radius {
                truncated
            } else {
                mid - toward * radius
            }
        } else {
            mid
        };
        let x = if x.is_finite() {
            x.clamp(a + eps, b - eps)
        } else {
            mid
        };
        let gx = g(x);
        if (gx > 0.0) == b_outside {
            b = x;
            gb = gx;
        } else {
            a = x;
            ga = gx;
        }
    }
    0.5 * (a + b)
}

/// V at the evenly spaced frequencies `from_hz + k·step_hz`, k = 0 … n−1 (`step_hz` may be
/// negative), written to `out` (cleared first): the same quantity as [`vibration_rad`] by the
/// map's recurrence (see [`sensitivity_map`]), agreeing with it to ~1e-13 (tested).
///
/// ```
/// use input_shaping::vibration::{vibration_on_grid, vibration_rad};
/// use input_shaping::Impulse;
/// let zvd = [(0.0, 0.25), (0.5, 0.5), (1.0, 0.25)].map(|(time, amplitude)| Impulse { time, amplitude });
/// let mut v = Vec::new();
/// vibration_on_grid(&zvd, 0.5, 0.01, 101, 0.02, &mut v); // 0.5 … 1.5 Hz at ζ = 0.02
/// for (k, v) in v.iter().enumerate() {
///     let omega = 2.0 * std::f64::consts::PI * (0.5 + 0.01 * k as f64);
///     assert!((v - vibration_rad(&zvd, omega, 0.02)).abs() < 1e-12);
/// }
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn vibration_on_grid(
    impulses: &[Impulse],
    from_hz: f64,
    step_hz: f64,
    n: usize,
    zeta: f64,
    out: &mut Vec<f64>,
) {
    out.clear();
    out.resize(n, 0.0);
    RowEvaluator::new(impulses, step_hz).fill(from_hz, zeta, out);
}

/// [`vibration_on_grid`] for a shaper: its impulses, or the product of its convolution
/// factors' rows (see [`Shaper`]).
pub(crate) fn shaper_on_grid(
    shaper: &Shaper,
    from_hz: f64,
    step_hz: f64,
    n: usize,
    zeta: f64,
    out: &mut Vec<f64>,
) {
    Rows::new(shaper, step_hz).fill(from_hz, zeta, out, n);
}

/// The complex residual-vibration phasor of an impulse sequence and its derivatives, for the
/// designs that solve for impulses with Newton's method (EI with damping, unity-magnitude,
/// bang-bang).
///
/// With t_L the time of the *last impulse of the slice* (t_n for a sorted shaper),
/// P(ω) = Σ Aᵢ e^{−ζω(t_L − tᵢ)} e^{iω_d tᵢ}, so |P| is exactly V of Singhose 2009 eq. 11
/// ([`vibration_rad`]). Writing P = Σ Aᵢ e^{ω sᵢ} with sᵢ = λtᵢ − ζt_L and λ = ζ + i√(1−ζ²):
///
/// - ∂P/∂ω = Σ Aᵢ sᵢ e^{ωsᵢ}, ∂²P/∂ω² = Σ Aᵢ sᵢ² e^{ωsᵢ};
/// - ∂P/∂Aₖ = e^{ωsₖ}, ∂²P/∂ω∂Aₖ = sₖ e^{ωsₖ};
/// - ∂P/∂tₖ = ωλAₖe^{ωsₖ} − [k = L] ωζP,
///   ∂²P/∂ω∂tₖ = λAₖ(1 + ωsₖ)e^{ωsₖ} − [k = L] ζ(P + ω ∂P/∂ω).
#[derive(Debug, Clone, PartialEq)]
pub struct VibrationPhasor {
    /// P(ω); its modulus is V.
    pub value: nalgebra::Complex<f64>,
    /// ∂P/∂ω.
    pub d_omega: nalgebra::Complex<f64>,
    /// ∂²P/∂ω².
    pub d_omega2: nalgebra::Complex<f64>,
    /// ∂P/∂Aₖ for each impulse k.
    pub d_amplitude: Vec<nalgebra::Complex<f64>>,
    /// ∂P/∂tₖ for each impulse k (the last one also moves the reference time t_L).
    pub d_time: Vec<nalgebra::Complex<f64>>,
    /// ∂²P/∂ω∂Aₖ for each impulse k.
    pub d_omega_d_amplitude: Vec<nalgebra::Complex<f64>>,
    /// ∂²P/∂ω∂tₖ for each impulse k.
    pub d_omega_d_time: Vec<nalgebra::Complex<f64>>,
}

/// [`VibrationPhasor`] of `impulses` (in the given order; the last one is the reference) at
/// undamped frequency `omega` (rad/s) and damping ratio `zeta` (0 ≤ ζ < 1, the caller's to
/// ensure).
///
/// ```
/// use input_shaping::vibration::{vibration_phasor, vibration_rad};
/// use input_shaping::Impulse;
/// let zv = [Impulse { time: 0.0, amplitude: 0.5 }, Impulse { time: 0.5, amplitude: 0.5 }];
/// let p = vibration_phasor(&zv, 5.0, 0.0);
/// assert!((p.value.norm() - vibration_rad(&zv, 5.0, 0.0)).abs() < 1e-12); // |P| = V
/// // ∂P/∂ω against a central difference.
/// let h = 1e-6;
/// let d = (vibration_phasor(&zv, 5.0 + h, 0.0).value - vibration_phasor(&zv, 5.0 - h, 0.0).value) / (2.0 * h);
/// assert!((p.d_omega - d).norm() < 1e-6);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn vibration_phasor(impulses: &[Impulse], omega: f64, zeta: f64) -> VibrationPhasor {
    let lambda = nalgebra::Complex::new(zeta, (1.0 - zeta * zeta).sqrt());
    let t_last = impulses.last().map_or(0.0, |imp| imp.time);
    let n = impulses.len();
    let mut out = VibrationPhasor {
        value: nalgebra::Complex::new(0.0, 0.0),
        d_omega: nalgebra::Complex::new(0.0, 0.0),
        d_omega2: nalgebra::Complex::new(0.0, 0.0),
        d_amplitude: Vec::with_capacity(n),
        d_time: Vec::with_capacity(n),
        d_omega_d_amplitude: Vec::with_capacity(n),
        d_omega_d_time: Vec::with_capacity(n),
    };
    for imp in impulses {
        let s = lambda * imp.time - zeta * t_last;
        let e = (s * omega).exp();
        out.value += e * imp.amplitude;
        out.d_omega += s * e * imp.amplitude;
        out.d_omega2 += s * s * e * imp.amplitude;
        out.d_amplitude.push(e);
        out.d_omega_d_amplitude.push(s * e);
        out.d_time.push(lambda * e * (omega * imp.amplitude));
        out.d_omega_d_time
            .push(lambda * (s * omega + 1.0) * e * imp.amplitude);
    }
    if let (Some(dt), Some(dwdt)) = (out.d_time.last_mut(), out.d_omega_d_time.last_mut()) {
        *dt -= out.value * (omega * zeta);
        *dwdt -= (out.value + out.d_omega * omega) * zeta;
    }
    out
}
/// Checks a plant frequency 0 < f ≤ [`crate::mode::MAX_FREQUENCY_HZ`] given in field `field`.
fn plant_frequency(field: &str, frequency_hz: f64) -> Result<f64> {
    positive(field, frequency_hz)?;
    if frequency_hz > crate::mode::MAX_FREQUENCY_HZ {
        return Err(Error::invalid(
            field,
            format!(
                "must be at most {} Hz, got {frequency_hz}",
                crate::mode::MAX_FREQUENCY_HZ
            ),
        ));
    }
    Ok(frequency_hz)
}

/// Checks a damping range `from` … `to` (0 ≤ from < to < 1) given in fields `from_field`,
/// `to_field`.
fn damping_range(from_field: &str, from: f64, to_field: &str, to: f64) -> Result<()> {
    damping_ratio(from_field, from)?;
    damping_ratio(to_field, to)?;
    if to <= from {
        return Err(Error::invalid(
            to_field,
            format!("must be greater than {from_field} ({from}), got {to}"),
        ));
    }
    Ok(())
}

// ----------------------------------------------------------------------------------------------
// Sensitivity to the damping ratio

/// Options of a sensitivity curve V(ζ) at a fixed frequency.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct DampingSensitivityOptions {
    /// Undamped natural frequency of the plant in Hz (> 0).
    pub frequency_hz: f64,
    /// First damping ratio, 0 ≤ ζ < 1.
    pub from_damping: f64,
    /// Last damping ratio, `from_damping` < ζ < 1.
    pub to_damping: f64,
    /// Number of evenly spaced damping ratios, 2 … [`MAX_CURVE_POINTS`].
    pub points: usize,
}

/// A sensitivity curve over damping: V at evenly spaced damping ratios, frequency fixed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct DampingSensitivityCurve {
    /// Damping ratios ζ.
    pub damping: Vec<f64>,
    /// Residual vibration (fraction) at each damping ratio.
    pub vibration: Vec<f64>,
}

/// The sensitivity curve V(ζ) of `shaper` over a range of damping ratios at one undamped
/// natural frequency: how much vibration is left when the plant's damping is not the one the
/// shaper was designed for (Singhose 2009 eq. 11 read as a function of ζ; Fig. 10 is the
/// surface it is one section of).
///
/// ```
/// use input_shaping::vibration::{damping_sensitivity, residual_vibration, DampingSensitivityOptions};
/// use input_shaping::{design::zero_vibration::zvd, Mode};
/// let shaper = zvd(&Mode::new(1.0, 0.0)?)?;
/// let options = DampingSensitivityOptions { frequency_hz: 1.0, from_damping: 0.0, to_damping: 0.3, points: 7 };
/// let curve = damping_sensitivity(&shaper, &options)?;
/// assert!(curve.vibration[0] < 1e-12); // designed for ζ = 0
/// for (&z, &v) in curve.damping.iter().zip(&curve.vibration) {
///     assert!((v - residual_vibration(&shaper, &Mode::new(1.0, z)?)).abs() < 1e-12);
/// }
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn damping_sensitivity(
    shaper: &Shaper,
    options: &DampingSensitivityOptions,
) -> Result<DampingSensitivityCurve> {
    let f = plant_frequency("frequencyHz", options.frequency_hz)?;
    damping_range(
        "fromDamping",
        options.from_damping,
        "toDamping",
        options.to_damping,
    )?;
    count("points", options.points, 2, MAX_CURVE_POINTS)?;
    let omega = 2.0 * std::f64::consts::PI * f;
    let damping: Vec<f64> =
        linspace(options.from_damping, options.to_damping, options.points).collect();
    let vibration = damping
        .iter()
        .map(|&z| shaper_vibration(shaper, omega, z))
        .collect();
    Ok(DampingSensitivityCurve { damping, vibration })
}

/// The damping insensitivity band of a shaper at a mode: the contiguous range of damping ratios
/// containing the mode's damping where V ≤ Vtol, at the mode's (undamped natural) frequency.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct DampingInsensitivity {
    /// Lower band edge (damping ratio, ≥ 0).
    pub low_damping: f64,
    /// Upper band edge (damping ratio, ≤ [`MAX_BAND_DAMPING`]).
    pub high_damping: f64,
    /// Band width `high_damping − low_damping`, in damping ratio (ζ is already dimensionless, so
    /// unlike the frequency insensitivity it is not divided by the mode's value). 0 when V
    /// exceeds Vtol at the mode itself.
    pub width: f64,
}

/// Upper edges of a damping band are searched up to this damping ratio.
pub const MAX_BAND_DAMPING: f64 = 0.999;

/// Damping insensitivity of `shaper` at `mode` (frequency held at the mode's): the band of ζ
/// where V(ω_m, ζ) ≤ Vtol around the mode's damping. The edges are bracketed by a scan with step
/// min(10⁻³, 0.1/(ω_m t_n)) in ζ (V's phase ω√(1−ζ²)tᵢ and decay ζω(t_n − tᵢ) change by at most
/// ~ω t_n per unit of ζ away from ζ → 1) and refined by the ITP method, as in [`insensitivity`].
///
/// ```
/// use input_shaping::vibration::{damping_insensitivity, residual_vibration};
/// use input_shaping::{design::zero_vibration::zv, Mode};
/// let mode = Mode::new(1.0, 0.1)?;
/// let shaper = zv(&mode)?; // V = Vtol at both edges of the band
/// let band = damping_insensitivity(&shaper, &mode, 0.05)?;
/// assert!(band.low_damping < 0.1 && 0.1 < band.high_damping);
/// for z in [band.low_damping, band.high_damping] {
///     assert!((residual_vibration(&shaper, &Mode::new(1.0, z)?) - 0.05).abs() < 1e-6);
/// }
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn damping_insensitivity(
    shaper: &Shaper,
    mode: &Mode,
    vtol: f64,
) -> Result<DampingInsensitivity> {
    tolerable_vibration(vtol)?;
    let omega = mode.omega_rad_s();
    let z_m = mode.damping();
    let threshold = vtol * (1.0 + VTOL_SLACK) + 1e-14;
    let excess = |z: f64| shaper_vibration(shaper, omega, z) - threshold;
    if excess(z_m) > 0.0 {
        return Ok(DampingInsensitivity {
            low_damping: z_m,
            high_damping: z_m,
            width: 0.0,
        });
    }
    let step = 1e-3_f64.min(0.1 / (omega * shaper.duration()).max(f64::MIN_POSITIVE));
    // At most 10⁵ steps per side (ζ spans less than 1).
    let high_damping = band_edge(&excess, z_m, MAX_BAND_DAMPING.max(z_m), step, 1e5);
    let low_damping = band_edge(&excess, z_m, 0.0, step, 1e5);
    Ok(DampingInsensitivity {
        low_damping,
        high_damping,
        width: high_damping - low_damping,
    })
}

// ----------------------------------------------------------------------------------------------
// The frequency × damping map

/// Most grid points along either axis of a sensitivity map.
pub const MAX_MAP_AXIS_POINTS: usize = 2000;
/// Most grid points of a sensitivity map in total (frequency points × damping points).
pub const MAX_MAP_POINTS: usize = 1_000_000;

/// Options of a sensitivity map V(f, ζ) on an evenly spaced frequency × damping grid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct SensitivityMapOptions {
    /// First frequency in Hz (≥ 0).
    pub from_hz: f64,
    /// Last frequency in Hz (> `from_hz`).
    pub to_hz: f64,
    /// Number of frequencies, 2 … [`MAX_MAP_AXIS_POINTS`].
    pub frequency_points: usize,
    /// First damping ratio, 0 ≤ ζ < 1.
    pub damping_from: f64,
    /// Last damping ratio, `damping_from` < ζ < 1.
    pub damping_to: f64,
    /// Number of damping ratios, 2 … [`MAX_MAP_AXIS_POINTS`]; frequency points × damping points
    /// at most [`MAX_MAP_POINTS`].
    pub damping_points: usize,
}

/// A sensitivity map: V on a frequency × damping grid (Singhose 2009 Fig. 10).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct SensitivityMap {
    /// Frequencies in Hz (the columns).
    pub frequency_hz: Vec<f64>,
    /// Damping ratios (the rows).
    pub damping: Vec<f64>,
    /// Residual vibration (fraction), row-major: one row per damping ratio, so
    /// `vibration[k * frequency_hz.len() + j]` is V at `damping[k]`, `frequency_hz[j]`.
    pub vibration: Vec<f64>,
}

impl SensitivityMap {
    /// Row `k`: V over the frequencies at `damping[k]` (`None` past the last row).
    pub fn row(&self, k: usize) -> Option<&[f64]> {
        let n = self.frequency_hz.len();
        self.vibration
            .get(k.checked_mul(n)?..k.checked_add(1)?.checked_mul(n)?)
    }

    /// V at `damping[k]`, `frequency_hz[j]` (`None` outside the grid).
    pub fn get(&self, k: usize, j: usize) -> Option<f64> {
        self.row(k)?.get(j).copied()
    }
}

/// The sensitivity map V(f, ζ) of `shaper` on an evenly spaced grid (Singhose 2009 Fig. 10).
///
/// Each row (one damping ratio) is computed with a geometric recurrence. Per impulse, the term
/// of eq. 11 is A·exp(ω·(−ζ(t_n − tᵢ) + i√(1−ζ²)tᵢ)), exponential in ω, so its value at f + Δf
/// is its value at f times a fixed complex factor: a grid point costs one complex
/// multiply-add per impulse instead of an `exp` and a `sin_cos`. Eight neighbouring
/// frequencies advance side by side (each by the factor for 8Δf), which lets the compiler
/// vectorise, and every [`MAP_RESEED`] points the terms are recomputed from the formula, so
/// rounding never accumulates over more than ~40 multiplications. Tests check
/// every point against [`vibration_rad`] to 10⁻¹².
///
/// ```
/// use input_shaping::vibration::{residual_vibration, sensitivity_map, SensitivityMapOptions};
/// use input_shaping::{design::zero_vibration::zvd, Mode};
/// let shaper = zvd(&Mode::new(1.0, 0.05)?)?;
/// let options = SensitivityMapOptions {
///     from_hz: 0.5, to_hz: 1.5, frequency_points: 11, damping_from: 0.0, damping_to: 0.2, damping_points: 5,
/// };
/// let map = sensitivity_map(&shaper, &options)?;
/// let (k, j) = (1, 4); // ζ = 0.05, f = 0.9 Hz
/// let exact = residual_vibration(&shaper, &Mode::new(map.frequency_hz[j], map.damping[k])?);
/// assert!((map.get(k, j).unwrap() - exact).abs() < 1e-12);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn sensitivity_map(shaper: &Shaper, options: &SensitivityMapOptions) -> Result<SensitivityMap> {
    frequency_range(options.from_hz, options.to_hz)?;
    let nf = count(
        "frequencyPoints",
        options.frequency_points,
        2,
        MAX_MAP_AXIS_POINTS,
    )?;
    damping_range(
        "dampingFrom",
        options.damping_from,
        "dampingTo",
        options.damping_to,
    )?;
    let nz = count(
        "dampingPoints",
        options.damping_points,
        2,
        MAX_MAP_AXIS_POINTS,
    )?;
    if nf * nz > MAX_MAP_POINTS {
        return Err(Error::TooLarge {
            field: "frequencyPoints × dampingPoints".into(),
            value: (nf * nz) as f64,
            limit: MAX_MAP_POINTS as f64,
        });
    }
    let frequency_hz: Vec<f64> = linspace(options.from_hz, options.to_hz, nf).collect();
    let damping: Vec<f64> = linspace(options.damping_from, options.damping_to, nz).collect();
    let mut vibration = vec![0.0; nf * nz];
    let step_hz = (options.to_hz - options.from_hz) / (nf - 1) as f64;
    let mut rows = Rows::new(shaper, step_hz);
    for (row, &zeta) in vibration.chunks_exact_mut(nf).zip(&damping) {
        rows.fill_slice(options.from_hz, zeta, row);
    }
    Ok(SensitivityMap {
        frequency_hz,
        damping,
        vibration,
    })
}

/// [`RowEvaluator`]s for each convolution factor of a shaper (see [`Shaper`]): V on a row of
/// frequencies is the product of the factors' rows.
struct Rows {
    factors: Vec<RowEvaluator>,
    scratch: Vec<f64>,
}

impl Rows {
    fn new(shaper: &Shaper, step_hz: f64) -> Self {
        Rows {
            factors: shaper
                .factors()
                .map(|f| RowEvaluator::new(f, step_hz))
                .collect(),
            scratch: Vec::new(),
        }
    }

    /// Writes V(`from_hz` + k·step, `zeta`), k = 0 … n−1, to `out` (cleared first).
    fn fill(&mut self, from_hz: f64, zeta: f64, out: &mut Vec<f64>, n: usize) {
        out.clear();
        out.resize(n, 0.0);
        self.fill_slice(from_hz, zeta, out);
    }

    /// Writes V(`from_hz` + k·step, `zeta`) into `out[k]` for every k.
    fn fill_slice(&mut self, from_hz: f64, zeta: f64, out: &mut [f64]) {
        let Some((first, rest)) = self.factors.split_first_mut() else {
            return;
        };
        first.fill(from_hz, zeta, out);
        for factor in rest {
            self.scratch.clear();
            self.scratch.resize(out.len(), 0.0);
            factor.fill(from_hz, zeta, &mut self.scratch);
            for (v, w) in out.iter_mut().zip(&self.scratch) {
                *v *= w;
            }
        }
    }
}

/// Frequencies advanced side by side in [`sensitivity_map`].
const MAP_LANES: usize = 8;
/// Points of a map row between two recomputations from the formula (a multiple of the 8
/// frequencies advanced side by side).
pub const MAP_RESEED: usize = 256;

/// Scratch space for evaluating V on evenly spaced frequencies (rows of a sensitivity map,
/// curves, band traces): allocated once, reused for every row.
struct RowEvaluator {
    /// Spacing of the frequencies, Hz (negative to walk downwards).
    step_hz: f64,
    /// Impulse times and amplitudes divided by `scale` (so |amplitude| ≤ 1 and C² + S² cannot
    /// overflow however large the user's amplitudes are).
    times: Vec<f64>,
    amplitudes: Vec<f64>,
    scale: f64,
    t_n: f64,
    /// Per impulse, the current contributions (real, imaginary) at the frequencies of the lanes.
    re: Vec<[f64; MAP_LANES]>,
    im: Vec<[f64; MAP_LANES]>,
    /// Per impulse, the factor that advances a contribution by Δf and by `MAP_LANES`·Δf.
    step: Vec<(f64, f64)>,
    stride: Vec<(f64, f64)>,
}

impl RowEvaluator {
    fn new(impulses: &[Impulse], step_hz: f64) -> Self {
        let n = impulses.len();
        let scale = impulses
            .iter()
            .map(|imp| imp.amplitude.abs())
            .fold(0.0, f64::max);
        // A shaper always has a non-zero amplitude; guard anyway so nothing divides by zero.
        let scale = if scale > 0.0 { scale } else { 1.0 };
        RowEvaluator {
            step_hz,
            times: impulses.iter().map(|imp| imp.time).collect(),
            amplitudes: impulses.iter().map(|imp| imp.amplitude / scale).collect(),
            scale,
            t_n: impulses.last().map_or(0.0, |imp| imp.time),
            re: vec![[0.0; MAP_LANES]; n],
            im: vec![[0.0; MAP_LANES]; n],
            step: vec![(0.0, 0.0); n],
            stride: vec![(0.0, 0.0); n],
        }
    }

    /// Writes V(`from_hz` + k·step, `zeta`) into `out[k]` for every k.
    fn fill(&mut self, from_hz: f64, zeta: f64, out: &mut [f64]) {
        use std::f64::consts::PI;
        let nf = out.len();
        if nf == 0 {
            return;
        }
        let damped = (1.0 - zeta * zeta).sqrt();
        let t_n = self.t_n;
        let d_omega = 2.0 * PI * self.step_hz;
        for ((step, stride), &t) in self.step.iter_mut().zip(&mut self.stride).zip(&self.times) {
            *step = term(1.0, t, t_n, d_omega, zeta, damped);
            *stride = term(1.0, t, t_n, MAP_LANES as f64 * d_omega, zeta, damped);
        }
        for block in (0..nf).step_by(MAP_RESEED) {
            let omega = 2.0 * PI * (from_hz + self.step_hz * block as f64);
            // Seeds: the formula at the block's first frequency, stepped by Δf across the lanes.
            for (((re, im), &(sr, si)), (&a, &t)) in self
                .re
                .iter_mut()
                .zip(&mut self.im)
                .zip(&self.step)
                .zip(self.amplitudes.iter().zip(&self.times))
            {
                let (mut pr, mut pi) = term(a, t, t_n, omega, zeta, damped);
                for l in 0..MAP_LANES {
                    re[l] = pr;
                    im[l] = pi;
                    (pr, pi) = (pr * sr - pi * si, pr * si + pi * sr);
                }
            }
            let end = (block + MAP_RESEED).min(nf);
            for group in out[block..end].chunks_mut(MAP_LANES) {
                let mut c = [0.0; MAP_LANES];
                let mut s = [0.0; MAP_LANES];
                for ((re, im), &(zr, zi)) in self.re.iter_mut().zip(&mut self.im).zip(&self.stride)
                {
                    for l in 0..MAP_LANES {
                        c[l] += re[l];
                        s[l] += im[l];
                        let r = re[l] * zr - im[l] * zi;
                        im[l] = re[l] * zi + im[l] * zr;
                        re[l] = r;
                    }
                }
                for (v, (c, s)) in group.iter_mut().zip(c.iter().zip(&s)) {
                    *v = self.scale * (c * c + s * s).sqrt();
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{refine_crossing, vibration_moment, vibration_moments};
    use crate::shaper::Impulse;
    use std::cell::Cell;

    /// The one-pass moments are [`vibration_moment`]'s, order by order, to the last bit (the
    /// polish relies on it: its results did not change when it switched to them), on uneven
    /// times, negative amplitudes and damping from 0 to 0.9.
    #[test]
    fn one_pass_moments_are_the_single_ones_bit_for_bit() {
        let imps: Vec<Impulse> = (0..9)
            .map(|i| {
                let x = f64::from(i);
                Impulse {
                    time: 0.37 * x + 0.011 * x * x,
                    amplitude: if i % 3 == 1 { -0.2 } else { 0.3 + 0.01 * x },
                }
            })
            .collect();
        for (omega, zeta) in [(1.0, 0.0), (7.3, 0.02), (31.0, 0.3), (0.2, 0.9)] {
            let all = vibration_moments(&imps, omega, zeta, 4);
            assert_eq!(all.len(), 5);
            for (k, m) in all.iter().enumerate() {
                let single = vibration_moment(&imps, omega, zeta, k as u32);
                assert_eq!(m.map(f64::to_bits), single.map(f64::to_bits), "k = {k}");
            }
        }
    }

    /// `magnitude` is `hypot` within two ulps where it takes the plain formula, and `hypot`
    /// itself where a square would overflow or underflow (without that fallback the plain
    /// formula gives ∞ or 0 there and this fails); NaN and ∞ as `hypot` has them.
    #[test]
    fn magnitude_is_hypot() {
        use super::magnitude;
        let mut x = 0.123_f64;
        for _ in 0..20_000 {
            x = (x * 3.7 + 0.31).fract();
            let (c, s) = ((x - 0.5) * 10f64.powi((x * 40.0) as i32 - 20), 0.7 - x);
            let (m, h) = (magnitude(c, s), c.hypot(s));
            assert!(
                (m - h).abs() <= 2.0 * f64::EPSILON * h,
                "{c} {s}: {m} vs {h}"
            );
        }
        for (c, s) in [
            (3e200, 4e200),
            (-3e-200, 4e-200),
            (1e300, 1.0),
            (0.0, 0.0),
            (5e-320, 0.0),
        ] {
            assert_eq!(magnitude(c, s), c.hypot(s), "{c} {s}");
        }
        assert!(magnitude(f64::NAN, 1.0).is_nan() && magnitude(1.0, f64::NAN).is_nan());
        assert_eq!(magnitude(f64::INFINITY, f64::NAN), f64::INFINITY);
        assert_eq!(magnitude(-f64::INFINITY, 1.0), f64::INFINITY);
    }

    /// [`super::sin_cos`] gives the bits of `sin` and `cos` called one by one (in wasm it is
    /// libm's `sincos`, and std's `sin` and `cos` are libm's too): over arguments from 10⁻³⁰⁰ to
    /// 10³⁰⁰ of both signs — each octant, the kernels' small-argument paths, the large
    /// arguments' Payne–Hanek reduction — and ±0, ±∞, NaN. Run natively and in wasm.
    #[wasm_bindgen_test::wasm_bindgen_test(unsupported = test)]
    fn sincos_is_sin_and_cos() {
        let bits = |(a, b): (f64, f64)| (a.to_bits(), b.to_bits());
        let mut u = 0.123_f64;
        let mut args = vec![
            0.0,
            -0.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            1e-310,
        ];
        for _ in 0..100_000 {
            u = (u * 3.7 + 0.31).fract();
            let x = (u - 0.5) * 10f64.powi((u * 1e4) as i32 % 600 - 300);
            args.extend([
                x,
                x.abs().fract() * 12.0,
                (u * 8.0).floor() * std::f64::consts::FRAC_PI_4,
            ]);
        }
        for x in args {
            let (s, c) = super::sin_cos(x);
            if x.is_finite() {
                assert_eq!(bits((s, c)), bits((x.sin(), x.cos())), "{x:e}");
            } else {
                assert!(s.is_nan() && c.is_nan(), "{x}");
            }
        }
    }

    /// Runs `refine_crossing` on `g` over (`inside`, `outside`) and returns the crossing and
    /// the number of evaluations of `g`.
    fn counted(g: impl Fn(f64) -> f64, inside: f64, outside: f64) -> (f64, usize) {
        let calls = Cell::new(0);
        let x = refine_crossing(
            &|x| {
                calls.set(calls.get() + 1);
                g(x)
            },
            inside,
            outside,
        );
        (x, calls.get())
    }

    /// Independent oracle: plain bisection until the bracket's ends are adjacent floats.
    fn bisection(g: impl Fn(f64) -> f64, mut inside: f64, mut outside: f64) -> (f64, usize) {
        let mut calls = 0;
        loop {
            let mid = 0.5 * (inside + outside);
            if mid == inside || mid == outside {
                return (mid, calls);
            }
            calls += 1;
            if g(mid) > 0.0 {
                outside = mid;
            } else {
                inside = mid;
            }
        }
    }

    #[test]
    fn smooth_crossings_are_found_to_the_last_bit_in_a_fifth_of_bisections_steps() {
        // x³ = 2 from both directions, and the band edge of a ZV-like V(f) = |cos(π f / 2)|
        // crossing 5 % (closed form: f = 2 acos(0.05) / π).
        type Case = (Box<dyn Fn(f64) -> f64>, f64, f64, f64); // g, inside, outside, root
        let cases: [Case; 3] = [
            (Box::new(|x: f64| x * x * x - 2.0), 1.0, 2.0, 2f64.cbrt()),
            (Box::new(|x: f64| 2.0 - x * x * x), 2.0, 1.0, 2f64.cbrt()),
            (
                Box::new(|f: f64| (std::f64::consts::FRAC_PI_2 * f).cos().abs() - 0.05),
                1.0,
                0.5,
                2.0 * 0.05f64.acos() / std::f64::consts::PI,
            ),
        ];
        for (g, inside, outside, root) in cases {
            let (x, calls) = counted(&g, inside, outside);
            let (b, bisections) = bisection(&g, inside, outside);
            assert!(
                (x - root).abs() <= 2.0 * f64::EPSILON * root,
                "{x} vs {root}"
            );
            assert!(
                (x - b).abs() <= 2.0 * f64::EPSILON * root,
                "{x} vs bisection {b}"
            );
            assert!(calls <= 12, "{calls} evaluations (bisection: {bisections})");
            assert!(bisections >= 50);
        }
    }

    #[test]
    fn steps_flat_crossings_and_nans_take_no_more_than_bisection_plus_three() {
        let step = |x: f64| if x > 0.3 { 1.0 } else { -1.0 };
        let (x, calls) = counted(step, 0.0, 1.0);
        let (b, bisections) = bisection(step, 0.0, 1.0);
        assert!((x - 0.3).abs() <= 2.0 * f64::EPSILON, "{x}");
        assert!((x - b).abs() <= 2.0 * f64::EPSILON, "{x} vs {b}");
        assert!(calls <= bisections + 3, "{calls} vs {bisections}");
        // A crossing so flat that false position barely moves: the bound still holds.
        let flat = |x: f64| (x - 0.3).powi(9);
        let (x, calls) = counted(flat, 0.0, 1.0);
        let (_, bisections) = bisection(flat, 0.0, 1.0);
        assert!((x - 0.3).abs() <= 2.0 * f64::EPSILON, "{x}");
        assert!(calls <= bisections + 3, "{calls} vs {bisections}");
        // NaN above 0.6 counts as inside (searching downwards): the crossing is where g turns
        // positive.
        let positive_then_nan = |x: f64| if x < 0.6 { 1.0 + x } else { f64::NAN };
        let (x, calls) = counted(positive_then_nan, 1.0, 0.0);
        let (_, bisections) = bisection(positive_then_nan, 1.0, 0.0);
        assert!((x - 0.6).abs() <= 2.0 * f64::EPSILON, "{x}");
        assert!(calls <= bisections + 3, "{calls} vs {bisections}");
    }
}
