//! Variance-based (Sobol') sensitivity of scalar and time-history outputs.
//!
//! For independent parameters `X_1..X_d` and an output `Y = f(X)` (one value per output
//! column: a time step, a channel, a metric), the first-order index
//! `S_i = Var(E[Y|X_i]) / Var(Y)` is the share of the variance that `X_i` explains alone,
//! and the total index `ST_i = E[Var(Y|X_~i)] / Var(Y)` the share of every term that
//! involves `X_i`. `0 <= S_i <= ST_i <= 1` in theory; estimates of small indices can be
//! slightly negative (report them with their intervals, do not clip them).
//!
//! The workflow:
//!
//! 1. [`SaltelliDesign::generate`] builds the pick-freeze design `A, AB_1..AB_d, [BA_1..BA_d,]
//!    B` over a [`ParameterSpace`](impactcal_core::ParameterSpace) from any core sampling
//!    method (scrambled Sobol' recommended), in SALib's row layout ([`DesignLayout`]);
//! 2. the caller runs the model (or a surrogate) on every row;
//! 3. [`analyze`] estimates `S_i`, `ST_i` (and `S_ik`) at every output column in one pass,
//!    the aggregated indices over all columns, bootstrap intervals with the same resamples
//!    for every column, and flags columns whose variance is (nearly) zero.
//!
//! Also: [`given_data_first_order`] for first-order indices from an existing ensemble
//! without a pick-freeze design, and [`replicate_spread`] for intervals from independently
//! scrambled designs. Test functions with exact indices (Ishigami, the G-function) are in
//! [`impactcal_core::test_functions`].
//!
//! Designs and outputs are faer matrices with one model run per row: the design's points
//! (`N (d + 2) x d`) and the outputs (`N (d + 2) x T`, one column per output).
//!
//! ```
//! use faer::ColRef;
//! use impactcal_core::sampling::Method;
//! use impactcal_core::test_functions;
//! use impactcal_core::{Parameter, ParameterSpace};
//! use impactcal_sobol::{analyze, SaltelliDesign, SobolOptions};
//! use std::f64::consts::PI;
//!
//! let space = ParameterSpace::new(
//!     ["x1", "x2", "x3"]
//!         .iter()
//!         .map(|n| Parameter::new(*n, -PI, PI, 0.0))
//!         .collect::<Result<Vec<_>, _>>()?,
//! )?;
//! let design = SaltelliDesign::generate(&space, 4096, Method::ScrambledSobol, false, 1)?;
//! let y: Vec<f64> = design
//!     .points
//!     .row_iter()
//!     .map(|x| {
//!         let x: Vec<f64> = x.iter().copied().collect();
//!         test_functions::ishigami(&x, 7.0, 0.1)
//!     })
//!     .collect();
//! let outputs = ColRef::from_slice(&y).as_mat();
//! let s = analyze(&design.layout, outputs, &SobolOptions::default())?;
//! let exact = test_functions::ishigami_indices(7.0, 0.1);
//! for i in 0..3 {
//!     assert!((s.first_order[0][i] - exact.first_order[i]).abs() < 0.02);
//!     assert!((s.total[0][i] - exact.total[i]).abs() < 0.02);
//! }
//! # Ok::<(), impactcal_sobol::SobolError>(())
//! ```

mod accumulate;
mod analysis;
mod design;
mod error;
mod estimators;
mod given_data;
mod replicates;
pub mod stats;

pub use analysis::{AggregatedIndices, BootstrapInfo, SobolIndices, SobolOptions, analyze};
pub use design::{DesignLayout, SaltelliDesign};
pub use error::{Result, SobolError};
pub use estimators::{FirstOrderEstimator, TotalEstimator};
pub use given_data::{GivenDataIndices, GivenDataOptions, given_data_first_order};
pub use replicates::{ReplicateSpread, replicate_spread};
