//! The calibration study of the source paper (its §4-5), over any [`Model`]:
//!
//! 1. the nominal (baseline) run and a jitter ensemble about it measure the model's own
//!    noise ([`impactcal_core::noise`]); channels whose predictability horizon ends inside
//!    the window leave the objective (unless kept on request);
//! 2. a scrambled-Halton ensemble of `N` runs; failed runs are reported by index and kept out;
//! 3. M1 ([`m1`]): the envelope of `Q(t) = ||v(t)||_2` over the ensemble against the test's
//!    `Q_e(t)`, the intervals where it leaves, the observed exceedance against the expected
//!    one of a draw of the model with the test's measurement noise (measured on the test's
//!    pre-impact part, else on the band the model leaves empty, or `sigma`), the
//!    probability and the verdict; the test is used with the masks of `core::quality`
//!    (clipped samples and spikes bridged) and its offsets removed
//!    ([`channels::prepared_test`]);
//! 4. sensors ([`sensors`]): effective-independence placement on the ensemble's impact
//!    shapes; the test expanded from the sensors to the other channels through the baseline's
//!    shapes, with its error;
//! 5. M2 ([`m2`]) of the baseline against the test;
//! 6. surrogates ([`surrogates`]) of `Q(t)` and of the sensor histories, every kind with its
//!    leave-one-out error, the best used; a smoothing surrogate beside them;
//! 7. Sobol' indices of `Q(t)` over time from surrogate evaluations ([`sensitivity`]);
//! 8. CORS-RBF reconciliation ([`reconcile`]) with new true-model runs, warm-started from the
//!    baseline and the ensemble, minimising `ln` of the relative prediction error over the sensors;
//! 9. the before/after table: prediction error, `Q(t)` error, M2 count above 0.9, and per
//!    sensor relative L2, Sprague-Geers C and ISO/TS 18571 R.
//!
//! Every true-model run is made as one [`ModelRuns`] says, through the runner's journal in the output
//! folder ([`execute`]: recorded before it starts and after its result is read); running the
//! same study again, after an interruption at any moment, reuses finished runs, re-attaches
//! to runs still queued or running and gives the same result, bit for bit. [`StudyResult`] holds every number (`study.json`);
//! [`document::report`] turns it into the report document.

pub mod channels;
pub mod document;
pub mod execute;
pub mod m1;
pub mod m2;
pub mod measured_noise;
pub mod options;
pub mod plan;
pub mod reconcile;
pub mod result;
pub mod sensitivity;
pub mod sensors;
pub mod subspace;
pub mod surrogates;

use std::path::Path;

use faer::Mat;
use impactcal_core::noise::{JitterOptions, SimulationNoise, jitter_points};
use impactcal_core::sampling::sample;
use impactcal_core::{Cfc, ChannelMap, Histories, Model, SamplingMethod};

use crate::error::{CalibrateError, Result};
use crate::memory::Guard;
use crate::metrics::{CurveMetrics, Iso18571};

pub use execute::{InProcess, ModelRuns, Observer, RunOutcome, Silent, SolverRuns};
pub use m1::{M1, Verdict};
pub use options::{StudyOptions, ValidStudyOptions};
pub use plan::{StudyShapes, estimated_peak};
pub use result::StudyResult;
pub use subspace::Subspace;

use channels::{indices_of, prepared_test, q_of, relative_error, relative_l2};
use execute::Runs;
use plan::Plan;
use result::{
    BeforeAfter, ChannelsSummary, Curves, EnsembleSummary, Errors, FailedRun, M2BeforeAfter,
    NoiseSummary, SensorErrors, SurrogateSummary,
};

/// The measured side of a study.
#[derive(Debug, Clone, Copy)]
pub struct TestData<'a> {
    /// The test's histories (any time base that covers the model's window).
    pub histories: &'a Histories,
    /// A map from test to model channels (`None`: equal labels pair).
    pub map: Option<&'a ChannelMap>,
    /// CFC class applied to the test and to every run before anything is compared.
    pub cfc: Option<Cfc>,
}

