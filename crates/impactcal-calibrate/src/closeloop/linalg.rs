//! Small linear-algebra pieces of the loop on whitened vectors: inner products and the
//! SVD of a residual matrix (the Jacobian's least squares are in `closeloop::jacobian`).

use faer::Mat;

use crate::error::{CalibrateError, Result};

/// `<a, b>`.
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The leading singular triplet `(sigma_1, u_1, v_1)` and the singular values of the
/// `rows x cols` matrix `m` (row-major), signs fixed so that `u_1`'s largest entry is
/// positive.
///
/// # Errors
/// [`CalibrateError::Study`] when the SVD does not converge.
pub(crate) fn svd_rows(
    m: &[f64],
    rows: usize,
    cols: usize,
) -> Result<(Vec<f64>, Mat<f64>, Mat<f64>)> {
    let a = Mat::from_fn(rows, cols, |i, j| m[i * cols + j]);
    let svd = a
        .thin_svd()
        .map_err(|e| CalibrateError::study("residual SVD", format!("{e:?}")))?;
    let s: Vec<f64> = svd.S().column_vector().iter().copied().collect();
    let mut u = svd.U().to_owned();
    let mut v = svd.V().to_owned();
    for j in 0..s.len() {
        let (mut best, mut at) = (0.0, 0);
        for i in 0..rows {
            if u[(i, j)].abs() > best {
                best = u[(i, j)].abs();
                at = i;
            }
        }
        if u[(at, j)] < 0.0 {
            for i in 0..rows {
                u[(i, j)] = -u[(i, j)];
            }
            for i in 0..cols {
                v[(i, j)] = -v[(i, j)];
            }
        }
    }
    Ok((s, u, v))
}
