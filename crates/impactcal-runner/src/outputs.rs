//! Reading a run's output back as [`Histories`]: our wide CSV, LS-DYNA's ASCII `nodout`, or
//! a CSV whose time and channel columns the user names.
//!
//! Time bases: our CSV must be uniform (as everywhere in the workspace). LS-DYNA writes a
//! `nodout` block at the first cycle past each output interval, so its time stamps stray by
//! up to one solver step; a `nodout`, `binout` or user CSV whose steps are not uniform is
//! put on the uniform base of their mean step by linear interpolation (same number of
//! samples, same first and last time), or of the smallest step when the steps differ by
//! more than half of it (an output interval that changed during the run), with a note.
//!
//! The `nodout` layout read here is the one LS-DYNA documents and its `l2a` translator
//! writes: a block per output time headed `n o d a l   p r i n t   o u t   f o r   t i m e
//! s t e p <cycle> ( at time <t> )`, then a column line `nodal point  x-disp ... z-coor`,
//! then one line per node: the node id (10 columns) and twelve numbers (12 columns each):
//! displacement, velocity, acceleration and coordinates in x, y, z. A second block per time
//! with rotations (`nodal point  x-rot ...`) is skipped. An optional `{BEGIN LEGEND}` ...
//! `{END LEGEND}` section is skipped. Fortran numbers without an `E` (`1.2345-100`) are read.

use std::path::{Path, PathBuf};

use impactcal_core::{CoreError, Histories, NodalQuantity, Table, TableOptions};
use serde::{Deserialize, Serialize};

use crate::error::{Result, RunnerError};

/// The format of a solver's output file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum OutputFormat {
    /// Our wide CSV (`time,<label>,...`), as `impactcal simulate --out` writes it.
    #[default]
    Csv,
    /// LS-DYNA's ASCII `nodout`.
    Nodout,
    /// A branch of LS-DYNA's `binout` (LSDA) files ([`crate::binout`]): `branch` and
    /// `channels` name what to read.
    Binout,
    /// A CSV with a header, its time column and channel columns named in the configuration.
    UserCsv,
}

/// Where a run's output is and how to read it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// The format.
    #[serde(default)]
    pub format: OutputFormat,
    /// The file, relative to the run's work directory.
    pub file: String,
    /// `nodout`: the quantity (velocity by default).
    #[serde(default)]
    pub quantity: NodalQuantity,
    /// `nodout`: the nodes to keep (all by default), in this order.
    #[serde(default)]
    pub nodes: Option<Vec<u64>>,
    /// `binout`: the branch (`nodout`, `glstat`, `matsum`, `rwforc/forces`, ...).
    #[serde(default)]
    pub branch: Option<String>,
    /// `binout`: the channels, variable names or `<id>.<variable>` labels (all by default).
    #[serde(default)]
    pub channels: Option<Vec<String>>,
    /// `user-csv`: the time column (`time` by default).
    #[serde(default)]
    pub time_column: Option<String>,
    /// `user-csv`: the channel columns to keep (all others by default), in this order.
    #[serde(default)]
    pub columns: Option<Vec<String>>,
    /// The time the output must reach; an output that ends earlier (by more than half a
    /// step) is reported as truncated.
    #[serde(default)]
    pub end_time: Option<f64>,
    /// The unit given to the histories read back (none of the formats carries one); empty
    /// by default.
    #[serde(default)]
    pub unit: Option<String>,
}

impl OutputSpec {
    /// Our wide CSV in `file`.
    pub fn csv(file: impl Into<String>) -> Self {
        OutputSpec {
            format: OutputFormat::Csv,
            file: file.into(),
            quantity: NodalQuantity::default(),
            nodes: None,
            branch: None,
            channels: None,
            time_column: None,
            columns: None,
            end_time: None,
            unit: None,
        }
    }

