//! The candidate shape matrix: one labelled row per candidate DOF, one column per shape.

use std::path::Path;

use faer::{Mat, MatRef};
use impactcal_core::CoreError;

use crate::error::{Result, SensorsError};

/// The measurement axis of a nodal DOF label `<node>.<x|y|z>`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    /// Global x.
    X,
    /// Global y.
    Y,
    /// Global z.
    Z,
}

/// Splits a label `<node>.<x|y|z>` (axis case-insensitive) into node and axis; `None` for
/// any other form.
///
/// ```
/// use impactcal_sensors::{split_label, Axis};
/// assert_eq!(split_label("1042.z"), Some(("1042", Axis::Z)));
/// assert_eq!(split_label("pelvis_acc"), None);
/// ```
pub fn split_label(label: &str) -> Option<(&str, Axis)> {
    let (node, dir) = label.rsplit_once('.')?;
    if node.is_empty() {
        return None;
    }
    let dir = match dir {
        "x" | "X" => Axis::X,
        "y" | "Y" => Axis::Y,
        "z" | "Z" => Axis::Z,
        _ => return None,
    };
    Some((node, dir))
}

/// Candidate DOFs and the shapes they observe: the `s x k` matrix `Phi` whose row `i` is
/// the value of each of the `k` target shapes at candidate DOF `i`, with one unique,
/// non-empty label per row (`<node>.<x|y|z>` for nodal DOFs).
///
/// Every value is finite. The columns need not be orthonormal: effective independence
/// depends only on the column space (see the crate docs).
#[derive(Debug, Clone)]
pub struct CandidateShapes {
    labels: Vec<String>,
    shapes: Mat<f64>,
}

