//! The experiment file: one TOML schema for studies and closed loops, parsed in one place.
//!
//! ```toml
//! [model]                  # one of: airframe = "coarse" | deck = "model.k" | kind = "drop-tower"
//!                          # | kind = "kolsky-bar" with test = "copper.toml" (the bar test)
//!                          # | kind = "lumped" with file = "board.toml" (the lumped system)
//! airframe = "coarse"
//! file = "board.toml"      # kind = "lumped": the lumped system's file
//! end_time = 0.025         # airframe only (s)
//! set = { "ground.friction" = 0.3 }   # held values (airframe; the drop tower's condition)
//!
//! [parameters]             # decks: study names -> deck quantities (optional)
//! belly = "section.3.t"
//!
//! [space]                  # preset = "table1" | "table2" (airframe), or a bounds file
//! bounds = "bounds.csv"
//!
//! [test]
//! data = "test.csv"        # wide CSV or an ISO-MME data set
//! map = "map.csv"          # optional channel map
//! cfc = 60                 # optional CFC class
//! sigma = 0.5              # optional measurement noise; else measured on the test
//! repeats = ["drop3.csv"]  # kind = "lumped": further tests of the article, calibrated on too
//!
//! [holdout]                # the loop's holdout test at another condition
//! data = "holdout.csv"
//! set = { v0 = 5.0 }       # (kind = "lumped": none; each test's input is its condition)
//! repeats = ["drop4.csv"]  # kind = "lumped": as many holdout tests as calibration tests
//!
//! [solver]                 # instead of [model]: an external solver (deck template, command)
//! template = "deck.k"
//!
//! [candidates.damp]        # a template's (or parameterised deck's) held quantity the loop may free
//! lower = 0.0
//! upper = 1000.0
//! held = 0.0
//! description = "mass-proportional damping (1/s)"
//!
//! [held]                   # quantities the template holds at one value (test conditions)
//! vz = -5.0
//!
//! [executor]               # where runs happen: "local" (default) | "processes" | "slurm"
//! kind = "processes"
//! jobs = 2                 # default: the machine's cores
//! retries = 1              # further attempts of a failing run (default 2)
//!
//! [study]                  # StudyOptions: halton_runs, sensors, shapes, jitter_runs, ...
//! [loop]                   # LoopOptions: jitter_runs, reconcile_runs, recalibrate_runs, ...
//! ```
//!
//! Each word means one thing: `halton_runs` is the study's Halton ensemble, `jitter_runs`
//! and `jitter_eps` the jitter ensemble measuring the model's own noise (study and loop),
//! `cors_batch` the points CORS-RBF proposes at a time (study and loop), `[executor]
//! retries` the runner's further attempts. Every key is set in one place: a key of an
//! earlier schema is an error that names its new place ([`RENAMED`]), an unknown key one
//! that lists the closest names, each with its line.

use std::collections::BTreeMap;
use std::path::PathBuf;

use impactcal_calibrate::closeloop::LoopOptions;
use impactcal_calibrate::study::StudyOptions;
use impactcal_core::{CoreError, ParamGuard};
use impactcal_runner::config::{ExecutorTable, SolverSection};
use serde::Deserialize;
use toml::de::{DeTable, DeValue};

use crate::error::{ExperimentError, Result};

/// An experiment file as written: every section, typed.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExperimentFile {
    /// `[model]`: the built-in model (absent with `[solver]`).
    pub model: Option<ModelSection>,
    /// `[parameters]`: a deck's quantities under the experiment's names.
    #[serde(default)]
    pub parameters: BTreeMap<String, String>,
    /// `[space]`: the declared parameters.
    #[serde(default)]
    pub space: SpaceSection,
    /// `[test]`: the measured test (a Kolsky bar's is its own bar test, `[model] test`).
    #[serde(default)]
    pub test: TestSection,
    /// `[holdout]`: a test at another condition the loop never fits.
    pub holdout: Option<HoldoutSection>,
    /// `[solver]`: an external solver instead of `[model]`.
    pub solver: Option<SolverSection>,
    /// `[executor]`: where the runs happen (default: in this process) and the runner's
    /// retries: the runner's own table, as in a batch file.
    pub executor: Option<ExecutorTable>,
    /// `[study]`: the study's options.
    #[serde(default)]
    pub study: StudyOptions,
    /// `[loop]`: the closed loop's options.
    #[serde(default, rename = "loop")]
    pub loop_options: LoopOptions,
    /// `[candidates.<name>]`: the held quantities of a deck template (or a parameterised
    /// deck) that the closed loop may free, each with its admissible range and held value.
    #[serde(default)]
    pub candidates: BTreeMap<String, CandidateSection>,
    /// `[held]`: quantities the template holds at one value (a test condition such as the
    /// impact speed), which a holdout's `set` may change.
    #[serde(default)]
    pub held: BTreeMap<String, f64>,
}

