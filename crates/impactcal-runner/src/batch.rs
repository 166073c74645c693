//! A batch of runs: its points, work directories, journal, and the driver that every
//! executor shares (prepare a run, record it, read its result, decide on a retry, resume).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use impactcal_core::{Histories, PointRows};

use crate::error::{Result, RunnerError, io, run_io};
use crate::journal::{Entry, Journal};
use crate::solver::{Solver, SolverCommand};
use crate::template::{Template, check_names};
use crate::workdir::{self, RunRecord, now, read_exit_status, run_dir, write_atomic};

/// A request to stop, shared between a signal handler and the driver: the executors stop
/// starting runs, kill their local processes or `scancel` their Slurm jobs, and return
/// [`RunnerError::Cancelled`]. The journal keeps everything done so far.
#[derive(Debug, Clone, Default)]
pub struct Cancel(Arc<AtomicBool>);

impl Cancel {
    /// A token not cancelled yet.
    pub fn new() -> Self {
        Self::default()
    }
    /// Asks the batch to stop (callable from a signal handler: it only sets a flag).
    pub fn cancel(&self) {
        self.0.store(true, Ordering::SeqCst);
    }
    /// Whether a stop was asked for.
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::SeqCst)
    }
}

/// A batch of solver runs: one per point, in `<out>/runs/<study>/<index>/`, with the
/// journal `<out>/runs/<study>/journal.jsonl`.
#[derive(Debug, Clone)]
pub struct Batch {
    study: String,
    root: PathBuf,
    solver: Solver,
    names: Vec<String>,
    points: Vec<Vec<f64>>,
    retries: u32,
    identity: Option<String>,
    set: BTreeMap<String, f64>,
    stored: Option<Vec<String>>,
}

