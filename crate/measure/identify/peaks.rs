//! Stage 1: candidate peaks of the detection PSD by topographic prominence.

use crate::measure::psd::Psd;

/// A detected peak: bin on the detection PSD and its prominence in dB.
#[derive(Debug, Clone, Copy)]
pub(super) struct Peak {
    pub(super) frequency_hz: f64,
    pub(super) prominence_db: f64,
}

/// Local maxima of the dB spectrum smoothed over 2h + 1 bins, in bins `band[0]..=band[1]`, with
/// their topographic prominence (height over the higher of the lowest points between it and a
/// higher point on each side, or the context's end), the `max_modes` most prominent. The
/// smoothing and the prominence are read over `context`, which may be wider than the band
/// (the spectrum around it: a peak near the band's end then keeps its flank beyond it,
/// instead of the end standing for its base).
pub(super) fn detect_within(
    psd: &Psd,
    band: [usize; 2],
    context: [usize; 2],
    min_db: f64,
    max_modes: usize,
    h: usize,
) -> Vec<Peak> {
    let [lo, hi] = context;
    let sm = smoothed_db(&to_db(&psd.psd[lo..=hi]), 0, hi - lo, h);
    let mut peaks = Vec::new();
    for (i, prominence) in maxima(&sm) {
        if lo + i < band[0] || lo + i > band[1] {
            continue;
        }
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

/// The local maxima of `sm` (a value above its left neighbour and not below its right one; the
/// ends are none) with their topographic prominence: the height over the higher of their two
/// [`bases`].
pub(super) fn maxima(sm: &[f64]) -> Vec<(usize, f64)> {
    let n = sm.len();
    let (lefts, rights) = bases(sm);
    (1..n.saturating_sub(1))
        .filter(|&i| sm[i] > sm[i - 1] && sm[i] >= sm[i + 1])
        .map(|i| (i, sm[i] - lefts[i].max(rights[i])))
        .collect()
}

/// Each value's bases: the lowest value between it and the nearest higher one on its left
/// (the start when none; the value itself included, the higher one not), and the same on its
/// right. One pass each way with a stack of the values not yet exceeded, each holding the
/// lowest value of the run it closes: O(n), where walking out from every maximum is O(n²) on
/// a long sweep's periodogram (tens of thousands of bins, thousands of maxima).
fn bases(sm: &[f64]) -> (Vec<f64>, Vec<f64>) {
    fn pass(values: impl Iterator<Item = f64>, n: usize) -> Vec<f64> {
        let mut stack: Vec<(f64, f64)> = Vec::new();
        let mut out = Vec::with_capacity(n);
        for v in values {
            let mut low = v;
            while let Some(&(top, run_low)) = stack.last() {
                if top > v {
                    break;
                }
                low = low.min(run_low);
                stack.pop();
            }
            out.push(low);
            stack.push((v, low));
        }
        out
    }
    let n = sm.len();
    let left = pass(sm.iter().copied(), n);
    let mut right = pass(sm.iter().rev().copied(), n);
    right.reverse();
    (left, right)
}

/// A PSD in dB (10·log₁₀, floored at 10⁻³⁰⁰).
pub(super) fn to_db(psd: &[f64]) -> Vec<f64> {
    psd.iter().map(|p| 10.0 * p.max(1e-300).log10()).collect()
}

/// `db[lo..=hi]` averaged over ±`h` values within `lo..=hi` (fewer at its ends), indexed from
/// `lo`: the smoothing peaks are found and measured on. By running sums (a long sweep's
/// periodogram has tens of thousands of bins in its band and `h` reaches hundreds: summing
/// each window anew was most of a 128 s recording's identification).
pub(super) fn smoothed_db(db: &[f64], lo: usize, hi: usize, h: usize) -> Vec<f64> {
    let mut prefix = Vec::with_capacity(hi + 2 - lo);
    prefix.push(0.0);
    let mut total = 0.0;
    for v in &db[lo..=hi] {
        total += v;
        prefix.push(total);
    }
    (lo..=hi)
        .map(|k| {
            let (a, b) = (k.saturating_sub(h).max(lo), (k + h).min(hi));
            (prefix[b + 1 - lo] - prefix[a - lo]) / (b - a + 1) as f64
        })
        .collect()
}

/// A response rising into the end of `sm` (dB, smoothed, one value per bin): its top, the
/// highest of the last `last` values, standing `min_db` or more over the lowest point between
/// it and the nearest higher value on its left (or `sm`'s start) — the topographic prominence
/// of a peak whose right side is past the end. Returned: that prominence, dB, and the top's
/// index in `sm`. Used where a sweep's end cuts a response off (a spectrum file's cliff, a raw
/// sweep's band).
pub(super) fn rising_into_end(sm: &[f64], last: usize, min_db: f64) -> Option<(f64, usize)> {
    let n = sm.len();
    if last == 0 || n <= last {
        return None;
    }
    let (at, top) = (n - last..n).fold((n - 1, f64::NEG_INFINITY), |best, j| {
        if sm[j] > best.1 {
            (j, sm[j])
        } else {
            best
        }
    });
    let mut low = top;
    for &v in sm[..n - last].iter().rev() {
        if v > top {
            break;
        }
        low = low.min(v);
    }
    let prominence = top - low;
    (prominence >= min_db).then_some((prominence, at))
}

#[cfg(test)]
mod tests {
    use super::{bases, rising_into_end};

    /// The stack's bases are the walk's: from each value out to the first higher one on each
    /// side, the lowest value met (itself included). Random sequences with many ties (values
    /// on a coarse grid) and a long one.
    #[wasm_bindgen_test::wasm_bindgen_test(unsupported = test)]
    fn bases_are_the_walks_lowest_values() {
        let walk = |sm: &[f64], i: usize, step: isize| {
            let mut low = sm[i];
            let mut j = i as isize + step;
            while j >= 0 && (j as usize) < sm.len() && sm[j as usize] <= sm[i] {
                low = low.min(sm[j as usize]);
                j += step;
            }
            low
        };
        let mut state = 99u64;
        for n in [1usize, 2, 3, 10, 57, 400, 3000] {
            for levels in [3u64, 50, 1 << 20] {
                let sm: Vec<f64> = (0..n)
                    .map(|_| {
                        state = state
                            .wrapping_mul(6364136223846793005)
                            .wrapping_add(1442695040888963407);
                        ((state >> 33) % levels) as f64 - 7.5
                    })
                    .collect();
                let (left, right) = bases(&sm);
                for i in 0..n {
                    assert_eq!(left[i], walk(&sm, i, -1), "n {n} left {i}");
                    assert_eq!(right[i], walk(&sm, i, 1), "n {n} right {i}");
                }
            }
        }
    }

    /// A ramp into the end stands its rise; a peak inside with a higher bin on its left is
    /// measured down to the lowest point after that bin; a falling end is no candidate.
    #[wasm_bindgen_test::wasm_bindgen_test(unsupported = test)]
    fn a_rise_into_the_end_and_its_prominence() {
        let ramp: Vec<f64> = (0..20).map(|k| k as f64).collect();
        assert_eq!(rising_into_end(&ramp, 3, 6.0), Some((19.0, 19)));
        // 30 dB at the start, down to 0, up to 10 at the end: 10 dB over the valley.
        let mut v = vec![30.0, 20.0, 10.0, 0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 9.0];
        assert_eq!(rising_into_end(&v, 3, 6.0), Some((10.0, 8)));
        assert_eq!(rising_into_end(&v, 3, 10.5), None);
        // The top more than `last` values from the end: not rising into it.
        v.extend([5.0, 2.0, 1.0]);
        assert_eq!(rising_into_end(&v, 3, 0.5), None);
        assert_eq!(rising_into_end(&v, 2, 0.5), None);
        assert_eq!(rising_into_end(&v[..3], 3, 0.0), None);
    }
}
