//! The error type of `impactcal-models`.

use impactcal_core::{CoreError, ErrorKind};

/// Everything that can go wrong while reading a bar test, analysing it or running a model.
///
/// Errors about a test file name the file, the key (as a dotted TOML path such as
/// `incident.modulus`) and what is wrong with it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ModelsError {
    /// A key of a test file that is missing, of the wrong type or out of range.
    #[error("{file}: `{key}`: {message}")]
    Key {
        /// The file (or the name given to text parsed from memory).
        file: String,
        /// The dotted key path, for example `transmitted.gain`.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// A test file that is not valid TOML.
    #[error("{file}: not valid TOML: {message}")]
    Toml {
        /// The file.
        file: String,
        /// The parser's message (it gives the line and column).
        message: String,
    },
    /// A file that could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The path.
        path: String,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// A record that the analysis or the model cannot use, and why (for example an incident
    /// pulse longer than the gauge's round trip, which leaves no time to separate it from
    /// its reflection).
    #[error("{what}: {message}")]
    Record {
        /// What was being analysed.
        what: String,
        /// What is wrong.
        message: String,
    },
    /// An option or parameter value out of its admissible range.
    #[error("{name} = {value}: {message}")]
    Invalid {
        /// The option or parameter.
        name: String,
        /// The value given.
        value: String,
        /// What is wrong, with the admissible range.
        message: String,
    },
    /// A numerical procedure that failed on valid input (a root that could not be
    /// bracketed, a run that became non-finite).
    #[error("{what}: {message}")]
    Numerical {
        /// The procedure.
        what: String,
        /// What happened.
        message: String,
    },
    /// From `impactcal-core` (histories, signals files, parameter spaces).
    #[error(transparent)]
    Core(#[from] CoreError),
}

impl ModelsError {
    /// What kind of fault this is: [`ErrorKind::Io`] for files that could not be read,
    /// [`ErrorKind::Numerical`] for [`ModelsError::Numerical`], the core error's kind for
    /// [`ModelsError::Core`], and [`ErrorKind::BadInput`] for everything else.
    pub fn kind(&self) -> ErrorKind {
        match self {
            ModelsError::Io { .. } => ErrorKind::Io,
            ModelsError::Numerical { .. } => ErrorKind::Numerical,
            ModelsError::Core(e) => e.kind(),
            _ => ErrorKind::BadInput,
        }
    }

    /// An [`Invalid`](ModelsError::Invalid) error.
    pub fn invalid(
        name: impl Into<String>,
        value: impl std::fmt::Display,
        message: impl Into<String>,
    ) -> Self {
        ModelsError::Invalid {
            name: name.into(),
            value: value.to_string(),
            message: message.into(),
        }
    }

    /// A [`Record`](ModelsError::Record) error.
    pub fn record(what: impl Into<String>, message: impl Into<String>) -> Self {
        ModelsError::Record {
            what: what.into(),
            message: message.into(),
        }
    }
}

impl From<ModelsError> for CoreError {
    /// A models error inside a [`Model`](impactcal_core::Model) run: core errors pass
    /// through, others are wrapped as [`CoreError::Simulation`].
    fn from(e: ModelsError) -> Self {
        match e {
            ModelsError::Core(c) => c,
            other => CoreError::simulation(other),
        }
    }
}

/// `Result` with [`ModelsError`].
pub type Result<T, E = ModelsError> = std::result::Result<T, E>;