impl Batch {
    /// A batch of `points` (one per row; coordinates in the order of `names`) run by
    /// `solver` under `out`. `study` names the batch's directory (letters, digits, `_`, `-`,
    /// `.`). Retries default to 2 (three attempts in all for a run that fails in a way that
    /// another attempt may cure: a solver failure, a timeout, bad output, a lost task).
    ///
    /// # Errors
    /// [`RunnerError::Config`] for a bad study name or solver; [`RunnerError::Names`] when
    /// a name is not a plain identifier or names and templates do not match;
    /// [`impactcal_core::CoreError`] for no points, a point of the wrong length or a
    /// non-finite coordinate (naming the point).
    pub fn new<'p>(
        out: &Path,
        study: &str,
        solver: Solver,
        names: Vec<String>,
        points: impl Into<PointRows<'p>>,
    ) -> Result<Batch> {
        Batch::new_at(out, study, solver, names, points, &[])
    }

    /// [`Batch::new`] with quantities held at given values in every run (a test condition,
    /// such as the impact speed of a holdout test): `set` is written to each run's
    /// `params.json` under `set`, rendered into the templates beside the point's
    /// coordinates (a template names them like parameters), and part of the journal's batch
    /// line, so a journal of the batch at another condition is not resumed.
    ///
    /// # Errors
    /// As [`Batch::new`], the templates checked against the names and `set` together;
    /// [`RunnerError::Names`] when a name of `set` is also a coordinate or is repeated;
    /// [`impactcal_core::CoreError`] for a non-finite value.
    pub fn new_at<'p>(
        out: &Path,
        study: &str,
        solver: Solver,
        names: Vec<String>,
        points: impl Into<PointRows<'p>>,
        set: &[(String, f64)],
    ) -> Result<Batch> {
        let study_ok = !study.is_empty()
            && study != "."
            && study != ".."
            && study
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'));
        if !study_ok {
            return Err(RunnerError::Config {
                file: "configuration".into(),
                message: format!(
                    "study name `{study}` must be letters, digits, `_`, `-` or `.` only"
                ),
            });
        }
        solver.check("configuration")?;
        let mut held = BTreeMap::new();
        for (name, value) in set {
            if names.contains(name) || held.insert(name.clone(), *value).is_some() {
                return Err(RunnerError::Names {
                    file: "batch".into(),
                    message: format!(
                        "`{name}` is set twice (a coordinate of the points, or repeated in the \
                         condition)"
                    ),
                });
            }
            impactcal_core::check_finite(&format!("condition `{name}`"), &[*value])?;
        }
        let templates: Vec<&Template> = solver.inputs.iter().map(|(t, _)| t).collect();
        // Without templates the names reach the solver only through `params.json`.
        if !templates.is_empty() {
            let mut all = names.clone();
            all.extend(held.keys().cloned());
            check_names(&templates, &all)?;
        }
        let points = points.into();
        if points.is_empty() {
            return Err(impactcal_core::CoreError::Empty {
                what: "batch (no points)".into(),
            }
            .into());
        }
        let mut rows = Vec::with_capacity(points.len());
        for i in 0..points.len() {
            let p = points.point(i).into_owned();
            if p.len() != names.len() {
                return Err(impactcal_core::CoreError::DimensionMismatch {
                    what: format!("coordinates of point {i}"),
                    expected: names.len(),
                    found: p.len(),
                }
                .into());
            }
            impactcal_core::check_finite(&format!("point {i}"), &p)?;
            rows.push(p);
        }
        Ok(Batch {
            study: study.to_string(),
            root: out.join("runs").join(study),
            solver,
            names,
            points: rows,
            retries: 2,
            identity: None,
            set: held,
            stored: None,
        })
    }

    /// A batch over the parameters of `space` (points in its order and units), as a study
    /// submits its ensemble: [`Batch::new`] with the space's names.
    ///
    /// # Errors
    /// As [`Batch::new`].
    pub fn for_space<'p>(
        out: &Path,
        study: &str,
        solver: Solver,
        space: &impactcal_core::ParameterSpace,
        points: impl Into<PointRows<'p>>,
    ) -> Result<Batch> {
        Batch::for_space_at(out, study, solver, space, points, &[])
    }

    /// [`Batch::for_space`] at the condition `set` ([`Batch::new_at`]).
    ///
    /// # Errors
    /// As [`Batch::new_at`].
    pub fn for_space_at<'p>(
        out: &Path,
        study: &str,
        solver: Solver,
        space: &impactcal_core::ParameterSpace,
        points: impl Into<PointRows<'p>>,
        set: &[(String, f64)],
    ) -> Result<Batch> {
        let names = space.names().iter().map(|s| s.to_string()).collect();
        Batch::new_at(out, study, solver, names, points, set)
    }

    /// The same batch with at most `retries` further attempts per run.
    #[must_use]
    pub fn with_retries(mut self, retries: u32) -> Self {
        self.retries = retries;
        self
    }

    /// The same batch whose journal is tied to `identity` instead of the solver's
    /// fingerprint: a caller that knows what decides the results (a study's fingerprint,
    /// which covers its model) may then run the batch on another executor, whose solver
    /// command differs, and still resume it.
    #[must_use]
    pub fn with_identity(mut self, identity: impl Into<String>) -> Self {
        self.identity = Some(identity.into());
        self
    }

    /// The same batch keeping only the channels `labels` (in this order) of each run in its
    /// `result.csv`, as read from the solver's output; `None` keeps every channel (the
    /// default). A caller that compares a few channels of a model with many (24 of an
    /// airframe's 1,215) stores what it uses: the file holds `labels.len()` columns instead of
    /// the model's all. The solver's own output files are left as the solver wrote them. A
    /// run whose output lacks one of `labels` fails, naming the label.
    #[must_use]
    pub fn with_stored_channels(mut self, labels: Option<Vec<String>>) -> Self {
        self.stored = labels;
        self
    }

    /// The channels each run's `result.csv` keeps (`None`: all).
    pub fn stored_channels(&self) -> Option<&[String]> {
        self.stored.as_deref()
    }

    /// `<out>/runs/<study>`: the runs' directories and the journal.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// The journal's path.
    pub fn journal_path(&self) -> PathBuf {
        self.root.join("journal.jsonl")
    }

    /// Number of runs.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the batch has no run (never: [`Batch::new`] refuses that).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The solver.
    pub fn solver(&self) -> &Solver {
        &self.solver
    }

    /// The names of the points' coordinates.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The coordinates of run `index`.
    pub(crate) fn point(&self, index: usize) -> &[f64] {
        &self.points[index]
    }

    /// The study name.
    pub fn study(&self) -> &str {
        &self.study
    }
}