    /// Checks the specification: a relative file inside the work directory, a positive end
    /// time.
    ///
    /// # Errors
    /// [`RunnerError::Config`] naming the field.
    pub fn check(&self, file: &str) -> Result<()> {
        let p = Path::new(&self.file);
        let inside = !self.file.is_empty()
            && p.is_relative()
            && p.components()
                .all(|c| matches!(c, std::path::Component::Normal(_)));
        if !inside {
            return Err(RunnerError::Config {
                file: file.into(),
                message: format!(
                    "output file `{}` must be a relative path inside the run's directory",
                    self.file
                ),
            });
        }
        if self.format == OutputFormat::Binout && self.branch.as_deref().is_none_or(str::is_empty) {
            return Err(RunnerError::Config {
                file: file.into(),
                message: "output format `binout` needs `branch` (for example \"nodout\")".into(),
            });
        }
        if let Some(t) = self.end_time {
            if !(t.is_finite() && t > 0.0) {
                return Err(RunnerError::Config {
                    file: file.into(),
                    message: format!("output end_time {t} must be finite and positive"),
                });
            }
        }
        Ok(())
    }

    /// Reads the output of run `run` from its work directory `dir`.
    ///
    /// # Errors
    /// [`RunnerError::Output`] naming the run and the file: missing, empty, malformed (with
    /// the line), truncated (a `nodout` time step with fewer nodes than the first, a last
    /// record cut short, an end before `end_time`), or nodes/columns that are not there.
    pub fn read(&self, run: usize, dir: &Path) -> Result<Histories> {
        let path = dir.join(&self.file);
        let fail = |message: String| RunnerError::Output {
            run,
            path: path.clone(),
            message,
        };
        if self.format == OutputFormat::Binout {
            if !path.exists() {
                return Err(fail("the solver wrote no output file".into()));
            }
            let b = crate::binout::Binout::open(&path).map_err(|e| fail(e.to_string()))?;
            let (h, _) = b
                .histories(
                    self.branch.as_deref().unwrap_or(""),
                    self.channels.as_deref().unwrap_or(&[]),
                )
                .map_err(|e| fail(e.to_string()))?;
            return self.finish(h, fail);
        }
        let text = match std::fs::read(&path) {
            Ok(bytes) => String::from_utf8_lossy(&bytes).into_owned(),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(fail("the solver wrote no output file".into()));
            }
            Err(e) => return Err(fail(format!("cannot read: {e}"))),
        };
        if text.trim().is_empty() {
            return Err(fail("the output file is empty".into()));
        }
        let name = path.display().to_string();
        let h = match self.format {
            OutputFormat::Csv => Histories::parse_csv(&text, &name).map_err(|e| fail(position(e))),
            OutputFormat::Nodout => parse_nodout(&text, self.quantity, self.nodes.as_deref())
                .map(|(h, _)| h)
                .map_err(|(line, m)| fail(format!("line {line}: {m}"))),
            OutputFormat::UserCsv => self.parse_user_csv(&text, &name).map_err(fail),
            OutputFormat::Binout => Err(fail("binout is not text".into())),
        }?;
        self.finish(h, fail)
    }

    /// The end-time check and the unit of histories read back.
    fn finish(&self, h: Histories, fail: impl Fn(String) -> RunnerError) -> Result<Histories> {
        if let Some(end) = self.end_time {
            let last = h.start() + (h.samples() - 1) as f64 * h.dt();
            if last < end - 0.5 * h.dt() {
                return Err(fail(format!(
                    "truncated: the output ends at t = {last:e}, before the expected end time {end:e}"
                )));
            }
        }
        Ok(match &self.unit {
            Some(u) => h.with_unit(u.clone()),
            None => h,
        })
    }

    fn parse_user_csv(&self, text: &str, name: &str) -> std::result::Result<Histories, String> {
        let table = Table::parse(text, name, TableOptions::default()).map_err(position)?;
        let time = self.time_column.as_deref().unwrap_or("time");
        let header = table.header();
        let channel_names: Vec<&str> = match &self.columns {
            Some(c) => c.iter().map(String::as_str).collect(),
            None => header
                .iter()
                .map(String::as_str)
                .filter(|h| *h != time)
                .collect(),
        };
        let mut wanted = vec![time];
        wanted.extend(&channel_names);
        let missing: Vec<&str> = wanted
            .iter()
            .copied()
            .filter(|w| table.column_index(w).is_none())
            .collect();
        if !missing.is_empty() {
            return Err(format!(
                "no column{} `{}` (the header has: {})",
                if missing.len() > 1 { "s" } else { "" },
                missing.join("`, `"),
                header.join(", ")
            ));
        }
        let col = |n: &str| table.column_index(n).unwrap_or(0);
        let times: Vec<f64> = table.rows().iter().map(|r| r[col(time)]).collect();
        let channels: Vec<Vec<f64>> = channel_names
            .iter()
            .map(|n| table.rows().iter().map(|r| r[col(n)]).collect())
            .collect();
        let labels = channel_names.iter().map(|s| s.to_string()).collect();
        uniform(labels, &times, channels, table.lines())
            .map(|(h, _)| h)
            .map_err(|(l, m)| format!("row {l}: {m}"))
    }
}

