//! `[model] kind = "lumped"`: a driven lumped system ([`impactcal_models::lumped`]) whose
//! file `[model] file` names, driven by each test's own input channel (the file's `[base]
//! channel`).
//!
//! ```toml
//! [model]
//! kind = "lumped"
//! file = "board.toml"
//!
//! [test]
//! data = "drop1.csv"
//! repeats = ["drop2.csv"]   # further tests of the same article, calibrated on together
//!
//! [holdout]                 # optional: as many tests as the calibration set
//! data = "drop3.csv"
//! repeats = ["drop4.csv"]
//! ```
//!
//! The model is [`LumpedRepeats`]: the calibration tests side by side (labels `r<k>/<channel>`
//! when there are several, the channel's own label otherwise), the holdout tests at the
//! condition [`REPEAT_SET`]` = 1`, which the loop's holdout is given. The measured side is
//! the same tests' output channels, labelled alike ([`measured`]); with two or more
//! calibration tests the scatter between them is measured channel by channel and reported.
//!
//! Refused, naming the file and the key: no `[model] file`; `set` or `end_time` in
//! `[model]`, `[space]`, `[parameters]`, `[candidates]` or `[held]` (the lumped file declares
//! the stiffnesses and damping ratios, the model lists its own candidates); a `[test] map`
//! (the outputs carry the test's channel names); a `[holdout] set` (a lumped test's
//! condition is its input); `file` or `repeats` with any other model.

use std::path::{Path, PathBuf};

use impactcal_core::Histories;
use impactcal_core::quality::{QualityOptions, check};
use impactcal_models::lumped::{
    ChannelScatter, LumpedRepeats, LumpedSystem, REPEAT_SET, alignment, scatter,
};
use impactcal_runner::fingerprint;

use crate::error::{ExperimentError, Result, io};
use crate::model::{Built, ExperimentModel, resolve};
use crate::read_test;
use crate::schema::ExperimentFile;

/// The `[model] kind` of a lumped system.
pub const KIND: &str = "lumped";

/// Tests as read: `(path, record)` each, the base channel repaired.
type Tests = Vec<(String, Histories)>;

/// What a file says of a lumped model: its system file and its tests, as written
/// (relative to the file).
#[derive(Debug, Clone, PartialEq)]
pub struct LumpedSpec {
    /// The lumped system's file.
    pub file: PathBuf,
    /// The calibration tests: `[test] data`, then `[test] repeats`.
    pub tests: Vec<PathBuf>,
    /// The holdout tests: `[holdout] data`, then `[holdout] repeats` (empty without
    /// `[holdout]`).
    pub holdout: Vec<PathBuf>,
}

/// The measured side of a lumped experiment.
#[derive(Debug, Clone)]
pub struct LumpedMeasured {
    /// The calibration tests' output channels, labelled as the model labels them.
    pub test: Histories,
    /// The holdout tests' likewise, with their condition (`repeat_set = 1`).
    pub holdout: Option<(Histories, Vec<(String, f64)>)>,
    /// The scatter between the calibration tests, per output channel (empty for one test),
    /// the tests aligned in time on their base channel.
    pub scatter: Vec<ChannelScatter>,
    /// The time (s) by which each calibration test triggered later than the first, read
    /// from the base channel ([`impactcal_models::lumped::alignment`]; empty for one test).
    pub shifts: Vec<f64>,
}

fn fault(name: &str, message: impl std::fmt::Display) -> ExperimentError {
    ExperimentError::File {
        file: name.to_string(),
        message: message.to_string(),
    }
}

/// Refuses what only a lumped model takes (`[model] file`, `[test] repeats`, `[holdout]
/// repeats`) in a file of another model, and a `[holdout]` without its `set`.
///
/// # Errors
/// [`ExperimentError::File`] naming the key.
pub(crate) fn refuse_elsewhere(f: &ExperimentFile, name: &str) -> Result<()> {
    let only = |key: &str| {
        fault(
            name,
            format!("{key} applies to `[model] kind = \"lumped\"`, not to this model"),
        )
    };
    if f.model.as_ref().is_some_and(|m| m.file.is_some()) {
        return Err(only("[model] file"));
    }
    if !f.test.repeats.is_empty() {
        return Err(only("[test] repeats"));
    }
    if let Some(h) = &f.holdout {
        if !h.repeats.is_empty() {
            return Err(only("[holdout] repeats"));
        }
        if h.set.is_empty() {
            return Err(fault(
                name,
                "[holdout] set: give the holdout's condition (`set = { v0 = 5.0 }`)",
            ));
        }
    }
    Ok(())
}

