//! Models that are not the shell solver: lumped and one-dimensional models of laboratory
//! impact tests, each a [`Model`](impactcal_core::Model) (and, where it holds quantities it
//! could free, an [`Enrichable`](impactcal_core::Enrichable)) driven by the measured inputs
//! the test has.
//!
//! - [`kolsky`]: the split-Hopkinson (Kolsky) pressure bar: a bar test as data (the neutral
//!   test form, the Los Alamos record converted into it).
//! - [`lumped`]: driven lumped systems (masses, springs, dashpots, gap contacts) defined in
//!   a file and driven by a measured base acceleration.
//!
//! The drop tower (`impactcal_core::drop_tower`) belongs here too and moves into this crate
//! later; until then it stays in `impactcal-core`.
//!
//! This crate depends on `impactcal-core` only.

pub mod error;
mod keys;
pub mod kolsky;
pub mod lumped;

pub use error::{ModelsError, Result};
