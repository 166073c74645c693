//! Test data against the peers' own output (`tests/data/`, written by
//! `benches/peers/testdata_metrics.sh --write-fixtures`): the CFC filters against pyisomme's
//! ISO-6487 filter, and ISO-MME data sets written by pyisomme (transcoded into four encodings,
//! as folders and zip archives) read back with pyisomme's values, codes and units. Then the
//! malformed sets a user meets: a missing channel file, a non-numeric sample, a zero sampling
//! interval, a truncated zip.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use std::path::{Path, PathBuf};

use impactcal_core::testdata::TextEncoding;
use impactcal_core::{Cfc, CoreError, IsoMme};
use serde_json::Value;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn cfc_filters_equal_pyisomme_iso_6487() {
    let text = std::fs::read_to_string(data("cfc_pyisomme.json")).unwrap();
    let cases: Value = serde_json::from_str(&text).unwrap();
    let cases = cases["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 16);
    for c in cases {
        let cfc = Cfc::from_class(c["cfc"].as_u64().unwrap() as u32).unwrap();
        let ours = cfc
            .filter(&floats(&c["input"]), c["dt"].as_f64().unwrap(), "case")
            .unwrap();
        let theirs = floats(&c["output"]);
        let peak = theirs.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let worst = ours
            .iter()
            .zip(&theirs)
            .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        // The fixture keeps 10 significant digits; the filters agree to 1e-10 of the peak.
        assert!(
            worst < 1e-9 * peak,
            "{} {cfc}: {worst} of peak {peak}",
            c["name"]
        );
    }
}

#[test]
fn isomme_sets_written_by_pyisomme_read_back_alike() {
    let text = std::fs::read_to_string(data("isomme/expected.json")).unwrap();
    let expected: Value = serde_json::from_str(&text).unwrap();
    let encodings = [
        ("ascii", TextEncoding::Ascii),
        ("utf-8", TextEncoding::Utf8),
        ("iso-8859-1", TextEncoding::Latin1),
        ("windows-1252", TextEncoding::Windows1252),
    ];
    for (label, encoding) in encodings {
        let sets = expected[label].as_array().unwrap();
        assert_eq!(sets.len(), 2, "{label}: folder and zip");
        for e in sets {
            let rel = e["path"].as_str().unwrap().trim_start_matches("isomme/");
            let set = IsoMme::read(data("isomme").join(rel), &[]).unwrap();
            assert_eq!(set.encoding, encoding, "{rel}");
            let lab = set
                .test_info
                .iter()
                .find(|(k, _)| k == "Laboratory name")
                .unwrap();
            assert_eq!(lab.1.as_deref(), e["laboratory"].as_str(), "{rel}");
            let channels = e["channels"].as_array().unwrap();
            assert_eq!(set.channels.len(), channels.len());
            for (ours, theirs) in set.channels.iter().zip(channels) {
                assert_eq!(ours.code, theirs["code"].as_str().unwrap());
                assert_eq!(ours.unit, theirs["unit"].as_str().unwrap());
                assert_eq!(ours.name.as_deref(), theirs["name"].as_str());
                assert_eq!(
                    ours.values,
                    floats(&theirs["values"]),
                    "{rel} {}",
                    ours.code
                );
                let time = floats(&theirs["time"]);
                assert!((ours.start - time[0]).abs() < 1e-15);
                assert!((ours.dt - (time[1] - time[0])).abs() < 1e-15);
                // pyisomme leaves out the time of the first sample; both take 0 s, and
                // we say so.
                assert!(
                    ours.notes
                        .iter()
                        .any(|n| n.contains("time of first sample"))
                );
            }
            let (h, _) = set.to_histories().unwrap();
            assert_eq!(h.labels()[0], "11HEAD0000H3ACXA");
            assert_eq!(h.samples(), 25);
        }
    }
    // A selection by pattern.
    let set = IsoMme::read(
        data("isomme/utf-8/T13.zip"),
        &["11CHST*".into(), "*FOZB".into()],
    )
    .unwrap();
    let codes: Vec<&str> = set.channels.iter().map(|c| c.code.as_str()).collect();
    assert_eq!(codes, ["11CHST0000H3DSXB", "11FEMRLE00H3FOZB"]);
    // Units differ: the histories carry none and the notes say so.
    let (h, notes) = set.to_histories().unwrap();
    assert_eq!(h.unit(), "");
    assert!(notes[0].contains("units differ"));
}

/// A copy of the ASCII set in a fresh temporary folder.
fn copy_set() -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let src = data("isomme/ascii/T13");
    let dst = dir.path().join("T13");
    std::fs::create_dir_all(dst.join("Channel")).unwrap();
    std::fs::copy(src.join("T13.mme"), dst.join("T13.mme")).unwrap();
    for f in std::fs::read_dir(src.join("Channel")).unwrap() {
        let f = f.unwrap();
        std::fs::copy(f.path(), dst.join("Channel").join(f.file_name())).unwrap();
    }
    (dir, dst)
}

