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

/// A drop-tower loop file (hidden contact damping in the test, a holdout at 5 m/s) with
/// the `[executor]` table `executor`, written in `dir` with its data.
fn drop_tower_loop(dir: &Path, executor: &str) -> PathBuf {
    let truth = DropTower::new()
        .at_condition(&[("contact_damping".into(), 0.2)])
        .unwrap();
    for (file, v0, seed) in [("test.csv", None, 3), ("holdout.csv", Some(5.0), 4)] {
        let model = match v0 {
            Some(v) => truth.at_condition(&[("v0".into(), v)]).unwrap(),
            None => truth.clone(),
        };
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
        noisy.write_csv(dir.join(file)).unwrap();
    }
    let p = dir.join("loop.toml");
    std::fs::write(
        &p,
        format!(
            "[model]\nkind = \"drop-tower\"\n\n[test]\ndata = \"test.csv\"\n\n\
             [holdout]\ndata = \"holdout.csv\"\nset = {{ v0 = 5.0 }}\n\n\
             [budget]\nensemble = 6\nreconcile = 16\nrecalibrate = 16\nseed = 2\n\n{executor}"
        ),
    )
    .unwrap();
    p
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
