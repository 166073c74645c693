//! End-to-end tests of `impactcal batch`: the built-in solver run in process and as a pool
//! of processes, failures named per run, and a driver killed mid-batch then resumed.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

mod common;
use common::{example_file, impactcal};

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// Writes a copy of `examples/batch/batch.toml` with the `[executor]` (and optionally the
/// solver command) replaced, next to a copy of the template, and returns its path.
fn config(dir: &Path, executor: &str, command: Option<&str>) -> PathBuf {
    std::fs::copy(example_file("batch", "strip.k"), dir.join("strip.k")).unwrap();
    let base = std::fs::read_to_string(example_file("batch", "batch.toml")).unwrap();
    let mut text = base[..base.find("[executor]").unwrap()].to_string();
    if let Some(c) = command {
        text = text.replace("[solver]\n", &format!("[solver]\ncommand = {c}\n"));
    }
    text += executor;
    let p = dir.join("batch.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn points(dir: &Path, text: &str) -> PathBuf {
    let p = dir.join("points.csv");
    std::fs::write(&p, text).unwrap();
    p
}

fn run(config: &Path, points: &Path, out: &Path) -> std::process::Output {
    impactcal(&[
        "batch",
        "--config",
        config.to_str().unwrap(),
        "--points",
        points.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ])
}

fn summary(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

fn result(out: &Path, index: usize) -> String {
    std::fs::read_to_string(out.join(format!("runs/strip/{index}/result.csv"))).unwrap()
}

const POINTS: &str = "t,vz\n0.002,-5\n0.0025,-4\n0.0015,-6\n0.0022,-4.5\n";

#[test]
fn processes_and_in_process_agree_and_failures_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let p = points(dir.path(), &format!("{POINTS}-0.001,-5\n"));
    let cfg = config(
        dir.path(),
        "[executor]\nkind = \"processes\"\njobs = 2\nretries = 1\n",
        None,
    );
    let out = dir.path().join("pool");
    let o = run(&cfg, &p, &out);
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(stderr.lines().count(), 2, "{stderr}");
    assert!(
        stderr.contains("run 4: the solver exited with status 2; see ")
            && stderr.contains("runs/strip/4/stderr.txt"),
        "{stderr}"
    );
    let s = summary(&out);
    assert_eq!(s["succeeded"], 4);
    assert_eq!(s["failed"], 1);
    // A solver failure is retried once (retries = 1), then reported.
    assert_eq!(s["results"][4]["attempts"], 2);
    let why = std::fs::read_to_string(out.join("runs/strip/4/stderr.txt")).unwrap();
    assert!(
        why.contains("thickness: must be finite and positive, got -0.001"),
        "{why}"
    );
    // The rendered deck holds the values in their fixed fields; params.json records them.
    let deck = std::fs::read_to_string(out.join("runs/strip/1/strip.k")).unwrap();
    assert!(
        deck.contains("    0.0025    0.0025    0.0025    0.0025\n"),
        "{deck}"
    );
    assert!(deck.contains("       2.0       0.0        -4\n"), "{deck}");
    let params: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("runs/strip/1/params.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(params["values"], serde_json::json!([0.0025, -4.0]));
    assert_eq!(params["exit_status"], 0);

    // The same points in process give the same histories, to the last bit.
    let cfg = config(dir.path(), "[executor]\nkind = \"local\"\n", None);
    let local = dir.path().join("local");
    let o = run(&cfg, &points(dir.path(), POINTS), &local);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for i in 0..4 {
        assert_eq!(result(&out, i), result(&local, i), "run {i}");
    }
    // Different points give different histories (the parameters reach the solver).
    assert_ne!(result(&local, 0), result(&local, 1));
    // Running again reuses every result.
    let o = run(&cfg, &points(dir.path(), POINTS), &local);
    assert!(o.status.success());
    assert_eq!(summary(&local)["reused"], 4);
    // Other points under the same study are refused, not mixed in.
    let o = run(&cfg, &points(dir.path(), "t,vz\n0.003,-5\n"), &local);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("belongs to a different batch"));
}

#[test]
fn bad_input_is_typed_and_named() {
    let dir = tempfile::tempdir().unwrap();
    let exec = "[executor]\nkind = \"processes\"\njobs = 2\n";
    // A name that is not an identifier never reaches a file or a command.
    let cfg = config(dir.path(), exec, None);
    let o = run(
        &cfg,
        &points(dir.path(), "t,vz,a;rm -rf\n0.002,-5,1\n"),
        &dir.path().join("o1"),
    );
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("must be plain identifiers") && e.contains("`a;rm -rf`"),
        "{e}"
    );
    assert!(!dir.path().join("o1/runs").exists());
    // The retries of earlier files' [batch] table name their new place, before any run.
    let old = dir.path().join("old.toml");
    let text = std::fs::read_to_string(&cfg).unwrap();
    std::fs::write(&old, text.replace("[batch]\n", "[batch]\nretries = 1\n")).unwrap();
    let o = run(&old, &points(dir.path(), POINTS), &dir.path().join("o0"));
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("line 4: [batch] retries: renamed: write [executor] retries"),
        "{e}"
    );
    assert!(!dir.path().join("o0").exists());
    // The template names a parameter the points lack, and the reverse.
    let o = run(
        &cfg,
        &points(dir.path(), "t\n0.002\n"),
        &dir.path().join("o2"),
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("placeholder `vz` names no parameter"));
    let o = run(
        &cfg,
        &points(dir.path(), "t,vz,m\n0.002,-5,1\n"),
        &dir.path().join("o3"),
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("`m` appears nowhere in the template"));
    // A solver that does not exist: every run names it; bad input.
    let cfg = config(
        dir.path(),
        exec,
        Some("[\"no-such-solver-17\", \"strip.k\"]"),
    );
    let o = run(&cfg, &points(dir.path(), POINTS), &dir.path().join("o4"));
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("cannot start the solver `no-such-solver-17`: not found"),
        "{e}"
    );
    // A run whose work directory cannot be created fails alone.
    let cfg = config(dir.path(), exec, None);
    let out = dir.path().join("o5");
    std::fs::create_dir_all(out.join("runs/strip")).unwrap();
    std::fs::write(out.join("runs/strip/2"), "in the way").unwrap();
    let o = run(&cfg, &points(dir.path(), POINTS), &out);
    assert_eq!(o.status.code(), Some(1));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("run 2: ") && e.contains("runs/strip/2"), "{e}");
    assert_eq!(summary(&out)["succeeded"], 3);
    // A solver that runs past the time limit is killed, retried, and reported.
    let cfg = config(
        dir.path(),
        "[executor]\nkind = \"processes\"\njobs = 2\ntimeout = 0.3\nretries = 1\n",
        Some("[\"sleep\", \"30\"]"),
    );
    let started = Instant::now();
    let o = run(
        &cfg,
        &points(dir.path(), "t,vz\n0.002,-5\n"),
        &dir.path().join("o6"),
    );
    assert!(started.elapsed() < Duration::from_secs(10));
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("ran longer than 0.3 s and was killed"));
    assert_eq!(summary(&dir.path().join("o6"))["results"][0]["attempts"], 2);
}

