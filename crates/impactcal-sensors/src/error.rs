//! The error type of `impactcal-sensors`.

use impactcal_core::{CoreError, ErrorKind};

/// Everything that can stop a sensor placement.
///
/// Counts are numbers of candidate DOFs in per-DOF placement and numbers of nodes in
/// node-grouped placement, as stated in each variant. Faults shared with the other crates
/// are [`CoreError`]s under [`SensorsError::Core`]: a NaN or infinite shape value
/// ([`CoreError::NonFinite`], naming the candidate and the shape), an option out of range
/// ([`CoreError::InvalidOption`]), a wrong size, an empty matrix, a CSV fault (file, row and
/// column).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SensorsError {
    /// A fault of a kind shared by every crate, or of reading shared input.
    #[error(transparent)]
    Core(#[from] CoreError),
    /// Computing impact shapes from an ensemble of histories failed.
    #[error(transparent)]
    Shapes(#[from] impactcal_shapes::ShapesError),
    /// Fewer usable candidates than target shapes: the shapes cannot be told apart.
    #[error(
        "{candidates} usable candidate DOFs for {shapes} shapes: need at least as many candidates as shapes"
    )]
    TooFewCandidates {
        /// Usable candidate DOFs (after exclusions and dropping all-zero rows).
        candidates: usize,
        /// Number of shapes (columns).
        shapes: usize,
    },
    /// The target count is below the number of shapes (or, for nodes, the target nodes
    /// cannot hold as many DOFs as there are shapes).
    #[error("target of {target} {unit} cannot observe {shapes} shapes ({dofs} DOFs at most)")]
    TargetBelowShapes {
        /// The target count.
        target: usize,
        /// `"sensors"` or `"nodes"`.
        unit: &'static str,
        /// The most DOFs the target can hold.
        dofs: usize,
        /// Number of shapes.
        shapes: usize,
    },
    /// The target count exceeds what is available.
    #[error(
        "target of {target} {unit} exceeds the {available} usable {unit}{}",
        if *equivalent > 0 {
            format!(
                " ({equivalent} more repeat the information of others, such as mirror images on a \
                 symmetric structure, and count as one with them; see the equivalence tolerance)"
            )
        } else {
            String::new()
        }
    )]
    TargetAboveCandidates {
        /// The target count.
        target: usize,
        /// `"sensors"` or `"nodes"`.
        unit: &'static str,
        /// What is available, counting each set of equivalent candidates once.
        available: usize,
        /// Usable candidates left out as equivalent to another.
        equivalent: usize,
    },
    /// The shape matrix (restricted to the usable candidates and weighted) does not have
    /// full column rank.
    #[error(
        "the shape matrix has numerical rank {rank} but {shapes} shapes (sigma_min/sigma_max = {ratio:e}); truncate the shapes to {rank}"
    )]
    RankDeficient {
        /// Number of singular values above the tolerance.
        rank: usize,
        /// Number of shapes (columns).
        shapes: usize,
        /// Smallest over largest singular value.
        ratio: f64,
    },
    /// A label named in an option is not a candidate.
    #[error("{option}: no candidate labelled `{label}`")]
    UnknownLabel {
        /// The option (`keep`, `exclude`).
        option: &'static str,
        /// The label.
        label: String,
    },
    /// A label is both required and forbidden.
    #[error("`{label}` is both kept and excluded")]
    KeepExcludeConflict {
        /// The label.
        label: String,
    },
    /// More DOFs or nodes must stay than the target allows.
    #[error("{kept} {unit} must stay but the target is {target}")]
    TooManyKept {
        /// Number that must stay.
        kept: usize,
        /// `"sensors"` or `"nodes"`.
        unit: &'static str,
        /// The target.
        target: usize,
    },
    /// A label does not have the form `<node>.<x|y|z>` needed by node-grouped placement.
    #[error("candidate `{label}`: node-grouped placement needs labels `<node>.<x|y|z>`")]
    BadNodeLabel {
        /// The label.
        label: String,
    },
    /// Every removable candidate is essential: removing any would make the information
    /// matrix singular (the DOFs that must stay do not span the shapes).
    #[error(
        "cannot go below {remaining} {unit}: every removable candidate is essential (score {score})"
    )]
    AllEssential {
        /// Count still in the set.
        remaining: usize,
        /// `"sensors"` or `"nodes"`.
        unit: &'static str,
        /// The smallest score found.
        score: f64,
    },
    /// A dense factorisation failed to converge.
    #[error("numerical failure: {0}")]
    Numerical(String),
}

/// `Result` with [`SensorsError`].
pub type Result<T, E = SensorsError> = std::result::Result<T, E>;

impl SensorsError {
    /// What kind of fault this is: that of the wrapped [`CoreError`] or
    /// [`ShapesError`](impactcal_shapes::ShapesError); [`ErrorKind::Numerical`] for a
    /// factorisation that failed; [`ErrorKind::BadInput`] for the rest (targets, labels and
    /// shape matrices that cannot give a placement).
    pub fn kind(&self) -> ErrorKind {
        match self {
            SensorsError::Core(e) => e.kind(),
            SensorsError::Shapes(e) => e.kind(),
            SensorsError::Numerical(_) => ErrorKind::Numerical,
            _ => ErrorKind::BadInput,
        }
    }
}
