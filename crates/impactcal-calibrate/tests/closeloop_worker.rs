//! The closed loop on a worker that fails: the loop stops with a typed error naming the
//! run's stage and the worker's exit status and message, the journal keeps the failure,
//! and the same loop run again (here in process) ends with the result of a loop that never
//! failed.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use impactcal_calibrate::CalibrateError;
use impactcal_calibrate::closeloop::{LoopOptions, run_loop, run_loop_on};
use impactcal_calibrate::study::{Silent, TestData};
use impactcal_core::drop_tower::DropTower;
use impactcal_core::synthetic::{Measurement, measured};
use impactcal_core::{Enrichable, Model};
use impactcal_runner::{
    Cancel, Executor, OutputSpec, ProcessOptions, Runner, Solver, SolverCommand,
};

#[test]
fn a_failing_worker_is_reported_with_its_exit_status_and_loses_nothing() {
    let truth = DropTower::new()
        .at_condition(&[("contact_damping".into(), 0.2)])
        .unwrap();
    let y = truth.simulate(&[75.0, 9e5]).unwrap();
    let test = measured(
        &y,
        &Measurement {
            snr_db: Some(40.0),
            seed: 5,
            ..Measurement::default()
        },
    )
    .unwrap();
    let data = TestData {
        histories: &test,
        map: None,
        cfc: None,
    };
    let options = LoopOptions {
        ensemble: 6,
        reconcile: 16,
        recalibrate: 16,
        ..LoopOptions::default()
    };
    let failing = Runner {
        solver: Solver {
            inputs: Vec::new(),
            command: SolverCommand::Argv(vec![
                "sh".into(),
                "-c".into(),
                "echo 'licence server unreachable' >&2; exit 3".into(),
            ]),
            output: OutputSpec::csv("out.csv"),
        },
        executor: Executor::Processes(ProcessOptions {
            jobs: 2,
            timeout: None,
        }),
        in_process: None,
        retries: 1,
        cancel: Cancel::new(),
    };
    let model = DropTower::new();
    let dir = tempfile::tempdir().unwrap();
    let e = run_loop_on(
        &model,
        "drop tower",
        data,
        None,
        &options,
        dir.path(),
        &Silent,
        Some(&failing),
    )
    .unwrap_err();
    assert!(matches!(e, CalibrateError::Core(_)), "{e:?}");
    let message = e.to_string();
    assert!(message.contains("the nominal run"), "{message}");
    assert!(message.contains("status 3"), "{message}");
    assert!(message.contains("licence server unreachable"), "{message}");
    // The journal holds both attempts' failures, each with the exit status.
    let journal = std::fs::read_to_string(dir.path().join("runs/nominal/journal.jsonl")).unwrap();
    let failures: Vec<&str> = journal
        .lines()
        .filter(|l| l.contains("\"event\":\"failure\""))
        .collect();
    assert_eq!(failures.len(), 2, "{journal}");
    assert!(failures.iter().all(|l| l.contains("status 3")), "{journal}");

    // Run again in the same folder, in process: the loop completes, as a loop that never
    // met the failing worker.
    let resumed = run_loop(
        &model,
        "drop tower",
        data,
        None,
        &options,
        dir.path(),
        &Silent,
    )
    .unwrap();
    let fresh = tempfile::tempdir().unwrap();
    let clean = run_loop(
        &model,
        "drop tower",
        data,
        None,
        &options,
        fresh.path(),
        &Silent,
    )
    .unwrap();
    assert_eq!(
        serde_json::to_string(&resumed).unwrap(),
        serde_json::to_string(&clean).unwrap()
    );
}
