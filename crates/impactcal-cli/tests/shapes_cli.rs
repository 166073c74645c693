//! End-to-end tests of `impactcal shapes`, `compare` and `expand` on the shipped example and
//! on malformed files.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;
use common::{example, impactcal, json};

use std::path::{Path, PathBuf};

#[test]
fn shapes_on_the_example() {
    let input = example("analysis.csv");
    let v = json(&impactcal(&[
        "shapes",
        "--input",
        input.to_str().unwrap(),
        "--shapes",
        "3",
    ]));
    assert_eq!(v["channels"].as_array().unwrap().len(), 24);
    let sv: Vec<f64> = serde_json::from_value(v["singular_values"].clone()).unwrap();
    assert_eq!(sv.len(), 3);
    assert!(sv[0] >= sv[1] && sv[1] >= sv[2]);
    assert_eq!(v["shapes"].as_array().unwrap().len(), 3);
    assert_eq!(v["shapes"][0].as_array().unwrap().len(), 24);
    assert_eq!(v["time"].as_array().unwrap().len(), 401);
    assert_eq!(v["time_functions"][2].as_array().unwrap().len(), 401);
    let c: Vec<f64> = serde_json::from_value(v["contributions"].clone()).unwrap();
    let e: Vec<f64> = serde_json::from_value(v["energy_fractions"].clone()).unwrap();
    assert!(c.iter().sum::<f64>() < 1.0 && e[0] > c[0]);
    // Truncation by contribution keeps the fewest shapes reaching the fraction.
    let v = json(&impactcal(&[
        "shapes",
        "--input",
        input.to_str().unwrap(),
        "--contribution",
        "0.8",
    ]));
    let c: Vec<f64> = serde_json::from_value(v["contributions"].clone()).unwrap();
    assert!(c.iter().sum::<f64>() >= 0.8 && c[..c.len() - 1].iter().sum::<f64>() < 0.8);
}

#[test]
fn compare_with_itself_is_the_identity() {
    let a = example("analysis.csv");
    let v = json(&impactcal(&[
        "compare",
        "--test",
        a.to_str().unwrap(),
        "--analysis",
        a.to_str().unwrap(),
        "--shapes",
        "4",
    ]));
    assert_eq!(v["matched_above_0_9"], 4);
    for (i, row) in v["orthogonality"].as_array().unwrap().iter().enumerate() {
        for (j, x) in row.as_array().unwrap().iter().enumerate() {
            let expect = if i == j { 1.0 } else { 0.0 };
            assert!((x.as_f64().unwrap() - expect).abs() < 1e-10);
        }
    }
    let t = example("test.csv");
    let v = json(&impactcal(&[
        "compare",
        "--test",
        t.to_str().unwrap(),
        "--analysis",
        a.to_str().unwrap(),
        "--shapes",
        "3",
    ]));
    for key in [
        "pairs",
        "principal_cosines",
        "test_contributions",
        "analysis_contributions",
    ] {
        assert!(v[key].is_array(), "missing {key}");
    }
    assert_eq!(v["pairs"][0].as_array().unwrap().len(), 3);
}

