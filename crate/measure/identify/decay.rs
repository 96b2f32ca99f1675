//! Stage 4: the free decay — finding a ring-down and fitting damped sinusoids to it.

use super::{Estimate, Method};
use crate::measure::fit::{levenberg_marquardt, FitResult};
use std::f64::consts::PI;

/// Finds a ring-down: returns (start, end) sample indices and its level in dB: the strongest
/// block of two periods of the lowest mode at least 20 dB over the quiet level (the lower
/// quartile of the blocks), the block two before it at most half of it (a hit, not a slow
/// build-up); the decay ends where the blocks fall below twice the quiet level.
pub(super) fn find_decay(signal: &[f64], fs: f64, lowest_hz: f64) -> Option<(usize, usize, f64)> {
    let n = signal.len();
    let block = ((2.0 * fs / lowest_hz).round() as usize).max(8);
    let blocks = n / block;
    if blocks < 8 {
        return None;
    }
    let rms: Vec<f64> = (0..blocks)
        .map(|b| {
            let s = &signal[b * block..(b + 1) * block];
            let mean = s.iter().sum::<f64>() / block as f64;
            (s.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / block as f64).sqrt()
        })
        .collect();
    let mut sorted = rms.clone();
    sorted.sort_by(f64::total_cmp);
    // The quiet level: the lower quartile of the blocks, not their median — a short record
    // can be mostly ring-down (its median block then lies inside the decay).
    let median = sorted[blocks / 4].max(1e-300);
    let (b_max, &top) = rms.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1))?;
    let level_db = 20.0 * (top / median).log10();
    if level_db < 20.0 {
        return None;
    }
    // It must be a hit: the block two before the top is at most half of it.
    if b_max >= 2 && rms[b_max - 2] > 0.5 * top {
        return None;
    }
    let from = b_max.saturating_sub(1) * block;
    let to = ((b_max + 1) * block).min(n);
    let mean = signal[from..to].iter().sum::<f64>() / (to - from) as f64;
    let peak = (from..to).max_by(|&a, &b| {
        (signal[a] - mean)
            .abs()
            .total_cmp(&(signal[b] - mean).abs())
    })?;
    let start = peak + 2;
    let end_block = (b_max + 1..blocks)
        .find(|&b| rms[b] < 2.0 * median)
        .unwrap_or(blocks - 1);
    let end = ((end_block + 2) * block).min(n);
    (end > start + 32).then_some((start, end, level_db))
}

/// The residual of `y` (at times `tau`) after projecting out the linear terms: for θ = (ln σᵢ,
/// ln ω_dᵢ) in `x`, the aᵢ, bᵢ of e^{−σᵢτ}(aᵢ cos ω_dᵢτ + bᵢ sin ω_dᵢτ) and the drift c₀ + c₁τ
/// are solved by least squares (normal equations, Cholesky). False when singular.
fn project(y: &[f64], tau: &[f64], x: &[f64], out: &mut Vec<f64>) -> bool {
    let m = x.len() / 2;
    let n = y.len();
    let t_end = tau[n - 1].max(1e-300);
    let cols = 2 * m + 2;
    let mut basis = vec![0.0; cols * n];
    for i in 0..m {
        let s = x[2 * i].exp();
        let w = x[2 * i + 1].exp();
        for k in 0..n {
            let e = (-s * tau[k]).exp();
            let (sn, cs) = (w * tau[k]).sin_cos();
            basis[k * cols + 2 * i] = e * cs;
            basis[k * cols + 2 * i + 1] = e * sn;
        }
    }
    for k in 0..n {
        basis[k * cols + 2 * m] = 1.0;
        basis[k * cols + 2 * m + 1] = tau[k] / t_end;
    }
    let mut ata = nalgebra::DMatrix::<f64>::zeros(cols, cols);
    let mut aty = nalgebra::DVector::<f64>::zeros(cols);
    for k in 0..n {
        let row = &basis[k * cols..(k + 1) * cols];
        for a in 0..cols {
            aty[a] += row[a] * y[k];
            for b in a..cols {
                ata[(a, b)] += row[a] * row[b];
            }
        }
    }
    for a in 0..cols {
        for b in 0..a {
            ata[(a, b)] = ata[(b, a)];
        }
        ata[(a, a)] *= 1.0 + 1e-12;
        ata[(a, a)] += 1e-300;
    }
    let Some(chol) = ata.cholesky() else {
        return false;
    };
    let c = chol.solve(&aty);
    out.clear();
    for k in 0..n {
        let row = &basis[k * cols..(k + 1) * cols];
        let fit: f64 = row.iter().zip(c.iter()).map(|(a, b)| a * b).sum();
        out.push(y[k] - fit);
    }
    true
}

