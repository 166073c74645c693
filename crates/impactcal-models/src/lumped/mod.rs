//! Driven lumped models: masses, springs, dashpots and gap contacts between them or to a
//! base that moves with a measured acceleration; the outputs are the absolute accelerations
//! of named masses, each named after the test channel that measured it.
//!
//! - [`system`]: the system as a file ([`LumpedSystem`]) and its typed errors.

pub mod system;

pub use system::{BASE, Dashpot, Gap, GapSides, LumpedSystem, Node, Output, Spring};
