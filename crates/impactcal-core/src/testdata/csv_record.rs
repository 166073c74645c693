//! Test records in wide CSV with their own time column.

use std::path::Path;

use crate::error::{CoreError, Result};
use crate::histories::{Histories, TIME_STEP_TOLERANCE};
use crate::signal::{Resampling, resample_uniform};
use crate::table::{Table, TableOptions};

/// A measured record read from wide CSV (`time,<label>,...`), on a uniform time base.
///
/// A file whose time steps are uniform (every step within [`TIME_STEP_TOLERANCE`] of the
/// mean step) is taken as it is, exactly as [`Histories::parse_csv`] takes it. A file whose
/// steps vary (a logger that drops samples, a record exported at irregular times) is resampled
/// linearly onto a uniform base at its median step, and [`TestRecord::resampling`] says so.
#[derive(Debug, Clone, PartialEq)]
pub struct TestRecord {
    /// The channels on a uniform time base.
    pub histories: Histories,
    /// How the record was resampled, when its time steps were not uniform.
    pub resampling: Option<Resampling>,
}

impl TestRecord {
    /// Reads a record from a CSV file (see [`TestRecord::parse`]).
    ///
    /// # Errors
    /// [`CoreError::Io`] when unreadable, otherwise as [`TestRecord::parse`].
    pub fn read(path: impl AsRef<Path>) -> Result<TestRecord> {
        let (text, name) = crate::table::read_text(path.as_ref())?;
        TestRecord::parse(&text, &name)
    }

    /// Parses wide CSV whose first column is `time`.
    ///
    /// # Errors
    /// As [`Histories::parse_csv`] for the header and cells; [`CoreError::Csv`] naming the row
    /// where time goes backwards or repeats.
    pub fn parse(text: &str, source_name: &str) -> Result<TestRecord> {
        let table = Table::parse(text, source_name, TableOptions::default())?;
        let times: Vec<f64> = table.rows().iter().map(|r| r[0]).collect();
        let position = |k: usize, message: String| CoreError::Csv {
            file: source_name.to_string(),
            row: table.lines()[k],
            column: 1,
            message,
        };
        for k in 1..times.len() {
            if times[k].total_cmp(&times[k - 1]).is_eq() {
                return Err(position(
                    k,
                    format!("time {} repeats the previous row's", times[k]),
                ));
            }
            if times[k] < times[k - 1] {
                return Err(position(
                    k,
                    format!(
                        "time {} goes backwards (previous {})",
                        times[k],
                        times[k - 1]
                    ),
                ));
            }
        }
        let n = times.len();
        let uniform = n < 2 || {
            let mean = (times[n - 1] - times[0]) / (n - 1) as f64;
            times
                .windows(2)
                .all(|w| ((w[1] - w[0]) - mean).abs() <= TIME_STEP_TOLERANCE * mean)
        };
        if uniform {
            return Ok(TestRecord {
                histories: Histories::parse_csv(text, source_name)?,
                resampling: None,
            });
        }
        let channels: Vec<Vec<f64>> = (1..table.header().len())
            .map(|c| table.rows().iter().map(|r| r[c]).collect())
            .collect();
        let (resampled, resampling) = resample_uniform(&times, &channels)?;
        let histories = Histories::from_channels(
            table.header()[1..].to_vec(),
            resampled,
            resampling.dt,
            times[0],
            "",
        )?;
        Ok(TestRecord {
            histories,
            resampling: Some(resampling),
        })
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn row_of(text: &str) -> usize {
        match TestRecord::parse(text, "t.csv").unwrap_err() {
            CoreError::Csv { row, column, .. } => {
                assert_eq!(column, 1);
                row
            }
            e => panic!("unexpected {e}"),
        }
    }

    #[test]
    fn uniform_files_are_read_as_they_are() {
        let text = "time,a,b\n0,1,2\n0.1,2,3\n0.2,3,4\n";
        let r = TestRecord::parse(text, "t.csv").unwrap();
        assert!(r.resampling.is_none());
        assert_eq!(r.histories, Histories::parse_csv(text, "t.csv").unwrap());
    }

    #[test]
    fn non_uniform_files_are_resampled_and_say_so() {
        let text = "time,a\n0,0\n0.001,2\n0.0025,5\n0.003,6\n0.004,8\n";
        let r = TestRecord::parse(text, "t.csv").unwrap();
        let s = r.resampling.unwrap();
        assert_relative_eq!(s.dt, 0.001, max_relative = 1e-12);
        assert_eq!(s.source_samples, 5);
        assert_eq!(r.histories.samples(), 5);
        // a = 2000 t on every segment.
        for (k, v) in r.histories.channel(0).iter().enumerate() {
            assert_relative_eq!(*v, 2.0 * k as f64, epsilon = 1e-9);
        }
        assert!(s.to_string().contains("resampled"));
    }

    #[test]
    fn time_going_backwards_or_repeating_names_the_row() {
        assert_eq!(row_of("time,a\n0,1\n0.1,2\n0.05,3\n"), 4);
        assert_eq!(row_of("time,a\n0,1\n0.1,2\n0.1,3\n0.2,3\n"), 4);
        assert_eq!(row_of("time,a\n\n0,1\n0.1,2\n0.3,3\n0.2,3\n"), 6);
    }
}
