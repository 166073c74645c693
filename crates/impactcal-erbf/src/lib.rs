//! Surrogates of whole time histories for impact-model calibration.
//!
//! - [`RbfInterpolant`]: classic radial basis function interpolation (cubic, thin-plate,
//!   Gaussian, multiquadric [`RadialFunction`]s; polynomial tail of degree -1, 0 or 1; optional
//!   smoothing), with values, gradients, batch prediction, leave-one-out errors and cheap
//!   growth by [`RbfInterpolant::add_points`]. The surrogate of the CORS-RBF optimiser.
//! - [`Erbf`]: the extended radial basis function metamodel of Mullur and Messac (Gaussian
//!   radial functions plus, per sample and input, the non-radial functions of [`nrbf`]),
//!   inputs scaled by the bounds of a parameter space, minimum-norm coefficients through a
//!   QR factorisation of `A^T`. Predicts whole time histories at the cost of one solve.
//! - [`ResponseSurrogate`]: any of the above over a parameter space with named outputs, as
//!   the `impactcal surrogate` command fits, saves and loads it.
//! - [`metrics`]: RAAE, RMAE and R^2. The test functions of the accuracy record are
//!   [`impactcal_core::test_functions`]; its designs, core's Latin hypercube.
//!
//! Training points and queries are faer matrices with one sample per row (`N x m`),
//! responses one row per sample (`N x T`); `fit_rows` takes rows of `Vec<f64>` for
//! convenience. Options are checked into [`ValidErbfOptions`] / [`ValidRbfOptions`]
//! ([`ParamGuard`](impactcal_core::ParamGuard)) before a fit works with them.
//!
//! Both models offer batch prediction (parallel, thread-count independent), gradients with
//! respect to the inputs, leave-one-out errors, a conditioning diagnostic, a flag for
//! queries outside the training domain, and serde serialisation (as options and training
//! data; loading refits).
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
//!
//! An ERBF surrogate of a two-sample "time history" over two bounded parameters:
//!
//! ```
//! use faer::Mat;
//! use impactcal_core::{Parameter, ParameterSpace};
//! use impactcal_erbf::{Erbf, ErbfOptions};
//!
//! let space = ParameterSpace::new(vec![
//!     Parameter::new("t_skin", 0.03, 0.07, 0.05)?,
//!     Parameter::new("e_foam", 100.0, 300.0, 200.0)?,
//! ])?;
//! let x = Mat::from_fn(12, 2, |i, j| {
//!     let u = ((i * (3 + 4 * j) + j) % 12) as f64 / 11.0;
//!     space.parameters()[j].lower + u * space.parameters()[j].width()
//! });
//! let f = Mat::from_fn(12, 2, |i, t| x[(i, 0)] * 100.0 + x[(i, 1)] * (t as f64 + 1.0) / 100.0);
//! let model = Erbf::fit(&space, x.as_ref(), f.as_ref(), ErbfOptions::default())?;
//! assert!(model.training_residual() < 1e-10);
//! assert_eq!(model.n_basis(), 12 * (3 * 2 + 1));
//! let history = model.predict(&[0.05, 200.0])?;
//! assert_eq!(history.len(), 2);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod basis;
pub mod bordered;
pub mod buffer;
pub mod components;
mod data;
pub mod erbf;
pub mod error;
mod factor;
pub mod loo;
mod lu;
pub mod metrics;
pub mod nested;
pub mod nrbf;
pub mod options;
mod projection;
pub mod radial;
pub mod rbf;
pub mod shape_basis;
mod smoothing;
pub mod surrogate;
mod thin_qr;
pub mod trend;
pub mod tuning;

pub use bordered::{BorderedRbf, RbfCoefficients};
pub use buffer::TrainingValues;
pub use components::{Components, OutputBasis, Tuning};
pub use erbf::Erbf;
pub use error::{ErbfError, Result};
pub use loo::{ErrorSummary, LooMethod};
pub use metrics::Accuracy;
pub use options::{ErbfOptions, FamilyWeights, ValidErbfOptions};
pub use radial::{PolyDegree, RadialFunction};
pub use rbf::{RbfInterpolant, RbfOptions, ValidRbfOptions};
pub use shape_basis::{ShapeBasis, ShapeSpectrum};
pub use surrogate::{
    FitOptions, LOO_ROUND_OFF, LooComparison, ResponseSurrogate, SurrogateKind, SurrogateModel,
};
pub use trend::linear_trend_loo;
pub use tuning::{ComponentOptions, Selection};