/// Runs the study of `model` against `test` in the folder `dir` (created if needed; its
/// journal is reused when it belongs to the same study). `description` names the model in
/// the result and enters the study's fingerprint with the space, the options and the test.
///
/// # Errors
/// [`CalibrateError::ForeignJournal`] when `dir` holds another study's journal;
/// [`CalibrateError::Study`] when the data cannot support the options (no shared channel, no
/// predictable channel, more sensors than channels, no successful run); the errors of each
/// method; [`CalibrateError::Journal`] for a journal that cannot be written.
pub fn run_model<M: Model>(
    model: &M,
    description: &str,
    test: TestData<'_>,
    options: &ValidStudyOptions,
    dir: &Path,
    observer: &dyn Observer,
) -> Result<StudyResult> {
    run(&InProcess(model), description, test, options, dir, observer)
}

/// The fingerprint of a study: a hash of the model's description, its space, the options,
/// the CFC class, the channel map and the test's values.
pub fn fingerprint(
    model_runs: &dyn ModelRuns,
    description: &str,
    test: TestData<'_>,
    options: &StudyOptions,
) -> String {
    let mut bytes = Vec::new();
    bytes.extend_from_slice(description.as_bytes());
    bytes.extend(serde_json::to_vec(model_runs.space()).unwrap_or_default());
    bytes.extend(serde_json::to_vec(options).unwrap_or_default());
    bytes.extend(format!("{:?}", test.cfc.map(Cfc::class)).as_bytes());
    if let Some(m) = test.map {
        for e in &m.entries {
            bytes.extend(format!("{}>{}*{};", e.test_label, e.model_label, e.gain).as_bytes());
        }
    }
    let h = test.histories;
    h.labels().iter().for_each(|l| bytes.extend(l.as_bytes()));
    bytes.extend(h.dt().to_le_bytes());
    bytes.extend(h.start().to_le_bytes());
    h.data().iter().for_each(|v| bytes.extend(v.to_le_bytes()));
    impactcal_runner::fingerprint(&bytes)
}

