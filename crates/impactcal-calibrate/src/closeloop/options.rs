//! The loop's options, checked once into a valid form.

use serde::{Deserialize, Serialize};

use impactcal_core::{CoreError, ParamGuard};

use crate::error::Result;

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
    /// Keep every channel of every run in its `result.csv`. By default only the nominal
    /// runs (of the test and of the holdout) keep every channel; every other run stores the
    /// channels the loop compares (24 of the airframe's 1,215 in the demo). Not part of the
    /// loop's fingerprint when off, so that folders written before it resume.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub keep_all_channels: bool,
    /// Memory the loop's process may use, in bytes; `None`: what the machine has available
    /// (`crate::memory`). A stage whose estimate does not fit stops the loop with a
    /// [`CalibrateError::Memory`](crate::CalibrateError::Memory) before it allocates. Not read from a loop file nor part of
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
            keep_all_channels: false,
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

    /// Checks every option ([`ParamGuard::check_ref`]), then the run budgets against
    /// `declared`, the dimension of the model's space: CORS needs
    /// [`cors_runs_needed`](Self::cors_runs_needed)`(declared)` runs to calibrate and
    /// `cors_runs_needed(declared + max_added)` to recalibrate.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] (as [`CalibrateError::Core`](crate::CalibrateError::Core)) naming the first bad
    /// option as `loop.<key>`, and for a budget too small to (re)calibrate, with the
    /// number of runs needed.
    pub fn check_budgets(&self, declared: usize) -> Result<()> {
        ParamGuard::check_ref(self)?;
        let need = Self::cors_runs_needed(declared);
        if self.reconcile < need {
            return Err(CoreError::invalid_option(
                "loop.reconcile_runs",
                self.reconcile,
                format!(
                    "cannot calibrate {declared} parameters: CORS needs at least {need} runs \
                     (an initial design of {} and two steps)",
                    2 * (declared + 1)
                ),
            )
            .into());
        }
        if self.max_added > 0 {
            let need = Self::cors_runs_needed(declared + self.max_added);
            if self.recalibrate < need {
                return Err(CoreError::invalid_option(
                    "loop.recalibrate_runs",
                    self.recalibrate,
                    format!(
                        "cannot recalibrate up to {} parameters ({declared} declared + \
                         max_added {}): at least {need} are needed; raise it or lower \
                         max_added",
                        declared + self.max_added,
                        self.max_added
                    ),
                )
                .into());
            }
        }
        Ok(())
    }
}

impl ParamGuard for LoopOptions {
    type Checked = LoopOptions;

