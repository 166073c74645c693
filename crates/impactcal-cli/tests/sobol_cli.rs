//! `impactcal sample` and `impactcal sobol` end to end on files.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::needless_range_loop)]

use std::path::Path;

use serde_json::Value;

mod common;
use common::impactcal;

const BOUNDS: &str = "name,lower,upper,nominal\n\
    x1,-3.141592653589793,3.141592653589793,0\n\
    x2,-3.141592653589793,3.141592653589793,0\n\
    x3,-3.141592653589793,3.141592653589793,0\n";

fn read_rows(path: &Path) -> (String, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_string();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

fn ishigami(x: &[f64]) -> f64 {
    x[0].sin() * (1.0 + 0.1 * x[2].powi(4)) + 7.0 * x[1].sin().powi(2)
}

#[test]
fn sample_then_sobol_gives_ishigami_indices() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    std::fs::write(p("b.csv"), BOUNDS).unwrap();
    let out = impactcal(&[
        "sample",
        "--bounds",
        &p("b.csv"),
        "--method",
        "saltelli",
        "--n",
        "4096",
        "--seed",
        "2",
        "--second-order",
        "--out",
        &p("p.csv"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (header, rows) = read_rows(Path::new(&p("p.csv")));
    assert_eq!(header, "x1,x2,x3");
    assert_eq!(rows.len(), 4096 * 8);
    let mut y = String::from("q.0,q.1,flat\n");
    for x in &rows {
        let v = ishigami(x);
        y.push_str(&format!("{v},{},2.5\n", 2.0 * v + 1000.0));
    }
    std::fs::write(p("y.csv"), y).unwrap();
    let out = impactcal(&[
        "sobol",
        "--bounds",
        &p("b.csv"),
        "--params",
        &p("p.csv"),
        "--outputs",
        &p("y.csv"),
        "--bootstrap",
        "50",
        "--second-order",
        "--out",
        &p("s.json"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("flat"));
    let s: Value = serde_json::from_str(&std::fs::read_to_string(p("s.json")).unwrap()).unwrap();
    for key in [
        "parameters",
        "outputs",
        "first_order",
        "total",
        "first_order_ci",
        "total_ci",
        "second_order",
        "aggregated",
        "low_variance_outputs",
    ] {
        assert!(s.get(key).is_some(), "missing {key}");
    }
    let exact_s1 = [0.313_905, 0.442_411, 0.0];
    let exact_st = [0.557_589, 0.442_411, 0.243_684];
    for t in 0..2 {
        for i in 0..3 {
            let s1 = s["first_order"][t][i].as_f64().unwrap();
            let st = s["total"][t][i].as_f64().unwrap();
            assert!((s1 - exact_s1[i]).abs() < 0.02, "S1 {t} {i}: {s1}");
            assert!((st - exact_st[i]).abs() < 0.02, "ST {t} {i}: {st}");
        }
    }
    assert!(s["first_order"][2][0].is_null());
    assert_eq!(s["low_variance_outputs"][0], "flat");
    let s13 = s["second_order"][0][0][2].as_f64().unwrap();
    assert!((s13 - 0.243_684).abs() < 0.04, "S13 {s13}");
    let agg = s["aggregated"]["first_order"][1].as_f64().unwrap();
    assert!((agg - 0.442_411).abs() < 0.02);

    // The same rows without --second-order do not fit: exit code 2 and a hint.
    let out = impactcal(&[
        "sobol",
        "--bounds",
        &p("b.csv"),
        "--params",
        &p("p.csv"),
        "--outputs",
        &p("y.csv"),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("second order"));
}

#[test]
fn sample_methods_write_named_columns() {
    let dir = tempfile::tempdir().unwrap();
    let b = dir.path().join("b.csv");
    std::fs::write(&b, BOUNDS).unwrap();
    for method in ["halton", "sobol", "lhs", "slhd", "random"] {
        let o = dir.path().join(format!("{method}.csv"));
        let out = impactcal(&[
            "sample",
            "--bounds",
            b.to_str().unwrap(),
            "--method",
            method,
            "--n",
            "10",
            "--out",
            o.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{method}");
        // Sobol' warns about 10 not being a power of two.
        let warned = String::from_utf8_lossy(&out.stderr).contains("power of two");
        assert_eq!(warned, method == "sobol", "{method}");
        let (header, rows) = read_rows(&o);
        assert_eq!(header, "x1,x2,x3");
        assert_eq!(rows.len(), 10);
        assert!(
            rows.iter()
                .flatten()
                .all(|v| v.abs() <= std::f64::consts::PI)
        );
        if method == "slhd" {
            for i in 0..10 {
                for j in 0..3 {
                    assert!((rows[i][j] + rows[9 - i][j]).abs() < 1e-12);
                }
            }
        }
    }
    // Plain Halton from index 0 starts at the lower corner.
    let out = impactcal(&[
        "sample",
        "--bounds",
        b.to_str().unwrap(),
        "--method",
        "halton",
        "--no-scramble",
        "--n",
        "2",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.lines().nth(1).unwrap().starts_with("-3.14159"),
        "{text}"
    );
    let bad = impactcal(&[
        "sample",
        "--bounds",
        b.to_str().unwrap(),
        "--method",
        "lhs",
        "--n",
        "0",
    ]);
    assert_eq!(bad.status.code(), Some(2));
}
