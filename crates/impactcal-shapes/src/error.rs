//! The error type of `impactcal-shapes`.

use impactcal_core::CoreError;

/// What can go wrong when computing, comparing or expanding impact shapes.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ShapesError {
    /// An error from the shared types (file input, histories).
    #[error(transparent)]
    Core(#[from] CoreError),
    /// A matrix or set with no rows or columns.
    #[error("{what} is empty")]
    Empty {
        /// The object that is empty.
        what: String,
    },
    /// A NaN or infinite entry.
    #[error("{what}: non-finite value at row {row}, column {column}")]
    NonFinite {
        /// The matrix.
        what: String,
        /// 0-based row.
        row: usize,
        /// 0-based column.
        column: usize,
    },
    /// Sizes that do not fit together.
    #[error("{what}: expected {expected}, found {found}")]
    DimensionMismatch {
        /// The quantity whose size is wrong.
        what: String,
        /// Required size.
        expected: usize,
        /// Given size.
        found: usize,
    },
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
    /// An option outside its valid range.
    #[error("invalid option: {0}")]
    InvalidOption(String),
    /// The SVD did not converge.
    #[error("the singular value decomposition did not converge")]
    NoConvergence,
}

/// `Result` with [`ShapesError`].
pub type Result<T, E = ShapesError> = std::result::Result<T, E>;
