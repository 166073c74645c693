//! The settings of a study, checked once into [`ValidStudyOptions`].

use impactcal_core::{CoreError, ParamGuard};
use serde::{Deserialize, Serialize};

/// The settings of a calibration study (the `[study]` table of a study file). Defaults are
/// the source paper's where it gives one: 41 sensors, 1,000 (here 1,024, a power of two for
/// the Sobol' design) surrogate evaluations per sensitivity sample, 60 reconciliation runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StudyOptions {
    /// Runs of the Halton ensemble `N` (the paper: 150 for Table 1, 50 for Table 2).
    pub halton_runs: usize,
    /// Sensors `K` placed by effective independence on the ensemble's impact shapes.
    pub sensors: usize,
    /// Impact shapes kept for placement and M2 (at most `sensors`).
    pub shapes: usize,
    /// Base rows `n` of the Saltelli design evaluated on the surrogate of Q(t)
    /// (`n (d + 2)` evaluations).
    pub sensitivity_samples: usize,
    /// New true-model runs of the CORS-RBF reconciliation (0: no reconciliation).
    pub reconcile_runs: usize,
    /// Points CORS-RBF proposes at a time (runs of a batch go in parallel); part of the
    /// study's definition, since the sequence of points depends on it.
    pub cors_batch: usize,
    /// Seed of the ensemble, the jitter ensemble, the Sobol' design and CORS-RBF.
    pub seed: u64,
    /// Runs `J` of the jitter ensemble that measures the model's own noise.
    pub jitter_runs: usize,
    /// Largest relative perturbation of the jitter ensemble.
    pub jitter_eps: f64,
    /// A channel is predictable while its jitter spread stays within this fraction of its
    /// RMS signal; channels whose horizon ends inside the window leave the objective.
    pub noise_fraction: f64,
    /// Keep unpredictable channels in the objective (flagged in the result).
    pub keep_unpredictable: bool,
    /// Stop after M1 (the screening of a first parameter set).
    pub screen_only: bool,
    /// Keep every channel of every run in its `result.csv`. By default the runs after the
    /// jitter ensemble (the ensemble and the reconciliation) store only the objective
    /// channels, the ones the study compares (a test of 24 channels against a model of 1,215
    /// stores 24); the nominal and jitter runs keep every channel. Not part of the study's
    /// fingerprint when off, so that folders written before it resume.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub keep_all_channels: bool,
    /// Memory the study's process may use, in bytes; `None`: what the machine has
    /// available (`crate::memory`). A stage whose estimate does not fit stops the study
    /// with a [`crate::CalibrateError::Memory`] before it allocates. Not read from a study
    /// file nor part of the study's fingerprint or result (`impactcal study --max-memory`
    /// sets it).
    #[serde(skip)]
    pub max_memory: Option<u64>,
    /// Measurement noise standard deviation of every test channel as compared (after the
    /// filter), when known (`[test] sigma` of a study file); `None`: measured on the test
    /// (its pre-impact part, else the band the model leaves empty).
    pub sigma: Option<f64>,
}

impl Default for StudyOptions {
    fn default() -> Self {
        StudyOptions {
            halton_runs: 50,
            sensors: 41,
            shapes: 10,
            sensitivity_samples: 1024,
            reconcile_runs: 60,
            cors_batch: 2,
            seed: 1,
            jitter_runs: 8,
            jitter_eps: 1e-4,
            noise_fraction: 0.05,
            keep_unpredictable: false,
            screen_only: false,
            keep_all_channels: false,
            max_memory: None,
            sigma: None,
        }
    }
}

impl ParamGuard for StudyOptions {
    type Checked = ValidStudyOptions;

    /// Checks every option on its own (whether the model and the test can support them is
    /// checked when the study runs).
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for an ensemble of fewer than 2 runs (a budget of 0
    /// included), 0 sensors or shapes, more shapes than sensors, fewer than 2 sensitivity
    /// samples, a reconciliation batch of 0, fewer than 2 jitter runs, `jitter_eps` outside
    /// `(0, 0.1]` or `noise_fraction` not positive.
    fn check_ref(&self) -> impactcal_core::Result<()> {
        if self.halton_runs < 2 {
            return Err(CoreError::invalid_option(
                "study.halton_runs",
                self.halton_runs,
                "an ensemble needs at least 2 runs",
            ));
        }
        if self.sensors == 0 {
            return Err(CoreError::invalid_option(
                "study.sensors",
                0,
                "place at least one sensor",
            ));
        }
        if self.shapes == 0 || self.shapes > self.sensors {
            return Err(CoreError::invalid_option(
                "study.shapes",
                self.shapes,
                format!("must lie in 1..={} (the sensor count)", self.sensors),
            ));
        }
        if self.sensitivity_samples < 2 {
            return Err(CoreError::invalid_option(
                "study.sensitivity_samples",
                self.sensitivity_samples,
                "must be at least 2",
            ));
        }
        if self.cors_batch == 0 {
            return Err(CoreError::invalid_option(
                "study.cors_batch",
                0,
                "must be at least 1",
            ));
        }
        if self.jitter_runs < 2 {
            return Err(CoreError::invalid_option(
                "study.jitter_runs",
                self.jitter_runs,
                "a jitter ensemble needs at least 2 runs",
            ));
        }
        if !(self.jitter_eps > 0.0 && self.jitter_eps <= 0.1) {
            return Err(CoreError::invalid_option(
                "study.jitter_eps",
                self.jitter_eps,
                "must lie in (0, 0.1]",
            ));
        }
        if !(self.noise_fraction > 0.0 && self.noise_fraction.is_finite()) {
            return Err(CoreError::invalid_option(
                "study.noise_fraction",
                self.noise_fraction,
                "must be positive",
            ));
        }
        if let Some(s) = self.sigma
            && !(s.is_finite() && s >= 0.0)
        {
            return Err(CoreError::invalid_option(
                "test.sigma",
                s,
                "must be finite and non-negative",
            ));
        }
        Ok(())
    }

    fn check(self) -> impactcal_core::Result<ValidStudyOptions> {
        ValidStudyOptions::checked(self)
    }
}

impactcal_core::valid_options! {
    /// [`StudyOptions`] that passed their checks: the only form a study runs with.
    #[derive(Debug, Clone, PartialEq)]
    pub struct ValidStudyOptions(StudyOptions);
}
