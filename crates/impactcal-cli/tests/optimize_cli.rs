//! End-to-end tests of `impactcal optimize suggest`: a shell-style loop of suggest, run,
//! append reproduces the library's closed loop, batches, failures and bad input.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;
use common::impactcal;

use std::io::Write;
use std::path::Path;

use impactcal::core::points::to_rows;
use impactcal::core::{Table, TableOptions, test_functions};
use impactcal::cors::{
    AdaptiveRegion, CandidateDecay, Converged, Cors, CorsOptions, Perturbation, RepeatRefinement,
    Restart,
};

/// Runs `impactcal optimize suggest` on the files with extra arguments.
fn run_suggest(bounds: &Path, history: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "optimize",
        "suggest",
        "--bounds",
        bounds.to_str().unwrap(),
        "--history",
        history.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    impactcal(&args)
}

fn suggest(bounds: &Path, history: &Path, extra: &[&str]) -> Vec<Vec<f64>> {
    let out = run_suggest(bounds, history, extra);
    assert!(
        out.status.success(),
        "failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let t = Table::parse(&text, "stdout", TableOptions::default()).unwrap();
    assert_eq!(t.header(), &["x1", "x2"]);
    t.rows().to_vec()
}

fn append(history: &Path, x: &[f64], value: f64) {
    let new = !history.exists();
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(history)
        .unwrap();
    if new {
        writeln!(f, "x1,x2,objective").unwrap();
    }
    let v = if value.is_nan() {
        String::new()
    } else {
        value.to_string()
    };
    writeln!(f, "{},{},{v}", x[0], x[1]).unwrap();
}

fn branin_bounds(dir: &Path) -> std::path::PathBuf {
    let p = dir.join("bounds.csv");
    std::fs::write(&p, "name,lower,upper,nominal\nx1,-5,10,2.5\nx2,0,15,7.5\n").unwrap();
    p
}

#[test]
fn shell_loop_reproduces_the_library_loop() {
    let f = test_functions::by_name("branin").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let bounds = branin_bounds(dir.path());
    let history = dir.path().join("history.csv");
    let n = 20;
    let mut cli_points = Vec::new();
    for _ in 0..n {
        let x = suggest(&bounds, &history, &["--seed", "7"]).pop().unwrap();
        append(&history, &x, f.eval(&x));
        cli_points.push(x);
    }
    let mut study = Cors::new(f.space().unwrap(), CorsOptions::with_seed(7)).unwrap();
    study.minimize(|x| f.eval(x), n).unwrap();
    let lib_points: Vec<Vec<f64>> = study.evaluations().iter().map(|e| e.x.clone()).collect();
    // Bit for bit: the history round-trips through shortest float formatting.
    assert_eq!(cli_points, lib_points);
}

/// The search options of the command (local half-width, global-only, restart) give the
/// same points as the library with the same options.
#[test]
fn search_options_reproduce_the_library_loop() {
    let f = test_functions::by_name("branin").unwrap();
    let cases: [(&[&str], CorsOptions); 17] = [
        (
            &["--local-half-width", "0.15"],
            CorsOptions {
                local_region: Some(0.15),
                ..CorsOptions::with_seed(3)
            },
        ),
        (
            &["--global-only"],
            CorsOptions {
                local_region: None,
                ..CorsOptions::with_seed(3)
            },
        ),
        (
            &["--restart-patience", "4"],
            CorsOptions {
                restart: Some(Restart {
                    patience: Some(4),
                    ..Restart::default()
                }),
                ..CorsOptions::with_seed(3)
            },
        ),
        (
            &["--local-first"],
            CorsOptions {
                local_first: true,
                ..CorsOptions::with_seed(3)
            },
        ),
        (
            &["--local-escape", "4"],
            CorsOptions {
                local_escape: Some(4),
                ..CorsOptions::with_seed(3)
            },
        ),
        (
            &["--no-local-escape"],
            CorsOptions {
                local_escape: None,
                ..CorsOptions::with_seed(3)
            },
        ),
        (
            // With the local cycle first, pattern cycle 1 (steps 6..11 after the design of
            // 6 points) is the second region's first.
            &["--second-region", "0.4", "--local-first"],
            CorsOptions {
                second_region: Some(0.4),
                local_first: true,
                ..CorsOptions::with_seed(3)
            },
        ),
        (
            &["--no-second-region"],
            CorsOptions {
                second_region: None,
                ..CorsOptions::with_seed(3)
            },
        ),
        (
            &["--no-perturbation"],
            CorsOptions {
                perturbation: None,
                ..CorsOptions::with_seed(3)
            },
        ),
        (
            &["--perturb-horizon", "20"],
            CorsOptions {
                perturbation: Some(Perturbation { horizon: Some(20) }),
                ..CorsOptions::with_seed(3)
            },
        ),
        (
            &["--budget", "12"],
            CorsOptions {
                budget: Some(12),
                ..CorsOptions::with_seed(3)
            },
        ),
        (
            &["--no-repeat-refinement"],
            CorsOptions {
                repeat_refinement: None,
                ..CorsOptions::with_seed(3)
            },
        ),
        (
            &["--repeat-refinement", "2"],
            CorsOptions {
                repeat_refinement: Some(RepeatRefinement {
                    max_repeats: 2,
                    ..RepeatRefinement::default()
                }),
                ..CorsOptions::with_seed(3)
            },
        ),
        (
            &["--candidate-floor", "50", "--candidate-horizon", "20"],
            CorsOptions {
                candidate_decay: Some(CandidateDecay {
                    min_per_dim: 50,
                    horizon: 20,
                }),
                ..CorsOptions::with_seed(3)
            },
        ),
        (
            &["--merit-weights", "0.3,0.5,0.8,0.95"],
            CorsOptions {
                merit_weights: Some(vec![0.3, 0.5, 0.8, 0.95]),
                ..CorsOptions::with_seed(3)
            },
        ),
        (
            &[
                "--adaptive-region",
                "escape",
                "--adaptive-shrink-after",
                "2",
                "--adaptive-halvings",
                "2",
            ],
            CorsOptions {
                adaptive_region: Some(AdaptiveRegion {
                    shrink_after: Some(2),
                    halvings: 2,
                    on_converged: Converged::Escape,
                    ..AdaptiveRegion::default()
                }),
                ..CorsOptions::with_seed(3)
            },
        ),
        (
            &[
                "--adaptive-region",
                "restart-outside",
                "--adaptive-shrink-after",
                "2",
                "--adaptive-halvings",
                "1",
                "--adaptive-sigma-only",
            ],
            CorsOptions {
                adaptive_region: Some(AdaptiveRegion {
                    shrink_after: Some(2),
                    halvings: 1,
                    on_converged: Converged::RestartOutside,
                    shrink_box: false,
                    ..AdaptiveRegion::default()
                }),
                ..CorsOptions::with_seed(3)
            },
        ),
    ];
    for (flags, options) in cases {
        let dir = tempfile::tempdir().unwrap();
        let bounds = branin_bounds(dir.path());
        let history = dir.path().join("history.csv");
        let n = 24;
        let mut extra = vec!["--seed", "3"];
        extra.extend_from_slice(flags);
        let mut cli_points = Vec::new();
        for _ in 0..n {
            let x = suggest(&bounds, &history, &extra).pop().unwrap();
            append(&history, &x, f.eval(&x));
            cli_points.push(x);
        }
        let mut study = Cors::new(f.space().unwrap(), options).unwrap();
        study.minimize(|x| f.eval(x), n).unwrap();
        let lib: Vec<Vec<f64>> = study.evaluations().iter().map(|e| e.x.clone()).collect();
        assert_eq!(cli_points, lib, "{flags:?}");
    }
    // The flags change the search (else the test above could not fail).
    let run = |flags: &[&str]| {
        let dir = tempfile::tempdir().unwrap();
        let bounds = branin_bounds(dir.path());
        let history = dir.path().join("history.csv");
        let mut extra = vec!["--seed", "3"];
        extra.extend_from_slice(flags);
        let mut points = Vec::new();
        for _ in 0..24 {
            let x = suggest(&bounds, &history, &extra).pop().unwrap();
            append(&history, &x, f.eval(&x));
            points.push(x);
        }
        points
    };
    assert_ne!(run(&[]), run(&["--global-only"]));
    // `--budget` leaves Branin's first 24 points as they are (its walk takes no Gaussian
    // candidate of the local cycles, the only ones the schedule acts on); that it reaches
    // the options is shown by `--budget 0` being refused as `budget`
    // (`bad_search_options_are_input_errors`), and that the budget changes a walk by the
    // library's `budget_sets_the_perturbation_horizon` (Hartmann-6).
}

#[test]
fn batch_failures_and_empty_history() {
    let f = test_functions::by_name("branin").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let bounds = branin_bounds(dir.path());
    let history = dir.path().join("history.csv");
    // No history yet: the first three design points.
    let first = suggest(&bounds, &history, &["--batch", "3"]);
    assert_eq!(first.len(), 3);
    let design = to_rows(
        Cors::new(f.space().unwrap(), CorsOptions::with_seed(0))
            .unwrap()
            .design_points()
            .unwrap()
            .as_ref(),
    );
    assert_eq!(first, design[..3].to_vec());
    // Run the whole design, one run failing; then a batch of four CORS points.
    for (k, x) in design.iter().enumerate() {
        append(&history, x, if k == 2 { f64::NAN } else { f.eval(x) });
    }
    let batch = suggest(&bounds, &history, &["--batch", "4"]);
    assert_eq!(batch.len(), 4);
    for (i, a) in batch.iter().enumerate() {
        assert!(a[0] >= -5.0 && a[0] <= 10.0 && a[1] >= 0.0 && a[1] <= 15.0);
        for b in batch.iter().skip(i + 1).chain(design.iter()) {
            assert!(
                (a[0] - b[0]).abs() + (a[1] - b[1]).abs() > 1e-6,
                "{a:?} repeats {b:?}"
            );
        }
    }
}

/// Only a history file that does not exist (in a directory that does) starts a new study;
/// any other history that cannot be read is reported, never taken for "no evaluation yet".
#[test]
fn only_a_missing_history_starts_a_new_study() {
    let dir = tempfile::tempdir().unwrap();
    let bounds = branin_bounds(dir.path());
    // Missing file in an existing directory: the first design point.
    let fresh = suggest(&bounds, &dir.path().join("new.csv"), &[]);
    assert_eq!(fresh.len(), 1);
    // A header without rows is a history without evaluations: the same point.
    let header = dir.path().join("header.csv");
    std::fs::write(&header, "x1,x2,objective\n").unwrap();
    assert_eq!(suggest(&bounds, &header, &[]), fresh);
    // A mistyped directory (the history could never be appended to) and a directory where
    // the file should be: I/O errors naming the path.
    for path in [
        dir.path().join("no_such_dir").join("history.csv"),
        dir.path().to_path_buf(),
    ] {
        let out = run_suggest(&bounds, &path, &[]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{}: {err}", path.display());
        assert!(out.stdout.is_empty(), "{}", path.display());
        assert!(err.contains(&path.display().to_string()), "{err}");
    }
    // An empty file is not a history: reported, not a new study.
    let empty = dir.path().join("empty.csv");
    std::fs::write(&empty, "").unwrap();
    let out = run_suggest(&bounds, &empty, &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("empty.csv"));
    // Extra columns are named, like missing ones.
    let extra = dir.path().join("extra.csv");
    std::fs::write(&extra, "x1,x2,objective,comment\n1,2,3,4\n").unwrap();
    let out = run_suggest(&bounds, &extra, &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("unexpected column `comment`"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn bad_history_is_an_input_error() {
    let dir = tempfile::tempdir().unwrap();
    let bounds = branin_bounds(dir.path());
    let history = dir.path().join("history.csv");
    std::fs::write(&history, "x1,objective\n1,2\n").unwrap();
    let out = impactcal(&[
        "optimize",
        "suggest",
        "--bounds",
        bounds.to_str().unwrap(),
        "--history",
        history.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no column `x2`"), "{err}");
    std::fs::write(&history, "x1,x2,objective\n100,2,1\n").unwrap();
    let out = impactcal(&[
        "optimize",
        "suggest",
        "--bounds",
        bounds.to_str().unwrap(),
        "--history",
        history.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("row 2, column 1: parameter `x1` = 100 lies outside"),
        "{err}"
    );
}

#[test]
fn bad_search_options_are_input_errors() {
    let dir = tempfile::tempdir().unwrap();
    let bounds = branin_bounds(dir.path());
    let history = dir.path().join("history.csv");
    for (flags, expected) in [
        (&["--local-half-width", "0"][..], "local_region"),
        (&["--restart-patience", "0"][..], "patience"),
        (&["--perturb-horizon", "1"][..], "perturbation.horizon"),
        (&["--budget", "0"][..], "budget"),
        (&["--local-escape", "0"][..], "local_escape"),
        (&["--second-region", "0"][..], "second_region"),
        (
            &["--candidate-floor", "0"][..],
            "candidate_decay.min_per_dim",
        ),
        (&["--merit-weights", "0.5,2"][..], "merit_weights"),
        (
            &["--adaptive-region", "restore", "--adaptive-halvings", "0"][..],
            "adaptive_region.halvings",
        ),
        (&["--adaptive-halvings", "3"][..], "--adaptive-region"),
        (
            &["--local-half-width", "0.2", "--global-only"][..],
            "cannot be used",
        ),
    ] {
        let out = run_suggest(&bounds, &history, flags);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flags:?}: {err}");
        assert!(err.contains(expected), "{flags:?}: {err}");
    }
}

/// `optimize answer` on the history of a noisy Branin loop gives the library's best sample
/// and smoothed-surrogate answer; a history too short for the surrogate is an input error.
#[test]
fn answer_reports_best_sample_and_surrogate_answer() {
    let f = test_functions::by_name("branin").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let bounds = branin_bounds(dir.path());
    let history = dir.path().join("history.csv");
    let mut study = Cors::new(f.space().unwrap(), CorsOptions::with_seed(3)).unwrap();
    // Deterministic "noise" of a few units (1 % of Branin's range over the box is 3).
    let mut k = 0.0_f64;
    study
        .minimize(
            |x| {
                k += 1.0;
                f.eval(x) + 3.0 * (k * 2.399).sin()
            },
            40,
        )
        .unwrap();
    for e in study.evaluations() {
        append(&history, &e.x, e.value.unwrap());
    }
    let answer = |path: &Path| {
        impactcal(&[
            "optimize",
            "answer",
            "--bounds",
            bounds.to_str().unwrap(),
            "--history",
            path.to_str().unwrap(),
        ])
    };
    let out = answer(&history);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let best = study.best().unwrap();
    let lib = study.surrogate_answer().unwrap().unwrap();
    assert_eq!(doc["best_sample"]["objective"], best.value.unwrap());
    assert_eq!(doc["best_sample"]["parameters"]["x1"], best.x[0]);
    assert_eq!(doc["surrogate"]["row"], lib.index + 1);
    assert_eq!(doc["surrogate"]["parameters"]["x2"], lib.x[1]);
    assert_eq!(doc["surrogate"]["predicted"], lib.predicted);
    assert_eq!(doc["surrogate"]["smoothing"], lib.smoothing);
    assert!(lib.smoothing > 0.0);

    let short = dir.path().join("short.csv");
    std::fs::write(&short, "x1,x2,objective\n1,2,3\n4,5,6\n").unwrap();
    let out = answer(&short);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("too few for the smoothed surrogate"), "{err}");
}