fn edit(path: &Path, from: &str, to: &str) {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.contains(from), "{from} not in {}", path.display());
    std::fs::write(path, text.replacen(from, to, 1)).unwrap();
}

#[test]
fn a_missing_channel_file_names_the_index_line() {
    let (_dir, set) = copy_set();
    std::fs::remove_file(set.join("Channel/T13.002")).unwrap();
    match IsoMme::read(&set, &[]).unwrap_err() {
        CoreError::MissingFile {
            file,
            line,
            missing,
        } => {
            assert!(file.ends_with("T13.chn"));
            assert_eq!(line, 3);
            assert!(missing.ends_with("Channel/T13.002"));
        }
        e => panic!("unexpected {e}"),
    }
    // Selecting the other channels reads fine.
    assert!(IsoMme::read(&set, &["11HEAD*".into()]).is_ok());
}

#[test]
fn a_non_numeric_sample_names_file_and_line() {
    let (_dir, set) = copy_set();
    let file = set.join("Channel/T13.003");
    let text = std::fs::read_to_string(&file).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let k = lines.len() - 3;
    let mut broken = lines.clone();
    broken[k] = "1.2.3";
    std::fs::write(&file, broken.join("\n")).unwrap();
    match IsoMme::read(&set, &[]).unwrap_err() {
        CoreError::Line {
            file,
            line,
            message,
        } => {
            assert!(file.ends_with("T13.003"));
            assert_eq!(line, k + 1);
            assert!(message.contains("1.2.3"));
        }
        e => panic!("unexpected {e}"),
    }
}

#[test]
fn a_zero_sampling_interval_names_file_and_line() {
    let (_dir, set) = copy_set();
    edit(
        &set.join("Channel/T13.001"),
        "Sampling interval           :0.0005",
        "Sampling interval           :0",
    );
    let e = IsoMme::read(&set, &[]).unwrap_err();
    assert!(matches!(e, CoreError::Line { line: 1, .. }), "{e}");
    assert!(
        e.to_string()
            .contains("T13.001: line 1: sampling interval 0 must be positive"),
        "{e}"
    );
}

#[test]
fn a_truncated_zip_is_an_archive_error() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = std::fs::read(data("isomme/utf-8/T13.zip")).unwrap();
    let cut = dir.path().join("T13.zip");
    std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
    let e = IsoMme::read(&cut, &[]).unwrap_err();
    assert!(matches!(e, CoreError::Archive { .. }), "{e}");
    assert!(e.to_string().contains("T13.zip"));
}

#[test]
fn a_dropped_sample_is_filled_and_reported() {
    let (_dir, set) = copy_set();
    let file = set.join("Channel/T13.003");
    let text = std::fs::read_to_string(&file).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let k = lines.len() - 5;
    let (a, b): (f64, f64) = (lines[k - 1].parse().unwrap(), lines[k + 1].parse().unwrap());
    lines[k] = "NOVALUE".into();
    std::fs::write(&file, lines.join("\n")).unwrap();
    let read = IsoMme::read(&set, &[]).unwrap();
    let c = &read.channels[2];
    let n = c.values.len();
    assert!((c.values[n - 5] - 0.5 * (a + b)).abs() < 1e-12);
    assert!(c.notes.iter().any(|n| n.contains("1 dropped sample")));
}
