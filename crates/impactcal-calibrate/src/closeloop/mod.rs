//! The closed loop: from the residual a calibration leaves to the effect the model lacks,
//! added and recalibrated, with the error before and after.
//!
//! Over any [`Enrichable`] model and a measured test:
//!
//! 1. **Nuisance terms first** ([`nuisance`]): a trigger offset `tau`, and a gain and bias
//!    per channel, `test_s(t) = g_s y_s(t - tau) + b_s`, profiled out of every comparison
//!    and never offered as physics; gains near a units factor are flagged.
//! 2. **Noise floor** ([`noise_floor`]): measurement noise per channel (given, pre-impact
//!    window, or the frequencies where the model has no content), its level and its AR
//!    model, and the model's own simulation noise from a jitter ensemble, combined in
//!    quadrature into the whitening weights; the masks of `core::quality` (clipped runs,
//!    spikes) give zero weight (`study::channels::prepared_test`); the test's offsets are the
//!    biases of step 1. Every residual and every direction is then prewhitened channel by
//!    channel with the noise's AR filter (`prewhiten`: the generalised least-squares form),
//!    so that every likelihood below sees white noise.
//! 3. **Calibration**: CORS-RBF then a Gauss-Newton polish to a least-squares
//!    optimum.
//! 4. **Detection** ([`detection`]): reduced chi-square, whiteness, the residual SVD
//!    against the noise edge; model-form error when chi-square exceeds its quantile and the
//!    residual is coherent.
//! 5. **Attribution** ([`attribution`]): one run per candidate for its direction; the
//!    confounding ratio `kappa` against what is already fitted; amplitude with interval,
//!    explained fraction, score statistic, admissibility, mutual coherence; a ranking.
//! 6. **Forward selection** ([`selection`]): the best eligible candidate is added and the
//!    model recalibrated (CORS warm-started from the previous optimum, its own budget, then
//!    the polish); kept when BIC falls by more than 2; repeated until no model-form error
//!    remains, nothing eligible is left, BIC stops falling or `max_added` is reached.
//! 7. **Unattributed model-form error** ([`discrepancy`]): when error remains, its low-rank
//!    sensor and time signature, never presented as a physical effect.
//! 8. **Before and after** on the calibration test and on a holdout test at another
//!    condition ([`Enrichable::at_condition`]), which the loop never fits (its trigger offset
//!    and biases are profiled, its gains are the calibration test's sensors').
//!
//! Every model run goes through the study's journaled runner, in stages named for the round
//! and step (`nominal`, `noise`, `r0-cors`, `r1-gn2-jac`, `r0-candidates`, `holdout`, ...):
//! a loop run again in the same folder reuses every finished run and gives the same result.
//!
//! ```
//! use impactcal_calibrate::closeloop::{LoopOptions, Verdict, run_loop};
//! use impactcal_calibrate::study::{Silent, TestData};
//! use impactcal_core::drop_tower::DropTower;
//! use impactcal_core::synthetic::{Measurement, measured};
//! use impactcal_core::{Enrichable, Model, Parameter};
//!
//! // The truth has contact damping the model holds at zero.
//! let model = DropTower::new();
//! let truth = model.at_condition(&[("contact_damping".into(), 0.2)])?;
//! let y = truth.simulate(&[75.0, 9e5])?;
//! let test = measured(&y, &Measurement { snr_db: Some(40.0), seed: 1, ..Default::default() })?;
//! let dir = tempfile::tempdir()?;
//! let data = TestData { histories: &test, map: None, cfc: None };
//! let result = run_loop(&model, "drop tower", data, None, &LoopOptions::default(), dir.path(), &Silent)?;
//! assert_eq!(result.verdict, Verdict::Attributed);
//! assert_eq!(result.added[0].name, "contact_damping");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod agreement;
pub mod attribution;
pub mod detection;
pub mod discrepancy;
pub mod document;
mod fit;
mod jacobian;
mod linalg;
mod model_noise;
pub mod noise_floor;
pub mod nuisance;
pub mod options;
pub mod plan;
mod prewhiten;
pub mod result;
pub mod selection;

use std::cell::Cell;
use std::path::Path;

