//! End-to-end tests of `impactcal convert`, `filter`, `metrics` and `check` on the ISO-MME
//! sets written by pyisomme (the core crate's fixtures), the real-data excerpts and small CSV
//! files, including the bad input a user produces: each gives one line on stderr and exit
//! code 2.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

mod common;
use common::{impactcal, json};

use std::path::{Path, PathBuf};

use impactcal::calibrate::metrics::{ChannelPair, CompareOptions, compare};
use impactcal::core::{Cfc, Histories};

fn fixture(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../impactcal-core/tests/data")
        .join(rel)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Runs the command and checks it failed on bad input with one line naming `needle`.
fn bad_input(args: &[&str], needle: &str) {
    let out = impactcal(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains(needle), "{err} lacks {needle}");
}

/// A pulse record `time,a,b` at 10 kHz from `start`, scaled by `gain`.
fn pulses(dir: &Path, name: &str, start: f64, n: usize, gain: f64) -> PathBuf {
    let labels = vec!["a".to_string(), "b".to_string()];
    let t: Vec<f64> = (0..n).map(|k| start + k as f64 * 1e-4).collect();
    let a = t
        .iter()
        .map(|t| gain * 30.0 * (-((t - 0.02) / 0.005).powi(2)).exp())
        .collect();
    let b = t
        .iter()
        .map(|t| gain * 8.0 * (-((t - 0.025) / 0.008).powi(2)).exp() * (300.0 * t).cos())
        .collect();
    let h = Histories::from_channels(labels, vec![a, b], 1e-4, start, "").unwrap();
    let path = dir.join(name);
    h.write_csv(&path).unwrap();
    path
}

#[test]
fn convert_an_isomme_zip_to_csv() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.csv");
    let run = impactcal(&[
        "convert",
        "--isomme",
        s(&fixture("isomme/iso-8859-1/T13.zip")),
        "--channels",
        "11HEAD*,*FOZB",
        "--out",
        s(&out),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(
        err.contains("[g]") && err.contains("[kN]") && err.contains("taken as 0 s"),
        "{err}"
    );
    let h = Histories::read_csv(&out).unwrap();
    assert_eq!(h.labels(), ["11HEAD0000H3ACXA", "11FEMRLE00H3FOZB"]);
    assert_eq!(h.samples(), 25);
    let set = impactcal::core::IsoMme::read(fixture("isomme/iso-8859-1/T13"), &[]).unwrap();
    assert_eq!(h.channel(1), set.channels[2].values.as_slice());
}

#[test]
fn convert_a_non_uniform_csv_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("raw.csv");
    std::fs::write(&raw, "time,x\n0,0\n0.001,1\n0.0025,2.5\n0.003,3\n0.004,4\n").unwrap();
    let out = dir.path().join("u.csv");
    let run = impactcal(&["convert", "--csv", s(&raw), "--out", s(&out)]);
    assert!(run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).contains("resampled linearly"));
    let h = Histories::read_csv(&out).unwrap();
    assert_eq!(h.samples(), 5);
    assert!((h.value(0, 2) - 2.0).abs() < 1e-12);
}

