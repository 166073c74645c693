//! How the study's true-model runs are made: one small seam ([`ModelRuns`]: what a run is)
//! between the study and whatever runs the model, where the runs happen being the runner's
//! [`Executor`](impactcal_runner::Executor); and `Runs` (crate-internal), which runs each
//! stage of a study as a batch of [`impactcal_runner`] with its journal.
//!
//! Layout of a study's output folder `<dir>`: `<dir>/runs/fingerprint` holds the study's
//! fingerprint; each stage of runs is a batch `<dir>/runs/<stage>/` with the runner's
//! journal `journal.jsonl` and one work directory per run (`<index>/`: `params.json`, the
//! solver's files, `result.csv`). The reconciliation proposes its points a few at a time,
//! each proposal depending on the results before it, so each proposal is its own batch
//! `reconcile-<first run>`. The journal records each run before it is started (for Slurm,
//! the job array's name and id before and after `sbatch`) and each result after it is read;
//! the study always works with the histories as read back from `result.csv` (our CSV
//! writes the shortest text that reads back as the same number), so a resumed study uses
//! the same bits as an uninterrupted one. A stage may store only the channels it uses
//! (`Runs::storing`: the study's objective channels, the loop's compared ones). A stage's
//! histories are not held in memory: each stage reads from its runs' result files what it
//! uses, one run at a time ([`Outcomes`]).

use std::path::{Path, PathBuf};

use impactcal_core::{CoreError, Histories, Model, ParameterSpace};
use impactcal_runner::{
    Batch, Cancel, Hooks, InProcessSolver, ModelSolver, OutputSpec, RunResult, Runner, RunnerError,
    Solver, SolverCommand, run_batch_with,
};

use crate::error::{CalibrateError, Result};

/// The outcome of one run as the study keeps it: the histories or the failure's message.
pub type RunOutcome = std::result::Result<Histories, String>;

/// What a study's true-model run is: the parameter space, the runner's [`Solver`] that runs
/// one point (and, for a solver run in this process, what runs it), with where the runs
/// happen (the runner's [`Executor`](impactcal_runner::Executor)). [`InProcess`] runs a
/// [`Model`] in this process; [`SolverRuns`] runs any solver of a [`Runner`] (an external
/// solver through deck templates, a worker program, the built-in solver in process).
pub trait ModelRuns: Sync {
    /// The parameters every point has, in order.
    fn space(&self) -> &ParameterSpace;

    /// The solver that runs one point.
    fn solver(&self) -> Solver;

    /// Where the runs happen (default: this process).
    fn executor(&self) -> impactcal_runner::Executor {
        impactcal_runner::Executor::Local
    }

    /// The model a [`SolverCommand::InProcess`] solver runs at each point (default: none).
    fn model(&self) -> Option<&dyn Model> {
        None
    }

    /// What a [`SolverCommand::InProcess`] solver runs when it is not a model (default:
    /// none), such as the built-in shell solver on each run's deck.
    fn in_process(&self) -> Option<&dyn InProcessSolver> {
        None
    }

    /// Further attempts of a run that fails in a way another attempt may cure (default 0).
    fn retries(&self) -> u32 {
        0
    }

    /// A token that stops the runs when set (default: never set).
    fn cancel(&self) -> Cancel {
        Cancel::new()
    }

    /// Quantities held at given values in every run (a test condition, such as the impact
    /// speed of a holdout test), recorded in each run's `params.json` under `set` so that a
    /// worker process rebuilds the model at that condition (default: none).
    fn condition(&self) -> &[(String, f64)] {
        &[]
    }
}

/// A [`Model`] run in this process, points in parallel on rayon's pool, through the
/// runner's in-process solver (its journal and work directories, no child process).
#[derive(Debug)]
pub struct InProcess<'m, M>(pub &'m M);

impl<M: Model> ModelRuns for InProcess<'_, M> {
    fn space(&self) -> &ParameterSpace {
        self.0.space()
    }

    fn solver(&self) -> Solver {
        in_process()
    }

    fn model(&self) -> Option<&dyn Model> {
        Some(self.0)
    }
}