/// [`run_model`] with the runs any [`ModelRuns`] makes.
///
/// # Errors
/// As [`run_model`].
pub fn run(
    model_runs: &dyn ModelRuns,
    description: &str,
    test: TestData<'_>,
    options: &ValidStudyOptions,
    dir: &Path,
    observer: &dyn Observer,
) -> Result<StudyResult> {
    let space = model_runs.space().clone();
    crate::memory::check_run_counts(
        Guard::new(options.max_memory),
        &[
            ("study.halton_runs", options.halton_runs),
            ("study.jitter_runs", options.jitter_runs),
            ("study.reconcile_runs", options.reconcile_runs),
        ],
        space.dim(),
    )?;
    let fp = fingerprint(model_runs, description, test, options);
    let runs = Runs::open(model_runs, dir, &fp, observer)?;
    let prep = |h: &Histories| -> Result<Histories> {
        Ok(match test.cfc {
            Some(c) => h.filtered(c)?,
            None => h.clone(),
        })
    };

    // 1. Baseline, test on the model's channels, noise, objective channels.
    observer.plan(1 + options.jitter_runs + options.halton_runs + options.reconcile_runs);
    let nominal_point = space.nominal();
    let nominal_raw = runs
        .stage("nominal", std::slice::from_ref(&nominal_point))?
        .histories(0, "the nominal run")?;
    let baseline = prep(&nominal_raw)?;
    let pre =
        crate::closeloop::noise_floor::onset(baseline.data(), baseline.samples()).saturating_sub(3);
    let (test_m, _masks, preparation) =
        prepared_test(test.histories, test.map, test.cfc, &nominal_raw, Some(pre))?;
    let dropped = channels::dropped(test.histories, test.map, &nominal_raw)?;
    if let Some(w) = dropped.warning(test_m.channels()) {
        observer.warning(&w);
    }
    // The memory plan, from the shapes the nominal run gives (every shared channel taken as
    // an objective one), checked before any other stage.
    let mut plan = Plan {
        shapes: StudyShapes {
            run_values: nominal_raw.channels() * nominal_raw.samples(),
            samples: nominal_raw.samples(),
            channels: test_m.channels(),
            runs: options.halton_runs,
            shapes: options.shapes,
            sensors: options.sensors,
            parameters: space.dim(),
            sobol_rows: options.sensitivity_samples,
            threads: if model_runs.model().is_some() {
                rayon::current_num_threads()
            } else {
                0
            },
        },
        guard: Guard::new(options.max_memory),
    };
    plan.check_all()?;
    observer.step(&plan.line());
    let jitter = JitterOptions::new(options.jitter_runs, options.jitter_eps, options.seed);
    let jitter_pts = jitter_points(&space, &nominal_point, &jitter)?;
    let noise_runs = runs.stage("noise", &jitter_pts)?;
    let noise_ok: Vec<usize> = (0..noise_runs.len())
        .filter(|&i| noise_runs.succeeded(i))
        .collect();
    if noise_ok.len() < 2 {
        return Err(CalibrateError::study(
            "noise",
            "fewer than 2 jitter runs succeeded; the model's noise cannot be measured",
        ));
    }
    let jitter_run = |j: usize| prep(&noise_runs.histories(noise_ok[j], "a jitter run")?);
    let noise =
        SimulationNoise::from_run_reader(&baseline, noise_ok.len(), &mut |j| jitter_run(j))?;
    let window_end = baseline.start() + (baseline.samples() - 1) as f64 * baseline.dt();
    let shared: Vec<String> = test_m.labels().to_vec();
    let predictable: Vec<String> = noise
        .predictable_channels(window_end, options.noise_fraction)
        .into_iter()
        .map(|c| noise.labels[c].clone())
        .collect();
    let unpredictable: Vec<String> = shared
        .iter()
        .filter(|l| !predictable.contains(l))
        .cloned()
        .collect();
    let objective: Vec<String> = if options.keep_unpredictable {
        shared.clone()
    } else {
        shared
            .iter()
            .filter(|l| predictable.contains(l))
            .cloned()
            .collect()
    };
    if objective.is_empty() {
        return Err(CalibrateError::study(
            "objective channels",
            format!(
                "none of the {} channels the test shares with the model is predictable over \
                 the window (jitter spread above {} of the signal before {window_end} s); \
                 shorten the window or set keep_unpredictable",
                shared.len(),
                options.noise_fraction
            ),
        ));
    }
    if !options.screen_only {
        sensors::check_count(options.sensors, objective.len())?;
    }
    let noise_idx: Vec<usize> = objective.iter().filter_map(|l| noise.index_of(l)).collect();
    let q_noise = q_spread(&baseline, noise_ok.len(), &jitter_run, &objective)?;

    // 2. The ensemble.
    let design = sample(
        &space,
        SamplingMethod::ScrambledHalton,
        options.halton_runs,
        options.seed,
    )?;
    let points: Vec<Vec<f64>> = (0..design.points.nrows())
        .map(|i| design.points.row(i).iter().copied().collect())
        .collect();
    // From here on a run is read on the objective channels only: unless asked to keep
    // every channel, that is all a run stores.
    let runs = runs.storing((!options.keep_all_channels).then(|| objective.clone()));
    let outcomes = runs.stage("ensemble", &points)?;
    let mut failed = Vec::new();
    let mut ok = Vec::new();
    for (i, point) in points.iter().enumerate() {
        match outcomes.get(i) {
            Ok(_) => ok.push(i),
            Err(message) => failed.push(FailedRun {
                index: i,
                point: point.clone(),
                message,
            }),
        }
    }
    let ok_points: Vec<Vec<f64>> = ok.iter().map(|&i| points[i].clone()).collect();
    // The successful runs on the objective channels, filtered like the test, read one at
    // a time from their result files by each stage that uses them.
    let ensemble_run = |k: usize| -> Result<Histories> {
        let h = outcomes
            .histories(ok[k], "an ensemble run")?
            .select(&objective)?;
        prep(&h)
    };
    if ok.is_empty() {
        return Err(CalibrateError::study(
            "ensemble",
            format!(
                "all {} runs failed (first: {})",
                points.len(),
                failed[0].message
            ),
        ));
    }
    let ensemble = EnsembleSummary {
        requested: points.len(),
        succeeded: ok.len(),
        failed,
        points: points.clone(),
    };

    // 3. M1.
    observer.step("M1");
    let time = baseline.time();
    let test_obj = test_m.select(&objective)?;
    let base_obj = baseline.select(&objective)?;
    let all: Vec<usize> = (0..objective.len()).collect();
    // One pass over the runs: their response norms and their spectra's envelope.
    let mut q_runs: Vec<Vec<f64>> = Vec::with_capacity(ok.len());
    let envelopes = measured_noise::envelopes(
        &base_obj,
        (0..ok.len()).map(|k| {
            let h = ensemble_run(k)?;
            q_runs.push(q_of(&h, &all));
            Ok(h)
        }),
    )?;
    let q_test = q_of(&test_obj, &all);
    let q_baseline = q_of(&base_obj, &all);
    let (ar, measurement_noise) =
        measured_noise::measured(&test_obj, &envelopes, pre, test.cfc, options.sigma)?;
    let m1 = if ar.iter().all(|m| m.variance == 0.0) {
        m1::m1(&time, &q_runs, &q_test)?
    } else {
        m1::m1_with_noise(
            &time,
            (0..ok.len()).map(&ensemble_run),
            &test_obj,
            &ar,
            options.seed,
        )?
    };
    let mut result = StudyResult {
        model: description.to_string(),
        fingerprint: fp.clone(),
        space: space.clone(),
        options: (**options).clone(),
        window: [baseline.start(), window_end],
        samples: baseline.samples(),
        dt: baseline.dt(),
        unit: baseline.unit().to_string(),
        cfc: test.cfc.map(Cfc::class),
        channels: ChannelsSummary {
            model: nominal_raw.channels(),
            shared: shared.len(),
            objective: objective.clone(),
            unpredictable,
            kept_unpredictable: options.keep_unpredictable,
            dropped,
        },
        noise: NoiseSummary {
            runs: noise_ok.len(),
            eps: options.jitter_eps,
            fraction: options.noise_fraction,
            relative_spread: noise.relative_spread(window_end, &noise_idx),
            relative_spread_sensors: None,
            relative_spread_q: q_noise,
            median_horizon: median_horizon(&noise, &shared, options.noise_fraction),
        },
        ensemble,
        m1,
        test_preparation: preparation,
        measurement_noise,
        sensors: None,
        m2: None,
        surrogate: None,
        sensitivity: None,
        reconcile: None,
        errors: None,
        curves: Curves {
            time: time.clone(),
            q_test: q_test.clone(),
            q_baseline: q_baseline.clone(),
            q_calibrated: None,
            sensor: None,
            sensor_test: Vec::new(),
            sensor_baseline: Vec::new(),
            sensor_calibrated: None,
        },
    };
    if options.screen_only {
        return Ok(result);
    }

    // 4. Sensors and 5. M2 of the baseline.
    plan.shapes.channels = objective.len();
    plan.shapes.runs = ok.len();
    plan.check(plan::PLACEMENT, plan::PLACEMENT)?;
    observer.step("sensor placement");
    let sensors = sensors::place_sensors(
        &ensemble_run,
        ok.len(),
        &objective,
        options.sensors,
        options.shapes,
        &base_obj,
        &test_obj,
    )?;
    if let Some(note) = &sensors.note {
        observer.step(&format!("note: {note}"));
    }
    let selected = sensors.selected.clone();
    let sensor_idx: Vec<usize> = selected.iter().filter_map(|l| noise.index_of(l)).collect();
    result.noise.relative_spread_sensors = Some(noise.relative_spread(window_end, &sensor_idx));
    observer.step("M2");
    let m2_baseline = m2::m2(&base_obj, &test_obj, &objective, options.shapes)?;

    // 6. Surrogates and 7. sensitivity.
    plan.check(plan::SURROGATES, plan::SURROGATES)?;
    observer.step("surrogates");
    let x = Mat::from_fn(ok_points.len(), space.dim(), |i, j| ok_points[i][j]);
    let q_mat = Mat::from_fn(q_runs.len(), time.len(), |i, k| q_runs[i][k]);
    let at_sensors: Vec<Vec<f64>> = (0..ok.len())
        .map(|k| Ok(ensemble_run(k)?.select(&selected)?.data().to_vec()))
        .collect::<Result<_>>()?;
    let width = at_sensors.first().map_or(0, Vec::len);
    let s_mat = Mat::from_fn(at_sensors.len(), width, |i, k| at_sensors[i][k]);
    let (q_choice, q_fit) = surrogates::choose(&space, x.as_ref(), q_mat.as_ref())?;
    let (s_choice, _) = surrogates::choose(&space, x.as_ref(), s_mat.as_ref())?;
    result.surrogate = Some(SurrogateSummary {
        loo_rel_error: q_choice.loo_rel_error,
        q: q_choice,
        sensors: s_choice,
    });
    plan.check(plan::SENSITIVITY, plan::SENSITIVITY)?;
    observer.step("sensitivity");
    result.sensitivity = Some(sensitivity::sensitivity(
        &space,
        &q_fit,
        &time,
        options.sensitivity_samples,
        options.seed,
    )?);

    // 8. Reconciliation.
    let test_sensors = test_obj.select(&selected)?;
    let prediction_error = |h: &Histories| -> Result<f64> {
        relative_error(&prep(h)?.select(&selected)?, &test_sensors, &selected)
    };
    let shown = loudest(&test_sensors);
    result.curves.sensor = shown.clone();
    if let Some(l) = &shown {
        result.curves.sensor_test = test_sensors.channel_by_label(l)?.to_vec();
        result.curves.sensor_baseline = base_obj.channel_by_label(l)?.to_vec();
    }
    let baseline_errors = errors_of(
        &nominal_point,
        &base_obj,
        &test_obj,
        &selected,
        prediction_error(&nominal_raw)?,
        &q_test,
        Some(m2_baseline.matched_above_0_9),
    )?;
    result.m2 = Some(M2BeforeAfter {
        baseline: m2_baseline,
        calibrated: None,
    });
    result.sensors = Some(sensors);
    if options.reconcile_runs == 0 {
        return Ok(result);
    }
    // The baseline is a run of the model too: the optimiser starts from it and the
    // ensemble, so the calibrated model is never worse than the baseline.
    let mut start = vec![nominal_point.clone()];
    start.extend(points.iter().cloned());
    let start_outcome = |k: usize| -> RunOutcome {
        if k == 0 {
            Ok(nominal_raw.clone())
        } else {
            outcomes.get(k - 1)
        }
    };
    observer.stage("reconcile", options.reconcile_runs, 0);
    let mut run_batch =
        |first: usize, pts: &[Vec<f64>]| runs.stage_from("reconcile", first, pts, false);
    let best = reconcile::reconcile(
        &space,
        &start,
        &start_outcome,
        options.reconcile_runs,
        options.cors_batch,
        options.seed,
        &mut run_batch,
        &prediction_error,
    )?;
    observer.step("before and after");
    let calibrated = prep(&best.histories)?.select(&objective)?;
    let m2_calibrated = m2::m2(&calibrated, &test_obj, &objective, options.shapes)?;
    let calibrated_errors = errors_of(
        &best.summary.calibrated_point,
        &calibrated,
        &test_obj,
        &selected,
        best.summary.best_error,
        &q_test,
        Some(m2_calibrated.matched_above_0_9),
    )?;
    result.curves.q_calibrated = Some(q_of(&calibrated, &all));
    if let Some(l) = &shown {
        result.curves.sensor_calibrated = Some(calibrated.channel_by_label(l)?.to_vec());
    }
    if let Some(m2) = result.m2.as_mut() {
        m2.calibrated = Some(m2_calibrated);
    }
    result.errors = Some(BeforeAfter {
        reduction: 1.0 - calibrated_errors.prediction_error / baseline_errors.prediction_error,
        baseline: baseline_errors,
        calibrated: calibrated_errors,
    });
    result.reconcile = Some(best.summary);
    Ok(result)
}

