//! `impactcal study` end to end: a keyword deck studied and killed mid-ensemble (the resumed
//! study equals an uninterrupted one), the coarse airframe with a small budget, and every
//! bad input a user would produce (exit 2, one line, nothing overwritten).

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{example_file, impactcal, impactcal_with, progress_lines};

/// Writes a study file and the strip deck's nominal histories (the test) into `dir`.
fn strip_study(dir: &Path, study: &str) -> PathBuf {
    let deck = example_file("decks", "strip_drop.k");
    let test = dir.join("test.csv");
    if !test.exists() {
        let out = impactcal(&[
            "simulate",
            "--deck",
            deck.to_str().unwrap(),
            "--out",
            test.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let config = dir.join("study.toml");
    std::fs::write(
        &config,
        format!(
            "[model]\ndeck = {deck:?}\n\n[parameters]\nthickness = \"section.1.t\"\n\
             yield = \"material.1.sigy\"\n\n[test]\ndata = \"test.csv\"\n\n[study]\n{study}\n"
        ),
    )
    .unwrap();
    config
}

fn study(config: &Path, out: &Path) -> std::process::Output {
    study_with(config, out, &[])
}

/// `impactcal study` with `extra` arguments.
fn study_with(config: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "study",
        "--config",
        config.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    // No periodic progress lines: the lines are counted.
    impactcal_with(&args, &[("IMPACTCAL_PROGRESS_SECONDS", "1e6")])
}

/// The results a runner journal records (complete lines only).
fn results_in(journal: &Path) -> usize {
    std::fs::read_to_string(journal).map_or(0, |t| {
        t.lines()
            .filter(|l| l.starts_with("{\"event\":\"result\""))
            .count()
    })
}

/// A study of four runs without reconciliation.
const SMALL: &str = "halton_runs = 4\nsensors = 2\nshapes = 1\nreconcile_runs = 0\njitter_runs = 2";

const STRIP: &str = "halton_runs = 160\nsensors = 3\nshapes = 2\nsensitivity_samples = 64\n\
                     reconcile_runs = 6\njitter_runs = 3";

#[test]
fn a_killed_study_resumes_to_the_uninterrupted_result() {
    let dir = tempfile::tempdir().unwrap();
    let config = strip_study(dir.path(), STRIP);
    let whole = dir.path().join("whole");
    let out = study(&config, &whole);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    // Progress off a terminal: the plan (1 nominal + 3 jitter + 160 ensemble + 6
    // reconciliation runs), a line per stage of runs in words, a line per step, a last line.
    let lines = progress_lines(&err);
    let stages: Vec<&str> = lines
        .iter()
        .filter(|(_, _, t)| t.ends_with(" runs"))
        .map(|(_, _, t)| t.as_str())
        .collect();
    assert_eq!(
        stages,
        [
            "nominal run: 0/1 runs",
            "jitter ensemble (the model's own noise): 0/3 runs",
            "ensemble over the parameter space: 0/160 runs",
            "reconciliation, CORS-RBF search: 0/6 runs",
        ],
        "{err}"
    );
    let steps: Vec<&str> = lines.iter().map(|(_, _, t)| t.as_str()).collect();
    for step in [
        "M1",
        "sensor placement",
        "M2",
        "surrogates",
        "sensitivity",
        "before and after",
    ] {
        assert_eq!(
            steps.iter().filter(|t| **t == step).count(),
            1,
            "{step}: {err}"
        );
    }
    assert!(
        lines
            .iter()
            .all(|(done, planned, _)| done <= planned && *planned == 170),
        "{err}"
    );
    let last = lines.last().unwrap();
    assert_eq!((last.0, last.1), (170, 170), "{err}");
    assert!(last.2.starts_with("in "), "{err}");
    // The memory plan's line and the notes are steps too.
    assert!(
        steps[1].starts_with("memory: the study plans about"),
        "{err}"
    );
    let notes = steps.iter().filter(|t| t.starts_with("note: ")).count();
    assert_eq!(lines.len(), stages.len() + 7 + notes + 1, "{err}");

    let killed = dir.path().join("killed");
    let done = kill_study_after(
        &config,
        &killed,
        &killed.join("runs/ensemble/journal.jsonl"),
        10,
    );
    assert!(
        (10..160).contains(&done),
        "killed after {done} of 160 ensemble runs"
    );
    assert!(!killed.join("study.json").exists());

    let out = study(&config, &killed);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let a = std::fs::read_to_string(whole.join("study.json")).unwrap();
    let b = std::fs::read_to_string(killed.join("study.json")).unwrap();
    assert_eq!(a, b);
    let r: serde_json::Value = serde_json::from_str(&a).unwrap();
    for key in [
        "n_runs",
        "exceedance_fraction",
        "intervals",
        "verdict",
        "probability_bound",
    ] {
        assert!(r["m1"].get(key).is_some(), "m1.{key}");
    }
    assert_eq!(r["m1"]["n_runs"], 160);
    assert_eq!(r["sensors"]["selected"].as_array().unwrap().len(), 3);
    assert_eq!(r["reconcile"]["runs"], 6);
    assert!(r["reconcile"]["calibrated"]["thickness"].is_f64());
    assert!(r["sensitivity"]["first_order"]["yield"].is_array());
    for side in ["baseline", "calibrated"] {
        assert!(r["m2"][side]["matched_above_0_9"].is_u64());
        for key in ["rel_l2", "iso18571_r", "sprague_geers_c"] {
            assert!(r["errors"][side].get(key).is_some(), "errors.{side}.{key}");
        }
    }
    assert!(r["surrogate"]["loo_rel_error"].is_f64());
}

#[test]
fn the_coarse_airframe_end_to_end_with_a_small_budget() {
    let dir = tempfile::tempdir().unwrap();
    let test = dir.path().join("test.csv");
    let out = impactcal(&[
        "simulate",
        "--model",
        "airframe",
        "--end-time",
        "0.01",
        "--set",
        "belly_panel.t=0.108",
        "--out",
        test.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let config = dir.path().join("study.toml");
    std::fs::write(
        &config,
        "[model]\nairframe = \"coarse\"\nend_time = 0.01\n\n[space]\npreset = \"table2\"\n\n\
         [test]\ndata = \"test.csv\"\ncfc = 60\n\n[study]\nhalton_runs = 8\nsensors = 8\nshapes = 3\n\
         sensitivity_samples = 32\nreconcile_runs = 2\njitter_runs = 2\n",
    )
    .unwrap();
    let out = study(&config, &dir.path().join("out"));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("out/study.json")).unwrap()).unwrap();
    assert_eq!(r["channels"]["model"], 1215);
    assert_eq!(r["m1"]["n_runs"], 8);
    assert_eq!(r["reconcile"]["runs"], 2);
    let before = r["errors"]["baseline"]["prediction_error"]
        .as_f64()
        .unwrap();
    let after = r["errors"]["calibrated"]["prediction_error"]
        .as_f64()
        .unwrap();
    assert!(after <= before, "{after} > {before}");
    assert_eq!(r["sensitivity"]["ranking"].as_array().unwrap().len(), 6);
    // The report: one self-contained HTML file with every figure inline, and Markdown
    // linking one SVG file per figure.
    let out = dir.path().join("out");
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let markdown = std::fs::read_to_string(out.join("report.md")).unwrap();
    let svgs: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".svg"))
        .collect();
    assert!(svgs.len() >= 6, "{svgs:?}");
    assert_eq!(html.matches("<svg").count(), svgs.len());
    for svg in &svgs {
        assert!(markdown.contains(svg.as_str()), "{svg} not linked");
    }
    assert!(!html.contains("<script"));
}

/// Runs `impactcal study` expecting bad input: exit 2, one line on stderr containing `what`.
fn refused(config: &Path, out: &Path, what: &str) {
    let o = study(config, out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    let last = err.lines().last().unwrap_or_default();
    assert!(
        last.starts_with("impactcal: error:") && last.contains(what),
        "{err}"
    );
}

#[test]
fn bad_input_exits_with_code_two_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let config = strip_study(d, SMALL);
    let text = std::fs::read_to_string(&config).unwrap();
    let variant = |name: &str, from: &str, to: &str| -> PathBuf {
        let p = d.join(name);
        assert!(text.contains(from));
        std::fs::write(&p, text.replacen(from, to, 1)).unwrap();
        p
    };
    // An unknown model quantity: the near names are listed.
    let c = variant("typo.toml", "\"section.1.t\"", "\"section.1.tt\"");
    refused(&c, &d.join("o1"), "closest: `section.1.t`");
    // Bounds outside what the model accepts (the deck's +-20 %).
    std::fs::write(
        d.join("bounds.csv"),
        "name,lower,upper,nominal\nsection.1.t,0.001,0.003,0.002\n",
    )
    .unwrap();
    let c = variant(
        "bounds.toml",
        "[test]",
        "[space]\nbounds = \"bounds.csv\"\n\n[test]",
    );
    refused(&c, &d.join("o2"), "outside what the model accepts");
    // A test with no channel in common with the model.
    std::fs::write(d.join("other.csv"), "time,9.q\n0,1\n0.001,2\n0.002,3\n").unwrap();
    let c = variant("other.toml", "\"test.csv\"", "\"other.csv\"");
    refused(&c, &d.join("o3"), "no channel in common");
    // A budget of 0.
    let c = variant("zero.toml", "halton_runs = 4", "halton_runs = 0");
    refused(&c, &d.join("o4"), "study.halton_runs");
    // More sensors than channels (6).
    let c = variant("many.toml", "sensors = 2", "sensors = 7");
    refused(&c, &d.join("o5"), "7 sensors");
    // A malformed study file names its line.
    let c = variant("syntax.toml", "halton_runs = 4", "halton_runs = four");
    refused(&c, &d.join("o6"), "line");
    // A folder holding another study's journal: nothing is overwritten.
    let out = d.join("o7");
    assert!(study(&config, &out).status.success());
    let before = std::fs::read(out.join("study.json")).unwrap();
    let c = variant("seed.toml", "halton_runs = 4", "halton_runs = 4\nseed = 9");
    refused(&c, &out, "another study");
    assert_eq!(std::fs::read(out.join("study.json")).unwrap(), before);
}

/// `--max-memory` below what the process already holds: refused before any run, with the
/// guard's line (stage, estimate, what to change); a size that does not parse is refused
/// before anything runs.
#[test]
fn a_memory_limit_below_the_plan_stops_the_study_before_its_stages() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let config = strip_study(d, SMALL);
    let out = d.join("small");
    let args = |limit: &str| study_with(&config, &out, &["--max-memory", limit]);
    let o = args("1M");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    let last = err.lines().last().unwrap_or_default();
    assert!(
        last.starts_with("impactcal: error:")
            && last.contains("needs about")
            && last.contains("max_memory"),
        "{err}"
    );
    // A limit below what the process already holds is known before any run.
    assert!(!out.join("runs/nominal").exists());
    let o = args("lots");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("not a size"), "{err}");
    // With room, the same study runs in the same folder.
    let o = args("4G");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Spawns `impactcal study`, SIGKILLs it once `journal` records `after` results, and
