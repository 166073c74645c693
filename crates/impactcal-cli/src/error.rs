//! The command's error type, and the one place where a fault becomes an exit code.

use std::fmt;

use impactcal::ErrorKind;

/// A failure of the command, printed as one line on stderr: a message and the kind of
/// fault, which alone decides the exit code ([`CliError::exit_code`]).
#[derive(Debug)]
pub struct CliError {
    message: String,
    kind: ErrorKind,
}

impl CliError {
    /// The process exit code: 2 for bad input (a malformed file, an impossible option), 1
    /// for any other failure (a numerical failure, a file that cannot be read or written).
    pub fn exit_code(&self) -> u8 {
        match self.kind {
            ErrorKind::BadInput => 2,
            _ => 1,
        }
    }

    /// Bad input found by the command itself (its arguments, files that do not fit
    /// together).
    pub fn input(message: impl fmt::Display) -> Self {
        CliError {
            message: message.to_string(),
            kind: ErrorKind::BadInput,
        }
    }

    /// A file or stream that could not be read or written.
    pub fn io(message: impl fmt::Display) -> Self {
        CliError {
            message: message.to_string(),
            kind: ErrorKind::Io,
        }
    }

    /// A failure that is not the input's fault.
    pub fn failure(message: impl fmt::Display) -> Self {
        CliError {
            message: message.to_string(),
            kind: ErrorKind::Numerical,
        }
    }

    /// The same error, its message prefixed by `context` (for example the file it
    /// concerns) unless the message already starts with it.
    #[must_use]
    pub fn context(mut self, context: impl fmt::Display) -> Self {
        let context = context.to_string();
        if !self.message.starts_with(&context) {
            self.message = format!("{context}: {}", self.message);
        }
        self
    }
}

impl CliError {
    /// The same error with a hint appended in parentheses.
    #[must_use]
    pub fn hint(mut self, hint: impl fmt::Display) -> Self {
        self.message = format!("{} ({hint})", self.message);
        self
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl From<impactcal::Error> for CliError {
    fn from(e: impactcal::Error) -> Self {
        CliError {
            message: e.to_string(),
            kind: e.kind(),
        }
    }
}

/// Every library error becomes a command error through [`impactcal::Error`] and its kind.
macro_rules! from_library_error {
    ($($t:ty),*) => {
        $(impl From<$t> for CliError {
            fn from(e: $t) -> Self {
                impactcal::Error::from(e).into()
            }
        })*
    };
}

from_library_error!(
    impactcal::core::CoreError,
    impactcal::shapes::ShapesError,
    impactcal::sensors::SensorsError,
    impactcal::erbf::ErbfError,
    impactcal::sobol::SobolError,
    impactcal::cors::CorsError,
    impactcal::shell::ShellError,
    impactcal::calibrate::CalibrateError,
    impactcal::runner::RunnerError,
    impactcal::experiment::ExperimentError
);

#[cfg(test)]
mod tests {
    use super::*;
    use impactcal::core::CoreError;

    #[test]
    fn kinds_decide_the_exit_code() {
        assert_eq!(CliError::input("bad").exit_code(), 2);
        assert_eq!(CliError::io("disk").exit_code(), 1);
        assert_eq!(CliError::failure("svd").exit_code(), 1);
        let io = CoreError::Io {
            path: "a.csv".into(),
            source: std::io::Error::from(std::io::ErrorKind::NotFound),
        };
        assert_eq!(CliError::from(io).exit_code(), 1);
        let e = CliError::from(CoreError::invalid_option("n", 0, "must be positive"));
        assert_eq!(e.exit_code(), 2);
        assert_eq!(
            e.context("p.csv").to_string(),
            "p.csv: option `n` = 0: must be positive"
        );
        let e = CliError::input("p.csv: row 2").context("p.csv");
        assert_eq!(e.to_string(), "p.csv: row 2");
    }
}
