//! The loop's result, written as `loop.json`.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::attribution::{Attribution, Score};
use super::detection::Detection;
use super::discrepancy::Discrepancy;
use super::noise_floor::NoiseFloor;
use super::nuisance::Nuisance;
use crate::study::m1::M1;
use crate::study::m2::M2Result;

/// The loop's conclusion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Verdict {
    /// The calibrated model explains the test to its noise floor.
    #[serde(rename = "no-model-form-error")]
    NoModelFormError,
    /// Candidates were added and the enriched model explains the test to its noise floor.
    #[serde(rename = "attributed")]
    Attributed,
    /// Model-form error remains that no candidate explains (after any additions).
    #[serde(rename = "unattributed")]
    Unattributed,
}

/// A candidate added to the model, with its recalibrated value and 95 % interval (the
/// measurement noise's and the model's own noise's).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Added {
    /// The candidate.
    pub name: String,
    /// Its calibrated value.
    pub value: f64,
    /// Lower end of the interval.
    pub lower: f64,
    /// Upper end of the interval.
    pub upper: f64,
    /// The part of the standard error the model's own noise contributes, counted
    /// coherently from the jitter ensemble (`closeloop::model_noise`); the interval is
    /// `value +- 1.96 sqrt(se^2 + model_noise_sd^2 + roughness_sd^2 + pending_step^2)`,
    /// `se` the linearised standard error under the noise model (`closeloop::prewhiten`).
    #[serde(default)]
    pub model_noise_sd: f64,
    /// How far the optimiser's end point can wander on the objective the model's own noise
    /// makes rough: `se sqrt(R)`, `R` the RMS jump of the whitened chi-square between the
    /// jitter ensemble's runs, in the part of each draw no parameter absorbs
    /// (`closeloop::model_noise`). 0 for a smooth model.
    #[serde(default)]
    pub roughness_sd: f64,
    /// The Gauss-Newton step still pending at the calibrated point for this quantity
    /// (`J^+ e`): the distance from where the polish stopped to the linearised least-squares
    /// optimum. It enters the interval as one more standard deviation,
    /// `value +- 1.96 sqrt(se^2 + model_noise_sd^2 + roughness_sd^2 + pending_step^2)`: a polish stopped
    /// short of its optimum (on its iteration budget, or on a rough residual where no step
    /// helps) is off by about that much.
    #[serde(default)]
    pub pending_step: f64,
}

/// Information criteria of one model of the sequence (known-noise forms on the prewhitened
/// residual of `n` samples: `AIC = RSS + 2k`, `BIC = RSS + k ln n`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelScore {
    /// The candidates added in this model.
    pub added: Vec<String>,
    /// Fitted quantities (parameters and nuisance terms).
    pub k: usize,
    /// Weighted residual sum of squares.
    pub rss: f64,
    /// Akaike's criterion.
    pub aic: f64,
    /// Schwarz's criterion.
    pub bic: f64,
    /// Akaike weight among the models of the sequence.
    pub akaike_weight: f64,
    /// Whether the loop kept this model.
    pub kept: bool,
}

/// Errors of one model against one test (nuisance terms taken out, after filtering).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Errors {
    /// Relative L2 over the compared channels, `||test - model||_F / ||test||_F`.
    pub rel_l2: f64,
    /// Reduced chi-square of the residual.
    pub chi2_red: f64,
    /// Mean Sprague-Geers comprehensive error over the channels.
    pub sprague_geers_c: f64,
    /// Mean ISO/TS 18571 rating over the channels.
    pub iso18571_r: f64,
    /// M1: fraction of the samples at which the test's `Q_e(t)` leaves the envelope of the
    /// model's predictive ensemble (its linearised parameter posterior where the loop has
    /// its Jacobian, and the noise floor; `closeloop::agreement`). About `2 / (N + 1)` for
    /// a right model with `N` members, towards 1 with model-form error.
    pub m1_exceedance: f64,
    /// M1: the exceedance a draw of the predictive ensemble has, `2 / (N + 1)`.
    #[serde(default)]
    pub m1_expected: f64,
    /// M1: the probability that a draw of the ensemble leaves the envelope at least as
    /// often as the test (the study's beta-binomial, `study::m1`); below `1 / (N + 1)`
    /// the model cannot explain the test.
    #[serde(default)]
    pub m1_probability: f64,
    /// M2: paired impact shapes of model and test with `|M2| > 0.9`; `None` when the
    /// shapes cannot be formed (a response without signal on the compared channels).
    pub m2_above_0_9: Option<usize>,
    /// Impact shapes compared a side by M2.
    pub m2_shapes: usize,
    /// What the report draws of this comparison (histories, M1 envelope, M2 matrix).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub evidence: Option<Box<Evidence>>,
}

