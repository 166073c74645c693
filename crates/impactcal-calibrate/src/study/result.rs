//! The result of a study: every number, serialised as `study.json`.

use impactcal_core::ParameterSpace;
use impactcal_core::quality::RecordNoiseSource;
use serde::{Deserialize, Serialize};

use super::m1::M1;
use super::m2::M2Result;
use super::options::StudyOptions;
use super::reconcile::Reconcile;
use super::sensitivity::Sensitivity;
use super::sensors::SensorsResult;
use super::surrogates::SurrogateChoice;

/// Everything a study found (`study.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StudyResult {
    /// What the model is (as the caller described it).
    pub model: String,
    /// Hash of everything that defines the study (model description, space, options, test).
    pub fingerprint: String,
    /// The parameter space.
    pub space: ParameterSpace,
    /// The options.
    pub options: StudyOptions,
    /// First and last time of the study window (the model's record).
    pub window: [f64; 2],
    /// Samples per history and their step.
    pub samples: usize,
    /// Time step (s).
    pub dt: f64,
    /// Unit of the histories.
    pub unit: String,
    /// CFC class applied to test and runs, if any.
    pub cfc: Option<u32>,
    /// Which channels the study uses.
    pub channels: ChannelsSummary,
    /// The model's own noise at the nominal point.
    pub noise: NoiseSummary,
    /// The ensemble.
    pub ensemble: EnsembleSummary,
    /// Metric M1.
    pub m1: M1,
    /// The masks and offsets applied to the test before any comparison.
    #[serde(default)]
    pub test_preparation: super::channels::TestPreparation,
    /// The measurement noise M1 counted, per objective channel: where it came from, its
    /// standard deviation and lag-one correlation (after the filter).
    #[serde(default)]
    pub measurement_noise: Vec<MeasurementNoise>,
    /// The sensors (absent when the study stopped after M1).
    pub sensors: Option<SensorsResult>,
    /// Metric M2 before and after.
    pub m2: Option<M2BeforeAfter>,
    /// The surrogates and their LOO errors.
    pub surrogate: Option<SurrogateSummary>,
    /// Sobol' indices of Q(t).
    pub sensitivity: Option<Sensitivity>,
    /// The reconciliation.
    pub reconcile: Option<Reconcile>,
    /// The before/after errors.
    pub errors: Option<BeforeAfter>,
    /// The curves of the report's figures.
    pub curves: Curves,
}

/// Channel counts and lists.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelsSummary {
    /// Channels of the model.
    pub model: usize,
    /// Channels the test and the model share.
    pub shared: usize,
    /// Channels of the objective (Q, sensors, errors).
    pub objective: Vec<String>,
    /// Shared channels whose predictability horizon ends inside the window.
    pub unpredictable: Vec<String>,
    /// Whether unpredictable channels were kept in the objective.
    pub kept_unpredictable: bool,
    /// Channels of the test without a model channel and of the model without a test
    /// channel: not compared.
    #[serde(default)]
    pub dropped: crate::metrics::Dropped,
}

/// The jitter ensemble's findings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NoiseSummary {
    /// Successful jitter runs.
    pub runs: usize,
    /// Largest relative perturbation.
    pub eps: f64,
    /// Fraction of a channel's RMS its spread may reach.
    pub fraction: f64,
    /// Relative spread over the window and the objective channels (the noise floor of a
    /// relative L2 error over them).
    pub relative_spread: f64,
    /// The same over the sensors.
    pub relative_spread_sensors: Option<f64>,
    /// Relative spread of `Q(t)` (its jitter standard deviation over its RMS).
    pub relative_spread_q: f64,
    /// Median predictability horizon of the shared channels (s), `None` when more than half
    /// stay predictable over the whole record.
    pub median_horizon: Option<f64>,
}

/// A failed run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailedRun {
    /// Index in the ensemble.
    pub index: usize,
    /// The point.
    pub point: Vec<f64>,
    /// Why it failed.
    pub message: String,
}

/// The ensemble's runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnsembleSummary {
    /// Runs asked for.
    pub requested: usize,
    /// Runs that succeeded (the envelope and the surrogates use these).
    pub succeeded: usize,
    /// Runs that failed, kept out of everything.
    pub failed: Vec<FailedRun>,
    /// The points (rows in the space's order).
    pub points: Vec<Vec<f64>>,
}

/// M2 of the baseline and of the calibrated model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct M2BeforeAfter {
    /// Baseline (nominal) run against the test.
    pub baseline: M2Result,
    /// Calibrated run against the test.
    pub calibrated: Option<M2Result>,
}

/// The surrogates of Q(t) and of the sensor histories.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurrogateSummary {
    /// LOO error of the surrogate of Q(t) used for sensitivity (relative RMS).
    pub loo_rel_error: f64,
    /// Every surrogate of Q(t).
    pub q: SurrogateChoice,
    /// Every surrogate of the sensor histories.
    pub sensors: SurrogateChoice,
}

/// One sensor's metrics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensorErrors {
    /// The channel.
    pub label: String,
    /// Relative L2 error.
    pub rel_l2: f64,
    /// Sprague-Geers comprehensive error C.
    pub sprague_geers_c: f64,
    /// ISO/TS 18571 rating R.
    pub iso18571_r: f64,
}

/// The errors of one model run against the test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Errors {
    /// The parameters.
    pub point: Vec<f64>,
    /// Relative L2 error over all sensors and samples (the reconciliation's objective).
    pub prediction_error: f64,
    /// Relative L2 error of Q(t) against Q_e(t).
    pub q_error: f64,
    /// M2 pairs above 0.9.
    pub m2_matched_above_0_9: Option<usize>,
    /// Mean relative L2 over sensors.
    pub rel_l2: f64,
    /// Mean ISO/TS 18571 R over sensors.
    pub iso18571_r: f64,
    /// Mean Sprague-Geers C over sensors.
    pub sprague_geers_c: f64,
    /// Per sensor.
    pub per_sensor: Vec<SensorErrors>,
    /// Sensors on which a metric is undefined, with the reason.
    pub undefined: Vec<String>,
}

/// Baseline against calibrated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BeforeAfter {
    /// The nominal model.
    pub baseline: Errors,
    /// The calibrated model.
    pub calibrated: Errors,
    /// Relative reduction of the prediction error, `1 - after / before`.
    pub reduction: f64,
}

/// The curves the report plots.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Curves {
    /// Sample times.
    pub time: Vec<f64>,
    /// The test's Q_e(t).
    pub q_test: Vec<f64>,
    /// The baseline's Q(t).
    pub q_baseline: Vec<f64>,
    /// The calibrated model's Q(t).
    pub q_calibrated: Option<Vec<f64>>,
    /// The sensor whose histories are shown (the one with the largest signal).
    pub sensor: Option<String>,
    /// Its test history.
    pub sensor_test: Vec<f64>,
    /// Its baseline history.
    pub sensor_baseline: Vec<f64>,
    /// Its calibrated history.
    pub sensor_calibrated: Option<Vec<f64>>,
}

/// The measurement noise of one test channel as M1 counts it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeasurementNoise {
    /// The channel.
    pub label: String,
    /// Where it came from: `given` (`[test] sigma`), `quiet` (the pre-impact part),
    /// `model-free-band` (the band above the ensemble's bandwidth) or `none`.
    pub source: RecordNoiseSource,
    /// Standard deviation (the test's unit, after the filter; 0 for `none`).
    pub sigma: f64,
    /// Lag-one correlation.
    pub lag1: f64,
    /// AR order.
    pub order: usize,
    /// Why no noise was measured (source `none`).
    #[serde(default)]
    pub note: Option<String>,
}