use impactcal_core::noise::{JitterOptions, SimulationNoise, jitter_points};
use impactcal_core::{Cfc, ChannelMap, Enrichable, Histories, Model};

use crate::error::{CalibrateError, Result};
use crate::memory::Guard;
use crate::metrics::{CurveMetrics, Iso18571};
use crate::study::TestData;
use crate::study::channels::prepared_test;
use crate::study::execute::Observer;
use impactcal_runner::Runner;

pub use attribution::{Amplitude, Attribution, Score};
pub use detection::Detection;
pub use discrepancy::Discrepancy;
pub use noise_floor::NoiseFloor;
pub use nuisance::Nuisance;
pub use options::LoopOptions;
pub use plan::{LoopShapes, estimated_peak};
pub use result::{Added, ErrorSummary, Errors, LoopResult, ModelScore, Round, Stages, Verdict};

use agreement::Posterior;
use fit::{Ctx, Journaled};
use model_noise::ModelNoise;
use nuisance::{Frame, Terms};
use plan::Plan;

/// A holdout test: the measured histories and the condition they were taken at, as held
/// quantities of the model (`("v0", 6.0)`).
#[derive(Debug, Clone, Copy)]
pub struct Holdout<'a> {
    /// The holdout test (same channel map and filter as the calibration test).
    pub histories: &'a Histories,
    /// The condition.
    pub set: &'a [(String, f64)],
}

/// Runs the closed loop of `model` against `test` (and `holdout`) in the folder `dir`
/// (created if needed; its journal is reused when it belongs to the same loop).
///
/// # Errors
/// [`CalibrateError::Study`] for invalid options, a budget too small to recalibrate (with
/// the runs needed), a model with no candidate, a holdout condition the model cannot take,
/// test channels the map does not cover, a noise floor that cannot be measured;
/// [`CalibrateError::ForeignJournal`] when `dir` holds another loop's or study's journal;
/// run, journal and numerical errors.
pub fn run_loop<M: Enrichable>(
    model: &M,
    description: &str,
    test: TestData<'_>,
    holdout: Option<Holdout<'_>>,
    options: &LoopOptions,
    dir: &Path,
    observer: &dyn Observer,
) -> Result<LoopResult> {
    run_loop_on(
        model,
        description,
        test,
        holdout,
        options,
        dir,
        observer,
        None,
    )
}

