//! The least-squares pieces of the loop, on whitened vectors: the SVD of a Jacobian, its
//! solve and covariance, and the orthogonal projector onto its column space.

use faer::Mat;

use crate::error::{CalibrateError, Result};

/// The thin SVD `J = U S V^T` of an `n x m` matrix (columns given as vectors of length
/// `n`), truncated at the numerical rank (singular values above `1e-10 s_max`).
pub(crate) struct Lsq {
    u: Mat<f64>,
    s: Vec<f64>,
    v: Mat<f64>,
}

impl Lsq {
    /// Factors the matrix whose columns are `cols`.
    ///
    /// # Errors
    /// [`CalibrateError::Study`] when the SVD does not converge or there are no columns.
    pub fn new(cols: &[Vec<f64>]) -> Result<Self> {
        let m = cols.len();
        let n = cols.first().map_or(0, Vec::len);
        if m == 0 || n == 0 {
            return Err(CalibrateError::study("least squares", "no columns"));
        }
        let a = Mat::from_fn(n, m, |i, j| cols[j][i]);
        let svd = a
            .thin_svd()
            .map_err(|e| CalibrateError::study("least squares", format!("SVD: {e:?}")))?;
        let s_all: Vec<f64> = svd.S().column_vector().iter().copied().collect();
        let smax = s_all.iter().copied().fold(0.0, f64::max);
        let r = s_all.iter().filter(|&&x| x > 1e-10 * smax).count().max(1);
        Ok(Lsq {
            u: svd.U().subcols(0, r).to_owned(),
            s: s_all[..r].to_vec(),
            v: svd.V().subcols(0, r).to_owned(),
        })
    }

    /// The numerical rank `r`.
    pub fn rank(&self) -> usize {
        self.s.len()
    }

    /// `U z` for `z` of length `r`: the image of the parameter change `V S^-1 z`. With
    /// `z ~ N(0, I)` it is `J delta` for `delta ~ N(0, (J^T J)^+)`.
    pub fn span(&self, z: &[f64]) -> Vec<f64> {
        (0..self.u.nrows())
            .map(|i| z.iter().enumerate().map(|(j, c)| self.u[(i, j)] * c).sum())
            .collect()
    }

    /// `U^T y` (length = rank).
    fn ut(&self, y: &[f64]) -> Vec<f64> {
        (0..self.s.len())
            .map(|j| (0..y.len()).map(|i| self.u[(i, j)] * y[i]).sum())
            .collect()
    }

    /// The minimum-norm least-squares solution `x = V S^-1 U^T y`.
    pub fn solve(&self, y: &[f64]) -> Vec<f64> {
        let c = self.ut(y);
        (0..self.v.nrows())
            .map(|i| {
                (0..self.s.len())
                    .map(|j| self.v[(i, j)] * c[j] / self.s[j])
                    .sum()
            })
            .collect()
    }

    /// The diagonal of `(J^T J)^+`: the variances of the solution for unit white noise.
    pub fn variances(&self) -> Vec<f64> {
        (0..self.v.nrows())
            .map(|i| {
                (0..self.s.len())
                    .map(|j| (self.v[(i, j)] / self.s[j]).powi(2))
                    .sum()
            })
            .collect()
    }

    /// `P_J y = U U^T y`, the part of `y` the columns can reproduce.
    pub fn project(&self, y: &[f64]) -> Vec<f64> {
        let c = self.ut(y);
        (0..y.len())
            .map(|i| (0..self.s.len()).map(|j| self.u[(i, j)] * c[j]).sum())
            .collect()
    }
}

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
