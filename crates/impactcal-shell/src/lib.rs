//! An explicit shell-impact solver: the stand-in for LS-DYNA that produces the simulated
//! crash data impactcal calibrates.
//!
//! - Belytschko-Lin-Tsay 4-node shells (one in-plane point, corotational frame, 1 to 10
//!   thickness points, hourglass control, warping projection) and C0 triangles
//!   ([`element`]);
//! - plane-stress J2 plasticity with linear isotropic hardening by the exact return, and
//!   optional Cowper-Symonds rate scaling ([`material`]);
//! - lumped masses with scaled rotary inertia, point masses, gravity, mass-proportional
//!   damping, stiffness-proportional damping per part, shell bulk viscosity, single-point
//!   constraints, optional invariant node numbering;
//! - central-difference integration with the critical step recomputed every cycle
//!   ([`Simulation`]);
//! - stationary rigid planes with Coulomb friction (kinematic constraint, or penalty with a
//!   normal dashpot);
//! - any model as an [`impactcal_core::Model`] ([`DeckModel`]);
//! - energies, wall force and nodal histories as [`impactcal_core::Histories`] with labels
//!   `<node>.<x|y|z>`;
//! - the LS-DYNA keyword subset in and out ([`keyword`]).
//!
//! Element loops run in parallel with rayon; each element writes its own force slot and
//! nodes gather their slots in a fixed order, so results are bit-identical for any number
//! of threads. A run that goes unstable stops with [`ShellError::Unstable`] naming the
//! time, the cycle, the element and the cause.
//!
//! Build a model in code and run it: a 1 m steel strip, 20 x 1 quads, dropped flat on a
//! rigid floor.
//!
//! ```
//! use impactcal_shell::{
//!     InitialVelocity, Material, MaterialLaw, RigidWall, Section, ShellModel, Simulation,
//!     VelocityTarget,
//! };
//!
//! let mut m = ShellModel::new("strip drop");
//! for i in 0..=20u64 {
//!     for j in 0..=1u64 {
//!         m.add_node(1 + i * 2 + j, [0.05 * i as f64, 0.05 * j as f64, 0.01]);
//!     }
//! }
//! for i in 0..20u64 {
//!     let n = 1 + i * 2;
//!     m.add_shell(i + 1, 1, [n, n + 2, n + 3, n + 1]);
//! }
//! m.add_part(1, 1, 1);
//! m.sections.push(Section::new(1, 0.002));
//! m.materials.push(Material {
//!     id: 1,
//!     density: 7850.0,
//!     youngs: 210e9,
//!     poisson: 0.3,
//!     law: MaterialLaw::Plastic { yield_stress: 250e6, tangent_modulus: 1e9, rate: None },
//! });
//! m.initial_velocities.push(InitialVelocity::translation(VelocityTarget::All, [0.0, 0.0, -5.0]));
//! m.walls.push(RigidWall {
//!     friction: 0.2,
//!     ..RigidWall::plane([0.0; 3], [0.0, 0.0, 1.0])
//! });
//! m.control.end_time = 4e-3;
//! m.output.history_nodes = vec![21];
//! m.output.interval = 1e-4;
//!
//! let result = Simulation::new(&m)?.run()?;
//! let vz = result.velocity.as_ref().unwrap().channel_by_label("21.z")?.to_vec();
//! assert_eq!(vz[0], -5.0);
//! // The strip has landed and stopped: nothing passes through the floor.
//! assert!(vz.last().unwrap().abs() < 1.0);
//! assert!(result.summary.energy_ratio < 1.05);
//! # Ok::<(), impactcal_shell::ShellError>(())
//! ```
// `!(x > 0.0)` is used on purpose: it also rejects NaN.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

pub mod airframe;
pub mod contact;
pub mod deck_model;
pub mod element;
pub mod error;
mod geometry;
pub mod keyword;
pub mod material;
pub mod model;
mod rigid;
mod setup;
pub mod simulation;
mod validate;

pub use contact::{
    Contact, ContactControl, ContactFriction, ContactKind, ContactSurface, SideSettings,
};
pub use deck_model::DeckModel;
pub use error::{Result, ShellError, UnsupportedAt};
pub use model::{
    BodyLoadZ, BulkViscosity, Control, CowperSymonds, Curve, ElementThickness, Hardening,
    Hourglass, HourglassDef, HourglassForm, InitialVelocity, Material, MaterialLaw, MotionKind,
    MotionTarget, Node, NodeSet, NodeTarget, Output, Part, PartSet, PartStiffnessDamping,
    PointMass, PrescribedMotion, RigidConstraints, RigidWall, Section, Shell, ShellModel, Spc,
    SpotWeld, ThicknessRule, VelocityTarget, WallMethod, WallShape, WeldNodes,
};
pub use simulation::{Energies, PartEnergies, Progress, RunResult, RunSummary, Simulation};
