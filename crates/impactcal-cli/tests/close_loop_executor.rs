//! `impactcal close-loop` on the executors of a study file: the same loop through the local
//! executor and a process pool (each run `impactcal loop-point` in its own directory) ends
//! with the same `loop.json` byte for byte, also when the loop on the process pool is
//! killed (SIGKILL) mid-loop and run again; `impactcal loop-point` refuses a run that names
//! a quantity the model does not know; executors and tables the loop cannot use are refused.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::impactcal;
use impactcal::core::drop_tower::DropTower;
use impactcal::core::synthetic::{Measurement, measured};
use impactcal::core::{Enrichable, Model};

/// The shipped example `examples/loop/<name>`.
fn example(name: &str) -> PathBuf {
    common::example_file("loop", name)
}

/// The example loop file with the `[executor]` table `executor` instead of its own
/// (nothing: in process), written in `dir` (its data named by absolute paths).
fn drop_tower_loop(dir: &Path, executor: &str) -> PathBuf {
    let text = std::fs::read_to_string(example("processes.toml")).unwrap();
    let body = &text[..=text.find("\n[executor]\n").unwrap()];
    let body = body
        .replace("\"test.csv\"", &format!("{:?}", example("test.csv")))
        .replace("\"holdout.csv\"", &format!("{:?}", example("holdout.csv")));
    let p = dir.join("loop.toml");
    std::fs::write(&p, format!("{body}{executor}")).unwrap();
    p
}

/// The example's data are what its comment says: the drop tower with contact damping 0.2
/// it does not declare, at 4 and 5 m/s, measured at 40 dB (seeds 3 and 4).
#[test]
fn the_example_data_are_the_drop_tower_with_hidden_contact_damping() {
    let truth = DropTower::new()
        .at_condition(&[("contact_damping".into(), 0.2)])
        .unwrap();
    for (file, v0, seed) in [("test.csv", 4.0, 3), ("holdout.csv", 5.0, 4)] {
        let model = truth.at_condition(&[("v0".into(), v0)]).unwrap();
        let y = model.simulate(&[75.0, 9e5]).unwrap();
        let noisy = measured(
            &y,
            &Measurement {
                snr_db: Some(40.0),
                seed,
                ..Measurement::default()
            },
        )
        .unwrap();
        let mut text = Vec::new();
        noisy.write_csv_to(&mut text, file).unwrap();
        if std::env::var_os("IMPACTCAL_WRITE_EXAMPLE").is_some() {
            std::fs::write(example(file), &text).unwrap();
        }
        assert_eq!(std::fs::read(example(file)).unwrap(), text, "{file}");
    }
}

/// The shipped example runs as it is (on the process pool, with its timeout and retries).
#[test]
fn the_shipped_example_runs_on_the_process_pool() {
    let dir = tempfile::tempdir().unwrap();
    let o = close_loop(&example("processes.toml"), &dir.path().join("out"));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_str(&loop_json(&dir.path().join("out"))).unwrap();
    assert_eq!(v["verdict"], "attributed");
    assert_eq!(v["added"][0]["name"], "contact_damping");
    assert!(
        dir.path()
            .join("out/runs/holdout-enriched/0/stdout.txt")
            .is_file()
    );
}

fn close_loop(config: &Path, out: &Path) -> std::process::Output {
    impactcal(&[
        "close-loop",
        "--config",
        config.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ])
}

fn loop_json(out: &Path) -> String {
    std::fs::read_to_string(out.join("loop.json")).unwrap()
}

#[test]
fn the_loop_on_a_process_pool_equals_the_loop_in_process() {
    let dir = tempfile::tempdir().unwrap();
    let local = drop_tower_loop(dir.path(), "");
    let (a, b) = (dir.path().join("local"), dir.path().join("processes"));
    let o = close_loop(&local, &a);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let pool = drop_tower_loop(dir.path(), "[executor]\nkind = \"processes\"\njobs = 2\n");
    let o = close_loop(&pool, &b);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(loop_json(&a), loop_json(&b));
    let v: serde_json::Value = serde_json::from_str(&loop_json(&b)).unwrap();
    assert_eq!(v["verdict"], "attributed");
    assert_eq!(v["added"][0]["name"], "contact_damping");
}

