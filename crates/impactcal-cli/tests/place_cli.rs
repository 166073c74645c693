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
