//! Multi-channel time histories on a uniform time base.

use std::io::Write;
use std::path::Path;

use crate::error::{CoreError, Result};
use crate::table::{Table, TableOptions};

/// Which nodal quantity a set of nodal histories holds: what the built-in solver records at
/// its history nodes and what is read from LS-DYNA's `nodout` (in files: `displacement`,
/// `velocity`, `acceleration`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NodalQuantity {
    /// Displacement from the initial position.
    Displacement,
    /// Velocity (the default).
    #[default]
    Velocity,
    /// Acceleration.
    Acceleration,
}

impl NodalQuantity {
    /// The name used in files and on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            NodalQuantity::Displacement => "displacement",
            NodalQuantity::Velocity => "velocity",
            NodalQuantity::Acceleration => "acceleration",
        }
    }
}

/// Relative tolerance on the spacing of time stamps read from a file: a step may differ from
/// the mean step by this fraction of it (CSV files from other tools round their times).
pub const TIME_STEP_TOLERANCE: f64 = 1e-6;

/// A set of time histories: `channels x samples` values on the uniform time base
/// `t_k = start + k dt`, `k = 0..samples`, with one label per channel and a unit string.
///
/// Labels follow `<node>.<x|y|z>` for nodal channels (for example `1042.z`) and are free
/// text otherwise; they are unique and non-empty. Values are stored channel by channel
/// (each channel contiguous). Every value is finite.
#[derive(Debug, Clone, PartialEq)]
pub struct Histories {
    labels: Vec<String>,
    samples: usize,
    dt: f64,
    start: f64,
    unit: String,
    data: Vec<f64>,
}

