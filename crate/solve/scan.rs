//! Dense checks over bands: the sampled grid of (ω, ζ), its local maxima of V/Vtol refined by
//! golden-section search, and the initial samples of the exchange loop.

use super::{ratio, NormalizedBand, NormalizedLimit, NormalizedProblem, CHECK_TOLERANCE};
use crate::shaper::Impulse;
use crate::vibration::vibration_moment;

/// Most frequencies scanned per band and damping level.
const MAX_SCAN_FREQUENCIES: usize = 20_000;
/// Damping levels scanned over a damping range.
const DAMPING_LEVELS: usize = 9;
/// Scan points per period of V's oscillation in ω (which is 2π/T for a shaper of duration T).
const SCAN_PER_OSCILLATION: f64 = 24.0;
/// Golden-section iterations per coordinate when refining a maximum.
const REFINE_ITERATIONS: usize = 48;

/// A local maximum of V/Vtol over a band.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Peak {
    pub band: usize,
    pub omega: f64,
    pub zeta: f64,
    /// V/Vtol there.
    pub ratio: f64,
    /// Whether ω lies inside the band (not at an edge), so the peak is a stationary point in ω.
    pub omega_free: bool,
    /// Whether ζ lies inside a damping range (not at an end).
    pub zeta_free: bool,
}

/// Initial samples of a band for the convex program: frequencies about 1/12 of the band's
/// centre apart, both edges included, at the ends and middle of the damping range.
pub(crate) fn initial_samples(band: &NormalizedBand) -> Vec<NormalizedLimit> {
    let centre = 0.5 * (band.omega_lo + band.omega_hi);
    let width = band.omega_hi - band.omega_lo;
    let n = ((12.0 * width / centre).ceil() as usize).clamp(1, 200) + 1;
    let mut out = Vec::new();
    for zeta in damping_levels(band, 3) {
        for i in 0..n {
            let omega = if n == 1 {
                band.omega_lo
            } else {
                band.omega_lo + width * i as f64 / (n - 1) as f64
            };
            out.push(NormalizedLimit {
                omega,
                zeta,
                vtol: band.vtol(omega),
            });
        }
    }
    out
}

fn damping_levels(band: &NormalizedBand, levels: usize) -> Vec<f64> {
    if band.zeta_hi > band.zeta_lo {
        (0..levels)
            .map(|j| band.zeta_lo + (band.zeta_hi - band.zeta_lo) * j as f64 / (levels - 1) as f64)
            .collect()
    } else {
        vec![band.zeta_lo]
    }
}

fn frequencies(band: &NormalizedBand, duration: f64) -> Vec<f64> {
    let width = band.omega_hi - band.omega_lo;
    if width <= 0.0 {
        return vec![band.omega_lo];
    }
    let step = (2.0 * std::f64::consts::PI / (SCAN_PER_OSCILLATION * duration.max(1e-3)))
        .min(width / 16.0);
    let n = ((width / step).ceil() as usize).clamp(16, MAX_SCAN_FREQUENCIES);
    (0..=n)
        .map(|i| band.omega_lo + width * i as f64 / n as f64)
        .collect()
}

fn band_ratio(imps: &[Impulse], band: &NormalizedBand, omega: f64, zeta: f64) -> f64 {
    ratio(imps, omega, zeta, band.vtol(omega))
}

/// Golden-section search for the maximum of `g` on [a, b].
fn golden_max(g: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    const R: f64 = 0.618_033_988_749_894_9;
    let mut x1 = b - R * (b - a);
    let mut x2 = a + R * (b - a);
    let (mut g1, mut g2) = (g(x1), g(x2));
    for _ in 0..REFINE_ITERATIONS {
        if g1 < g2 {
            a = x1;
            x1 = x2;
            g1 = g2;
            x2 = a + R * (b - a);
            g2 = g(x2);
        } else {
            b = x2;
            x2 = x1;
            g2 = g1;
            x1 = b - R * (b - a);
            g1 = g(x1);
        }
    }
    0.5 * (a + b)
}

