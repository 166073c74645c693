//! The command's error type and exit codes.

use std::fmt;

/// A failure of the command, printed as one line on stderr.
#[derive(Debug)]
pub enum CliError {
    /// Bad input (a malformed file, an impossible option): exit code 2.
    Input(String),
    /// Anything else (a numerical failure, an output file that cannot be written): exit 1.
    Failure(String),
}

impl CliError {
    /// The process exit code for this error.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Input(_) => 2,
            CliError::Failure(_) => 1,
        }
    }

    /// An input error from anything printable.
    pub fn input(e: impl fmt::Display) -> Self {
        CliError::Input(e.to_string())
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Input(m) | CliError::Failure(m) => f.write_str(m),
        }
    }
}

impl From<impactcal::core::CoreError> for CliError {
    fn from(e: impactcal::core::CoreError) -> Self {
        use impactcal::core::CoreError as E;
        match e {
            E::Io { .. } => CliError::Failure(e.to_string()),
            _ => CliError::Input(e.to_string()),
        }
    }
}

impl From<impactcal::calibrate::CalibrateError> for CliError {
    fn from(e: impactcal::calibrate::CalibrateError) -> Self {
        if e.is_bad_input() {
            CliError::Input(e.to_string())
        } else {
            CliError::Failure(e.to_string())
        }
    }
}
