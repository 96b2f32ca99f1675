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
    let t_n = impulses.last().map_or(0.0, |imp| imp.time);
    let omega_d = omega * (1.0 - zeta * zeta).sqrt();
    let decay = zeta * omega;
    let (mut c, mut s) = (0.0, 0.0);
    for imp in impulses {
        let w = imp.amplitude * (-decay * (t_n - imp.time)).exp();
        let (sin, cos) = (omega_d * imp.time).sin_cos();
        c += w * cos;
        s += w * sin;
    }
    c.hypot(s)
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
    let step = (options.to_hz - options.from_hz) / (options.points - 1) as f64;
    let mut vibration = Vec::with_capacity(options.points);
    vibration_on_grid(
        shaper.impulses(),
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
    // V oscillates in f with period ~1/duration; sample it at least 40 times per period, but
    // spend at most MAX_SCAN_WORK impulse-evaluations per side (coarser beyond that).
    let per_period = 1.0 / (40.0 * shaper.duration().max(f64::MIN_POSITIVE));
    let work_step = |span: f64| span * shaper.len() as f64 / MAX_SCAN_WORK;
    let mut values = Vec::with_capacity(SCAN_CHUNK);
    let mut edge = |direction: f64, limit: f64| -> f64 {
        let span = (limit - f_m).abs();
        let step = (0.0025 * f_m)
            .min(per_period)
            .max(work_step(span))
            .max(span / 2e6);
        let h = direction * step;
        let mut inside = f_m;
        loop {
            let remaining = ((limit - inside) / h).floor().max(0.0) as usize;
            let n = remaining.min(SCAN_CHUNK);
            if n == 0 {
                return if excess(limit) > 0.0 {
                    bisect(&excess, inside, limit)
                } else {
                    limit
                };
            }
            vibration_on_grid(shaper.impulses(), inside + h, h, n, zeta, &mut values);
            if let Some(k) = values.iter().position(|&v| v > threshold) {
                let outside = inside + h * (k + 1) as f64;
                return bisect(&excess, inside + h * k as f64, outside);
            }
            inside += h * n as f64;
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

/// Grid points between exact re-seeds of the recurrence in [`vibration_on_grid`].
const RESEED: usize = 64;

/// V at the evenly spaced frequencies `from_hz + k·step_hz`, k = 0 … n−1, written to `out`
/// (cleared first). Same quantity as [`vibration_rad`], evaluated by rotating each impulse's
/// term e^{−ζω(t_n−tᵢ)} e^{iω_d tᵢ} from one frequency to the next with one complex multiply
/// (the terms are geometric in k) instead of an `exp` and a `sin_cos`; the terms are recomputed
/// exactly every [`RESEED`] points so rounding cannot accumulate. Agrees with
/// [`vibration_rad`] to ~1e-13 (tested).
pub fn vibration_on_grid(
    impulses: &[Impulse],
    from_hz: f64,
    step_hz: f64,
    n: usize,
    zeta: f64,
    out: &mut Vec<f64>,
) {
    out.clear();
    let two_pi = 2.0 * std::f64::consts::PI;
    let t_n = impulses.last().map_or(0.0, |imp| imp.time);
    let root = (1.0 - zeta * zeta).sqrt();
    // Per impulse: the rotation per step (re, im) and the current term (re, im).
    let rot: Vec<(f64, f64)> = impulses
        .iter()
        .map(|imp| {
            let decay = (-zeta * two_pi * step_hz * (t_n - imp.time)).exp();
            let (s, c) = (two_pi * step_hz * root * imp.time).sin_cos();
            (decay * c, decay * s)
        })
        .collect();
    let mut term = vec![(0.0, 0.0); impulses.len()];
    let mut k = 0;
    while k < n {
        let f = from_hz + step_hz * k as f64;
        let omega = two_pi * f;
        for (slot, imp) in term.iter_mut().zip(impulses) {
            let w = imp.amplitude * (-zeta * omega * (t_n - imp.time)).exp();
            let (s, c) = (omega * root * imp.time).sin_cos();
            *slot = (w * c, w * s);
        }
        let stop = (k + RESEED).min(n);
        while k < stop {
            let (mut c, mut s) = (0.0, 0.0);
            for ((tr, ti), &(rr, ri)) in term.iter_mut().zip(&rot) {
                c += *tr;
                s += *ti;
                let (nr, ni) = (*tr * rr - *ti * ri, *tr * ri + *ti * rr);
                *tr = nr;
                *ti = ni;
            }
            out.push(c.hypot(s));
            k += 1;
        }
    }
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