/// The results recorded by every journal of a loop's output folder (complete lines only).
fn results_in(out: &Path) -> usize {
    let Ok(stages) = std::fs::read_dir(out.join("runs")) else {
        return 0;
    };
    stages
        .filter_map(|e| std::fs::read_to_string(e.ok()?.path().join("journal.jsonl")).ok())
        .map(|t| {
            t.lines()
                .filter(|l| l.starts_with("{\"event\":\"result\""))
                .count()
        })
        .sum()
}

#[test]
fn a_loop_on_a_process_pool_killed_mid_loop_resumes_to_the_same_result() {
    let dir = tempfile::tempdir().unwrap();
    let config = drop_tower_loop(dir.path(), "[executor]\nkind = \"processes\"\njobs = 2\n");
    let whole = dir.path().join("whole");
    let o = close_loop(&config, &whole);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let total = serde_json::from_str::<serde_json::Value>(&loop_json(&whole)).unwrap()["runs"]
        .as_u64()
        .unwrap() as usize;

    let killed = dir.path().join("killed");
    let mut child = Command::new(env!("CARGO_BIN_EXE_impactcal"))
        .args(["close-loop", "--config", config.to_str().unwrap(), "--out"])
        .arg(&killed)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while results_in(&killed) < 20 && start.elapsed() < Duration::from_secs(120) {
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap(); // SIGKILL, mid-loop
    child.wait().unwrap();
    let done = results_in(&killed);
    assert!(
        (20..total).contains(&done),
        "killed after {done} of {total} runs"
    );
    assert!(!killed.join("loop.json").exists());

    let o = close_loop(&config, &killed);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(stderr.contains("from the journal"), "{stderr}");
    assert_eq!(loop_json(&whole), loop_json(&killed));
}

/// The `params.json` of a holdout run of a finished loop, changed by `edit`, given to
/// `impactcal loop-point`: its exit code and stderr.
fn loop_point(config: &Path, params: &str, dir: &Path) -> (Option<i32>, String) {
    let p = dir.join("edited.json");
    std::fs::write(&p, params).unwrap();
    let o = impactcal(&[
        "loop-point",
        "--config",
        config.to_str().unwrap(),
        "--params",
        p.to_str().unwrap(),
        "--out",
        dir.join("o.csv").to_str().unwrap(),
    ]);
    (o.status.code(), String::from_utf8_lossy(&o.stderr).into())
}

#[test]
fn the_worker_rebuilds_each_run_and_refuses_names_it_does_not_know() {
    let dir = tempfile::tempdir().unwrap();
    let config = drop_tower_loop(dir.path(), "[executor]\nkind = \"processes\"\njobs = 2\n");
    let out = dir.path().join("out");
    let o = close_loop(&config, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The enriched holdout run names the declared parameters, the candidate added and the
    // condition; the worker run again on it gives the run's result bit for bit.
    let run = out.join("runs/holdout-enriched/0");
    let params = std::fs::read_to_string(run.join("params.json")).unwrap();
    let record: serde_json::Value = serde_json::from_str(&params).unwrap();
    assert_eq!(
        record["names"],
        serde_json::json!(["modulus", "k_contact", "contact_damping"])
    );
    assert_eq!(record["set"], serde_json::json!({ "v0": 5.0 }));
    let (code, err) = loop_point(&config, &params, dir.path());
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(
        std::fs::read(dir.path().join("o.csv")).unwrap(),
        std::fs::read(run.join("out.csv")).unwrap()
    );
    // A candidate, a parameter or a condition the model does not know: exit 2, one line
    // naming it.
    for (from, to, needle) in [
        (
            "\"contact_damping\"",
            "\"contact_dumping\"",
            "contact_dumping",
        ),
        ("\"modulus\"", "\"stiffness\"", "own parameters"),
        ("\"v0\"", "\"v1\"", "v1"),
    ] {
        let (code, err) = loop_point(&config, &params.replace(from, to), dir.path());
        assert_eq!(code, Some(2), "{needle}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(needle), "{needle}: {err}");
    }
}

#[test]
fn executors_and_tables_the_loop_cannot_use_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    for (executor, needle) in [
        ("[executor]\nkind = \"cloud\"\n", "cloud"),
        ("[executor]\nkind = \"processes\"\njobs = 0\n", "jobs"),
        (
            "[executor]\nkind = \"processes\"\njobs = 2\nthreads = 3\n",
            "threads",
        ),
        ("[batch]\nstudy = \"mine\"\n", "[batch]: this table is gone"),
        (
            "[solver]\ntemplate = \"deck.k\"\ncommand = [\"ls-dyna\"]\n",
            "solver",
        ),
    ] {
        let config = drop_tower_loop(dir.path(), executor);
        let out = dir.path().join("out");
        let o = close_loop(&config, &out);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{needle}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(needle), "{needle}: {err}");
    }
}

/// A keyword deck's loop (the strip drop declaring its thickness, every other deck
/// quantity a candidate, a holdout at another drop speed) on the process pool equals the
/// same loop in process: the worker rebuilds the deck's subspace with every candidate of
/// the attribution runs and the holdout's condition.
#[test]
fn a_deck_loop_on_a_process_pool_equals_the_loop_in_process() {
    use impactcal::core::{Parameter, ParameterSpace};
    use impactcal::shell::DeckModel;
    use impactcal::shell::keyword::read_deck;

    let dir = tempfile::tempdir().unwrap();
    let deck_path = common::example_file("decks", "strip_drop.k");
    let declared = ParameterSpace::new(vec![
        Parameter::new("section.1.t", 0.0016, 0.0024, 0.002).unwrap(),
    ])
    .unwrap();
    let truth = DeckModel::new(read_deck(&deck_path).unwrap().model)
        .unwrap()
        .declare(&declared)
        .unwrap();
    let slower = truth
        .at_condition(&[("velocity.1.z".into(), -4.5)])
        .unwrap();
    for (name, m, seed) in [("test.csv", &truth, 1), ("holdout.csv", &slower, 2)] {
        let y = m.simulate(&[0.0021]).unwrap();
        let meas = Measurement {
            snr_db: Some(40.0),
            seed,
            ..Measurement::default()
        };
        let noisy = measured(&y, &meas).unwrap();
        noisy.write_csv(dir.path().join(name)).unwrap();
    }
    std::fs::write(
        dir.path().join("bounds.csv"),
        "name,lower,upper,nominal\nthickness,0.0016,0.0024,0.002\n",
    )
    .unwrap();
    let text = format!(
        "[model]\ndeck = {deck_path:?}\n\n[parameters]\nthickness = \"section.1.t\"\n\n\
         [space]\nbounds = \"bounds.csv\"\n\n[test]\ndata = \"test.csv\"\n\n\
         [holdout]\ndata = \"holdout.csv\"\nset = {{ \"velocity.1.z\" = -4.5 }}\n\n\
         [loop]\njitter_runs = 4\nreconcile_runs = 12\nrecalibrate_runs = 16\nseed = 1\n"
    );
    let outs = [dir.path().join("local"), dir.path().join("processes")];
    for (out, executor) in outs
        .iter()
        .zip(["", "\n[executor]\nkind = \"processes\"\njobs = 2\n"])
    {
        let config = dir.path().join("loop.toml");
        std::fs::write(&config, format!("{text}{executor}")).unwrap();
        let o = close_loop(&config, out);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    assert_eq!(loop_json(&outs[0]), loop_json(&outs[1]));
    // The attribution's runs named the thickness and every candidate of the deck.
    let params = std::fs::read_to_string(outs[1].join("runs/r0-candidates/0/params.json")).unwrap();
    let record: serde_json::Value = serde_json::from_str(&params).unwrap();
    let names = record["names"].as_array().unwrap();
    assert_eq!(names[0], "thickness");
    assert!(names.len() > 5, "{names:?}");
    assert!(outs[1].join("runs/r0-candidates/0/stdout.txt").is_file());
}
