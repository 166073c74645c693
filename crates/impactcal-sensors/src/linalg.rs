//! Small dense kernels: QR-based whitening, leverage scores, determinants of tiny matrices.

use faer::{Mat, MatRef};

use crate::error::{Result, SensorsError};

/// Gathers `rows` of the row-major `n x k` array `phi` into a faer matrix.
pub(crate) fn gather(phi: &[f64], k: usize, rows: &[usize]) -> Mat<f64> {
    Mat::from_fn(rows.len(), k, |i, j| phi[rows[i] * k + j])
}

/// The `k x k` upper-triangular factor `R` of a thin QR of the gathered rows
/// (`rows.len() >= k`), so that `Phi_rows^T Phi_rows = R^T R`.
pub(crate) fn r_factor(phi: &[f64], k: usize, rows: &[usize]) -> Mat<f64> {
    let m = gather(phi, k, rows);
    let qr = m.qr();
    let r = qr.thin_R();
    Mat::from_fn(k, k, |i, j| if i <= j { r[(i, j)] } else { 0.0 })
}

/// Solves `w R = phi` for the row vector `w` (forward substitution on `R^T`).
/// A zero pivot gives infinities; callers only pass `R` of full rank.
pub(crate) fn whiten_row(phi: &[f64], r: MatRef<'_, f64>, w: &mut [f64]) {
    let k = phi.len();
    for j in 0..k {
        let mut acc = phi[j];
        for i in 0..j {
            acc -= w[i] * r[(i, j)];
        }
        w[j] = acc / r[(j, j)];
    }
}

/// `ln det(Phi_rows^T Phi_rows) = 2 sum ln |R_ii|`.
pub(crate) fn log_det_gram(phi: &[f64], k: usize, rows: &[usize]) -> f64 {
    let r = r_factor(phi, k, rows);
    (0..k).map(|i| r[(i, i)].abs().ln()).sum::<f64>() * 2.0
}

/// Singular values (non-increasing) of an `m x k` matrix.
pub(crate) fn singular_values(m: MatRef<'_, f64>) -> Result<Vec<f64>> {
    let mut s = m
        .singular_values()
        .map_err(|e| SensorsError::Numerical(format!("SVD did not converge: {e:?}")))?;
    s.sort_by(|a, b| b.total_cmp(a));
    Ok(s)
}

/// Effective-independence (leverage) scores of the rows of `phi`:
/// `E_D,i = [Phi (Phi^T Phi)^-1 Phi^T]_ii = ||U(i,:)||^2`, where `U` holds the left singular
/// vectors of the numerical range of `Phi` (singular values above `1e-12 sigma_max`), so the
/// explicit inverse is never formed.
///
/// Each score lies in `[0, 1]` and the scores sum to the numerical rank of `Phi`; they do not
/// change when `Phi` is replaced by `Phi T` for an invertible `T`.
///
/// # Errors
/// [`SensorsError::Numerical`] if the SVD fails;
/// [`CoreError::Empty`](impactcal_core::CoreError::Empty) for an empty matrix,
/// [`CoreError::NonFinite`](impactcal_core::CoreError::NonFinite) for non-finite values.
///
/// ```
/// use faer::mat;
/// let phi = mat![[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]];
/// let e = impactcal_sensors::leverage_scores(phi.as_ref())?;
/// assert!((e.iter().sum::<f64>() - 2.0).abs() < 1e-12);
/// assert!((e[2] - 2.0 / 3.0).abs() < 1e-12);
/// # Ok::<(), impactcal_sensors::SensorsError>(())
/// ```
pub fn leverage_scores(phi: MatRef<'_, f64>) -> Result<Vec<f64>> {
    if phi.nrows() == 0 || phi.ncols() == 0 {
        return Err(impactcal_core::CoreError::Empty {
            what: "the shape matrix of the leverage scores".into(),
        }
        .into());
    }
    impactcal_core::check_finite_mat("shape matrix", phi)?;
    let svd = phi
        .thin_svd()
        .map_err(|e| SensorsError::Numerical(format!("SVD did not converge: {e:?}")))?;
    let s = svd.S().column_vector();
    let smax = (0..s.nrows()).map(|i| s[i]).fold(0.0, f64::max);
    let u = svd.U();
    let keep: Vec<usize> = (0..s.nrows()).filter(|&i| s[i] > 1e-12 * smax).collect();
    Ok((0..phi.nrows())
        .map(|i| keep.iter().map(|&j| u[(i, j)] * u[(i, j)]).sum())
        .collect())
}

/// Determinant of the `n x n` row-major matrix `a` (n <= 6 in practice) by Gaussian
/// elimination with partial pivoting; `a` is overwritten.
pub(crate) fn small_det(a: &mut [f64], n: usize) -> f64 {
    let mut det = 1.0;
    for c in 0..n {
        let p = (c..n)
            .max_by(|&i, &j| a[i * n + c].abs().total_cmp(&a[j * n + c].abs()))
            .unwrap_or(c);
        let pivot = a[p * n + c];
        if pivot == 0.0 {
            return 0.0;
        }
        if p != c {
            for j in 0..n {
                a.swap(p * n + j, c * n + j);
            }
            det = -det;
        }
        det *= pivot;
        for i in c + 1..n {
            let f = a[i * n + c] / pivot;
            if f != 0.0 {
                for j in c..n {
                    a[i * n + j] -= f * a[c * n + j];
                }
            }
        }
    }
    det
}

/// Inverse of the symmetric positive definite `n x n` (n <= 3) matrix `a` by Gauss-Jordan;
/// `None` when a pivot is not positive.
pub(crate) fn small_spd_inverse(a: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut m = a.to_vec();
    let mut inv = vec![0.0; n * n];
    for i in 0..n {
        inv[i * n + i] = 1.0;
    }
    for c in 0..n {
        let pivot = m[c * n + c];
        if pivot <= 0.0 || !pivot.is_finite() {
            return None;
        }
        for j in 0..n {
            m[c * n + j] /= pivot;
            inv[c * n + j] /= pivot;
        }
        for i in 0..n {
            if i != c {
                let f = m[i * n + c];
                for j in 0..n {
                    m[i * n + j] -= f * m[c * n + j];
                    inv[i * n + j] -= f * inv[c * n + j];
                }
            }
        }
    }
    Some(inv)
}

/// `sum_j a_j b_j`.
#[inline]
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    // Four independent partial sums let the compiler use vector lanes.
    let mut acc = [0.0; 4];
    let (a4, a_rest) = a.split_at(a.len() - a.len() % 4);
    let (b4, b_rest) = b.split_at(a4.len());
    for (x, y) in a4.chunks_exact(4).zip(b4.chunks_exact(4)) {
        for l in 0..4 {
            acc[l] += x[l] * y[l];
        }
    }
    let tail: f64 = a_rest.iter().zip(b_rest).map(|(x, y)| x * y).sum();
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}
