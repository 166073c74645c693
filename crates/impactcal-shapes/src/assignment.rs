//! Optimal one-to-one assignment on a rectangular weight matrix (Hungarian method with
//! potentials, O(n^2 m)).

/// Pairs rows with columns of `weights` (`rows x cols`, row-major) so that the sum of the
/// chosen weights is as large as possible, each row and column used at most once, and
/// `min(rows, cols)` pairs formed. Returns `(row, col)` pairs sorted by row.
pub(crate) fn max_weight_assignment(
    weights: &[f64],
    rows: usize,
    cols: usize,
) -> Vec<(usize, usize)> {
    if rows == 0 || cols == 0 {
        return Vec::new();
    }
    // Work on a cost matrix with n <= m (rows <= columns): transpose when needed.
    let transposed = rows > cols;
    let (n, m) = if transposed {
        (cols, rows)
    } else {
        (rows, cols)
    };
    let cost = |i: usize, j: usize| -> f64 {
        let w = if transposed {
            weights[j * cols + i]
        } else {
            weights[i * cols + j]
        };
        -w
    };
    // Classic potentials formulation, 1-based with a virtual column 0.
    let mut u = vec![0.0; n + 1];
    let mut v = vec![0.0; m + 1];
    let mut p = vec![0usize; m + 1];
    let mut way = vec![0usize; m + 1];
    for i in 1..=n {
        p[0] = i;
        let mut j0 = 0;
        let mut minv = vec![f64::INFINITY; m + 1];
        let mut used = vec![false; m + 1];
        loop {
            used[j0] = true;
            let i0 = p[j0];
            let mut delta = f64::INFINITY;
            let mut j1 = 0;
            for j in 1..=m {
                if !used[j] {
                    let cur = cost(i0 - 1, j - 1) - u[i0] - v[j];
                    if cur < minv[j] {
                        minv[j] = cur;
                        way[j] = j0;
                    }
                    if minv[j] < delta {
                        delta = minv[j];
                        j1 = j;
                    }
                }
            }
            for j in 0..=m {
                if used[j] {
                    u[p[j]] += delta;
                    v[j] -= delta;
                } else {
                    minv[j] -= delta;
                }
            }
            j0 = j1;
            if p[j0] == 0 {
                break;
            }
        }
        loop {
            let j1 = way[j0];
            p[j0] = p[j1];
            j0 = j1;
            if j0 == 0 {
                break;
            }
        }
    }
    let mut pairs: Vec<(usize, usize)> = (1..=m)
        .filter(|&j| p[j] != 0)
        .map(|j| {
            let (r, c) = (p[j] - 1, j - 1);
            if transposed { (c, r) } else { (r, c) }
        })
        .collect();
    pairs.sort_unstable();
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute_force(w: &[f64], rows: usize, cols: usize) -> f64 {
        // Best sum over all injective maps from the smaller side to the larger side.
        fn rec(w: &[f64], rows: usize, cols: usize, r: usize, used: &mut Vec<bool>) -> f64 {
            if r == rows {
                return 0.0;
            }
            let mut best = f64::NEG_INFINITY;
            for c in 0..cols {
                if !used[c] {
                    used[c] = true;
                    best = best.max(w[r * cols + c] + rec(w, rows, cols, r + 1, used));
                    used[c] = false;
                }
            }
            best
        }
        if rows <= cols {
            rec(w, rows, cols, 0, &mut vec![false; cols])
        } else {
            let t: Vec<f64> = (0..cols * rows)
                .map(|k| w[(k % rows) * cols + k / rows])
                .collect();
            rec(&t, cols, rows, 0, &mut vec![false; rows])
        }
    }

    #[test]
    fn matches_brute_force() {
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for (rows, cols) in [(1, 1), (3, 3), (4, 6), (6, 4), (5, 5), (2, 7)] {
            for _ in 0..20 {
                let w: Vec<f64> = (0..rows * cols).map(|_| next()).collect();
                let pairs = max_weight_assignment(&w, rows, cols);
                assert_eq!(pairs.len(), rows.min(cols));
                let total: f64 = pairs.iter().map(|&(r, c)| w[r * cols + c]).sum();
                assert!((total - brute_force(&w, rows, cols)).abs() < 1e-12);
                let mut seen_c: Vec<usize> = pairs.iter().map(|p| p.1).collect();
                seen_c.sort_unstable();
                seen_c.dedup();
                assert_eq!(seen_c.len(), pairs.len());
            }
        }
    }
}
