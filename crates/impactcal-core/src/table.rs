//! Reading and writing numeric CSV tables with a header row.
//!
//! Every CSV file of the project (histories, parameter samples, outputs, bounds) goes through
//! this module so that all of them report faults the same way: file, 1-based row (the header
//! is row 1) and 1-based column.

use std::io::Write;
use std::path::Path;

use faer::{Mat, MatRef};

use crate::error::{CoreError, Result};

/// A numeric table: one name per column and rows of equal length.
///
/// Built only by the reader ([`Table::read`], [`Table::parse`]) or the checked constructors
/// ([`Table::new`], [`Table::from_matrix`]), so that its invariants hold: names unique and
/// non-empty, every row as long as the header, no infinite value (NaN marks a missing
/// value), and a source line for every row.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// Column names from the header row, trimmed, unique and non-empty.
    pub(crate) header: Vec<String>,
    /// Data rows; every row has `header.len()` values.
    pub(crate) rows: Vec<Vec<f64>>,
    /// For each data row, its 1-based line number in the source (for later error messages).
    pub(crate) lines: Vec<usize>,
    /// The file (or the name given to text parsed from memory) the table came from.
    pub(crate) source: String,
}

/// What a table reader accepts beyond plain finite numbers.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TableOptions {
    /// Accept empty cells and `nan` (read as NaN), as in an optimisation history where a
    /// failed run has no objective. Infinite values are still rejected.
    pub allow_missing: bool,
    /// Accept a file that has a header but no data rows.
    pub allow_no_rows: bool,
}

impl Table {
    /// A table of the given columns and rows, as it would be written to a file: row `k`
    /// (0-based) gets line `k + 2` (the header is line 1).
    ///
    /// # Errors
    /// [`CoreError::Invalid`] for no columns, or an empty or repeated name;
    /// [`CoreError::DimensionMismatch`] for a row whose length differs from the header's;
    /// [`CoreError::NonFinite`] for an infinite value (NaN is allowed: a missing value,
    /// written as an empty cell).
    pub fn new(header: Vec<String>, rows: Vec<Vec<f64>>) -> Result<Table> {
        if header.is_empty() {
            return Err(CoreError::Invalid(
                "a table needs at least one column".into(),
            ));
        }
        for (j, name) in header.iter().enumerate() {
            if name.trim().is_empty() {
                return Err(CoreError::Invalid(format!(
                    "column {} of a table has an empty name",
                    j + 1
                )));
            }
            if header[..j].contains(name) {
                return Err(CoreError::Invalid(format!(
                    "column name `{name}` is used twice"
                )));
            }
        }
        for (i, row) in rows.iter().enumerate() {
            if row.len() != header.len() {
                return Err(CoreError::DimensionMismatch {
                    what: format!("table row {i}: number of values (one per column)"),
                    expected: header.len(),
                    found: row.len(),
                });
            }
            if let Some(j) = row.iter().position(|v| v.is_infinite()) {
                return Err(CoreError::NonFinite {
                    what: "table".into(),
                    location: format!("row {i}, column `{}`", header[j]),
                    value: row[j],
                });
            }
        }
        let lines = (2..rows.len() + 2).collect();
        Ok(Table {
            header,
            rows,
            lines,
            source: "(table)".into(),
        })
    }

    /// A table of the rows of `m` (`n x header.len()`), for example points or predictions.
    ///
    /// # Errors
    /// As [`Table::new`]; [`CoreError::DimensionMismatch`] when `m` has not one column per
    /// name.
    pub fn from_matrix(header: Vec<String>, m: MatRef<'_, f64>) -> Result<Table> {
        if header.len() != m.ncols() {
            return Err(CoreError::DimensionMismatch {
                what: "number of column names (one per matrix column)".into(),
                expected: m.ncols(),
                found: header.len(),
            });
        }
        Table::new(header, crate::points::to_rows(m))
    }

    /// Column names, in order.
    pub fn header(&self) -> &[String] {
        &self.header
    }

    /// Data rows; every row has one value per column (NaN for a missing value).
    pub fn rows(&self) -> &[Vec<f64>] {
        &self.rows
    }

    /// The 1-based line of each data row in its source.
    pub fn lines(&self) -> &[usize] {
        &self.lines
    }

    /// The file (or name) the table was read from; `(table)` for one built in memory.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Number of data rows.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether there is no data row.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The whole table as an `n x columns` matrix, one row per data row.
    pub fn to_matrix(&self) -> Mat<f64> {
        Mat::from_fn(self.rows.len(), self.header.len(), |i, j| self.rows[i][j])
    }

