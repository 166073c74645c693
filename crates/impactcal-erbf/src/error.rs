//! The error type of `impactcal-erbf`.

use impactcal_core::CoreError;

/// Everything that can go wrong when fitting, evaluating or loading a surrogate.
///
/// Sample indices in messages are 0-based positions in the training set (row `k` of the
/// points matrix); callers that read samples from a file map them to file lines.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ErbfError {
    /// An error of the shared types (parameter space, tables).
    #[error(transparent)]
    Core(#[from] CoreError),
    /// The training set is empty.
    #[error("no training samples (N = 0): a surrogate needs at least one sample")]
    NoSamples,
    /// A matrix or vector has the wrong size.
    #[error("{what}: expected {expected}, found {found}")]
    DimensionMismatch {
        /// The quantity whose size is wrong.
        what: String,
        /// The size required.
        expected: usize,
        /// The size given.
        found: usize,
    },
    /// A NaN or infinite number where finite numbers are required.
    #[error("{what}: non-finite value {value} at row {row}, column {column} (0-based)")]
    NonFinite {
        /// The quantity (for example `training points`).
        what: String,
        /// 0-based row.
        row: usize,
        /// 0-based column.
        column: usize,
        /// The offending value.
        value: f64,
    },
    /// Two training samples coincide or nearly coincide, so exact interpolation is
    /// impossible (two equal rows of the interpolation matrix).
    #[error(
        "training samples {first} and {second} (0-based) are duplicates: their distance \
         {distance:e} is below the tolerance {tolerance:e}; remove or merge one of them"
    )]
    DuplicateSamples {
        /// The earlier sample.
        first: usize,
        /// The later sample.
        second: usize,
        /// Their distance in the coordinates the model works in.
        distance: f64,
        /// The tolerance that was applied.
        tolerance: f64,
    },
    /// An option is out of its valid range.
    #[error("option `{name}` = {value}: {message}")]
    InvalidOption {
        /// The option.
        name: &'static str,
        /// The value given, as text.
        value: String,
        /// What is required.
        message: String,
    },
    /// The interpolation system is numerically singular.
    #[error(
        "the interpolation system is numerically singular (pivot ratio {ratio:e} below \
         {threshold:e}); the samples may be nearly coplanar, nearly duplicate, or too few for \
         the polynomial tail"
    )]
    Singular {
        /// Smallest over largest pivot magnitude of the factorisation.
        ratio: f64,
        /// The threshold below which the system is called singular.
        threshold: f64,
    },
    /// Leave-one-out errors are undefined for this training set (for example, removing a
    /// sample leaves too few points for the polynomial tail).
    #[error("leave-one-out error undefined at sample {sample} (0-based): {message}")]
    LooUndefined {
        /// The sample whose removal fails.
        sample: usize,
        /// Why.
        message: String,
    },
    /// Serialised model data that does not describe a valid model.
    #[error("invalid model data: {0}")]
    InvalidModel(String),
}

/// `Result` with [`ErbfError`].
pub type Result<T, E = ErbfError> = std::result::Result<T, E>;
