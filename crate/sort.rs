//! One stable sort for the whole crate.
//!
//! `slice::sort_by` is monomorphised for every comparator closure (about 4 KB of wasm each);
//! these helpers sort indices through a single `dyn` comparator instead, so every call site
//! shares one instantiation of the standard library's stable sort. The order is exactly
//! `sort_by`'s: stable, equal elements keep their order.

use std::cmp::Ordering;

/// Sorts `indices` stably by `cmp`, as `indices.sort_by(|&a, &b| cmp(a, b))`.
pub(crate) fn sort_indices(indices: &mut [usize], cmp: &dyn Fn(usize, usize) -> Ordering) {
    indices.sort_by(|&a, &b| cmp(a, b));
}

/// Sorts `v` stably by `cmp`, as `v.sort_by(cmp)`.
pub(crate) fn sort_by<T>(v: &mut [T], cmp: impl Fn(&T, &T) -> Ordering) {
    let mut order: Vec<usize> = (0..v.len()).collect();
    sort_indices(&mut order, &|a, b| cmp(&v[a], &v[b]));
    permute(v, &order);
}

/// Sorts `v` stably by an `f64` key in [`f64::total_cmp`]'s order, as
/// `sort_by(v, |a, b| key(a).total_cmp(&key(b)))` does, by a least-significant-digit radix
/// sort of the keys' bits (passes of a byte, a pass skipped where every key has the same
/// byte; none where `v` is already sorted: [`radix_order`]): the impulse times of a 6-mode
/// convolution (15 625) and the knots of a command shaped by it, in time order, without a
/// comparison sort.
pub(crate) fn sort_by_f64_key<T>(v: &mut [T], key: impl Fn(&T) -> f64) {
    let n = v.len();
    if n < 64 || u32::try_from(n).is_err() {
        return sort_by(v, |a, b| key(a).total_cmp(&key(b)));
    }
    let keys: Vec<u64> = v.iter().map(|x| total_order_bits(key(x))).collect();
    if let Some(order) = radix_order(&keys) {
        permute(v, &order);
    }
}

/// `x`'s bits as an unsigned integer in [`f64::total_cmp`]'s order: negative numbers (sign set)
/// reversed, after them the positive ones.
fn total_order_bits(x: f64) -> u64 {
    let b = x.to_bits();
    if b >> 63 == 1 {
        !b
    } else {
        b | 1 << 63
    }
}

/// The stable order of `keys` (at most u32::MAX of them) by a least-significant-digit radix
/// sort, or `None` where they are sorted already. Not generic: one copy in the module for
/// every caller of [`sort_by_f64_key`]. The passes go over the high 32 bits first (sign,
/// exponent and 20 bits of mantissa: times a millionth apart); the keys left tied there are
/// few and short runs, put in order by insertion. Should a run of ties be longer than
/// [`LONG_TIES`], the whole sort is done again over all 64 bits.
fn radix_order(keys: &[u64]) -> Option<Vec<usize>> {
    if keys.windows(2).all(|w| w[0] <= w[1]) {
        return None;
    }
    let n = keys.len();
    let mut order: Vec<u32> = (0..n as u32).collect();
    let mut next = vec![0_u32; n];
    let mut low = 32;
    loop {
        for shift in (low..64).step_by(8) {
            let byte = |i: u32| ((keys[i as usize] >> shift) & 0xff) as usize;
            let mut start = [0_usize; 257];
            for &i in &order {
                start[byte(i) + 1] += 1;
            }
            if start.contains(&n) {
                continue;
            }
            for b in 1..257 {
                start[b] += start[b - 1];
            }
            for &i in &order {
                let b = byte(i);
                next[start[b]] = i;
                start[b] += 1;
            }
            std::mem::swap(&mut order, &mut next);
        }
        if low == 0 || order_ties(keys, &mut order) {
            break;
        }
        // A long run of ties: the whole sort again, over all 64 bits.
        order = (0..n as u32).collect();
        low = 0;
    }
    Some(order.into_iter().map(|i| i as usize).collect())
}

/// Longest run of keys tied in their high 32 bits that [`order_ties`] puts in order.
const LONG_TIES: usize = 64;