#[test]
fn expand_writes_unmeasured_channels() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("e.csv");
    let o = impactcal(&[
        "expand",
        "--measured",
        example("measured.csv").to_str().unwrap(),
        "--model",
        example("analysis.csv").to_str().unwrap(),
        "--shapes",
        "3",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cond(Phi)"));
    let e = impactcal::core::Histories::read_csv(&out).unwrap();
    assert_eq!(e.channels(), 24 - 8);
    assert_eq!(e.samples(), 401);
    // The expanded z channels track the test data they estimate.
    let test = impactcal::core::Histories::read_csv(example("test.csv")).unwrap();
    let est = e.channel_by_label("101.z").unwrap();
    let truth = test.channel_by_label("101.z").unwrap();
    let err: f64 = est
        .iter()
        .zip(truth)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        .sqrt();
    let norm: f64 = truth.iter().map(|b| b * b).sum::<f64>().sqrt();
    assert!(err / norm < 0.1, "relative error {}", err / norm);
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Runs `shapes` on a malformed file: exit code 2, one line naming file, row and column.
fn rejects(text: &str, row: usize, column: usize) {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "bad.csv", text);
    let o = impactcal(&["shapes", "--input", p.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "input {text:?}");
    let msg = String::from_utf8_lossy(&o.stderr);
    assert_eq!(msg.lines().count(), 1, "{msg}");
    assert!(msg.contains("bad.csv"), "{msg}");
    assert!(
        msg.contains(&format!("row {row}, column {column}")),
        "{msg} (expected row {row}, column {column})"
    );
    assert!(!msg.contains("panicked"));
}

#[test]
fn malformed_histories_are_rejected_with_position() {
    rejects("time,a\n0,1\n0.1,2\n0.25,3\n0.3,4\n", 4, 1);
    rejects("time,a\n0,1\n0.1,2\n0.1,3\n", 4, 1);
    rejects("time,a\n0,1\n0.1,x\n", 3, 2);
    rejects("time,a\n0,1\n0.1,nan\n", 3, 2);
    rejects("time,a\n0,1\n0.1,inf\n", 3, 2);
    rejects("time,a,b\n0,1,2\n0.1,2\n", 3, 3);
    rejects("time,a,a\n0,1,2\n0.1,2,3\n", 1, 3);
    rejects("time,a,\n0,1,2\n0.1,2,3\n", 1, 3);
    rejects("secs,a\n0,1\n0.1,2\n", 1, 1);
}

#[test]
fn empty_and_missing_files_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "empty.csv", "");
    let o = impactcal(&["shapes", "--input", p.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("empty.csv"));
    let o = impactcal(&["shapes", "--input", "/nonexistent/y.csv"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("/nonexistent/y.csv"));
}

/// Files that share some channels: M2 on the shared ones, the others named in a warning and
/// in the JSON's `dropped`, each side's in its file's order.
#[test]
fn compare_names_the_channels_it_dropped() {
    let dir = tempfile::tempdir().unwrap();
    let t = write(
        dir.path(),
        "t.csv",
        "time,a,b,c\n0,1,0,2\n0.1,2,1,4\n0.2,3,0,7\n0.3,1,2,1\n",
    );
    let m = write(
        dir.path(),
        "m.csv",
        "time,c,a,x,y\n0,2,1,0,0\n0.1,4,2,1,1\n0.2,6,3,0,1\n0.3,1,1,1,0\n",
    );
    let o = impactcal(&[
        "compare",
        "--test",
        t.to_str().unwrap(),
        "--analysis",
        m.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("warning") && err.contains("`b`") && err.contains("`x`"),
        "{err}"
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["channels"], serde_json::json!(["a", "c"]));
    assert_eq!(v["dropped"]["test"], serde_json::json!(["b"]));
    assert_eq!(v["dropped"]["model"], serde_json::json!(["x", "y"]));
    // Nothing dropped: an empty `dropped`, no warning.
    let o = impactcal(&[
        "compare",
        "--test",
        t.to_str().unwrap(),
        "--analysis",
        t.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    assert!(!String::from_utf8_lossy(&o.stderr).contains("warning"));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["dropped"]["test"], serde_json::json!([]));
}

#[test]
fn impossible_requests_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "y.csv", "time,a,b\n0,1,2\n0.1,2,4\n0.2,3,6\n");
    let o = impactcal(&["shapes", "--input", p.to_str().unwrap(), "--shapes", "2"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("rank 1"));
    let q = write(dir.path(), "z.csv", "time,a,c\n0,1,2\n0.1,2,4\n0.2,3,6\n");
    // Files that share no channel: nothing to compare.
    let r = write(dir.path(), "r.csv", "time,d,e\n0,1,2\n0.1,2,4\n0.2,3,6\n");
    let o = impactcal(&[
        "compare",
        "--test",
        p.to_str().unwrap(),
        "--analysis",
        r.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("share no channel") && err.contains("`d`"),
        "{err}"
    );
    let o = impactcal(&[
        "expand",
        "--measured",
        q.to_str().unwrap(),
        "--model",
        p.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
}