/// The runs of a [`Runner`] over a parameter space: an external solver through deck
/// templates, or a program that reads each run's `params.json` (as `impactcal point` does
/// for the built-in models), on any executor; or the built-in solver in process, handed in
/// as the runner's in-process solver.
#[derive(Debug, Clone)]
pub struct SolverRuns {
    /// The parameters.
    pub space: ParameterSpace,
    /// The solver, where it runs, its retries and cancel token.
    pub runner: Runner,
}

impl ModelRuns for SolverRuns {
    fn space(&self) -> &ParameterSpace {
        &self.space
    }
    fn solver(&self) -> Solver {
        self.runner.solver.clone()
    }
    fn executor(&self) -> impactcal_runner::Executor {
        self.runner.executor.clone()
    }
    fn in_process(&self) -> Option<&dyn InProcessSolver> {
        self.runner.in_process()
    }
    fn retries(&self) -> u32 {
        self.runner.retries
    }
    fn cancel(&self) -> Cancel {
        self.runner.cancel.clone()
    }
}

/// The runs of one [`Model`] at one condition: in this process, or through a [`Runner`]
/// whose solver command runs one point of whatever model a caller names per batch (the
/// program reads each run's `params.json`, the names of the point's coordinates, their
/// values and the condition `set`, and rebuilds the model from them, as `impactcal point`
/// does for the closed loop's built-in models, whose space grows as effects are added and
/// whose holdout runs are at another condition).
pub(crate) struct Dispatch<'a> {
    /// The model (its space names the coordinates; run in process without a worker).
    pub model: &'a dyn Model,
    /// The runner, if the runs go to a worker program.
    pub worker: Option<&'a Runner>,
    /// The condition the model is at.
    pub condition: &'a [(String, f64)],
}

impl ModelRuns for Dispatch<'_> {
    fn space(&self) -> &ParameterSpace {
        self.model.space()
    }
    fn solver(&self) -> Solver {
        match self.worker {
            Some(w) => w.solver.clone(),
            None => in_process(),
        }
    }
    fn executor(&self) -> impactcal_runner::Executor {
        self.worker
            .map_or(impactcal_runner::Executor::Local, |w| w.executor.clone())
    }
    fn model(&self) -> Option<&dyn Model> {
        match self.worker {
            Some(_) => None,
            None => Some(self.model),
        }
    }
    fn retries(&self) -> u32 {
        self.worker.map_or(0, |w| w.retries)
    }
    fn cancel(&self) -> Cancel {
        self.worker.map_or_else(Cancel::new, |w| w.cancel.clone())
    }
    fn condition(&self) -> &[(String, f64)] {
        self.condition
    }
}

/// The runner's solver for a model run in this process.
fn in_process() -> Solver {
    Solver {
        inputs: Vec::new(),
        command: SolverCommand::InProcess {
            description: "in-process model".into(),
        },
        // The model's histories go straight to the run's result file: no second copy.
        output: OutputSpec::csv(impactcal_runner::workdir::RESULT),
    }
}

/// What a study or a loop tells the person waiting for it. All methods default to nothing.
///
/// The calls come in this order: [`plan`](Self::plan) whenever the estimate of the whole
/// computation's runs changes; [`stage`](Self::stage) when a stage of runs starts (its
/// journal name, which [`stage_title`](crate::progress::stage_title) puts in words); then, for each
/// part of a stage run in parts after the first, [`part`](Self::part); and
/// [`run_finished`](Self::run_finished) once per run, the runs read back from the journal
/// first. A stage's runs number `total` when it is announced; the runs a part adds are
/// within that total.
pub trait Observer: Sync {
    /// The whole computation is estimated at `runs` model runs, those already finished
    /// included (an estimate, revised as stages end: a loop cannot know its rounds ahead).
    fn plan(&self, _runs: usize) {}
    /// A stage of `total` runs starts; `reused` of them come from the journal.
    fn stage(&self, _name: &str, _total: usize, _reused: usize) {}
    /// A further part of the current stage starts; `reused` of its runs come from the
    /// journal (they are reported first, through [`run_finished`](Self::run_finished)).
    fn part(&self, _reused: usize) {}
    /// One more run of the current stage finished (from the journal or run now).
    fn run_finished(&self) {}
    /// A stage without model runs (a fit, an analysis) starts.
    fn step(&self, _name: &str) {}
    /// Something the person should know that does not stop the computation (channels
    /// left out of the comparison, for example).
    fn warning(&self, _text: &str) {}
}

