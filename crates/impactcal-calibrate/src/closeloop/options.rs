//! The loop's options, checked once into a valid form.

use serde::{Deserialize, Serialize};

use crate::error::{CalibrateError, Result};

/// Options of the closed loop. Defaults in parentheses.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LoopOptions {
    /// Level of every test (detection, whiteness, score) (default 0.01).
    pub alpha: f64,
    /// Smallest explained fraction for a candidate to be added (default 0.5).
    pub min_explained: f64,
    /// Most candidates added (default 3).
    pub max_added: usize,
    /// Runs of the jitter ensemble measuring the model's own noise (default 8; in files
    /// and JSON `jitter_runs`).
    #[serde(rename = "jitter_runs")]
    pub ensemble: usize,
    /// Relative jitter of the ensemble (default 1e-4; `jitter_eps`).
    #[serde(rename = "jitter_eps")]
    pub jitter: f64,
    /// CORS runs of the first calibration (default 24).
    #[serde(rename = "reconcile_runs")]
    pub reconcile: usize,
    /// CORS runs of each recalibration after adding a candidate (default 24).
    #[serde(rename = "recalibrate_runs")]
    pub recalibrate: usize,
    /// Gauss-Newton polish iterations after each CORS search (default 8).
    pub polish: usize,
    /// Points CORS proposes at a time (default 4).
    #[serde(rename = "cors_batch")]
    pub batch: usize,
    /// Seed of everything random (default 0).
    pub seed: u64,
    /// Largest trigger offset searched, in seconds; `None`: a tenth of the record.
    pub max_time_shift: Option<f64>,
    /// Finite step of the candidate runs, as a fraction of each admissible range (default 0.05).
    pub candidate_step: f64,
    /// Relative tolerance of the units flags (default 0.05).
    pub units_tolerance: f64,
    /// Measurement noise standard deviation for every channel, when known.
    pub sigma: Option<f64>,
    /// The candidates the loop may consider, by name; `None`: every candidate the model
    /// lists.
    pub candidates: Option<Vec<String>>,
    /// CFC class whose residual measures the noise when the pre-impact window is too short
    /// (default 1000).
    pub noise_band_cfc: u32,
    /// Whether a gain per channel is fitted (default true). `false` when the sensors'
    /// sensitivities are known (a calibration of the sensors): the gains stay 1, only the
    /// trigger offset and the biases are profiled, and an effect whose signature on a
    /// channel is mostly a change of scale is no longer absorbed by that channel's gain.
    pub fit_gains: bool,
    /// Members of each model's predictive ensemble for M1 (default 199; no runs: see
    /// `closeloop::agreement`).
    pub m1_members: usize,
    /// Memory the loop's process may use, in bytes; `None`: what the machine has available
    /// (`crate::memory`). A stage whose estimate does not fit stops the loop with a
    /// [`CalibrateError::Memory`] before it allocates. Not read from a loop file nor part of
    /// the loop's fingerprint (`impactcal close-loop --max-memory` sets it): a loop resumed
    /// with another limit reuses its journal.
    #[serde(skip)]
    pub max_memory: Option<u64>,
}

impl Default for LoopOptions {
    fn default() -> Self {
        LoopOptions {
            alpha: 0.01,
            min_explained: 0.5,
            max_added: 3,
            ensemble: 8,
            jitter: 1e-4,
            reconcile: 24,
            recalibrate: 24,
            polish: 8,
            batch: 4,
            seed: 0,
            max_time_shift: None,
            candidate_step: 0.05,
            units_tolerance: 0.05,
            sigma: None,
            noise_band_cfc: 1000,
            candidates: None,
            m1_members: 199,
            fit_gains: true,
            max_memory: None,
        }
    }
}

impl LoopOptions {
    /// Whether the candidate `name` is among those the loop may consider.
    pub fn allows(&self, name: &str) -> bool {
        self.candidates
            .as_ref()
            .is_none_or(|c| c.iter().any(|n| n == name))
    }

    /// CORS runs a (re)calibration of a `d`-parameter space needs: its initial design of
    /// `2 (d + 1)` points and two optimiser steps.
    pub fn cors_runs_needed(d: usize) -> usize {
        2 * (d + 1) + 2
    }

    /// Checks every option; `declared` is the dimension of the model's space.
    ///
    /// # Errors
    /// [`CalibrateError::Study`] naming the first bad option, and for a budget too small
    /// to (re)calibrate, with the number of runs needed.
    pub fn check(&self, declared: usize) -> Result<()> {
        let bad =
            |what: &str, why: String| Err(CalibrateError::study(format!("option `{what}`"), why));
        if !(self.alpha > 0.0 && self.alpha < 0.5) {
            return bad("alpha", format!("{} must lie in (0, 0.5)", self.alpha));
        }
        if !(0.0..=1.0).contains(&self.min_explained) {
            return bad(
                "min_explained",
                format!("{} must lie in [0, 1]", self.min_explained),
            );
        }
        if self.ensemble < 2 {
            return bad(
                "jitter_runs",
                format!("{} runs; the model's noise needs at least 2", self.ensemble),
            );
        }
        if !(self.jitter > 0.0 && self.jitter < 0.1) {
            return bad(
                "jitter_eps",
                format!("{} must lie in (0, 0.1)", self.jitter),
            );
        }
        if self.m1_members < 19 {
            return bad(
                "m1_members",
                format!(
                    "{}: an M1 envelope needs at least 19 members (a right model then leaves \
                     it at 10 % of the samples)",
                    self.m1_members
                ),
            );
        }
        if self.batch == 0 {
            return bad("cors_batch", "must be at least 1".into());
        }
        if !(self.candidate_step > 0.0 && self.candidate_step <= 0.5) {
            return bad(
                "candidate_step",
                format!("{} must lie in (0, 0.5]", self.candidate_step),
            );
        }
        if !(self.units_tolerance >= 0.0 && self.units_tolerance < 0.5) {
            return bad(
                "units_tolerance",
                format!("{} must lie in [0, 0.5)", self.units_tolerance),
            );
        }
        if let Some(s) = self.sigma
            && !(s.is_finite() && s > 0.0)
        {
            return bad("sigma", format!("{s} must be finite and positive"));
        }
        if let Some(s) = self.max_time_shift
            && !(s.is_finite() && s >= 0.0)
        {
            return bad(
                "max_time_shift",
                format!("{s} must be finite and non-negative"),
            );
        }
        let need = Self::cors_runs_needed(declared);
        if self.reconcile < need {
            return bad(
                "reconcile_runs",
                format!(
                    "{} runs cannot calibrate {declared} parameters: CORS needs at least {need} \
                     (an initial design of {} and two steps)",
                    self.reconcile,
                    2 * (declared + 1)
                ),
            );
        }
        if self.max_added > 0 {
            let need = Self::cors_runs_needed(declared + self.max_added);
            if self.recalibrate < need {
                return bad(
                    "recalibrate_runs",
                    format!(
                        "{} runs cannot recalibrate up to {} parameters ({declared} declared + \
                         max_added {}): at least {need} are needed; raise it or lower max_added",
                        self.recalibrate,
                        declared + self.max_added,
                        self.max_added
                    ),
                );
            }
        }
        Ok(())
    }
}
