//! `impactcal close-loop` end to end on the drop tower: a test with hidden damping, a
//! trigger offset and one wrong gain, and a holdout at another impact speed (loop.json,
//! report.html, report.md); and the bad inputs a user would produce (exit 2, one line).

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::path::Path;

use common::{impactcal, impactcal_with, progress_lines};
use impactcal::core::drop_tower::DropTower;
use impactcal::core::synthetic::{Measurement, measured};
use impactcal::core::{Enrichable, Model};

/// Writes `test.csv` and `holdout.csv` measured on the drop tower with hidden damping.
fn write_tests(dir: &Path) {
    let truth = DropTower::new()
        .at_condition(&[("damping".into(), 0.03)])
        .unwrap();
    for (name, model, seed) in [
        ("test.csv", truth.clone(), 1),
        (
            "holdout.csv",
            truth.at_condition(&[("v0".into(), 5.5)]).unwrap(),
            2,
        ),
    ] {
        let y = model.simulate(&[75.0, 9e5]).unwrap();
        let m = Measurement {
            time_shift: 3e-4,
            gains: vec![("a2".into(), 1.1)],
            snr_db: Some(40.0),
            seed,
            ..Measurement::default()
        };
        measured(&y, &m).unwrap().write_csv(dir.join(name)).unwrap();
    }
}

fn config(dir: &Path, text: &str) -> String {
    let p = dir.join("loop.toml");
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

/// Runs `impactcal close-loop` on the loop file `cfg` into `out`, which must succeed, and
/// returns its `loop.json` and what it printed on stderr.
fn close_loop(cfg: &str, out: &Path) -> (serde_json::Value, String) {
    let out = out.to_str().unwrap();
    // No periodic progress lines: the lines are counted.
    let o = impactcal_with(
        &["close-loop", "--config", cfg, "--out", out],
        &[("IMPACTCAL_PROGRESS_SECONDS", "1e6")],
    );
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success(), "{err}");
    let text = std::fs::read_to_string(Path::new(out).join("loop.json")).unwrap();
    (serde_json::from_str(&text).unwrap(), err)
}

const GOOD: &str = "[model]\nkind = \"drop-tower\"\n\n[test]\ndata = \"test.csv\"\n\n\
    [holdout]\ndata = \"holdout.csv\"\nset = { v0 = 5.5 }\n\n[loop]\njitter_runs = 8\n\
    reconcile_runs = 24\nrecalibrate_runs = 24\nseed = 1\n";

#[test]
fn finds_the_hidden_damping_and_writes_the_report() {
    let dir = tempfile::tempdir().unwrap();
    write_tests(dir.path());
    let out = dir.path().join("out");
    let (v, err) = close_loop(&config(dir.path(), GOOD), &out);
    assert_eq!(v["verdict"], "attributed");
    assert_eq!(v["added"][0]["name"], "damping");
    let (lo, hi) = (
        v["added"][0]["lower"].as_f64().unwrap(),
        v["added"][0]["upper"].as_f64().unwrap(),
    );
    assert!(lo <= 0.03 && 0.03 <= hi);
    assert_eq!(v["candidates"][0]["name"], "damping");
    assert!(v["detection"]["model_form_error"].as_bool().unwrap());
    assert!((v["nuisance"]["gains"]["a2"].as_f64().unwrap() - 1.1).abs() < 0.01);
    for t in ["calibration", "holdout"] {
        let e = &v["errors"][t];
        assert!(e["enriched"].as_f64().unwrap() < e["calibrated"].as_f64().unwrap());
    }
    assert!(v["runs"].as_u64().unwrap() > 20);
    assert!(out.join("report.html").exists() && out.join("report.md").exists());
    assert!(err.contains("verdict: attributed"));
    progress_tells_the_story(&err, &out, v["runs"].as_u64().unwrap() as usize);
    report_has_provenance_and_geometry(&v, &out);
}

