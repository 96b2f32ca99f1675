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
    // Apply the permutation (new[i] = old[order[i]]) cycle by cycle with swaps.
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
}
