//! Driven lumped models: masses, springs, dashpots and gap contacts between them or to a
//! base that moves with a measured acceleration; the outputs are the absolute accelerations
//! of named masses, each named after the test channel that measured it.
//!
//! - [`system`]: the system as a file ([`LumpedSystem`]) and its typed errors;
//! - [`integrate`]: the integrator, exact for the linear part and symplectic for the
//!   contacts ([`Dynamics`]);
//! - [`model`]: the system driven by a test record's base channel, as a `Model` and an
//!   `Enrichable` with its held quantities ([`LumpedModel`]);
//! - [`repeats`]: repeated tests of one article as one data set, calibration and holdout
//!   tests each with its own input ([`LumpedRepeats`]), and the scatter between repeats
//!   ([`scatter`]), after aligning the repeats in time on their input ([`alignment`]);
//! - [`align`]: the shift between two tests' inputs, to a fraction of a sample
//!   ([`input_shift`]).
//!
//! ```
//! use impactcal_core::{Enrichable, Histories, Model};
//! use impactcal_models::lumped::{LumpedModel, LumpedSystem};
//!
//! let system = LumpedSystem::parse(
//!     r#"
//!     [base]
//!     channel = "table"
//!     [masses]
//!     board = 0.05
//!     [springs.mount]
//!     between = ["base", "board"]
//!     stiffness = 1.8e7
//!     [outputs]
//!     "accel 1" = "board"
//!     "#,
//!     "board.toml",
//! )?;
//! // A step of the base: an undamped board overshoots to twice the step.
//! let record = Histories::from_channels(
//!     vec!["table".into()], vec![vec![100.0; 2000]], 1e-6, 0.0, "m/s^2")?;
//! let model = LumpedModel::new(system, &record)?;
//! assert_eq!(model.space().names(), ["k_mount", "zeta_mount"]);
//! let h = model.simulate(&model.space().nominal())?;
//! let peak = h.channel(0).iter().fold(0.0_f64, |m, a| m.max(*a));
//! assert!((peak - 200.0).abs() < 1e-2);
//! assert!(model.candidates().iter().any(|c| c.name() == "rattle_mount_c1_gap"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod align;
pub mod integrate;
pub mod model;
pub mod repeats;
pub mod system;

pub use align::{delay_exact, input_shift, shift_by};
pub use integrate::{Dynamics, GapLink, SpringLink, Trajectory};
pub use model::LumpedModel;
pub use repeats::{
    ChannelScatter, LumpedRepeats, REPEAT_SET, alignment, repeat_label, scatter, side_by_side,
};
pub use system::{BASE, Dashpot, Gap, GapSides, LumpedSystem, Node, Output, Spring};
