//! The error type of `impactcal-cors`.

use impactcal_core::{CoreError, ErrorKind};
use impactcal_erbf::ErbfError;

/// Everything that can go wrong while setting up or running a CORS-RBF study.
///
/// Faults shared with the other crates are [`CoreError`]s under [`CorsError::Core`]: an
/// option out of range ([`CoreError::InvalidOption`]), a point or list of the wrong length
/// ([`CoreError::DimensionMismatch`]), a NaN or infinite coordinate
/// ([`CoreError::NonFinite`], naming the point and the parameter) and file I/O
/// ([`CoreError::Io`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CorsError {
    /// A fault of a kind shared by every crate, or of the parameter space or a file.
    #[error(transparent)]
    Core(#[from] CoreError),
    /// A fault of the RBF surrogate that could not be worked around.
    #[error("RBF surrogate: {0}")]
    Rbf(#[from] ErbfError),
    /// A point outside the bounds of the parameter space.
    #[error("{what}: parameter `{parameter}` = {value} lies outside [{lower}, {upper}]")]
    OutOfBounds {
        /// Which point (for example `existing evaluation 3`).
        what: String,
        /// The parameter's name.
        parameter: String,
        /// The coordinate given.
        value: f64,
        /// Lower bound.
        lower: f64,
        /// Upper bound.
        upper: f64,
    },
    /// Two evaluated points that (nearly) coincide, which an interpolant cannot fit.
    #[error(
        "evaluations {first} and {second} nearly coincide (distance {distance:.3e} in the unit \
         box, tolerance {tolerance:.1e}); merge them or drop one"
    )]
    NearDuplicate {
        /// Index of the first point (in the evaluation history).
        first: usize,
        /// Index of the second point.
        second: usize,
        /// Their distance in the unit box.
        distance: f64,
        /// The tolerance below which points count as duplicates.
        tolerance: f64,
    },
    /// The initial set cannot support an RBF with a linear tail: it needs `dim + 1`
    /// affinely independent successful evaluations.
    #[error(
        "the initial set cannot support the surrogate: its {successes} successful evaluations \
         span an affine space of dimension {rank_minus_one}, but {dim} parameters need {needed} \
         affinely independent points (add evaluations, or let the optimiser run its design)"
    )]
    InsufficientInitialSet {
        /// Number of successful evaluations.
        successes: usize,
        /// Affine rank minus one of their points.
        rank_minus_one: usize,
        /// Number of parameters.
        dim: usize,
        /// Points needed: `dim + 1`.
        needed: usize,
    },
    /// A value that the chosen objective transform cannot take.
    #[error("evaluation value {value}: {message}")]
    TransformDomain {
        /// The value.
        value: f64,
        /// Why it cannot be transformed.
        message: String,
    },
    /// `tell` with an id that is not a pending suggestion.
    #[error("no pending suggestion has id {0} (already told, or never suggested)")]
    UnknownSuggestion(u64),
    /// A saved state that cannot be read back.
    #[error("optimiser state {source_name}: {message}")]
    State {
        /// The file or text the state came from.
        source_name: String,
        /// What is wrong.
        message: String,
    },
}

/// `Result` with [`CorsError`].
pub type Result<T, E = CorsError> = std::result::Result<T, E>;

impl CorsError {
    /// What kind of fault this is: that of the wrapped [`CoreError`] or [`ErbfError`], else
    /// [`ErrorKind::BadInput`] (points, values, ids or a saved state the study cannot take).
    pub fn kind(&self) -> ErrorKind {
        match self {
            CorsError::Core(e) => e.kind(),
            CorsError::Rbf(e) => e.kind(),
            _ => ErrorKind::BadInput,
        }
    }
}