impl LumpedSpec {
    /// The spec of a parsed file whose `[model] kind` is `lumped`.
    ///
    /// # Errors
    /// [`ExperimentError::File`] for each refusal of the module docs.
    pub fn of(f: &ExperimentFile, name: &str) -> Result<LumpedSpec> {
        let m = f.model.clone().unwrap_or_default();
        let Some(file) = m.file else {
            return Err(fault(
                name,
                "[model] kind = \"lumped\" needs `file = \"system.toml\"`, the lumped system's \
                 file",
            ));
        };
        let declares = [
            (
                !m.set.is_empty() || m.end_time.is_some(),
                "[model] set and end_time",
            ),
            (
                f.space.preset.is_some() || f.space.bounds.is_some(),
                "[space]",
            ),
            (!f.parameters.is_empty(), "[parameters]"),
            (
                !f.candidates.is_empty() || !f.held.is_empty(),
                "[candidates] and [held]",
            ),
        ];
        if let Some((_, what)) = declares.iter().find(|(given, _)| *given) {
            return Err(fault(
                name,
                format!(
                    "{what}: not for a lumped model; its file declares the stiffnesses and \
                     damping ratios (with their ranges) and the model lists its own candidates"
                ),
            ));
        }
        if f.test.map.is_some() {
            return Err(fault(
                name,
                "[test] map: a lumped model's outputs carry the test channel names of its \
                 file's [outputs]; name them there",
            ));
        }
        let mut holdout = Vec::new();
        if let Some(h) = &f.holdout {
            if !h.set.is_empty() {
                return Err(fault(
                    name,
                    "[holdout] set: a lumped test's condition is its own input; name the \
                     holdout tests only",
                ));
            }
            holdout.push(h.data.clone());
            holdout.extend(h.repeats.iter().cloned());
        }
        let Some(first) = &f.test.data else {
            return Err(fault(
                name,
                "[test] data: missing (the first calibration test of the lumped system)",
            ));
        };
        let mut tests = vec![first.clone()];
        tests.extend(f.test.repeats.iter().cloned());
        Ok(LumpedSpec {
            file,
            tests,
            holdout,
        })
    }

    /// Reads the system file and every test, each relative to `base`.
    fn read(&self, base: &Path, notes: &mut Vec<String>) -> Result<(LumpedSystem, [Tests; 2])> {
        let system = LumpedSystem::read(resolve(base, &self.file))?;
        let mut read = |paths: &[PathBuf]| -> Result<Tests> {
            paths
                .iter()
                .map(|p| {
                    let p = resolve(base, p);
                    let name = p.display().to_string();
                    let record = read_test(&p, notes)?;
                    let record = driving(&record, &system.base_channel, &name, notes)?;
                    Ok((name, record))
                })
                .collect()
        };
        let sets = [read(&self.tests)?, read(&self.holdout)?];
        Ok((system, sets))
    }

    /// Builds the model: the system driven by each test.
    ///
    /// # Errors
    /// The system file's and the tests' read errors; what [`LumpedRepeats::new`] refuses
    /// (a holdout set of another size, tests of different windows, a base channel missing
    /// or not finite), naming the test.
    pub fn build(&self, base: &Path) -> Result<Built> {
        let (system, [cal, hold]) = self.read(base, &mut Vec::new())?;
        let model = LumpedRepeats::new(&system, &as_refs(&cal), &as_refs(&hold))?;
        let mut bytes =
            std::fs::read(resolve(base, &self.file)).map_err(io(&resolve(base, &self.file)))?;
        for p in self.tests.iter().chain(&self.holdout) {
            let p = resolve(base, p);
            bytes.extend(std::fs::read(&p).map_err(io(&p))?);
        }
        Ok(Built {
            space: impactcal_core::Model::space(&model).clone(),
            model: Some(ExperimentModel::Lumped(Box::new(model))),
            description: format!(
                "lumped {} on {} calibration and {} holdout tests ({})",
                self.file.display(),
                self.tests.len(),
                self.holdout.len(),
                fingerprint(&bytes)
            ),
            geometry: None,
            notes: Vec::new(),
        })
    }
}