impl Histories {
    /// Builds histories from channel-major data (`data[c * samples + k]` is channel `c` at
    /// sample `k`).
    ///
    /// # Errors
    /// [`CoreError::Invalid`] for no channels, no samples, an empty or repeated label, or a
    /// time step that is not finite and positive; [`CoreError::DimensionMismatch`] when
    /// `data.len() != labels.len() * samples`; [`CoreError::NonFinite`] for a NaN or
    /// infinite value or start time.
    pub fn new(
        labels: Vec<String>,
        samples: usize,
        dt: f64,
        start: f64,
        unit: impl Into<String>,
        data: Vec<f64>,
    ) -> Result<Self> {
        if labels.is_empty() {
            return Err(CoreError::Invalid(
                "histories need at least one channel".into(),
            ));
        }
        if samples == 0 {
            return Err(CoreError::Invalid(
                "histories need at least one sample".into(),
            ));
        }
        check_labels(&labels)?;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(CoreError::Invalid(format!(
                "time step {dt} must be finite and positive"
            )));
        }
        if !start.is_finite() {
            return Err(CoreError::NonFinite {
                what: "start time".into(),
                location: "histories".into(),
                value: start,
            });
        }
        if data.len() != labels.len() * samples {
            return Err(CoreError::DimensionMismatch {
                what: "history values (channels x samples)".into(),
                expected: labels.len() * samples,
                found: data.len(),
            });
        }
        if let Some(i) = data.iter().position(|v| !v.is_finite()) {
            return Err(CoreError::NonFinite {
                what: "history value".into(),
                location: format!("channel `{}`, sample {}", labels[i / samples], i % samples),
                value: data[i],
            });
        }
        Ok(Histories {
            labels,
            samples,
            dt,
            start,
            unit: unit.into(),
            data,
        })
    }

    /// Builds histories from one vector per channel, all of the same length.
    ///
    /// # Errors
    /// As [`Histories::new`], plus [`CoreError::DimensionMismatch`] for channels of unequal
    /// length.
    pub fn from_channels(
        labels: Vec<String>,
        channels: Vec<Vec<f64>>,
        dt: f64,
        start: f64,
        unit: impl Into<String>,
    ) -> Result<Self> {
        if labels.len() != channels.len() {
            return Err(CoreError::DimensionMismatch {
                what: "number of channels (labels vs data)".into(),
                expected: labels.len(),
                found: channels.len(),
            });
        }
        let samples = channels.first().map_or(0, Vec::len);
        for (c, ch) in channels.iter().enumerate() {
            if ch.len() != samples {
                return Err(CoreError::DimensionMismatch {
                    what: format!("samples in channel `{}`", labels[c]),
                    expected: samples,
                    found: ch.len(),
                });
            }
        }
        Histories::new(labels, samples, dt, start, unit, channels.concat())
    }

    /// Number of channels `m`.
    pub fn channels(&self) -> usize {
        self.labels.len()
    }

    /// Number of samples `L` per channel.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// The time step.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The time of sample 0.
    pub fn start(&self) -> f64 {
        self.start
    }

    /// The unit of the values (may be empty).
    pub fn unit(&self) -> &str {
        &self.unit
    }

    /// The same histories with another unit string.
    #[must_use]
    pub fn with_unit(mut self, unit: impl Into<String>) -> Self {
        self.unit = unit.into();
        self
    }

    /// The channel labels in order.
    pub fn labels(&self) -> &[String] {
        &self.labels
    }

    /// All values, channel-major (`channels * samples` numbers).
    pub fn data(&self) -> &[f64] {
        &self.data
    }

    /// Channel `c` as a slice of `samples` values.
    ///
    /// # Panics
    /// If `c >= channels()` (an index, not user input).
    pub fn channel(&self, c: usize) -> &[f64] {
        &self.data[c * self.samples..(c + 1) * self.samples]
    }

    /// Value of channel `c` at sample `k`.
    ///
    /// # Panics
    /// If an index is out of range.
    pub fn value(&self, c: usize, k: usize) -> f64 {
        assert!(k < self.samples, "sample index out of range");
        self.data[c * self.samples + k]
    }

    /// The time stamps `start + k dt`.
    pub fn time(&self) -> Vec<f64> {
        (0..self.samples)
            .map(|k| self.start + k as f64 * self.dt)
            .collect()
    }

    /// Position of the channel labelled `label`.
    pub fn index_of(&self, label: &str) -> Option<usize> {
        self.labels.iter().position(|l| l == label)
    }

    /// The channel labelled `label`.
    ///
    /// # Errors
    /// [`CoreError::UnknownLabel`] when no channel has that label.
    pub fn channel_by_label(&self, label: &str) -> Result<&[f64]> {
        self.index_of(label)
            .map(|c| self.channel(c))
            .ok_or_else(|| self.unknown(label))
    }

    /// A new set holding the named channels in the order given.
    ///
    /// # Errors
    /// [`CoreError::UnknownLabel`] for a label not present; [`CoreError::Invalid`] for an
    /// empty or repeated selection.
    pub fn select<S: AsRef<str>>(&self, labels: &[S]) -> Result<Histories> {
        let mut data = Vec::with_capacity(labels.len() * self.samples);
        let mut names = Vec::with_capacity(labels.len());
        for l in labels {
            let l = l.as_ref();
            let c = self.index_of(l).ok_or_else(|| self.unknown(l))?;
            data.extend_from_slice(self.channel(c));
            names.push(l.to_string());
        }
        Histories::new(names, self.samples, self.dt, self.start, &*self.unit, data)
    }

    /// The 2-norm across channels at every sample, `Q(t_k) = sqrt(sum_c y_c(t_k)^2)`: the
    /// source paper's response-norm history (for velocity channels, the velocity norm).
    pub fn norm_history(&self) -> Vec<f64> {
        norm_history_of(&self.data, self.samples)
    }

    /// The labels of the `count` channels with the largest variance about their own mean,
    /// largest first, ties by label (all channels when `count` exceeds them): where a
    /// response moves. A channel that barely moves over the record is nearly a constant,
    /// whose gain and offset cannot be told apart.
    pub fn most_varying(&self, count: usize) -> Vec<String> {
        let mut scored: Vec<(f64, &String)> = self
            .labels
            .iter()
            .enumerate()
            .map(|(i, l)| {
                let c = self.channel(i);
                let mean = c.iter().sum::<f64>() / c.len() as f64;
                (c.iter().map(|x| (x - mean).powi(2)).sum::<f64>(), l)
            })
            .collect();
        scored.sort_by(|a, b| b.0.total_cmp(&a.0).then_with(|| a.1.cmp(b.1)));
        scored
            .into_iter()
            .take(count)
            .map(|(_, l)| l.clone())
            .collect()
    }

    fn unknown(&self, label: &str) -> CoreError {
        let mut available: Vec<&str> = self.labels.iter().take(5).map(String::as_str).collect();
        if self.labels.len() > 5 {
            available.push("...");
        }
        CoreError::UnknownLabel {
            label: label.to_string(),
            available: available.join(", "),
        }
    }

    /// Reads histories from a wide CSV file (see [`Histories::parse_csv`]).
    ///
    /// # Errors
    /// [`CoreError::Io`] when unreadable; otherwise as [`Histories::parse_csv`].
    pub fn read_csv(path: impl AsRef<Path>) -> Result<Histories> {
        let (text, name) = crate::table::read_text(path.as_ref())?;
        Histories::parse_csv(&text, &name)
    }

    /// Parses wide CSV: a header `time,<label>,<label>,...`, then one row per sample. The
    /// unit is left empty.
    ///
    /// # Errors
    /// [`CoreError::File`] for an empty file or no rows; [`CoreError::Csv`] with row and
    /// column for: a first column not called `time`, no channel columns, an empty or repeated
    /// label, a ragged row, a cell that is not a finite number, fewer than two samples,
    /// non-increasing time or a step that differs from the mean step by more than
    /// [`TIME_STEP_TOLERANCE`] of it.
    pub fn parse_csv(text: &str, source_name: &str) -> Result<Histories> {
        let table = Table::parse(text, source_name, TableOptions::default())?;
        let err = |row: usize, column: usize, message: String| CoreError::Csv {
            file: source_name.to_string(),
            row,
            column,
            message,
        };
        let header_row = table
            .lines
            .first()
            .map_or(1, |&l| l.saturating_sub(1).max(1));
        if !table.header[0].eq_ignore_ascii_case("time") {
            return Err(err(
                header_row,
                1,
                format!("first column is `{}`; expected `time`", table.header[0]),
            ));
        }
        if table.header.len() < 2 {
            return Err(err(header_row, 2, "no channel columns after `time`".into()));
        }
        let samples = table.rows.len();
        if samples < 2 {
            return Err(err(
                table.lines[0],
                1,
                "need at least two samples to define the time step".into(),
            ));
        }
        let t0 = table.rows[0][0];
        let mean_dt = (table.rows[samples - 1][0] - t0) / (samples - 1) as f64;
        for k in 1..samples {
            if table.rows[k][0] <= table.rows[k - 1][0] {
                return Err(err(
                    table.lines[k],
                    1,
                    format!(
                        "time {} does not increase (previous {})",
                        table.rows[k][0],
                        table.rows[k - 1][0]
                    ),
                ));
            }
        }
        for k in 1..samples {
            let step = table.rows[k][0] - table.rows[k - 1][0];
            if (step - mean_dt).abs() > TIME_STEP_TOLERANCE * mean_dt {
                return Err(err(
                    table.lines[k],
                    1,
                    format!(
                        "non-uniform time step {step} (mean step {mean_dt}); resample the record onto \
                         a uniform step first (`impactcal convert --csv`, or \
                         `signal::resample_uniform`)"
                    ),
                ));
            }
        }
        let channels = table.header.len() - 1;
        let mut data = vec![0.0; channels * samples];
        for (k, row) in table.rows.iter().enumerate() {
            for c in 0..channels {
                data[c * samples + k] = row[c + 1];
            }
        }
        Histories::new(
            table.header[1..].to_vec(),
            samples,
            mean_dt,
            t0,
            String::new(),
            data,
        )
    }

    /// Writes the wide CSV form read by [`Histories::parse_csv`]; numbers use shortest
    /// round-trip formatting, so values survive a write and read unchanged.
    ///
    /// # Errors
    /// [`CoreError::Io`] naming `name` when writing fails.
    pub fn write_csv_to(&self, mut out: impl Write, name: &str) -> Result<()> {
        let io = |source| CoreError::Io {
            path: name.to_string(),
            source,
        };
        writeln!(out, "time,{}", self.labels.join(",")).map_err(io)?;
        let mut row = vec![0.0; self.channels() + 1];
        for k in 0..self.samples {
            row[0] = self.start + k as f64 * self.dt;
            for c in 0..self.channels() {
                row[c + 1] = self.data[c * self.samples + k];
            }
            crate::table::write_row(&mut out, &row).map_err(io)?;
        }
        out.flush().map_err(io)
    }

    /// Writes the wide CSV form to a file.
    ///
    /// # Errors
    /// [`CoreError::Io`] when the file cannot be created or written.
    pub fn write_csv(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let file = std::fs::File::create(path).map_err(|source| CoreError::Io {
            path: name.clone(),
            source,
        })?;
        self.write_csv_to(std::io::BufWriter::new(file), &name)
    }
}

