//! From a feasible point of a linear program in standard form (A x = b, x ≥ 0, minimise c·x) to
//! one with at most as many nonzero entries as A has rows — a vertex when the rows are
//! independent, as the `direct` programs' are — whose objective is no larger (Carathéodory's reduction, the "purification" step of interior-point LP codes:
//! Megiddo, *On finding primal- and dual-optimal bases*, ORSA J. Computing 3(1), 1991).
//!
//! The grid programs of the `direct` family are such LPs: the zero-vibration equalities and
//! Σ A = 1 over hundreds of grid amplitudes, A ≥ 0, the centroid minimised. Where the optimum is
//! not unique (six modes, say), the interior-point solver returns the centre of the optimal
//! face — every grid amplitude positive, hundreds of them — not a vertex: nothing for the polish
//! to start from, and a support the fallback's own program cannot reproduce to its tolerance
//! (issue 24: six-mode `direct` ZVD gave 818 impulses natively, "numerically degenerate" in
//! wasm). Moving along the null space of the support's columns until an amplitude reaches 0,
//! one at a time, ends at a vertex of the same face.

/// A nonzero z with `Σ_k a[r][cols[k]] z_k = 0` for every row r (so `cols.len()` must exceed
/// the rank of those columns), scaled to max |z_k| = 1; `None` if the columns are independent
/// to rounding. Gaussian elimination with complete pivoting on the rows × `cols` submatrix: the
/// columns never chosen as pivots are free, and the null vector sets the first of them to 1.
fn null_vector(a: &[Vec<f64>], cols: &[usize]) -> Option<Vec<f64>> {
    let (m, k) = (a.len(), cols.len());
    let mut w: Vec<Vec<f64>> = a
        .iter()
        .map(|row| cols.iter().map(|&c| row[c]).collect())
        .collect();
    let scale = w
        .iter()
        .flatten()
        .fold(0.0_f64, |s, v| s.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    // perm[j]: the submatrix column now at position j.
    let mut perm: Vec<usize> = (0..k).collect();
    let mut rank = 0;
    while rank < m.min(k) {
        let (mut pr, mut pc, mut big) = (rank, rank, 0.0);
        for (r, row) in w.iter().enumerate().skip(rank) {
            for (c, v) in row.iter().enumerate().skip(rank) {
                if v.abs() > big {
                    (pr, pc, big) = (r, c, v.abs());
                }
            }
        }
        if big <= 1e-13 * scale {
            break;
        }
        w.swap(rank, pr);
        for row in w.iter_mut() {
            row.swap(rank, pc);
        }
        perm.swap(rank, pc);
        let pivot = w[rank].clone();
        for (r, row) in w.iter_mut().enumerate() {
            if r == rank || row[rank] == 0.0 {
                continue;
            }
            let f = row[rank] / pivot[rank];
            for (v, p) in row.iter_mut().zip(&pivot).skip(rank) {
                *v -= f * p;
            }
        }
        rank += 1;
    }
    if rank >= k {
        return None;
    }
    // Reduced: w[r][r] x_r + Σ_{j ≥ rank} w[r][j] x_j = 0 for r < rank. Free x_rank = 1.
    let mut z = vec![0.0; k];
    z[perm[rank]] = 1.0;
    for r in 0..rank {
        z[perm[r]] = -w[r][rank] / w[r][r];
    }
    let top = z.iter().fold(0.0_f64, |s, v| s.max(v.abs()));
    (top.is_finite() && top > 0.0).then(|| z.iter().map(|v| v / top).collect())
}

/// Moves `x` (A x = b, x ≥ 0 up to rounding, `a` the rows of A) to a point of {A x = b, x ≥ 0}
/// with at most as many positive entries as rows (a vertex if the rows are independent) and
/// c·x no larger: while more entries are positive than A has rows, a direction z in the
/// null space of (the first rows + 1 of) their columns, signed so that c·z ≤ 0, is followed
/// until an entry reaches 0, which is dropped. Each step keeps A x = b (to rounding) and removes
/// at least one entry, so it ends after at most (positive entries − rows) steps. Negative
/// entries (an interior-point solver's −1e-12) are set to 0 first.
pub(crate) fn to_vertex(a: &[Vec<f64>], c: &[f64], x: &mut [f64]) {
    let m = a.len();
    for v in x.iter_mut() {
        if v.is_nan() || *v < 0.0 {
            *v = 0.0;
        }
    }
    let mut support: Vec<usize> = (0..x.len()).filter(|&i| x[i] > 0.0).collect();
    while support.len() > m {
        let cols = &support[..=m];
        let Some(mut z) = null_vector(a, cols) else {
            break;
        };
        let cz: f64 = cols.iter().zip(&z).map(|(&i, zk)| c[i] * zk).sum();
        if cz > 0.0 || (cz == 0.0 && z.iter().all(|&v| v >= 0.0)) {
            z.iter_mut().for_each(|v| *v = -*v);
        }
        // The ratio test: the largest step that keeps every entry ≥ 0.
        let step = cols
            .iter()
            .zip(&z)
            .filter(|(_, &zk)| zk < 0.0)
            .map(|(&i, &zk)| x[i] / -zk)
            .fold(f64::INFINITY, f64::min);
        if !step.is_finite() {
            break; // z ≥ 0 with c·z < 0: unbounded; cannot happen with Σ x = 1 among the rows.
        }
        let mut blocked = false;
        for (&i, &zk) in cols.iter().zip(&z) {
            let moved = x[i] + step * zk;
            // The blocking entries land on 0 exactly (not on rounding's ±1e-17).
            x[i] = if zk < 0.0 && x[i] / -zk <= step {
                0.0
            } else {
                moved.max(0.0)
            };
            blocked |= x[i] == 0.0;
        }
        if !blocked {
            break;
        }
        support.retain(|&i| x[i] > 0.0);
    }
}

#[cfg(test)]
mod tests {
    use super::{null_vector, to_vertex};

    fn residual(a: &[Vec<f64>], x: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(row, bi)| (row.iter().zip(x).map(|(p, q)| p * q).sum::<f64>() - bi).abs())
            .fold(0.0, f64::max)
    }

    /// The null vector annihilates the chosen columns, including dependent ones (a repeated
    /// column, a rank-deficient block), and there is none for independent columns.
    #[test]
    fn null_vectors() {
        let a = vec![
            vec![1.0, 2.0, 3.0, 1.0, 0.5],
            vec![0.0, 1.0, 4.0, 1.0, -2.0],
            vec![1.0, 3.0, 7.0, 2.0, -1.5], // row 0 + row 1
        ];
        for cols in [
            vec![0, 1, 2],
            vec![0, 1, 2, 3],
            vec![1, 3, 4],
            vec![0, 3, 3],
        ] {
            let z = null_vector(&a, &cols).expect("dependent columns");
            let top = z.iter().fold(0.0_f64, |s, v| s.max(v.abs()));
            assert!((top - 1.0).abs() < 1e-15, "{z:?}");
            for row in &a {
                let s: f64 = cols.iter().zip(&z).map(|(&c, zk)| row[c] * zk).sum();
                assert!(s.abs() < 1e-14, "{cols:?}: {z:?} leaves {s}");
            }
        }
        let id = vec![vec![1.0, 0.0], vec![0.0, 1.0]];
        assert!(null_vector(&id, &[0, 1]).is_none());
    }

    /// An interior point of a small LP ends at a vertex: at most as many positive entries as
    /// rows, A x = b kept, x ≥ 0, c·x not larger — and, where the optimum is a unique vertex and
    /// the start is on the optimal face, that vertex.
    #[test]
    fn an_interior_point_goes_to_a_vertex() {
        // Σ x = 1 and Σ k x_k = 2 over x_0 … x_5 ≥ 0: vertices are pairs straddling 2.
        let a = vec![vec![1.0; 6], (0..6).map(f64::from).collect::<Vec<_>>()];
        let b = [1.0, 2.0];
        // Interior: x_k ∝ something positive with mean 2.
        let mut x = vec![0.25, 0.2, 0.15, 0.2, 0.1, 0.1];
        assert!(residual(&a, &x, &b) < 1e-14);
        let c: Vec<f64> = (0..6).map(|k| f64::from(k * k)).collect(); // convex: optimum at x_2 = 1
        let before: f64 = c.iter().zip(&x).map(|(p, q)| p * q).sum();
        to_vertex(&a, &c, &mut x);
        let after: f64 = c.iter().zip(&x).map(|(p, q)| p * q).sum();
        assert!(x.iter().all(|&v| v >= 0.0));
        assert!(x.iter().filter(|&&v| v > 0.0).count() <= 2, "{x:?}");
        assert!(residual(&a, &x, &b) < 1e-14, "{x:?}");
        assert!(after <= before + 1e-15, "{before} -> {after}");
        // On the optimal face {x_2 = 1} the start is already the vertex: kept as it is.
        let mut y = vec![0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        to_vertex(&a, &c, &mut y);
        assert_eq!(y, vec![0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
        // A flat objective: any vertex, two entries at most.
        let mut u = vec![2.0 / 6.0, 1.0 / 6.0, 1.0 / 6.0, 1.0 / 6.0, 1.0 / 6.0, 0.0];
        let bu = [1.0, a[1].iter().zip(&u).map(|(p, q)| p * q).sum::<f64>()];
        to_vertex(&a, &[0.0; 6], &mut u);
        assert!(u.iter().filter(|&&v| v > 0.0).count() <= 2, "{u:?}");
        assert!(residual(&a, &u, &bu) < 1e-14, "{u:?}");
    }
}