    /// Reads a table from a file; see [`Table::parse`] for the rules.
    ///
    /// # Errors
    /// [`CoreError::Io`] when the file cannot be read, otherwise as [`Table::parse`].
    pub fn read(path: impl AsRef<Path>, options: TableOptions) -> Result<Table> {
        let (text, name) = read_text(path.as_ref())?;
        Table::parse(&text, &name, options)
    }

    /// Parses CSV text whose first non-empty line is a header of column names.
    ///
    /// Blank lines are skipped; surrounding spaces are trimmed.
    ///
    /// # Errors
    /// [`CoreError::File`] for an empty text or (unless allowed) no data rows;
    /// [`CoreError::Csv`] naming `source_name`, row and column for an empty or duplicate
    /// column name, a row with the wrong number of fields, text that is not a number, or a
    /// non-finite value (NaN and empty cells are accepted only with `allow_missing`).
    pub fn parse(text: &str, source_name: &str, options: TableOptions) -> Result<Table> {
        let mut reader = csv_reader(text);
        let csv_error = |row: usize, column: usize, message: String| CoreError::Csv {
            file: source_name.to_string(),
            row,
            column,
            message,
        };
        let line_index = LineIndex::new(text);
        let record_line = |record: &csv::StringRecord| line_index.line_of(record);
        let mut records = reader.records();
        let header_record = loop {
            match records.next() {
                None => {
                    return Err(CoreError::File {
                        file: source_name.to_string(),
                        message: "the file is empty (expected a header row)".into(),
                    });
                }
                Some(Err(e)) => return Err(csv_read_error(source_name, &e)),
                Some(Ok(r)) if r.iter().all(str::is_empty) => continue,
                Some(Ok(r)) => break r,
            }
        };
        let header_row = record_line(&header_record);
        if let Some(separator) = foreign_separator(&header_record) {
            return Err(csv_error(
                header_row,
                1,
                format!(
                    "the header is one field containing `{separator}`: the file is separated by \
                     {}, and impactcal reads comma-separated files (export with `,` between \
                     fields and `.` as the decimal mark)",
                    separator_name(separator)
                ),
            ));
        }
        let mut header: Vec<String> = Vec::with_capacity(header_record.len());
        for (j, name) in header_record.iter().enumerate() {
            if name.is_empty() {
                return Err(csv_error(header_row, j + 1, "empty column name".into()));
            }
            if let Some(k) = header.iter().position(|h| h == name) {
                return Err(csv_error(
                    header_row,
                    j + 1,
                    format!("duplicate column name `{name}` (also column {})", k + 1),
                ));
            }
            header.push(name.to_string());
        }
        let mut rows = Vec::new();
        let mut lines = Vec::new();
        for record in records {
            let record = record.map_err(|e| csv_read_error(source_name, &e))?;
            if record.iter().all(str::is_empty) && record.len() <= 1 {
                continue;
            }
            let row = record_line(&record);
            if record.len() != header.len() {
                return Err(csv_error(
                    row,
                    record.len().min(header.len()) + 1,
                    format!(
                        "row has {} fields but the header has {}",
                        record.len(),
                        header.len()
                    ),
                ));
            }
            let mut values = Vec::with_capacity(header.len());
            for (j, cell) in record.iter().enumerate() {
                values.push(parse_cell(cell, options).map_err(|m| csv_error(row, j + 1, m))?);
            }
            rows.push(values);
            lines.push(row);
        }
        if rows.is_empty() && !options.allow_no_rows {
            return Err(CoreError::File {
                file: source_name.to_string(),
                message: "no data rows after the header".into(),
            });
        }
        Ok(Table {
            header,
            rows,
            lines,
            source: source_name.to_string(),
        })
    }

    /// Index of the column called `name`.
    pub fn column_index(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h == name)
    }

    /// Writes the table as CSV; numbers use Rust's shortest round-trip formatting, so reading
    /// the file back gives the same bits.
    ///
    /// # Errors
    /// [`CoreError::Io`] naming `name` when writing fails.
    pub fn write(&self, mut out: impl Write, name: &str) -> Result<()> {
        let io = |source| CoreError::Io {
            path: name.to_string(),
            source,
        };
        writeln!(out, "{}", self.header.join(",")).map_err(io)?;
        for row in &self.rows {
            write_row(&mut out, row).map_err(io)?;
        }
        out.flush().map_err(io)
    }
}

