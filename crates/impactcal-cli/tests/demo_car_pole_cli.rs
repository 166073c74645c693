//! `impactcal demo --car-pole` end to end on a synthetic stand-in of the public study's
//! folder (the real data are GPL-3 and kept outside the project): the study's file formats
//! with a known answer. "LS-DYNA" is a smooth function `f` of four parameters with outputs
//! in the study's units; "our solver" is `f(x + delta)`, so that our model matches the test
//! at the base design `c` exactly at `c - delta`. Also the messages for absent data and
//! malformed runs.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::fmt::Write as _;
use std::path::Path;
use std::process::Output;

use common::impactcal;

const BOUNDS: [(f64, f64); 4] = [(2.0, 4.0), (1.0, 3.0), (300.0, 500.0), (0.5, 1.5)];
const DELTA: [f64; 4] = [0.6, -0.5, 50.0, 0.3];

/// dmax (mm), fmax (N), vfin (mm/s), IE (N mm).
fn lsdyna(x: &[f64]) -> [f64; 4] {
    let (a, b, c, d) = (x[0] / 3.0, x[1] - 2.0, x[2] / 400.0, x[3] - 1.0);
    [
        -600.0 / (a * c.sqrt()) - 50.0 * d,
        7.0e5 * a * c + 1.0e5 * b,
        -700.0 + 400.0 * b + 300.0 * d,
        1.2e8 * (1.0 + 0.15 * (a - 1.0) + 0.03 * b + 0.1 * d),
    ]
}

fn ours(x: &[f64]) -> [f64; 4] {
    let shifted: Vec<f64> = x.iter().zip(DELTA).map(|(v, d)| v + d).collect();
    lsdyna(&shifted)
}

fn centre() -> Vec<f64> {
    BOUNDS.iter().map(|(a, b)| 0.5 * (a + b)).collect()
}

/// The radical inverse of `i` in `base` (a Halton coordinate).
fn halton(mut i: usize, base: usize) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= base as f64;
        r += f * (i % base) as f64;
        i /= base;
    }
    r
}

fn designs(n: usize) -> Vec<Vec<f64>> {
    (1..=n)
        .map(|i| {
            BOUNDS
                .iter()
                .zip([2, 3, 5, 7])
                .map(|((lo, hi), b)| lo + (hi - lo) * halton(i, b))
                .collect()
        })
        .collect()
}

/// The study's folder: problem, designs, LS-DYNA's outputs, and the log with two repeats
/// of the base design (their mean is `f(c)`).
fn study(dir: &Path) -> Vec<Vec<f64>> {
    std::fs::create_dir_all(dir.join("decks")).unwrap();
    std::fs::write(
        dir.join("p9_problem.txt"),
        "{'names': ['ta', 'tb', 'ya', 'tc'], 'units': ['mm', 'mm', 'MPa', 'mm'], \
         'num_vars': 4, 'bounds': [[2, 4], [1, 3], [300, 500], [0.5, 1.5]]}",
    )
    .unwrap();
    let x = designs(60);
    let mut text = String::new();
    for r in &x {
        let row: Vec<String> = r.iter().map(|v| format!("{v:.18e}")).collect();
        writeln!(text, "{}", row.join(",")).unwrap();
    }
    std::fs::write(dir.join("p9_X.csv"), text).unwrap();
    for (k, name) in ["dmax", "fmax", "vfin", "IE"].iter().enumerate() {
        let col: String = x
            .iter()
            .map(|r| format!("{:.18e}\n", lsdyna(r)[k]))
            .collect();
        std::fs::write(dir.join(format!("p9_Y_{name}.csv")), col).unwrap();
    }
    let y = lsdyna(&centre());
    let mut log = String::from("Model\n\n## base design output 2024-05-03\n");
    for s in [1.0 + 1e-3, 1.0 - 1e-3] {
        writeln!(
            log,
            "{{'fmax': {},\n 'dmax': {},\n 'vfin': {},\n 'IE': array([{:e}])}}\n",
            y[1] * s,
            y[0] * s,
            y[2] * s,
            y[3] * s
        )
        .unwrap();
    }
    log.push_str("# MODEL OUTPUT\n* 605: body\n");
    std::fs::write(dir.join("decks/MODIFICATIONS_LOG.md"), log).unwrap();
    x
}

/// Our results file as the cross-code script writes it: the base design, the first `n`
/// designs and a controlled rerun (not a design: skipped).
fn our_results(path: &Path, x: &[Vec<f64>], n: usize) {
    let mut text = String::from("row,dmax,fmax,vfin,IE,fmax_normal,HE,t_end,cycles,wall_s\n");
    let mut line = |label: &str, p: &[f64]| {
        let o = ours(p);
        writeln!(
            text,
            "{label},{},{},{},{},1,2,0.2,30000,0:40.00",
            o[0], o[1], o[2], o[3]
        )
        .unwrap();
    };
    line("base", &centre());
    for (i, p) in x.iter().take(n).enumerate() {
        line(&i.to_string(), p);
    }
    line("hourglass-viscous", &centre());
    std::fs::write(path, text).unwrap();
}