/// Lines of the journal that record a result.
fn results_in_journal(out: &Path) -> usize {
    std::fs::read_to_string(out.join("runs/strip/journal.jsonl"))
        .map(|t| {
            t.lines()
                .filter(|l| l.contains("\"event\":\"result\""))
                .count()
        })
        .unwrap_or(0)
}

#[test]
fn killed_driver_resumes_with_identical_results() {
    let dir = tempfile::tempdir().unwrap();
    let pts = "t,vz\n0.002,-5\n0.0025,-4\n0.0015,-6\n0.0022,-4.5\n0.0018,-5.5\n0.0021,-5.2\n";
    let p = points(dir.path(), pts);
    // Reference: uninterrupted, in process.
    let reference = dir.path().join("reference");
    let cfg = config(dir.path(), "[executor]\nkind = \"local\"\n", None);
    assert!(run(&cfg, &p, &reference).status.success());
    // A slow solver (a pause, then the built-in solver) on two processes.
    let exe = env!("CARGO_BIN_EXE_impactcal");
    let command = format!(
        "[\"sh\", \"-c\", \"sleep 0.4; exec \\\"$0\\\" simulate --deck strip.k --out out.csv\", \"{exe}\"]"
    );
    let cfg = config(
        dir.path(),
        "[executor]\nkind = \"processes\"\njobs = 2\n",
        Some(&command),
    );
    let out = dir.path().join("killed");
    for round in 0..2 {
        let mut child = Command::new(exe)
            .args(["batch", "--config", cfg.to_str().unwrap(), "--points"])
            .arg(&p)
            .arg("--out")
            .arg(&out)
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        // Kill (SIGKILL) once some results are in and others are running.
        let want = 2 * (round + 1);
        let deadline = Instant::now() + Duration::from_secs(60);
        while results_in_journal(&out) < want && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(20));
        }
        child.kill().unwrap();
        child.wait().unwrap();
        assert!(
            results_in_journal(&out) < 6,
            "round {round}: the batch finished before the kill"
        );
    }
    let o = run(&cfg, &p, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = summary(&out);
    assert!(s["reused"].as_u64().unwrap() >= 4, "{s}");
    for i in 0..6 {
        assert_eq!(result(&out, i), result(&reference, i), "run {i}");
    }
}
