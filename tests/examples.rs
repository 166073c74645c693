//! The user examples run (each in a fraction of a second to a few seconds), the shipped
//! example data are the examples' toy model at the stated points, and the end-to-end
//! example recovers the parameters of the test.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]
// Every example includes the toy model itself, as it is its own crate.
#![allow(clippy::duplicate_mod)]

#[path = "../examples/calibration.rs"]
#[allow(dead_code)]
mod calibration;
#[path = "../examples/experiment.rs"]
#[allow(dead_code)]
mod experiment;
#[path = "../examples/common/impact_model.rs"]
#[allow(dead_code)]
mod impact_model;
#[path = "../examples/step1_histories.rs"]
mod step1_histories;
#[path = "../examples/step2_shapes.rs"]
mod step2_shapes;
#[path = "../examples/step3_sensors.rs"]
mod step3_sensors;
#[path = "../examples/step4_surrogate.rs"]
mod step4_surrogate;
#[path = "../examples/step5_sensitivity.rs"]
mod step5_sensitivity;
#[path = "../examples/step6_optimise.rs"]
mod step6_optimise;

use impactcal::prelude::*;

#[test]
fn every_step_runs() {
    step1_histories::main().unwrap();
    step2_shapes::main().unwrap();
    step3_sensors::main().unwrap();
    step4_surrogate::main().unwrap();
    step5_sensitivity::main().unwrap();
    step6_optimise::main().unwrap();
}

#[test]
fn the_path_recovers_the_test_parameters() {
    let found = calibration::calibrate().unwrap();
    for (f, t) in found.iter().zip(impact_model::TEST_POINT) {
        assert!((f - t).abs() < 0.01 * t, "found {found:?}");
    }
}

/// `examples/data` holds the toy model at (1, 1) and at the test point, bit for bit, and
/// the measured file is a subset of the test.
#[test]
fn shipped_data_are_the_model() {
    use impact_model::{DT, NODES, SAMPLES, TEST_POINT, impact};
    let analysis = Histories::read_csv("examples/data/analysis.csv").unwrap();
    let test = Histories::read_csv("examples/data/test.csv").unwrap();
    // The files carry no unit; the data and labels are the model's, bit for bit.
    for (file, model) in [
        (&analysis, impact(NODES, SAMPLES, DT, 1.0, 1.0)),
        (
            &test,
            impact(NODES, SAMPLES, DT, TEST_POINT[0], TEST_POINT[1]),
        ),
    ] {
        assert_eq!(file.labels(), model.labels());
        assert_eq!(file.dt(), model.dt());
        assert_eq!(file.data(), model.data());
    }
    let measured = Histories::read_csv("examples/data/measured.csv").unwrap();
    assert_eq!(measured, test.select(measured.labels()).unwrap());
}

/// `examples/experiment.rs` runs the shipped study and loop files through the library: the
/// study finds the test's drop speed (the test is the strip dropped at vz = -5.2 in/s with
/// t = 0.0021 in) and the loop adds the contact damping hidden in its test (0.2) and cuts
/// the error on the test and on the holdout.
#[test]
fn the_experiment_example_runs_a_study_file_and_a_loop_file() {
    let dir = std::env::temp_dir().join(format!("impactcal-experiment-{}", std::process::id()));
    let (study, closed) = experiment::run(
        "examples/study/local.toml".as_ref(),
        "examples/loop/local.toml".as_ref(),
        &dir,
    )
    .unwrap();
    assert_eq!(
        study.result.m1.verdict,
        impactcal::calibrate::study::Verdict::CanExplain
    );
    let calibrated = &study.result.reconcile.as_ref().unwrap().calibrated;
    assert!((calibrated["vz"] + 5.2).abs() < 0.05, "{calibrated:?}");
    let errors = study.result.errors.as_ref().unwrap();
    assert!(errors.calibrated.prediction_error < 0.5 * errors.baseline.prediction_error);
    assert!(study.json.ends_with("study/study.json") && study.json.is_file());

    let r = &closed.result;
    assert_eq!(
        r.verdict,
        impactcal::calibrate::closeloop::Verdict::Attributed
    );
    assert_eq!(r.added[0].name, "contact_damping");
    assert!((r.added[0].value - 0.2).abs() < 0.02, "{:?}", r.added[0]);
    let holdout = r.errors.holdout.as_ref().unwrap();
    for e in [&r.errors.calibration, holdout] {
        assert!(e.enriched < 0.1 * e.calibrated, "{e:?}");
    }
    assert!(closed.json.ends_with("loop/loop.json") && closed.json.is_file());
    std::fs::remove_dir_all(&dir).ok();
}
