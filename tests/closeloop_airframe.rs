//! The closed loop on the coarse airframe (docs/closed-loop.md, docs/airframe.md
//! "Undeclared effects"): two declared thicknesses over 0 to 0.015 s, four candidate
//! effects, the truth with structural damping the model holds at zero, measured on the
//! sensor channels that move most, with white noise and a trigger offset; the sensors'
//! gains are known (`fit_gains = false`: with a gain fitted per channel the loop still finds
//! and adds the damping but calls what remains unattributed; docs/validation.md);
//! the holdout is the same truth dropped at another sink speed.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use std::path::{Path, PathBuf};

use impactcal::calibrate::closeloop::{Holdout, LoopOptions, LoopResult, Verdict, run_loop};
use impactcal::calibrate::study::{Silent, TestData};
use impactcal::core::enrich::Enrichable;
use impactcal::core::synthetic::{Measurement, measured};
use impactcal::core::{Cfc, Histories, Model};
use impactcal::shell::airframe::{Airframe, AirframeModel, AirframeOptions, MeshDensity, space_of};

/// The window (s): the first contact and crush of the belly.
const END: f64 = 0.015;
/// The declared thicknesses.
const DECLARED: [&str; 2] = ["belly_panel.t", "keel_beam_web.t"];
/// The candidates the loop may add.
const CANDIDATES: [&str; 4] = ["damping", "ground.friction", "mass.occupants", "rate.c"];
/// The truth's thicknesses, as factors on the nominal values.
const TRUE_FACTORS: [f64; 2] = [1.1, 0.95];
/// Sensor channels of the test: the ones of the truth that change most.
const CHANNELS: usize = 24;
/// The trigger offset of the test (s): two samples late.
const TAU: f64 = 2e-4;
/// The CFC class of the comparison. (CFC 60, 100 Hz, spans a period and a half of the
/// 15 ms window: its start-up transient would dominate the residual.)
const FILTER: u32 = 1000;
/// The holdout's sink speed (in/s).
const HOLDOUT_SPEED: f64 = 280.0;

fn model() -> AirframeModel {
    let mut o = AirframeOptions::new(MeshDensity::Coarse);
    o.end_time = END;
    AirframeModel::new(Airframe::new(o).unwrap(), space_of(&DECLARED).unwrap()).unwrap()
}

fn true_point(m: &AirframeModel) -> Vec<f64> {
    m.space()
        .nominal()
        .iter()
        .zip(TRUE_FACTORS)
        .map(|(x, f)| x * f)
        .collect()
}

/// The `CHANNELS` channels of `h` with the largest standard deviation after CFC 60,
/// largest first. (A velocity that barely changes over the window is a constant, and
/// its gain and bias cannot be told apart.)
fn loudest(h: &Histories) -> Vec<String> {
    let f = h.filtered(Cfc::from_class(60).unwrap()).unwrap();
    f.most_varying(CHANNELS)
}

/// The truth (the model with `hidden` set) measured on its loudest vertical channels, and
/// its holdout at `HOLDOUT_SPEED`, with noise seeds `seed` and `seed + 1`.
fn tests(hidden: &[(String, f64)], seed: u64) -> (Histories, Histories) {
    let m = model();
    let truth = m.at_condition(hidden).unwrap();
    let x = true_point(&m);
    let y = truth.simulate(&x).unwrap();
    let labels = loudest(&y);
    let m = Measurement {
        time_shift: TAU,
        snr_db: Some(40.0),
        seed,
        ..Measurement::default()
    };
    measure_both(&truth, &x, &y, &labels, &m, seed + 1)
}

/// The truth's run `y` at `x` and its run at the holdout's sink speed, measured on `labels`
/// with `m`, the holdout with the noise seed `holdout_seed`.
fn measure_both(
    truth: &AirframeModel,
    x: &[f64],
    y: &Histories,
    labels: &[String],
    m: &Measurement,
    holdout_seed: u64,
) -> (Histories, Histories) {
    let speed = [("impact.vertical".to_string(), HOLDOUT_SPEED)];
    let yh = truth.at_condition(&speed).unwrap().simulate(x).unwrap();
    let mh = Measurement {
        seed: holdout_seed,
        ..m.clone()
    };
    (
        measured(&y.select(labels).unwrap(), m).unwrap(),
        measured(&yh.select(labels).unwrap(), &mh).unwrap(),
    )
}

fn options() -> LoopOptions {
    LoopOptions {
        ensemble: 4,
        reconcile: LoopOptions::cors_runs_needed(2),
        recalibrate: LoopOptions::cors_runs_needed(3),
        max_added: 1,
        polish: 6,
        batch: 2,
        candidates: Some(CANDIDATES.iter().map(|s| s.to_string()).collect()),
        fit_gains: false,
        ..LoopOptions::default()
    }
}