impl CandidateShapes {
    /// Builds candidates from labels and an `s x k` matrix.
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`] when `labels.len() != shapes.nrows()`;
    /// [`CoreError::Invalid`] for no rows, no columns, or an empty or repeated label;
    /// [`CoreError::NonFinite`] naming the candidate and shape of a NaN or infinite value.
    pub fn new(labels: Vec<String>, shapes: MatRef<'_, f64>) -> Result<Self> {
        if labels.len() != shapes.nrows() {
            return Err(CoreError::DimensionMismatch {
                what: "candidate labels (one per shape-matrix row)".into(),
                expected: shapes.nrows(),
                found: labels.len(),
            }
            .into());
        }
        if shapes.nrows() == 0 || shapes.ncols() == 0 {
            return Err(CoreError::Invalid(format!(
                "the shape matrix is empty ({} x {})",
                shapes.nrows(),
                shapes.ncols()
            ))
            .into());
        }
        check_labels(&labels)?;
        for i in 0..shapes.nrows() {
            for j in 0..shapes.ncols() {
                let v = shapes[(i, j)];
                if !v.is_finite() {
                    return Err(CoreError::NonFinite {
                        what: "shape matrix".into(),
                        location: format!("candidate `{}`, shape {}", labels[i], j + 1),
                        value: v,
                    }
                    .into());
                }
            }
        }
        Ok(CandidateShapes {
            labels,
            shapes: shapes.to_owned(),
        })
    }

    /// Builds candidates from one row of `k` shape values per label.
    ///
    /// # Errors
    /// As [`CandidateShapes::new`], plus [`CoreError::DimensionMismatch`] for rows of
    /// unequal length.
    pub fn from_rows(labels: Vec<String>, rows: &[Vec<f64>]) -> Result<Self> {
        let k = rows.first().map_or(0, Vec::len);
        if let Some((i, r)) = rows.iter().enumerate().find(|(_, r)| r.len() != k) {
            return Err(CoreError::DimensionMismatch {
                what: format!("shape values in row {}", i + 1),
                expected: k,
                found: r.len(),
            }
            .into());
        }
        let m = Mat::from_fn(rows.len(), k, |i, j| rows[i][j]);
        CandidateShapes::new(labels, m.as_ref())
    }

    /// Reads a shape-matrix CSV file; see [`CandidateShapes::parse_csv`].
    ///
    /// # Errors
    /// [`CoreError::Io`] when the file cannot be read, otherwise as
    /// [`CandidateShapes::parse_csv`].
    pub fn read_csv(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| CoreError::Io {
            path: path.display().to_string(),
            source,
        })?;
        CandidateShapes::parse_csv(&text, &path.display().to_string())
    }

    /// Parses a shape matrix in CSV: a header `label,shape1,shape2,...` (the names after the
    /// first are free), then one row per candidate: its label and `k` finite numbers.
    /// Fields are trimmed; blank lines are skipped; quoting is not supported.
    ///
    /// # Errors
    /// [`CoreError::File`] for an empty text or no data rows; [`CoreError::Csv`] naming
    /// `source_name`, the 1-based row (the header is row 1) and column for a header with
    /// fewer than two columns, a row of the wrong length, an empty or repeated label, or a
    /// value that is not a finite number.
    pub fn parse_csv(text: &str, source_name: &str) -> Result<Self> {
        let csv = |row: usize, column: usize, message: String| -> SensorsError {
            CoreError::Csv {
                file: source_name.to_string(),
                row,
                column,
                message,
            }
            .into()
        };
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty());
        let Some((header_row, header)) = lines.next() else {
            return Err(CoreError::File {
                file: source_name.to_string(),
                message: "the file is empty (expected a header `label,shape1,...`)".into(),
            }
            .into());
        };
        let columns = header.split(',').count();
        if columns < 2 {
            return Err(csv(
                header_row,
                1,
                "the header needs a label column and at least one shape column".into(),
            ));
        }
        let k = columns - 1;
        let mut labels: Vec<String> = Vec::new();
        let mut seen = std::collections::HashMap::new();
        let mut values: Vec<f64> = Vec::new();
        for (row, line) in lines {
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if fields.len() != columns {
                return Err(csv(
                    row,
                    fields.len().min(columns) + 1,
                    format!(
                        "row has {} fields but the header has {columns}",
                        fields.len()
                    ),
                ));
            }
            let label = fields[0];
            if label.is_empty() {
                return Err(csv(row, 1, "empty label".into()));
            }
            if let Some(first) = seen.insert(label.to_string(), row) {
                return Err(csv(
                    row,
                    1,
                    format!("label `{label}` repeats the label of row {first}"),
                ));
            }
            for (j, cell) in fields[1..].iter().enumerate() {
                let v: f64 = cell
                    .parse()
                    .map_err(|_| csv(row, j + 2, format!("`{cell}` is not a number")))?;
                if !v.is_finite() {
                    return Err(csv(row, j + 2, format!("`{cell}` is not a finite number")));
                }
                values.push(v);
            }
            labels.push(label.to_string());
        }
        if labels.is_empty() {
            return Err(CoreError::File {
                file: source_name.to_string(),
                message: "no candidate rows after the header".into(),
            }
            .into());
        }
        let m = Mat::from_fn(labels.len(), k, |i, j| values[i * k + j]);
        CandidateShapes::new(labels, m.as_ref())
    }

    /// Number of candidate DOFs `s` (rows).
    pub fn candidates(&self) -> usize {
        self.labels.len()
    }

    /// Number of shapes `k` (columns).
    pub fn shapes_count(&self) -> usize {
        self.shapes.ncols()
    }

    /// The candidate labels, one per row.
    pub fn labels(&self) -> &[String] {
        &self.labels
    }

    /// The `s x k` shape matrix.
    pub fn shapes(&self) -> MatRef<'_, f64> {
        self.shapes.as_ref()
    }

    /// Index of the candidate labelled `label`.
    pub fn index_of(&self, label: &str) -> Option<usize> {
        self.labels.iter().position(|l| l == label)
    }
}

fn check_labels(labels: &[String]) -> Result<()> {
    let mut seen = std::collections::HashMap::with_capacity(labels.len());
    for (i, l) in labels.iter().enumerate() {
        if l.trim().is_empty() {
            return Err(
                CoreError::Invalid(format!("candidate {} has an empty label", i + 1)).into(),
            );
        }
        if let Some(j) = seen.insert(l.as_str(), i) {
            return Err(CoreError::Invalid(format!(
                "candidate label `{l}` appears twice (rows {} and {})",
                j + 1,
                i + 1
            ))
            .into());
        }
    }
    Ok(())
}
