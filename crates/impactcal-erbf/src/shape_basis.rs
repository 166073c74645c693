//! The impact-shape basis of an ensemble of histories: surrogates of shape coordinates
//! instead of every sample of a history.
//!
//! With training outputs `F` (`N x T`: one history of `T` samples per run) and their mean
//! history `f_bar` (the column means), the deviations `F - 1 f_bar^T` are decomposed by the
//! thin SVD of [`impactcal_shapes::ImpactShapes`] into `sum_i sigma_i u_i g_i^T`: the time
//! functions `g_i` (orthonormal, length `T`) are the ensemble's impact shapes over time, and
//! `a_ki = sigma_i u_ki` is run `k`'s coordinate on shape `i`. Keeping `k` shapes,
//!
//! ```text
//! F ~ 1 f_bar^T + A_k G_k^T,   ||F - 1 f_bar^T - A_k G_k^T||_F = sqrt(sum_{i>k} sigma_i^2),
//! ```
//!
//! and a surrogate of the `k` coordinates `a(x)` gives whole histories as
//! `f(x) = f_bar + G_k a(x)`, rebuilt only when asked for. Fitting `k` outputs instead of
//! `T` and rebuilding with a `Q x k x T` product instead of a `Q x N x T` one is what makes
//! the basis fast; the price is the truncation error, which [`ShapeBasis::truncation_error`]
//! reports and [`choose_count`] keeps below the surrogate's own leave-one-out error.

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatRef};
use impactcal_shapes::{ImpactShapes, ShapeOptions, SvdMethod, Truncation};

use crate::buffer;
use crate::error::Result;

/// How far below the surrogate's own leave-one-out error the truncation error must stay
/// when the shape count is chosen automatically: `0.25`, so that the truncation adds at
/// most `sqrt(1 + 0.25^2) - 1 = 3 %` to the error of the history (the two are orthogonal).
pub const TRUNCATION_RATIO: f64 = 0.25;

/// The mean history and impact shapes (time functions) of an ensemble of histories.
#[derive(Debug, Clone)]
pub struct ShapeBasis {
    /// Mean history `f_bar` (length `T`).
    mean: Vec<f64>,
    /// `[G | f_bar]` (`T x (k + 1)`): the time functions kept (orthonormal columns) and the
    /// mean history last, so that a rebuild is one product.
    functions: Mat<f64>,
    /// Singular values of the deviations, all of them up to the numerical rank.
    sigma: Vec<f64>,
    /// `||F - 1 f_bar^T||_F^2`.
    total: f64,
}

impl ShapeBasis {
    /// Decomposes the training outputs `values` (`N x T`) and returns the basis with every
    /// shape up to the numerical rank `r` of the deviations (at least one), and the
    /// training coordinates `A` (`N x r`, `A_ki = sigma_i u_ki`).
    ///
    /// Cost: one thin SVD of an `N x T` matrix, `O(N^2 T)`.
    ///
    /// # Errors
    /// [`CoreError::NonFinite`](impactcal_core::CoreError::NonFinite) or
    /// [`CoreError::Empty`](impactcal_core::CoreError::Empty) (under
    /// [`ErbfError::Shapes`](crate::ErbfError::Shapes)) for bad data; a failed SVD.
    pub fn new(values: MatRef<'_, f64>) -> Result<(Self, Mat<f64>)> {
        let (n, t) = values.shape();
        let mean: Vec<f64> = (0..t)
            .map(|c| values.col(c).iter().sum::<f64>() / n.max(1) as f64)
            .collect();
        let mut centred = buffer::copy(values);
        for (col, &m) in centred.col_iter_mut().zip(&mean) {
            col.iter_mut().for_each(|v| *v -= m);
        }
        let total = centred.squared_norm_l2();
        let options = ShapeOptions {
            truncation: Truncation::All,
            method: SvdMethod::Full,
        };
        let shapes = ImpactShapes::from_matrix(centred.as_ref(), &options)?;
        let sigma = shapes.singular_values().to_vec();
        let u = shapes.shapes();
        let coords = Mat::from_fn(n, sigma.len(), |k, i| sigma[i] * u[(k, i)]);
        let g = shapes.time_functions();
        let r = g.ncols();
        let functions = Mat::from_fn(t, r + 1, |i, j| if j < r { g[(i, j)] } else { mean[i] });
        let basis = ShapeBasis {
            mean,
            functions,
            sigma,
            total,
        };
        Ok((basis, coords))
    }

