//! Channel maps: which model channel each test channel is compared with.

use std::path::Path;

use super::conversion::Conversion;
use crate::error::{CoreError, Result};
use crate::histories::Histories;
use crate::table::{LineIndex, csv_reader};

/// One line of a channel map: the test channel `test_label`, converted by `conversion` when
/// it has one, is compared with the model channel `model_label` multiplied by `gain` (the
/// gain converts the model's unit into the test's).
#[derive(Debug, Clone, PartialEq)]
pub struct MapEntry {
    /// Label of the test (measured) channel.
    pub test_label: String,
    /// Label of the model channel.
    pub model_label: String,
    /// Factor applied to the model channel before comparing (1 when the map omits it).
    pub gain: f64,
    /// The conversion of the raw test channel into SI (a bridge, an accelerometer's
    /// sensitivity, a unit), applied before anything else.
    pub conversion: Option<Conversion>,
    /// 1-based line of the map file.
    pub line: usize,
}

/// A channel map read from CSV lines `test_label,model_label[,gain[,conversion]]`,
/// optionally under a header line `test_label,model_label[,gain[,conversion]]`. Blank lines
/// are skipped. A conversion is written as [`Conversion::parse`] reads it, for example
/// `HEAD_X,12.x,,accelerometer mv-per-g=0.5` or `SG1,bar.strain,1,quarter-bridge gf=2.06
/// gain=200 excitation=8`.
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
            if !(2..=4).contains(&record.len()) {
                return Err(err(
                    line,
                    record.len().min(4) + 1,
                    format!(
                        "expected `test_label,model_label[,gain[,conversion]]`, found {} fields",
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
            let conversion = match record.get(3) {
                None | Some("") => None,
                Some(text) => Some(Conversion::parse(text).map_err(|m| err(line, 4, m))?),
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
                conversion,
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

    /// `test` with the conversion of each mapped channel applied (other channels as they
    /// are).
    ///
    /// # Errors
    /// [`CoreError::NonFinite`] naming the channel and sample where a conversion gives a
    /// non-finite value (a bridge ratio at its pole).
    pub fn convert(&self, test: &Histories) -> Result<Histories> {
        if self.entries.iter().all(|e| e.conversion.is_none()) {
            return Ok(test.clone());
        }
        let mut channels = Vec::with_capacity(test.channels());
        for (c, label) in test.labels().iter().enumerate() {
            let conv = self
                .entries
                .iter()
                .find(|e| &e.test_label == label)
                .and_then(|e| e.conversion);
            let x = test.channel(c);
            channels.push(match conv {
                None => x.to_vec(),
                Some(cv) => {
                    let y: Vec<f64> = x.iter().map(|v| cv.apply(*v)).collect();
                    if let Some(k) = y.iter().position(|v| !v.is_finite()) {
                        return Err(CoreError::NonFinite {
                            what: format!("channel `{label}` converted by {}", self.file),
                            value: y[k],
                            location: format!("sample {k}"),
                        });
                    }
                    y
                }
            });
        }
        Histories::from_channels(
            test.labels().to_vec(),
            channels,
            test.dt(),
            test.start(),
            test.unit(),
        )
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
    fn conversions_apply_to_their_channels_only() {
        let m = ChannelMap::parse(
            "SG,bar.strain,,quarter-bridge gf=2 gain=100 excitation=10\nA,1.z,2,unit from=g\nB,2.z\n",
            "map.csv",
        )
        .unwrap();
        assert_eq!(m.entries[0].gain, 1.0);
        let h = Histories::from_channels(
            vec!["SG".into(), "A".into(), "B".into()],
            vec![vec![0.0, 2.0], vec![1.0, -1.0], vec![3.0, 4.0]],
            1e-3,
            0.0,
            "",
        )
        .unwrap();
        let c = m.convert(&h).unwrap();
        // V_r = 2 / 1000; strain = 4 V_r / (2 (1 - 2 V_r)).
        assert!((c.channel(0)[1] - 0.008 / (2.0 * 0.996)).abs() < 1e-15);
        assert_eq!(c.channel(1), &[9.80665, -9.80665]);
        assert_eq!(c.channel(2), &[3.0, 4.0]);
        // A ratio at the quarter bridge's pole (V_r = 1/2) is named.
        let h = Histories::from_channels(vec!["SG".into()], vec![vec![0.0, 500.0]], 1e-3, 0.0, "")
            .unwrap();
        let e = m.convert(&h).unwrap_err().to_string();
        assert!(e.contains("`SG`") && e.contains("sample 1"), "{e}");
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
        assert_eq!(pos("A,1.x,2,3,4\n"), (1, 5));
        assert_eq!(pos("A,1.x,2,third-bridge\n"), (1, 4));
        assert_eq!(pos("A,1.x,zero\n"), (1, 3));
        assert_eq!(pos("A,1.x,0\n"), (1, 3));
        assert_eq!(pos("A,1.x\nA,2.x\n"), (2, 1));
        assert_eq!(pos("A,\n"), (1, 2));
        assert!(ChannelMap::parse("test_label,model_label\n", "m").is_err());
    }
}