/// A CSV error as `row r, column c: message` (the path is said once, by the caller).
fn position(e: CoreError) -> String {
    match e {
        CoreError::Csv {
            row,
            column,
            message,
            ..
        } => format!("row {row}, column {column}: {message}"),
        CoreError::File { message, .. } => message,
        other => other.to_string(),
    }
}

/// Histories from channels at `times`, resampled when the steps are not uniform, with a
/// note saying so. `lines` gives the source line of each time for messages.
pub(crate) fn uniform(
    labels: Vec<String>,
    times: &[f64],
    channels: Vec<Vec<f64>>,
    lines: &[usize],
) -> std::result::Result<(Histories, Option<String>), (usize, String)> {
    let first = lines.first().copied().unwrap_or(1);
    if times.len() < 2 {
        return Err((first, "need at least two output times".into()));
    }
    for k in 1..times.len() {
        if times[k] <= times[k - 1] {
            return Err((
                lines[k],
                format!(
                    "time {} does not increase (previous {})",
                    times[k],
                    times[k - 1]
                ),
            ));
        }
    }
    let n = times.len();
    let mean = (times[n - 1] - times[0]) / (n - 1) as f64;
    let is_uniform = times
        .windows(2)
        .all(|w| ((w[1] - w[0]) - mean).abs() <= 1e-6 * mean);
    let (lo, hi) = times
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold((f64::INFINITY, 0.0_f64), |(a, b), d| (a.min(d), b.max(d)));
    let (channels, dt, note) = if is_uniform {
        (channels, mean, None)
    } else if hi <= 1.5 * lo {
        // Steps that stray by a solver step about one output interval: their mean, which
        // keeps the number of samples and the first and last times.
        let c = resample_at(times, &channels, mean);
        let note = format!(
            "output steps from {lo:e} to {hi:e}: resampled by linear interpolation onto their mean {mean:e} ({} samples)",
            c.first().map_or(0, Vec::len)
        );
        (c, mean, Some(note))
    } else {
        // Output intervals that changed during the run: the smallest keeps every value,
        // unless that would make far more samples than the file holds (times that are not
        // output times: a corrupt file), which is refused before anything is allocated.
        let samples = ((times[n - 1] - times[0]) / lo).min(1e18).floor() + 1.0;
        let values = samples * channels.len().max(1) as f64;
        if samples > 100.0 * n as f64 + 1000.0 || values > 5e7 {
            return Err((
                first,
                format!(
                    "output steps from {lo:e} to {hi:e}: the smallest step would give {samples:e} samples for {n} output times (the times look corrupt)"
                ),
            ));
        }
        let c = resample_at(times, &channels, lo);
        let note = format!(
            "output steps from {lo:e} to {hi:e} (the interval changed during the run): resampled by linear interpolation onto the smallest step ({} samples)",
            c.first().map_or(0, Vec::len)
        );
        (c, lo, Some(note))
    };
    Histories::from_channels(labels, channels, dt, times[0], "")
        .map(|h| (h, note))
        .map_err(|e| (first, e.to_string()))
}

