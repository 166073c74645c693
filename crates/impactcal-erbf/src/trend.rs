//! The linear trend: plain least-squares linear regression of every output on the inputs,
//! the yardstick a surrogate must beat to be worth its kernel.
//!
//! With `X = [1, x]` (`N x (m + 1)`) and its thin QR factorisation `X = Q R`, the hat
//! matrix is `H = Q Q^T`, the fitted values `H F` and the leave-one-out errors follow in
//! closed form (the PRESS residuals): `e_kt = (F - H F)_kt / (1 - H_kk)`, with
//! `H_kk = |row k of Q|^2`. No normal equations are formed.

use faer::linalg::solvers::Qr;
use faer::{Mat, MatRef};

use crate::data::check_training;
use crate::error::{ErbfError, Result};

/// Leave-one-out errors of the linear trend fitted to `points` (`N x m`) and `values`
/// (`N x T`): an `N x T` matrix `e_kt = F_kt - l^{(-k)}_t(x_k)`, where `l^{(-k)}` is the
/// least-squares linear fit without sample `k`. Cost `O(N m^2 + N m T)`.
///
/// The regression is affine-invariant, so raw or unit-scaled inputs give the same errors
/// (up to rounding); pass the scaled ones for balanced columns.
///
/// # Errors
/// As the training checks of [`RbfInterpolant::fit`](crate::RbfInterpolant::fit) (empty,
/// mismatched or non-finite data); [`ErbfError::LooUndefined`] when `N <= m + 1` or a
/// sample has leverage 1 (removing it leaves the trend undetermined).
pub fn linear_trend_loo(points: MatRef<'_, f64>, values: MatRef<'_, f64>) -> Result<Mat<f64>> {
    check_training(points, values, None)?;
    let (n, m) = points.shape();
    if n <= m + 1 {
        return Err(ErbfError::LooUndefined {
            sample: 0,
            message: format!(
                "a linear trend in {m} inputs needs more than {} samples, got {n}",
                m + 1
            ),
        });
    }
    let x = Mat::from_fn(
        n,
        m + 1,
        |i, j| if j == 0 { 1.0 } else { points[(i, j - 1)] },
    );
    let qr = Qr::new(x.as_ref());
    let q = qr.compute_thin_Q();
    let fitted = &q * (q.transpose() * values);
    let mut e = Mat::<f64>::zeros(n, values.ncols());
    for k in 0..n {
        let h: f64 = q.row(k).iter().map(|v| v * v).sum();
        let one_minus = 1.0 - h;
        if one_minus.is_nan() || one_minus <= 1e-10 {
            return Err(ErbfError::LooUndefined {
                sample: k,
                message: "the sample has leverage 1: without it the linear trend is \
                          undetermined"
                    .into(),
            });
        }
        for t in 0..values.ncols() {
            e[(k, t)] = (values[(k, t)] - fitted[(k, t)]) / one_minus;
        }
    }
    Ok(e)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use faer::linalg::solvers::SolveLstsq;

    /// The closed form equals refitting without each sample in turn.
    #[test]
    fn closed_form_matches_refits() {
        let n = 15;
        let x = Mat::from_fn(n, 2, |i, j| {
            ((i * (3 + 5 * j) + 2 * j) % n) as f64 / n as f64
        });
        let f = Mat::from_fn(n, 2, |i, t| {
            1.0 + 2.0 * x[(i, 0)] - x[(i, 1)] + (t as f64 + 1.0) * (7.0 * x[(i, 0)]).sin()
        });
        let e = linear_trend_loo(x.as_ref(), f.as_ref()).unwrap();
        for k in 0..n {
            let keep: Vec<usize> = (0..n).filter(|&i| i != k).collect();
            let xr = Mat::from_fn(
                n - 1,
                3,
                |i, j| {
                    if j == 0 { 1.0 } else { x[(keep[i], j - 1)] }
                },
            );
            let fr = Mat::from_fn(n - 1, 2, |i, t| f[(keep[i], t)]);
            let beta = Qr::new(xr.as_ref()).solve_lstsq(fr.as_ref());
            for t in 0..2 {
                let pred = beta[(0, t)] + beta[(1, t)] * x[(k, 0)] + beta[(2, t)] * x[(k, 1)];
                assert_relative_eq!(e[(k, t)], f[(k, t)] - pred, epsilon = 1e-10);
            }
        }
    }

    #[test]
    fn exact_linear_data_has_zero_loo_and_too_few_samples_fail() {
        let x = Mat::from_fn(6, 2, |i, j| ((i * (2 + j)) % 6) as f64 + 0.1 * j as f64);
        let f = Mat::from_fn(6, 1, |i, _| 3.0 - x[(i, 0)] + 0.5 * x[(i, 1)]);
        let e = linear_trend_loo(x.as_ref(), f.as_ref()).unwrap();
        assert!(e.norm_max() < 1e-10);
        let few = linear_trend_loo(x.as_ref().subrows(0, 3), f.as_ref().subrows(0, 3));
        assert!(matches!(few, Err(ErbfError::LooUndefined { .. })));
    }
}