/// Relative jitter spread of `Q(t)` over the objective channels: the RMS over time of the
/// standard deviation of Q over the `count` jitter runs `jitter(j)`, over the RMS of the
/// nominal Q.
fn q_spread(
    nominal: &Histories,
    count: usize,
    jitter: &dyn Fn(usize) -> Result<Histories>,
    labels: &[String],
) -> Result<f64> {
    let q0 = q_of(nominal, &indices_of(nominal, labels)?);
    let qs: Vec<Vec<f64>> = (0..count)
        .map(|j| {
            let h = jitter(j)?;
            indices_of(&h, labels).map(|i| q_of(&h, &i))
        })
        .collect::<Result<_>>()?;
    let j = qs.len() as f64;
    let (mut num, mut den) = (0.0, 0.0);
    for (k, q0k) in q0.iter().enumerate() {
        let mean = qs.iter().map(|q| q[k]).sum::<f64>() / j;
        num += qs.iter().map(|q| (q[k] - mean).powi(2)).sum::<f64>() / (j - 1.0);
        den += q0k * q0k;
    }
    Ok(if den > 0.0 { (num / den).sqrt() } else { 0.0 })
}

fn median_horizon(noise: &SimulationNoise, labels: &[String], fraction: f64) -> Option<f64> {
    let mut h: Vec<Option<f64>> = labels
        .iter()
        .filter_map(|l| noise.index_of(l))
        .map(|c| noise.horizon(c, fraction))
        .collect();
    h.sort_by(|a, b| match (a, b) {
        (Some(x), Some(y)) => x.total_cmp(y),
        (Some(_), None) => std::cmp::Ordering::Less,
        (None, Some(_)) => std::cmp::Ordering::Greater,
        (None, None) => std::cmp::Ordering::Equal,
    });
    h.get(h.len() / 2).copied().flatten()
}

