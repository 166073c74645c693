//! The error type of `impactcal-shapes`.

use impactcal_core::{CoreError, ErrorKind};

/// What can go wrong when computing, comparing or expanding impact shapes.
///
/// Faults shared with the other crates are [`CoreError`]s under [`ShapesError::Core`]: an
/// empty matrix ([`CoreError::Empty`]), a NaN or infinite entry ([`CoreError::NonFinite`],
/// naming row and column), sizes that do not fit ([`CoreError::DimensionMismatch`]) and an
/// option out of range ([`CoreError::InvalidOption`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ShapesError {
    /// A fault of a kind shared by every crate, or of the shared types (file input,
    /// histories).
    #[error(transparent)]
    Core(#[from] CoreError),
    /// More shapes were asked for than the data's numerical rank supports.
    #[error("{requested} shapes requested but the data has numerical rank {rank}")]
    TooManyShapes {
        /// Shapes asked for.
        requested: usize,
        /// Numerical rank of the data.
        rank: usize,
    },
    /// The two sides of a comparison or an expansion do not have the same channels.
    #[error("channel `{label}` of the {side} is missing on the other side")]
    LabelMismatch {
        /// The label without a partner.
        label: String,
        /// Which side has it (`test`, `analysis`, `measured data`...).
        side: String,
    },
    /// The shapes restricted to the measured channels are (numerically) rank deficient, so
    /// the expansion is not determined.
    #[error(
        "the {shapes} shapes at the {channels} measured channels have numerical rank {rank} \
         (condition number {condition:.3e}); measure more or better-placed channels or use fewer shapes"
    )]
    RankDeficient {
        /// Rank found.
        rank: usize,
        /// Number of shapes used.
        shapes: usize,
        /// Number of measured channels.
        channels: usize,
        /// sigma_max / sigma_min of the restricted shape matrix (infinite when singular).
        condition: f64,
    },
    /// The SVD did not converge.
    #[error("the singular value decomposition did not converge")]
    NoConvergence,
}

/// `Result` with [`ShapesError`].
pub type Result<T, E = ShapesError> = std::result::Result<T, E>;

impl ShapesError {
    /// What kind of fault this is: that of the wrapped [`CoreError`];
    /// [`ErrorKind::Numerical`] for an SVD that did not converge; [`ErrorKind::BadInput`]
    /// for the rest (requests the data cannot support).
    pub fn kind(&self) -> ErrorKind {
        match self {
            ShapesError::Core(e) => e.kind(),
            ShapesError::NoConvergence => ErrorKind::Numerical,
            _ => ErrorKind::BadInput,
        }
    }
}
