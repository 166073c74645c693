//! Reading parameter samples by name: the one rule every command follows.
//!
//! A sample table names its columns; the reader matches them to the parameters of a
//! [`ParameterSpace`] by name, in any order, and returns the samples as an `n x dim` matrix in
//! the space's order. The header must hold exactly the parameters and the extra columns the
//! caller asks for (an optimisation history's `objective`): a missing column and a column
//! nobody asked for are both errors that name them, so that a typo in a header never passes
//! unnoticed.

use std::path::Path;

use faer::Mat;

use crate::error::{CoreError, Result};
use crate::space::ParameterSpace;
use crate::table::{Table, TableOptions};

impl Table {
    /// Reads samples by parameter name: the columns named by the parameters of `space`, in
    /// the space's order, as an `n x dim` matrix, and the columns named in `also` (for
    /// example `objective`), in that order. The header must hold exactly these names, in any
    /// order: the one rule of every command that reads samples.
    ///
    /// # Errors
    /// [`CoreError::Columns`] naming every missing and every unexpected column;
    /// [`CoreError::Csv`] naming the file, row and column of an empty (missing) parameter
    /// value, which tables read with [`TableOptions::allow_missing`] can hold.
    pub fn samples(&self, space: &ParameterSpace, also: &[&str]) -> Result<Samples> {
        let expected: Vec<String> = space
            .names()
            .into_iter()
            .chain(also.iter().copied())
            .map(str::to_string)
            .collect();
        let missing: Vec<String> = expected
            .iter()
            .filter(|n| self.column_index(n).is_none())
            .cloned()
            .collect();
        let unexpected: Vec<String> = self
            .header
            .iter()
            .filter(|h| !expected.contains(h))
            .cloned()
            .collect();
        if !missing.is_empty() || !unexpected.is_empty() {
            return Err(CoreError::Columns {
                file: self.source.clone(),
                missing,
                unexpected,
                expected,
            });
        }
        let index: Vec<usize> = expected
            .iter()
            .filter_map(|n| self.column_index(n))
            .collect();
        let (params, others) = index.split_at(space.dim());
        for (row, &line) in self.rows.iter().zip(&self.lines) {
            if let Some(&j) = params.iter().find(|&&j| row[j].is_nan()) {
                return Err(CoreError::Csv {
                    file: self.source.clone(),
                    row: line,
                    column: j + 1,
                    message: format!("parameter `{}` is empty", self.header[j]),
                });
            }
        }
        let n = self.rows.len();
        Ok(Samples {
            points: Mat::from_fn(n, params.len(), |i, j| self.rows[i][params[j]]),
            also: others
                .iter()
                .map(|&j| self.rows.iter().map(|r| r[j]).collect())
                .collect(),
            lines: self.lines.clone(),
        })
    }
}

/// Samples read by parameter name ([`Table::samples`], [`read_samples`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Samples {
    /// `n x dim`: one sample per row, columns in the order of the parameter space.
    pub points: Mat<f64>,
    /// The columns asked for besides the parameters, in the order asked (NaN for a missing
    /// value where the table allows them).
    pub also: Vec<Vec<f64>>,
    /// The 1-based line of each sample in its file.
    pub lines: Vec<usize>,
}

/// Reads a sample table by parameter name: [`Table::read`] then [`Table::samples`].
///
/// # Errors
/// As [`Table::read`] and [`Table::samples`].
pub fn read_samples(
    path: impl AsRef<Path>,
    space: &ParameterSpace,
    also: &[&str],
    options: TableOptions,
) -> Result<Samples> {
    Table::read(path, options)?.samples(space, also)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::space::Parameter;

    fn position(err: CoreError) -> (usize, usize) {
        match err {
            CoreError::Csv { row, column, .. } => (row, column),
            other => panic!("expected a positioned CSV error, got {other}"),
        }
    }

    #[test]
    fn samples_by_name_follow_one_rule() {
        let space = ParameterSpace::new(vec![
            Parameter::new("a", 0.0, 1.0, 0.5).unwrap(),
            Parameter::new("b", 0.0, 1.0, 0.5).unwrap(),
        ])
        .unwrap();
        let options = TableOptions {
            allow_missing: true,
            allow_no_rows: false,
        };
        let t = Table::parse("objective,b,a\n3,0.2,0.1\n,0.4,0.3\n", "h.csv", options).unwrap();
        let s = t.samples(&space, &["objective"]).unwrap();
        assert_eq!(
            s.points,
            faer::Mat::from_fn(2, 2, |i, j| [[0.1, 0.2], [0.3, 0.4]][i][j])
        );
        assert_eq!(s.also[0][0].to_bits(), 3.0_f64.to_bits());
        assert!(s.also[0][1].is_nan());
        assert_eq!(s.lines, vec![2, 3]);
        // Missing and extra columns: one error naming both.
        let e = t.samples(&space, &[]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "h.csv: unexpected column `objective` (the header must name exactly these \
             columns, in any order: a, b)"
        );
        let t = Table::parse("a,c\n1,2\n", "p.csv", TableOptions::default()).unwrap();
        match t.samples(&space, &[]).unwrap_err() {
            CoreError::Columns {
                missing,
                unexpected,
                ..
            } => assert_eq!((missing, unexpected), (vec!["b".into()], vec!["c".into()])),
            e => panic!("unexpected {e}"),
        }
        // An empty parameter value is named by file, row and column.
        let t = Table::parse("a,b\n1,\n", "q.csv", options).unwrap();
        assert_eq!(position(t.samples(&space, &[]).unwrap_err()), (2, 2));
    }
}
