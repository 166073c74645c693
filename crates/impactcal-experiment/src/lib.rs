//! Experiment files: a calibration study or a closed loop described in one TOML file, run
//! through the library.
//!
//! One schema ([`schema`]) covers every section (`[model] [parameters] [space] [candidates] [held] [test]
//! [holdout] [solver] [executor] [study] [loop]`), parsed in one place with errors that
//! name the file, the line and the key. [`model`] turns the model sections into one
//! [`ExperimentModel`] (airframe, deck, drop tower) or an external solver; [`Experiment`]
//! runs the study ([`Experiment::study`]), the closed loop ([`Experiment::close_loop`]) or
//! one run of either in a run directory ([`Experiment::point`], what a process-pool or
//! Slurm worker runs).
//!
//! ```no_run
//! use impactcal_experiment::Experiment;
//!
//! let study = Experiment::from_file("examples/study/deck-processes.toml")?.study("study-out")?;
//! println!("M1: {}", study.result.m1.verdict.as_str());
//! let closed = Experiment::from_file("examples/loop/processes.toml")?.close_loop("loop-out")?;
//! println!("{:?}", closed.result.verdict);
//! # Ok::<(), impactcal_experiment::ExperimentError>(())
//! ```
//!
//! With `[executor] kind = "processes"` or `"slurm"`, a built-in model runs as `<program>
//! point --config <file>` in each run's directory, `<program>` being this process's
//! executable unless [`Experiment::with_program`] names another (the `impactcal` command
//! answers `point`; a program of one's own answers it by calling [`Experiment::point`]).

pub mod builtin;
pub mod declared;
pub mod error;
mod kolsky;
pub mod kolsky_report;
pub mod lumped;
pub mod model;
pub mod schema;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use impactcal_calibrate::CalibrateError;
use impactcal_calibrate::closeloop::{Holdout, LoopOptions, LoopResult, run_loop_on};
use impactcal_calibrate::report::{Block, Provenance, Report, ReportFiles, Section};
use impactcal_calibrate::study::document::Geometry;
use impactcal_calibrate::study::{
    InProcess, ModelRuns, Observer, Silent, SolverRuns, StudyResult, TestData, ValidStudyOptions,
};
use impactcal_core::enrich::rebuild;
use impactcal_core::{Cfc, ChannelMap, Histories, IsoMme, Model, ParamGuard, TestRecord};
use impactcal_runner::config::{ExecutorTable, SolverSection};
use impactcal_runner::workdir::{PARAMS, RunRecord};
use impactcal_runner::{
    Cancel, Executor, InProcessSolver, OutputSpec, Runner, Solver, SolverCommand,
};
use serde::Serialize;

pub use builtin::BuiltInSolver;
pub use declared::DeclaredModel;
pub use error::{ExperimentError, Result};
pub use model::{Built, Declarations, ExperimentModel, ModelSpec};
pub use schema::ExperimentFile;

use error::io;
use model::{record_error, resolve};

/// The file a worker writes its run's histories to (our wide CSV) in the run's directory.
pub const POINT_OUTPUT: &str = "out.csv";

/// An experiment file, parsed and checked, ready to run.
#[derive(Debug, Clone)]
pub struct Experiment {
    path: PathBuf,
    name: String,
    file: ExperimentFile,
    spec: ModelSpec,
    max_memory: Option<u64>,
    cancel: Cancel,
    program: Option<PathBuf>,
}

/// A finished study or loop: its result, written as JSON (`study.json` or `loop.json`),
/// and its report (`report.html`, `report.md` and the SVG figures).
#[derive(Debug)]
pub struct Finished<R> {
    /// The result.
    pub result: R,
    /// The report document (its `lead` lines are the verdict in a few sentences).
    pub report: Report,
    /// The JSON file.
    pub json: PathBuf,
    /// The report's files.
    pub files: ReportFiles,
}