    /// Number of shapes kept `k`.
    pub fn len(&self) -> usize {
        self.functions.ncols() - 1
    }

    /// Whether no shape is kept (never true for a basis from [`new`](Self::new)).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Number of samples `T` of a history.
    pub fn samples(&self) -> usize {
        self.mean.len()
    }

    /// The singular values of the deviations from the mean, all of them up to the
    /// numerical rank (also those not kept), non-increasing.
    pub fn singular_values(&self) -> &[f64] {
        &self.sigma
    }

    /// The mean history `f_bar`.
    pub fn mean(&self) -> &[f64] {
        &self.mean
    }

    /// The time functions kept, `T x k`, orthonormal columns.
    pub fn functions(&self) -> MatRef<'_, f64> {
        self.functions.as_ref().subcols(0, self.len())
    }

    /// Relative truncation error of `k` shapes on the training data,
    /// `||F - 1 f_bar^T - A_k G_k^T||_F / ||F - 1 f_bar^T||_F
    /// = sqrt(sum_{i>k} sigma_i^2 / sum_i sigma_i^2)` (0 when the runs are all equal).
    pub fn truncation_error(&self, k: usize) -> f64 {
        if self.total <= 0.0 {
            return 0.0;
        }
        // Summing the discarded singular values (all of them are kept up to the numerical
        // rank) avoids the cancellation of `total - kept`.
        let tail: f64 = self.sigma.iter().skip(k).map(|s| s * s).sum();
        (tail / self.total).sqrt()
    }

    /// Keeps the first `k` shapes (`k` is capped at the number kept; at least one).
    pub fn truncate(&mut self, k: usize) {
        let k = k.clamp(1, self.len().max(1));
        let len = self.len();
        if k < len {
            let f = &self.functions;
            self.functions =
                Mat::from_fn(f.nrows(), k + 1, |i, j| f[(i, if j < k { j } else { len })]);
        }
    }

    /// Histories from coordinates: `f_bar + G a` for every row `a` of `coords`
    /// (`Q x k`): a `Q x T` matrix, `O(Q k T)`.
    pub fn rebuild(&self, coords: MatRef<'_, f64>) -> Mat<f64> {
        let q = coords.nrows();
        let k = coords.ncols().min(self.len());
        // [a | 1] [G_k | f_bar]^T: the mean rides along as one more coordinate.
        let mut ext = Mat::<f64>::zeros(q, k + 1);
        ext.as_mut()
            .subcols_mut(0, k)
            .copy_from(coords.subcols(0, k));
        ext.col_mut(k).iter_mut().for_each(|v| *v = 1.0);
        let len = self.len();
        let fewer = (k < len).then(|| {
            Mat::from_fn(self.samples(), k + 1, |i, j| {
                self.functions[(i, if j < k { j } else { len })]
            })
        });
        let basis = fewer
            .as_ref()
            .map_or(self.functions.as_ref(), |b| b.as_ref());
        let mut out = buffer::zeros(q, self.samples());
        matmul(
            out.as_mut(),
            Accum::Replace,
            ext.as_ref(),
            basis.transpose(),
            1.0,
            faer::get_global_parallelism(),
        );
        out
    }

    /// The part of the training outputs that `k` shapes miss, `F - 1 f_bar^T - A_k G_k^T`
    /// (`N x T`), for training coordinates `coords` (`N x r`, `r >= k`).
    pub fn residual(&self, values: MatRef<'_, f64>, coords: MatRef<'_, f64>) -> Mat<f64> {
        let rebuilt = self.rebuild(coords);
        Mat::from_fn(values.nrows(), values.ncols(), |i, j| {
            values[(i, j)] - rebuilt[(i, j)]
        })
    }
}