/// Linear interpolation of `channels` at `times[0] + k dt` for every `k` up to the last time
/// (within `1e-9` of a step).
fn resample_at(times: &[f64], channels: &[Vec<f64>], dt: f64) -> Vec<Vec<f64>> {
    let span = times[times.len() - 1] - times[0];
    let n = (span / dt + 1e-9).floor() as usize + 1;
    channels
        .iter()
        .map(|c| {
            (0..n)
                .map(|k| {
                    let t = times[0] + k as f64 * dt;
                    let j = times.partition_point(|&x| x <= t).clamp(1, times.len() - 1);
                    let (t0, t1) = (times[j - 1], times[j]);
                    let s = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
                    c[j - 1] + s * (c[j] - c[j - 1])
                })
                .collect()
        })
        .collect()
}

/// A number as LS-DYNA's Fortran output writes it: `1.2345E-03`, or `1.2345-100` when the
/// exponent takes three digits.
fn fortran_number(s: &str) -> Option<f64> {
    if let Ok(v) = s.parse::<f64>() {
        return Some(v);
    }
    let body = s.strip_prefix(['-', '+']).unwrap_or(s);
    let split = body.rfind(['-', '+']).filter(|&p| p > 0)?;
    let offset = s.len() - body.len();
    let (mantissa, exponent) = s.split_at(offset + split);
    format!("{mantissa}e{exponent}").parse().ok()
}

/// The numbers of a line of LS-DYNA's fixed-width output, which may run together
/// (`0.00000E+00-1.50000E+00` is two numbers) and may drop the exponent letter
/// (`-1.5000-345`): each number is an optional sign, digits with a decimal point, and an
/// optional exponent (a letter `E`/`D` and signed digits, or a sign and digits right after
/// the mantissa).
fn scan_numbers(s: &str) -> std::result::Result<Vec<f64>, String> {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    let digits = |mut i: usize| {
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        i
    };
    while i < b.len() {
        if b[i] == b' ' || b[i] == b'\t' {
            i += 1;
            continue;
        }
        let start = i;
        if b[i] == b'+' || b[i] == b'-' {
            i += 1;
        }
        let m0 = i;
        i = digits(i);
        if i < b.len() && b[i] == b'.' {
            i = digits(i + 1);
        }
        if i == m0 || (i == m0 + 1 && b[m0] == b'.') {
            return Err(format!("`{}` is not a number", &s[start..]));
        }
        let mantissa = &s[start..i];
        let mut exponent = String::new();
        if i < b.len() && matches!(b[i], b'E' | b'e' | b'D' | b'd') {
            let e0 = i + 1;
            let mut j = e0;
            if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
                j += 1;
            }
            let k = digits(j);
            if k == j {
                return Err(format!("`{}` has an exponent without digits", &s[start..k]));
            }
            exponent = s[e0..k].to_string();
            i = k;
        } else if i + 1 < b.len()
            && (b[i] == b'+' || b[i] == b'-')
            && b[i + 1].is_ascii_digit()
            && mantissa.contains('.')
        {
            let k = digits(i + 1);
            exponent = s[i..k].to_string();
            i = k;
        }
        let text = if exponent.is_empty() {
            mantissa.to_string()
        } else {
            format!("{mantissa}e{exponent}")
        };
        out.push(
            text.parse::<f64>()
                .map_err(|_| format!("`{}` is not a number", &s[start..i]))?,
        );
    }
    Ok(out)
}

/// One output time of a `nodout` file: its header line, its time, and (node, x/y/z) in file
/// order.
type Step = (usize, f64, Vec<(u64, [f64; 3])>);