/// [`run_loop`] with the model's runs on a worker [`Runner`] (a process pool, a Slurm cluster)
/// instead of this process (`worker = None`). Each run's `params.json` names the model's
/// parameters (declared, then added candidates, in the order of [`Enrichable::enrich`]) and
/// the condition `set` of a holdout run; the worker must rebuild exactly that model (as
/// [`impactcal_core::enrich::rebuild`] does from the loop's base model) and refuse a name
/// it does not know. The journal is the same as in process, so a loop may be resumed on
/// another executor; the result is the same bit for bit.
///
/// # Errors
/// As [`run_loop`]; a run the worker fails is a [`CalibrateError::Core`] simulation error
/// naming the run's stage and the worker's exit status and last line of standard error.
#[allow(clippy::too_many_arguments)]
pub fn run_loop_on<M: Enrichable>(
    model: &M,
    description: &str,
    test: TestData<'_>,
    holdout: Option<Holdout<'_>>,
    options: &LoopOptions,
    dir: &Path,
    observer: &dyn Observer,
    worker: Option<&Runner>,
) -> Result<LoopResult> {
    let space = model.space().clone();
    let d0 = space.dim();
    options.check(d0)?;
    let listed = model.candidates();
    if let Some(names) = &options.candidates {
        for n in names {
            if !listed.iter().any(|c| c.name() == n) {
                return Err(CalibrateError::study(
                    format!("candidate `{n}`"),
                    format!(
                        "not a candidate of the model (it lists: {})",
                        listed
                            .iter()
                            .map(|c| c.name())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                ));
            }
        }
    }
    if !listed.iter().any(|c| options.allows(c.name())) {
        return Err(CalibrateError::study(
            "candidate list",
            "empty: the loop has no candidate effect to attribute a residual to",
        ));
    }
    let holdout_models = match holdout {
        Some(h) => Some((
            h,
            model.at_condition(h.set).map_err(|e| {
                CalibrateError::study("[holdout] set", format!("the model cannot take it: {e}"))
            })?,
        )),
        None => None,
    };
    let fp = fingerprint(description, &space, options, test, holdout);
    let used = Cell::new(0usize);
    let runner = Journaled {
        dir,
        fingerprint: &fp,
        observer,
        used: &used,
        worker,
        condition: &[],
        plan: None,
    };

    // Nominal run, the test on the model's channels.
    let nominal = space.nominal();
    let nominal_raw = runner
        .stage(model, "nominal", std::slice::from_ref(&nominal))?
        .histories(0, "the nominal run")?;
    check_covered(test.histories, test.map, &nominal_raw, "test")?;
    // The offsets stay: the nuisance terms fit a bias per channel on every sample.
    let (test_m, masks, preparation) =
        prepared_test(test.histories, test.map, test.cfc, &nominal_raw, None)?;
    let labels = test_m.labels().to_vec();
    let samples = test_m.samples();
    let dt = test_m.dt();

    // The memory plan, from the shapes the nominal run gives, checked before any stage.
    let plan = Plan {
        shapes: LoopShapes {
            channels: labels.len(),
            samples,
            run_values: nominal_raw.channels() * nominal_raw.samples(),
            dense: d0 + options.max_added + 1,
            candidates: listed.iter().filter(|c| options.allows(c.name())).count(),
            threads: if worker.is_some() {
                0
            } else {
                rayon::current_num_threads()
            },
            m1_members: options.m1_members,
        },
        guard: Guard::new(options.max_memory),
    };
    plan.check_all()?;
    observer.step(&plan.line());
    let runner = Journaled {
        plan: Some(&plan),
        ..runner
    };
    let prep = |h: &Histories| -> Result<Vec<f64>> {
        let h = match test.cfc {
            Some(c) => h.filtered(c)?,
            None => h.clone(),
        };
        Ok(h.select(&labels)?.data().to_vec())
    };
    let max_shift = options
        .max_time_shift
        .unwrap_or(0.1 * dt * (samples - 1) as f64);
    let band = Cfc::from_class(options.noise_band_cfc)?;
    let unit_gains = (!options.fit_gains).then(|| vec![1.0; labels.len()]);

    // The model's own noise and the noise floor.
    let (spread, model_noise) = model_spread(
        runner,
        model,
        &nominal,
        &nominal_raw,
        options,
        &labels,
        test.cfc,
        "noise",
    )?;
    let y_nominal = prep(&nominal_raw)?;
    let (mut frame, floor) = frame_of(
        &labels,
        test_m.data(),
        samples,
        dt,
        &y_nominal,
        &model_noise,
        &spread,
        max_shift,
        options,
        (test.cfc, band),
        unit_gains.as_deref(),
        preparation.pre_trigger.as_ref(),
    )?;
    noise_model(&mut frame, &masks, &floor)?;
    let ctx = Ctx {
        frame,
        cfc: test.cfc,
        max_shift,
        fixed_gains: unit_gains,
        runner,
        seed: options.seed,
        batch: options.batch,
        model_noise,
    };
    let onset = noise_floor::onset(&y_nominal, samples);
    let n_nuisance = 1 + if options.fit_gains { 2 } else { 1 } * labels.len();

    // Calibration and forward selection.
    observer.step("calibration");
    let fit0 = fit::calibrate(
        &ctx,
        model,
        "r0",
        std::slice::from_ref(&nominal),
        options.reconcile,
        options.polish,
    )?;
    let outcome = selection::forward(
        &ctx,
        model,
        fit0.clone(),
        options,
        onset,
        n_nuisance,
        floor.level_dof(),
    )?;
    let fit = &outcome.fit;
    let det0 = outcome.rounds[0].detection.clone();
    let det = outcome
        .rounds
        .last()
        .map_or_else(|| det0.clone(), |r| r.detection.clone());

    let verdict = if det.model_form_error {
        Verdict::Unattributed
    } else if outcome.added.is_empty() {
        Verdict::NoModelFormError
    } else {
        Verdict::Attributed
    };
    let unattributed = if verdict == Verdict::Unattributed {
        let closest = outcome
            .rounds
            .iter()
            .rev()
            .find_map(|r| r.attribution.as_ref())
            .map(|a| {
                a.ranked
                    .iter()
                    .take(3)
                    .map(|s| (s.name.clone(), s.explained_fraction))
                    .collect()
            })
            .unwrap_or_default();
        Some(discrepancy::fit(
            &labels,
            &fit.residual,
            samples,
            det.coherent_rank,
            closest,
        )?)
    } else {
        None
    };
    let draws = ctx.model_noise.stats(fit, &ctx.frame, None, None)?;
    let noise_var = draws.parameter_variances(fit.point.len());
    let roughness = draws.objective_noise();
    let added: Vec<Added> = outcome
        .added
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let v = fit.point[d0 + i];
            let pending = fit.pending[d0 + i];
            let rough_var = fit.se[d0 + i].powi(2) * roughness;
            let se =
                (fit.se[d0 + i].powi(2) + noise_var[d0 + i] + rough_var + pending * pending).sqrt();
            // Not determined by the data at the end point: the interval is the whole range.
            let (lower, upper, roughness_sd) = if se.is_finite() {
                (v - 1.96 * se, v + 1.96 * se, rough_var.sqrt())
            } else {
                (p.lower, p.upper, 0.0)
            };
            Added {
                name: p.name.clone(),
                value: v,
                lower,
                upper,
                model_noise_sd: noise_var[d0 + i].sqrt(),
                roughness_sd,
                pending_step: pending,
            }
        })
        .collect();

    // Before and after on the calibration test.
    observer.step("before and after");
    let p_of = |d: usize| d + n_nuisance;
    let (terms_nominal, _) = ctx.profile(&y_nominal);
    let posterior = |jac| Posterior { jac };
    let judge = Judge {
        options,
        noise_dof: floor.level_dof(),
    };
    let metrics_calibration = Stages {
        nominal: judge.errors(&ctx.frame, &y_nominal, &terms_nominal, p_of(d0), None, 0)?,
        calibrated: judge.errors(
            &ctx.frame,
            &fit0.y,
            &fit0.terms,
            p_of(d0),
            Some(posterior(fit0.jac.as_ref())),
            1,
        )?,
        enriched: judge.errors(
            &ctx.frame,
            &fit.y,
            &fit.terms,
            p_of(fit.point.len()),
            Some(posterior(fit.jac.as_ref())),
            2,
        )?,
    };

    // The holdout, never fitted.
    let metrics_holdout = match holdout_models {
        None => None,
        Some((h, declared_at)) => {
            observer.step("holdout");
            let enriched_model = model.enrich(&outcome.added)?;
            let enriched_at = enriched_model.at_condition(h.set)?;
            let nominal_h = runner
                .at(h.set)
                .stage(
                    &declared_at,
                    "holdout-nominal",
                    std::slice::from_ref(&nominal),
                )?
                .histories(0, "the holdout's nominal run")?;
            check_covered(h.histories, test.map, &nominal_h, "holdout")?;
            let (test_h, masks_h, preparation_h) =
                prepared_test(h.histories, test.map, test.cfc, &nominal_h, None)?;
            let calibrated_h = runner
                .at(h.set)
                .stage(
                    &declared_at,
                    "holdout-calibrated",
                    std::slice::from_ref(&fit0.point),
                )?
                .histories(0, "the holdout's calibrated run")?;
            let enriched_h = runner
                .at(h.set)
                .stage(
                    &enriched_at,
                    "holdout-enriched",
                    std::slice::from_ref(&fit.point),
                )?
                .histories(0, "the holdout's enriched run")?;
            let (spread_h, model_noise_h) = model_spread(
                runner.at(h.set),
                &declared_at,
                &nominal,
                &nominal_h,
                options,
                &labels,
                test.cfc,
                "holdout-noise",
            )?;
            let y_nom_h = prep(&nominal_h)?;
            let gains: Vec<f64> = fit.terms.gains.clone();
            let (mut frame_h, floor_h) = frame_of(
                &labels,
                test_h.data(),
                test_h.samples(),
                dt,
                &y_nom_h,
                &model_noise_h,
                &spread_h,
                max_shift,
                options,
                (test.cfc, band),
                Some(&gains),
                preparation_h.pre_trigger.as_ref(),
            )?;
            noise_model(&mut frame_h, &masks_h, &floor_h)?;
            let profile = |y: &[f64]| nuisance::profile(y, &frame_h, max_shift, Some(&gains)).0;
            let ys = [y_nom_h, prep(&calibrated_h)?, prep(&enriched_h)?];
            let judge = Judge {
                options,
                noise_dof: floor_h.level_dof(),
            };
            let at = |k: usize| {
                judge.errors(
                    &frame_h,
                    &ys[k],
                    &profile(&ys[k]),
                    p_of(0),
                    None,
                    3 + k as u64,
                )
            };
            Some(Stages {
                nominal: at(0)?,
                calibrated: at(1)?,
                enriched: at(2)?,
            })
        }
    };
    let rel = |s: &Stages<Errors>| Stages {
        nominal: s.nominal.rel_l2,
        calibrated: s.calibrated.rel_l2,
        enriched: s.enriched.rel_l2,
    };
    let names = model.enrich(&outcome.added)?;
    Ok(LoopResult {
        model: description.to_string(),
        verdict,
        detection: det0,
        nuisance: fit.terms.report(&labels, options.units_tolerance),
        noise_floor: floor,
        test_preparation: preparation,
        candidates: outcome.rounds[0]
            .attribution
            .as_ref()
            .map(|a| a.ranked.clone())
            .unwrap_or_default(),
        indistinguishable: outcome.rounds[0]
            .attribution
            .as_ref()
            .map(|a| a.indistinguishable.clone())
            .unwrap_or_default(),
        added,
        calibrated: names
            .space()
            .names()
            .iter()
            .zip(&fit.point)
            .map(|(n, v)| (n.to_string(), *v))
            .collect(),
        models: outcome.models,
        stopped: outcome.stopped,
        detection_final: det,
        unattributed,
        errors: ErrorSummary {
            calibration: rel(&metrics_calibration),
            holdout: metrics_holdout.as_ref().map(rel),
        },
        metrics_calibration,
        metrics_holdout,
        rounds: outcome.rounds,
        runs: used.get(),
        m1_members: options.m1_members,
        time_step: dt,
        start: test_m.start(),
    })
}