/// The fewest shapes `k` whose truncation error stays below [`TRUNCATION_RATIO`] times the
/// surrogate's own leave-one-out error over those shapes:
///
/// ```text
/// sum_{i>k} sigma_i^2 <= TRUNCATION_RATIO^2 sum_{i<=k} l_i,
/// ```
///
/// where `l_i` is the sum of squared leave-one-out errors of coordinate `i` and
/// `sigma_i^2` its energy. All `r = sigma.len()` shapes when no smaller count qualifies
/// (data the surrogate predicts almost exactly); `loo_energy` shorter than `sigma` counts
/// the missing entries as zero.
pub fn choose_count(sigma: &[f64], loo_energy: &[f64]) -> usize {
    let r = sigma.len();
    let mut loo = 0.0;
    for k in 1..=r {
        let tail: f64 = sigma[k..].iter().map(|s| s * s).sum();
        loo += loo_energy.get(k - 1).copied().unwrap_or(0.0);
        if tail <= TRUNCATION_RATIO * TRUNCATION_RATIO * loo {
            return k;
        }
    }
    r.max(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn rank_two_ensemble_is_rebuilt_exactly_from_two_shapes() {
        // F_kt = 1 + x_k sin(t) + x_k^2 cos(t): mean plus a rank-2 deviation.
        let f = Mat::from_fn(12, 200, |k, t| {
            let x = k as f64 / 11.0;
            let t = t as f64 * 0.05;
            1.0 + x * t.sin() + x * x * t.cos()
        });
        let (mut basis, coords) = ShapeBasis::new(f.as_ref()).unwrap();
        assert_eq!(coords.ncols(), basis.len());
        assert!(basis.truncation_error(2) < 1e-12);
        assert!(basis.truncation_error(1) > 1e-3);
        basis.truncate(2);
        let back = basis.rebuild(coords.as_ref());
        for i in 0..12 {
            for j in 0..200 {
                assert_relative_eq!(back[(i, j)], f[(i, j)], epsilon = 1e-12);
            }
        }
        // The residual of one shape has exactly the norm the truncation error reports.
        let mut one = basis.clone();
        one.truncate(1);
        let r = one.residual(f.as_ref(), coords.as_ref());
        let mut centred = f.clone();
        for j in 0..200 {
            let m = one.mean()[j];
            centred.col_mut(j).iter_mut().for_each(|v| *v -= m);
        }
        assert_relative_eq!(
            r.norm_l2() / centred.norm_l2(),
            one.truncation_error(1),
            max_relative = 1e-10
        );
    }

    #[test]
    fn count_keeps_truncation_below_the_loo_error() {
        let sigma = [10.0, 3.0, 1.0, 0.1, 0.01];
        // Coordinates predicted to 1 % of their size: truncation must fall below 0.25 of
        // that.
        let loo: Vec<f64> = sigma.iter().map(|s| (0.01 * s) * (0.01 * s)).collect();
        let k = choose_count(&sigma, &loo);
        let tail = |k: usize| sigma[k..].iter().map(|s| s * s).sum::<f64>();
        let own = |k: usize| loo[..k].iter().sum::<f64>();
        assert!(tail(k) <= 0.0625 * own(k));
        assert!(tail(k - 1) > 0.0625 * own(k - 1));
        assert_eq!(k, 4);
        // Coordinates the surrogate cannot predict at all: few shapes suffice.
        let bad: Vec<f64> = sigma.iter().map(|s| s * s).collect();
        assert_eq!(choose_count(&sigma, &bad), 2);
        // Exact predictions: every shape.
        assert_eq!(choose_count(&sigma, &[0.0; 5]), 5);
    }
}