/// The dense scan of one band: every grid point's (ω, ζ, V/Vtol), and the refined local maxima.
pub(crate) fn band_peaks(
    imps: &[Impulse],
    band: &NormalizedBand,
    band_index: usize,
    checked: Option<&mut Vec<(f64, f64, f64)>>,
) -> Vec<Peak> {
    let duration = imps.last().map_or(0.0, |i| i.time);
    let ws = frequencies(band, duration);
    let zs = damping_levels(band, DAMPING_LEVELS);
    let grid: Vec<Vec<f64>> = zs
        .iter()
        .map(|&z| ws.iter().map(|&w| band_ratio(imps, band, w, z)).collect())
        .collect();
    if let Some(checked) = checked {
        for &z in &zs {
            for &w in &ws {
                checked.push((w, z, band.vtol(w)));
            }
        }
    }
    let (nz, nw) = (zs.len(), ws.len());
    let mut peaks = Vec::new();
    for j in 0..nz {
        for i in 0..nw {
            let g = grid[j][i];
            let mut is_max = true;
            for dj in -1i64..=1 {
                for di in -1i64..=1 {
                    if di == 0 && dj == 0 {
                        continue;
                    }
                    let (jj, ii) = (j as i64 + dj, i as i64 + di);
                    if jj < 0 || ii < 0 || jj >= nz as i64 || ii >= nw as i64 {
                        continue;
                    }
                    let other = grid[jj as usize][ii as usize];
                    // Strict on one side so a plateau yields one maximum.
                    if other > g || (other == g && (dj, di) < (0, 0)) {
                        is_max = false;
                    }
                }
            }
            if !is_max {
                continue;
            }
            // Refine: alternate golden sections in ω and ζ within the neighbouring cells.
            let (w_lo, w_hi) = (ws[i.saturating_sub(1)], ws[(i + 1).min(nw - 1)]);
            let (z_lo, z_hi) = (zs[j.saturating_sub(1)], zs[(j + 1).min(nz - 1)]);
            let (mut w, mut z) = (ws[i], zs[j]);
            for _ in 0..2 {
                if w_hi > w_lo {
                    let cand = golden_max(|x| band_ratio(imps, band, x, z), w_lo, w_hi);
                    if band_ratio(imps, band, cand, z) > band_ratio(imps, band, w, z) {
                        w = cand;
                    }
                }
                if z_hi > z_lo {
                    let cand = golden_max(|x| band_ratio(imps, band, w, x), z_lo, z_hi);
                    if band_ratio(imps, band, w, cand) > band_ratio(imps, band, w, z) {
                        z = cand;
                    }
                }
            }
            // A maximum of V/Vtol at a kink of a piecewise-linear Vtol is not a stationary
            // point: pin it there.
            let mut at_kink = false;
            for &(wk, _) in &band.tolerance {
                if wk > band.omega_lo && wk < band.omega_hi && (w - wk).abs() <= 1e-7 * wk {
                    w = wk;
                    at_kink = true;
                }
            }
            let edge = |x: f64, lo: f64, hi: f64| {
                (x - lo).abs() <= 1e-9 * hi.abs().max(1e-300)
                    || (hi - x).abs() <= 1e-9 * hi.abs().max(1e-300)
            };
            peaks.push(Peak {
                band: band_index,
                omega: w,
                zeta: z,
                ratio: band_ratio(imps, band, w, z),
                omega_free: band.omega_hi > band.omega_lo
                    && !at_kink
                    && !edge(w, band.omega_lo, band.omega_hi),
                zeta_free: band.zeta_hi > band.zeta_lo && !edge(z, band.zeta_lo, band.zeta_hi),
            });
        }
    }
    peaks
}

/// The outcome of checking a design against all its constraints.
#[derive(Debug, Clone, Default)]
pub(crate) struct Report {
    /// Band maxima above Vtol, as new samples for the convex program.
    pub violations: Vec<NormalizedLimit>,
    /// Every (ω, ζ, Vtol) checked.
    pub checked: Vec<(f64, f64, f64)>,
    /// Largest V/Vtol found at sampled limits.
    pub worst_limit: f64,
    /// Largest scaled moment found at zero-vibration constraints.
    pub worst_moment: f64,
}

/// Largest |moment| of order k at a zero constraint, scaled by t_nᵏ (so it compares with V).
pub(crate) fn scaled_moment(imps: &[Impulse], omega: f64, zeta: f64, k: u32) -> f64 {
    let t_n = imps.last().map_or(0.0, |i| i.time).max(1e-300);
    let [c, s] = vibration_moment(imps, omega, zeta, k);
    crate::vibration::magnitude(c, s) / t_n.powi(k as i32)
}

/// Checks a normalized design: sampled limits, zero constraints, and a dense scan of every band.
pub(crate) fn check(norm: &NormalizedProblem, imps: &[Impulse]) -> Report {
    let mut report = Report::default();
    for l in &norm.limits {
        report.worst_limit = report.worst_limit.max(ratio(imps, l.omega, l.zeta, l.vtol));
        report.checked.push((l.omega, l.zeta, l.vtol));
    }
    for z in &norm.zeros {
        for k in 0..=z.derivatives {
            report.worst_moment = report
                .worst_moment
                .max(scaled_moment(imps, z.omega, z.zeta, k));
        }
    }
    for (b, band) in norm.bands.iter().enumerate() {
        let peaks = band_peaks(imps, band, b, Some(&mut report.checked));
        for p in peaks {
            report.checked.push((p.omega, p.zeta, band.vtol(p.omega)));
            if p.ratio > 1.0 + CHECK_TOLERANCE {
                report.violations.push(NormalizedLimit {
                    omega: p.omega,
                    zeta: p.zeta,
                    vtol: band.vtol(p.omega),
                });
            }
        }
    }
    report
}