fn misfit(o: [f64; 4], y: [f64; 4], scale: &[f64]) -> f64 {
    (0..4).map(|k| ((o[k] - y[k]) / scale[k]).powi(2)).sum()
}

fn demo(data: &Path, runs: &Path, out: &Path) -> Output {
    impactcal(&[
        "demo",
        "--car-pole",
        data.to_str().unwrap(),
        "--runs",
        runs.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ])
}

#[test]
fn calibrates_the_stand_in_to_its_known_point() {
    let tmp = tempfile::tempdir().unwrap();
    let data = tmp.path().join("car_pole");
    let x = study(&data);
    let results = tmp.path().join("results.csv");
    our_results(&results, &x, 30);
    let out = tmp.path().join("out");
    let o = demo(&data, &results, &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("31 of our runs reused"), "{stdout}");
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("car-pole.json")).unwrap()).unwrap();
    assert_eq!(j["designs_reused"], 31);
    assert_eq!(j["rows_skipped"], serde_json::json!(["hourglass-viscous"]));
    // The test: the mean of the repeats; the scales: LS-DYNA's spread over the designs.
    let y = lsdyna(&centre());
    let mut scale = Vec::new();
    for (k, t) in j["test"].as_array().unwrap().iter().enumerate() {
        assert!(
            (t["value"].as_f64().unwrap() / y[k] - 1.0).abs() < 1e-12,
            "{t}"
        );
        let col: Vec<f64> = x.iter().map(|r| lsdyna(r)[k]).collect();
        let m = col.iter().sum::<f64>() / 60.0;
        let sd = (col.iter().map(|v| (v - m).powi(2)).sum::<f64>() / 59.0).sqrt();
        assert!(
            (t["scale"].as_f64().unwrap() / sd - 1.0).abs() < 1e-12,
            "{t}"
        );
        scale.push(sd);
    }
    // Before: our run at the base design, read back; after: our model at the calibrated
    // point, against the truth `c - delta`.
    let run = &j["run_at_target"];
    assert!((run[0]["model"].as_f64().unwrap() / ours(&centre())[0] - 1.0).abs() < 1e-12);
    let cal: Vec<f64> = j["calibration"]["calibrated_point"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let before = misfit(ours(&centre()), y, &scale);
    let after = misfit(ours(&cal), y, &scale);
    assert!(before > 1.0, "{before}");
    assert!(after < 1e-2 * before, "J {before} -> {after}");
    for (k, (v, (lo, hi))) in cal.iter().zip(BOUNDS).enumerate() {
        let truth = centre()[k] - DELTA[k];
        assert!(
            (v - truth).abs() < 0.03 * (hi - lo),
            "{k}: {v} against {truth}"
        );
    }
    // The deck of the calibrated point names the model where the user keeps it.
    let deck = std::fs::read_to_string(out.join("calibrated.k")).unwrap();
    assert!(deck.starts_with("*KEYWORD\n*PARAMETER\nrta,"), "{deck}");
    assert!(deck.contains(&format!(
        "{}",
        data.join("decks/car6_crash_v223.k").display()
    )));
    assert!(
        std::fs::read_to_string(out.join("report.md"))
            .unwrap()
            .contains("| dmax |")
    );
}

#[test]
fn absent_data_and_bad_runs_are_clear_messages() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let absent = tmp.path().join("nowhere");
    let o = demo(&absent, Path::new("r.csv"), &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("no car pole study here"), "{err}");
    assert!(!out.exists());

    let data = tmp.path().join("car_pole");
    let x = study(&data);
    let run = |runs: &Path| {
        let o = demo(&data, runs, &out);
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).to_string(),
        )
    };
    let results = tmp.path().join("results.csv");
    our_results(&results, &x, 12);
    let text = std::fs::read_to_string(&results).unwrap();
    // A NaN output, a design that is not in the study, a missing column.
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut cells: Vec<String> = lines[3].split(',').map(str::to_string).collect();
    cells[1] = "NaN".into();
    lines[3] = cells.join(",");
    std::fs::write(&results, lines.join("\n")).unwrap();
    let (code, err) = run(&results);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("line 4: NaN is not a finite number"), "{err}");
    std::fs::write(&results, text.replace("\n5,", "\n75,")).unwrap();
    let (code, err) = run(&results);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("`75`: neither `base` nor a row 0..60"),
        "{err}"
    );
    std::fs::write(&results, text.replace("vfin,", "v,")).unwrap();
    let (code, err) = run(&results);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("no column `vfin`"), "{err}");
    let o = impactcal(&[
        "demo",
        "--car-pole",
        data.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--runs RESULTS is needed"));
}