/// Where the result of a finished run is: its histories in our CSV, and their unit.
#[derive(Debug, Clone, PartialEq)]
pub struct RunResult {
    /// `<out>/runs/<study>/<index>/result.csv`.
    pub file: PathBuf,
    /// The unit of the histories.
    pub unit: String,
}

impl RunResult {
    /// Reads the histories back, exactly as the batch handed them out.
    ///
    /// # Errors
    /// [`RunnerError::Core`] when the file cannot be read or parsed (it was removed or
    /// edited since).
    pub fn read(&self) -> Result<Histories> {
        Ok(Histories::read_csv(&self.file)?.with_unit(self.unit.clone()))
    }
}

/// The outcome of a batch: one entry per point, in input order. The histories are not held
/// (a batch of 10,000 runs of 30 channels x 1,000 samples would hold 2.4 GB): they go to
/// [`Hooks::finished`] as each run finishes, and stay in each run's `result.csv`
/// ([`BatchReport::histories`]).
#[derive(Debug)]
pub struct BatchReport {
    /// `runs[i]`: where the histories of run `i` are, or why it failed (naming the run and
    /// the file).
    pub runs: Vec<Result<RunResult, RunnerError>>,
    /// `reused[i]`: the result was found finished in the journal (a resumed batch).
    pub reused: Vec<bool>,
    /// `attempts[i]`: the number of the attempt that gave the outcome (1-based, counted
    /// over every session of the batch).
    pub attempts: Vec<u32>,
}

impl BatchReport {
    /// The histories of run `index`, read back from its result file.
    ///
    /// # Errors
    /// The run's error when it failed (as text, in [`RunnerError::Output`]); an index out of
    /// range; [`RunResult::read`]'s errors.
    pub fn histories(&self, index: usize) -> Result<Histories> {
        match self.runs.get(index) {
            Some(Ok(r)) => r.read(),
            Some(Err(e)) => Err(RunnerError::Output {
                run: index,
                path: PathBuf::new(),
                message: e.to_string(),
            }),
            None => Err(RunnerError::Config {
                file: "batch".into(),
                message: format!("no run {index} (the batch has {})", self.runs.len()),
            }),
        }
    }

    /// The failed runs.
    pub fn failures(&self) -> impl Iterator<Item = (usize, &RunnerError)> {
        self.runs
            .iter()
            .enumerate()
            .filter_map(|(i, r)| r.as_ref().err().map(|e| (i, e)))
    }
}

/// What the journal says of one run when a batch is opened.
#[derive(Debug, Clone, Default)]
pub(crate) struct InFlight {
    /// The attempt in flight.
    pub attempt: u32,
    /// A local process: pid and start ticks.
    pub process: Option<(u32, u64)>,
    /// A Slurm array: its token (job name), job id once known, and the task.
    pub slurm: Option<(String, Option<String>, usize)>,
}

/// Called with each run's final outcome: the histories (moved to the caller, exactly as a
/// resumed batch reads them back) or the error. Runs reused from the journal come first, in
/// index order; then runs as they finish, from any thread.
pub type OnFinished<'a> = dyn Fn(usize, std::result::Result<Histories, &RunnerError>) + Sync + 'a;

/// What a caller hooks into [`run_batch_with`](crate::run_batch_with).
#[derive(Clone, Copy, Default)]
pub struct Hooks<'a> {
    /// The solver that [`SolverCommand::InProcess`] runs.
    pub in_process: Option<&'a dyn crate::solver::InProcessSolver>,
    /// Called once the journal is read, before any run: the number of runs the journal
    /// holds as finished (they are reused unless their result file no longer reads).
    pub opened: Option<&'a (dyn Fn(usize) + Sync)>,
    /// Called with each run's final outcome.
    pub finished: Option<&'a OnFinished<'a>>,
}

