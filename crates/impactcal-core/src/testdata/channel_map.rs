//! Channel maps: which model channel each test channel is compared with.

use std::path::Path;

use crate::error::{CoreError, Result};
use crate::table::{LineIndex, csv_reader};

/// One line of a channel map: the test channel `test_label` is compared with the model channel
/// `model_label` multiplied by `gain` (the gain converts the model's unit into the test's).
#[derive(Debug, Clone, PartialEq)]
pub struct MapEntry {
    /// Label of the test (measured) channel.
    pub test_label: String,
    /// Label of the model channel.
    pub model_label: String,
    /// Factor applied to the model channel before comparing (1 when the map omits it).
    pub gain: f64,
    /// 1-based line of the map file.
    pub line: usize,
}

/// A channel map read from CSV lines `test_label,model_label[,gain]`, optionally under a
/// header line `test_label,model_label[,gain]`. Blank lines are skipped.
///
/// A test label may appear once; a model label may serve several test channels (two sensors
/// compared with one model node).
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelMap {
    /// The file the map came from (for messages).
    pub file: String,
    /// The entries in file order.
    pub entries: Vec<MapEntry>,
}

impl ChannelMap {
    /// Reads a map file (see [`ChannelMap::parse`]).
    ///
    /// # Errors
    /// [`CoreError::Io`] when unreadable, otherwise as [`ChannelMap::parse`].
    pub fn read(path: impl AsRef<Path>) -> Result<ChannelMap> {
        let (text, name) = crate::table::read_text(path.as_ref())?;
        ChannelMap::parse(&text, &name)
    }

    /// Parses map text.
    ///
    /// # Errors
    /// [`CoreError::Csv`] naming line and column for a line with fewer than two or more than
    /// three fields, an empty label, a gain that is not a finite non-zero number, or a test
    /// label that appears twice; [`CoreError::File`] for a map without entries.
    pub fn parse(text: &str, source_name: &str) -> Result<ChannelMap> {
        let lines = LineIndex::new(text);
        let err = |line: usize, column: usize, message: String| CoreError::Csv {
            file: source_name.to_string(),
            row: line,
            column,
            message,
        };
        let mut entries: Vec<MapEntry> = Vec::new();
        for record in csv_reader(text).records() {
            let record = record.map_err(|e| CoreError::File {
                file: source_name.to_string(),
                message: e.to_string(),
            })?;
            if record.iter().all(str::is_empty) {
                continue;
            }
            let line = lines.line_of(&record);
            if entries.is_empty() && record.get(0) == Some("test_label") {
                continue;
            }
            if !(2..=3).contains(&record.len()) {
                return Err(err(
                    line,
                    record.len().min(3) + 1,
                    format!(
                        "expected `test_label,model_label[,gain]`, found {} fields",
                        record.len()
                    ),
                ));
            }
            let (test_label, model_label) = (&record[0], &record[1]);
            for (column, label) in [(1, test_label), (2, model_label)] {
                if label.is_empty() {
                    return Err(err(line, column, "empty label".into()));
                }
            }
            let gain = match record.get(2) {
                None | Some("") => 1.0,
                Some(cell) => match cell.parse::<f64>() {
                    Ok(g) if g.is_finite() && g != 0.0 => g,
                    _ => {
                        return Err(err(
                            line,
                            3,
                            format!("gain `{cell}` is not a finite non-zero number"),
                        ));
                    }
                },
            };
            if let Some(first) = entries.iter().find(|e| e.test_label == test_label) {
                return Err(err(
                    line,
                    1,
                    format!(
                        "test label `{test_label}` is already mapped on line {}",
                        first.line
                    ),
                ));
            }
            entries.push(MapEntry {
                test_label: test_label.to_string(),
                model_label: model_label.to_string(),
                gain,
                line,
            });
        }
        if entries.is_empty() {
            return Err(CoreError::File {
                file: source_name.to_string(),
                message: "the channel map has no entries".into(),
            });
        }
        Ok(ChannelMap {
            file: source_name.to_string(),
            entries,
        })
    }

    /// Checks that every test label is among `test_labels` and every model label among
    /// `model_labels`.
    ///
    /// # Errors
    /// [`CoreError::MapLabel`] naming the map's line of the first unknown label.
    pub fn check<S: AsRef<str>, T: AsRef<str>>(
        &self,
        test_labels: &[S],
        model_labels: &[T],
    ) -> Result<()> {
        for e in &self.entries {
            for (side, label, labels) in [
                ("test", &e.test_label, short_list(test_labels)),
                ("model", &e.model_label, short_list(model_labels)),
            ] {
                if !labels.0.iter().any(|l| l == label) {
                    return Err(CoreError::MapLabel {
                        file: self.file.clone(),
                        line: e.line,
                        side,
                        label: label.clone(),
                        available: labels.1,
                    });
                }
            }
        }
        Ok(())
    }
}

/// All labels as strings, and the first five joined for a message.
fn short_list<S: AsRef<str>>(labels: &[S]) -> (Vec<&str>, String) {
    let all: Vec<&str> = labels.iter().map(AsRef::as_ref).collect();
    let mut shown: Vec<&str> = all.iter().take(5).copied().collect();
    if all.len() > 5 {
        shown.push("...");
    }
    let text = shown.join(", ");
    (all, text)
}

#[cfg(test)]
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;

    #[test]
    fn reads_entries_with_and_without_gain() {
        let m = ChannelMap::parse(
            "test_label,model_label,gain\nHEAD_X,12.x,0.0254\n\nHEAD_Z, 12.z\n",
            "map.csv",
        )
        .unwrap();
        assert_eq!(m.entries.len(), 2);
        assert_eq!(m.entries[0].gain, 0.0254);
        assert_eq!(m.entries[1].gain, 1.0);
        assert_eq!(m.entries[1].model_label, "12.z");
        assert_eq!(m.entries[1].line, 4);
        m.check(&["HEAD_X", "HEAD_Z"], &["12.x", "12.z"]).unwrap();
    }

    #[test]
    fn unknown_labels_name_the_line_and_side() {
        let m = ChannelMap::parse("A,1.x\nB,2.x\n", "map.csv").unwrap();
        match m.check(&["A", "B"], &["1.x"]).unwrap_err() {
            CoreError::MapLabel {
                line, side, label, ..
            } => {
                assert_eq!((line, side, label.as_str()), (2, "model", "2.x"));
            }
            e => panic!("unexpected {e}"),
        }
        let e = m.check(&["A"], &["1.x", "2.x"]).unwrap_err();
        assert!(
            e.to_string().contains("map.csv: line 2: test label `B`"),
            "{e}"
        );
    }

    #[test]
    fn malformed_lines_are_positioned() {
        let pos = |text: &str| match ChannelMap::parse(text, "m").unwrap_err() {
            CoreError::Csv { row, column, .. } => (row, column),
            e => panic!("unexpected {e}"),
        };
        assert_eq!(pos("A,1.x\nB\n"), (2, 2));
        assert_eq!(pos("A,1.x,2,3\n"), (1, 4));
        assert_eq!(pos("A,1.x,zero\n"), (1, 3));
        assert_eq!(pos("A,1.x,0\n"), (1, 3));
        assert_eq!(pos("A,1.x\nA,2.x\n"), (2, 1));
        assert_eq!(pos("A,\n"), (1, 2));
        assert!(ChannelMap::parse("test_label,model_label\n", "m").is_err());
    }
}
