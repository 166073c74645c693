//! The split-Hopkinson (Kolsky) pressure bar.
//!
//! A striker hits the incident bar; the compressive pulse it launches (the incident wave)
//! runs past a strain gauge to the specimen, squeezed between the incident and the
//! transmitted bar; part of it reflects back past the same gauge as a tensile wave (the
//! reflected wave), part passes through the specimen into the transmitted bar and past its
//! gauge (the transmitted wave). The bars stay elastic, so the three gauge strains give the
//! forces and velocities at both faces of the specimen.
//!
//! Sign convention throughout: compression positive (strains, stresses, forces), particle
//! velocities positive towards the transmitted bar.
//!
//! - [`form`]: the neutral test form (TOML in SI units beside a signals file in volts), its
//!   bridges and the gauge strains ([`KolskyTest`]);
//! - [`lanl`]: the Los Alamos record converted into it;
//! - [`waves`]: the incident gauge's record split into incident and reflected waves, records
//!   resampled to what the bars carry;
//! - [`classic`]: the classic one- and three-wave analysis (stress, strain, strain rate,
//!   equilibrium);
//! - [`dispersion`]: the Pochhammer-Chree first mode, solved, and waves moved along a bar
//!   with it;
//! - [`model`]: the bar model, driven by the measured incident pulse ([`KolskyModel`]).

pub mod classic;
pub mod dispersion;
pub mod form;
pub mod lanl;
pub mod model;
pub mod waves;

pub use classic::ClassicAnalysis;
pub use dispersion::DispersionCurve;
pub use form::{BarSetup, GaugeBridge, KolskyTest, STRAIN_CHANNELS, Section, SpecimenSetup};
pub use lanl::{GainRow, LanlConversion, LanlOptions, from_lanl};
pub use model::{FaceRun, KolskyModel, OUTPUT_CHANNELS};
pub use waves::{Resampling, Separated, separate};