/// The jitter spread of `model` about `point` on `labels`, `S x T` (filtered like the test),
/// and the ensemble's draws of the model's noise (each run minus the nominal run, with the
/// jitter it was given).
#[allow(clippy::too_many_arguments)]
fn model_spread<M: Model>(
    runner: Journaled<'_>,
    model: &M,
    point: &[f64],
    nominal: &Histories,
    options: &LoopOptions,
    labels: &[String],
    cfc: Option<Cfc>,
    name: &str,
) -> Result<(Vec<f64>, ModelNoise)> {
    let jitter = JitterOptions::new(options.ensemble, options.jitter, options.seed);
    let pts = jitter_points(model.space(), point, &jitter)?;
    let runs = runner.stage(model, name, &pts)?;
    let used: Vec<usize> = (0..runs.len()).filter(|&i| runs.succeeded(i)).collect();
    if used.len() < 2 {
        return Err(CalibrateError::study(
            name,
            "fewer than 2 jitter runs succeeded; the model's noise cannot be measured",
        ));
    }
    let shifts = used
        .iter()
        .map(|&i| pts[i].iter().zip(point).map(|(a, b)| a - b).collect())
        .collect();
    let nominal = nominal.select(labels)?;
    let nominal = match cfc {
        Some(c) => nominal.filtered(c)?,
        None => nominal,
    };
    let draws = ModelNoise {
        runs,
        used,
        shifts,
        nominal: nominal.clone(),
        labels: labels.to_vec(),
        cfc,
    };
    let noise = SimulationNoise::from_run_reader(&nominal, draws.len(), &mut |j| draws.run(j))?;
    Ok((noise.spread.concat(), draws))
}