/// Parses a `nodout` file into the chosen quantity of the chosen nodes. Errors carry the
/// 1-based line.
fn parse_nodout(
    text: &str,
    quantity: NodalQuantity,
    nodes: Option<&[u64]>,
) -> std::result::Result<(Histories, Option<String>), (usize, String)> {
    #[derive(PartialEq)]
    enum Block {
        None,
        Translation,
        Other,
    }
    let offset = match quantity {
        NodalQuantity::Displacement => 0,
        NodalQuantity::Velocity => 3,
        NodalQuantity::Acceleration => 6,
    };
    // Per output time: its line, its time, and (node, xyz) in file order.
    let mut steps: Vec<Step> = Vec::new();
    let mut block = Block::None;
    let mut legend = false;
    for (i, line) in text.lines().enumerate() {
        let n = i + 1;
        let trimmed = line.trim();
        if trimmed.starts_with("{BEGIN LEGEND}") {
            legend = true;
            continue;
        }
        if legend {
            legend = !trimmed.starts_with("{END LEGEND}");
            continue;
        }
        if trimmed.starts_with("n o d a l   p r i n t   o u t") {
            let time = trimmed
                .split_once("at time")
                .and_then(|(_, rest)| fortran_number(rest.trim().trim_end_matches(')').trim()))
                .ok_or((
                    n,
                    "a time-step header without a readable `at time`".to_string(),
                ))?;
            // The rotation block repeats the header of the same time step.
            if steps.last().is_none_or(|s| s.1.to_bits() != time.to_bits()) {
                steps.push((n, time, Vec::new()));
            }
            block = Block::None;
            continue;
        }
        if trimmed.starts_with("nodal point") {
            block = if trimmed.contains("x-disp") {
                Block::Translation
            } else {
                Block::Other
            };
            continue;
        }
        if trimmed.is_empty() {
            block = Block::None;
            continue;
        }
        if block != Block::Translation {
            continue;
        }
        let (id, rest) = trimmed
            .split_once(char::is_whitespace)
            .unwrap_or((trimmed, ""));
        let node: u64 = id
            .parse()
            .map_err(|_| (n, format!("node id `{id}` is not a whole number")))?;
        let values = scan_numbers(rest).map_err(|m| (n, m))?;
        if values.len() < 12 {
            return Err((
                n,
                format!(
                    "a node record with {} of 13 fields (truncated?)",
                    values.len() + 1
                ),
            ));
        }
        let mut xyz = [0.0; 3];
        for (c, v) in xyz.iter_mut().enumerate() {
            *v = values[offset + c];
            if !v.is_finite() {
                return Err((
                    n,
                    format!("value {} of node {node} is not finite", offset + c + 1),
                ));
            }
        }
        if let Some(step) = steps.last_mut() {
            step.2.push((node, xyz));
        }
    }
    let Some(first) = steps.first() else {
        return Err((1, "no time step (not a nodout file?)".into()));
    };
    let all: Vec<u64> = first.2.iter().map(|(id, _)| *id).collect();
    if all.is_empty() {
        return Err((first.0, "the first time step lists no node".into()));
    }
    for (line, _, rows) in &steps {
        let ids: Vec<u64> = rows.iter().map(|(id, _)| *id).collect();
        if ids != all {
            return Err((
                *line,
                format!(
                    "this time step lists {} nodes where the first lists {} (truncated or mixed output)",
                    ids.len(),
                    all.len()
                ),
            ));
        }
    }
    let chosen: Vec<usize> = match nodes {
        None => (0..all.len()).collect(),
        Some(want) => {
            let mut idx = Vec::new();
            for w in want {
                let Some(k) = all.iter().position(|a| a == w) else {
                    let list: Vec<String> = all.iter().map(u64::to_string).collect();
                    return Err((
                        first.0,
                        format!("node {w} is not in the file (nodes: {})", list.join(", ")),
                    ));
                };
                idx.push(k);
            }
            idx
        }
    };
    let mut labels = Vec::new();
    let mut channels = Vec::new();
    for &k in &chosen {
        for (c, axis) in ["x", "y", "z"].iter().enumerate() {
            labels.push(format!("{}.{axis}", all[k]));
            channels.push(steps.iter().map(|s| s.2[k].1[c]).collect());
        }
    }
    let times: Vec<f64> = steps.iter().map(|s| s.1).collect();
    let lines: Vec<usize> = steps.iter().map(|s| s.0).collect();
    uniform(labels, &times, channels, &lines)
}