#[test]
fn filter_writes_the_library_result() {
    let dir = tempfile::tempdir().unwrap();
    let input = pulses(dir.path(), "a.csv", 0.0, 500, 1.0);
    let out = dir.path().join("f.csv");
    let run = impactcal(&[
        "filter",
        "--input",
        s(&input),
        "--cfc",
        "180",
        "--out",
        s(&out),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let expected = Histories::read_csv(&input)
        .unwrap()
        .filtered(Cfc::Cfc180)
        .unwrap();
    assert_eq!(Histories::read_csv(&out).unwrap().data(), expected.data());
}

#[test]
fn metrics_json_has_the_documented_keys_and_matches_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let test = pulses(dir.path(), "t.csv", 0.0, 600, 1.0);
    let model = pulses(dir.path(), "m.csv", -0.005, 800, 1.1);
    let v = json(&impactcal(&[
        "metrics",
        "--test",
        s(&test),
        "--analysis",
        s(&model),
        "--cfc",
        "180",
    ]));
    let ch = &v["channels"][0];
    for key in [
        "test_label",
        "model_label",
        "rel_l2",
        "rms",
        "peak_error",
        "time_of_peak_error",
    ] {
        assert!(!ch[key].is_null(), "channels[0] lacks {key}");
    }
    for (group, keys) in [
        ("sprague_geers", &["m", "p", "c"][..]),
        ("russell", &["m", "p", "c"]),
        (
            "iso18571",
            &["r", "corridor", "phase", "magnitude", "slope", "grade"],
        ),
    ] {
        for k in keys {
            assert!(!ch[group][k].is_null(), "{group}.{k}");
            assert!(!v["overall"][group][k].is_null(), "overall {group}.{k}");
            assert!(!v["q_norm"][group][k].is_null(), "q_norm {group}.{k}");
        }
    }
    assert!(v["overall"]["worst_channel"].is_string());
    // A 10 % scaling: Sprague-Geers M = 0.1 on every channel (after the same filter).
    let m = ch["sprague_geers"]["m"].as_f64().unwrap();
    assert!((m - 0.1).abs() < 1e-6, "{m}");
    let t = Histories::read_csv(&test).unwrap();
    let a = Histories::read_csv(&model).unwrap();
    let options = CompareOptions {
        cfc: Some(Cfc::Cfc180),
        ..CompareOptions::default()
    };
    let lib = compare(&t, &a, &ChannelPair::by_label(&t, &a).unwrap(), &options).unwrap();
    assert_eq!(
        v["overall"]["iso18571"]["r"].as_f64().unwrap(),
        lib.overall.iso18571.r
    );
}

#[test]
fn a_map_with_a_gain_pairs_renamed_channels() {
    let dir = tempfile::tempdir().unwrap();
    let test = pulses(dir.path(), "t.csv", 0.0, 400, 1.0);
    let model = dir.path().join("m.csv");
    std::fs::write(
        &model,
        std::fs::read_to_string(pulses(dir.path(), "x.csv", 0.0, 400, 2.0))
            .unwrap()
            .replacen("time,a,b", "time,12.z,13.z", 1),
    )
    .unwrap();
    let map = dir.path().join("map.csv");
    std::fs::write(
        &map,
        "test_label,model_label,gain\na,12.z,0.5\nb,13.z,0.5\n",
    )
    .unwrap();
    let v = json(&impactcal(&[
        "metrics",
        "--test",
        s(&test),
        "--analysis",
        s(&model),
        "--map",
        s(&map),
    ]));
    assert_eq!(v["channels"][1]["model_label"], "13.z");
    assert!(v["overall"]["rel_l2"].as_f64().unwrap() < 1e-12);
    assert_eq!(v["overall"]["iso18571"]["r"].as_f64().unwrap(), 1.0);
    std::fs::write(&map, "a,12.z\nb,14.z\n").unwrap();
    bad_input(
        &[
            "metrics",
            "--test",
            s(&test),
            "--analysis",
            s(&model),
            "--map",
            s(&map),
        ],
        "map.csv: line 2: model label `14.z`",
    );
}

#[test]
fn bad_input_is_one_line_and_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let test = pulses(dir.path(), "t.csv", 0.0, 400, 1.0);
    let late = pulses(dir.path(), "late.csv", 1.0, 400, 1.0);
    let short = pulses(dir.path(), "short.csv", 0.0, 300, 1.0);
    bad_input(
        &["metrics", "--test", s(&test), "--analysis", s(&late)],
        "no overlap in time",
    );
    bad_input(
        &["metrics", "--test", s(&test), "--analysis", s(&short)],
        "restrict the comparison window",
    );
    // ... which the window then allows, without a note; a window reaching past the test's
    // end is cut to it, and the note says so.
    for (window, note) in [("0,0.025", false), ("0.01,5", true)] {
        let out = impactcal(&[
            "metrics",
            "--test",
            s(&test),
            "--analysis",
            s(if note { &test } else { &short }),
            "--window",
            window,
        ]);
        assert!(out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(
            err.contains("note: the test has samples over [0.01, 0.0399"),
            note,
            "{window}: {err}"
        );
    }
    let back = dir.path().join("back.csv");
    std::fs::write(&back, "time,a\n0,1\n0.001,2\n0.0005,3\n").unwrap();
    bad_input(
        &[
            "filter",
            "--input",
            s(&back),
            "--cfc",
            "60",
            "--out",
            s(&dir.path().join("o.csv")),
        ],
        "row 4, column 1: time 0.0005 goes backwards",
    );
    let slow = dir.path().join("slow.csv");
    let rows: String = (0..50)
        .map(|k| format!("{},{}\n", k as f64 * 1e-3, k))
        .collect();
    std::fs::write(&slow, format!("time,a\n{rows}")).unwrap();
    bad_input(
        &[
            "filter",
            "--input",
            s(&slow),
            "--cfc",
            "1000",
            "--out",
            s(&dir.path().join("o.csv")),
        ],
        "CFC 1000 needs a sampling rate above 4167 Hz",
    );
    bad_input(
        &[
            "filter",
            "--input",
            s(&slow),
            "--cfc",
            "100",
            "--out",
            s(&dir.path().join("o.csv")),
        ],
        "not one of 60, 180, 600, 1000",
    );
    // ISO-MME: a truncated zip and a missing channel file.
    let bytes = std::fs::read(fixture("isomme/ascii/T13.zip")).unwrap();
    let cut = dir.path().join("cut.zip");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    bad_input(
        &[
            "convert",
            "--isomme",
            s(&cut),
            "--out",
            s(&dir.path().join("o.csv")),
        ],
        "cut.zip",
    );
    let set = dir.path().join("T13");
    std::fs::create_dir_all(set.join("Channel")).unwrap();
    for f in [
        "T13.mme",
        "Channel/T13.chn",
        "Channel/T13.001",
        "Channel/T13.003",
    ] {
        std::fs::copy(fixture("isomme/ascii/T13").join(f), set.join(f)).unwrap();
    }
    bad_input(
        &[
            "convert",
            "--isomme",
            s(&set),
            "--out",
            s(&dir.path().join("o.csv")),
        ],
        "T13.chn: line 3: names `Channel/T13.002`",
    );
}

/// A file of the repository's real-data excerpts (`tests/data/`).
fn real(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data")
        .join(rel)
}

#[test]
fn check_reports_a_real_record_in_the_documented_json_and_one_line_per_finding() {
    let dir = tempfile::tempdir().unwrap();
    // The drop tower's test 4 excerpt: board 4 clipped at its negative rail for two samples.
    let path = real("droptower/test4_excerpt.csv");
    let out = impactcal(&["check", "--test", s(&path), "--pre-trigger", "3.5e-4"]);
    let q = json(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    let channels = q["channels"].as_array().unwrap();
    assert_eq!(channels.len(), 6);
    for c in channels {
        for key in [
            "offset",
            "noise_std",
            "lag1",
            "white",
            "clipped",
            "spikes",
            "drift",
        ] {
            assert!(c.get(key).is_some(), "{key} missing in {c}");
        }
    }
    let board4 = channels.iter().find(|c| c["label"] == "accel_4").unwrap();
    let clip = board4["clipped"][0].as_array().unwrap();
    assert!((clip[2].as_f64().unwrap() + 71.5605456679512).abs() < 1e-9);
    assert_eq!(board4["white"], false);
    // One line per finding, each naming the file and the channel.
    assert!(err.lines().all(|l| l.starts_with(s(&path))), "{err}");
    assert_eq!(
        err.lines()
            .filter(|l| l.contains("accel_4: clipped at -7.156055e1"))
            .count(),
        1,
        "{err}"
    );
    // The Los Alamos Kolsky layout, written to a file.
    let kolsky = real("kolsky/cu_excerpt.raw");
    let json_path = dir.path().join("q.json");
    let out = impactcal(&["check", "--test", s(&kolsky), "--out", s(&json_path)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let q: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
    assert_eq!(q["channels"][1]["label"], "transmitted");
}

#[test]
fn check_refuses_bad_records_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let test = pulses(dir.path(), "t.csv", 0.0, 400, 1.0);
    bad_input(
        &["check", "--test", s(&test), "--pre-trigger", "NaN"],
        "must be a finite time",
    );
    bad_input(
        &["check", "--test", s(&test), "--pre-trigger", "0.001"],
        "at least 32 are needed",
    );
    bad_input(
        &["check", "--test", s(&test), "--acceleration", "a,z"],
        "`z` is not a channel",
    );
    let far = dir.path().join("far.csv");
    let mut text = String::from("time,a\n");
    for k in 0..100 {
        text.push_str(&format!("{},{}\n", k as f64 * 1e-6, k % 3));
    }
    text.push_str("1000,1\n");
    std::fs::write(&far, text).unwrap();
    bad_input(&["check", "--test", s(&far)], "split it at the gap");
    let raw = dir.path().join("bad.raw");
    std::fs::write(&raw, "a\tb\tc\n").unwrap();
    bad_input(&["check", "--test", s(&raw)], "row 1, column 4");
}
