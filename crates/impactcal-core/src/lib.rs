//! Shared types of impactcal.
//!
//! - [`Histories`]: channels x samples on a uniform time base, with labels, read from and
//!   written to wide CSV (`time,<label>,...`).
//! - [`points`]: the one form of a point set, an `n x d` faer matrix with one point per row,
//!   and its conversions from and to rows.
//! - [`ParameterSpace`] and [`Parameter`]: named bounded parameters, the unit-cube map of
//!   single points and of whole matrices, and bounds files `name,lower,upper,nominal[,unit]`.
//! - [`testdata`]: measured data in: CSV records on their own time base, ISO-MME data sets,
//!   channel maps from test to model labels.
//! - [`signal`]: SAE J211 / ISO 6487 CFC filters, interpolation of model histories onto test
//!   time points, resampling and cropping.
//! - [`quality`]: checks of measured data before it is used (offsets, coloured noise and its
//!   AR model, mains lines, clipping, spikes, drift, gaps), the masks that keep faulty
//!   samples out of every residual, and the noise level from a band a model leaves empty.
//! - [`Model`]: a parameter vector in, histories out, with parallel batch evaluation.
//! - [`noise`]: the noise a model produces on its own, measured with a jitter ensemble
//!   ([`SimulationNoise`]: spread per channel and time, predictability horizons).
//! - [`sampling`]: Halton (plain and scrambled), Sobol' (Joe-Kuo, optionally Owen-scrambled),
//!   Latin hypercube and symmetric Latin hypercube samples, seeded, mapped onto a space.
//! - [`Table`]: the numeric CSV reader every file of the project goes through, reporting the
//!   file, row and column of the first fault.
//! - [`CoreError`]: the typed error of all of the above, and the kinds of fault shared by
//!   every crate ([`ErrorKind`]); [`ParamGuard`], how options are checked into a valid form.
//! - [`test_functions`]: standard test functions with their published constants.
//! - [`drop_tower`]: a fast impact model (three masses dropped on a contact spring) with its
//!   candidate effects, and [`synthetic`]: "measured" data made from model histories with a
//!   trigger offset, channel gains and biases, and noise at a given SNR.
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

pub mod drop_tower;
pub mod enrich;
pub mod error;
pub mod histories;
pub mod model;
pub mod noise;
pub mod points;
pub mod quality;
pub mod samples;
pub mod sampling;
pub mod signal;
pub mod simd;
pub mod space;
pub mod synthetic;
pub mod table;
pub mod test_functions;
pub mod testdata;

pub use enrich::{Candidate, Enrichable};
pub use error::{CoreError, ErrorKind, ParamGuard, Result, check_finite, check_finite_mat};
pub use histories::{Histories, NodalQuantity, norm_history_of};
pub use model::{BatchResults, Model, RunFailure};
pub use noise::{GroupHorizon, JitterOptions, SimulationNoise};
pub use points::PointRows;
pub use samples::{Samples, read_samples};
pub use sampling::Method as SamplingMethod;
pub use signal::Cfc;
pub use space::{Parameter, ParameterSpace};
pub use table::{Table, TableOptions, read_text};
pub use testdata::{ChannelMap, IsoMme, TestRecord};
