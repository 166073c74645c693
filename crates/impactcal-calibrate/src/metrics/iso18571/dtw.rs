//! Dynamic time warping inside a Sakoe-Chiba band, as ISO/TS 18571 uses it for the
//! magnitude score.

/// Warps `x` (computed) against `y` (reference), both of length `n`, with squared-difference
/// local cost, the symmetric steps (down, left, diagonal, each of weight 1) and the band
/// `|i - j| <= band`, and returns `sum |x_w - y_w|` and `sum |y_w|` over the warping path.
///
/// The accumulated cost is `D[i][j] = (x_i - y_j)^2 + min(D[i-1][j], D[i][j-1],
/// D[i-1][j-1])`. The path is traced back from `(n-1, n-1)` taking the cheapest of the three
/// predecessors, preferring `(i-1, j)`, then `(i, j-1)`, then `(i-1, j-1)` on ties (the order
/// of the dtwalign package that objective-rating-metrics uses).
///
/// `scratch` is reused between calls to avoid allocating the `n x (2 band + 1)` table.
pub(crate) fn warped_l1(x: &[f64], y: &[f64], band: usize, scratch: &mut Vec<f64>) -> (f64, f64) {
    let n = x.len();
    let width = 2 * band + 1;
    scratch.clear();
    scratch.resize(n * width, f64::INFINITY);
    let d = scratch.as_mut_slice();
    // Cell (i, j) lives at d[i * width + j + band - i]: row i holds j in i-band..=i+band.
    let at = |i: usize, j: usize| i * width + j + band - i;
    for (i, &xi) in x.iter().enumerate() {
        let lo = i.saturating_sub(band);
        let hi = (i + band).min(n - 1);
        let row = i * width + band - i;
        let mut left = f64::INFINITY;
        if i == 0 {
            for j in lo..=hi {
                let cost = (xi - y[j]) * (xi - y[j]);
                left = if j == 0 { cost } else { cost + left };
                d[row + j] = left;
            }
            continue;
        }
        // Cell (i-1, j) lives at prev + j.
        let prev = row + 1 - width;
        for j in lo..=hi {
            let cost = (xi - y[j]) * (xi - y[j]);
            let up = if j < i + band {
                d[prev + j]
            } else {
                f64::INFINITY
            };
            let diag = if j > 0 {
                d[prev + j - 1]
            } else {
                f64::INFINITY
            };
            left = cost + up.min(left).min(diag);
            d[row + j] = left;
        }
    }
    let get = |i: usize, j: usize, d: &[f64]| -> f64 {
        if i.abs_diff(j) > band {
            f64::INFINITY
        } else {
            d[at(i, j)]
        }
    };
    let (mut i, mut j) = (n - 1, n - 1);
    let (mut diff, mut norm) = ((x[i] - y[j]).abs(), y[j].abs());
    while i > 0 || j > 0 {
        let up = if i > 0 {
            get(i - 1, j, d)
        } else {
            f64::INFINITY
        };
        let left = if j > 0 {
            get(i, j - 1, d)
        } else {
            f64::INFINITY
        };
        let diag = if i > 0 && j > 0 {
            get(i - 1, j - 1, d)
        } else {
            f64::INFINITY
        };
        if up <= left && up <= diag {
            i -= 1;
        } else if left <= diag {
            j -= 1;
        } else {
            i -= 1;
            j -= 1;
        }
        diff += (x[i] - y[j]).abs();
        norm += y[j].abs();
    }
    (diff, norm)
}

#[cfg(test)]
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;

    /// The full-matrix recursion, for comparison.
    fn reference(x: &[f64], y: &[f64], band: usize) -> (f64, f64) {
        let n = x.len();
        let mut d = vec![vec![f64::INFINITY; n]; n];
        for i in 0..n {
            for j in 0..n {
                if i.abs_diff(j) > band {
                    continue;
                }
                let cost = (x[i] - y[j]).powi(2);
                if i == 0 && j == 0 {
                    d[i][j] = cost;
                    continue;
                }
                let mut best = f64::INFINITY;
                if i > 0 {
                    best = best.min(d[i - 1][j]);
                }
                if j > 0 {
                    best = best.min(d[i][j - 1]);
                }
                if i > 0 && j > 0 {
                    best = best.min(d[i - 1][j - 1]);
                }
                d[i][j] = cost + best;
            }
        }
        let (mut i, mut j) = (n - 1, n - 1);
        let (mut a, mut b) = ((x[i] - y[j]).abs(), y[j].abs());
        while i > 0 || j > 0 {
            let up = if i > 0 { d[i - 1][j] } else { f64::INFINITY };
            let left = if j > 0 { d[i][j - 1] } else { f64::INFINITY };
            let diag = if i > 0 && j > 0 {
                d[i - 1][j - 1]
            } else {
                f64::INFINITY
            };
            let m = up.min(left).min(diag);
            if up == m {
                i -= 1;
            } else if left == m {
                j -= 1;
            } else {
                i -= 1;
                j -= 1;
            }
            a += (x[i] - y[j]).abs();
            b += y[j].abs();
        }
        (a, b)
    }

    #[test]
    fn banded_table_matches_the_full_one() {
        let mut scratch = Vec::new();
        for (n, band) in [(1, 0), (2, 0), (10, 0), (30, 2), (57, 5), (100, 99)] {
            let x: Vec<f64> = (0..n).map(|k| (k as f64 * 0.37).sin() * 3.0).collect();
            let y: Vec<f64> = (0..n)
                .map(|k| (k as f64 * 0.41 + 0.2).sin() * 2.5)
                .collect();
            assert_eq!(
                warped_l1(&x, &y, band, &mut scratch),
                reference(&x, &y, band),
                "n {n} band {band}"
            );
        }
    }

    #[test]
    fn identical_curves_warp_onto_the_diagonal() {
        let x: Vec<f64> = (0..40).map(|k| (k as f64 * 0.2).sin()).collect();
        let (diff, norm) = warped_l1(&x, &x, 4, &mut Vec::new());
        assert_eq!(diff, 0.0);
        assert!((norm - x.iter().map(|v| v.abs()).sum::<f64>()).abs() < 1e-12);
    }
}
