//! The crate's error type.

use std::path::PathBuf;

use impactcal_calibrate::CalibrateError;
use impactcal_core::{CoreError, ErrorKind};
use impactcal_models::ModelsError;
use impactcal_runner::RunnerError;
use impactcal_shell::ShellError;

/// What went wrong with an experiment file or its runs.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExperimentError {
    /// A key of the file that is unknown, renamed, set twice or has a value that does not
    /// fit, with the line it is on.
    #[error("{file}: line {line}: {key}: {message}")]
    Key {
        /// The experiment file.
        file: String,
        /// 1-based line of the key.
        line: usize,
        /// The key, as `[section] name`.
        key: String,
        /// What is wrong and what to write instead.
        message: String,
    },
    /// A fault of the file that is not one key's (TOML syntax with its line and column, a
    /// section that is missing, sections that do not fit together).
    #[error("{file}: {message}")]
    File {
        /// The experiment file.
        file: String,
        /// What is wrong.
        message: String,
    },
    /// A fault found while building or running what a section describes, named by the file
    /// and the section.
    #[error("{file}: [{section}]: {source}")]
    Section {
        /// The experiment file.
        file: String,
        /// The section (`model`, `space`, `test`, ...).
        section: String,
        /// The fault.
        #[source]
        source: Box<ExperimentError>,
    },
    /// A file that cannot be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// From `impactcal-core`.
    #[error(transparent)]
    Core(#[from] CoreError),
    /// From `impactcal-shell` (decks, the airframe).
    #[error(transparent)]
    Shell(#[from] ShellError),
    /// From `impactcal-runner` (solvers, executors, run records).
    #[error(transparent)]
    Runner(#[from] RunnerError),
    /// From `impactcal-calibrate` (the study and the loop).
    #[error(transparent)]
    Calibrate(#[from] CalibrateError),
    /// From `impactcal-models` (model files and their records: a Kolsky bar test, a lumped
    /// system, ...).
    #[error(transparent)]
    Models(#[from] ModelsError),
}

impl ExperimentError {
    /// What kind of fault this is: a file or a value the user can fix is
    /// [`ErrorKind::BadInput`]; the wrapped crates' errors keep their kind.
    pub fn kind(&self) -> ErrorKind {
        match self {
            ExperimentError::Key { .. } | ExperimentError::File { .. } => ErrorKind::BadInput,
            ExperimentError::Section { source, .. } => source.kind(),
            ExperimentError::Io { .. } => ErrorKind::Io,
            ExperimentError::Core(e) => e.kind(),
            ExperimentError::Shell(e) => e.kind(),
            ExperimentError::Runner(e) => e.kind(),
            ExperimentError::Calibrate(e) => e.kind(),
            ExperimentError::Models(e) => e.kind(),
        }
    }

    /// This error placed in `section` of `file` (a [`ExperimentError::Section`]), unless it
    /// already names a file.
    #[must_use]
    pub fn in_section(self, file: &str, section: &str) -> Self {
        match self {
            e @ (ExperimentError::Key { .. }
            | ExperimentError::File { .. }
            | ExperimentError::Section { .. }) => e,
            e => ExperimentError::Section {
                file: file.to_string(),
                section: section.to_string(),
                source: Box::new(e),
            },
        }
    }
}

/// `Result` with [`ExperimentError`].
pub type Result<T, E = ExperimentError> = std::result::Result<T, E>;

/// A closure mapping an I/O error on `path` into [`ExperimentError::Io`].
pub(crate) fn io(path: &std::path::Path) -> impl FnOnce(std::io::Error) -> ExperimentError + '_ {
    move |source| ExperimentError::Io {
        path: path.to_path_buf(),
        source,
    }
}