/// What the report draws of one model against one test, the numbers behind [`Errors`]:
/// the compared histories, the M1 envelope and the M2 matrix.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Evidence {
    /// The test with the nuisance terms taken out (`(test(t + tau) - b) / g`), in the test's
    /// unit after filtering: `S x T` row-major, channels in the order of
    /// [`LoopResult::channels`], `T` samples from [`LoopResult::start`] at
    /// [`LoopResult::time_step`].
    pub test: Vec<f64>,
    /// The model's response on the same channels and samples.
    pub model: Vec<f64>,
    /// M1: the predictive envelope of `Q(t)` (the norm over the channels), the test's
    /// `Q_e(t)` and where it leaves the envelope.
    pub m1: M1,
    /// M2: the matrix of the impact shapes of model (rows) and test (columns), their
    /// contributions and the optimal pairing; `None` when the shapes cannot be formed.
    pub m2: Option<M2Result>,
}

/// Errors of the three models against one test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Stages<T> {
    /// The model at its nominal point.
    pub nominal: T,
    /// The declared model calibrated.
    pub calibrated: T,
    /// The enriched model recalibrated (the calibrated one when nothing was added).
    pub enriched: T,
}

/// Relative L2 before and after, on the calibration test and the holdout.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ErrorSummary {
    /// On the calibration test.
    pub calibration: Stages<f64>,
    /// On the holdout test (never fitted), when one was given.
    pub holdout: Option<Stages<f64>>,
}

/// One round of forward selection.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Round {
    /// Candidates in the model of this round.
    pub added: Vec<String>,
    /// Its calibrated point (name -> value).
    pub calibrated: BTreeMap<String, f64>,
    /// Detection on its residual.
    pub detection: Detection,
    /// Attribution of its residual (none when the loop stopped before attributing).
    pub attribution: Option<Attribution>,
    /// Runs of its (re)calibration.
    pub runs: usize,
}

/// A candidate of the model's catalogue, as the report names it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateInfo {
    /// Its unit (may be empty).
    pub unit: String,
    /// What it is, in a few words.
    pub description: String,
}

/// Everything the closed loop found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LoopResult {
    /// What the model was.
    pub model: String,
    /// The conclusion.
    pub verdict: Verdict,
    /// Detection on the calibrated declared model's residual.
    pub detection: Detection,
    /// The nuisance terms of the calibration test (final model).
    pub nuisance: Nuisance,
    /// The noise floor of the calibration test.
    pub noise_floor: NoiseFloor,
    /// The masks and offsets applied to the test before any comparison.
    #[serde(default)]
    pub test_preparation: crate::study::channels::TestPreparation,
    /// Channels of the test without a model channel and of the model without a test
    /// channel: not compared.
    #[serde(default)]
    pub dropped: crate::metrics::Dropped,
    /// The first attribution's ranking.
    pub candidates: Vec<Score>,
    /// Candidate pairs these sensors cannot tell apart (first attribution).
    pub indistinguishable: Vec<(String, String, f64)>,
    /// Candidates added, in order.
    pub added: Vec<Added>,
    /// The final calibrated point, declared and added parameters.
    pub calibrated: BTreeMap<String, f64>,
    /// The models of the sequence with their information criteria.
    pub models: Vec<ModelScore>,
    /// Why forward selection stopped.
    pub stopped: String,
    /// Detection on the final model's residual.
    pub detection_final: Detection,
    /// The unattributed model-form error, when the verdict says so.
    pub unattributed: Option<Discrepancy>,
    /// Relative L2 before and after.
    pub errors: ErrorSummary,
    /// The full before/after metrics on the calibration test.
    pub metrics_calibration: Stages<Errors>,
    /// The same on the holdout.
    pub metrics_holdout: Option<Stages<Errors>>,
    /// Every round of selection.
    pub rounds: Vec<Round>,
    /// True-model runs used (journaled runs read back count too).
    pub runs: usize,
    /// Members of the predictive ensembles behind the M1 exceedances.
    pub m1_members: usize,
    /// Sampling step of the compared histories (s): the time axis of the patterns.
    pub time_step: f64,
    /// Time of their first sample (s).
    pub start: f64,
    /// The compared channels, in the order of every per-channel vector of the result.
    #[serde(default)]
    pub channels: Vec<String>,
    /// The unit of the compared histories (the test's, e.g. `in/s`; empty when not given).
    #[serde(default)]
    pub unit: String,
    /// The CFC class test and runs were filtered with, if any.
    #[serde(default)]
    pub cfc: Option<u32>,
    /// The holdout's condition (held quantities and their values), empty without one.
    #[serde(default)]
    pub holdout_condition: Vec<(String, f64)>,
    /// The enriched model's parameters (declared, then added): bounds, nominal, unit.
    #[serde(default)]
    pub parameters: Vec<impactcal_core::Parameter>,
    /// The model's candidates: name -> unit and what it is, in a few words.
    #[serde(default)]
    pub catalogue: BTreeMap<String, CandidateInfo>,
    /// The seed of every random draw of the loop.
    #[serde(default)]
    pub seed: u64,
    /// The digest of the loop's configuration (model, parameter space, options, filter,
    /// channel map, test and holdout data): the journal's fingerprint.
    #[serde(default)]
    pub digest: String,
}
