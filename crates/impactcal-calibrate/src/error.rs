//! The error type of `impactcal-calibrate`.

use impactcal_core::CoreError;

/// Everything that can go wrong when judging a model against a test.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CalibrateError {
    /// Reading, filtering or interpolating the data failed.
    #[error(transparent)]
    Core(#[from] CoreError),
    /// A curve on which a metric is undefined: a reference that is identically zero (no
    /// relative error exists), a computed curve that is identically zero (no phase exists),
    /// or a reference that is constant (ISO/TS 18571 has no corridor or slope for it).
    #[error("{what}: {reason}")]
    Degenerate {
        /// The channel or curve.
        what: String,
        /// Why the metric is undefined.
        reason: String,
    },
    /// Two curves of different lengths, or too short for the metric.
    #[error("{what}: {reason}")]
    Length {
        /// The channel or curve.
        what: String,
        /// What is wrong with the lengths.
        reason: String,
    },
    /// An option outside its allowed range.
    #[error("invalid option: {0}")]
    InvalidOption(String),
}

/// `Result` with [`CalibrateError`].
pub type Result<T, E = CalibrateError> = std::result::Result<T, E>;

impl CalibrateError {
    /// The same error with its subject rewritten by `f` (for example to name the channel a
    /// metric failed on); errors without a subject are returned unchanged.
    #[must_use]
    pub fn with_subject(self, f: impl FnOnce(&str) -> String) -> Self {
        match self {
            CalibrateError::Degenerate { what, reason } => CalibrateError::Degenerate {
                what: f(&what),
                reason,
            },
            CalibrateError::Length { what, reason } => CalibrateError::Length {
                what: f(&what),
                reason,
            },
            other => other,
        }
    }

    /// Whether the error is the user's input (a malformed file, an impossible option, a curve
    /// on which a metric is undefined) rather than a failure of the program.
    pub fn is_bad_input(&self) -> bool {
        match self {
            CalibrateError::Core(CoreError::Io { .. }) => false,
            CalibrateError::Core(_)
            | CalibrateError::Degenerate { .. }
            | CalibrateError::Length { .. }
            | CalibrateError::InvalidOption(_) => true,
        }
    }
}
