//! Independent checks for the reliability tests (issue 6): residual vibration written out here
//! from Singhose 2009 eq. 11 (not through the library's `vibration` module), its frequency
//! derivatives, dense scans with refined maxima, and the invariants of a valid shaper.
#![allow(dead_code)]

use input_shaping::Shaper;
use std::f64::consts::PI;

/// (time, amplitude) pairs of a shaper.
pub fn pairs(shaper: &Shaper) -> Vec<(f64, f64)> {
    shaper
        .impulses()
        .iter()
        .map(|i| (i.time, i.amplitude))
        .collect()
}

/// Singhose 2009 eq. 11, written out: V = e^{−ζωt_n} √(C² + S²) with
/// C = Σ Aᵢ e^{ζωtᵢ} cos(ω√(1−ζ²) tᵢ), S = Σ Aᵢ e^{ζωtᵢ} sin(ω√(1−ζ²) tᵢ), ω = 2πf.
/// The factor e^{−ζωt_n} is taken inside the sum (e^{−ζω(t_n−tᵢ)}) so it cannot overflow.
pub fn v_eq11(imps: &[(f64, f64)], f_hz: f64, zeta: f64) -> f64 {
    let w = 2.0 * PI * f_hz;
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let t_n = imps.iter().map(|p| p.0).fold(0.0_f64, f64::max);
    let (mut c, mut s) = (0.0_f64, 0.0_f64);
    for &(t, a) in imps {
        let e = a * (-zeta * w * (t_n - t)).exp();
        c += e * (wd * t).cos();
        s += e * (wd * t).sin();
    }
    (c * c + s * s).sqrt()
}

/// |dᵏP/dωᵏ| / t_nᵏ where P(ω) = Σ Aᵢ exp(ω qᵢ), qᵢ = −ζ(t_n − tᵢ) + i√(1−ζ²) tᵢ, is the
/// complex vibration phasor of eq. 11 (V = |P|). P and its first n derivatives vanish at ω
/// exactly when V and its first n frequency derivatives do (Singhose 2009 eq. 16), so this
/// checks ZVD-type guarantees without the library's moment formula. Scaled by t_nᵏ so it is
/// dimensionless.
pub fn phasor_derivative(imps: &[(f64, f64)], f_hz: f64, zeta: f64, k: u32) -> f64 {
    let w = 2.0 * PI * f_hz;
    let d = (1.0 - zeta * zeta).sqrt();
    let t_n = imps.iter().map(|p| p.0).fold(0.0_f64, f64::max);
    let scale = if t_n > 0.0 { t_n } else { 1.0 };
    let (mut re, mut im) = (0.0_f64, 0.0_f64);
    for &(t, a) in imps {
        // q / scale, raised to k, times A e^{ωq}.
        let (qr, qi) = (-zeta * (t_n - t) / scale, d * t / scale);
        let (mut pr, mut pi) = (1.0_f64, 0.0_f64);
        for _ in 0..k {
            let r = pr * qr - pi * qi;
            pi = pr * qi + pi * qr;
            pr = r;
        }
        let mag = a * (w * -zeta * (t_n - t)).exp();
        let (sn, cs) = (w * d * t).sin_cos();
        let (er, ei) = (mag * cs, mag * sn);
        re += pr * er - pi * ei;
        im += pr * ei + pi * er;
    }
    re.hypot(im)
}

/// Largest V on [lo, hi] at damping ζ: `n` evenly spaced samples, then every local maximum
/// of the samples refined by golden-section search. Returns (frequency, V) of the largest.
pub fn max_on_band(imps: &[(f64, f64)], lo: f64, hi: f64, zeta: f64, n: usize) -> (f64, f64) {
    let n = n.max(3);
    let h = (hi - lo) / (n - 1) as f64;
    let vs: Vec<f64> = (0..n)
        .map(|i| v_eq11(imps, lo + h * i as f64, zeta))
        .collect();
    let mut best = (lo, vs[0]);
    for i in 0..n {
        let left = if i == 0 { f64::NEG_INFINITY } else { vs[i - 1] };
        let right = if i + 1 == n {
            f64::NEG_INFINITY
        } else {
            vs[i + 1]
        };
        if vs[i] >= left && vs[i] >= right {
            let a = (lo + h * (i as f64 - 1.0)).max(lo);
            let b = (lo + h * (i as f64 + 1.0)).min(hi);
            let (f, v) = golden_max(|f| v_eq11(imps, f, zeta), a, b);
            let (f, v) = if v >= vs[i] {
                (f, v)
            } else {
                (lo + h * i as f64, vs[i])
            };
            if v > best.1 {
                best = (f, v);
            }
        }
    }
    best
}

/// Maximum of a unimodal `g` on [a, b] by golden-section search (60 steps: 1e-12 of the span).
pub fn golden_max(g: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> (f64, f64) {
    let r = (5.0_f64.sqrt() - 1.0) / 2.0;
    let mut x1 = b - r * (b - a);
    let mut x2 = a + r * (b - a);
    let (mut g1, mut g2) = (g(x1), g(x2));
    for _ in 0..60 {
        if g1 < g2 {
            a = x1;
            x1 = x2;
            g1 = g2;
            x2 = a + r * (b - a);
            g2 = g(x2);
        } else {
            b = x2;
            x2 = x1;
            g2 = g1;
            x1 = b - r * (b - a);
            g1 = g(x1);
        }
    }
    if g1 > g2 {
        (x1, g1)
    } else {
        (x2, g2)
    }
}

/// Minimum of a unimodal `g` on [a, b] (golden section on −g).
pub fn golden_min(g: impl Fn(f64) -> f64, a: f64, b: f64) -> (f64, f64) {
    let (x, v) = golden_max(|x| -g(x), a, b);
    (x, -v)
}

/// The invariants every shaper the library returns must have: at least one impulse, at most
/// `input_shaping::shaper::MAX_IMPULSES`, finite times and amplitudes, times strictly
/// increasing, the first at 0.
pub fn check_valid(shaper: &Shaper) -> Result<(), String> {
    let imps = shaper.impulses();
    if imps.is_empty() {
        return Err("no impulses".into());
    }
    // A convolution past MAX_IMPULSES stays factored (its list formed lazily), up to
    // MAX_CONVOLVED_IMPULSES.
    let limit = if shaper.is_factored() {
        input_shaping::shaper::MAX_CONVOLVED_IMPULSES
    } else {
        input_shaping::shaper::MAX_IMPULSES
    };
    if imps.len() > limit {
        return Err(format!("{} impulses", imps.len()));
    }
    if imps[0].time != 0.0 {
        return Err(format!("first impulse at {} instead of 0", imps[0].time));
    }
    for (k, i) in imps.iter().enumerate() {
        if !i.time.is_finite() || !i.amplitude.is_finite() {
            return Err(format!("impulse {k} not finite: {i:?}"));
        }
        if k > 0 && imps[k - 1].time >= i.time {
            return Err(format!("times not increasing at {k}: {imps:?}"));
        }
    }
    // A factored shaper's duration is the sum of its factors'; its expanded list's last time is
    // that sum unless another product falls within the merge tolerance (1e-12 of the span) of
    // it, which keeps the earlier time (a 1e-9 Hz mode's ZV-D²⁴ with a 41 Hz one: 4·10⁹ s).
    let last = imps[imps.len() - 1].time;
    let slack = if shaper.is_factored() {
        1e-12 * last
    } else {
        0.0
    };
    if (shaper.duration() - last).abs() > slack {
        return Err(format!(
            "duration {} is not the last time {last}",
            shaper.duration()
        ));
    }
    Ok(())
}
