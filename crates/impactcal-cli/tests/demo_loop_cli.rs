//! `impactcal demo --close-loop` end to end in a reduced size (a 4 ms window, six channels,
//! two candidates, small budgets): the files it writes, the nuisance terms it recovers
//! against what the demo hid, the reveal, and a second run in the same folder that reuses
//! every run and writes the same `loop.json`. The full demo is recorded in
//! docs/validation.md.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::path::Path;

use common::impactcal;

fn demo(out: &Path) -> String {
    let o = impactcal(&[
        "demo",
        "--close-loop",
        "--out",
        out.to_str().unwrap(),
        "--end-time",
        "0.004",
        "--channels",
        "6",
        "--loop-ensemble",
        "2",
        "--loop-reconcile",
        "16",
        "--loop-recalibrate",
        "18",
        "--loop-polish",
        "2",
        "--max-added",
        "1",
        "--candidates",
        "damping,ground.friction",
        "--threads",
        "2",
    ]);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success(), "{err}");
    String::from_utf8_lossy(&o.stdout).to_string()
}

fn read(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn the_closed_loop_demo_finds_the_nuisance_terms_reveals_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let stdout = demo(dir.path());
    for f in [
        "test.csv",
        "holdout.csv",
        "loop.json",
        "demo.json",
        "report.html",
        "report.md",
    ] {
        assert!(dir.path().join(f).exists(), "{f} missing");
    }
    assert!(
        stdout.contains("the reveal:") && stdout.contains("relative L2"),
        "{stdout}"
    );
    let l = read(&dir.path().join("loop.json"));
    let d = read(&dir.path().join("demo.json"));
    // The trigger offset the demo hid (2e-4 s) is found within a fifth of a sample; the
    // wrong gain (1.2 on the first channel) within 3 %.
    let tau = l["nuisance"]["time_shift"].as_f64().unwrap();
    assert!((tau - 2e-4).abs() < 2e-5, "{tau}");
    let wrong = d["channels"][0].as_str().unwrap();
    let g = l["nuisance"]["gains"][wrong].as_f64().unwrap();
    assert!((g - 1.2).abs() < 0.036, "{g}");
    assert_eq!(d["channels"].as_array().unwrap().len(), 6);
    // The reveal sits beside the loop's findings, in demo.json and in the report.
    let reveal = d["reveal"].as_array().unwrap();
    assert!(
        reveal[0]["quantity"]
            .as_str()
            .unwrap()
            .starts_with("damping")
    );
    assert_eq!(reveal[0]["hidden"], "10");
    let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
    assert!(md.contains("The reveal") && md.contains("M1 exceedance"));
    // M1 and M2 rows on both tests.
    for t in ["metrics_calibration", "metrics_holdout"] {
        for s in ["nominal", "calibrated", "enriched"] {
            let e = &l[t][s];
            let m1 = e["m1_exceedance"].as_f64().unwrap();
            assert!((0.0..=1.0).contains(&m1), "{t} {s} {m1}");
            assert!(e["m2_shapes"].as_u64().unwrap() <= 6);
        }
    }
    // The nominal runs keep every channel of the airframe; every other run stores the six
    // channels compared.
    let header = |run: &Path| -> Vec<String> {
        let text = std::fs::read_to_string(run.join("result.csv")).unwrap();
        let mut labels: Vec<String> = text
            .lines()
            .next()
            .unwrap()
            .split(',')
            .skip(1)
            .map(String::from)
            .collect();
        labels.sort();
        labels
    };
    let mut compared: Vec<String> = d["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap().to_string())
        .collect();
    compared.sort();
    let runs = dir.path().join("runs");
    let mut stages = 0;
    for stage in std::fs::read_dir(&runs).unwrap() {
        let stage = stage.unwrap().path();
        if !stage.is_dir() {
            continue;
        }
        stages += 1;
        let name = stage.file_name().unwrap().to_string_lossy().to_string();
        let h = header(&stage.join("0"));
        if name == "nominal" || name == "holdout-nominal" {
            assert_eq!(h.len(), 1215, "{name}");
        } else {
            assert_eq!(h, compared, "{name}");
        }
    }
    assert!(stages > 5, "{stages} stages");
    // Run again in the same folder: every run is read back, the result is the same.
    let first = std::fs::read_to_string(dir.path().join("loop.json")).unwrap();
    demo(dir.path());
    let again = std::fs::read_to_string(dir.path().join("loop.json")).unwrap();
    assert_eq!(first, again);
}