impl std::fmt::Debug for Hooks<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Hooks")
            .field("in_process", &self.in_process.is_some())
            .field("opened", &self.opened.is_some())
            .field("finished", &self.finished.is_some())
            .finish()
    }
}

#[derive(Debug)]
struct State {
    results: Vec<Option<Result<RunResult, RunnerError>>>,
    reused: Vec<bool>,
    last_attempt: Vec<u32>,
    session_attempts: Vec<u32>,
}

/// The part of running a batch that every executor shares.
pub(crate) struct Driver<'a> {
    pub batch: &'a Batch,
    pub cancel: &'a Cancel,
    pub executor: &'static str,
    pub hooks: Hooks<'a>,
    journal: Mutex<Journal>,
    state: Mutex<State>,
}

impl<'a> Driver<'a> {
    /// Opens the batch's journal, checks it belongs to this batch (writing the batch line
    /// when new), reuses finished runs, stops orphaned local solver processes, collects runs
    /// that ended while no driver watched, and returns the runs still to do and the Slurm
    /// tasks that may still be queued or running.
    pub fn open(
        batch: &'a Batch,
        cancel: &'a Cancel,
        executor: &'static str,
        hooks: Hooks<'a>,
    ) -> Result<(Driver<'a>, Vec<usize>, BTreeMap<usize, InFlight>)> {
        std::fs::create_dir_all(&batch.root).map_err(io(&batch.root))?;
        let path = batch.journal_path();
        let (mut journal, entries) = Journal::open(&path)?;
        let header = Entry::Batch {
            study: batch.study.clone(),
            names: batch.names.clone(),
            points: batch.points.clone(),
            solver: batch
                .identity
                .clone()
                .unwrap_or_else(|| batch.solver.fingerprint()),
            set: batch.set.clone(),
        };
        match entries.first() {
            None => journal.append(&header)?,
            Some(first) if *first == header => {}
            Some(_) => {
                return Err(RunnerError::Journal {
                    path,
                    line: 1,
                    message:
                        "the journal belongs to a different batch (other points, names or solver); \
                              use another output directory or study name"
                            .into(),
                });
            }
        }
        let n = batch.len();
        let mut done: Vec<Option<(String, String)>> = vec![None; n];
        let mut last_attempt = vec![0u32; n];
        let mut flight: BTreeMap<usize, InFlight> = BTreeMap::new();
        let mut tokens: BTreeMap<String, Option<String>> = BTreeMap::new();
        for e in &entries {
            match e {
                Entry::Submit { index, attempt, .. } if *index < n => {
                    last_attempt[*index] = last_attempt[*index].max(*attempt);
                    done[*index] = None;
                    flight.insert(
                        *index,
                        InFlight {
                            attempt: *attempt,
                            ..InFlight::default()
                        },
                    );
                }
                Entry::Started {
                    index,
                    attempt,
                    pid,
                    start_ticks,
                } => {
                    if let Some(f) = flight.get_mut(index).filter(|f| f.attempt == *attempt) {
                        f.process = Some((*pid, *start_ticks));
                    }
                }
                Entry::SlurmSubmit { token, indices } => {
                    tokens.insert(token.clone(), None);
                    for (k, i) in indices.iter().enumerate() {
                        if let Some(f) = flight.get_mut(i) {
                            f.slurm = Some((token.clone(), None, k));
                        }
                    }
                }
                Entry::SlurmJob { token, job_id } => {
                    tokens.insert(token.clone(), Some(job_id.clone()));
                }
                Entry::Result {
                    index, file, unit, ..
                } if *index < n => {
                    flight.remove(index);
                    done[*index] = Some((file.clone(), unit.clone()));
                }
                Entry::Failure { index, .. } => {
                    flight.remove(index);
                }
                _ => {}
            }
        }
        for f in flight.values_mut() {
            if let Some((token, job, _)) = &mut f.slurm {
                *job = tokens.get(token).cloned().flatten();
            }
        }
        let driver = Driver {
            batch,
            cancel,
            executor,
            hooks,
            journal: Mutex::new(journal),
            state: Mutex::new(State {
                results: (0..n).map(|_| None).collect(),
                reused: vec![false; n],
                last_attempt,
                session_attempts: vec![0; n],
            }),
        };
        if let Some(opened) = hooks.opened {
            opened(done.iter().filter(|d| d.is_some()).count());
        }
        let in_process = matches!(batch.solver.command, SolverCommand::InProcess { .. });
        let mut pending = Vec::new();
        let mut slurm = BTreeMap::new();
        for (i, finished) in done.into_iter().enumerate() {
            if let Some((file, unit)) = finished {
                let result = RunResult {
                    file: batch.root.join(file),
                    unit,
                };
                if let Ok(h) = result.read() {
                    {
                        let mut s = driver.lock_state();
                        s.results[i] = Some(Ok(result));
                        s.reused[i] = true;
                    }
                    if let Some(f) = hooks.finished {
                        f(i, Ok(h));
                    }
                    continue;
                }
            }
            match flight.remove(&i) {
                Some(f) if f.slurm.is_some() => {
                    slurm.insert(i, f);
                }
                Some(f) => {
                    if let Some((pid, ticks)) = f.process {
                        stop_orphan(pid, ticks);
                    }
                    // Ended while no driver watched: its exit status is on disk (an
                    // in-process solver is run again: its unit was not kept).
                    if !in_process && read_exit_status(&run_dir(&batch.root, i)).is_some() {
                        let outcome = driver.collect(i, f.attempt, None);
                        if !driver.settle(i, f.attempt, outcome)? {
                            let mut s = driver.lock_state();
                            s.reused[i] = true;
                            continue;
                        }
                    }
                    pending.push(i);
                }
                None => pending.push(i),
            }
        }
        Ok((driver, pending, slurm))
    }

