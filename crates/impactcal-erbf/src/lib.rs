//! Surrogates of whole time histories for impact-model calibration.
//!
//! - [`RbfInterpolant`]: classic radial basis function interpolation (cubic, thin-plate,
//!   Gaussian, multiquadric kernels; polynomial tail of degree -1, 0 or 1; optional
//!   smoothing), with values, gradients, batch prediction, leave-one-out errors and cheap
//!   growth by [`RbfInterpolant::add_points`]. The surrogate of the CORS-RBF optimiser.
//! - [`metrics`]: RAAE, RMAE and R^2.
//!
//! Every model fits `T` outputs at once (for example the samples of a time history) with a
//! single factorisation.
//!
//! ```
//! use impactcal_erbf::{RbfInterpolant, RbfOptions};
//!
//! // f(x, y) = x + 2 y is reproduced exactly by a cubic RBF with a linear tail.
//! let pts = vec![vec![0.0, 0.0], vec![1.0, 0.0], vec![0.0, 1.0], vec![1.0, 1.0], vec![0.3, 0.6]];
//! let f: Vec<f64> = pts.iter().map(|p| p[0] + 2.0 * p[1]).collect();
//! let s = RbfInterpolant::fit_rows(&pts, &f, RbfOptions::cubic())?;
//! assert!((s.predict(&[0.5, 0.25])?[0] - 1.0).abs() < 1e-12);
//! let (_, grad) = s.value_and_gradient(&[0.5, 0.25])?;
//! assert!((grad[1] - 2.0).abs() < 1e-10);
//! # Ok::<(), impactcal_erbf::ErbfError>(())
//! ```

pub mod data;
pub mod error;
pub mod kernel;
pub mod loo;
pub mod metrics;
pub mod rbf;

pub use data::StoredMat;
pub use error::{ErbfError, Result};
pub use kernel::{Kernel, PolyDegree};
pub use loo::{ErrorSummary, LooMethod};
pub use metrics::Accuracy;
pub use rbf::{RbfInterpolant, RbfOptions};