/// The measured side of an experiment, read from its files.
#[derive(Debug, Clone)]
pub struct Measured {
    /// The test's histories.
    pub test: Histories,
    /// The channel map.
    pub map: Option<ChannelMap>,
    /// The CFC class.
    pub cfc: Option<Cfc>,
    /// The holdout test and its condition.
    pub holdout: Option<(Histories, Vec<(String, f64)>)>,
    /// What the readers noticed (resampling, ISO-MME notes, deck warnings), and the
    /// scatter between repeated tests.
    pub notes: Vec<String>,
    /// The measurement noise the test itself states, where `[test] sigma` is not given: a
    /// Kolsky bar's gauge noise before its pulse.
    pub sigma: Option<f64>,
    /// The scatter between repeated calibration tests, per channel (a lumped model's;
    /// empty otherwise).
    pub scatter: Vec<impactcal_models::lumped::ChannelScatter>,
    /// The time (s) by which each repeated calibration test triggered later than the
    /// first, read from its input, before the scatter (a lumped model's; empty otherwise).
    pub shifts: Vec<f64>,
}

impl Experiment {
    /// Reads and checks an experiment file.
    ///
    /// # Errors
    /// [`ExperimentError::Io`] when it cannot be read; the errors of [`schema::parse`] and
    /// [`ModelSpec::of`].
    pub fn from_file(path: impl AsRef<Path>) -> Result<Experiment> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(io(path))?;
        Experiment::parse(&text, path)
    }

    /// Parses the text of an experiment file; `path` places its relative paths and names
    /// it in messages.
    ///
    /// # Errors
    /// As [`Experiment::from_file`].
    pub fn parse(text: &str, path: impl AsRef<Path>) -> Result<Experiment> {
        let path = path.as_ref().to_path_buf();
        let name = path.display().to_string();
        let file = schema::parse(text, &name)?;
        let spec = ModelSpec::of(&file, &name)?;
        Ok(Experiment {
            path,
            name,
            file,
            spec,
            max_memory: None,
            cancel: Cancel::new(),
            program: None,
        })
    }

    /// The same experiment whose stages may use at most `bytes` of memory (`None`: what
    /// the machine has available); a stage whose estimate does not fit stops before it
    /// allocates. Not part of the experiment's fingerprint.
    #[must_use]
    pub fn with_max_memory(mut self, bytes: Option<u64>) -> Self {
        self.max_memory = bytes;
        self
    }

    /// The same experiment whose workers run `program point --config <file>` (default: this
    /// process's executable).
    #[must_use]
    pub fn with_program(mut self, program: impl Into<PathBuf>) -> Self {
        self.program = Some(program.into());
        self
    }

    /// The token that stops the runs on an executor when set (for a Ctrl-C handler).
    pub fn cancel(&self) -> Cancel {
        self.cancel.clone()
    }

    /// The file as parsed.
    pub fn file(&self) -> &ExperimentFile {
        &self.file
    }

    /// The model it describes.
    pub fn spec(&self) -> &ModelSpec {
        &self.spec
    }

    fn base(&self) -> &Path {
        self.path.parent().unwrap_or(Path::new(""))
    }

    /// Builds the model.
    ///
    /// # Errors
    /// As [`ModelSpec::build`], the fault placed in the file.
    pub fn build(&self) -> Result<Built> {
        self.spec
            .build(self.base(), &self.name)
            .map_err(|e| e.in_section(&self.name, "model"))
    }

    /// The measurement noise level the study and the loop both take: `[test] sigma` where
    /// the file gives it, else the level the test itself states (`Measured::sigma`: a
    /// Kolsky bar's gauge noise before its pulse), else `None` (each then measures it on
    /// the test its own way).
    pub fn noise_sigma(&self, measured: &Measured) -> Option<f64> {
        self.file.test.sigma.or(measured.sigma)
    }

    /// The study's options: `[study]`, with the noise level of [`Experiment::noise_sigma`]
    /// and the memory limit.
    ///
    /// # Errors
    /// [`ExperimentError::Section`] naming the option out of range.
    pub fn study_options(&self, measured: &Measured) -> Result<ValidStudyOptions> {
        let mut options = self.file.study.clone();
        options.sigma = self.noise_sigma(measured);
        options.max_memory = self.max_memory;
        options
            .check()
            .map_err(|e| ExperimentError::from(e).in_section(&self.name, "study"))
    }

    /// The loop's options: `[loop]`, with the noise level of [`Experiment::noise_sigma`]
    /// and the memory limit (checked when the loop starts, against the model's dimension).
    pub fn loop_options(&self, measured: &Measured) -> LoopOptions {
        let mut options = self.file.loop_options.clone();
        options.sigma = self.noise_sigma(measured);
        options.max_memory = self.max_memory;
        options
    }

    /// Reads the test, its map and filter, and the holdout.
    ///
    /// # Errors
    /// The readers' errors, placed in `[test]` or `[holdout]`.
    pub fn measured(&self) -> Result<Measured> {
        let t = &self.file.test;
        let base = self.base();
        let in_test = |e: ExperimentError| e.in_section(&self.name, "test");
        let mut notes = Vec::new();
        let mut sigma = None;
        let cfc = t
            .cfc
            .map(Cfc::from_class)
            .transpose()
            .map_err(|e| in_test(e.into()))?;
        if let ModelSpec::Lumped(spec) = &self.spec {
            let m = lumped::measured(spec, base, &mut notes).map_err(in_test)?;
            notes.extend(lumped::scatter_notes(&m.scatter, &m.shifts));
            return Ok(Measured {
                test: m.test,
                map: None,
                cfc,
                holdout: m.holdout,
                notes,
                sigma: None,
                scatter: m.scatter,
                shifts: m.shifts,
            });
        }
        let test = match (&self.spec, &t.data) {
            (ModelSpec::KolskyBar { test }, _) => {
                let (h, s, n) = kolsky::measured(&resolve(base, test))
                    .map_err(|e| e.in_section(&self.name, "model"))?;
                if t.sigma.is_none() {
                    sigma = s;
                    notes.extend(n);
                }
                h
            }
            (_, Some(data)) => read_test(&resolve(base, data), &mut notes).map_err(in_test)?,
            (_, None) => {
                return Err(ExperimentError::File {
                    file: self.name.clone(),
                    message: "[test] data: missing (the measured test, wide CSV or ISO-MME)".into(),
                });
            }
        };
        let map = t
            .map
            .as_ref()
            .map(|m| ChannelMap::read(resolve(base, m)))
            .transpose()
            .map_err(|e| in_test(e.into()))?;
        let test = match (&self.spec, &map) {
            (ModelSpec::KolskyBar { .. }, Some(map)) => {
                kolsky::mapped(test, map).map_err(in_test)?
            }
            _ => test,
        };
        let holdout = match &self.file.holdout {
            Some(h) => Some((
                read_test(&resolve(base, &h.data), &mut notes)
                    .map_err(|e| e.in_section(&self.name, "holdout"))?,
                h.set.clone().into_iter().collect(),
            )),
            None => None,
        };
        Ok(Measured {
            test,
            map,
            cfc,
            holdout,
            notes,
            sigma,
            scatter: Vec::new(),
            shifts: Vec::new(),
        })
    }

    /// What sets the model's window, and its end where the file gives it before any run:
    /// the airframe's `[model] end_time` (default 0.08 s), an external solver's
    /// `[solver.output] end_time`; a deck's `*CONTROL_TERMINATION` and the drop tower's
    /// fixed window are known once the model runs.
    fn window(&self) -> (String, Option<f64>) {
        match &self.spec {
            ModelSpec::Airframe { end_time, .. } => (
                "`[model] end_time`".into(),
                Some(
                    end_time.unwrap_or(
                        impactcal_shell::airframe::AirframeOptions::new(
                            impactcal_shell::airframe::MeshDensity::Coarse,
                        )
                        .end_time,
                    ),
                ),
            ),
            ModelSpec::External { solver, .. } => (
                "the template's end time and `[solver.output] end_time`".into(),
                solver.output.end_time,
            ),
            ModelSpec::Deck { path, .. } => (
                format!(
                    "the end time of `*CONTROL_TERMINATION` in {}",
                    path.display()
                ),
                None,
            ),
            _ => ("(the model's window is fixed)".into(), None),
        }
    }

    /// The advice of a test that does not cover the model's window, naming what sets the
    /// window in this file.
    fn window_advice(&self, test_end: f64) -> String {
        let end = (test_end * 1e9).round() / 1e9;
        match self.window() {
            (key, _) if key.starts_with('(') => {
                format!("give a record that reaches the model's end {key}")
            }
            (key, _) => format!("set {key} to at most {end} s, or give a longer record"),
        }
    }

    /// Refuses, before any run, a test whose record ends before the model's window where
    /// the file gives the window's end ([`Experiment::window`]); fills in the advice of a
    /// study's or loop's [`CalibrateError::TestShorterThanModel`] otherwise.
    fn check_window(&self, test: &Histories) -> Result<()> {
        let test_end = test.start() + test.samples().saturating_sub(1) as f64 * test.dt();
        match self.window() {
            (_, Some(end)) if test_end < end - 1e-6 * test.dt() => {
                Err(self.in_window(CalibrateError::TestShorterThanModel {
                    test_start: test.start(),
                    test_end,
                    model_start: 0.0,
                    model_end: end,
                    advice: String::new(),
                }))
            }
            _ => Ok(()),
        }
    }

    /// `e` as an error of this file; a test shorter than the model's window with this
    /// file's advice.
    fn in_window(&self, e: CalibrateError) -> ExperimentError {
        let e = match e {
            CalibrateError::TestShorterThanModel {
                test_start,
                test_end,
                model_start,
                model_end,
                advice,
            } => CalibrateError::TestShorterThanModel {
                test_start,
                test_end,
                model_start,
                model_end,
                advice: if test_end < model_end {
                    self.window_advice(test_end)
                } else {
                    advice
                },
            },
            other => other,
        };
        ExperimentError::from(e).in_section(&self.name, "test")
    }

    /// Runs the study in `out` (created if needed; a journal there of the same study is
    /// reused) and writes `study.json` and the report.
    ///
    /// # Errors
    /// As [`Experiment::study_with`].
    pub fn study(&self, out: impl AsRef<Path>) -> Result<Finished<StudyResult>> {
        self.study_with(out.as_ref(), &Silent)
    }

    /// [`Experiment::study`] telling `observer` about its stages and notes.
    ///
    /// # Errors
    /// The options' errors, the model's and the test's, the study's
    /// ([`impactcal_calibrate::study::run`]), and I/O errors writing the results.
    pub fn study_with(&self, out: &Path, observer: &dyn Observer) -> Result<Finished<StudyResult>> {
        let started = Instant::now();
        let built = self.build()?;
        let measured = self.measured()?;
        let options = self.study_options(&measured)?;
        self.check_window(&measured.test)?;
        notify(observer, built.notes.iter().chain(&measured.notes));
        let runner = self.study_runner(&built)?;
        std::fs::create_dir_all(out).map_err(io(out))?;
        let test = TestData {
            histories: &measured.test,
            map: measured.map.as_ref(),
            cfc: measured.cfc,
        };
        let run = |model_runs: &dyn ModelRuns| {
            impactcal_calibrate::study::run(
                model_runs,
                &built.description,
                test,
                &options,
                out,
                observer,
            )
        };
        let result = match (&runner, &built.model) {
            (Some(r), _) => run(r),
            (None, Some(m)) => run(&InProcess(m)),
            (None, None) => Err(impactcal_calibrate::CalibrateError::study(
                "[solver]",
                "an external solver needs an executor",
            )),
        }
        .map_err(|e| match e {
            CalibrateError::TestShorterThanModel { .. } => self.in_window(e),
            e => ExperimentError::from(e).in_section(&self.name, "study"),
        })?;
        let provenance = Provenance::now(
            command_line(),
            result.fingerprint.clone(),
            result.options.seed,
            started.elapsed().as_secs_f64(),
        );
        write_study(result, built.geometry.as_ref(), Some(&provenance), out)
    }

    /// The runs of a study that go through the runner's solver: an external `[solver]` on
    /// any executor (without a `command` on the local executor, the built-in solver on each
    /// run's deck, in process), or the built-in model on a process pool or Slurm (each run
    /// `point` on this file in its directory). `None` for the built-in model in this
    /// process.
    fn study_runner(&self, built: &Built) -> Result<Option<SolverRuns>> {
        let table = self.executor_table();
        let (solver, in_process) = match (&self.file.solver, &table.executor) {
            (Some(s), executor) => self.external_solver(s, executor)?,
            (None, Executor::Local) => return Ok(None),
            (None, _) => (self.point_solver(Some("velocity"))?, None),
        };
        let runner = Runner {
            in_process,
            ..self.runner(table, solver)?
        };
        Ok(Some(SolverRuns {
            space: built.space.clone(),
            runner,
        }))
    }

    /// The solver of `[solver]` on `executor`, its templates holding the declared
    /// candidates and held quantities at their held values, and the built-in solver for a
    /// run without a `command` in this process.
    fn external_solver(
        &self,
        s: &SolverSection,
        executor: &Executor,
    ) -> Result<(Solver, Option<Arc<dyn InProcessSolver + Send>>)> {
        let program = self.program()?;
        let solver = s
            .solver(self.base(), &self.path, executor, Some(&program))
            .map_err(|e| ExperimentError::from(e).in_section(&self.name, "solver"))?;
        let declared = Declarations {
            candidates: self.file.candidates.clone(),
            held: self.file.held.clone(),
        };
        let builtin: Arc<dyn InProcessSolver + Send> = Arc::new(BuiltInSolver::new(s.quantity));
        Ok((declared::holding(solver, &declared.values()), Some(builtin)))
    }

    /// `[executor]` (default: in this process, 2 retries).
    fn executor_table(&self) -> ExecutorTable {
        self.file.executor.clone().unwrap_or_default()
    }

    /// The runner of `solver` on the executor of `table`, checked, with its retries and
    /// this experiment's cancel token.
    fn runner(&self, table: ExecutorTable, solver: Solver) -> Result<Runner> {
        table
            .executor
            .check()
            .map_err(|e| ExperimentError::from(e).in_section(&self.name, "executor"))?;
        Ok(Runner {
            retries: table.retries,
            cancel: self.cancel.clone(),
            ..Runner::new(solver, table.executor)
        })
    }

    fn program(&self) -> Result<PathBuf> {
        match &self.program {
            Some(p) => Ok(p.clone()),
            None => std::env::current_exe().map_err(io(Path::new("the running program"))),
        }
    }

    /// The solver that runs `<program> point --config <file>` in each run's directory
    /// (reading its `params.json`, writing [`POINT_OUTPUT`]); `unit` is the histories'
    /// unit (our CSV does not carry it).
    fn point_solver(&self, unit: Option<&str>) -> Result<Solver> {
        let program = self.program()?;
        let config = std::fs::canonicalize(&self.path).map_err(io(&self.path))?;
        let mut output = OutputSpec::csv(POINT_OUTPUT);
        output.unit = unit.map(str::to_string);
        Ok(Solver {
            inputs: Vec::new(),
            command: SolverCommand::Argv(vec![
                program.display().to_string(),
                "point".into(),
                "--config".into(),
                config.display().to_string(),
            ]),
            output,
        })
    }

    /// Runs the closed loop in `out` (created if needed; a journal there of the same loop
    /// is reused) and writes `loop.json` and the report.
    ///
    /// # Errors
    /// As [`Experiment::close_loop_with`].
    pub fn close_loop(&self, out: impl AsRef<Path>) -> Result<Finished<LoopResult>> {
        self.close_loop_with(out.as_ref(), &Silent)
    }

    /// [`Experiment::close_loop`] telling `observer` about its stages and notes.
    ///
    /// An external solver's loop runs every stage through the runner on `[executor]` (in
    /// process by default), its candidates and held quantities those of `[candidates]` and
    /// `[held]`.
    ///
    /// # Errors
    /// The model's, the test's and the loop's errors ([`run_loop_on`]); I/O errors writing
    /// the results.
    pub fn close_loop_with(
        &self,
        out: &Path,
        observer: &dyn Observer,
    ) -> Result<Finished<LoopResult>> {
        let started = Instant::now();
        let built = self.build()?;
        let Some(model) = &built.model else {
            return Err(ExperimentError::File {
                file: self.name.clone(),
                message: "the closed loop needs a model that lists its candidate effects".into(),
            });
        };
        let measured = self.measured()?;
        self.check_window(&measured.test)?;
        notify(observer, built.notes.iter().chain(&measured.notes));
        let worker = self.worker()?;
        std::fs::create_dir_all(out).map_err(io(out))?;
        let test = TestData {
            histories: &measured.test,
            map: measured.map.as_ref(),
            cfc: measured.cfc,
        };
        let holdout = measured.holdout.as_ref().map(|(histories, set)| Holdout {
            histories,
            set: set.as_slice(),
        });
        let options = self.loop_options(&measured);
        let result = run_loop_on(
            model,
            &built.description,
            test,
            holdout,
            &options,
            out,
            observer,
            worker.as_ref(),
        )
        .map_err(|e| match e {
            CalibrateError::TestShorterThanModel { .. } => self.in_window(e),
            e => ExperimentError::from(e).in_section(&self.name, "loop"),
        })?;
        let provenance = Provenance::now(
            command_line(),
            result.digest.clone(),
            result.seed,
            started.elapsed().as_secs_f64(),
        );
        let mut report = impactcal_calibrate::closeloop::document::report_with(
            &result,
            built.geometry.as_ref(),
            Some(&provenance),
        );
        if let ExperimentModel::KolskyBar(bar) = model {
            // A section that cannot be drawn says why; the loop's result is kept.
            let section = kolsky_report::section(bar, &result).unwrap_or_else(|e| Section {
                heading: "The bar test".into(),
                blocks: vec![Block::Paragraph(format!(
                    "The bar test's figures could not be drawn: {e}"
                ))],
            });
            let at = report.sections.len().min(1);
            report.sections.insert(at, section);
        }
        finish(result, report, out, "loop.json")
    }

    /// The worker of a loop: for an external solver, the solver on `[executor]` (any
    /// executor, the local one included); for a built-in model on a process pool or Slurm,
    /// `point` on this file in each run's directory. `None` for a built-in model in
    /// process.
    fn worker(&self) -> Result<Option<Runner>> {
        let table = self.executor_table();
        if let Some(s) = &self.file.solver {
            let (solver, in_process) = self.external_solver(s, &table.executor)?;
            return Ok(Some(Runner {
                in_process,
                ..self.runner(table, solver)?
            }));
        }
        if table.executor == Executor::Local {
            return Ok(None);
        }
        let solver = self.point_solver(None)?;
        self.runner(table, solver).map(Some)
    }

    /// One run of the experiment's model in the run directory `dir`: reads its
    /// `params.json`, runs [`Experiment::point_at`] and writes the histories to
    /// `dir/`[`POINT_OUTPUT`]. What a process-pool or Slurm worker does for a study's and a
    /// loop's runs alike.
    ///
    /// # Errors
    /// As [`Experiment::point_at`]; I/O errors of the two files.
    pub fn point(&self, dir: impl AsRef<Path>) -> Result<()> {
        let dir = dir.as_ref();
        let record = read_record(&dir.join(PARAMS))?;
        let h = self.point_at(&record)?;
        h.write_csv(dir.join(POINT_OUTPUT))?;
        Ok(())
    }

    /// The histories of the model rebuilt as the run `record` says (its parameters, which
    /// start with the model's own and may add candidate effects in the order the loop added
    /// them, and its condition `set`), at the run's values.
    ///
    /// # Errors
    /// [`ExperimentError::File`] for an external solver (its runs are the solver's);
    /// a core error for a name the model does not know, values outside its space or a
    /// condition it cannot hold; the model's own errors.
    pub fn point_at(&self, record: &RunRecord) -> Result<Histories> {
        let built = self.build()?;
        let (Some(model), None) = (&built.model, &self.file.solver) else {
            return Err(ExperimentError::File {
                file: self.name.clone(),
                message: "`point` runs the built-in model of a file; this one names a [solver]"
                    .into(),
            });
        };
        if record.values.len() != record.names.len() {
            return Err(record_error(
                "values",
                format!(
                    "{} values for {} names",
                    record.values.len(),
                    record.names.len()
                ),
            ));
        }
        let set: Vec<(String, f64)> = record.set.clone().into_iter().collect();
        let m = rebuild(model, &record.names, &set)?;
        m.space().to_unit(&record.values)?;
        Ok(m.simulate(&record.values)?)
    }
}