/// The report `close-loop` wrote ends with its provenance: this version, the command line
/// as given, the loop's digest and seed from `loop.json`. The same writer draws the
/// residual's pattern on a structure when the model places its channels (the drop tower
/// places none; the airframe's runs are too slow for a test, so its `loop.json` is written
/// again with a geometry that places each channel).
fn report_has_provenance_and_geometry(v: &serde_json::Value, out: &Path) {
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    let provenance = md
        .split("## Provenance")
        .nth(1)
        .expect("a provenance section");
    let digest = v["digest"].as_str().unwrap();
    for item in [
        format!("impactcal {}", env!("CARGO_PKG_VERSION")),
        "close-loop --config".to_string(),
        digest.to_string(),
        format!("| seed | {} |", v["seed"]),
    ] {
        assert!(provenance.contains(&item), "{item} not in {provenance}");
    }
    assert!(!out.join("fig-residual-structure-before.svg").exists());

    let result: impactcal::calibrate::closeloop::LoopResult =
        serde_json::from_value(v.clone()).unwrap();
    let labels: Vec<String> = v["detection"]["u1"]
        .as_object()
        .unwrap()
        .keys()
        .cloned()
        .collect();
    let mut geometry = impactcal::calibrate::study::document::Geometry {
        unit: "in".into(),
        ..Default::default()
    };
    for (i, l) in labels.iter().enumerate() {
        let at = [10.0 * i as f64, 0.0, 5.0];
        geometry.points.push(at);
        geometry.channels.insert(l.clone(), at);
    }
    let again = out.join("again");
    std::fs::create_dir_all(&again).unwrap();
    let done = impactcal::experiment::write_loop(result, Some(&geometry), None, &again).unwrap();
    for f in [
        "fig-residual-structure-before",
        "fig-residual-structure-after",
    ] {
        assert!(
            done.files.figures.contains(&again.join(format!("{f}.svg"))),
            "{f} not drawn"
        );
    }
}

/// Whether a progress text is a stage of runs: `<title>: <done>/<total> runs[ (...)]`.
fn is_stage(text: &str) -> bool {
    text.rsplit_once(": ").is_some_and(|(_, counts)| {
        counts
            .split_once(" runs")
            .and_then(|(c, _)| c.split_once('/'))
            .is_some_and(|(a, b)| a.parse::<usize>().is_ok() && b.parse::<usize>().is_ok())
    })
}

/// The loop's progress off a terminal: a line per stage of runs (one per journal stage, a
/// stage run in parts counted once) and per step, stages in words (no journal name), runs
/// done never past runs planned nor going back, and the last count the loop's runs; the
/// verdict on a line of its own after them.
fn progress_tells_the_story(err: &str, out: &Path, runs: usize) {
    let lines = progress_lines(err);
    let mut stages = std::collections::BTreeSet::new();
    for entry in std::fs::read_dir(out.join("runs")).unwrap() {
        let entry = entry.unwrap();
        if !entry.file_type().unwrap().is_dir() {
            continue;
        }
        let name = entry.file_name().to_string_lossy().to_string();
        // A stage run in parts: `<stage>-<first run>` after the first part.
        let whole = match name.rsplit_once('-') {
            Some((stage, first)) if stage.ends_with("cors") && first.parse::<usize>().is_ok() => {
                stage.to_string()
            }
            _ => name,
        };
        stages.insert(whole);
    }
    let stage_lines: Vec<&(usize, usize, String)> =
        lines.iter().filter(|(_, _, t)| is_stage(t)).collect();
    assert_eq!(stage_lines.len(), stages.len(), "{stages:?}\n{err}");
    for (_, _, text) in &lines {
        assert!(!text.contains("-gn") && !text.contains("r0-"), "{text}");
    }
    assert!(
        stage_lines
            .iter()
            .any(|(_, _, t)| t.starts_with("calibration, Gauss-Newton step 1, Jacobian: 0/2 runs")),
        "{err}"
    );
    assert!(
        stage_lines
            .iter()
            .any(|(_, _, t)| t.starts_with("calibration, CORS-RBF search: 0/24 runs")),
        "{err}"
    );
    let mut before = 0;
    for (done, planned, text) in &lines {
        assert!(done <= planned, "{done}/{planned} {text}");
        assert!(*done >= before, "{text}");
        before = *done;
    }
    let last = lines.last().unwrap();
    assert_eq!((last.0, last.1), (runs, runs), "{err}");
    assert!(last.2.starts_with("in "), "{err}");
    assert_eq!(
        lines.first().map(|l| l.2.as_str()),
        Some("nominal run: 0/1 runs")
    );
    let verdict = err.lines().find(|l| l.contains("verdict:")).unwrap();
    assert!(verdict.starts_with("verdict: attributed"), "{verdict}");
}

