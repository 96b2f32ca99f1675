//! Stage 2: the half-power bandwidth estimate of one peak (the seed of the fits).

use super::{Estimate, Method, SignalKind};
use crate::measure::psd::Psd;

/// The half-power analysis of one peak.
#[derive(Debug, Clone, Copy)]
pub(super) struct HalfPower {
    pub(super) peak_hz: f64,
    pub(super) peak_psd: f64,
    pub(super) width_hz: f64,
    pub(super) estimate: Estimate,
}

/// Half-power bandwidth around the largest bin within ±`search_hz` of `near_hz`.
pub(super) fn half_power(
    psd: &Psd,
    near_hz: f64,
    search_hz: f64,
    lo: usize,
    hi: usize,
    kind: SignalKind,
) -> Option<HalfPower> {
    let df = psd.resolution_hz;
    let a = (((near_hz - search_hz) / df).floor().max(lo as f64) as usize).max(lo + 1);
    let b = (((near_hz + search_hz) / df).ceil() as usize).min(hi.saturating_sub(1));
    if a > b {
        return None;
    }
    let p = &psd.psd;
    let k = (a..=b).max_by(|&x, &y| p[x].total_cmp(&p[y]))?;
    if p[k] <= 0.0 {
        return None;
    }
    let (ym, y0, yp) = (
        p[k - 1].max(1e-300).ln(),
        p[k].ln(),
        p[k + 1].max(1e-300).ln(),
    );
    let denom = ym - 2.0 * y0 + yp;
    let delta = if denom < 0.0 {
        (0.5 * (ym - yp) / denom).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    let peak_hz = (k as f64 + delta) * df;
    let peak = (y0 - 0.25 * (ym - yp) * delta).exp();
    let half = 0.5 * peak;
    // Left crossing.
    let mut j = k;
    while j > lo && p[j] > half {
        j -= 1;
    }
    if p[j] > half {
        return None;
    }
    let slope_l = (p[j + 1] - p[j]) / df;
    let f1 = (j as f64 + (half - p[j]) / (p[j + 1] - p[j])) * df;
    let mut j = k;
    while j < hi && p[j] > half {
        j += 1;
    }
    if p[j] > half {
        return None;
    }
    let slope_r = (p[j - 1] - p[j]) / df;
    let f2 = (j as f64 - (half - p[j]) / (p[j - 1] - p[j])) * df;
    let width = f2 - f1;
    if width.is_nan() || width <= 0.0 {
        return None;
    }
    let zeta_raw = width / (2.0 * peak_hz);
    let z2 = (1.0 - 2.0 * zeta_raw * zeta_raw).max(0.05).sqrt();
    let fn_hz = match kind {
        SignalKind::Position => peak_hz / z2,
        SignalKind::Velocity => peak_hz,
        SignalKind::Acceleration => peak_hz * z2,
    };
    // Uncertainty: each bin's relative standard deviation 1/√K moves a crossing by
    // s·half/slope; leakage widens by up to ENBW/2 bins; the formula is biased by ~2.5ζ².
    let s = 1.0 / (psd.segments.max(1) as f64).sqrt();
    let d1 = s * half / slope_l.abs().max(1e-300);
    let d2 = s * half / slope_r.abs().max(1e-300);
    let d1 = d1.min(width);
    let d2 = d2.min(width);
    let sigma_width = (d1 * d1
        + d2 * d2
        + (0.5 * psd.enbw_bins * df).powi(2)
        + (2.5 * zeta_raw * zeta_raw * width).powi(2))
    .sqrt();
    let sigma_f = (0.25 * (d1 * d1 + d2 * d2) + df * df / 12.0).sqrt();
    Some(HalfPower {
        peak_hz,
        peak_psd: peak,
        width_hz: width,
        estimate: Estimate {
            method: Method::HalfPower,
            frequency_hz: fn_hz,
            damping: zeta_raw,
            frequency_uncertainty_hz: sigma_f,
            damping_uncertainty: sigma_width / (2.0 * peak_hz),
        },
    })
}

/// The PSD averaged over 2h + 1 bins (fewer at the ends).
pub(super) fn smoothed(psd: &Psd, h: usize) -> Psd {
    if h == 0 {
        return psd.clone();
    }
    let p = &psd.psd;
    let n = p.len();
    let mut prefix = vec![0.0; n + 1];
    for i in 0..n {
        prefix[i + 1] = prefix[i] + p[i];
    }
    let psd_s = (0..n)
        .map(|i| {
            let a = i.saturating_sub(h);
            let b = (i + h + 1).min(n);
            (prefix[b] - prefix[a]) / (b - a) as f64
        })
        .collect();
    Psd {
        psd: psd_s,
        segments: psd.segments * (2 * h + 1),
        ..psd.clone()
    }
}