/// An observer that says nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Observer for Silent {}

/// What a run is, the output folder and the observer of one study.
pub(crate) struct Runs<'a> {
    model_runs: &'a dyn ModelRuns,
    root: PathBuf,
    fingerprint: String,
    observer: &'a dyn Observer,
    /// The channels each run's `result.csv` keeps (`None`: all).
    stored: Option<Vec<String>>,
}

impl<'a> Runs<'a> {
    /// The runs of the study with `fingerprint` in the folder `dir` (created if needed).
    ///
    /// # Errors
    /// [`CalibrateError::ForeignJournal`] when `dir` holds another study's runs (nothing is
    /// written then); [`CalibrateError::Journal`] when the folder cannot be written.
    pub fn open(
        model_runs: &'a dyn ModelRuns,
        dir: &Path,
        fingerprint: &str,
        observer: &'a dyn Observer,
    ) -> Result<Runs<'a>> {
        let stamp = dir.join("runs").join("fingerprint");
        match std::fs::read_to_string(&stamp) {
            Ok(found) if found.trim() == fingerprint => {}
            Ok(found) => {
                return Err(CalibrateError::ForeignJournal {
                    dir: dir.display().to_string(),
                    found: found.trim().to_string(),
                    expected: fingerprint.to_string(),
                });
            }
            Err(_) => {
                let root = dir.join("runs");
                std::fs::create_dir_all(&root).map_err(|e| io(&root, e))?;
                impactcal_runner::workdir::write_atomic(&stamp, fingerprint.as_bytes())
                    .map_err(|e| io(&stamp, e))?;
            }
        }
        Ok(Runs {
            model_runs,
            root: dir.to_path_buf(),
            fingerprint: fingerprint.to_string(),
            observer,
            stored: None,
        })
    }

    /// The same runs storing only the channels `labels` of each new run in its
    /// `result.csv` (`None`: every channel; runs already finished are read as they were
    /// stored). Each stage's readers select the channels they use, so a stage stored with
    /// more channels reads the same.
    #[must_use]
    pub fn storing(&self, labels: Option<Vec<String>>) -> Runs<'a> {
        Runs {
            model_runs: self.model_runs,
            root: self.root.clone(),
            fingerprint: self.fingerprint.clone(),
            observer: self.observer,
            stored: labels,
        }
    }

    /// The outcomes of `points` as stage `stage`: runs the journal holds as finished are
    /// read back, the others run through the executor, each journaled before it starts and
    /// after its result is read. Outcomes in input order; each run's histories stay in its
    /// result file until asked for ([`Outcomes::get`]).
    ///
    /// # Errors
    /// [`CalibrateError::Runner`] when the stage's journal cannot be written or belongs to
    /// another study, the executor cannot run the solver, or the runs were cancelled.
    pub fn stage(&self, stage: &str, points: &[Vec<f64>]) -> Result<Outcomes> {
        self.stage_from(stage, 0, points, true)
    }

    /// [`stage`](Self::stage) for runs `first..first + points.len()` of a stage run in
    /// parts (each part its own batch, `<stage>-<first>`); `announce` tells the observer a
    /// stage starts.
    ///
    /// # Errors
    /// As [`stage`](Self::stage).
    pub fn stage_from(
        &self,
        stage: &str,
        first: usize,
        points: &[Vec<f64>],
        announce: bool,
    ) -> Result<Outcomes> {
        if points.is_empty() {
            if announce {
                self.observer.stage(stage, 0, 0);
            }
            return Ok(Outcomes { runs: Vec::new() });
        }
        let name = batch_name(stage, first, announce);
        let space = self.model_runs.space();
        let batch = Batch::for_space_at(
            &self.root,
            &name,
            self.model_runs.solver(),
            space,
            points,
            self.model_runs.condition(),
        )?
        .with_retries(self.model_runs.retries())
        .with_identity(self.fingerprint.clone())
        .with_stored_channels(self.stored.clone());
        let opened = |reused: usize| {
            if announce {
                self.observer.stage(stage, points.len(), reused);
            } else {
                self.observer.part(reused);
            }
        };
        // Each run's histories are dropped as it finishes: they stay in its result file.
        let finished = |_: usize, _: std::result::Result<Histories, &RunnerError>| {
            self.observer.run_finished();
        };
        let model = self.model_runs.model().map(ModelSolver);
        let hooks = Hooks {
            in_process: match &model {
                Some(m) => Some(m as &dyn InProcessSolver),
                None => self.model_runs.in_process(),
            },
            opened: Some(&opened),
            finished: Some(&finished),
        };
        let report = run_batch_with(
            &batch,
            &self.model_runs.executor(),
            &self.model_runs.cancel(),
            hooks,
        )?;
        Ok(Outcomes {
            runs: report
                .runs
                .into_iter()
                .map(|r| r.map_err(|e| failure_message(&e)))
                .collect(),
        })
    }
}