/// The channel with the largest RMS.
fn loudest(h: &Histories) -> Option<String> {
    (0..h.channels())
        .map(|c| (c, h.channel(c).iter().map(|v| v * v).sum::<f64>()))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(c, _)| h.labels()[c].clone())
}

/// The errors of `model` (objective channels, prepared) against `test`.
fn errors_of(
    point: &[f64],
    model: &Histories,
    test: &Histories,
    sensors: &[String],
    prediction_error: f64,
    q_test: &[f64],
    m2_count: Option<usize>,
) -> Result<Errors> {
    let all: Vec<usize> = (0..model.channels()).collect();
    let iso = Iso18571::new();
    let mut per_sensor = Vec::new();
    let mut undefined = Vec::new();
    for l in sensors {
        let (m, t) = (model.channel_by_label(l)?, test.channel_by_label(l)?);
        match CurveMetrics::between(t, m, test.dt(), &iso) {
            Ok(c) => per_sensor.push(SensorErrors {
                label: l.clone(),
                rel_l2: c.pointwise.rel_l2,
                sprague_geers_c: c.sprague_geers.comprehensive,
                iso18571_r: c.iso18571.r,
            }),
            Err(e) => undefined.push(format!("{l}: {e}")),
        }
    }
    let n = per_sensor.len().max(1) as f64;
    let mean = |f: fn(&SensorErrors) -> f64| per_sensor.iter().map(f).sum::<f64>() / n;
    Ok(Errors {
        point: point.to_vec(),
        prediction_error,
        q_error: relative_l2(&q_of(model, &all), q_test),
        m2_matched_above_0_9: m2_count,
        rel_l2: mean(|s| s.rel_l2),
        iso18571_r: mean(|s| s.iso18571_r),
        sprague_geers_c: mean(|s| s.sprague_geers_c),
        per_sensor,
        undefined,
    })
}
