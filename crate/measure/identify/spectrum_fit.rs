//! Stage 3: least-squares fit of the modal power spectrum.

use super::half_power::HalfPower;
use super::{Estimate, Method, SignalKind};
use crate::measure::fft::Complex;
use crate::measure::fit::levenberg_marquardt;
use crate::measure::psd::{window, Psd, WindowKind};
use std::f64::consts::PI;

/// Modal power spectrum (see the module docs) at frequency `f`.
pub(super) fn modal_psd(params: &[f64], modes: usize, power: i32, f: f64) -> f64 {
    let w = 2.0 * PI * f;
    let mut h = Complex::default();
    for i in 0..modes {
        let wn = 2.0 * PI * params[3 * i].exp();
        let z = params[3 * i + 1].exp();
        let g = params[3 * i + 2];
        let den = Complex::new(wn * wn - w * w, 2.0 * z * wn * w);
        let num = g * (w / wn).powi(power) * wn * wn / den.norm_sqr();
        // g·(ω/ωₙ)^p·ωₙ²/den = num·conj(den)
        h += den.conj() * num;
    }
    h.norm_sqr() + params[3 * modes].exp()
}

/// The window's spectral kernel |W(ν)|² at ν = j·Δf/q, j = −J … J, normalised to sum 1.
pub(super) fn kernel(kind: WindowKind, n: usize, q: usize, j_max: usize) -> Vec<f64> {
    let w = window(kind, n, false, 6.0);
    let mut out: Vec<f64> = (0..=2 * j_max)
        .map(|jj| {
            let j = jj as f64 - j_max as f64;
            let mut acc = Complex::default();
            for (i, &wi) in w.iter().enumerate() {
                acc += Complex::cis(-2.0 * PI * j * i as f64 / (q * n) as f64) * wi;
            }
            acc.norm_sqr()
        })
        .collect();
    let s: f64 = out.iter().sum();
    out.iter_mut().for_each(|v| *v /= s);
    out
}

/// The bins fitted by [`spectrum_fit`]: from the lowest seed's −6ζ (30–90 %) to the highest's
/// +6ζ (≥ 30 %) inside `lo..=hi`; all within ±3 half-power widths of a peak, the others thinned
/// to about 1500; positive ones only.
fn fit_bins(psd: &Psd, initial: &[HalfPower], lo: usize, hi: usize) -> Option<Vec<usize>> {
    let df = psd.resolution_hz;
    let f_lo = initial
        .iter()
        .map(|h| h.estimate.frequency_hz * (1.0 - (6.0 * h.estimate.damping).clamp(0.3, 0.9)))
        .fold(f64::INFINITY, f64::min);
    let f_hi = initial
        .iter()
        .map(|h| h.estimate.frequency_hz * (1.0 + (6.0 * h.estimate.damping).max(0.3)))
        .fold(0.0, f64::max);
    let a = ((f_lo / df).floor() as usize).max(lo).max(1);
    let b = ((f_hi / df).ceil() as usize).min(hi);
    if b <= a + 8 {
        return None;
    }
    let near = |k: usize| {
        let f = k as f64 * df;
        initial
            .iter()
            .any(|h| (f - h.peak_hz).abs() <= 3.0 * h.width_hz.max(2.0 * df))
    };
    let far = (a..=b).filter(|&k| !near(k)).count();
    let stride = (far / 1500).max(1);
    let mut bins = Vec::new();
    let mut far_seen = 0;
    for k in a..=b {
        if near(k) {
            bins.push(k);
        } else {
            if far_seen % stride == 0 {
                bins.push(k);
            }
            far_seen += 1;
        }
    }
    let bins: Vec<usize> = bins.into_iter().filter(|&k| psd.psd[k] > 0.0).collect();
    (bins.len() >= 3 * initial.len() + 4).then_some(bins)
}

