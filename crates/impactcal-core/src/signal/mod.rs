//! Signal processing for comparing tests with models: the SAE J211 / ISO 6487 channel
//! frequency class filters ([`Cfc`]), linear interpolation of model histories onto a test's
//! time points ([`interpolate_onto`]), linear resampling of non-uniform records onto a uniform
//! base ([`resample_uniform`]) and cropping to a time window ([`crop`]).
//!
//! Every comparison filters both sides with the same class, each on its own time base, and
//! only then interpolates the model onto the test's time points: filtering first makes the
//! CFC filter the anti-aliasing filter of the interpolation.

mod cfc;
mod resample;

pub use cfc::Cfc;
pub use resample::{Resampling, crop, interpolate_onto, resample_uniform};
