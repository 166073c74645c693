//! ISO-MME data sets (ISO/TS 13499): the exchange format of crash-test laboratories.
//!
//! A data set is a folder (or a `.zip` archive of one) holding a `<test>.mme` file of test
//! information and a `Channel/` folder with an index `<test>.chn` and one text file per channel,
//! `<test>.001`, `<test>.002`, ... The index lists the channels as
//! `Name of channel 001 :<code> / <name>`; each channel file starts with header lines
//! `<name> :<value>` (among them `Channel code`, `Unit`, `Sampling interval`,
//! `Time of first sample`, `Number of samples`) followed by one sample per line. `NOVALUE`
//! marks an empty field or a dropped sample.
//!
//! [`IsoMme::read`] reads such a set from the folder, its `.mme` file or a `.zip` archive, in
//! ASCII, UTF-8, ISO-8859-1 or Windows-1252 text ([`TextEncoding`]). Channel codes become
//! labels and units are kept. Where a file leaves a field out, the reader applies the
//! default and says so in [`IsoMmeChannel::notes`]:
//!
//! - no `Time of first sample`: the first sample is at time 0 s;
//! - no `Unit`: the unit is left empty;
//! - isolated dropped samples (`NOVALUE` between two values) are filled linearly.
//!
//! A channel whose time comes from another channel (`Reference channel :explicit` with
//! `Reference channel name`) takes that channel's samples as its time stamps; if they are not
//! uniform the channel is resampled linearly onto their median step, and the notes say so.

mod source;
mod text;

use std::path::Path;

use crate::error::{CoreError, Result};
use crate::histories::{Histories, TIME_STEP_TOLERANCE};
use crate::signal::{interpolate_onto, resample_uniform};
use source::Source;
pub use text::TextEncoding;
use text::{Field, decode, field, numbered_lines};

/// One channel of an ISO-MME data set, on a uniform time base.
#[derive(Debug, Clone, PartialEq)]
pub struct IsoMmeChannel {
    /// The channel number of its file name (`001` for `<test>.001`).
    pub number: String,
    /// The channel code (the label it gets in [`Histories`]).
    pub code: String,
    /// The channel's free-text name from the index or its own header, if any.
    pub name: Option<String>,
    /// The unit as written (empty when the file gives none).
    pub unit: String,
    /// Time of the first sample.
    pub start: f64,
    /// Sampling interval.
    pub dt: f64,
    /// The samples.
    pub values: Vec<f64>,
    /// The channel file, as shown in messages.
    pub file: String,
    /// The text encoding the channel file was found in.
    pub encoding: TextEncoding,
    /// Every header field of the channel file in order (`None` for `NOVALUE` or empty).
    pub header: Vec<(String, Option<String>)>,
    /// Defaults applied and repairs made while reading, in words.
    pub notes: Vec<String>,
}

/// An ISO-MME data set read from disk.
#[derive(Debug, Clone, PartialEq)]
pub struct IsoMme {
    /// The path given to [`IsoMme::read`].
    pub source: String,
    /// The test number (the stem of the `.mme` file).
    pub test_number: String,
    /// The header fields of the `.mme` file in order.
    pub test_info: Vec<(String, Option<String>)>,
    /// The text encoding of the `.mme` file.
    pub encoding: TextEncoding,
    /// The channels selected, in index order.
    pub channels: Vec<IsoMmeChannel>,
}

/// Whether channel code `code` matches `pattern`, in which `*` stands for any run of
/// characters and `?` for one; letters match without regard to case.
pub fn code_matches(pattern: &str, code: &str) -> bool {
    let p: Vec<char> = pattern.to_ascii_uppercase().chars().collect();
    let c: Vec<char> = code.to_ascii_uppercase().chars().collect();
    // Classic two-pointer glob match with backtracking to the last `*`.
    let (mut i, mut j, mut star, mut mark) = (0, 0, None, 0);
    while j < c.len() {
        if i < p.len() && (p[i] == '?' || p[i] == c[j]) {
            i += 1;
            j += 1;
        } else if i < p.len() && p[i] == '*' {
            star = Some(i);
            mark = j;
            i += 1;
        } else if let Some(s) = star {
            i = s + 1;
            mark += 1;
            j = mark;
        } else {
            return false;
        }
    }
    p[i..].iter().all(|&ch| ch == '*')
}

