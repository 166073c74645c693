//! Calibration of impact models against tests: curve metrics, the calibration study and the
//! closed loop.
//!
//! # The study ([`study`], docs/study.md)
//!
//! A model with `d` declared parameters is run at its nominal point, on a jitter ensemble
//! about it (every parameter moved by at most `jitter_eps` relative: the model's own noise,
//! docs/simulation-noise.md) and on `N` scrambled Halton points over the space. With
//! `v(t, p)` the objective channels at time `t`:
//! - **M1**: `Q(t, p) = ||v(t, p)||_2`; the ensemble's minimum and maximum at each `t` make
//!   the envelope, and the test's `Q_e(t)` leaves it at a fraction of its samples. That
//!   fraction is compared with what a draw of the model with the test's noise gives
//!   (`2/(N+1)` and the noise's share, a beta-binomial); the verdict is `cannot-explain`
//!   when the probability of leaving at least as often is below `1/(N+1)`;
//! - **sensors**: the ensemble's impact shapes (SVD of the runs concatenated in time) and
//!   Kammer's effective independence choose the sensor channels;
//! - **M2**: the `|cos|` matrix between the impact shapes of model and test, paired one to
//!   one, counts the pairs above 0.9;
//! - **surrogates** (ERBF and classic RBFs, chosen by leave-one-out) of `Q(t)` and the
//!   sensor histories give **Sobol' indices over time** (first-order and total);
//! - **reconciliation**: CORS-RBF minimises `ln` of the relative L2 prediction error at the
//!   sensors, warm-started from the ensemble, and the errors before and after are reported
//!   (relative L2, Sprague-Geers, ISO/TS 18571).
//!
//! # The closed loop ([`closeloop`], docs/closed-loop.md)
//!
//! For an [`Enrichable`](impactcal_core::Enrichable) model and a test `Y`: nuisance terms of
//! the rig (trigger offset `tau`, gain `g_s` and bias `b_s` per channel,
//! `Y_s(t) = g_s y_s(t - tau) + b_s`) are profiled out of every comparison; the residual is
//! whitened by the measurement noise and the model's jitter spread,
//! `w_s(t) = 1 / sqrt(sigma_s^2 + spread_s(t)^2)`, and each channel's AR colour. After a
//! calibration (CORS-RBF and a Gauss-Newton polish) model-form error is **detected** when
//! the reduced chi-square exceeds its `F` (or chi-square) quantile and the residual's first
//! singular value the noise edge `1.2 (sqrt(T) + sqrt(S))`. Each candidate effect the model
//! lists is **attributed** by its direction `g_k` with the part the fit can mimic removed,
//! `g~_k = (I - P_J) g_k`: score `LM_k = <g~_k, e>^2 / <g~_k, g~_k>` (chi-square with one
//! degree of freedom, Bonferroni over the candidates), explained fraction and confounding
//! ratio `||P_J g_k|| / ||g_k||`. The best eligible candidate is **added** and the model
//! **recalibrated**; it is kept when BIC falls by more than 2 against a control
//! recalibration without it. What no candidate explains is reported as unattributed
//! model-form error (the residual's leading singular components). Errors, M1 and M2 before
//! and after are given on the test and on a holdout at another condition.
//!
//! Both run on any executor of the runner (in process, a process pool, Slurm) through a
//! journal that makes them resumable; the crate `impactcal-experiment` runs them from a
//! file.
//!
//! # Scalar tests ([`scalar`], docs/study.md)
//!
//! A test of a handful of named scalars (an intrusion, a peak force, an energy), each with
//! its own scale `sigma_k`: one surrogate per scalar from the model's runs and CORS-RBF on
//! `J(p) = sum_k ((s_k(p) - y_k) / sigma_k)^2`, with the errors per scalar before and after.
//!
//! # Metrics ([`metrics`], docs/metrics.md)
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
pub mod progress;
pub mod report;
pub mod scalar;
pub mod study;

pub use error::{CalibrateError, Result};
