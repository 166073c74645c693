//! A dense row-major block of points.

use crate::error::{CoreError, Result};
use crate::table::Table;

/// `n` points of dimension `dim`, stored row-major: point `i` is `data[i*dim..(i+1)*dim]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Points {
    n: usize,
    dim: usize,
    data: Vec<f64>,
}

impl Points {
    /// Wraps row-major data.
    ///
    /// # Errors
    /// [`CoreError::Invalid`] when `dim` is zero; [`CoreError::DimensionMismatch`] when
    /// `data.len() != n * dim`.
    pub fn new(n: usize, dim: usize, data: Vec<f64>) -> Result<Self> {
        if dim == 0 {
            return Err(CoreError::Invalid(
                "points need at least one dimension".into(),
            ));
        }
        if n.checked_mul(dim) != Some(data.len()) {
            return Err(CoreError::DimensionMismatch {
                what: format!("data length of {n} points of dimension {dim}"),
                expected: n.saturating_mul(dim),
                found: data.len(),
            });
        }
        Ok(Points { n, dim, data })
    }

    /// Wraps data whose length the caller has made `n * dim` (with `dim > 0`).
    pub(crate) fn from_parts(n: usize, dim: usize, data: Vec<f64>) -> Self {
        debug_assert!(dim > 0 && data.len() == n * dim);
        Points { n, dim, data }
    }

    /// Points from rows of equal length.
    ///
    /// # Errors
    /// [`CoreError::Invalid`] for no rows or empty rows; [`CoreError::DimensionMismatch`]
    /// naming the first row whose length differs from the first row's.
    pub fn from_rows(rows: &[Vec<f64>]) -> Result<Self> {
        let dim = rows.first().map_or(0, Vec::len);
        if dim == 0 {
            return Err(CoreError::Invalid(
                "points need at least one row of at least one value".into(),
            ));
        }
        let mut data = Vec::with_capacity(rows.len() * dim);
        for (i, row) in rows.iter().enumerate() {
            if row.len() != dim {
                return Err(CoreError::DimensionMismatch {
                    what: format!("length of row {i}"),
                    expected: dim,
                    found: row.len(),
                });
            }
            data.extend_from_slice(row);
        }
        Points::new(rows.len(), dim, data)
    }

    /// Number of points.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Dimension of each point.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Point `i`. Panics when `i >= n()`, like slice indexing.
    pub fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.dim..(i + 1) * self.dim]
    }

    /// Point `i`, mutable. Panics when `i >= n()`.
    pub fn row_mut(&mut self, i: usize) -> &mut [f64] {
        &mut self.data[i * self.dim..(i + 1) * self.dim]
    }

    /// The points in order.
    pub fn rows(&self) -> std::slice::ChunksExact<'_, f64> {
        self.data.chunks_exact(self.dim)
    }

    /// The points in order, mutable.
    pub fn rows_mut(&mut self) -> std::slice::ChunksExactMut<'_, f64> {
        self.data.chunks_exact_mut(self.dim)
    }

    /// Coordinate `j` of every point. Panics when `j >= dim()`.
    pub fn column(&self, j: usize) -> Vec<f64> {
        self.rows().map(|r| r[j]).collect()
    }

    /// The row-major data.
    pub fn as_slice(&self) -> &[f64] {
        &self.data
    }

    /// The row-major data, by value.
    pub fn into_vec(self) -> Vec<f64> {
        self.data
    }

    /// One `Vec` per point.
    pub fn to_rows(&self) -> Vec<Vec<f64>> {
        self.rows().map(<[f64]>::to_vec).collect()
    }

    /// A [`Table`] with the given column names (for writing CSV).
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`] when `header.len() != dim()`.
    pub fn to_table(&self, header: Vec<String>) -> Result<Table> {
        if header.len() != self.dim {
            return Err(CoreError::DimensionMismatch {
                what: "number of column names".into(),
                expected: self.dim,
                found: header.len(),
            });
        }
        Ok(Table {
            header,
            rows: self.to_rows(),
            lines: (2..self.n + 2).collect(),
        })
    }
}