    fn lock_state(&self) -> std::sync::MutexGuard<'_, State> {
        self.state
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Appends to the journal.
    pub fn record(&self, entry: &Entry) -> Result<()> {
        self.journal
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .append(entry)
    }

    /// The directory of run `index`.
    pub fn dir(&self, index: usize) -> PathBuf {
        run_dir(&self.batch.root, index)
    }

    /// Takes the next attempt number of run `index`, writes its inputs into a clean work
    /// directory with `params.json`, and returns the attempt. A per-run failure (a directory
    /// that cannot be created, a value that does not fit) is returned as `Ok(Err(..))`.
    pub fn prepare(&self, index: usize) -> Result<(u32, Result<PathBuf>)> {
        let attempt = {
            let mut s = self.lock_state();
            s.last_attempt[index] += 1;
            s.session_attempts[index] += 1;
            s.last_attempt[index]
        };
        Ok((attempt, self.write_inputs(index, attempt)))
    }

    fn write_inputs(&self, index: usize, attempt: u32) -> Result<PathBuf> {
        let dir = self.dir(index);
        std::fs::create_dir_all(&dir).map_err(run_io(index, &dir))?;
        let output = self.batch.solver.output.file.clone();
        for stale in [
            workdir::EXIT_STATUS,
            workdir::RESULT,
            workdir::STDOUT,
            workdir::STDERR,
            output.as_str(),
        ] {
            let p = dir.join(stale);
            match std::fs::remove_file(&p) {
                Ok(()) => {}
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(e) => return Err(run_io(index, p)(e)),
            }
        }
        let values = &self.batch.points[index];
        let mut written = values.clone();
        let mut names = self.batch.names.clone();
        names.extend(self.batch.set.keys().cloned());
        let mut all = values.clone();
        all.extend(self.batch.set.values());
        for (template, name) in &self.batch.solver.inputs {
            let (text, w) = template.render(index, &names, &all)?;
            for (k, v) in w.iter().take(values.len()).enumerate() {
                if v.to_bits() != values[k].to_bits() {
                    written[k] = *v;
                }
            }
            let p = dir.join(name);
            write_atomic(&p, text.as_bytes()).map_err(run_io(index, p))?;
        }
        let record = RunRecord {
            index,
            attempt,
            names: self.batch.names.clone(),
            values: values.clone(),
            written,
            set: self.batch.set.clone(),
            prepared_at: now(),
            finished_at: None,
            seconds: None,
            exit_status: None,
        };
        self.write_record(index, &record)?;
        Ok(dir)
    }

