//! End-to-end tests of `impactcal place`: the chain example of reference/shapes-efi.md §4.1,
//! node placement, placement from histories, and malformed input.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;
use common::{example, impactcal, json};

#[test]
fn place_reproduces_the_chain_example() {
    let s = example("chain_shapes.csv");
    let golden: [(&str, &[&str], f64); 3] = [
        ("5", &["2.x", "3.x", "6.x", "7.x", "10.x"], 0.203999),
        ("4", &["3.x", "6.x", "7.x", "10.x"], 0.108821),
        ("3", &["3.x", "6.x", "10.x"], 0.055298),
    ];
    for (k, kept, ratio) in golden {
        let v = json(&impactcal(&[
            "place",
            "--shape-matrix",
            s.to_str().unwrap(),
            "--sensors",
            k,
        ]));
        let selected: Vec<String> = serde_json::from_value(v["selected"].clone()).unwrap();
        assert_eq!(selected, kept);
        assert!((v["determinant_ratio"].as_f64().unwrap() - ratio).abs() < 1e-6);
        assert_eq!(v["counts_by_direction"]["x"], kept.len());
        assert_eq!(v["counts_by_direction"]["z"], 0);
        assert!(v["condition_number"].as_f64().unwrap() >= 1.0);
        assert!(v["max_off_diagonal"].as_f64().unwrap() < 1.0);
    }
    let v = json(&impactcal(&[
        "place",
        "--shape-matrix",
        s.to_str().unwrap(),
        "--sensors",
        "3",
    ]));
    let order: Vec<&str> = v["removal_order"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["label"].as_str().unwrap())
        .collect();
    assert_eq!(order, ["1.x", "8.x", "4.x", "5.x", "9.x", "2.x", "7.x"]);
    let first = v["removal_order"][0]["score"].as_f64().unwrap();
    assert!((first - 0.128210).abs() < 1e-6);
    // keep and exclude
    let v = json(&impactcal(&[
        "place",
        "--shape-matrix",
        s.to_str().unwrap(),
        "--sensors",
        "3",
        "--keep",
        "1.x",
        "--exclude",
        "10.x,9.x",
    ]));
    let selected: Vec<String> = serde_json::from_value(v["selected"].clone()).unwrap();
    assert!(selected.contains(&"1.x".into()) && !selected.contains(&"10.x".into()));
}

#[test]
fn place_nodes_from_histories() {
    let input = example("analysis.csv");
    let v = json(&impactcal(&[
        "place",
        "--histories",
        input.to_str().unwrap(),
        "--shapes",
        "3",
        "--sensors",
        "2",
        "--nodes",
    ]));
    let selected: Vec<String> = serde_json::from_value(v["selected"].clone()).unwrap();
    assert_eq!(selected.len(), 6);
    let c = &v["counts_by_direction"];
    assert_eq!(
        (c["x"].clone(), c["y"].clone(), c["z"].clone()),
        (2.into(), 2.into(), 2.into())
    );
    assert_eq!(v["shapes"], 3);
    assert_eq!(v["candidates"], 24);
    let r = v["determinant_ratio"].as_f64().unwrap();
    assert!(r > 0.0 && r < 1.0);
    // Per DOF, 5 sensors for 3 shapes.
    let v = json(&impactcal(&[
        "place",
        "--histories",
        input.to_str().unwrap(),
        "--shapes",
        "3",
        "--sensors",
        "5",
    ]));
    assert_eq!(v["selected"].as_array().unwrap().len(), 5);
    assert_eq!(v["removal_order"].as_array().unwrap().len(), 19);
}