/// An index entry `Name of channel NNN :<code> / <name>`.
struct IndexEntry {
    number: String,
    code: String,
    name: Option<String>,
    line: usize,
}

impl IsoMme {
    /// Reads the data set at `path` (its folder, its `.mme` file or a `.zip` archive), keeping
    /// the channels whose codes match any of `patterns` (all channels when `patterns` is
    /// empty; see [`code_matches`]).
    ///
    /// # Errors
    /// - [`CoreError::Io`] when a file cannot be read; [`CoreError::Archive`] for a zip file
    ///   that is truncated or corrupt;
    /// - [`CoreError::File`] for a path that is not a data set, a set without `.mme` file or
    ///   `.chn` index, or a selection that matches no channel;
    /// - [`CoreError::MissingFile`] naming the `.chn` line of a channel whose file is absent;
    /// - [`CoreError::Line`] naming the file and line of a malformed index entry, a sample
    ///   that is not a number, a sampling interval that is missing, zero, negative or not a
    ///   number, a time of first sample that is not a number, a sample count that disagrees
    ///   with the header, or a dropped sample at either end of a channel.
    pub fn read(path: impl AsRef<Path>, patterns: &[String]) -> Result<IsoMme> {
        let path = path.as_ref();
        let (mut source, mme_name) = Source::open(path)?;
        let (root, file) = match mme_name.rsplit_once('/') {
            Some((root, file)) => (format!("{root}/"), file.to_string()),
            None => (String::new(), mme_name.clone()),
        };
        let test_number = file[..file.len() - 4].to_string();
        let (mme_text, encoding) = decode(&source.read(&mme_name)?);
        let test_info = numbered_lines(&mme_text)
            .filter_map(|(n, l)| field(l, n))
            .map(|f| (f.name, f.value))
            .collect();
        let chn_wanted = format!("{root}Channel/{test_number}.chn");
        let chn_name = source.find(&chn_wanted).ok_or_else(|| CoreError::File {
            file: source.display(&mme_name),
            message: format!("the data set has no channel index `{chn_wanted}`"),
        })?;
        let chn_shown = source.display(&chn_name);
        let (chn_text, _) = decode(&source.read(&chn_name)?);
        let index = parse_index(&chn_text, &chn_shown)?;
        let selected: Vec<&IndexEntry> = index
            .iter()
            .filter(|e| patterns.is_empty() || patterns.iter().any(|p| code_matches(p, &e.code)))
            .collect();
        if selected.is_empty() {
            return Err(CoreError::File {
                file: chn_shown,
                message: if index.is_empty() {
                    "the channel index lists no channels".into()
                } else {
                    format!(
                        "no channel code matches {} (codes: {})",
                        patterns.join(", "),
                        index
                            .iter()
                            .take(6)
                            .map(|e| e.code.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                },
            });
        }
        let mut raw = Vec::new();
        for entry in &selected {
            raw.push(read_channel(
                &mut source,
                &root,
                &test_number,
                entry,
                &chn_shown,
            )?);
        }
        let mut channels = Vec::with_capacity(raw.len());
        for r in &raw {
            channels.push(resolve_time(
                r,
                &raw,
                &index,
                &mut source,
                &root,
                &test_number,
                &chn_shown,
            )?);
        }
        Ok(IsoMme {
            source: path.display().to_string(),
            test_number,
            test_info,
            encoding,
            channels,
        })
    }

    /// All notes of all channels, each prefixed with its channel code.
    pub fn notes(&self) -> Vec<String> {
        self.channels
            .iter()
            .flat_map(|c| c.notes.iter().map(move |n| format!("{}: {n}", c.code)))
            .collect()
    }

    /// The channels as [`Histories`] labelled by channel code, with notes on what was done
    /// to put them on one time base.
    ///
    /// Channels sharing sampling interval, start and length are taken as they are. Otherwise
    /// they are interpolated linearly onto the finest sampling interval over the time range
    /// that all of them cover, and a note says so. The unit is the channels' common unit, or
    /// empty (with a note listing them) when they differ.
    ///
    /// # Errors
    /// [`CoreError::Invalid`] for two channels with the same code or channels without a
    /// common time range.
    pub fn to_histories(&self) -> Result<(Histories, Vec<String>)> {
        let mut notes = Vec::new();
        for (i, c) in self.channels.iter().enumerate() {
            if let Some(d) = self.channels[..i].iter().find(|d| d.code == c.code) {
                return Err(CoreError::Invalid(format!(
                    "channel code `{}` is used by {} and {}; select one with a pattern",
                    c.code, d.file, c.file
                )));
            }
        }
        let first = &self.channels[0];
        let same_base = self.channels.iter().all(|c| {
            c.values.len() == first.values.len()
                && (c.dt - first.dt).abs() <= TIME_STEP_TOLERANCE * first.dt
                && (c.start - first.start).abs() <= TIME_STEP_TOLERANCE * first.dt
        });
        let labels: Vec<String> = self.channels.iter().map(|c| c.code.clone()).collect();
        let unit = if self.channels.iter().all(|c| c.unit == first.unit) {
            first.unit.clone()
        } else {
            notes.push(format!(
                "units differ between channels ({}); the histories carry no common unit",
                self.channels
                    .iter()
                    .map(|c| format!("{} [{}]", c.code, c.unit))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
            String::new()
        };
        if same_base {
            let data = self.channels.iter().map(|c| c.values.clone()).collect();
            return Ok((
                Histories::from_channels(labels, data, first.dt, first.start, unit)?,
                notes,
            ));
        }
        let dt = self
            .channels
            .iter()
            .map(|c| c.dt)
            .fold(f64::INFINITY, f64::min);
        let start = self
            .channels
            .iter()
            .map(|c| c.start)
            .fold(f64::NEG_INFINITY, f64::max);
        let end = self
            .channels
            .iter()
            .map(|c| c.start + (c.values.len() - 1) as f64 * c.dt)
            .fold(f64::INFINITY, f64::min);
        if end <= start {
            return Err(CoreError::Invalid(
                "the selected channels share no common time range".into(),
            ));
        }
        let samples = ((end - start) / dt + 1e-6).floor() as usize + 1;
        let mut data = Vec::with_capacity(samples * self.channels.len());
        for c in &self.channels {
            let one = Histories::new(
                vec![c.code.clone()],
                c.values.len(),
                c.dt,
                c.start,
                "",
                c.values.clone(),
            )?;
            data.extend_from_slice(interpolate_onto(&one, start, dt, samples, &c.file)?.data());
        }
        notes.push(format!(
            "channels differ in sampling interval, start or length: interpolated linearly onto {samples} samples every {dt:e} s from {start} s (the range all of them cover)"
        ));
        Ok((
            Histories::new(labels, samples, dt, start, unit, data)?,
            notes,
        ))
    }
}

/// Parses the `Name of channel NNN` entries of a `.chn` index.
fn parse_index(text: &str, shown: &str) -> Result<Vec<IndexEntry>> {
    let mut out = Vec::new();
    for (n, line) in numbered_lines(text) {
        let Some(f) = field(line, n) else { continue };
        let Some(number) = f.name.strip_prefix("Name of channel") else {
            continue;
        };
        let number = number.trim().to_string();
        let bad = |message: String| CoreError::Line {
            file: shown.to_string(),
            line: n,
            message,
        };
        if number.is_empty() || !number.chars().all(|c| c.is_ascii_digit()) {
            return Err(bad(format!(
                "`{}` does not end in a channel number",
                f.name
            )));
        }
        let value = f
            .value
            .ok_or_else(|| bad(format!("channel {number} has no code")))?;
        let (code, name) = match value.split_once('/') {
            Some((code, name)) => (
                code.trim(),
                Some(name.trim().to_string()).filter(|s| !s.is_empty()),
            ),
            None => (value.trim(), None),
        };
        let code = code
            .split_whitespace()
            .next()
            .unwrap_or_default()
            .to_string();
        if code.is_empty() {
            return Err(bad(format!("channel {number} has no code")));
        }
        out.push(IndexEntry {
            number,
            code,
            name,
            line: n,
        });
    }
    Ok(out)
}

/// A channel file as read, before its time base is settled.
struct RawChannel {
    entry_number: String,
    code: String,
    name: Option<String>,
    fields: Vec<Field>,
    values: Vec<f64>,
    file: String,
    encoding: TextEncoding,
    notes: Vec<String>,
}

impl RawChannel {
    fn get(&self, name: &str) -> Option<&Field> {
        self.fields
            .iter()
            .find(|f| f.name.eq_ignore_ascii_case(name))
    }

    fn bad(&self, line: usize, message: String) -> CoreError {
        CoreError::Line {
            file: self.file.clone(),
            line,
            message,
        }
    }

    /// The numeric value of header field `name`: `Ok(None)` when absent or `NOVALUE`.
    fn number(&self, name: &str) -> Result<Option<(f64, usize)>> {
        match self.get(name) {
            Some(Field {
                value: Some(v),
                line,
                ..
            }) => match v.parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(Some((x, *line))),
                _ => Err(self.bad(*line, format!("{name} `{v}` is not a number"))),
            },
            _ => Ok(None),
        }
    }
}

fn read_channel(
    source: &mut Source,
    root: &str,
    test_number: &str,
    entry: &IndexEntry,
    chn_shown: &str,
) -> Result<RawChannel> {
    let wanted = format!("{root}Channel/{test_number}.{}", entry.number);
    let name = source.find(&wanted).ok_or_else(|| CoreError::MissingFile {
        file: chn_shown.to_string(),
        line: entry.line,
        missing: wanted.clone(),
    })?;
    let shown = source.display(&name);
    let (text, encoding) = decode(&source.read(&name)?);
    let mut fields = Vec::new();
    let mut samples: Vec<(usize, Option<f64>)> = Vec::new();
    let mut in_header = true;
    for (n, line) in numbered_lines(&text) {
        let trimmed = line.trim();
        if in_header {
            if trimmed.is_empty() {
                continue;
            }
            if let Some(f) = field(trimmed, n) {
                fields.push(f);
                continue;
            }
            in_header = false;
        }
        if trimmed.is_empty() {
            continue;
        }
        if trimmed.eq_ignore_ascii_case("NOVALUE") {
            samples.push((n, None));
            continue;
        }
        match trimmed.parse::<f64>() {
            Ok(v) if v.is_finite() => samples.push((n, Some(v))),
            _ => {
                return Err(CoreError::Line {
                    file: shown,
                    line: n,
                    message: format!("sample `{trimmed}` is not a number"),
                });
            }
        }
    }
    let mut raw = RawChannel {
        entry_number: entry.number.clone(),
        code: entry.code.clone(),
        name: entry.name.clone(),
        fields,
        values: Vec::new(),
        file: shown,
        encoding,
        notes: Vec::new(),
    };
    if let Some(Field {
        value: Some(code), ..
    }) = raw.get("Channel code")
    {
        raw.code = code.clone();
    }
    if raw.name.is_none() {
        raw.name = raw.get("Name of the channel").and_then(|f| f.value.clone());
    }
    if samples.is_empty() {
        return Err(CoreError::File {
            file: raw.file,
            message: "the channel file holds no samples".into(),
        });
    }
    if let Some((count, line)) = raw.number("Number of samples")? {
        if (count - samples.len() as f64).abs() > 0.5 {
            return Err(raw.bad(
                line,
                format!(
                    "the header announces {count} samples but the file holds {}",
                    samples.len()
                ),
            ));
        }
    }
    raw.values = fill_dropouts(&samples, &mut raw)?;
    Ok(raw)
}

/// Fills runs of dropped samples (`NOVALUE`) that have a value on each side by linear
/// interpolation, noting how many were filled.
fn fill_dropouts(samples: &[(usize, Option<f64>)], raw: &mut RawChannel) -> Result<Vec<f64>> {
    let n = samples.len();
    for k in [0, n - 1] {
        if samples[k].1.is_none() {
            return Err(raw.bad(
                samples[k].0,
                "a dropped sample (NOVALUE) at the end of a channel cannot be filled".into(),
            ));
        }
    }
    let mut values: Vec<f64> = samples.iter().map(|s| s.1.unwrap_or(f64::NAN)).collect();
    let mut filled = 0;
    let mut k = 1;
    while k < n {
        if values[k].is_nan() {
            let a = k - 1;
            let mut b = k;
            while values[b].is_nan() {
                b += 1;
            }
            for j in k..b {
                let w = (j - a) as f64 / (b - a) as f64;
                values[j] = values[a] + w * (values[b] - values[a]);
            }
            filled += b - k;
            k = b;
        }
        k += 1;
    }
    if filled > 0 {
        raw.notes.push(format!(
            "{filled} dropped sample(s) (NOVALUE) filled by linear interpolation"
        ));
    }
    Ok(values)
}

/// Settles the channel's time base: implicit (start and interval in its header) or explicit
/// (the samples of a reference channel).
fn resolve_time(
    raw: &RawChannel,
    all: &[RawChannel],
    index: &[IndexEntry],
    source: &mut Source,
    root: &str,
    test_number: &str,
    chn_shown: &str,
) -> Result<IsoMmeChannel> {
    let mut notes = raw.notes.clone();
    let unit = match raw.get("Unit") {
        Some(Field { value: Some(u), .. }) => u.clone(),
        _ => {
            notes.push("no unit given: left empty".into());
            String::new()
        }
    };
    let explicit = raw
        .get("Reference channel")
        .and_then(|f| f.value.as_deref())
        .is_some_and(|v| v.eq_ignore_ascii_case("explicit"));
    let (start, dt, values) = if explicit {
        let reference = raw
            .get("Reference channel name")
            .and_then(|f| f.value.clone());
        let line = raw.get("Reference channel").map_or(1, |f| f.line);
        let Some(reference) = reference else {
            return Err(raw.bad(
                line,
                "an explicit time reference needs a `Reference channel name`".into(),
            ));
        };
        let times = reference_times(&reference, all, index, source, root, test_number, chn_shown)
            .ok_or_else(|| {
                raw.bad(
                    line,
                    format!("the reference channel `{reference}` is not in the data set"),
                )
            })??;
        if times.len() != raw.values.len() {
            return Err(raw.bad(
                line,
                format!(
                    "the reference channel `{reference}` holds {} samples, this channel {}",
                    times.len(),
                    raw.values.len()
                ),
            ));
        }
        let (mut resampled, r) = resample_uniform(&times, std::slice::from_ref(&raw.values))
            .map_err(|e| raw.bad(line, format!("time reference `{reference}`: {e}")))?;
        let n = times.len();
        let mean = (times[n - 1] - times[0]) / (n - 1) as f64;
        let uniform = times
            .windows(2)
            .all(|w| ((w[1] - w[0]) - mean).abs() <= TIME_STEP_TOLERANCE * mean);
        if uniform {
            (times[0], mean, raw.values.clone())
        } else {
            notes.push(format!("time from `{reference}`: {r}"));
            (times[0], r.dt, resampled.swap_remove(0))
        }
    } else {
        let dt = match raw.number("Sampling interval")? {
            Some((dt, _)) if dt > 0.0 => dt,
            Some((dt, line)) => {
                return Err(raw.bad(line, format!("sampling interval {dt} must be positive")));
            }
            None => {
                let line = raw.get("Sampling interval").map_or(1, |f| f.line);
                return Err(raw.bad(
                    line,
                    "no sampling interval (and no explicit time reference)".into(),
                ));
            }
        };
        let start = match raw.number("Time of first sample")? {
            Some((t, _)) => t,
            None => {
                notes.push("no time of first sample: taken as 0 s".into());
                0.0
            }
        };
        (start, dt, raw.values.clone())
    };
    Ok(IsoMmeChannel {
        number: raw.entry_number.clone(),
        code: raw.code.clone(),
        name: raw.name.clone(),
        unit,
        start,
        dt,
        values,
        file: raw.file.clone(),
        encoding: raw.encoding,
        header: raw
            .fields
            .iter()
            .map(|f| (f.name.clone(), f.value.clone()))
            .collect(),
        notes,
    })
}

/// The samples of the channel with code `code`, read from the selection or from its file.
/// `None` when no channel has that code.
fn reference_times(
    code: &str,
    all: &[RawChannel],
    index: &[IndexEntry],
    source: &mut Source,
    root: &str,
    test_number: &str,
    chn_shown: &str,
) -> Option<Result<Vec<f64>>> {
    if let Some(c) = all.iter().find(|c| c.code == code) {
        return Some(Ok(c.values.clone()));
    }
    let entry = index.iter().find(|e| e.code == code)?;
    Some(read_channel(source, root, test_number, entry, chn_shown).map(|c| c.values))
}

#[cfg(test)]
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;

    #[test]
    fn glob_patterns() {
        assert!(code_matches("11HEAD*", "11HEAD0000H3ACXA"));
        assert!(code_matches("*ACX?", "11HEAD0000H3ACXA"));
        assert!(code_matches("11head*acxa", "11HEAD0000H3ACXA"));
        assert!(!code_matches("11CHST*", "11HEAD0000H3ACXA"));
        assert!(code_matches("*", "X"));
        assert!(!code_matches("?", "XY"));
    }
}