fn check_labels(labels: &[String]) -> Result<()> {
    for (i, l) in labels.iter().enumerate() {
        if l.trim().is_empty() {
            return Err(CoreError::Invalid(format!(
                "channel {i} has an empty label"
            )));
        }
        if let Some(j) = labels[..i].iter().position(|m| m == l) {
            return Err(CoreError::Invalid(format!(
                "label `{l}` is used by channels {j} and {i}"
            )));
        }
    }
    Ok(())
}

/// [`Histories::norm_history`] of a channel-major block (`data[c * samples + k]`, channels
/// one after another): `Q(t_k) = sqrt(sum_c data[c * samples + k]^2)`, `samples` values.
/// A trailing partial channel is summed as far as it goes.
pub fn norm_history_of(data: &[f64], samples: usize) -> Vec<f64> {
    let mut q = vec![0.0; samples];
    for channel in data.chunks(samples.max(1)) {
        for (acc, v) in q.iter_mut().zip(channel) {
            *acc += v * v;
        }
    }
    q.iter_mut().for_each(|v| *v = v.sqrt());
    q
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn sample() -> Histories {
        Histories::from_channels(
            vec!["1.x".into(), "1.z".into(), "force".into()],
            vec![
                vec![0.0, 1.0, 2.0],
                vec![3.0, 4.0, 5.0],
                vec![-1.0, 0.5, 1e-9],
            ],
            1e-4,
            0.002,
            "in/s",
        )
        .unwrap()
    }

    #[test]
    fn most_varying_ranks_by_variance_about_the_mean_ties_by_label() {
        let h = sample();
        // Variances 2, 2 and 7/6: the two ramps tie and fall back to label order.
        assert_eq!(h.most_varying(3), vec!["1.x", "1.z", "force"]);
        assert_eq!(h.most_varying(1), vec!["1.x"]);
        assert_eq!(h.most_varying(9).len(), 3);
        let q = h.norm_history();
        assert_eq!(q, norm_history_of(&h.data, h.samples));
        assert_relative_eq!(q[1], (1.0f64 + 16.0 + 0.25).sqrt());
    }

    fn fault(text: &str) -> (usize, usize) {
        match Histories::parse_csv(text, "h.csv").unwrap_err() {
            CoreError::Csv { row, column, .. } => (row, column),
            e => panic!("expected positioned error, got {e}"),
        }
    }

    #[test]
    fn csv_round_trip() {
        let h = sample();
        let mut buf = Vec::new();
        h.write_csv_to(&mut buf, "mem").unwrap();
        let back = Histories::parse_csv(std::str::from_utf8(&buf).unwrap(), "mem").unwrap();
        assert_eq!(back.labels(), h.labels());
        assert_eq!(back.data(), h.data());
        assert_relative_eq!(back.dt(), h.dt(), max_relative = 1e-12);
        assert_relative_eq!(back.start(), h.start());
    }

    #[test]
    fn malformed_files_name_row_and_column() {
        assert_eq!(fault("t,a\n0,1\n1,2\n"), (1, 1));
        assert_eq!(fault("time\n0\n1\n"), (1, 2));
        assert_eq!(fault("time,a\n0,1\n"), (2, 1));
        assert_eq!(fault("time,a\n0,1\n1,2\n1,3\n"), (4, 1));
        assert_eq!(fault("time,a\n0,1\n1,2\n2.5,3\n3,4\n"), (4, 1));
        assert_eq!(fault("time,a\n0,1\n1,abc\n"), (3, 2));
        assert_eq!(fault("time,a\n0,1\n1,NaN\n"), (3, 2));
        assert_eq!(fault("time,a\n0,1\n1,-inf\n"), (3, 2));
        assert_eq!(fault("time,a,b\n0,1,2\n1,2\n"), (3, 3));
        assert_eq!(fault("time,a,a\n0,1,2\n1,2,3\n"), (1, 3));
        assert_eq!(fault("time,a,\n0,1,2\n1,2,3\n"), (1, 3));
        assert!(matches!(
            Histories::parse_csv("", "h.csv").unwrap_err(),
            CoreError::File { .. }
        ));
    }

    #[test]
    fn rounded_time_stamps_are_accepted() {
        let h = Histories::parse_csv("time,a\n0,1\n0.333333333,2\n0.666666667,3\n", "h").unwrap();
        assert_relative_eq!(h.dt(), 0.3333333335, max_relative = 1e-9);
    }

    #[test]
    fn selection_and_norm() {
        let h = sample();
        let s = h.select(&["force", "1.x"]).unwrap();
        assert_eq!(s.labels(), &["force".to_string(), "1.x".to_string()]);
        assert_eq!(s.channel(1), h.channel(0));
        assert!(matches!(
            h.select(&["9.y"]).unwrap_err(),
            CoreError::UnknownLabel { .. }
        ));
        let q = h.norm_history();
        assert_relative_eq!(q[0], (0.0f64 + 9.0 + 1.0).sqrt());
        assert_relative_eq!(h.time()[2], 0.0022, max_relative = 1e-12);
    }

    #[test]
    fn constructor_validates() {
        let l = || vec!["a".to_string()];
        assert!(Histories::new(l(), 2, 0.1, 0.0, "", vec![1.0]).is_err());
        assert!(Histories::new(l(), 1, 0.0, 0.0, "", vec![1.0]).is_err());
        assert!(Histories::new(l(), 1, 0.1, 0.0, "", vec![f64::NAN]).is_err());
        assert!(Histories::new(vec![], 0, 0.1, 0.0, "", vec![]).is_err());
        let dup = vec!["a".to_string(), "a".to_string()];
        assert!(Histories::new(dup, 1, 0.1, 0.0, "", vec![1.0, 2.0]).is_err());
    }
}
