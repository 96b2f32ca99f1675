//! Stage 1: candidate peaks of the detection PSD by topographic prominence.

use crate::measure::psd::Psd;

/// A detected peak: bin on the detection PSD and its prominence in dB.
#[derive(Debug, Clone, Copy)]
pub(super) struct Peak {
    pub(super) frequency_hz: f64,
    pub(super) prominence_db: f64,
}

/// Local maxima of the dB spectrum smoothed over 2h + 1 bins in bins `lo..=hi`, with their
/// topographic prominence (height over the higher of the lowest points between it and a higher
/// point on each side, or the band's end).
pub(super) fn detect(
    psd: &Psd,
    lo: usize,
    hi: usize,
    min_db: f64,
    max_modes: usize,
    h: usize,
) -> Vec<Peak> {
    detect_within(psd, [lo, hi], [lo, hi], min_db, max_modes, h)
}

/// [`detect`] with the peaks in bins `band[0]..=band[1]` but the smoothing and the prominence
/// read over the wider `context` (the spectrum around the band: a peak near the band's end
/// then keeps its flank beyond it, instead of the end standing for its base).
pub(super) fn detect_within(
    psd: &Psd,
    band: [usize; 2],
    context: [usize; 2],
    min_db: f64,
    max_modes: usize,
    h: usize,
) -> Vec<Peak> {
    let [lo, hi] = context;
    let db: Vec<f64> = psd
        .psd
        .iter()
        .map(|p| 10.0 * p.max(1e-300).log10())
        .collect();
    let sm: Vec<f64> = (lo..=hi)
        .map(|k| {
            let a = k.saturating_sub(h).max(lo);
            let b = (k + h).min(hi);
            db[a..=b].iter().sum::<f64>() / (b - a + 1) as f64
        })
        .collect();
    let n = sm.len();
    let mut peaks = Vec::new();
    for i in 1..n.saturating_sub(1) {
        if lo + i < band[0] || lo + i > band[1] {
            continue;
        }
        if !(sm[i] > sm[i - 1] && sm[i] >= sm[i + 1]) {
            continue;
        }
        let mut left = sm[i];
        let mut j = i;
        while j > 0 {
            j -= 1;
            if sm[j] > sm[i] {
                break;
            }
            left = left.min(sm[j]);
        }
        let mut right = sm[i];
        let mut j = i;
        while j + 1 < n {
            j += 1;
            if sm[j] > sm[i] {
                break;
            }
            right = right.min(sm[j]);
        }
        let prominence = sm[i] - left.max(right);
        if prominence >= min_db {
            // The raw maximum near the smoothed one.
            let k0 = lo + i;
            let a = k0.saturating_sub(h).max(band[0]);
            let b = (k0 + h).min(band[1]);
            let k = (a..=b)
                .max_by(|&x, &y| psd.psd[x].total_cmp(&psd.psd[y]))
                .unwrap_or(k0);
            peaks.push(Peak {
                frequency_hz: psd.frequency_hz[k],
                prominence_db: prominence,
            });
        }
    }
    crate::sort::sort_by(&mut peaks, |a, b| {
        b.prominence_db.total_cmp(&a.prominence_db)
    });
    peaks.truncate(max_modes);
    crate::sort::sort_by(&mut peaks, |a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    peaks
}