    fn write_record(&self, index: usize, record: &RunRecord) -> Result<()> {
        let p = self.dir(index).join(workdir::PARAMS);
        let text = serde_json::to_string_pretty(record).map_err(|e| RunnerError::RunIo {
            run: index,
            path: p.clone(),
            source: std::io::Error::other(e),
        })?;
        write_atomic(&p, text.as_bytes()).map_err(run_io(index, p))
    }

    /// Reads the result of run `index` from its directory: the exit status, then the
    /// output (given `unit` when the solver said it); writes `result.csv` atomically and
    /// completes `params.json`. The histories returned are `result.csv` as written, read
    /// back, so that a run and its reuse by a resumed batch give the same bits.
    pub fn collect(&self, index: usize, attempt: u32, unit: Option<String>) -> Result<Histories> {
        let dir = self.dir(index);
        let Some(status) = read_exit_status(&dir) else {
            return Err(RunnerError::Output {
                run: index,
                path: dir.join(workdir::EXIT_STATUS),
                message: "no exit status: the solver did not finish".into(),
            });
        };
        let p = dir.join(workdir::PARAMS);
        let record: Option<RunRecord> = std::fs::read_to_string(&p)
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok());
        let outcome = if status == 0 {
            self.batch.solver.output.read(index, &dir)
        } else {
            Err(RunnerError::SolverExit {
                run: index,
                status: describe_status(status),
                stderr: dir.join(workdir::STDERR),
            })
        };
        let outcome = match (outcome, &self.batch.stored) {
            (Ok(h), Some(labels)) => h.select(labels).map_err(|e| RunnerError::Output {
                run: index,
                path: dir.join(&self.batch.solver.output.file),
                message: format!("the channels to store: {e}"),
            }),
            (outcome, _) => outcome,
        };
        let outcome = match outcome {
            Ok(h) => {
                let unit = unit.unwrap_or_else(|| h.unit().to_string());
                let mut text = Vec::new();
                h.write_csv_to(&mut text, workdir::RESULT)?;
                let r = dir.join(workdir::RESULT);
                write_atomic(&r, &text).map_err(run_io(index, &r))?;
                let back = String::from_utf8_lossy(&text);
                Ok(Histories::parse_csv(&back, &r.display().to_string())?.with_unit(unit))
            }
            Err(e) => Err(e),
        };
        if let Some(mut record) = record.filter(|r| r.attempt == attempt) {
            let t = now();
            record.finished_at = Some(t);
            record.seconds = Some(t - record.prepared_at);
            record.exit_status = Some(status);
            self.write_record(index, &record)?;
        }
        outcome
    }

    /// Records the outcome of an attempt and says whether to try again: a result is
    /// journaled and kept; a failure is retried when another attempt may help and the
    /// run's attempts in this session are within the limit, and kept otherwise. Journal
    /// failures are returned as errors (the batch cannot go on without its record).
    pub fn settle(&self, index: usize, attempt: u32, outcome: Result<Histories>) -> Result<bool> {
        match outcome {
            Ok(h) => {
                let unit = h.unit().to_string();
                self.record(&Entry::Result {
                    index,
                    attempt,
                    file: format!("{index}/{}", workdir::RESULT),
                    unit: unit.clone(),
                })?;
                self.lock_state().results[index] = Some(Ok(RunResult {
                    file: self.dir(index).join(workdir::RESULT),
                    unit,
                }));
                if let Some(f) = self.hooks.finished {
                    f(index, Ok(h));
                }
                Ok(false)
            }
            Err(e) => {
                let retry = e.retryable()
                    && self.lock_state().session_attempts[index] <= self.batch.retries;
                self.record(&Entry::Failure {
                    index,
                    attempt,
                    error: e.to_string(),
                    retry,
                })?;
                if !retry {
                    if let Some(f) = self.hooks.finished {
                        f(index, Err(&e));
                    }
                    self.lock_state().results[index] = Some(Err(e));
                }
                Ok(retry)
            }
        }
    }

    /// Runs `index` to its outcome with `execute` (which starts the solver in the prepared
    /// directory and returns its exit status), retrying as [`settle`](Self::settle) says.
    pub fn drive(
        &self,
        index: usize,
        execute: impl Fn(&Self, usize, u32, &Path) -> Result<(i32, Option<String>)>,
    ) -> Result<()> {
        loop {
            if self.cancel.is_cancelled() {
                return Err(cancelled("no new run started"));
            }
            let (attempt, dir) = self.prepare(index)?;
            let outcome = match dir {
                Err(e) => Err(e),
                Ok(dir) => {
                    self.record(&Entry::Submit {
                        index,
                        attempt,
                        executor: self.executor.into(),
                    })?;
                    match execute(self, index, attempt, &dir) {
                        Err(e @ RunnerError::Cancelled { .. }) => return Err(e),
                        Err(e) => Err(e),
                        Ok((status, unit)) => {
                            let p = dir.join(workdir::EXIT_STATUS);
                            write_atomic(&p, format!("{status}\n").as_bytes())
                                .map_err(run_io(index, p))?;
                            self.collect(index, attempt, unit)
                        }
                    }
                }
            };
            if !self.settle(index, attempt, outcome)? {
                return Ok(());
            }
        }
    }

    /// The report, in input order.
    pub fn finish(self) -> BatchReport {
        let s = self
            .state
            .into_inner()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let runs = s
            .results
            .into_iter()
            .enumerate()
            .map(|(i, r)| {
                r.unwrap_or_else(|| {
                    Err(RunnerError::Output {
                        run: i,
                        path: run_dir(&self.batch.root, i),
                        message: "the run did not finish".into(),
                    })
                })
            })
            .collect();
        BatchReport {
            runs,
            reused: s.reused,
            attempts: s.last_attempt,
        }
    }
}