/// `[candidates.<name>]`: a held quantity the closed loop may add to the model.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CandidateSection {
    /// Lower end of its admissible range (where a fitted value is physical).
    pub lower: f64,
    /// Upper end of its admissible range.
    pub upper: f64,
    /// The value the model holds it at until the loop frees it.
    pub held: f64,
    /// What it is (in the loop's report).
    #[serde(default)]
    pub description: Option<String>,
}

/// `[model]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSection {
    /// A built-in model by name: `drop-tower`, `lumped`.
    pub kind: Option<String>,
    /// The model's own file (`kind = "lumped"`: the lumped system), relative to the file.
    pub file: Option<PathBuf>,
    /// The built-in airframe's mesh density (`coarse`, `medium`, `fine`).
    pub airframe: Option<String>,
    /// A keyword deck (relative to the file).
    pub deck: Option<PathBuf>,
    /// Simulated time of the airframe (s).
    pub end_time: Option<f64>,
    /// Held values: airframe quantities, or the drop tower's condition.
    #[serde(default)]
    pub set: BTreeMap<String, f64>,
    /// The bar test of `kind = "kolsky-bar"` in the neutral form (relative to the file).
    pub test: Option<PathBuf>,
}

/// `[space]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpaceSection {
    /// `table1` or `table2` (airframe).
    pub preset: Option<String>,
    /// A bounds file `name,lower,upper,nominal[,unit]` (relative to the file).
    pub bounds: Option<PathBuf>,
}

/// `[test]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TestSection {
    /// Wide CSV or an ISO-MME data set (relative to the file); required for every model
    /// but the Kolsky bar, whose measured signals are those of its bar test.
    pub data: Option<PathBuf>,
    /// Channel map `test_label,model_label[,gain]`.
    pub map: Option<PathBuf>,
    /// CFC class applied to the test and every run.
    pub cfc: Option<u32>,
    /// Measurement noise standard deviation of every channel (after the filter); default:
    /// measured on the test.
    pub sigma: Option<f64>,
    /// Further tests of the same article calibrated on with `data`, each with its own
    /// input (`kind = "lumped"`).
    #[serde(default)]
    pub repeats: Vec<PathBuf>,
}

/// `[holdout]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HoldoutSection {
    /// The holdout test's data (same map and filter as the test).
    pub data: PathBuf,
    /// Its condition, as held quantities of the model (required but for `kind =
    /// "lumped"`, whose tests' inputs are their conditions).
    #[serde(default)]
    pub set: BTreeMap<String, f64>,
    /// Further holdout tests of the same article (`kind = "lumped"`).
    #[serde(default)]
    pub repeats: Vec<PathBuf>,
}

/// The sections of a file and their keys (`None`: any key, as in `[parameters]`). Tables
/// below a key (`[solver.output]`) are checked by their own types.
pub const SECTIONS: &[(&str, Option<&[&str]>)] = &[
    (
        "model",
        Some(&[
            "kind", "file", "airframe", "deck", "end_time", "set", "test",
        ]),
    ),
    ("parameters", None),
    ("candidates", None),
    ("held", None),
    ("space", Some(&["preset", "bounds"])),
    ("test", Some(&["data", "map", "cfc", "sigma", "repeats"])),
    ("holdout", Some(&["data", "set", "repeats"])),
    (
        "solver",
        Some(&[
            "template", "deck", "inputs", "command", "quantity", "output",
        ]),
    ),
    (
        "executor",
        Some(&[
            "kind",
            "retries",
            "jobs",
            "timeout",
            "partition",
            "account",
            "time",
            "mem",
            "cpus_per_task",
            "max_running",
            "max_array",
            "poll",
            "sbatch_args",
            "bin",
        ]),
    ),
    (
        "study",
        Some(&[
            "halton_runs",
            "sensors",
            "shapes",
            "sensitivity_samples",
            "reconcile_runs",
            "cors_batch",
            "seed",
            "jitter_runs",
            "jitter_eps",
            "noise_fraction",
            "keep_unpredictable",
            "screen_only",
            "keep_all_channels",
        ]),
    ),
    (
        "loop",
        Some(&[
            "alpha",
            "min_explained",
            "max_added",
            "jitter_runs",
            "jitter_eps",
            "reconcile_runs",
            "recalibrate_runs",
            "polish",
            "cors_batch",
            "seed",
            "max_time_shift",
            "candidate_step",
            "units_tolerance",
            "candidates",
            "noise_band_cfc",
            "fit_gains",
            "m1_members",
            "keep_all_channels",
        ]),
    ),
];

