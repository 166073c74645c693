//! Driven lumped models: masses, springs, dashpots and gap contacts between them or to a
//! base that moves with a measured acceleration; the outputs are the absolute accelerations
//! of named masses, each named after the test channel that measured it.
//!
//! - [`system`]: the system as a file ([`LumpedSystem`]) and its typed errors;
//! - [`integrate`]: the integrator, exact for the linear part and symplectic for the
//!   contacts ([`Dynamics`]);
//! - [`model`]: the system driven by a test record's base channel, as a `Model` and an
//!   `Enrichable` with its held quantities ([`LumpedModel`]).

pub mod integrate;
pub mod model;
pub mod system;

pub use integrate::{Dynamics, GapLink, SpringLink, Trajectory};
pub use model::LumpedModel;
pub use system::{BASE, Dashpot, Gap, GapSides, LumpedSystem, Node, Output, Spring};