/// The whitened frame of a test and its noise floor. The nominal run `y_nominal` and the
/// jitter runs of `model_noise` (read one at a time, only when a channel's noise comes
/// from the band) are the model ensemble whose bandwidth bounds the noise's band;
/// `filters` the test's CFC (the one the test and the runs went through) and the class of
/// the high band; `lead` the test's record before the model's start
/// (`study::channels::pre_trigger`), measured with the window's quiet start.
#[allow(clippy::too_many_arguments)]
fn frame_of(
    labels: &[String],
    test: &[f64],
    samples: usize,
    dt: f64,
    y_nominal: &[f64],
    model_noise: &ModelNoise,
    spread: &[f64],
    max_shift: f64,
    options: &LoopOptions,
    filters: (Option<Cfc>, Cfc),
    fixed_gains: Option<&[f64]>,
    lead: Option<&Histories>,
) -> Result<(Frame, NoiseFloor)> {
    let mut frame = Frame {
        labels: labels.to_vec(),
        samples,
        dt,
        test: test.to_vec(),
        weights: vec![1.0; test.len()],
        whitener: prewhiten::Prewhitener::default(),
    };
    let (terms, _) = nuisance::profile(y_nominal, &frame, max_shift, fixed_gains);
    let onset = noise_floor::onset(y_nominal, samples) as f64 + terms.tau / dt;
    let pre = (onset - 3.0).floor().max(0.0) as usize;
    // A test that departs before the model's start leaves its record's last samples out.
    let lead: Vec<f64> = lead.map_or_else(Vec::new, |h| {
        let late = (3.0 - onset).ceil().max(0.0) as usize;
        let keep = h.samples().saturating_sub(late);
        (0..h.channels())
            .flat_map(|c| h.channel(c)[..keep].iter().copied())
            .collect()
    });
    let members = || {
        let runs = (0..model_noise.len()).map(|j| Ok(model_noise.run(j)?.data().to_vec()));
        noise_floor::envelopes_of(
            std::iter::once(Ok(y_nominal.to_vec())).chain(runs),
            labels.len(),
            samples,
        )
    };
    let floor = noise_floor::estimate(
        labels,
        test,
        &members,
        samples,
        dt,
        &lead,
        pre.min(samples),
        spread,
        options.sigma,
        filters,
    )?;
    frame.weights = noise_floor::weights(&floor, spread, samples);
    Ok((frame, floor))
}

