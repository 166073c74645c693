//! Calibration of impact models against tests.
//!
//! [`metrics`] judges a computed time history against a measured one with the curve metrics
//! crash analysts use: relative L2, RMS, peak and time-of-peak errors, Sprague-Geers,
//! Russell, and the ISO/TS 18571 rating with its corridor, phase, magnitude and slope scores.
//! It works on slices and on whole [`Histories`](impactcal_core::Histories) pairs, where it
//! applies the same CFC filter to both sides and interpolates the model onto the test's time
//! points.
//!
//! ```
//! use impactcal_calibrate::metrics::{Grade, Iso18571, SpragueGeers};
//!
//! // A measured pulse and a model that peaks 10 % high, 2 ms late (10 kHz sampling).
//! let pulse = |at: f64, amp: f64| -> Vec<f64> {
//!     (0..801).map(|k| amp * (-((k as f64 - at) / 60.0).powi(2)).exp()).collect()
//! };
//! let test = pulse(300.0, 40.0);
//! let model = pulse(320.0, 44.0);
//! let sg = SpragueGeers::between(&test, &model)?;
//! assert!((sg.magnitude - 0.1).abs() < 1e-9);
//! let iso = Iso18571::new().rate(&test, &model, 1e-4)?;
//! assert_eq!(iso.shift_samples, 20);
//! assert!(iso.grade >= Grade::Good);
//! # Ok::<(), impactcal_calibrate::CalibrateError>(())
//! ```

pub mod closeloop;
pub mod error;
pub mod memory;
pub mod metrics;
pub mod report;
pub mod study;

pub use error::{CalibrateError, Result};
