//! The initial design and the checks on an initial set: affine rank, near-duplicates.

use faer::{Mat, MatRef};
use impactcal_core::points::to_rows;
use impactcal_core::sampling::{seeded_rng, symmetric_latin_hypercube};

use crate::error::Result;
use crate::geometry::distance;

/// Number of random symmetric Latin hypercubes among which the design is chosen.
const DESIGN_TRIES: usize = 100;

/// A symmetric Latin hypercube design of `n` points in `(0, 1)^dim`, one per row of an
/// `n x dim` matrix, that holds `dim + 1` affinely independent points: among 100 designs
/// drawn from `seed`, the affinely spanning one with the largest minimum pairwise distance
/// (the first in draw order on ties). When none spans (only for `n < dim + 1`, which the
/// options forbid, or in degenerate tiny cases) the best by distance is returned.
///
/// # Errors
/// Those of the sampler (`n` or `dim` zero).
pub fn symmetric_design(n: usize, dim: usize, seed: u64) -> Result<Mat<f64>> {
    let mut rng = seeded_rng(seed);
    let mut best: Option<(bool, f64, Mat<f64>)> = None;
    for _ in 0..DESIGN_TRIES {
        let pts = symmetric_latin_hypercube(n, dim, &mut rng)?;
        let spans = affine_rank(pts.as_ref()) == dim + 1;
        let sep = min_pairwise_distance(pts.as_ref());
        let better = match &best {
            None => true,
            Some((s, d, _)) => (spans && !s) || (spans == *s && sep > *d),
        };
        if better {
            best = Some((spans, sep, pts));
        }
    }
    Ok(best.map_or_else(|| Mat::zeros(0, dim), |b| b.2))
}

/// The smallest distance between two of `points` (rows; infinity for fewer than two).
pub fn min_pairwise_distance(points: MatRef<'_, f64>) -> f64 {
    let rows = to_rows(points);
    let mut m = f64::INFINITY;
    for (i, a) in rows.iter().enumerate() {
        for b in &rows[i + 1..] {
            m = m.min(distance(a, b));
        }
    }
    m
}

/// The affine rank of `points` (`n x d`, one point per row): the rank of the
/// `n x (d + 1)` matrix `P` whose row `i` is `[1, x_i]`, with singular values below `1e-10`
/// of the largest (times `max(n, d + 1)`) counted as zero. An RBF with a linear tail is
/// uniquely solvable on distinct points exactly when this is `d + 1`.
pub fn affine_rank(points: MatRef<'_, f64>) -> usize {
    affine_rank_of_rows(&to_rows(points))
}

/// [`affine_rank`] of points given as rows (all of the same length).
pub(crate) fn affine_rank_of_rows(points: &[Vec<f64>]) -> usize {
    let Some(d) = points.first().map(Vec::len) else {
        return 0;
    };
    let n = points.len();
    // Centre the coordinates so that the constant column is not swamped.
    let mut mean = vec![0.0; d];
    for p in points {
        for (m, v) in mean.iter_mut().zip(p) {
            *m += v / n as f64;
        }
    }
    let p = Mat::from_fn(n, d + 1, |i, j| {
        if j == 0 {
            1.0
        } else {
            points[i][j - 1] - mean[j - 1]
        }
    });
    let Ok(s) = p.singular_values() else {
        return 0;
    };
    let hi = s.iter().copied().fold(0.0, f64::max);
    let tol = 1e-10 * hi * n.max(d + 1) as f64;
    s.iter().filter(|v| **v > tol).count()
}

/// The first pair `(i, j)`, `i < j`, of `points` (rows) closer than `tol`, with their
/// distance.
pub(crate) fn find_near_duplicate(points: &[Vec<f64>], tol: f64) -> Option<(usize, usize, f64)> {
    for j in 1..points.len() {
        for i in 0..j {
            let r = distance(&points[i], &points[j]);
            if r <= tol {
                return Some((i, j, r));
            }
        }
    }
    None
}