/// The frame's noise model: zero weight for the masked samples of `core::quality` (clipped
/// runs and spikes, per channel in frame order: they leave every residual), and each
/// channel's AR whitening of the noise `floor` measured, started afresh after each mask.
///
/// # Errors
/// [`CalibrateError::Study`] for a noise model that is not stationary.
fn noise_model(frame: &mut Frame, masks: &[Vec<bool>], floor: &NoiseFloor) -> Result<()> {
    let t = frame.samples;
    for (s, m) in masks.iter().enumerate() {
        for (k, &out) in m.iter().enumerate().take(t) {
            if out {
                frame.weights[s * t + k] = 0.0;
            }
        }
    }
    let masked = frame
        .weights
        .chunks(t)
        .map(|w| w.iter().map(|v| *v == 0.0).collect())
        .collect();
    frame.whitener = prewhiten::Prewhitener::new(&frame.labels, &floor.ar_models(), masked, t)?;
    Ok(())
}

/// What judges a model's response against a test: the loop's options and the degrees of
/// freedom of the noise level's estimate (`NoiseFloor::level_dof`).
struct Judge<'a> {
    options: &'a LoopOptions,
    noise_dof: Option<f64>,
}

impl Judge<'_> {
    /// The errors of model response `y` under nuisance `terms` against the frame's test,
    /// with `p` fitted quantities; `posterior` widens the M1 ensemble by the parameters'
    /// linearised uncertainty; `stream` separates the seeds of the M1 ensembles.
    fn errors(
        &self,
        frame: &Frame,
        y: &[f64],
        terms: &Terms,
        p: usize,
        posterior: Option<Posterior<'_>>,
        stream: u64,
    ) -> Result<Errors> {
        let corrected = nuisance::corrected_test(frame, terms);
        let num: f64 = corrected.iter().zip(y).map(|(a, b)| (a - b).powi(2)).sum();
        let den: f64 = corrected.iter().map(|a| a * a).sum();
        let residual = nuisance::residual(y, frame, terms);
        let det = detection::detect(
            &frame.labels,
            &residual,
            frame.samples,
            p,
            self.options.alpha,
            self.noise_dof,
        )?;
        let iso = Iso18571::new();
        let t = frame.samples;
        let (mut sg, mut r, mut k) = (0.0, 0.0, 0.0);
        for s in 0..frame.labels.len() {
            if let Ok(m) = CurveMetrics::between(
                &corrected[s * t..(s + 1) * t],
                &y[s * t..(s + 1) * t],
                frame.dt,
                &iso,
            ) {
                sg += m.sprague_geers.comprehensive;
                r += m.iso18571.r;
                k += 1.0;
            }
        }
        let m1 = agreement::m1_exceedance(
            frame,
            y,
            terms,
            posterior,
            self.options.m1_members,
            self.options
                .seed
                .wrapping_add(stream.wrapping_mul(0x9E37_79B9_7F4A_7C15)),
        )?;
        let m2 = agreement::m2_count(frame, y, terms).ok();
        Ok(Errors {
            rel_l2: if den > 0.0 {
                (num / den).sqrt()
            } else {
                f64::NAN
            },
            chi2_red: det.chi2_red,
            sprague_geers_c: if k > 0.0 { sg / k } else { f64::NAN },
            iso18571_r: if k > 0.0 { r / k } else { f64::NAN },
            m1_exceedance: m1.exceedance_fraction,
            m1_expected: m1.expected_exceedance,
            m1_probability: m1.probability,
            m2_above_0_9: m2.map(|m| m.0),
            m2_shapes: m2.map_or(0, |m| m.1),
        })
    }
}