/// returns how many it had recorded by then.
fn kill_study_after(config: &Path, out: &Path, journal: &Path, after: usize) -> usize {
    let mut child = Command::new(env!("CARGO_BIN_EXE_impactcal"))
        .args([
            "study",
            "--config",
            config.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while results_in(journal) < after && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    results_in(journal)
}

#[test]
fn a_study_on_the_process_pool_killed_and_resumed_is_identical() {
    // Our own `impactcal simulate --deck` as an external solver, two processes at a time.
    let config = example_file("study", "processes.toml");
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole");
    let out = study(&config, &whole);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let killed = dir.path().join("killed");
    let journal = killed.join("runs/ensemble/journal.jsonl");
    let done = kill_study_after(&config, &killed, &journal, 8);
    assert!((8..40).contains(&done), "killed after {done} of 40 runs");
    assert!(!killed.join("study.json").exists());
    // Every result the journal holds was recorded as submitted before it.
    let text = std::fs::read_to_string(&journal).unwrap();
    let mut submitted = std::collections::BTreeSet::new();
    for line in text.lines() {
        let e: serde_json::Value = serde_json::from_str(line).unwrap();
        let index = e["index"].as_u64();
        match e["event"].as_str().unwrap() {
            "submit" => {
                submitted.insert(index.unwrap());
            }
            "result" => assert!(submitted.contains(&index.unwrap()), "{line}"),
            _ => {}
        }
    }

    let out = study(&config, &killed);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains(&format!(
            "ensemble over the parameter space: 0/40 runs ({done} from the journal)"
        )),
        "{stderr}"
    );
    let a = std::fs::read_to_string(whole.join("study.json")).unwrap();
    let b = std::fs::read_to_string(killed.join("study.json")).unwrap();
    assert_eq!(a, b);
    let r: serde_json::Value = serde_json::from_str(&a).unwrap();
    assert_eq!(r["m1"]["n_runs"], 40);
    assert_eq!(r["reconcile"]["runs"], 4);
    // Each run kept its files: the rendered deck, the solver's exit status, the result.
    let run = killed.join("runs/ensemble/0");
    for f in [
        "strip.k",
        "exit_status",
        "stdout.txt",
        "params.json",
        "result.csv",
    ] {
        assert!(run.join(f).is_file(), "{f}");
    }
}

#[test]
fn a_built_in_model_on_the_process_pool_equals_the_in_process_study() {
    // `impactcal study-point` runs the deck model in each run's directory.
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(example_file("study", "deck-processes.toml")).unwrap();
    let deck = example_file("decks", "strip_drop.k");
    let test = example_file("study", "test.csv");
    let text = text
        .replace("\"../decks/strip_drop.k\"", &format!("{deck:?}"))
        .replace("\"test.csv\"", &format!("{test:?}"));
    let processes = dir.path().join("processes.toml");
    std::fs::write(&processes, &text).unwrap();
    let local = dir.path().join("local.toml");
    std::fs::write(
        &local,
        text.replace("kind = \"processes\"", "kind = \"local\""),
    )
    .unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    for (config, out) in [(&processes, &a), (&local, &b)] {
        let o = study(config, out);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    assert_eq!(
        std::fs::read_to_string(a.join("study.json")).unwrap(),
        std::fs::read_to_string(b.join("study.json")).unwrap()
    );
    // The process pool ran a process per point (its standard output kept), the local
    // executor none.
    assert!(a.join("runs/ensemble/3/stdout.txt").is_file());
    assert!(!b.join("runs/ensemble/3/stdout.txt").exists());
    // A worker given a point of another space says so.
    let run = a.join("runs/ensemble/3");
    let params = std::fs::read_to_string(run.join("params.json"))
        .unwrap()
        .replace("\"thickness\"", "\"thick\"");
    std::fs::write(dir.path().join("params.json"), params).unwrap();
    let o = impactcal(&[
        "study-point",
        "--config",
        processes.to_str().unwrap(),
        "--params",
        dir.path().join("params.json").to_str().unwrap(),
        "--out",
        dir.path().join("o.csv").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("thick") && e.contains("must start with the model's own parameters"),
        "{e}"
    );
}
