//! Input checks shared by both surrogates, and the serialised form of a matrix.

use faer::{Mat, MatRef};
use impactcal_core::check_finite_mat;
use serde::{Deserialize, Serialize};

use crate::error::{ErbfError, Result, no_samples};
use impactcal_core::error::dimension_mismatch;

/// A dense matrix in serialisable form: its shape and its entries in column-major order
/// (entry `(i, j)` at `data[i + j * nrows]`). faer 0.24 has no serde support, so fitted
/// models store their matrices this way; it is the private form of a saved model, not part
/// of the API (matrices are faer's everywhere else).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct StoredMat {
    /// Number of rows.
    nrows: usize,
    /// Number of columns.
    ncols: usize,
    /// `nrows * ncols` entries, column-major.
    data: Vec<f64>,
}

impl StoredMat {
    /// Copies a matrix.
    pub(crate) fn from_mat(m: MatRef<'_, f64>) -> Self {
        let mut data = Vec::with_capacity(m.nrows() * m.ncols());
        for j in 0..m.ncols() {
            data.extend(m.col(j).iter().copied());
        }
        StoredMat {
            nrows: m.nrows(),
            ncols: m.ncols(),
            data,
        }
    }

    /// The matrix, after checking that the data length matches the shape.
    ///
    /// # Errors
    /// [`ErbfError::InvalidModel`] when `data.len() != nrows * ncols`.
    pub(crate) fn to_mat(&self, what: &str) -> Result<Mat<f64>> {
        if self.nrows.checked_mul(self.ncols) != Some(self.data.len()) {
            return Err(ErbfError::InvalidModel(format!(
                "{what}: {} entries do not fill a {} x {} matrix",
                self.data.len(),
                self.nrows,
                self.ncols
            )));
        }
        Ok(MatRef::from_column_major_slice(&self.data, self.nrows, self.ncols).to_owned())
    }
}

/// Builds an `n x d` matrix from rows (the convenience form of the `fit_rows`
/// constructors).
///
/// # Errors
/// [`CoreError::Empty`](impactcal_core::CoreError::Empty) for no rows;
/// [`CoreError::DimensionMismatch`](impactcal_core::CoreError::DimensionMismatch) for a
/// ragged row.
pub(crate) fn mat_from_rows(rows: &[Vec<f64>], what: &str) -> Result<Mat<f64>> {
    if rows.is_empty() {
        return Err(no_samples());
    }
    Ok(impactcal_core::points::from_rows(rows, what)?)
}

/// Checks the training set: at least one sample, points `N x d` with `d >= 1` (or exactly
/// `expected_dim` when given), values `N x T` with `T >= 1`, all finite.
pub(crate) fn check_training(
    points: MatRef<'_, f64>,
    values: MatRef<'_, f64>,
    expected_dim: Option<usize>,
) -> Result<()> {
    check_training_points(points, values, expected_dim)?;
    check_finite_mat("training values", values)?;
    Ok(())
}

/// [`check_training`] without the pass over the values for finiteness, for callers that
/// check them on their own first pass (the shape basis).
pub(crate) fn check_training_points(
    points: MatRef<'_, f64>,
    values: MatRef<'_, f64>,
    expected_dim: Option<usize>,
) -> Result<()> {
    if points.nrows() == 0 {
        return Err(no_samples());
    }
    if let Some(d) = expected_dim
        && points.ncols() != d
    {
        return Err(dimension_mismatch(
            "training points: number of columns (parameters)",
            d,
            points.ncols(),
        ));
    }
    if points.ncols() == 0 {
        return Err(dimension_mismatch(
            "training points: number of columns (parameters), at least",
            1,
            0,
        ));
    }
    if values.nrows() != points.nrows() {
        return Err(dimension_mismatch(
            "training values: number of rows (one per sample)",
            points.nrows(),
            values.nrows(),
        ));
    }
    if values.ncols() == 0 {
        return Err(dimension_mismatch(
            "training values: number of columns (outputs), at least",
            1,
            0,
        ));
    }
    check_finite_mat("training points", points)?;
    Ok(())
}

/// Checks query points: `d` columns, all finite.
pub(crate) fn check_queries(points: MatRef<'_, f64>, d: usize) -> Result<()> {
    if points.ncols() != d {
        return Err(dimension_mismatch(
            "query points: number of columns (parameters)",
            d,
            points.ncols(),
        ));
    }
    Ok(check_finite_mat("query points", points)?)
}

/// Returns the first pair `(i, j)`, `i < j`, of rows closer than `tol` (Euclidean), with
/// their distance. `O(N^2 d)`.
pub(crate) fn find_duplicate(points: MatRef<'_, f64>, tol: f64) -> Option<(usize, usize, f64)> {
    let n = points.nrows();
    for j in 1..n {
        for i in 0..j {
            let d2: f64 = (0..points.ncols())
                .map(|c| {
                    let t = points[(i, c)] - points[(j, c)];
                    t * t
                })
                .sum();
            let dist = d2.sqrt();
            if dist <= tol {
                return Some((i, j, dist));
            }
        }
    }
    None
}

/// Errors with [`ErbfError::DuplicateSamples`] when two rows are closer than `tol`.
pub(crate) fn reject_duplicates(points: MatRef<'_, f64>, tol: f64) -> Result<()> {
    match find_duplicate(points, tol) {
        None => Ok(()),
        Some((first, second, distance)) => Err(ErbfError::DuplicateSamples {
            first,
            second,
            distance,
            tolerance: tol,
        }),
    }
}

/// Stacks per-sample rows of `t` values (as computed in parallel, each possibly failed) into
/// an `n x t` matrix, returning the error of the lowest sample that failed.
pub(crate) fn collect_rows(rows: Vec<Result<Vec<f64>>>, t: usize) -> Result<Mat<f64>> {
    let mut e = Mat::<f64>::zeros(rows.len(), t);
    for (k, row) in rows.into_iter().enumerate() {
        for (c, v) in row?.into_iter().enumerate() {
            e[(k, c)] = v;
        }
    }
    Ok(e)
}

/// A copy of `m` without row `k`.
pub(crate) fn without_row(m: MatRef<'_, f64>, k: usize) -> Mat<f64> {
    Mat::from_fn(m.nrows() - 1, m.ncols(), |i, j| {
        m[(if i < k { i } else { i + 1 }, j)]
    })
}

/// A copy of `m` with the rows of `extra` appended.
pub(crate) fn stack_rows(m: MatRef<'_, f64>, extra: MatRef<'_, f64>) -> Mat<f64> {
    let n = m.nrows();
    Mat::from_fn(n + extra.nrows(), m.ncols(), |i, j| {
        if i < n { m[(i, j)] } else { extra[(i - n, j)] }
    })
}