/// Puts each run of `order` whose keys tie in the high 32 bits in the order of the whole keys,
/// stably (insertion); false as soon as a run longer than [`LONG_TIES`] needs it (the runs
/// before it are then in order, the rest not).
fn order_ties(keys: &[u64], order: &mut [u32]) -> bool {
    let key = |i: u32| keys[i as usize];
    let mut i = 0;
    while i < order.len() {
        let high = key(order[i]) >> 32;
        let mut j = i + 1;
        while j < order.len() && key(order[j]) >> 32 == high {
            j += 1;
        }
        let run = &mut order[i..j];
        if run.windows(2).any(|w| key(w[0]) > key(w[1])) {
            if run.len() > LONG_TIES {
                return false;
            }
            for k in 1..run.len() {
                let x = run[k];
                let mut m = k;
                while m > 0 && key(run[m - 1]) > key(x) {
                    run[m] = run[m - 1];
                    m -= 1;
                }
                run[m] = x;
            }
        }
        i = j;
    }
    true
}

/// Applies the permutation `order` to `v` (new[i] = old[order[i]]) cycle by cycle with swaps.
fn permute<T>(v: &mut [T], order: &[usize]) {
    let mut done = vec![false; v.len()];
    for start in 0..v.len() {
        let mut at = start;
        while !done[at] {
            done[at] = true;
            let next = order[at];
            if next == start {
                break;
            }
            v.swap(at, next);
            at = next;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_order_as_sort_by() {
        let mut seed = 12345u64;
        for n in 0..60 {
            let v: Vec<(u8, usize)> = (0..n)
                .map(|i| {
                    seed = seed
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    ((seed >> 60) as u8, i)
                })
                .collect();
            let mut a = v.clone();
            let mut b = v.clone();
            a.sort_by_key(|x| x.0);
            sort_by(&mut b, |x, y| x.0.cmp(&y.0));
            assert_eq!(a, b);
        }
    }
    /// The radix sort by an f64 key gives `sort_by`'s stable order by `total_cmp`: keys with
    /// many ties, both zeros, negatives, infinities and NaNs of both signs, sorted and reversed
    /// inputs, sizes around the radix path's threshold; keys a few units in the last place
    /// apart (tied in the high 32 bits the passes sort by) in short runs, put in order by
    /// insertion, and in one long run, sorted again over all 64 bits.
    #[test]
    fn radix_by_f64_key_is_the_stable_sort_by_total_cmp() {
        let mut seed = 99u64;
        let mut rand = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            seed >> 11
        };
        let specials = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            -f64::NAN,
            1e-300,
            5e-324,
        ];
        let mut radix_runs = 0;
        for n in [0, 1, 63, 64, 65, 200, 1000, 15_625] {
            for kind in 0..6 {
                let v: Vec<(f64, usize)> = (0..n)
                    .map(|i| {
                        let r = rand();
                        let x = match kind {
                            0 => (r % 17) as f64 * 0.25,
                            1 => specials[(r % specials.len() as u64) as usize],
                            2 => f64::from_bits(r) * if r & 1 == 0 { 1.0 } else { -1.0 },
                            3 => -(i as f64),
                            // 500 groups (runs of ≤ 64 ties for every n here) ...
                            4 => f64::from_bits((1.0 + (r % 500) as f64).to_bits() + (r >> 20) % 7),
                            // ... and one group.
                            _ => f64::from_bits(1.5f64.to_bits() + (r >> 20) % 1000),
                        };
                        (x, i)
                    })
                    .collect();
                let mut want = v.clone();
                sort_by(&mut want, |a, b| a.0.total_cmp(&b.0));
                let mut got = v.clone();
                sort_by_f64_key(&mut got, |x| x.0);
                let bits =
                    |w: &[(f64, usize)]| w.iter().map(|x| (x.0.to_bits(), x.1)).collect::<Vec<_>>();
                assert_eq!(bits(&got), bits(&want), "n {n}, kind {kind}");
                radix_runs += usize::from(n >= 64);
            }
        }
        assert!(radix_runs >= 20);
    }
}
