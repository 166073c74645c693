//! CORS-RBF: global optimisation of expensive simulations with radial basis function
//! surrogates (Regis & Shoemaker, J. Global Optim. 31:153-171, 2005).
//!
//! A study works in the unit box of a [`ParameterSpace`](impactcal_core::ParameterSpace).
//! It starts from a symmetric Latin hypercube of `2 (d + 1)` points, from the user's
//! existing evaluations, or both. Each further point minimises an interpolating RBF
//! surrogate `s_n` (cubic or thin-plate, linear tail, fitted to every successful
//! evaluation) subject to staying at least `beta_n Delta_n` away from every evaluated point,
//! where `Delta_n = max_x min_j |x - x_j|` is the maximin distance and `beta_n` cycles
//! through `<0.9, 0.75, 0.25, 0.05, 0.03, 0>` once per evaluation: global search at the
//! start of a cycle, local search at its end.
//!
//! - [`Cors`]: the study, split as argmin splits a solver: a serialisable [`CorsState`],
//!   a step that is a pure function of it, and this driver. Ask and tell
//!   ([`Cors::suggest`] one or a batch of `q` distinct points, [`Cors::tell`] results, NaN
//!   for a failed run), or the closed loop [`Cors::minimize`]. State to and from JSON
//!   ([`Cors::save`], [`Cors::load`]), and [`Cors::from_history`] for stateless drivers.
//!   A point that had to be space-filling says why ([`FillReason`]).
//! - Under a noisy objective, [`Cors::surrogate_answer`] is the evaluated point where a
//!   smoothed RBF (smoothing chosen by leave-one-out) is lowest, next to the luckiest
//!   sample [`Cors::best`].
//! - [`CorsOptions`]: kernel, pattern, initial design, objective [`Transform`], stopping
//!   and restart rules (one stall rule for both), seed; checked into [`ValidCorsOptions`].
//!
//! Points are in the units of the parameter space; sets of points (a warm start, a history)
//! are faer matrices with one point per row. The Dixon-Szego test set is
//! [`impactcal_core::test_functions`].
//!
//! ```
//! use impactcal_core::test_functions;
//! use impactcal_cors::{Cors, CorsOptions};
//!
//! let branin = test_functions::by_name("branin").unwrap();
//! let mut study = Cors::new(branin.space()?, CorsOptions::with_seed(0))?;
//! let outcome = study.minimize(|x| branin.eval(x), 40)?;
//! let best = outcome.best.unwrap();
//! // Within 1% of the global minimum 0.397887 after 40 evaluations.
//! assert!(branin.relative_error(best.value.unwrap()) < 0.01);
//! // The study can be saved and resumed exactly.
//! let again = Cors::from_json(&study.to_json()?, "inline")?;
//! assert_eq!(again.evaluations(), study.evaluations());
//! # Ok::<(), impactcal_cors::CorsError>(())
//! ```

pub mod answer;
pub mod design;
pub mod error;
mod geometry;
pub mod optimizer;
pub mod options;
mod region;
mod schedule;
mod stall;
pub mod state;
mod step;
mod subproblem;
pub mod surrogate;

pub use answer::SurrogateAnswer;
pub use error::{CorsError, Result};
pub use optimizer::{Cors, Outcome, StopReason};
pub use options::{
    AdaptiveRegion, CandidateDecay, Converged, CorsOptions, DEFAULT_PATTERN, InitialDesign,
    Perturbation, RepeatRefinement, Restart, Stopping, SurrogateKernel, Transform,
    ValidCorsOptions, dycors_decay,
};
pub use state::{CorsState, Evaluation, FillReason, Mode, Origin, Suggestion};