/// The estimate of mode i from the fit of (ln σ, ln ω_d): ω = √(σ² + ω_d²), ζ = σ/ω, with
/// their standard deviations propagated from the covariance.
fn estimate(fit: &FitResult, i: usize) -> Option<Estimate> {
    let s = fit.x[2 * i].exp();
    let w = fit.x[2 * i + 1].exp();
    let big_w = s.hypot(w);
    let z = s / big_w;
    let (vs, vw, c) = (
        fit.covariance(2 * i, 2 * i)?,
        fit.covariance(2 * i + 1, 2 * i + 1)?,
        fit.covariance(2 * i, 2 * i + 1)?,
    );
    // Gradients with respect to (ln σ, ln ω_d).
    let dz = [s * w * w / big_w.powi(3), -s * w * w / big_w.powi(3)];
    let dw = [s * s / big_w, w * w / big_w];
    let var = |g: [f64; 2]| g[0] * g[0] * vs + 2.0 * g[0] * g[1] * c + g[1] * g[1] * vw;
    let sz = var(dz).max(0.0).sqrt();
    let sf = var(dw).max(0.0).sqrt() / (2.0 * PI);
    (z.is_finite() && z < 1.0).then_some(Estimate {
        method: Method::FreeDecay,
        frequency_hz: big_w / (2.0 * PI),
        damping: z,
        frequency_uncertainty_hz: sf,
        damping_uncertainty: sz,
    })
}

/// Fits damped sinusoids to `y` (sampled at `fs`) from initial (fₙ, ζ) per mode.
pub(super) fn decay_fit(y: &[f64], fs: f64, initial: &[(f64, f64)]) -> Option<Vec<Estimate>> {
    let m = initial.len();
    let tau: Vec<f64> = (0..y.len()).map(|i| i as f64 / fs).collect();
    let residual = |x: &[f64], out: &mut Vec<f64>| project(y, &tau, x, out);
    let mut x: Vec<f64> = initial
        .iter()
        .flat_map(|&(f, z)| {
            let w = 2.0 * PI * f;
            [
                (z.max(1e-4) * w).ln(),
                (w * (1.0 - z * z).max(1e-6).sqrt()).ln(),
            ]
        })
        .collect();
    // Coarse scan of each frequency over ±3 half-power widths before the local fit.
    let mut buf = Vec::new();
    for (i, &(_, z)) in initial.iter().enumerate() {
        let w0 = x[2 * i + 1].exp();
        let span = (3.0 * z.max(0.002)).min(0.3);
        let mut best = (f64::INFINITY, x[2 * i + 1]);
        for s in 0..=40 {
            let w = w0 * (1.0 + span * (s as f64 / 20.0 - 1.0));
            let mut xs = x.clone();
            xs[2 * i + 1] = w.ln();
            if residual(&xs, &mut buf) {
                let rss: f64 = buf.iter().map(|v| v * v).sum();
                if rss < best.0 {
                    best = (rss, w.ln());
                }
            }
        }
        x[2 * i + 1] = best.1;
    }
    let steps: Vec<f64> = (0..2 * m)
        .map(|i| if i % 2 == 0 { 1e-6 } else { 1e-8 })
        .collect();
    let fit = levenberg_marquardt(residual, &x, &steps, 80)?;
    (0..m).map(|i| estimate(&fit, i)).collect()
}