/// The outcomes of one stage of runs, in input order: where each run's histories are, or
/// why the run failed. Nothing is held in memory: [`get`](Self::get) reads a run's
/// histories back from its result file (the same bits the run handed out), so that a stage
/// of many runs is read one run at a time.
#[derive(Debug, Clone, Default)]
pub struct Outcomes {
    runs: Vec<std::result::Result<RunResult, String>>,
}

impl Outcomes {
    /// Number of runs.
    pub fn len(&self) -> usize {
        self.runs.len()
    }

    /// Whether the stage had no run.
    pub fn is_empty(&self) -> bool {
        self.runs.is_empty()
    }

    /// Whether run `index` succeeded (false for an index out of range).
    pub fn succeeded(&self, index: usize) -> bool {
        matches!(self.runs.get(index), Some(Ok(_)))
    }

    /// The outcome of run `index`: its histories read back from its result file, or the
    /// failure's message. A result file that no longer reads (removed or edited since) and
    /// an index out of range are failures too, with the reason.
    pub fn get(&self, index: usize) -> RunOutcome {
        match self.runs.get(index) {
            Some(Ok(r)) => r.read().map_err(|e| e.to_string()),
            Some(Err(m)) => Err(m.clone()),
            None => Err(format!(
                "no run {index} (the stage has {})",
                self.runs.len()
            )),
        }
    }

    /// The histories of run `index`, or its failure as a simulation error naming `what`.
    ///
    /// # Errors
    /// [`CalibrateError::Core`] with the failure's message.
    pub fn histories(&self, index: usize, what: &str) -> Result<Histories> {
        histories_of(self.get(index), what)
    }
}

/// The batch of a stage (or of the part of a stage starting at run `first`): letters,
/// digits, `_`, `-` and `.` of the stage's name.
fn batch_name(stage: &str, first: usize, whole: bool) -> String {
    let clean: String = stage
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if whole {
        clean
    } else {
        format!("{clean}-{first}")
    }
}

/// The message a study keeps of a failed run: for a solver that exited with an error, its
/// status and the last line of its standard error (no path, so that the record does not
/// depend on where the study ran); otherwise the runner's message.
fn failure_message(e: &RunnerError) -> String {
    if let RunnerError::SolverExit { status, stderr, .. } = e {
        let text = std::fs::read_to_string(stderr).unwrap_or_default();
        let last = text.lines().rev().find(|l| !l.trim().is_empty());
        return match last {
            Some(line) => format!("solver exited with {status}: {}", line.trim()),
            None => format!("solver exited with {status}"),
        };
    }
    e.to_string()
}

fn io(path: &Path, e: std::io::Error) -> CalibrateError {
    CalibrateError::Journal {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// The histories of a successful outcome, or the simulation error.
pub(crate) fn histories_of(outcome: RunOutcome, what: &str) -> Result<Histories> {
    outcome.map_err(|m| CalibrateError::Core(CoreError::Simulation(format!("{what}: {m}").into())))
}
