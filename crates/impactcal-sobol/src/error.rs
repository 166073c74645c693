//! The error type of `impactcal-sobol`.

use impactcal_core::{CoreError, ErrorKind};

/// Everything that can go wrong when building a design or estimating indices.
///
/// Row and column numbers are 0-based positions in the design (row `r` is the `r`-th model
/// run in the SALib order) and in the output matrix. Faults shared with the other crates (a
/// wrong size, a non-finite output, an option out of range) are [`CoreError`]s, under
/// [`SobolError::Core`].
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SobolError {
    /// A fault of a kind shared by every crate ([`CoreError::DimensionMismatch`],
    /// [`CoreError::NonFinite`], [`CoreError::InvalidOption`]), or of the shared types
    /// (parameter spaces, sampling, tables).
    #[error(transparent)]
    Core(#[from] CoreError),
    /// The number of rows is not `N (d + 2)` (or `N (2d + 2)` with second order).
    #[error("{rows} rows do not fit a Saltelli design of {d} parameters: {detail}")]
    RowCount {
        /// Rows given.
        rows: usize,
        /// Number of parameters.
        d: usize,
        /// What was expected, and a hint.
        detail: String,
    },
    /// Second-order indices asked of a design that cannot give them.
    #[error("second-order indices need {needs}; the design has {has}")]
    TooSmallForSecondOrder {
        /// What is needed.
        needs: String,
        /// What the design has.
        has: String,
    },
    /// A parameter matrix that does not have the pick-freeze structure of the layout.
    #[error("design row {row}, parameter {parameter}: {detail}")]
    DesignStructure {
        /// 0-based row.
        row: usize,
        /// 0-based parameter.
        parameter: usize,
        /// What is wrong.
        detail: String,
    },
}

/// `Result` with [`SobolError`].
pub type Result<T, E = SobolError> = std::result::Result<T, E>;

impl SobolError {
    /// What kind of fault this is: that of the [`CoreError`] it wraps, else
    /// [`ErrorKind::BadInput`] (a design of the wrong size or structure).
    pub fn kind(&self) -> ErrorKind {
        match self {
            SobolError::Core(e) => e.kind(),
            _ => ErrorKind::BadInput,
        }
    }
}