/// Starting parameters from the half-power seeds, gain signs from `signs` (bit i−1 flips
/// mode i), and the finite-difference steps.
fn start(initial: &[HalfPower], signs: usize, floor0: f64) -> (Vec<f64>, Vec<f64>) {
    let m = initial.len();
    let mut x0 = Vec::with_capacity(3 * m + 1);
    for (i, h) in initial.iter().enumerate() {
        let sign = if i > 0 && (signs >> (i - 1)) & 1 == 1 {
            -1.0
        } else {
            1.0
        };
        let z = h.estimate.damping.clamp(1e-4, 0.6);
        x0.push(h.estimate.frequency_hz.ln());
        x0.push(z.ln());
        x0.push(sign * h.peak_psd.sqrt() * 2.0 * z);
    }
    x0.push(floor0.ln());
    let steps = (0..3 * m + 1)
        .map(|i| {
            if i == 3 * m {
                1e-5
            } else if i % 3 == 0 {
                1e-7
            } else if i % 3 == 1 {
                1e-5
            } else {
                1e-6 * x0[i].abs().max(1e-300)
            }
        })
        .collect();
    (x0, steps)
}

/// Fits the modal spectrum to the PSD around the peaks; returns one estimate per mode.
pub(super) fn spectrum_fit(
    psd: &Psd,
    initial: &[HalfPower],
    lo: usize,
    hi: usize,
    kind: SignalKind,
) -> Option<Vec<Estimate>> {
    let m = initial.len();
    let df = psd.resolution_hz;
    let power = kind.power();
    let bins = fit_bins(psd, initial, lo, hi)?;
    // Leakage kernel near narrow peaks (half-power width below 12 bins).
    let (q, j_max) = (4usize, 16usize);
    let narrow: Vec<&HalfPower> = initial.iter().filter(|h| h.width_hz < 12.0 * df).collect();
    let kern = if narrow.is_empty() {
        Vec::new()
    } else {
        kernel(WindowKind::Hann, psd.segment_length, q, j_max)
    };
    let convolve: Vec<bool> = bins
        .iter()
        .map(|&k| {
            let f = k as f64 * df;
            narrow
                .iter()
                .any(|h| (f - h.peak_hz).abs() <= 4.0 * h.width_hz + 4.0 * df)
        })
        .collect();
    let logs: Vec<f64> = bins.iter().map(|&k| psd.psd[k].ln()).collect();
    let floor0 = {
        let mut v: Vec<f64> = bins.iter().map(|&k| psd.psd[k]).collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 10].max(1e-300) * 0.5
    };
    let model = |x: &[f64], out: &mut Vec<f64>| -> bool {
        out.clear();
        for (i, &k) in bins.iter().enumerate() {
            let f = k as f64 * df;
            let s = if convolve[i] && !kern.is_empty() {
                kern.iter()
                    .enumerate()
                    .map(|(jj, c)| {
                        let nu = f + (jj as f64 - j_max as f64) * df / q as f64;
                        c * modal_psd(x, m, power, nu.abs())
                    })
                    .sum::<f64>()
            } else {
                modal_psd(x, m, power, f)
            };
            if !(s > 0.0 && s.is_finite()) {
                return false;
            }
            out.push(logs[i] - s.ln());
        }
        true
    };
    let mut best: Option<crate::measure::fit::FitResult> = None;
    for signs in 0..(1usize << (m - 1)) {
        let (x0, steps) = start(initial, signs, floor0);
        if let Some(fit) = levenberg_marquardt(model, &x0, &steps, 60) {
            if best.as_ref().is_none_or(|b| fit.rss < b.rss) {
                best = Some(fit);
            }
        }
    }
    let fit = best?;
    let inflate = psd.enbw_bins.sqrt();
    (0..m)
        .map(|i| {
            let f = fit.x[3 * i].exp();
            let z = fit.x[3 * i + 1].exp();
            let sf = fit.sigma(3 * i)? * inflate * f;
            let sz = fit.sigma(3 * i + 1)? * inflate * z;
            (f.is_finite() && z > 0.0 && z < 1.0 && f > 0.0).then_some(Estimate {
                method: Method::SpectrumFit,
                frequency_hz: f,
                damping: z,
                frequency_uncertainty_hz: sf,
                damping_uncertainty: sz,
            })
        })
        .collect()
}
