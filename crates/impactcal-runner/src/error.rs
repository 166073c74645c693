//! The error type of `impactcal-runner`.

use std::path::PathBuf;

use impactcal_core::{CoreError, ErrorKind};

/// Everything that can go wrong while preparing, running and reading back solver runs.
///
/// Variants that concern one run carry its 0-based `run` index in the batch and the file at
/// fault, so that a failure names what to look at; a failed run never stops the others.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RunnerError {
    /// A shared fault (a CSV file, a parameter, a dimension), from `impactcal-core`.
    #[error(transparent)]
    Core(#[from] CoreError),
    /// The configuration cannot be used.
    #[error("{file}: {message}")]
    Config {
        /// The configuration file (or `configuration` when built in code).
        file: String,
        /// What is wrong.
        message: String,
    },
    /// A deck template (or another templated input) cannot be used.
    #[error("{file}: line {line}: {message}")]
    Template {
        /// The template file.
        file: String,
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The names of the template and of the parameters do not match.
    #[error("{file}: {message}")]
    Names {
        /// The template file.
        file: String,
        /// Which names are missing on which side.
        message: String,
    },
    /// A value that cannot be written into its field of the deck.
    #[error("run {run}: parameter `{name}` = {value}: {message}")]
    Value {
        /// The run.
        run: usize,
        /// The parameter.
        name: String,
        /// Its value.
        value: f64,
        /// Why it cannot be written.
        message: String,
    },
    /// A file or directory of a run could not be created, written or read.
    #[error("run {run}: {}: {source}", path.display())]
    RunIo {
        /// The run.
        run: usize,
        /// The file or directory.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// A file or directory outside a run (the journal, a batch script) could not be used.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// The solver program could not be started (not found, not executable).
    #[error("run {run}: cannot start the solver `{program}`: {message}")]
    SolverStart {
        /// The run.
        run: usize,
        /// The program (the first element of the command).
        program: String,
        /// Why.
        message: String,
    },
    /// The solver ended with a non-zero exit status (or was killed by a signal).
    #[error("run {run}: the solver exited with {status}; see {}", stderr.display())]
    SolverExit {
        /// The run.
        run: usize,
        /// `status 3`, `signal 9`, or the scheduler's exit code.
        status: String,
        /// The solver's captured standard error (its last lines are worth reading).
        stderr: PathBuf,
    },
    /// The solver ran longer than the per-run time limit and was killed.
    #[error("run {run}: the solver ran longer than {seconds} s and was killed; see {}", dir.display())]
    Timeout {
        /// The run.
        run: usize,
        /// The limit.
        seconds: f64,
        /// The run's work directory.
        dir: PathBuf,
    },
    /// The solver exited cleanly but its output is missing, empty, truncated or malformed.
    #[error("run {run}: {}: {message}", path.display())]
    Output {
        /// The run.
        run: usize,
        /// The output file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// A run that the scheduler lost (no exit status written and no longer queued).
    #[error("run {run}: Slurm task {job} ended without an exit status ({state}); see {}", dir.display())]
    Lost {
        /// The run.
        run: usize,
        /// `<array job id>_<task>`.
        job: String,
        /// What the scheduler still knows of it (state and exit code), or `unknown`.
        state: String,
        /// The run's work directory.
        dir: PathBuf,
    },
    /// A scheduler command failed or refused the job; its own message is kept.
    #[error("{command}: {message}")]
    Scheduler {
        /// The command (`sbatch`, `squeue`, ...).
        command: String,
        /// The scheduler's message (its standard error).
        message: String,
    },
    /// The scheduler refused the job array holding this run; its message is kept.
    #[error("run {run}: sbatch refused the job ({}): {message}", script.display())]
    Submit {
        /// The run.
        run: usize,
        /// The batch script submitted.
        script: PathBuf,
        /// The scheduler's message.
        message: String,
    },
    /// The journal cannot be read, or belongs to a different batch.
    #[error("{}: line {line}: {message}", path.display())]
    Journal {
        /// The journal file.
        path: PathBuf,
        /// 1-based line (0 for the file as a whole).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// An LS-DYNA result file (`binout` or `nodout`) that cannot be read: not the format,
    /// a feature the reader does not cover, cut short, or a branch, variable or id that is
    /// not there.
    #[error("{}: {message}", path.display())]
    Result {
        /// The file.
        path: PathBuf,
        /// What is wrong, with the byte offset or line where there is one.
        message: String,
    },
    /// The batch was interrupted (Ctrl-C); the journal holds everything done so far and a
    /// rerun resumes.
    #[error("interrupted; {message}")]
    Cancelled {
        /// What was done about the runs in flight.
        message: String,
    },
}

/// `Result` with [`RunnerError`].
pub type Result<T, E = RunnerError> = std::result::Result<T, E>;

impl RunnerError {
    /// What kind of fault this is: configuration, templates, names, values, a solver that
    /// cannot be started, a refused job and a journal of another batch are
    /// [`ErrorKind::BadInput`]; files that cannot be written are [`ErrorKind::Io`]; a
    /// solver that fails, times out, writes bad output or is lost, and an interruption,
    /// are [`ErrorKind::Numerical`] (a run that failed on valid input).
    pub fn kind(&self) -> ErrorKind {
        match self {
            RunnerError::Core(e) => e.kind(),
            RunnerError::Config { .. }
            | RunnerError::Template { .. }
            | RunnerError::Names { .. }
            | RunnerError::Value { .. }
            | RunnerError::SolverStart { .. }
            | RunnerError::Scheduler { .. }
            | RunnerError::Submit { .. }
            | RunnerError::Journal { .. }
            | RunnerError::Result { .. } => ErrorKind::BadInput,
            RunnerError::RunIo { .. } | RunnerError::Io { .. } => ErrorKind::Io,
            RunnerError::SolverExit { .. }
            | RunnerError::Timeout { .. }
            | RunnerError::Output { .. }
            | RunnerError::Lost { .. }
            | RunnerError::Cancelled { .. } => ErrorKind::Numerical,
        }
    }

    /// The run this error concerns, when it concerns one.
    pub fn run(&self) -> Option<usize> {
        match self {
            RunnerError::Value { run, .. }
            | RunnerError::RunIo { run, .. }
            | RunnerError::SolverStart { run, .. }
            | RunnerError::SolverExit { run, .. }
            | RunnerError::Timeout { run, .. }
            | RunnerError::Output { run, .. }
            | RunnerError::Submit { run, .. }
            | RunnerError::Lost { run, .. } => Some(*run),
            _ => None,
        }
    }

    /// Whether running again may help (a solver failure, a timeout, a lost task), as
    /// opposed to a fault that repeats on every attempt (bad values, a missing program).
    pub fn retryable(&self) -> bool {
        matches!(
            self,
            RunnerError::SolverExit { .. }
                | RunnerError::Timeout { .. }
                | RunnerError::Output { .. }
                | RunnerError::Lost { .. }
                | RunnerError::RunIo { .. }
        )
    }
}

/// An I/O error of run `run` on `path`.
pub(crate) fn run_io(
    run: usize,
    path: impl Into<PathBuf>,
) -> impl FnOnce(std::io::Error) -> RunnerError {
    let path = path.into();
    move |source| RunnerError::RunIo { run, path, source }
}

/// An I/O error on `path` outside a run.
pub(crate) fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> RunnerError {
    let path = path.into();
    move |source| RunnerError::Io { path, source }
}