#[test]
fn bad_input_exits_2_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    write_tests(dir.path());
    let cases = [
        (GOOD.replace("v0 = 5.5", "v0 = 30.0"), "[holdout] set"),
        (
            GOOD.replace("seed = 1", "seed = 1\ncandidates = []"),
            "candidate list",
        ),
        (
            GOOD.replace("recalibrate_runs = 24", "recalibrate_runs = 6"),
            "at least 14",
        ),
        (
            GOOD.replace(
                "kind = \"drop-tower\"",
                "kind = \"drop-tower\"\nset = { v0 = 99.0 }",
            ),
            "v0",
        ),
        (GOOD.replace("drop-tower", "pendulum"), "unknown"),
    ];
    for (text, needle) in cases {
        let cfg = config(dir.path(), &text);
        let out = dir.path().join("bad");
        let o = impactcal(&[
            "close-loop",
            "--config",
            &cfg,
            "--out",
            out.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{needle}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(needle), "{needle}: {err}");
    }
    // A test channel the model does not have.
    let t = std::fs::read_to_string(dir.path().join("test.csv")).unwrap();
    let extra: String = t
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 0 {
                format!("{l},belt\n")
            } else {
                format!("{l},0\n")
            }
        })
        .collect();
    std::fs::write(dir.path().join("test.csv"), extra).unwrap();
    let cfg = config(dir.path(), GOOD);
    let o = impactcal(&[
        "close-loop",
        "--config",
        &cfg,
        "--out",
        dir.path().join("bad2").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("belt"), "{err}");
}

/// `--max-memory` below what the process already holds: refused before any run, with the
/// guard's line (stage, estimate, held, limit, what to change); the same loop with room
/// then runs in the same folder.
#[test]
fn a_memory_limit_below_the_plan_stops_the_loop_before_its_stages() {
    let dir = tempfile::tempdir().unwrap();
    write_tests(dir.path());
    let cfg = config(dir.path(), GOOD);
    let out = dir.path().join("small");
    let run = |limit: &str| {
        impactcal(&[
            "close-loop",
            "--config",
            &cfg,
            "--out",
            out.to_str().unwrap(),
            "--max-memory",
            limit,
        ])
    };
    let o = run("1M");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    let last = err.lines().last().unwrap_or_default();
    for needle in [
        "stage `",
        "needs about",
        "this process holds",
        "1.0 MB",
        "max_memory",
    ] {
        assert!(last.contains(needle), "{needle}: {err}");
    }
    // A limit below what the process already holds is known before any run.
    assert!(!out.join("runs/nominal").exists());
    let o = run("4G");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("memory: the loop plans about"), "{err}");
}

/// The loop on a keyword deck, configured as a study file configures it: the strip drop
/// declares its thickness; the test was measured on the deck itself at another thickness
/// (0.0021), with a trigger offset and noise, and the holdout at another drop speed. Nothing
/// is missing from the model, so the loop must calibrate the thickness and stay silent.
#[test]
fn stays_silent_on_a_deck_without_a_missing_effect() {
    use impactcal::core::{Parameter, ParameterSpace};
    use impactcal::shell::DeckModel;
    use impactcal::shell::keyword::read_deck;

    let dir = tempfile::tempdir().unwrap();
    let deck_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/decks/strip_drop.k");
    let deck = read_deck(&deck_path).unwrap();
    let declared = ParameterSpace::new(vec![
        Parameter::new("section.1.t", 0.0016, 0.0024, 0.002).unwrap(),
    ])
    .unwrap();
    let truth = DeckModel::new(deck.model)
        .unwrap()
        .declare(&declared)
        .unwrap();
    for (name, m, seed) in [
        ("test.csv", truth.clone(), 1),
        (
            "holdout.csv",
            truth
                .at_condition(&[("velocity.1.z".into(), -4.5)])
                .unwrap(),
            2,
        ),
    ] {
        let y = m.simulate(&[0.0021]).unwrap();
        let meas = Measurement {
            time_shift: 2e-5,
            snr_db: Some(40.0),
            seed,
            ..Measurement::default()
        };
        measured(&y, &meas)
            .unwrap()
            .write_csv(dir.path().join(name))
            .unwrap();
    }
    std::fs::write(
        dir.path().join("bounds.csv"),
        "name,lower,upper,nominal\nthickness,0.0016,0.0024,0.002\n",
    )
    .unwrap();
    let text = format!(
        "[model]\ndeck = \"{}\"\n\n[parameters]\nthickness = \"section.1.t\"\n\n\
         [space]\nbounds = \"bounds.csv\"\n\n[test]\ndata = \"test.csv\"\n\n\
         [holdout]\ndata = \"holdout.csv\"\nset = {{ \"velocity.1.z\" = -4.5 }}\n\n\
         [loop]\njitter_runs = 8\nreconcile_runs = 24\nrecalibrate_runs = 24\nseed = 1\n",
        deck_path.display()
    );
    let (v, _) = close_loop(&config(dir.path(), &text), &dir.path().join("out"));
    assert_eq!(v["verdict"], "no-model-form-error", "{v:#}");
    assert_eq!(v["added"].as_array().unwrap().len(), 0);
    let t = v["calibrated"]["thickness"].as_f64().unwrap();
    assert!((t - 0.0021).abs() < 0.00005, "thickness {t}");
}
