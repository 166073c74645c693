//! The messages a user gets for the mistakes a user makes: each a typed error (exit 2, one
//! line naming what, where and what to do) before any run where it can be known, or a
//! warning on stderr with a field in the JSON.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::path::Path;

use common::{example_file, impactcal};

/// Runs `args`, which must fail with exit 2 and one line on stderr holding every one of
/// `needles`; returns that line.
fn refused(args: &[&str], needles: &[&str]) -> String {
    let o = impactcal(args);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| l.contains("error:")).collect();
    assert_eq!(lines.len(), 1, "{err}");
    for n in needles {
        assert!(lines[0].contains(n), "`{n}` not in: {err}");
    }
    lines[0].to_string()
}

/// Copies the strip study (an external solver on a deck template, in process) into `dir`
/// with the test `test` (relative to `dir`) and returns its file.
fn strip_study(dir: &Path, test: &str) -> String {
    std::fs::create_dir_all(dir.join("study")).unwrap();
    std::fs::create_dir_all(dir.join("batch")).unwrap();
    for f in ["bounds.csv", "test.csv"] {
        std::fs::copy(example_file("study", f), dir.join("study").join(f)).unwrap();
    }
    std::fs::copy(example_file("batch", "strip.k"), dir.join("batch/strip.k")).unwrap();
    let text = std::fs::read_to_string(example_file("study", "local.toml"))
        .unwrap()
        .replace("data = \"test.csv\"", &format!("data = \"{test}\""));
    let p = dir.join("study/study.toml");
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

/// A test that ends before the model's window: said the right way round (the test's
/// record, then the model's window), with the key of this file that sets the window, and
/// before any run (the output folder is not even made).
#[test]
fn a_test_shorter_than_the_window_names_the_key_before_any_run() {
    let dir = tempfile::tempdir().unwrap();
    let test = std::fs::read_to_string(example_file("study", "test.csv")).unwrap();
    // The first 50 rows: 0 to 0.00096 s of the model's 0.002 s.
    let short: String = test.lines().take(51).map(|l| format!("{l}\n")).collect();
    std::fs::create_dir_all(dir.path().join("study")).unwrap();
    std::fs::write(dir.path().join("study/short.csv"), short).unwrap();
    let cfg = strip_study(dir.path(), "short.csv");
    let out = dir.path().join("out");
    refused(
        &["study", "--config", &cfg, "--out", out.to_str().unwrap()],
        &[
            "[test]",
            "the test record covers [0, 0.00098] s but the model's window is [0, 0.002] s",
            "`[solver.output] end_time` to at most 0.00098 s",
        ],
    );
    assert!(!out.exists());
}

/// The drop tower's window is known once it runs: the same message after its nominal run,
/// with the advice that fits a fixed window.
#[test]
fn a_loop_test_shorter_than_a_fixed_window_asks_for_a_longer_record() {
    let dir = tempfile::tempdir().unwrap();
    let test = std::fs::read_to_string(example_file("loop", "test.csv")).unwrap();
    let short: String = test.lines().take(30).map(|l| format!("{l}\n")).collect();
    std::fs::write(dir.path().join("test.csv"), short).unwrap();
    let cfg = dir.path().join("loop.toml");
    std::fs::write(
        &cfg,
        "[model]\nkind = \"drop-tower\"\n\n[test]\ndata = \"test.csv\"\n",
    )
    .unwrap();
    refused(
        &[
            "close-loop",
            "--config",
            cfg.to_str().unwrap(),
            "--out",
            dir.path().join("out").to_str().unwrap(),
        ],
        &[
            "the test record covers [0, 0.0028] s but the model's window is [0, 0.04] s",
            "give a record that reaches the model's end",
        ],
    );
}

/// A test that lacks one of the model's channels: the loop goes on with a warning on
/// stderr, and `loop.json` says which channel was not compared.
#[test]
fn a_test_lacking_a_model_channel_is_a_warning_and_a_json_field() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["test.csv", "holdout.csv"] {
        let text = std::fs::read_to_string(example_file("loop", name)).unwrap();
        assert!(text.starts_with("time,a1,a2,a3\n"));
        let cut: String = text
            .lines()
            .map(|l| format!("{}\n", l.rsplit_once(',').unwrap().0))
            .collect();
        std::fs::write(dir.path().join(name), cut).unwrap();
    }
    let cfg = dir.path().join("loop.toml");
    let text = std::fs::read_to_string(example_file("loop", "local.toml")).unwrap();
    std::fs::write(&cfg, text).unwrap();
    let out = dir.path().join("out");
    let o = common::impactcal_with(
        &[
            "close-loop",
            "--config",
            cfg.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        &[("IMPACTCAL_PROGRESS_SECONDS", "1e6")],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let warnings: Vec<&str> = err.lines().filter(|l| l.contains("warning:")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(
        warnings[0].contains("1 of the model's 3 channels are not in the test (`a3`)"),
        "{err}"
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("loop.json")).unwrap()).unwrap();
    assert_eq!(v["dropped"]["model"], serde_json::json!(["a3"]));
    assert_eq!(v["dropped"]["test"], serde_json::json!([]));
}

/// `metrics` on a test of 6 channels against a model that has 3 of them: exit 0, the
/// metrics of the 3, a warning naming the 3 left out, and the JSON saying so.
#[test]
fn metrics_on_part_of_the_channels_warns_and_says_so_in_the_json() {
    let dir = tempfile::tempdir().unwrap();
    let test = example_file("study", "test.csv");
    let text = std::fs::read_to_string(&test).unwrap();
    assert!(text.starts_with("time,21.x,21.y,21.z,42.x,42.y,42.z\n"));
    let half: String = text
        .lines()
        .map(|l| format!("{}\n", l.split(',').take(4).collect::<Vec<_>>().join(",")))
        .collect();
    let model = dir.path().join("model.csv");
    std::fs::write(&model, half).unwrap();
    let o = impactcal(&[
        "metrics",
        "--test",
        test.to_str().unwrap(),
        "--analysis",
        model.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains(
            "warning: compared 3 of the test's 6 channels: the test's `42.x`, `42.y`, `42.z` \
             have no model channel"
        ),
        "{err}"
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["channels"].as_array().unwrap().len(), 3);
    assert_eq!(
        v["dropped"]["test"],
        serde_json::json!(["42.x", "42.y", "42.z"])
    );
    assert_eq!(v["dropped"]["model"], serde_json::json!([]));
}

/// A run count no machine holds: refused before any run, naming the key, its value and the
/// bytes, instead of an abort on a failed allocation.
#[test]
fn a_run_count_no_machine_holds_is_refused_before_any_run() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["test.csv", "holdout.csv"] {
        std::fs::copy(example_file("loop", name), dir.path().join(name)).unwrap();
    }
    let text = std::fs::read_to_string(example_file("loop", "local.toml"))
        .unwrap()
        .replace("jitter_runs = 6 ", "jitter_runs = 100000000000 ");
    let cfg = dir.path().join("loop.toml");
    std::fs::write(&cfg, text).unwrap();
    let out = dir.path().join("out");
    refused(
        &[
            "close-loop",
            "--config",
            cfg.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        &[
            "[loop]",
            "loop.jitter_runs = 100000000000",
            "GB",
            "give loop.jitter_runs a number of runs the machine can hold",
        ],
    );
    assert!(!out.join("runs").exists());
    // The study's ensemble likewise.
    let cfg = strip_study(dir.path(), "test.csv");
    let text = std::fs::read_to_string(&cfg)
        .unwrap()
        .replace("halton_runs = 16", "halton_runs = 100000000000");
    std::fs::write(&cfg, text).unwrap();
    let out = dir.path().join("study-out");
    refused(
        &["study", "--config", &cfg, "--out", out.to_str().unwrap()],
        &["study.halton_runs = 100000000000"],
    );
    assert!(!out.join("runs").exists());
}

/// `--set` outside the catalogue's range: an error naming the range and the unit, before
/// the model is built.
#[test]
fn a_set_outside_the_range_names_the_range() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.csv");
    refused(
        &[
            "simulate",
            "--model",
            "airframe",
            "--set",
            "nose.t=1e9",
            "--out",
            out.to_str().unwrap(),
        ],
        &["`nose.t`", "1000000000", "range 0.048 to 0.072 in"],
    );
    assert!(!out.exists());
    let deck = dir.path().join("airframe.k");
    refused(
        &[
            "airframe",
            "--set",
            "nose.t=0.01",
            "--out",
            deck.to_str().unwrap(),
        ],
        &["`nose.t`", "range 0.048 to 0.072 in"],
    );
    assert!(!deck.exists());
}

/// `--out` naming a file: said so, with what `--out` takes.
#[test]
fn an_out_that_names_a_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("results.txt");
    std::fs::write(&file, "keep me").unwrap();
    let cfg = strip_study(dir.path(), "test.csv");
    refused(
        &["study", "--config", &cfg, "--out", file.to_str().unwrap()],
        &["is a file", "--out names a folder"],
    );
    refused(
        &["demo", "--out", file.join("sub").to_str().unwrap()],
        &["is a file"],
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "keep me");
}

/// The demo's options refused before its first run: more sensors than the airframe has
/// channels, and a candidate name with a typo (with the closest names).
#[test]
fn demo_options_are_refused_before_the_first_run() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("demo");
    refused(
        &["demo", "--sensors", "5000", "--out", out.to_str().unwrap()],
        &["--sensors 5000", "1215 sensor channels", "at most 1215"],
    );
    assert!(!out.join("test.csv").exists() && !out.join("table1").exists());
    let out = dir.path().join("loop");
    refused(
        &[
            "demo",
            "--close-loop",
            "--candidates",
            "dampng",
            "--out",
            out.to_str().unwrap(),
        ],
        &["candidate `dampng`", "closest", "`damping`"],
    );
    assert!(!out.join("test.csv").exists());
}
