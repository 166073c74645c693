//! The error type of `impactcal-sobol`.

use impactcal_core::CoreError;

/// Everything that can go wrong when building a design or estimating indices.
///
/// Row and column numbers are 0-based positions in the design (row `r` is the `r`-th model
/// run in the SALib order) and in the output matrix.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SobolError {
    /// An error of the shared types (parameter spaces, sampling, tables).
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
    /// A matrix has the wrong number of columns or rows for its partner.
    #[error("{what}: expected {expected}, found {found}")]
    Mismatch {
        /// What does not match.
        what: String,
        /// The size required.
        expected: usize,
        /// The size given.
        found: usize,
    },
    /// A NaN or infinite model output.
    #[error("output row {row}, column {column}: non-finite value {value}")]
    NonFiniteOutput {
        /// 0-based row (model run).
        row: usize,
        /// 0-based output column.
        column: usize,
        /// The value.
        value: f64,
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
    /// An option out of its range.
    #[error("invalid option: {0}")]
    InvalidOption(String),
}

/// `Result` with [`SobolError`].
pub type Result<T, E = SobolError> = std::result::Result<T, E>;
