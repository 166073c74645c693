//! Point sets as faer matrices, the one form of the workspace: a set of `n` points of
//! dimension `d` is an `n x d` [`Mat`] (or a [`MatRef`] view), one point per row, columns in
//! the order of the parameters. A single point is a slice `&[f64]`.
//!
//! Samplers return matrices, [`ParameterSpace`](crate::ParameterSpace) maps whole matrices
//! to and from the unit cube, and the method crates take views. This module holds the
//! conversions to and from rows of `Vec<f64>`, for callers who build points by hand.
//!
//! ```
//! use impactcal_core::points;
//!
//! let x = points::from_rows(&[vec![1.0, 2.0], vec![3.0, 4.0]], "points")?;
//! assert_eq!((x.nrows(), x.ncols()), (2, 2));
//! assert_eq!(points::row(x.as_ref(), 1), vec![3.0, 4.0]);
//! assert_eq!(points::to_rows(x.as_ref()), vec![vec![1.0, 2.0], vec![3.0, 4.0]]);
//! assert!(points::from_rows(&[vec![1.0, 2.0], vec![3.0]], "points").is_err());
//! # Ok::<(), impactcal_core::CoreError>(())
//! ```

use std::borrow::Cow;

use faer::{Mat, MatRef};

use crate::error::{CoreError, Result};

/// An `n x d` matrix from rows of equal length `d` (the length of the first row). No rows
/// give a `0 x 0` matrix.
///
/// # Errors
/// [`CoreError::DimensionMismatch`] naming `what` and the first row whose length differs
/// from the first row's.
pub fn from_rows(rows: &[Vec<f64>], what: &str) -> Result<Mat<f64>> {
    let d = rows.first().map_or(0, Vec::len);
    if let Some((i, r)) = rows.iter().enumerate().find(|(_, r)| r.len() != d) {
        return Err(CoreError::DimensionMismatch {
            what: format!("{what}: length of row {i}"),
            expected: d,
            found: r.len(),
        });
    }
    Ok(Mat::from_fn(rows.len(), d, |i, j| rows[i][j]))
}

/// An `n x d` matrix from `n * d` values stored point after point (row-major).
///
/// # Errors
/// [`CoreError::DimensionMismatch`] when `data.len() != n * d`.
pub fn from_row_major(n: usize, d: usize, data: &[f64]) -> Result<Mat<f64>> {
    if n.checked_mul(d) != Some(data.len()) {
        return Err(CoreError::DimensionMismatch {
            what: format!("data length of {n} points of dimension {d}"),
            expected: n.saturating_mul(d),
            found: data.len(),
        });
    }
    Ok(Mat::from_fn(n, d, |i, j| data[i * d + j]))
}

/// Point `i` (row `i`) as a vector. Panics when `i >= m.nrows()`, like slice indexing.
pub fn row(m: MatRef<'_, f64>, i: usize) -> Vec<f64> {
    m.row(i).iter().copied().collect()
}

/// Coordinate `j` of every point (column `j`). Panics when `j >= m.ncols()`.
pub fn column(m: MatRef<'_, f64>, j: usize) -> Vec<f64> {
    m.col(j).iter().copied().collect()
}

/// One vector per point.
pub fn to_rows(m: MatRef<'_, f64>) -> Vec<Vec<f64>> {
    (0..m.nrows()).map(|i| row(m, i)).collect()
}

/// The entries point after point (row-major).
pub fn to_row_major(m: MatRef<'_, f64>) -> Vec<f64> {
    (0..m.nrows())
        .flat_map(|i| (0..m.ncols()).map(move |j| m[(i, j)]))
        .collect()
}

/// A borrowed set of points, one per row: a matrix view (the workspace's form) or, for
/// convenience, a slice of rows, whose lengths may differ (each point is then checked on
/// its own). Functions that take `impl Into<PointRows>` accept `MatRef`, `&Mat`,
/// `&[Vec<f64>]` and `&Vec<Vec<f64>>`.
#[derive(Debug, Clone, Copy)]
pub enum PointRows<'a> {
    /// An `n x d` matrix, one point per row.
    Matrix(MatRef<'a, f64>),
    /// One vector per point.
    Rows(&'a [Vec<f64>]),
}

impl<'a> PointRows<'a> {
    /// Number of points.
    pub fn len(&self) -> usize {
        match self {
            PointRows::Matrix(m) => m.nrows(),
            PointRows::Rows(r) => r.len(),
        }
    }

    /// Whether there is no point.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Point `i`: borrowed from a slice of rows, copied out of a matrix. Panics when
    /// `i >= len()`.
    pub fn point(&self, i: usize) -> Cow<'a, [f64]> {
        match self {
            PointRows::Matrix(m) => Cow::Owned(row(*m, i)),
            PointRows::Rows(r) => Cow::Borrowed(r[i].as_slice()),
        }
    }
}

impl<'a> From<MatRef<'a, f64>> for PointRows<'a> {
    fn from(m: MatRef<'a, f64>) -> Self {
        PointRows::Matrix(m)
    }
}

impl<'a> From<&'a Mat<f64>> for PointRows<'a> {
    fn from(m: &'a Mat<f64>) -> Self {
        PointRows::Matrix(m.as_ref())
    }
}

impl<'a> From<&'a [Vec<f64>]> for PointRows<'a> {
    fn from(r: &'a [Vec<f64>]) -> Self {
        PointRows::Rows(r)
    }
}

impl<'a> From<&'a Vec<Vec<f64>>> for PointRows<'a> {
    fn from(r: &'a Vec<Vec<f64>>) -> Self {
        PointRows::Rows(r.as_slice())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversions_round_trip() {
        let rows = vec![vec![1.0, 2.0, 3.0], vec![4.0, 5.0, 6.0]];
        let m = from_rows(&rows, "p").unwrap();
        assert_eq!(to_rows(m.as_ref()), rows);
        assert_eq!(to_row_major(m.as_ref()), vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert_eq!(from_row_major(2, 3, &to_row_major(m.as_ref())).unwrap(), m);
        assert_eq!(column(m.as_ref(), 2), vec![3.0, 6.0]);
        assert!(matches!(
            from_row_major(2, 2, &[1.0]),
            Err(CoreError::DimensionMismatch { expected: 4, .. })
        ));
        let empty = from_rows(&[], "p").unwrap();
        assert_eq!((empty.nrows(), empty.ncols()), (0, 0));
        let pr = PointRows::from(&rows);
        assert_eq!(pr.len(), 2);
        assert_eq!(&*pr.point(1), &[4.0, 5.0, 6.0]);
        assert_eq!(&*PointRows::from(&m).point(0), &[1.0, 2.0, 3.0]);
    }
}