/// Tells `observer` each note as a step (`note: ...`).
fn notify<'a>(observer: &dyn Observer, notes: impl Iterator<Item = &'a String>) {
    for n in notes {
        observer.step(&format!("note: {n}"));
    }
}

/// Writes `result` as pretty JSON plus a newline to `path`.
fn write_json(result: &impl Serialize, path: &Path) -> Result<()> {
    let json = serde_json::to_string_pretty(result).map_err(|e| ExperimentError::File {
        file: path.display().to_string(),
        message: format!("cannot encode the result: {e}"),
    })?;
    std::fs::write(path, json + "\n").map_err(io(path))
}

/// The command line of this process, its arguments joined by spaces: what a report's
/// provenance records as the command.
pub fn command_line() -> String {
    std::env::args().collect::<Vec<_>>().join(" ")
}

/// Writes a study's `study.json` and report (`report.html`, `report.md`, SVG figures) into
/// `out`; `geometry` places the airframe's sensors, impact shapes and changes in the
/// report's figures; `provenance`, when given, ends the report.
///
/// # Errors
/// I/O and rendering errors.
pub fn write_study(
    result: StudyResult,
    geometry: Option<&Geometry>,
    provenance: Option<&Provenance>,
    out: &Path,
) -> Result<Finished<StudyResult>> {
    let report = impactcal_calibrate::study::document::report_with(&result, geometry, provenance);
    finish(result, report, out, "study.json")
}