/// The measured side of `spec` (paths relative to `base`): each set's output channels of
/// the system, labelled as the model labels them ([`impactcal_models::lumped::repeat_label`]), and the scatter
/// between the calibration tests; what the readers notice goes to `notes`.
///
/// # Errors
/// The readers' errors; a test lacking an output channel (naming the test); tests of
/// different windows.
pub fn measured(spec: &LumpedSpec, base: &Path, notes: &mut Vec<String>) -> Result<LumpedMeasured> {
    let (system, [cal, hold]) = spec.read(base, notes)?;
    let outputs: Vec<String> = system.outputs.iter().map(|o| o.channel.clone()).collect();
    let side_by_side = |set: &[(String, Histories)]| -> Result<Histories> {
        Ok(impactcal_models::lumped::side_by_side(
            &as_refs(set),
            &outputs,
        )?)
    };
    let test = side_by_side(&cal)?;
    let holdout = if hold.is_empty() {
        None
    } else {
        Some((side_by_side(&hold)?, vec![(REPEAT_SET.to_string(), 1.0)]))
    };
    let (scatter, shifts) = if cal.len() >= 2 {
        let shifts = alignment(&as_refs(&cal), &system.base_channel)?;
        (scatter(&as_refs(&cal), &outputs, &shifts)?, shifts)
    } else {
        (Vec::new(), Vec::new())
    };
    Ok(LumpedMeasured {
        test,
        holdout,
        scatter,
        shifts,
    })
}

/// A line with the calibration tests' shifts, then a line per channel of the scatter
/// between them, for the notes of a study or loop.
pub fn scatter_notes(scatter: &[ChannelScatter], shifts: &[f64]) -> Vec<String> {
    let aligned = (shifts.len() >= 2).then(|| {
        format!(
            "calibration tests aligned on their input before their scatter: each triggered \
             later than the first by {} us",
            shifts
                .iter()
                .map(|s| format!("{:.2}", s * 1e6))
                .collect::<Vec<_>>()
                .join(", ")
        )
    });
    aligned
        .into_iter()
        .chain(scatter.iter().map(|s| {
            format!(
                "scatter between the {} calibration tests, `{}`: RMS {:.4} ({:.1} % of the \
                 repeats' RMS)",
                s.repeats,
                s.channel,
                s.rms,
                100.0 * s.relative
            )
        }))
        .collect()
}

/// `record` with its base channel `base` checked as `impactcal check` checks a channel and
/// repaired ([`impactcal_core::quality::RecordQuality::repaired`]): its offset (the mean
/// of its quiet part before the drop) removed, its clipped samples and spikes bridged
/// linearly between their neighbours, since the model integrates the input and a spike or
/// an offset in it would drive the system as if it were motion. What is repaired goes to
/// `notes`. A record without the base channel is returned as it is (the model names it).
///
/// # Errors
/// The quality check's errors on the channel.
fn driving(
    record: &Histories,
    base: &str,
    name: &str,
    notes: &mut Vec<String>,
) -> Result<Histories> {
    let Some(c) = record.index_of(base) else {
        return Ok(record.clone());
    };
    let input = record.select(&[base])?;
    let quality = check(&input, &QualityOptions::default())?;
    let repaired = quality.repaired(&input)?;
    let masked = quality.masked_count();
    if masked > 0 {
        notes.push(format!(
            "{name}: input `{base}`: {masked} clipped or spiked samples bridged before it              drives the model"
        ));
    }
    let channels = (0..record.channels())
        .map(|k| {
            if k == c {
                repaired.channel(0).to_vec()
            } else {
                record.channel(k).to_vec()
            }
        })
        .collect();
    Ok(Histories::from_channels(
        record.labels().to_vec(),
        channels,
        record.dt(),
        record.start(),
        record.unit(),
    )?)
}

/// `(name, histories)` pairs as borrowed pairs.
fn as_refs(set: &[(String, Histories)]) -> Vec<(&str, &Histories)> {
    set.iter().map(|(n, h)| (n.as_str(), h)).collect()
}