fn close_with(
    test: &Histories,
    holdout: &Histories,
    dir: &Path,
    options: &LoopOptions,
) -> LoopResult {
    let set = [("impact.vertical".to_string(), HOLDOUT_SPEED)];
    let data = TestData {
        histories: test,
        map: None,
        cfc: Some(Cfc::from_class(FILTER).unwrap()),
    };
    let h = Holdout {
        histories: holdout,
        set: &set,
    };
    run_loop(
        &model(),
        "coarse airframe, 0-0.015 s",
        data,
        Some(h),
        options,
        dir,
        &Silent,
    )
    .unwrap()
}

/// An empty folder for a loop under cargo's temporary directory for integration tests.
fn fresh(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("closeloop-airframe-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn hidden_damping_on_the_airframe_is_found_and_the_error_falls() {
    let (test, holdout) = tests(&[("damping".into(), 10.0)], 1);
    let dir = fresh("hidden-damping");
    // The polish crawls on the airframe's rough response (each full Gauss-Newton step too
    // short): from the path the CORS search takes here it needs 12 iterations to reach the
    // optimum (docs/closed-loop.md, "the samples at each end").
    let options = LoopOptions {
        polish: 14,
        ..options()
    };
    let r = close_with(&test, &holdout, &dir, &options);
    // The result beside the journal, for a look at a failure.
    std::fs::write(
        dir.join("loop.json"),
        serde_json::to_string_pretty(&r).unwrap(),
    )
    .unwrap();
    let summary = format!(
        "{:?}\n{:?}\n{:?}\n{:?}\n{:?}",
        ranking(&r),
        r.added,
        r.errors,
        r.nuisance,
        r.calibrated
    );
    println!("{summary}");
    // Detected, damping ranked first and added.
    assert!(r.detection.model_form_error, "{summary}");
    assert_eq!(r.candidates[0].name, "damping", "{summary}");
    assert_eq!(r.verdict, Verdict::Attributed, "{}\n{summary}", r.stopped);
    let a = &r.added[0];
    assert_eq!(a.name, "damping");
    // Its value within 5 % of the truth. (Its 95 % interval is not asserted: 10.001
    // [9.944, 10.058] with a pending Gauss-Newton step of 0.0018 after 14 polish
    // iterations; after 6 the same path stood at 9.68 [9.42, 9.94], a step of 0.11 still
    // pending.)
    assert!((a.value - 10.0).abs() < 0.5, "{a:?}");
    // The declared thicknesses recovered within 2 %, and the nuisance terms.
    let x = true_point(&model());
    for (name, truth) in DECLARED.iter().zip(&x) {
        let v = r.calibrated[*name];
        assert!(
            (v / truth - 1.0).abs() < 0.02,
            "{name}: {v} against {truth}"
        );
    }
    assert!((r.nuisance.time_shift - TAU).abs() < 2e-5, "{summary}");
    // The error falls on the calibration test and on the holdout, never fitted.
    errors_fall(&r, 0.5, 0.5, &summary);
    // M1: the test leaves the enriched model's predictive envelope less often than the
    // calibrated one's, on both tests.
    for m in [&r.metrics_calibration, r.metrics_holdout.as_ref().unwrap()] {
        assert!(
            m.enriched.m1_exceedance < m.calibrated.m1_exceedance,
            "{m:?}"
        );
    }
    println!("{:?}\n{:?}", r.metrics_calibration, r.metrics_holdout);
}

#[test]
fn without_a_hidden_effect_the_loop_on_the_airframe_stays_silent() {
    let (test, holdout) = tests(&[], 2);
    let dir = fresh("negative-control");
    // The statistics judge a least-squares optimum: from the nominal thicknesses (10 % and
    // 5 % off) the small budget above leaves chi2_red 4.3, which reads as model-form error.
    let options = LoopOptions {
        reconcile: 16,
        polish: 12,
        ..options()
    };
    let r = close_with(&test, &holdout, &dir, &options);
    println!("{:?}\n{:?}", r.metrics_calibration, r.metrics_holdout);
    assert_eq!(r.verdict, Verdict::NoModelFormError, "{:?}", r.detection);
    assert!(r.added.is_empty());
    assert!((r.nuisance.time_shift - TAU).abs() < 2e-5);
    // The calibrated model is right: the test leaves its predictive envelope at about
    // 2/(N+1) = 1 % of the samples, on both tests.
    for m in [&r.metrics_calibration, r.metrics_holdout.as_ref().unwrap()] {
        assert!(m.calibrated.m1_exceedance < 0.05, "{m:?}");
    }
}

/// The reduced family's mass case (docs/validation.md, "The closed loop over a family of
/// hidden effects"): the occupants' mass 14 % above what the model holds, a gain of 1.12
/// on the channel that moves most fitted among the nuisance terms, white noise of 0.5 %,
/// a trigger offset of three samples, 12 channels. The loop must rank the mass first, add
/// it near its truth with the truth inside its interval, recover the thicknesses, the gain
/// and the trigger, cut the error on both tests and end `attributed` (the case the loop once
/// left with the gain taking up part of the effect, and later in another basin of the
/// thicknesses).
#[test]
fn a_hidden_mass_with_a_wrong_gain_is_found_and_the_gain_recovered() {
    const MASS: f64 = 0.8;
    const GAIN: f64 = 1.12;
    const TAU3: f64 = 3e-4;
    let m = model();
    let truth = m.at_condition(&[("mass.occupants".into(), MASS)]).unwrap();
    let x = true_point(&m);
    let y = truth.simulate(&x).unwrap();
    let f = y.filtered(Cfc::from_class(FILTER).unwrap()).unwrap();
    let vertical: Vec<&String> = f.labels().iter().filter(|l| l.ends_with(".z")).collect();
    let labels = f.select(&vertical).unwrap().most_varying(12);
    let wrong = labels[0].clone();
    let m = Measurement {
        time_shift: TAU3,
        gains: vec![(wrong.clone(), GAIN)],
        snr_db: Some(46.0206),
        seed: 1,
        ..Measurement::default()
    };
    let (test, holdout) = measure_both(&truth, &x, &y, &labels, &m, 101);
    let options = LoopOptions {
        reconcile: 16,
        polish: 12,
        fit_gains: true,
        candidates: Some(
            ["damping", "ground.friction", "mass.occupants", "rate.c"]
                .iter()
                .map(|s| s.to_string())
                .collect(),
        ),
        ..options()
    };
    let dir = fresh("hidden-mass");
    let r = close_with(&test, &holdout, &dir, &options);
    // The result beside the journal, for a look at a failure.
    std::fs::write(
        dir.join("loop.json"),
        serde_json::to_string_pretty(&r).unwrap(),
    )
    .unwrap();
    let summary = format!(
        "{:?}\n{:?}\n{:?}\n{:?}\n{}",
        ranking(&r),
        r.added,
        r.errors,
        r.nuisance.gains.get(&wrong),
        r.stopped
    );
    println!("{summary}");
    assert_eq!(r.candidates[0].name, "mass.occupants", "{summary}");
    // What remains after the mass is added is noise: the recalibration must reach the
    // truth's basin (a search of ten runs once left it at a thinner belly, chi2_red 2.45).
    assert_eq!(r.verdict, Verdict::Attributed, "{summary}");
    let a = &r.added[0];
    assert_eq!(a.name, "mass.occupants", "{summary}");
    assert!((a.value / MASS - 1.0).abs() < 0.01, "{summary}");
    assert!(a.lower <= MASS && MASS <= a.upper, "{summary}");
    // The declared thicknesses recovered within 2 %.
    for (name, truth) in DECLARED.iter().zip(&x) {
        let v = r.calibrated[*name];
        assert!(
            (v / truth - 1.0).abs() < 0.02,
            "{name}: {v} against {truth}"
        );
    }
    // The gain within 3 % and the trigger within a fifth of a sample (1e-4 s).
    assert!(
        (r.nuisance.gains[&wrong] / GAIN - 1.0).abs() < 0.03,
        "{summary}"
    );
    assert!((r.nuisance.time_shift - TAU3).abs() < 2e-5, "{summary}");
    errors_fall(&r, 0.7, 1.0, &summary);
}

/// Asserts that the enriched model's error is under `calibration` times the calibrated
/// one's on the calibration test and under `holdout` times it on the holdout.
/// Each candidate's name, kappa, explained fraction and status, in rank order (for the
/// printed summary of a loop).
fn ranking(r: &LoopResult) -> Vec<(&String, f64, f64, &String)> {
    r.candidates
        .iter()
        .map(|c| (&c.name, c.kappa, c.explained_fraction, &c.status))
        .collect()
}

fn errors_fall(r: &LoopResult, calibration: f64, holdout: f64, summary: &str) {
    let e = &r.errors;
    assert!(
        e.calibration.enriched < calibration * e.calibration.calibrated,
        "{summary}"
    );
    let h = e.holdout.as_ref().unwrap();
    assert!(h.enriched < holdout * h.calibrated, "{summary}");
}