/// Every test channel must pair with a model channel (through the map, or by label).
fn check_covered(
    test: &Histories,
    map: Option<&ChannelMap>,
    model: &Histories,
    what: &str,
) -> Result<()> {
    let missing: Vec<&str> = test
        .labels()
        .iter()
        .filter(|l| match map {
            Some(m) => !m.entries.iter().any(|e| &&e.test_label == l),
            None => model.index_of(l).is_none(),
        })
        .map(String::as_str)
        .collect();
    if missing.is_empty() {
        Ok(())
    } else {
        Err(CalibrateError::study(
            format!("{what} channels"),
            format!(
                "{} not covered by {} (model channels: {}); map them or drop them from the test",
                missing.join(", "),
                if map.is_some() {
                    "the channel map"
                } else {
                    "the model's labels"
                },
                model.labels().join(", ")
            ),
        ))
    }
}

fn fingerprint(
    description: &str,
    space: &impactcal_core::ParameterSpace,
    options: &LoopOptions,
    test: TestData<'_>,
    holdout: Option<Holdout<'_>>,
) -> String {
    let mut bytes = b"closed-loop\n".to_vec();
    bytes.extend_from_slice(description.as_bytes());
    bytes.extend(serde_json::to_vec(space).unwrap_or_default());
    bytes.extend(serde_json::to_vec(options).unwrap_or_default());
    bytes.extend(format!("{:?}", test.cfc.map(Cfc::class)).as_bytes());
    if let Some(m) = test.map {
        for e in &m.entries {
            bytes.extend(format!("{}>{}*{};", e.test_label, e.model_label, e.gain).as_bytes());
        }
    }
    let mut add = |h: &Histories| {
        h.labels().iter().for_each(|l| bytes.extend(l.as_bytes()));
        bytes.extend(h.dt().to_le_bytes());
        bytes.extend(h.start().to_le_bytes());
        h.data().iter().for_each(|v| bytes.extend(v.to_le_bytes()));
    };
    add(test.histories);
    if let Some(h) = holdout {
        add(h.histories);
        for (n, v) in h.set {
            bytes.extend(format!("{n}={v};").as_bytes());
        }
    }
    impactcal_runner::fingerprint(&bytes)
}