/// Reads a whole text file, returning its text and its path as a display name.
///
/// # Errors
/// [`CoreError::Io`] naming the path.
pub fn read_text(path: &Path) -> Result<(String, String)> {
    let name = path.display().to_string();
    match std::fs::read_to_string(path) {
        Ok(text) => Ok((text, name)),
        Err(source) => Err(CoreError::Io { path: name, source }),
    }
}

/// The CSV reader every file goes through: no implicit header (callers check it), rows of
/// any length (callers report ragged rows with a position), fields trimmed.
pub(crate) fn csv_reader(text: &str) -> csv::Reader<&[u8]> {
    csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes())
}

/// Maps byte offsets of a text to 1-based line numbers (the csv crate's own line count skips
/// blank lines, so positions are taken from byte offsets instead).
/// The csv crate reports a record's start before any blank lines it skipped, so those are
/// stepped over here.
pub(crate) struct LineIndex<'a> {
    text: &'a [u8],
    starts: Vec<usize>,
}

impl<'a> LineIndex<'a> {
    pub(crate) fn new(text: &'a str) -> Self {
        LineIndex {
            text: text.as_bytes(),
            starts: std::iter::once(0)
                .chain(text.match_indices('\n').map(|(i, _)| i + 1))
                .collect(),
        }
    }

    /// 1-based line on which `record` starts.
    pub(crate) fn line_of(&self, record: &csv::StringRecord) -> usize {
        let mut byte = record
            .position()
            .map_or(0, |p| usize::try_from(p.byte()).unwrap_or(usize::MAX));
        while matches!(self.text.get(byte), Some(b'\n' | b'\r')) {
            byte += 1;
        }
        self.starts.partition_point(|&start| start <= byte)
    }
}

/// Writes one CSV row of numbers, NaN as an empty cell.
pub(crate) fn write_row(out: &mut impl Write, row: &[f64]) -> std::io::Result<()> {
    let mut line = String::with_capacity(row.len() * 12);
    for (j, v) in row.iter().enumerate() {
        if j > 0 {
            line.push(',');
        }
        if !v.is_nan() {
            line.push_str(&v.to_string());
        }
    }
    line.push('\n');
    out.write_all(line.as_bytes())
}

/// The separator of a file exported with another delimiter than the comma (a spreadsheet's
/// semicolon, a tab or a `|`): the header is then one field that contains it.
fn foreign_separator(header: &csv::StringRecord) -> Option<char> {
    if header.len() != 1 {
        return None;
    }
    [';', '\t', '|']
        .into_iter()
        .find(|&c| header[0].contains(c))
}

fn separator_name(separator: char) -> &'static str {
    match separator {
        ';' => "semicolons",
        '\t' => "tabs",
        _ => "`|`",
    }
}

fn csv_read_error(source_name: &str, e: &csv::Error) -> CoreError {
    match e.position() {
        Some(p) => CoreError::Csv {
            file: source_name.to_string(),
            row: usize::try_from(p.line()).unwrap_or(usize::MAX),
            column: 1,
            message: e.to_string(),
        },
        None => CoreError::File {
            file: source_name.to_string(),
            message: e.to_string(),
        },
    }
}

