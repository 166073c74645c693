//! End-to-end tests of `impactcal convert --binout` / `--nodout` on files written by LS-DYNA
//! (the runner's test data, with their licences).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

mod common;
use common::impactcal;

use impactcal::core::Histories;
use std::path::PathBuf;

fn data(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../impactcal-runner/tests/data/lsdyna")
        .join(p)
}

fn s(p: &std::path::Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn convert_lists_and_writes_binout_branches() {
    let b = data("binout/R9_3_1/binout");
    let list = impactcal(&["convert", "--binout", s(&b), "--list"]);
    assert!(
        list.status.success(),
        "{}",
        String::from_utf8_lossy(&list.stderr)
    );
    let text = String::from_utf8_lossy(&list.stdout);
    assert!(
        text.contains("glstat: 88 output times; cycle (1)"),
        "{text}"
    );
    assert!(
        text.contains("rwforc/forces: 88 output times; normal_force (1)"),
        "{text}"
    );
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m.csv");
    let run = impactcal(&[
        "convert",
        "--binout",
        s(&b),
        "--branch",
        "matsum",
        "--channels",
        "kinetic_energy,internal_energy",
        "--out",
        s(&out),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let h = Histories::read_csv(&out).unwrap();
    assert_eq!(h.channels(), 4);
    assert!(
        h.labels()
            .iter()
            .all(|l| l.ends_with("_energy") && l.contains('.'))
    );
    assert!(String::from_utf8_lossy(&run.stderr).contains("resampled"));
    // A branch that is not there names those that are; no branch says to give one.
    let bad = impactcal(&[
        "convert",
        "--binout",
        s(&b),
        "--branch",
        "nodout",
        "--out",
        s(&out),
    ]);
    assert_eq!(bad.status.code(), Some(2));
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        err.contains("no branch `nodout`") && err.contains("glstat"),
        "{err}"
    );
    let none = impactcal(&["convert", "--binout", s(&b), "--out", s(&out)]);
    assert_eq!(none.status.code(), Some(2));
    // Not a binout: a typed error naming the file, no panic.
    let junk = dir.path().join("junk");
    std::fs::write(&junk, b"\x02\x03not lsda").unwrap();
    let bad = impactcal(&["convert", "--binout", s(&junk), "--list"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("junk"));
}

#[test]
fn convert_reads_a_real_nodout() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("n.csv");
    let run = impactcal(&[
        "convert",
        "--nodout",
        s(&data("nodout/nodout")),
        "--quantity",
        "displacement",
        "--nodes",
        "8",
        "--out",
        s(&out),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let h = Histories::read_csv(&out).unwrap();
    assert_eq!(h.labels(), ["8.x", "8.y", "8.z"]);
    assert!(h.channel(2).iter().all(|&z| z == -1.5));
}
