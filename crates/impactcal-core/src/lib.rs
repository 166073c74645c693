//! Shared types of impactcal.
//!
//! - [`Histories`]: channels x samples on a uniform time base, with labels, read from and
//!   written to wide CSV (`time,<label>,...`).
//! - [`ParameterSpace`] and [`Parameter`]: named bounded parameters, the unit-cube map, and
//!   bounds files `name,lower,upper,nominal[,unit]`.
//! - [`Model`]: a parameter vector in, histories out, with parallel batch evaluation.
//! - [`noise`]: the noise a model produces on its own, measured with a jitter ensemble
//!   ([`SimulationNoise`]: spread per channel and time, predictability horizons).
//! - [`filter`]: a CFC low-pass filter (SAE J211 style) for single channels.
//! - [`sampling`]: Halton (plain and scrambled), Sobol' (Joe-Kuo, optionally Owen-scrambled),
//!   Latin hypercube and symmetric Latin hypercube samples, seeded, mapped onto a space.
//! - [`Table`]: the numeric CSV reader every file of the project goes through, reporting the
//!   file, row and column of the first fault.
//! - [`CoreError`]: the typed error of all of the above.
//!
//! ```
//! use impactcal_core::{Histories, Parameter, ParameterSpace};
//!
//! let space = ParameterSpace::new(vec![
//!     Parameter::new("belly_panel.t", 0.032, 0.064, 0.04)?.with_unit("in"),
//! ])?;
//! assert_eq!(space.to_unit(&[0.048])?, vec![0.5]);
//!
//! let h = Histories::parse_csv("time,12.z\n0,0\n0.001,-3\n0.002,-5\n", "inline")?;
//! assert_eq!(h.channels(), 1);
//! assert_eq!(h.samples(), 3);
//! assert_eq!(h.channel_by_label("12.z")?, &[0.0, -3.0, -5.0]);
//! # Ok::<(), impactcal_core::CoreError>(())
//! ```

pub mod error;
pub mod filter;
pub mod histories;
pub mod model;
pub mod noise;
pub mod sampling;
pub mod space;
pub mod table;

pub use error::{CoreError, Result, check_finite};
pub use histories::Histories;
pub use model::{BatchResults, Model, RunFailure};
pub use noise::{GroupHorizon, JitterOptions, SimulationNoise};
pub use sampling::{Method as SamplingMethod, Points};
pub use space::{Parameter, ParameterSpace};
pub use table::{Table, TableOptions, read_text};
