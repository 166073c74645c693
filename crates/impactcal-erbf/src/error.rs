//! The error type of `impactcal-erbf`.

use impactcal_core::{CoreError, ErrorKind};

/// Everything that can go wrong when fitting, evaluating or loading a surrogate.
///
/// Sample indices in messages are 0-based positions in the training set (row `k` of the
/// points matrix); callers that read samples from a file map them to file lines. Faults
/// shared with the other crates are [`CoreError`]s under [`ErbfError::Core`]: an empty
/// training set ([`CoreError::Empty`]), a wrong size ([`CoreError::DimensionMismatch`]), a
/// NaN or infinite entry ([`CoreError::NonFinite`], naming row and column) and an option
/// out of range ([`CoreError::InvalidOption`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ErbfError {
    /// A fault of a kind shared by every crate, or of the shared types (parameter space,
    /// tables).
    #[error(transparent)]
    Core(#[from] CoreError),
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
    /// The impact-shape decomposition of the training outputs failed (an output basis of
    /// [`crate::shape_basis`]).
    #[error(transparent)]
    Shapes(#[from] impactcal_shapes::ShapesError),
    /// Serialised model data that does not describe a valid model.
    #[error("invalid model data: {0}")]
    InvalidModel(String),
}

/// `Result` with [`ErbfError`].
pub type Result<T, E = ErbfError> = std::result::Result<T, E>;

impl ErbfError {
    /// What kind of fault this is: that of the wrapped [`CoreError`];
    /// [`ErrorKind::Numerical`] for a singular system or an undefined leave-one-out error;
    /// [`ErrorKind::BadInput`] for duplicate samples and invalid model data.
    pub fn kind(&self) -> ErrorKind {
        match self {
            ErbfError::Core(e) => e.kind(),
            ErbfError::Shapes(e) => e.kind(),
            ErbfError::Singular { .. } | ErbfError::LooUndefined { .. } => ErrorKind::Numerical,
            _ => ErrorKind::BadInput,
        }
    }
}

/// The empty training set.
pub(crate) fn no_samples() -> ErbfError {
    CoreError::Empty {
        what: "the training set (N = 0; a surrogate needs at least one sample)".into(),
    }
    .into()
}