/// Keys of earlier files, `(section, key, where it is now)`: each is an error naming its
/// new place, so that no old file runs with a value silently dropped or overridden.
pub const RENAMED: &[(&str, &str, &str)] = &[
    ("study", "ensemble", "[study] halton_runs"),
    ("study", "noise_runs", "[study] jitter_runs"),
    ("study", "noise_eps", "[study] jitter_eps"),
    ("study", "reconcile_batch", "[study] cors_batch"),
    ("study", "sigma", "[test] sigma"),
    ("loop", "ensemble", "[loop] jitter_runs"),
    ("loop", "jitter", "[loop] jitter_eps"),
    ("loop", "reconcile", "[loop] reconcile_runs"),
    ("loop", "recalibrate", "[loop] recalibrate_runs"),
    ("loop", "batch", "[loop] cors_batch"),
    ("loop", "sigma", "[test] sigma"),
    ("budget", "ensemble", "[loop] jitter_runs"),
    ("budget", "reconcile", "[loop] reconcile_runs"),
    ("budget", "recalibrate", "[loop] recalibrate_runs"),
    ("budget", "seed", "[loop] seed"),
    ("batch", "retries", "[executor] retries"),
];

/// Sections of earlier files that are gone, with what replaced them.
const GONE: &[(&str, &str)] = &[
    (
        "budget",
        "its keys are in [loop] (jitter_runs, reconcile_runs, recalibrate_runs, seed)",
    ),
    (
        "batch",
        "retries are [executor] retries; a study's or loop's runs go to <out>/runs/<stage>/",
    ),
];

/// Parses the text of an experiment file named `file` (for messages): checks every key
/// against [`SECTIONS`] and [`RENAMED`], then reads the typed sections. A study whose file
/// gives `sensors` but not `shapes` keeps `min(10, sensors)` shapes (the default follows the
/// value the user wrote).
///
/// # Errors
/// [`ExperimentError::File`] for TOML that does not parse or a value of the wrong type (with
/// its line and column); [`ExperimentError::Key`] for an unknown key
/// (with the closest names), a key of an earlier schema (with its new place), a section
/// that is gone, or a `[loop]` value out of range (with what it must be).
pub fn parse(text: &str, file: &str) -> Result<ExperimentFile> {
    let doc = DeTable::parse(text).map_err(|e| toml_error(&e, text, file))?;
    check_keys(doc.get_ref(), text, file)?;
    let mut parsed: ExperimentFile =
        toml::from_str(text).map_err(|e| toml_error(&e, text, file))?;
    let study = doc.get_ref().get("study").map(|v| v.get_ref());
    let written = |key: &str| {
        study
            .and_then(DeValue::as_table)
            .is_some_and(|t| t.get(key).is_some())
    };
    if !written("shapes") {
        parsed.study.shapes = parsed.study.shapes.min(parsed.study.sensors);
    }
    check_declared(&parsed, doc.get_ref(), text, file)?;
    check_loop(&parsed.loop_options, doc.get_ref(), text, file)?;
    Ok(parsed)
}

/// Checks `[loop]` as the file is read ([`ParamGuard::check_ref`]), so that a value out of
/// range is named with its line before anything runs; the run budgets, which depend on the
/// model's dimension, are checked when the loop starts
/// ([`LoopOptions::check_budgets`]).
fn check_loop(options: &LoopOptions, doc: &DeTable<'_>, text: &str, file: &str) -> Result<()> {
    match ParamGuard::check_ref(options) {
        Ok(()) => Ok(()),
        Err(CoreError::InvalidOption {
            name,
            value,
            message,
        }) => {
            let key = name.strip_prefix("loop.").unwrap_or(&name);
            Err(ExperimentError::Key {
                file: file.to_string(),
                line: line_of(doc, &["loop", key], text),
                key: format!("[loop] {key}"),
                message: format!("{value}: {message}"),
            })
        }
        Err(e) => Err(e.into()),
    }
}

