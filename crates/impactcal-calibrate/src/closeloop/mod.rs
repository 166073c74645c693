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
//! 5. **Attribution** ([`attribution`]): two runs per candidate for its direction (a small
//!    step and the far end of its range, the better kept); the
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
mod frame;
mod holdout;
mod jacobian;
mod judge;
mod linalg;
mod model_noise;
pub mod noise_floor;
pub mod nuisance;
pub mod options;
pub mod plan;
mod prewhiten;
mod report;
pub mod result;
pub mod selection;
mod setup;
#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod toy;

use std::cell::Cell;
use std::path::Path;

use impactcal_core::{Cfc, Enrichable, Histories};

use crate::error::Result;
use crate::progress::LoopRunEstimate;
use crate::study::TestData;
use crate::study::execute::Observer;
use impactcal_runner::Runner;

pub use attribution::{Amplitude, Attribution, Score};
pub use detection::Detection;
pub use discrepancy::Discrepancy;
pub use noise_floor::NoiseFloor;
pub use nuisance::Nuisance;
pub use options::LoopOptions;
pub use plan::{LoopShapes, estimated_peak};
pub use result::{
    Added, ErrorSummary, Errors, Evidence, LoopResult, ModelScore, Round, Stages, Verdict,
};
pub use setup::check_inputs;

use fit::Journaled;

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
/// [`CalibrateError::Core`](crate::CalibrateError::Core) with [`impactcal_core::CoreError::InvalidOption`] naming the
/// option as `loop.<key>` for an invalid option or a budget too small to recalibrate (with
/// the runs needed); [`CalibrateError::Study`](crate::CalibrateError::Study) for a model with no candidate, a holdout condition the model cannot take,
/// test channels the map does not cover, a noise floor that cannot be measured;
/// [`CalibrateError::ForeignJournal`](crate::CalibrateError::ForeignJournal) when `dir` holds another loop's or study's journal;
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
/// As [`run_loop`]; a run the worker fails is a [`CalibrateError::Core`](crate::CalibrateError::Core) simulation error
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
    let holdout_models = setup::checked_inputs(model, options, holdout)?;
    let fp = fingerprint(description, model.space(), options, test, holdout);
    let used = Cell::new(0usize);
    let allowed = model
        .candidates()
        .iter()
        .filter(|c| options.allows(c.name()))
        .count();
    let estimate = LoopRunEstimate::new(
        options,
        model.space().dim(),
        allowed,
        holdout_models.is_some(),
    );
    let runner = Journaled {
        dir,
        fingerprint: &fp,
        observer,
        used: &used,
        worker,
        condition: &[],
        plan: None,
        estimate: Some(&estimate),
        stored: None,
    };
    runner.replan(|e| 1 + e.after_nominal());
    let nominal = setup::nominal(&runner, model, test)?;
    let threads = if worker.is_some() {
        0
    } else {
        rayon::current_num_threads()
    };
    let plan = setup::plan(model, &nominal, options, threads)?;
    observer.step(&plan.line());
    // Every later run is read on the compared channels only: unless asked to keep every
    // channel, that is all a run stores.
    let runner = Journaled {
        plan: Some(&plan),
        stored: (!options.keep_all_channels).then_some(nominal.labels.as_slice()),
        ..runner
    };
    let setting = frame::nuisance(runner, model, &nominal, test.cfc, options)?;
    let (fit0, outcome) = recalibration(&setting, model, &nominal.point, options)?;
    let d0 = model.space().dim();
    let det0 = outcome.rounds[0].detection.clone();
    let det = outcome
        .rounds
        .last()
        .map_or_else(|| det0.clone(), |r| r.detection.clone());
    let (verdict, unattributed) = report::verdict(&outcome, &det, &nominal.labels, &nominal.test)?;
    let ctx = &setting.ctx;
    let draws = ctx
        .model_noise
        .stats(&outcome.fit, &ctx.frame, None, None)?;
    let added = report::added(&outcome.fit, &outcome.added, d0, &draws);

    observer.step("before and after");
    let metrics_calibration =
        judge::calibration_errors(&setting, &fit0, &outcome.fit, d0, options)?;
    let metrics_holdout = match &holdout_models {
        None => None,
        Some((h, declared_at)) => {
            observer.step("holdout");
            Some(holdout::holdout_errors(
                &setting,
                model,
                (*h, declared_at),
                &outcome.added,
                &nominal,
                (&fit0, &outcome.fit),
                test,
                options,
            )?)
        }
    };
    let rel = |s: &Stages<Errors>| Stages {
        nominal: s.nominal.rel_l2,
        calibrated: s.calibrated.rel_l2,
        enriched: s.enriched.rel_l2,
    };
    let (candidates, indistinguishable) = report::first_attribution(&outcome);
    let enriched = model.enrich(&outcome.added)?;
    let fit = &outcome.fit;
    Ok(LoopResult {
        model: description.to_string(),
        verdict,
        detection: det0,
        nuisance: fit.terms.report(&nominal.labels, options.units_tolerance),
        noise_floor: setting.floor,
        test_preparation: nominal.preparation,
        dropped: nominal.dropped,
        candidates,
        indistinguishable,
        added,
        calibrated: enriched
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
        time_step: nominal.test.dt(),
        start: nominal.test.start(),
        unit: nominal.test.unit().to_string(),
        channels: nominal.labels,
        cfc: test.cfc.map(Cfc::class),
        holdout_condition: holdout.map(|h| h.set.to_vec()).unwrap_or_default(),
        parameters: enriched.space().parameters().to_vec(),
        catalogue: model
            .candidates()
            .into_iter()
            .map(|c| {
                (
                    c.parameter.name,
                    result::CandidateInfo {
                        unit: c.parameter.unit,
                        description: c.description,
                    },
                )
            })
            .collect(),
        seed: options.seed,
        digest: fp,
    })
}

/// The recalibration stage: the declared model calibrated from its nominal point (journal
/// stages `r0-...`: CORS with `options.reconcile` runs, then the polish), then forward
/// selection from that fit (detection, attribution and enrichment round by round,
/// `selection::forward`). Returns the first calibration and the outcome.
///
/// # Errors
/// Run, journal and numerical errors of the fits and attributions.
fn recalibration<M: Enrichable>(
    setting: &frame::Setting<'_>,
    model: &M,
    nominal: &[f64],
    options: &LoopOptions,
) -> Result<(fit::Fit, selection::Outcome)> {
    let ctx = &setting.ctx;
    ctx.runner.observer.step("calibration");
    let fit0 = fit::calibrate(
        ctx,
        model,
        "r0",
        &[nominal.to_vec()],
        options.reconcile,
        options.polish,
    )?;
    let outcome = selection::forward(
        ctx,
        model,
        fit0.clone(),
        options,
        setting.onset,
        setting.n_nuisance,
        setting.floor.level_dof(),
    )?;
    Ok((fit0, outcome))
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
