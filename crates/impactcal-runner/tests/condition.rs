//! A batch at a condition (`Batch::new_at`): the held values reach the templates and each
//! run's `params.json`, enter the journal's batch line (a journal at another condition is
//! not resumed), and names that clash or that no template uses are refused.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use impactcal_runner::workdir::RunRecord;
use impactcal_runner::{
    Batch, Cancel, Executor, OutputSpec, RunnerError, Solver, SolverCommand, Template, run_batch,
};

fn solver() -> Solver {
    let template = Template::parse("time,y\n0,<<a>>\n1,<<v0>>\n", "deck.csv").unwrap();
    Solver {
        inputs: vec![(template, "deck.csv".into())],
        command: SolverCommand::Argv(vec!["cp".into(), "deck.csv".into(), "out.csv".into()]),
        output: OutputSpec::csv("out.csv"),
    }
}

fn batch(out: &std::path::Path, v0: f64) -> Result<Batch, RunnerError> {
    Batch::new_at(
        out,
        "held",
        solver(),
        vec!["a".into()],
        &vec![vec![1.5], vec![-2.0]],
        &[("v0".into(), v0)],
    )
}

#[test]
fn the_condition_reaches_the_templates_params_and_journal() {
    let dir = tempfile::tempdir().unwrap();
    let b = batch(dir.path(), 7.0).unwrap();
    let report = run_batch(&b, &Executor::Local, &Cancel::new()).unwrap();
    assert_eq!(report.histories(1).unwrap().channel(0), [-2.0, 7.0]);
    let record: RunRecord =
        serde_json::from_str(&std::fs::read_to_string(b.root().join("1/params.json")).unwrap())
            .unwrap();
    assert_eq!(record.names, ["a"]);
    assert_eq!(record.values, [-2.0]);
    assert_eq!(record.set.get("v0"), Some(&7.0));
    let journal = std::fs::read_to_string(b.journal_path()).unwrap();
    assert!(
        journal
            .lines()
            .next()
            .unwrap()
            .contains("\"set\":{\"v0\":7.0}")
    );
    // Run again: reused. At another condition: refused, the journal untouched.
    let again = run_batch(&b, &Executor::Local, &Cancel::new()).unwrap();
    assert!(again.reused.iter().all(|&r| r));
    let other = batch(dir.path(), 8.0).unwrap();
    let e = run_batch(&other, &Executor::Local, &Cancel::new()).unwrap_err();
    assert!(matches!(e, RunnerError::Journal { .. }), "{e}");
    assert_eq!(std::fs::read_to_string(b.journal_path()).unwrap(), journal);
}

#[test]
fn clashing_unused_and_non_finite_conditions_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let base = || {
        Batch::new(
            dir.path(),
            "held",
            solver(),
            vec!["a".into()],
            &vec![vec![1.0]],
        )
    };
    // Without its condition the template's <<v0>> has no value.
    assert!(base().is_err());
    let two = |set: &[(String, f64)]| {
        Batch::new_at(
            dir.path(),
            "held",
            solver(),
            vec!["a".into(), "v0".into()],
            &vec![vec![1.0, 2.0]],
            set,
        )
    };
    assert!(two(&[]).is_ok());
    let e = two(&[("v0".into(), 3.0)]).unwrap_err();
    assert!(e.to_string().contains("`v0` is set twice"), "{e}");
    let e = two(&[("w".into(), 3.0)]).unwrap_err();
    assert!(
        matches!(e, RunnerError::Names { .. }) && e.to_string().contains("`w`"),
        "{e}"
    );
    assert!(two(&[("w".into(), f64::NAN)]).is_err());
    // A solver without templates (one that reads params.json) takes any condition.
    let bare = Solver {
        inputs: Vec::new(),
        command: SolverCommand::Argv(vec!["true".into()]),
        output: OutputSpec::csv("out.csv"),
    };
    let b = Batch::new_at(
        dir.path(),
        "bare",
        bare,
        vec!["a".into()],
        &vec![vec![1.0]],
        &[("v0".into(), 5.0), ("angle".into(), 0.1)],
    )
    .unwrap();
    assert_eq!(b.len(), 1);
}