/// Reads an ASCII `nodout` file: the `quantity` of the `nodes` (all by default) as
/// histories labelled `<node>.<x|y|z>`, on a uniform time base, with a note when the output
/// times had to be resampled (see the module docs).
///
/// # Errors
/// [`RunnerError::Io`] when the file cannot be read; [`RunnerError::Result`] naming the
/// line of a malformed, truncated or mixed record or a node that is not in the file.
pub fn read_nodout(
    path: &Path,
    quantity: NodalQuantity,
    nodes: Option<&[u64]>,
) -> Result<(Histories, Option<String>)> {
    let bytes = std::fs::read(path).map_err(crate::error::io(path))?;
    let text = String::from_utf8_lossy(&bytes);
    parse_nodout(&text, quantity, nodes).map_err(|(line, m)| RunnerError::Result {
        path: path.to_path_buf(),
        message: format!("line {line}: {m}"),
    })
}

/// The path of the output of a run in `dir`.
pub fn output_path(spec: &OutputSpec, dir: &Path) -> PathBuf {
    dir.join(&spec.file)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `nodout` in LS-DYNA's documented layout (the `l2a` translator's formats: node id in
    /// 9 columns, the first number in 13, the others in 12, scientific with 4 decimals).
    /// `value` as C's `%w.dE` writes it: `d.ddddE+XX`, right-aligned in `w` columns.
    fn e(value: f64, w: usize, d: usize) -> String {
        let s = format!("{value:.d$E}");
        let (m, x) = s.split_once('E').unwrap();
        let x: i32 = x.parse().unwrap();
        let sign = if x < 0 { '-' } else { '+' };
        format!("{:>w$}", format!("{m}E{sign}{:02}", x.abs()))
    }

    fn nodout(times: &[f64], nodes: &[u64], value: impl Fn(f64, u64, usize) -> f64) -> String {
        let mut s = String::from(
            " ls-dyna R13.1.1     date 11/24/2026\n\n{BEGIN LEGEND}\n Entity #        Title\n       21     tip\n{END LEGEND}\n",
        );
        for (k, &t) in times.iter().enumerate() {
            let header = format!(
                "\n\n\n n o d a l   p r i n t   o u t   f o r   t i m e  s t e p{:8}                              ( at time{} )\n",
                10 * k + 1,
                e(t, 14, 7)
            );
            s += &header;
            s += "\n nodal point  x-disp     y-disp      z-disp      x-vel       y-vel       z-vel      x-accl      y-accl      z-accl      x-coor      y-coor      z-coor\n";
            for &n in nodes {
                s += &format!("{n:9}{}", e(value(t, n, 0), 13, 4));
                for c in 1..12 {
                    s += &e(value(t, n, c), 12, 4);
                }
                s += "\n";
            }
            s += &header;
            s += "\n nodal point  x-rot      y-rot       z-rot      x-rot vel   y-rot vel   z-rot vel   x-rot acc   y-rot acc   z-rot acc\n";
            for &n in nodes {
                s += &format!("{n:9}{}", e(9.0, 13, 4));
                for _ in 1..9 {
                    s += &e(9.0, 12, 4);
                }
                s += "\n";
            }
        }
        s
    }

    fn v(t: f64, n: u64, c: usize) -> f64 {
        // Column c of node n: displacement = 100 t^2, velocity = 200 t, accel = 200.
        let base = match c / 3 {
            0 => 100.0 * t * t,
            1 => 200.0 * t,
            2 => 200.0,
            _ => 0.5,
        };
        base * (1.0 + c as f64 % 3.0) + n as f64 * 1e-3
    }

    #[test]
    fn nodout_reads_the_documented_layout() {
        let times: Vec<f64> = (0..6).map(|k| k as f64 * 1e-4).collect();
        let text = nodout(&times, &[21, 42], v);
        let (h, _) = parse_nodout(&text, NodalQuantity::Velocity, None).unwrap();
        assert_eq!(h.labels(), ["21.x", "21.y", "21.z", "42.x", "42.y", "42.z"]);
        assert_eq!(h.samples(), 6);
        assert!((h.dt() - 1e-4).abs() < 1e-12);
        // 42.y at t = 3e-4: 200 t * 2 + 0.042 written with 5 significant digits.
        let want = 200.0 * 3e-4 * 2.0 + 0.042;
        assert!(
            (h.value(4, 3) - want).abs() < 1e-4 * want,
            "{}",
            h.value(4, 3)
        );
        let (d, _) = parse_nodout(&text, NodalQuantity::Displacement, Some(&[42])).unwrap();
        assert_eq!(d.labels(), ["42.x", "42.y", "42.z"]);
        let e = parse_nodout(&text, NodalQuantity::Velocity, Some(&[7])).unwrap_err();
        assert!(e.1.contains("node 7 is not in the file"), "{e:?}");
    }

    #[test]
    fn nodout_truncation_and_jitter() {
        let times: Vec<f64> = (0..5).map(|k| k as f64 * 1e-4).collect();
        let text = nodout(&times, &[1, 2, 3], v);
        // Cut inside the last step's node lines: that step lists fewer nodes.
        let rotation = text.rfind(" n o d a l").unwrap();
        let translation = text[..rotation].rfind(" n o d a l").unwrap();
        let cut = translation + text[translation..].find("        2 ").unwrap();
        let e = parse_nodout(&text[..cut + 40], NodalQuantity::Velocity, None).unwrap_err();
        assert!(e.1.contains("fields (truncated?)"), "{e:?}");
        let e = parse_nodout(&text[..cut], NodalQuantity::Velocity, None).unwrap_err();
        assert!(
            e.1.contains("lists 1 nodes where the first lists 3"),
            "{e:?}"
        );
        // Output times a solver step late: resampled onto the mean step.
        let late = [0.0, 1.02e-4, 2.01e-4, 3.03e-4, 4.0e-4];
        let (h, note) =
            parse_nodout(&nodout(&late, &[1], v), NodalQuantity::Velocity, None).unwrap();
        assert!(note.unwrap().contains("resampled"));
        assert!((h.dt() - 1e-4).abs() < 3e-6, "{}", h.dt());
        // Velocity is linear in t, so the interpolated samples stay on the line.
        for k in 0..h.samples() {
            let t = k as f64 * h.dt();
            assert!((h.value(0, k) - (200.0 * t + 1e-3)).abs() < 1e-3, "{k}");
        }
        assert_eq!(fortran_number("1.2345-100"), Some(1.2345e-100));
        assert_eq!(fortran_number("-2.00000-3"), Some(-2e-3));
    }

    #[test]
    fn user_csv_by_named_columns() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("o.csv"),
            "step,t,acc,vel\n0,0,1,2\n1,0.5,3,4\n2,1.0,5,6\n",
        )
        .unwrap();
        let mut spec = OutputSpec::csv("o.csv");
        spec.format = OutputFormat::UserCsv;
        spec.time_column = Some("t".into());
        spec.columns = Some(vec!["vel".into()]);
        let h = spec.read(4, dir.path()).unwrap();
        assert_eq!(h.labels(), ["vel"]);
        assert_eq!(h.channel(0), [2.0, 4.0, 6.0]);
        spec.columns = Some(vec!["vel".into(), "force".into()]);
        let e = spec.read(4, dir.path()).unwrap_err();
        assert!(e.to_string().starts_with("run 4: "), "{e}");
        assert!(e.to_string().contains("no column `force`"), "{e}");
        // Missing, empty, truncated (a ragged last row) and too short are all named.
        let e = OutputSpec::csv("none.csv").read(1, dir.path()).unwrap_err();
        assert!(
            e.to_string()
                .contains("none.csv: the solver wrote no output file"),
            "{e}"
        );
        std::fs::write(dir.path().join("cut.csv"), "time,a\n0,1\n1,2\n2,").unwrap();
        let e = OutputSpec::csv("cut.csv").read(1, dir.path()).unwrap_err();
        assert!(e.to_string().contains("row 4"), "{e}");
        std::fs::write(dir.path().join("short.csv"), "time,a\n0,1\n1,2\n").unwrap();
        let mut spec = OutputSpec::csv("short.csv");
        spec.end_time = Some(2.0);
        let e = spec.read(1, dir.path()).unwrap_err();
        assert!(e.to_string().contains("truncated"), "{e}");
        assert_eq!(e.kind(), impactcal_core::ErrorKind::Numerical);
    }
}