    /// Checks every option on its own (the run budgets against the model's dimension are
    /// checked by [`LoopOptions::check_budgets`] when the loop starts).
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] naming the first bad option as `loop.<key>` (the key
    /// of a loop file): `alpha` outside `(0, 0.5)`, `min_explained` outside `[0, 1]`,
    /// fewer than 2 `jitter_runs`, `jitter_eps` outside `(0, 0.1)`, fewer than 19
    /// `m1_members`, a `cors_batch` of 0, `candidate_step` outside `(0, 0.5]`,
    /// `units_tolerance` outside `[0, 0.5)`, a `sigma` not finite and positive, a
    /// `max_time_shift` not finite and non-negative, an empty candidate name.
    fn check_ref(&self) -> impactcal_core::Result<()> {
        let bad = |key: &str, value: &dyn std::fmt::Display, why: &str| {
            Err(CoreError::invalid_option(format!("loop.{key}"), value, why))
        };
        if !(self.alpha > 0.0 && self.alpha < 0.5) {
            return bad("alpha", &self.alpha, "must lie in (0, 0.5)");
        }
        if !(0.0..=1.0).contains(&self.min_explained) {
            return bad("min_explained", &self.min_explained, "must lie in [0, 1]");
        }
        if self.ensemble < 2 {
            return bad(
                "jitter_runs",
                &self.ensemble,
                "the model's noise needs at least 2 runs",
            );
        }
        if !(self.jitter > 0.0 && self.jitter < 0.1) {
            return bad("jitter_eps", &self.jitter, "must lie in (0, 0.1)");
        }
        if self.m1_members < 19 {
            return bad(
                "m1_members",
                &self.m1_members,
                "an M1 envelope needs at least 19 members (a right model then leaves it at \
                 10 % of the samples)",
            );
        }
        if self.batch == 0 {
            return bad("cors_batch", &0, "must be at least 1");
        }
        if !(self.candidate_step > 0.0 && self.candidate_step <= 0.5) {
            return bad(
                "candidate_step",
                &self.candidate_step,
                "must lie in (0, 0.5]",
            );
        }
        if !(self.units_tolerance >= 0.0 && self.units_tolerance < 0.5) {
            return bad(
                "units_tolerance",
                &self.units_tolerance,
                "must lie in [0, 0.5)",
            );
        }
        if let Some(s) = self.sigma
            && !(s.is_finite() && s > 0.0)
        {
            return bad("sigma", &s, "must be finite and positive");
        }
        if let Some(s) = self.max_time_shift
            && !(s.is_finite() && s >= 0.0)
        {
            return bad("max_time_shift", &s, "must be finite and non-negative");
        }
        if let Some(names) = &self.candidates
            && names.iter().any(|n| n.trim().is_empty())
        {
            return bad("candidates", &"\"\"", "a candidate name is empty");
        }
        Ok(())
    }

    fn check(self) -> impactcal_core::Result<LoopOptions> {
        ParamGuard::check_ref(&self)?;
        Ok(self)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::error::CalibrateError;

    /// The defaults pass; each bad value is refused with `CoreError::InvalidOption` naming
    /// its key as a loop file spells it.
    #[test]
    fn a_bad_value_is_refused_naming_its_key() {
        let base = LoopOptions::default();
        assert!(ParamGuard::check_ref(&base).is_ok());
        assert!(base.check_budgets(2).is_ok());
        let cases: Vec<(LoopOptions, &str)> = vec![
            (
                LoopOptions {
                    alpha: 0.7,
                    ..base.clone()
                },
                "loop.alpha",
            ),
            (
                LoopOptions {
                    min_explained: 1.5,
                    ..base.clone()
                },
                "loop.min_explained",
            ),
            (
                LoopOptions {
                    ensemble: 1,
                    ..base.clone()
                },
                "loop.jitter_runs",
            ),
            (
                LoopOptions {
                    jitter: 0.0,
                    ..base.clone()
                },
                "loop.jitter_eps",
            ),
            (
                LoopOptions {
                    m1_members: 5,
                    ..base.clone()
                },
                "loop.m1_members",
            ),
            (
                LoopOptions {
                    batch: 0,
                    ..base.clone()
                },
                "loop.cors_batch",
            ),
            (
                LoopOptions {
                    candidate_step: 0.0,
                    ..base.clone()
                },
                "loop.candidate_step",
            ),
            (
                LoopOptions {
                    units_tolerance: f64::NAN,
                    ..base.clone()
                },
                "loop.units_tolerance",
            ),
            (
                LoopOptions {
                    sigma: Some(-1.0),
                    ..base.clone()
                },
                "loop.sigma",
            ),
            (
                LoopOptions {
                    max_time_shift: Some(f64::INFINITY),
                    ..base.clone()
                },
                "loop.max_time_shift",
            ),
            (
                LoopOptions {
                    candidates: Some(vec![" ".into()]),
                    ..base.clone()
                },
                "loop.candidates",
            ),
        ];
        for (o, key) in cases {
            match ParamGuard::check_ref(&o) {
                Err(CoreError::InvalidOption { name, .. }) => assert_eq!(name, key),
                other => panic!("{key}: {other:?}"),
            }
            // The loop's own check refuses it the same way.
            let e = o.check_budgets(2).unwrap_err();
            assert!(
                matches!(e, CalibrateError::Core(CoreError::InvalidOption { .. })),
                "{e}"
            );
            assert!(e.to_string().contains(&format!("`{key}`")), "{e}");
        }
        // Budgets against the model's dimension: 2 (2 + 1) + 2 = 8 runs for 2 parameters,
        // 2 (2 + 3 + 1) + 2 = 14 to recalibrate with up to 3 added.
        let e = LoopOptions::check_budgets(
            &LoopOptions {
                reconcile: 7,
                ..base.clone()
            },
            2,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("`loop.reconcile_runs` = 7") && e.contains("at least 8"),
            "{e}"
        );
        let e = LoopOptions::check_budgets(
            &LoopOptions {
                recalibrate: 13,
                ..base.clone()
            },
            2,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("`loop.recalibrate_runs` = 13") && e.contains("at least 14"),
            "{e}"
        );
        assert!(
            LoopOptions::check_budgets(
                &LoopOptions {
                    recalibrate: 0,
                    max_added: 0,
                    ..base
                },
                2
            )
            .is_ok()
        );
    }
}