/// Parses one cell; the error message does not include the position (the caller adds it).
pub(crate) fn parse_cell(cell: &str, options: TableOptions) -> std::result::Result<f64, String> {
    if cell.is_empty() {
        return if options.allow_missing {
            Ok(f64::NAN)
        } else {
            Err("empty cell (expected a number)".into())
        };
    }
    let value: f64 = cell
        .parse()
        .map_err(|_| format!("`{cell}` is not a number"))?;
    if value.is_nan() {
        if options.allow_missing {
            return Ok(f64::NAN);
        }
        return Err(format!("`{cell}` is not a finite number"));
    }
    if value.is_infinite() {
        return Err(format!("`{cell}` is not a finite number"));
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Table> {
        Table::parse(text, "t.csv", TableOptions::default())
    }

    fn position(err: CoreError) -> (usize, usize) {
        match err {
            CoreError::Csv { row, column, .. } => (row, column),
            other => panic!("expected a positioned CSV error, got {other}"),
        }
    }

    #[test]
    fn reads_header_and_rows() {
        let t = parse("a, b\n1,2\n\n3,4.5\n").unwrap();
        assert_eq!(t.header(), &["a", "b"]);
        assert_eq!(t.rows(), &[vec![1.0, 2.0], vec![3.0, 4.5]]);
        assert_eq!(t.lines(), &[2, 4]);
        assert_eq!(t.source(), "t.csv");
    }

    #[test]
    fn faults_are_positioned() {
        assert_eq!(position(parse("a,b\n1,2\n3,x\n").unwrap_err()), (3, 2));
        assert_eq!(position(parse("a,b\n1,2\n3\n").unwrap_err()), (3, 2));
        assert_eq!(position(parse("a,b\n1,2,3\n").unwrap_err()), (2, 3));
        assert_eq!(position(parse("a,a\n1,2\n").unwrap_err()), (1, 2));
        assert_eq!(position(parse("a,\n1,2\n").unwrap_err()), (1, 2));
        assert_eq!(position(parse("a,b\nNaN,2\n").unwrap_err()), (2, 1));
        assert_eq!(position(parse("a,b\n1,inf\n").unwrap_err()), (2, 2));
        assert_eq!(position(parse("a,b\n1,\n").unwrap_err()), (2, 2));
        assert!(matches!(parse("").unwrap_err(), CoreError::File { .. }));
        assert!(matches!(
            parse("a,b\n").unwrap_err(),
            CoreError::File { .. }
        ));
    }

    #[test]
    fn files_with_another_separator_are_named() {
        for (text, name) in [
            ("time;a.x;b.x\n0;1,5;2\n", "semicolons"),
            ("\n\ntime\ta.x\n0\t1\n", "tabs"),
            ("a|b\n1|2\n", "`|`"),
        ] {
            let err = parse(text).unwrap_err();
            let message = err.to_string();
            assert!(message.contains(name), "{message}");
            assert!(message.contains("comma-separated"), "{message}");
            let header_line = text.lines().position(|l| !l.is_empty()).unwrap() + 1;
            assert_eq!(position(err), (header_line, 1));
        }
        // One column whose name has none of them is an ordinary single-column table.
        assert_eq!(parse("a\n1\n").unwrap().header(), &["a"]);
    }

    #[test]
    fn missing_values_when_allowed() {
        let options = TableOptions {
            allow_missing: true,
            allow_no_rows: false,
        };
        let t = Table::parse("a,b\n1,\n2,nan\n", "t.csv", options).unwrap();
        assert!(t.rows()[0][1].is_nan() && t.rows()[1][1].is_nan());
        assert!(Table::parse("a,b\n1,inf\n", "t.csv", options).is_err());
    }

    #[test]
    fn write_then_read_is_lossless() {
        let t = Table::new(
            vec!["x".into(), "y".into()],
            vec![vec![0.1 + 0.2, -1e-300], vec![std::f64::consts::PI, 7.0]],
        )
        .unwrap();
        assert_eq!(t.lines(), &[2, 3]);
        let mut buf = Vec::new();
        t.write(&mut buf, "mem").unwrap();
        let back = parse(std::str::from_utf8(&buf).unwrap()).unwrap();
        assert_eq!(
            (back.header(), back.rows(), back.lines()),
            (t.header(), t.rows(), t.lines())
        );
    }

    #[test]
    fn checked_constructors_refuse_invalid_tables() {
        let h = |names: &[&str]| names.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        assert!(Table::new(vec![], vec![]).is_err());
        assert!(Table::new(h(&["a", "a"]), vec![]).is_err());
        assert!(Table::new(h(&["a", " "]), vec![]).is_err());
        assert!(matches!(
            Table::new(h(&["a", "b"]), vec![vec![1.0]]),
            Err(CoreError::DimensionMismatch {
                expected: 2,
                found: 1,
                ..
            })
        ));
        assert!(Table::new(h(&["a"]), vec![vec![f64::INFINITY]]).is_err());
        assert!(Table::new(h(&["a"]), vec![vec![f64::NAN]]).is_ok());
        let m = faer::Mat::from_fn(2, 2, |i, j| (i + 2 * j) as f64);
        let t = Table::from_matrix(h(&["p", "q"]), m.as_ref()).unwrap();
        assert_eq!(t.rows(), &[vec![0.0, 2.0], vec![1.0, 3.0]]);
        assert_eq!(t.to_matrix(), m);
        assert!(Table::from_matrix(h(&["p"]), m.as_ref()).is_err());
    }
}
