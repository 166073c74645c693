//! Sensor placement for impact tests by Kammer's effective independence (EfI).
//!
//! Given a candidate shape matrix `Phi` (`s` candidate DOFs x `k` target shapes, for
//! example the impact shapes of an ensemble of simulations), effective independence keeps
//! the `N` DOFs that make the `k` shapes as observable and as distinguishable as possible:
//! it maximises, greedily, `det(Phi_N^T Phi_N)` (D-optimal design), which keeps the
//! orthogonality matrix of the measured shapes well conditioned.
//!
//! - `E_D,i = [Phi (Phi^T Phi)^-1 Phi^T]_ii` is the leverage of DOF `i`: it lies in
//!   `[0, 1]`, the values sum to `k`, and removing DOF `i` multiplies `det(Phi^T Phi)` by
//!   exactly `1 - E_D,i`. It is computed from an orthonormal basis (QR), never from an
//!   explicit inverse, and does not change when `Phi` becomes `Phi T` (`T` invertible).
//! - Backward elimination ([`PlacementMethod::Backward`], Kammer 1991) removes the DOF of smallest
//!   `E_D` until `N` remain, updating every `E_D` by Sherman-Morrison in `O(s k)` per step,
//!   with a fresh QR every 100 steps against drift. Ties go to the lowest candidate index.
//! - Triaxial sensors ([`Grouping::Node`]): a node is scored by `1 - det(I - E_bb)` over its
//!   `3 x 3` block of the projector, the exact fraction of `det` lost with it; blocks are
//!   updated by Woodbury.
//! - Options ([`PlacementOptions`], whose setters check their values): DOFs to keep, DOFs
//!   to exclude, noise per DOF (prewhitening), a forward greedy method started by QR with
//!   column pivoting, and a swap refinement.
//! - Straight from simulations ([`place_from_histories`]): the runs of an ensemble are
//!   concatenated in time, their impact shapes computed (`impactcal-shapes`) and the
//!   placement made on those shapes, as the source paper does.
//! - The [`Placement`] carries the chosen DOFs, the removal order with each score, the
//!   retained information `det(A_kept)/det(A_full)`, the condition number, the largest
//!   off-diagonal of the normalised Gram matrix and the counts per axis.
//!
//! ```
//! use impactcal_sensors::{CandidateShapes, PlacementOptions, place};
//!
//! // Fixed-free chain of 10 unit masses and springs: its three lowest modes,
//! // phi_j(i) = sin((2j - 1) i pi / 21).
//! let labels: Vec<String> = (1..=10).map(|i| format!("{i}.x")).collect();
//! let rows: Vec<Vec<f64>> = (1..=10)
//!     .map(|i| {
//!         (1..=3)
//!             .map(|j| ((2 * j - 1) as f64 * i as f64 * std::f64::consts::PI / 21.0).sin())
//!             .collect()
//!     })
//!     .collect();
//! let candidates = CandidateShapes::from_rows(labels, &rows)?;
//! let placement = place(&candidates, &PlacementOptions::new(3))?;
//! assert_eq!(placement.selected, ["3.x", "6.x", "10.x"]);
//! assert!((placement.determinant_ratio - 0.055298).abs() < 1e-6);
//! # Ok::<(), impactcal_sensors::SensorsError>(())
//! ```

mod candidates;
mod elimination;
mod engine;
mod ensemble;
mod equivalence;
mod error;
mod linalg;
mod options;
mod place;

pub use candidates::{Axis, CandidateShapes, split_label};
pub use elimination::{ESSENTIAL, Elimination};
pub use ensemble::{EnsemblePlacement, concatenate_runs, place_from_histories};
pub use error::{Result, SensorsError};
pub use linalg::leverage_scores;
pub use options::{DEFAULT_EQUIVALENCE_TOLERANCE, Grouping, PlacementMethod, PlacementOptions};
pub use place::{AxisCounts, Equivalent, Placement, Step, Swap, place};