#[test]
fn bad_input_exits_2_naming_file_row_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("s.csv");
    std::fs::write(&bad, "label,a,b\n1.x,1,0\n2.x,0,oops\n3.x,1,1\n").unwrap();
    let out = impactcal(&[
        "place",
        "--shape-matrix",
        bad.to_str().unwrap(),
        "--sensors",
        "2",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("s.csv: row 3, column 3"), "{err}");

    let s = example("chain_shapes.csv");
    let out = impactcal(&[
        "place",
        "--shape-matrix",
        s.to_str().unwrap(),
        "--sensors",
        "2",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("3 shapes"));
    let out = impactcal(&[
        "place",
        "--shape-matrix",
        s.to_str().unwrap(),
        "--sensors",
        "3",
        "--keep",
        "11.x",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("11.x"));
    let out = impactcal(&["place", "--sensors", "3"]);
    assert_eq!(out.status.code(), Some(2));
}

/// Runs `impactcal place` on a shape matrix for `sensors` sensors with extra arguments.
fn place_matrix(matrix: &std::path::Path, sensors: &str, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "place",
        "--shape-matrix",
        matrix.to_str().unwrap(),
        "--sensors",
        sensors,
    ];
    args.extend_from_slice(extra);
    impactcal(&args)
}

fn selected(v: &serde_json::Value) -> Vec<String> {
    serde_json::from_value(v["selected"].clone()).unwrap()
}

/// `--noise` prewhitens: the selection equals that of the shape matrix whose rows are
/// divided by their sigma; equal sigmas change nothing; a very noisy DOF is avoided.
#[test]
fn noise_levels_weight_the_candidates() {
    let dir = tempfile::tempdir().unwrap();
    let shapes = example("chain_shapes.csv");
    let text = std::fs::read_to_string(&shapes).unwrap();
    let sigma = |label: &str| match label {
        "10.x" => 20.0,
        "3.x" => 4.0,
        "7.x" => 0.5,
        _ => 1.0,
    };
    let mut noise = String::from("label,sigma\n");
    let mut weighted = String::new();
    for (i, line) in text.lines().enumerate() {
        if i == 0 {
            weighted.push_str(line);
            weighted.push('\n');
            continue;
        }
        let mut fields = line.split(',');
        let label = fields.next().unwrap();
        noise.push_str(&format!("{label},{}\n", sigma(label)));
        let row: Vec<String> = fields
            .map(|v| (v.parse::<f64>().unwrap() / sigma(label)).to_string())
            .collect();
        weighted.push_str(&format!("{label},{}\n", row.join(",")));
    }
    let noise_path = dir.path().join("noise.csv");
    let weighted_path = dir.path().join("weighted.csv");
    std::fs::write(&noise_path, &noise).unwrap();
    std::fs::write(&weighted_path, &weighted).unwrap();
    let run = |extra: &[&str], matrix: &std::path::Path| json(&place_matrix(matrix, "3", extra));
    let plain = run(&[], &shapes);
    let noisy = run(&["--noise", noise_path.to_str().unwrap()], &shapes);
    let prewhitened = run(&[], &weighted_path);
    assert_eq!(selected(&noisy), selected(&prewhitened));
    assert_ne!(selected(&noisy), selected(&plain));
    assert!(selected(&plain).contains(&"10.x".to_string()));
    assert!(!selected(&noisy).contains(&"10.x".to_string()));

    let equal: String = std::iter::once("label,sigma\n".to_string())
        .chain((1..=10).map(|i| format!("{i}.x,2.5\n")))
        .collect();
    let equal_path = dir.path().join("equal.csv");
    std::fs::write(&equal_path, equal).unwrap();
    let same = run(&["--noise", equal_path.to_str().unwrap()], &shapes);
    assert_eq!(selected(&same), selected(&plain));
}

#[test]
fn bad_noise_tables_exit_2_naming_the_label() {
    let dir = tempfile::tempdir().unwrap();
    let shapes = example("chain_shapes.csv");
    let cases = [
        (
            "missing.csv",
            "label,sigma\n1.x,1\n2.x,1\n",
            "no noise level for candidate `3.x`",
        ),
        (
            "unknown.csv",
            "label,sigma\n1.x,1\n11.x,1\n",
            "`11.x`, which is not a candidate",
        ),
        ("two.csv", "label,a,b\n1.x,1,2\n", "one value column"),
        (
            "negative.csv",
            "label,sigma\n1.x,-1\n2.x,1\n3.x,1\n4.x,1\n5.x,1\n6.x,1\n7.x,1\n8.x,1\n9.x,1\n10.x,1\n",
            "1.x",
        ),
        ("text.csv", "label,sigma\n1.x,loud\n", "row 2"),
    ];
    for (name, text, expected) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        let out = place_matrix(&shapes, "3", &["--noise", path.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains(expected), "{name}: {err}");
    }
}

/// With histories the noise table is matched to the channel labels; equal levels change
/// nothing.
#[test]
fn noise_levels_apply_to_history_channels() {
    let dir = tempfile::tempdir().unwrap();
    let input = example("analysis.csv");
    let header = std::fs::read_to_string(&input).unwrap();
    let labels: Vec<&str> = header.lines().next().unwrap().split(',').skip(1).collect();
    let noise: String = std::iter::once("label,sigma\n".to_string())
        .chain(labels.iter().map(|l| format!("{},3\n", l.trim())))
        .collect();
    let path = dir.path().join("noise.csv");
    std::fs::write(&path, noise).unwrap();
    let args = [
        "place",
        "--histories",
        input.to_str().unwrap(),
        "--shapes",
        "3",
        "--sensors",
        "4",
    ];
    let plain = json(&impactcal(&args));
    let mut with = args.to_vec();
    with.extend_from_slice(&["--noise", path.to_str().unwrap()]);
    assert_eq!(selected(&json(&impactcal(&with))), selected(&plain));
}
