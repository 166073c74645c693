//! Accuracy metrics of surrogates (Jin, Chen and Simpson's convention).
//!
//! With `y` the true values at `n` test points, `yhat` the predictions and `STD` the
//! standard deviation of `y` (population form, divisor `n`):
//!
//! - RAAE = `sum |y - yhat| / (n STD)`;
//! - RMAE = `max |y - yhat| / STD`;
//! - R^2 = `1 - sum (y - yhat)^2 / sum (y - mean y)^2`.
//!
//! For time histories the matrices are `n x T` and every (point, time) pair is pooled.

use faer::MatRef;
use serde::{Deserialize, Serialize};

/// RAAE, RMAE and R^2 of predictions against truth.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Accuracy {
    /// Relative average absolute error.
    pub raae: f64,
    /// Relative maximum absolute error.
    pub rmae: f64,
    /// Coefficient of determination.
    pub r2: f64,
}

impl Accuracy {
    /// Pooled metrics of `predicted` against `truth`, both `n x T`. The metrics are `NaN`
    /// when the truth is constant (and finite for identical non-constant inputs: 0, 0, 1).
    ///
    /// # Panics
    /// Never; mismatched shapes compare the common part only.
    pub fn new(predicted: MatRef<'_, f64>, truth: MatRef<'_, f64>) -> Self {
        let rows = predicted.nrows().min(truth.nrows());
        let cols = predicted.ncols().min(truth.ncols());
        let truth = truth.submatrix(0, 0, rows, cols);
        let std = pooled_std(truth);
        let n = (rows * cols) as f64;
        let (mut sum_abs, mut max_abs, mut sse) = (0.0, 0.0_f64, 0.0);
        for j in 0..cols {
            for i in 0..rows {
                let e = truth[(i, j)] - predicted[(i, j)];
                sum_abs += e.abs();
                max_abs = max_abs.max(e.abs());
                sse += e * e;
            }
        }
        let sst = std * std * n;
        Accuracy {
            raae: sum_abs / (n * std),
            rmae: max_abs / std,
            r2: 1.0 - sse / sst,
        }
    }

    /// Metrics of scalar predictions.
    pub fn of_slices(predicted: &[f64], truth: &[f64]) -> Self {
        let n = predicted.len().min(truth.len());
        Self::new(
            MatRef::from_column_major_slice(&predicted[..n], n, 1),
            MatRef::from_column_major_slice(&truth[..n], n, 1),
        )
    }
}

/// Population standard deviation of all entries of `m` pooled together.
pub fn pooled_std(m: MatRef<'_, f64>) -> f64 {
    let n = (m.nrows() * m.ncols()) as f64;
    if n == 0.0 {
        return 0.0;
    }
    let mean = m.col_iter().flat_map(|c| c.iter().copied()).sum::<f64>() / n;
    let var = m
        .col_iter()
        .flat_map(|c| c.iter().copied())
        .map(|v| (v - mean) * (v - mean))
        .sum::<f64>()
        / n;
    var.sqrt()
}