/// Writes a loop's `loop.json` and report into `out`; `geometry` draws the residual's
/// sensor pattern on the structure; `provenance`, when given, ends the report.
///
/// # Errors
/// I/O and rendering errors.
pub fn write_loop(
    result: LoopResult,
    geometry: Option<&Geometry>,
    provenance: Option<&Provenance>,
    out: &Path,
) -> Result<Finished<LoopResult>> {
    let report =
        impactcal_calibrate::closeloop::document::report_with(&result, geometry, provenance);
    finish(result, report, out, "loop.json")
}

/// Writes `result` as `out/<json>` and `report` into `out`.
fn finish<R: Serialize>(result: R, report: Report, out: &Path, json: &str) -> Result<Finished<R>> {
    let json = out.join(json);
    write_json(&result, &json)?;
    let files = impactcal_calibrate::report::write(&report, out)?;
    Ok(Finished {
        result,
        report,
        json,
        files,
    })
}

/// Reads a run's record (`params.json`).
///
/// # Errors
/// [`ExperimentError::Io`]; [`ExperimentError::File`] for a record that does not parse.
pub fn read_record(path: &Path) -> Result<RunRecord> {
    let text = std::fs::read_to_string(path).map_err(io(path))?;
    serde_json::from_str(&text).map_err(|e| ExperimentError::File {
        file: path.display().to_string(),
        message: e.to_string(),
    })
}

/// A test file: an ISO-MME data set (a folder, an `.mme` file or a zip) or wide CSV; what
/// the readers notice goes to `notes`.
///
/// # Errors
/// The readers' errors.
pub fn read_test(path: &Path, notes: &mut Vec<String>) -> Result<Histories> {
    let is_mme = path.is_dir()
        || path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("mme") || e.eq_ignore_ascii_case("zip"));
    if is_mme {
        let set = IsoMme::read(path, &[])?;
        let (h, n) = set.to_histories()?;
        notes.extend(n.iter().map(ToString::to_string));
        Ok(h)
    } else {
        let record = TestRecord::read(path)?;
        if let Some(r) = &record.resampling {
            notes.push(format!("{}: {r}", path.display()));
        }
        Ok(record.histories)
    }
}
