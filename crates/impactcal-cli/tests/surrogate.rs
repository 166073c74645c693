//! End-to-end tests of `impactcal surrogate fit|predict` on CSV files.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;
use std::process::Command;

fn impactcal(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_impactcal"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Response history of sample (a, b) at 20 instants.
fn response(a: f64, b: f64) -> Vec<f64> {
    (0..20)
        .map(|t| (0.3 * t as f64 * a).sin() * b + 0.01 * a * b)
        .collect()
}

fn write_case(dir: &Path, n: usize) -> (Vec<[f64; 2]>, Vec<Vec<f64>>) {
    std::fs::write(
        dir.join("bounds.csv"),
        "name,lower,upper,nominal,unit\na,1,3,2,mm\nb,-5,5,0,\n",
    )
    .unwrap();
    // A Latin-square style design: stratified in both inputs, columns in reverse order.
    let pts: Vec<[f64; 2]> = (0..n)
        .map(|i| {
            let u = (i as f64 + 0.5) / n as f64;
            let v = (((7 * i + 3) % n) as f64 + 0.5) / n as f64;
            [1.0 + 2.0 * u, -5.0 + 10.0 * v]
        })
        .collect();
    let mut p = String::from("b,a\n");
    let mut y = (0..20)
        .map(|t| format!("y{t}"))
        .collect::<Vec<_>>()
        .join(",")
        + "\n";
    let mut ys = Vec::new();
    for q in &pts {
        p.push_str(&format!("{},{}\n", q[1], q[0]));
        let r = response(q[0], q[1]);
        y.push_str(
            &r.iter()
                .map(|v| v.to_string())
                .collect::<Vec<_>>()
                .join(","),
        );
        y.push('\n');
        ys.push(r);
    }
    std::fs::write(dir.join("P.csv"), p).unwrap();
    std::fs::write(dir.join("Y.csv"), y).unwrap();
    (pts, ys)
}

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

#[test]
fn fit_then_predict_reproduces_the_training_histories_for_every_kind() {
    let dir = tempfile::tempdir().unwrap();
    let (_, ys) = write_case(dir.path(), 23);
    let d = |f: &str| dir.path().join(f).display().to_string();
    for kind in ["erbf", "gaussian", "cubic", "thin-plate", "multiquadric"] {
        let (code, _, err) = impactcal(&[
            "surrogate",
            "fit",
            "--bounds",
            &d("bounds.csv"),
            "--params",
            &d("P.csv"),
            "--outputs",
            &d("Y.csv"),
            "--kind",
            kind,
            "--out",
            &d("model.json"),
        ]);
        assert_eq!(code, 0, "{kind}: {err}");
        assert!(err.contains("training residual"), "{err}");
        assert!(err.contains("leave-one-out error: rms"), "{err}");
        let (code, _, err) = impactcal(&[
            "surrogate",
            "predict",
            "--model",
            &d("model.json"),
            "--params",
            &d("P.csv"),
            "--out",
            &d("Yhat.csv"),
        ]);
        assert_eq!(code, 0, "{kind}: {err}");
        assert!(!err.contains("warning"), "{err}");
        let (header, rows) = read_csv(&dir.path().join("Yhat.csv"));
        assert_eq!(header.len(), 20);
        assert_eq!(header[3], "y3");
        for (row, truth) in rows.iter().zip(&ys) {
            for (a, b) in row.iter().zip(truth) {
                assert!((a - b).abs() < 1e-9, "{kind}: {a} vs {b}");
            }
        }
    }
}

#[test]
fn predict_warns_outside_the_bounds_and_interpolates_inside() {
    let dir = tempfile::tempdir().unwrap();
    write_case(dir.path(), 40);
    let d = |f: &str| dir.path().join(f).display().to_string();
    let (code, stdout, err) = impactcal(&[
        "surrogate",
        "fit",
        "--bounds",
        &d("bounds.csv"),
        "--params",
        &d("P.csv"),
        "--outputs",
        &d("Y.csv"),
    ]);
    assert_eq!(code, 0, "{err}");
    std::fs::write(dir.path().join("model.json"), stdout).unwrap();
    std::fs::write(dir.path().join("Q.csv"), "a,b\n2.1,0.7\n3.5,0\n").unwrap();
    let (code, stdout, err) = impactcal(&[
        "surrogate",
        "predict",
        "--model",
        &d("model.json"),
        "--params",
        &d("Q.csv"),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("1 of 2 query rows lie outside"), "{err}");
    assert!(err.contains("line 3"), "{err}");
    let first: Vec<f64> = stdout
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let truth = response(2.1, 0.7);
    let err_max = first
        .iter()
        .zip(&truth)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(err_max < 0.1, "interpolation error {err_max}");
}

#[test]
fn bad_input_exits_with_code_2_and_says_where() {
    let dir = tempfile::tempdir().unwrap();
    write_case(dir.path(), 10);
    let d = |f: &str| dir.path().join(f).display().to_string();
    let fit = |params: &str| {
        impactcal(&[
            "surrogate",
            "fit",
            "--bounds",
            &d("bounds.csv"),
            "--params",
            params,
            "--outputs",
            &d("Y.csv"),
        ])
    };
    // A duplicated sample: lines 3 and 6 of the file.
    let text = std::fs::read_to_string(dir.path().join("P.csv")).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines[5] = lines[2];
    std::fs::write(dir.path().join("dup.csv"), lines.join("\n") + "\n").unwrap();
    let (code, _, err) = fit(&d("dup.csv"));
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("lines 3 and 6"), "{err}");
    // A missing parameter column.
    std::fs::write(dir.path().join("nob.csv"), "a\n1\n2\n").unwrap();
    let (code, _, err) = fit(&d("nob.csv"));
    assert_eq!(code, 2);
    assert!(err.contains("no column `b`"), "{err}");
    // Row counts that differ.
    let short: Vec<&str> = text.lines().take(5).collect();
    std::fs::write(dir.path().join("short.csv"), short.join("\n") + "\n").unwrap();
    let (code, _, err) = fit(&d("short.csv"));
    assert_eq!(code, 2);
    assert!(err.contains("one response row per sample"), "{err}");
    // Not a model.
    let (code, _, err) = impactcal(&[
        "surrogate",
        "predict",
        "--model",
        &d("bounds.csv"),
        "--params",
        &d("P.csv"),
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("not a surrogate model"), "{err}");
}

/// `impactcal surrogate fit` on `bounds.csv`, `P.csv` and `Y.csv` of `dir`, writing
/// `m.json`, with `extra` arguments.
fn fit_in(dir: &Path, extra: &[&str]) -> (i32, String, String) {
    let d = |f: &str| dir.join(f).display().to_string();
    let (b, p, y, m) = (d("bounds.csv"), d("P.csv"), d("Y.csv"), d("m.json"));
    let mut args = vec![
        "surrogate",
        "fit",
        "--bounds",
        &b,
        "--params",
        &p,
        "--outputs",
        &y,
        "--out",
        &m,
    ];
    args.extend_from_slice(extra);
    impactcal(&args)
}

/// `--basis shapes --shapes K`: the training histories come back to within the truncation
/// of K shapes, the summary names the shapes, and the saved model predicts the same.
#[test]
fn shape_basis_fit_reproduces_the_training_runs_within_its_truncation() {
    let dir = tempfile::tempdir().unwrap();
    let (_, ys) = write_case(dir.path(), 23);
    let d = |f: &str| dir.path().join(f).display().to_string();
    let (code, _, err) = impactcal(&[
        "surrogate",
        "fit",
        "--bounds",
        &d("bounds.csv"),
        "--params",
        &d("P.csv"),
        "--outputs",
        &d("Y.csv"),
        "--kind",
        "cubic",
        "--basis",
        "shapes",
        "--shapes",
        "14",
        "--out",
        &d("m.json"),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("14 impact shapes"), "{err}");
    assert!(err.contains("linear trend"), "{err}");
    let (code, _, err) = impactcal(&[
        "surrogate",
        "predict",
        "--model",
        &d("m.json"),
        "--params",
        &d("P.csv"),
        "--out",
        &d("Yhat.csv"),
    ]);
    assert_eq!(code, 0, "{err}");
    let (_, rows) = read_csv(&dir.path().join("Yhat.csv"));
    // The 14 shapes are the numerical rank of the centred runs: exact reproduction.
    for (r, y) in rows.iter().zip(&ys) {
        for (a, b) in r.iter().zip(y) {
            assert!((a - b).abs() < 1e-8 * (1.0 + b.abs()), "{a} vs {b}");
        }
    }
    // A count without the basis, and a count above the rank, are bad input.
    for extra in [
        &["--shapes", "3"][..],
        &["--basis", "shapes", "--shapes", "40"][..],
    ] {
        let (code, _, err) = fit_in(dir.path(), extra);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(err.contains("shape"), "{err}");
    }
}

/// Noisy data around a plane: the interpolating cubic's leave-one-out error is worse than
/// the linear trend's and `fit` says so; with `--auto` the smoothing it chooses brings the
/// error down to the trend's (no worse than 5 % above it).
#[test]
fn fit_warns_when_worse_than_a_linear_trend() {
    let dir = tempfile::tempdir().unwrap();
    write_unit_square_case(dir.path(), 60, (17, 5), "y", |i, a, b| {
        // Deterministic "noise" of amplitude 0.5 on a plane of range 3.
        let noise = 0.5 * ((i * 7919 % 101) as f64 / 50.0 - 1.0);
        format!("{}", 1.0 + 2.0 * a + b + noise)
    });
    let fit = |extra: &[&str]| fit_in(dir.path(), extra);
    let (code, _, err) = fit(&["--kind", "cubic"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("warning: y: the leave-one-out error"), "{err}");
    let (code, _, err) = fit(&["--kind", "cubic", "--auto"]);
    assert_eq!(code, 0, "{err}");
    let line = err
        .lines()
        .find(|l| l.contains("y: leave-one-out rms / std"))
        .unwrap();
    let nums: Vec<f64> = line
        .split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .filter_map(|s| s.parse().ok())
        .collect();
    let (model, trend) = (nums[nums.len() - 2], nums[nums.len() - 1]);
    assert!(model <= 1.05 * trend, "{line}");
}

/// Outputs a linear trend reproduces exactly (a plane) or that never change (a constant, as
/// a history's first instants often are): no `NaN` and no round-off ratio in the summary; a
/// kernel whose linear tail reproduces the plane draws no warning, one without a tail is
/// told the output is linear.
#[test]
fn linear_and_constant_outputs_are_summarised_without_nan_or_false_warnings() {
    let dir = tempfile::tempdir().unwrap();
    write_unit_square_case(dir.path(), 20, (7, 3), "plane,constant", |_, a, b| {
        format!("{},4.5", 2.0 * a - b)
    });
    for kind in ["cubic", "thin-plate", "auto"] {
        let (code, _, err) = fit_in(dir.path(), &["--kind", kind]);
        assert_eq!(code, 0, "{kind}: {err}");
        assert!(
            !err.contains("NaN") && !err.contains("warning"),
            "{kind}: {err}"
        );
        assert!(err.contains("constant: constant over the samples"), "{err}");
    }
    let (code, _, err) = fit_in(dir.path(), &["--kind", "gaussian"]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("NaN"), "{err}");
    assert!(
        err.contains("warning: plane: a linear trend reproduces this output to round-off"),
        "{err}"
    );
    assert!(!err.contains("warning: constant"), "{err}");
}

/// Writes `bounds.csv` (a, b on [0, 1]), `P.csv` with `n` points of a stratified design
/// (a in order, b permuted by `i -> (step i + shift) mod n`) and `Y.csv` with `header` and
/// the row `row(i, a, b)` of each point.
fn write_unit_square_case(
    dir: &Path,
    n: usize,
    (step, shift): (usize, usize),
    header: &str,
    row: impl Fn(usize, f64, f64) -> String,
) {
    std::fs::write(
        dir.join("bounds.csv"),
        "name,lower,upper,nominal\na,0,1,0.5\nb,0,1,0.5\n",
    )
    .unwrap();
    let mut p = String::from("a,b\n");
    let mut y = format!("{header}\n");
    for i in 0..n {
        let a = (i as f64 + 0.5) / n as f64;
        let b = (((step * i + shift) % n) as f64 + 0.5) / n as f64;
        p.push_str(&format!("{a},{b}\n"));
        y.push_str(&format!("{}\n", row(i, a, b)));
    }
    std::fs::write(dir.join("P.csv"), p).unwrap();
    std::fs::write(dir.join("Y.csv"), y).unwrap();
}