/// The 1-based line of the key `path` (a section, then keys below it) in `doc`, or 0.
fn line_of(doc: &DeTable<'_>, path: &[&str], text: &str) -> usize {
    let mut table = doc;
    let mut line = 0;
    for key in path {
        let Some((k, v)) = table.iter().find(|(k, _)| k.get_ref().as_ref() == *key) else {
            break;
        };
        line = line_col(text, k.span().start).0;
        match v.get_ref().as_table() {
            Some(t) => table = t,
            None => break,
        }
    }
    line
}

/// Checks `[candidates]`, `[held]` and, for a file that declares them or names a
/// `[solver]`, the holdout's condition: each range `lower < upper` with the held value in
/// it, every value finite, no name both a candidate and held, and a holdout `set` that
/// names only candidates and held quantities.
fn check_declared(f: &ExperimentFile, doc: &DeTable<'_>, text: &str, file: &str) -> Result<()> {
    let key = |path: &[&str], message: String| ExperimentError::Key {
        file: file.to_string(),
        line: line_of(doc, path, text),
        key: match path {
            [s, n, k, ..] => format!("[{s}.{n}] {k}"),
            [s, n] if *s == "candidates" => format!("[{s}.{n}]"),
            [s, n] => format!("[{s}] {n}"),
            _ => path.join("."),
        },
        message,
    };
    for (name, c) in &f.candidates {
        for (k, v) in [("lower", c.lower), ("upper", c.upper), ("held", c.held)] {
            if !v.is_finite() {
                return Err(key(
                    &["candidates", name, k],
                    format!("{v}: must be finite"),
                ));
            }
        }
        if c.lower >= c.upper {
            return Err(key(
                &["candidates", name, "upper"],
                format!(
                    "{}: must exceed lower = {} (the admissible range is [lower, upper])",
                    c.upper, c.lower
                ),
            ));
        }
        if !(c.lower..=c.upper).contains(&c.held) {
            return Err(key(
                &["candidates", name, "held"],
                format!(
                    "{}: outside the admissible range [{}, {}]",
                    c.held, c.lower, c.upper
                ),
            ));
        }
        if f.held.contains_key(name) {
            return Err(key(
                &["held", name],
                format!("`{name}` is also [candidates.{name}]: declare it once"),
            ));
        }
    }
    for (name, v) in &f.held {
        if !v.is_finite() {
            return Err(key(&["held", name], format!("{v}: must be finite")));
        }
    }
    let declares =
        !f.candidates.is_empty() || !f.held.is_empty() || (f.solver.is_some() && f.model.is_none());
    if let (true, Some(h)) = (declares, &f.holdout) {
        let known: Vec<&str> = f
            .candidates
            .keys()
            .chain(f.held.keys())
            .map(String::as_str)
            .collect();
        for name in h.set.keys() {
            if !known.contains(&name.as_str()) {
                return Err(key(
                    &["holdout", "set"],
                    format!(
                        "`{name}` is neither a [candidates] entry nor a [held] quantity, so no \
                         run can hold it at another value; {}",
                        if known.is_empty() {
                            "declare it in [held] with its value in the calibration test".into()
                        } else {
                            format!("closest declared: {}", closest(name, &known))
                        }
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The `line L, column C: message` of a TOML error.
fn toml_error(e: &toml::de::Error, text: &str, file: &str) -> ExperimentError {
    let place = e
        .span()
        .map(|s| {
            let (line, col) = line_col(text, s.start);
            format!("line {line}, column {col}: ")
        })
        .unwrap_or_default();
    ExperimentError::File {
        file: file.to_string(),
        message: format!("{place}{}", one_line(e.message())),
    }
}

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// 1-based line and column of byte `at` of `text`.
fn line_col(text: &str, at: usize) -> (usize, usize) {
    let at = at.min(text.len());
    let before = text.get(..at).unwrap_or("");
    let line = before.matches('\n').count() + 1;
    let col = at - before.rfind('\n').map_or(0, |p| p + 1) + 1;
    (line, col)
}

/// Checks the sections and keys of `doc`.
fn check_keys(doc: &DeTable<'_>, text: &str, file: &str) -> Result<()> {
    let key_error =
        |span: std::ops::Range<usize>, key: String, message: String| ExperimentError::Key {
            file: file.to_string(),
            line: line_col(text, span.start).0,
            key,
            message,
        };
    let section_names: Vec<&str> = SECTIONS.iter().map(|(s, _)| *s).collect();
    for (name, value) in doc {
        let section = name.get_ref().as_ref();
        let table = value.get_ref().as_table();
        if let Some((_, why)) = GONE.iter().find(|(g, _)| *g == section) {
            // A renamed key inside names its own new place; the section's note otherwise.
            if let Some(t) = table {
                for (k, _) in t {
                    let key = k.get_ref().as_ref();
                    if let Some((_, _, new)) =
                        RENAMED.iter().find(|(s, o, _)| *s == section && *o == key)
                    {
                        return Err(key_error(
                            k.span(),
                            format!("[{section}] {key}"),
                            format!("renamed: write {new}"),
                        ));
                    }
                }
            }
            return Err(key_error(
                name.span(),
                format!("[{section}]"),
                format!("this table is gone: {why}"),
            ));
        }
        let Some((_, keys)) = SECTIONS.iter().find(|(s, _)| *s == section) else {
            return Err(key_error(
                name.span(),
                format!("[{section}]"),
                format!(
                    "unknown section; closest: {}",
                    closest(section, &section_names)
                ),
            ));
        };
        let (Some(keys), Some(t)) = (keys, table) else {
            continue;
        };
        for (k, _) in t {
            let key = k.get_ref().as_ref();
            if keys.contains(&key) {
                continue;
            }
            let message = match RENAMED.iter().find(|(s, o, _)| *s == section && *o == key) {
                Some((_, _, new)) => format!("renamed: write {new}"),
                None => format!("unknown key; closest: {}", closest(key, keys)),
            };
            return Err(key_error(k.span(), format!("[{section}] {key}"), message));
        }
    }
    Ok(())
}

/// Up to three names of `names` closest to `name` (Jaro-Winkler similarity), quoted: the
/// same suggestion a parameter name gets ([`impactcal_calibrate::study::subspace::near`]).
pub fn closest(name: &str, names: &[&str]) -> String {
    impactcal_calibrate::study::subspace::near(name, names)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        match parse(text, "x.toml") {
            Ok(_) => panic!("parsed: {text}"),
            Err(e) => e.to_string(),
        }
    }

    const TEST: &str = "[test]\ndata = \"t.csv\"\n";

    #[test]
    fn every_listed_option_key_is_a_field_and_every_field_is_listed() {
        let listed = |s: &str| -> Vec<String> {
            let keys = SECTIONS.iter().find(|(n, _)| *n == s).and_then(|(_, k)| *k);
            keys.unwrap_or_default()
                .iter()
                .map(|k| k.to_string())
                .collect()
        };
        // `keep_all_channels` is written only when set (so that older folders resume).
        for (section, json) in [
            (
                "study",
                serde_json::to_value(StudyOptions {
                    keep_all_channels: true,
                    ..StudyOptions::default()
                }),
            ),
            (
                "loop",
                serde_json::to_value(LoopOptions {
                    keep_all_channels: true,
                    ..LoopOptions::default()
                }),
            ),
        ] {
            let json = json.unwrap_or_default();
            let mut fields: Vec<String> = json
                .as_object()
                .map(|o| o.keys().cloned().collect())
                .unwrap_or_default();
            // sigma is written once, in [test].
            fields.retain(|f| f != "sigma");
            fields.sort();
            let mut keys = listed(section);
            keys.sort();
            assert_eq!(fields, keys, "[{section}]");
        }
    }

    #[test]
    fn unknown_keys_name_line_and_closest_names() {
        let e = err(&format!("{TEST}[study]\nhalton_runs = 8\nsensor = 3\n"));
        assert!(
            e.starts_with("x.toml: line 5: [study] sensor: unknown key; closest: `sensors`"),
            "{e}"
        );
        let e = err(&format!("{TEST}[studdy]\nseed = 1\n"));
        assert!(
            e.contains("line 3: [studdy]: unknown section; closest: `study`"),
            "{e}"
        );
    }

    #[test]
    fn old_keys_name_their_new_place() {
        for (text, line, new) in [
            ("[study]\nensemble = 8\n", 4, "[study] halton_runs"),
            ("[study]\nnoise_runs = 3\n", 4, "[study] jitter_runs"),
            ("[study]\nreconcile_batch = 3\n", 4, "[study] cors_batch"),
            ("[study]\nsigma = 0.1\n", 4, "[test] sigma"),
            ("[loop]\nensemble = 6\n", 4, "[loop] jitter_runs"),
            ("[loop]\nbatch = 6\n", 4, "[loop] cors_batch"),
            ("[loop]\nsigma = 0.1\n", 4, "[test] sigma"),
            ("[budget]\nreconcile = 16\n", 4, "[loop] reconcile_runs"),
            ("[batch]\nretries = 1\n", 4, "[executor] retries"),
        ] {
            let e = err(&format!("{TEST}{text}"));
            assert!(
                e.contains(&format!("line {line}:")) && e.contains(&format!("write {new}")),
                "{text}: {e}"
            );
        }
        let e = err(&format!("{TEST}[batch]\nstudy = \"x\"\n"));
        assert!(e.contains("[batch]: this table is gone"), "{e}");
    }

    #[test]
    fn a_key_set_twice_is_an_error_with_its_line() {
        let e = err(&format!("{TEST}[study]\nseed = 1\nseed = 2\n"));
        assert!(e.contains("line 5"), "{e}");
    }

    #[test]
    fn shapes_follow_sensors_unless_written() {
        let f = parse(&format!("{TEST}[study]\nsensors = 4\n"), "x.toml").unwrap();
        assert_eq!((f.study.sensors, f.study.shapes), (4, 4));
        let f = parse(&format!("{TEST}[study]\nsensors = 30\n"), "x.toml").unwrap();
        assert_eq!(f.study.shapes, 10);
        let f = parse(
            &format!("{TEST}[study]\nsensors = 4\nshapes = 2\n"),
            "x.toml",
        )
        .unwrap();
        assert_eq!(f.study.shapes, 2);
    }

    #[test]
    fn processes_without_jobs_use_the_machines_cores() {
        let f = parse(
            &format!("{TEST}[executor]\nkind = \"processes\"\nretries = 1\n"),
            "x.toml",
        )
        .unwrap();
        let e = f.executor.unwrap();
        assert_eq!(e.retries, 1);
        let impactcal_runner::Executor::Processes(p) = e.executor else {
            panic!("{:?}", e.executor)
        };
        assert_eq!(p.jobs, impactcal_runner::executor::machine_cores());
        assert!(p.jobs >= 1);
        let e = err(&format!(
            "{TEST}[executor]\nkind = \"processes\"\njobs = \"2\"\n"
        ));
        assert!(e.contains("line "), "{e}");
    }

    /// A `[loop]` value out of range is refused as the file is read, naming the file, the
    /// line and the key, before the model is built or anything runs.
    #[test]
    fn a_bad_loop_value_is_refused_when_the_file_is_read() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("loop.toml");
        // No model and no test data exist: the file is refused before they are looked at.
        let text = "[model]\ndeck = \"absent.k\"\n[test]\ndata = \"absent.csv\"\n\
                    [loop]\nseed = 3\nalpha = 0.7\n";
        std::fs::write(&path, text).unwrap();
        let e = match crate::Experiment::from_file(&path) {
            Ok(_) => panic!("a [loop] alpha of 0.7 was accepted"),
            Err(e) => e,
        };
        assert!(matches!(e, ExperimentError::Key { line: 7, .. }), "{e:?}");
        assert_eq!(
            e.to_string(),
            format!(
                "{}: line 7: [loop] alpha: 0.7: must lie in (0, 0.5)",
                path.display()
            )
        );
        // Another key, another line; a valid [loop] parses.
        let e = err(&format!("{TEST}[loop]\njitter_runs = 1\n"));
        assert!(
            e.starts_with("x.toml: line 4: [loop] jitter_runs: 1: the model's noise needs"),
            "{e}"
        );
        assert!(parse(&format!("{TEST}[loop]\nalpha = 0.05\n"), "x.toml").is_ok());
    }

    #[test]
    fn wrong_types_name_line_and_column() {
        let e = err(&format!("{TEST}[study]\nhalton_runs = \"many\"\n"));
        assert!(e.starts_with("x.toml: line 4, column"), "{e}");
        // A file without [test] parses (a Kolsky bar's test is its bar test); every other
        // model is refused when its spec is made.
        let f = parse("[study]\nseed = 1\n", "x.toml").unwrap();
        let e = crate::model::ModelSpec::of(&f, "x.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("[test] data: missing"), "{e}");
    }
}
