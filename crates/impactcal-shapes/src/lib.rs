//! Impact shapes of multi-channel impact time histories.
//!
//! A response matrix `Y` (m channels x L samples, for example the velocities of many nodes
//! during a crash) is decomposed by the thin SVD into
//! `Y = sum_i sigma_i phi_i g_i^T` (source paper Eq. 4.2): impact shapes `phi_i` over the
//! channels, time functions `g_i` over the samples, and singular values `sigma_i` whose
//! shares `delta_i = sigma_i / sum sigma_l` say how much each shape contributes (Eq. 4.3).
//!
//! - [`ImpactShapes`]: the decomposition with a deterministic sign rule, truncation
//!   ([`Truncation`]), contributions, energy fractions, reconstruction; the full thin SVD or a
//!   randomized truncated solver ([`SvdMethod`]).
//! - [`Orthogonality`]: calibration metric M2 (Eq. 4.4) between analysis and test shapes,
//!   optimal pairing, the count above a threshold, principal-angle cosines.
//! - [`Expansion`]: unmeasured responses from measured ones through model shapes
//!   (Eqs. 4.5-4.8), with `cond(Phi)`.
//!
//! ```
//! use faer::Mat;
//! use impactcal_shapes::{ImpactShapes, Orthogonality, ShapeOptions};
//!
//! // Two rank-one patterns over 4 channels and 100 samples.
//! let y = Mat::from_fn(4, 100, |i, j| {
//!     let t = j as f64 / 100.0;
//!     3.0 * [0.5, 0.5, 0.5, 0.5][i] * (6.0 * t).sin() + [0.5, -0.5, 0.5, -0.5][i] * (2.0 * t).cos()
//! });
//! let shapes = ImpactShapes::from_matrix(y.as_ref(), &ShapeOptions::default())?;
//! assert_eq!(shapes.len(), 2);
//! let m2 = Orthogonality::from_matrices(shapes.shapes(), shapes.shapes())?;
//! assert_eq!(m2.matched_above(0.9), 2);
//! # Ok::<(), impactcal_shapes::ShapesError>(())
//! ```

mod assignment;
mod checks;
pub mod decompose;
pub mod error;
pub mod expansion;
pub mod orthogonality;
pub mod randomized;

pub use decompose::{ContributionBasis, ImpactShapes, ShapeOptions, SvdMethod, Truncation};
pub use error::{Result, ShapesError};
pub use expansion::{Expansion, expand_matrix};
pub use orthogonality::{Orthogonality, ShapePair};
pub use randomized::RandomizedSvd;