/// A [`RunnerError::Cancelled`].
pub(crate) fn cancelled(message: &str) -> RunnerError {
    RunnerError::Cancelled {
        message: format!("{message}; run the same command again to resume"),
    }
}

/// `exit 3`, or `signal 9` for statuses above 128 (the shell's convention).
pub(crate) fn describe_status(status: i32) -> String {
    if status > 128 && status < 160 {
        format!("signal {} (status {status})", status - 128)
    } else {
        format!("status {status}")
    }
}

/// Stops a solver process left running by a driver that was killed: only if the pid
/// still belongs to the process that was started (same start time), so a reused pid is
/// never touched. Waits until it has exited (or is a zombie).
fn stop_orphan(pid: u32, start_ticks: u64) {
    let alive = |pid: u32| -> Option<(char, u64)> {
        let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
        let rest = &stat[stat.rfind(')')? + 1..];
        let fields: Vec<&str> = rest.split_whitespace().collect();
        let state = fields.first()?.chars().next()?;
        let ticks = fields.get(19)?.parse().ok()?;
        Some((state, ticks))
    };
    match alive(pid) {
        Some((state, ticks)) if ticks == start_ticks && state != 'Z' => {}
        _ => return,
    }
    let _ = std::process::Command::new("kill")
        .args(["-KILL", &pid.to_string()])
        .status();
    for _ in 0..200 {
        match alive(pid) {
            Some((state, ticks)) if ticks == start_ticks && state != 'Z' => {
                std::thread::sleep(std::time::Duration::from_millis(10));
            }
            _ => return,
        }
    }
}

/// The start time of process `pid` in clock ticks since boot (field 22 of
/// `/proc/<pid>/stat`), or 0 when unknown.
pub(crate) fn start_ticks(pid: u32) -> u64 {
    std::fs::read_to_string(format!("/proc/{pid}/stat"))
        .ok()
        .and_then(|stat| {
            let rest = &stat[stat.rfind(')')? + 1..];
            rest.split_whitespace().nth(19)?.parse().ok()
        })
        .unwrap_or(0)
}
