//! `[model] kind = "lumped"` in study and loop files: the model a file builds is the lumped
//! system driven by each test's own input, the measured side carries the same labels,
//! repeated tests calibrate side by side and hold out side by side with their scatter
//! reported, and the malformed files users write are refused naming what is wrong.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use std::f64::consts::PI;
use std::path::Path;

use impactcal_core::synthetic::{Measurement, measured};
use impactcal_core::{Enrichable, Histories, Model};
use impactcal_experiment::{Experiment, ModelSpec};
use impactcal_models::lumped::{LumpedModel, LumpedSystem, REPEAT_SET};

const DT: f64 = 1e-6;
const SAMPLES: usize = 2000;

const SYSTEM: &str = "[base]\nchannel = \"bottom\"\nunit = 9806.65\n[masses]\nboard = 0.05\n\
    [springs.mount]\nbetween = [\"base\", \"board\"]\nstiffness = 1.7765e7\ndamping_ratio = 0.03\n\
    [outputs]\n\"accel_1\" = \"board\"\n";

/// A drop of `peak` (record units) and `width` (s): the base half-sine and the board's
/// response to it from the system, measured with 40 dB of white noise (seed `seed`).
fn drop(peak: f64, width: f64, seed: u64) -> Histories {
    let base: Vec<f64> = (0..SAMPLES)
        .map(|k| {
            let t = k as f64 * DT;
            if t <= width {
                peak * (PI * t / width).sin()
            } else {
                0.0
            }
        })
        .collect();
    let input =
        Histories::from_channels(vec!["bottom".into()], vec![base.clone()], DT, 0.0, "kg_n")
            .unwrap();
    let system = LumpedSystem::parse(SYSTEM, "board.toml").unwrap();
    let model = LumpedModel::new(system, &input).unwrap();
    let board = model.simulate(&model.space().nominal()).unwrap();
    let board = measured(
        &board,
        &Measurement {
            snr_db: Some(40.0),
            seed,
            ..Measurement::default()
        },
    )
    .unwrap();
    Histories::from_channels(
        vec!["bottom".into(), "accel_1".into()],
        vec![base, board.channel(0).to_vec()],
        DT,
        0.0,
        "kg_n",
    )
    .unwrap()
}

fn write_drops(d: &Path) {
    std::fs::write(d.join("board.toml"), SYSTEM).unwrap();
    for (k, (peak, width)) in [
        (20.0, 1e-4),
        (24.0, 0.9e-4),
        (22.0, 0.95e-4),
        (27.0, 0.85e-4),
    ]
    .into_iter()
    .enumerate()
    {
        drop(peak, width, k as u64)
            .write_csv(d.join(format!("drop{}.csv", k + 1)))
            .unwrap();
    }
}

fn parse(d: &Path, text: &str) -> Experiment {
    Experiment::parse(text, d.join("loop.toml")).unwrap()
}

fn refused(d: &Path, text: &str) -> String {
    match Experiment::parse(text, d.join("loop.toml")).and_then(|e| e.build().map(|_| e)) {
        Ok(_) => panic!("accepted: {text}"),
        Err(e) => e.to_string(),
    }
}

/// One test: the file's model is the lumped system driven by that test's bottom channel,
/// bit for bit; its outputs carry the test's labels, the measured side is the test's board
/// channel.
#[test]
fn a_lumped_file_builds_the_system_driven_by_its_test() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_drops(d);
    let e = parse(
        d,
        "[model]\nkind = \"lumped\"\nfile = \"board.toml\"\n[test]\ndata = \"drop1.csv\"\n",
    );
    assert!(matches!(e.spec(), ModelSpec::Lumped(_)));
    let built = e.build().unwrap();
    assert_eq!(built.space.names(), ["k_mount", "zeta_mount"]);
    assert!(
        built
            .description
            .starts_with("lumped board.toml on 1 calibration")
    );
    let model = built.model.unwrap();
    let p = model.space().nominal();
    let h = model.simulate(&p).unwrap();
    let record = Histories::read_csv(d.join("drop1.csv")).unwrap();
    let direct = LumpedModel::new(LumpedSystem::read(d.join("board.toml")).unwrap(), &record)
        .unwrap()
        .simulate(&p)
        .unwrap();
    assert_eq!(h.labels(), ["accel_1"]);
    assert_eq!(h.data(), direct.data());
    assert!(
        model
            .candidates()
            .iter()
            .any(|c| c.name() == "rattle_mount_c1_gap")
    );
    let m = e.measured().unwrap();
    assert_eq!(m.test.labels(), ["accel_1"]);
    assert_eq!(
        m.test.channel(0),
        record.channel_by_label("accel_1").unwrap()
    );
    assert!(m.holdout.is_none() && m.scatter.is_empty());
}

/// Repeated tests: two calibration drops side by side, two holdout drops at `repeat_set =
/// 1`, each channel the run of its own drop's input; the scatter between the calibration
/// drops is reported per channel, and the same labels measured.
#[test]
fn repeated_tests_calibrate_and_hold_out_side_by_side() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_drops(d);
    let e = parse(
        d,
        "[model]\nkind = \"lumped\"\nfile = \"board.toml\"\n\
         [test]\ndata = \"drop1.csv\"\nrepeats = [\"drop3.csv\"]\n\
         [holdout]\ndata = \"drop2.csv\"\nrepeats = [\"drop4.csv\"]\n",
    );
    let model = e.build().unwrap().model.unwrap();
    let p = model.space().nominal();
    let system = LumpedSystem::read(d.join("board.toml")).unwrap();
    let own = |file: &str| {
        let r = Histories::read_csv(d.join(file)).unwrap();
        LumpedModel::new(system.clone(), &r)
            .unwrap()
            .simulate(&p)
            .unwrap()
    };
    let h = model.simulate(&p).unwrap();
    assert_eq!(h.labels(), ["r1/accel_1", "r2/accel_1"]);
    assert_eq!(h.channel(0), own("drop1.csv").channel(0));
    assert_eq!(h.channel(1), own("drop3.csv").channel(0));
    let m = e.measured().unwrap();
    assert_eq!(m.test.labels(), h.labels());
    let (holdout, set) = m.holdout.unwrap();
    assert_eq!(set, [(REPEAT_SET.to_string(), 1.0)]);
    assert_eq!(holdout.labels(), h.labels());
    let held = model.at_condition(&set).unwrap().simulate(&p).unwrap();
    assert_eq!(held.channel(0), own("drop2.csv").channel(0));
    assert_eq!(held.channel(1), own("drop4.csv").channel(0));
    // The scatter of drops 1 and 3 by hand, drop 3 read at its shift on the input: the RMS
    // over samples of |y1 - y3| / sqrt(2).
    assert_eq!(m.shifts.len(), 2);
    assert_eq!(m.shifts[0], 0.0);
    let y = |f: &str| {
        Histories::read_csv(d.join(f))
            .unwrap()
            .channel_by_label("accel_1")
            .unwrap()
            .to_vec()
    };
    let dt = Histories::read_csv(d.join("drop1.csv")).unwrap().dt();
    let (y1, y3) = (
        y("drop1.csv"),
        impactcal_models::lumped::delay_exact(&y("drop3.csv"), -m.shifts[1] / dt),
    );
    let by_hand = (y1
        .iter()
        .zip(&y3)
        .map(|(a, b)| (a - b).powi(2) / 2.0)
        .sum::<f64>()
        / SAMPLES as f64)
        .sqrt();
    assert_eq!(m.scatter.len(), 1);
    assert!((m.scatter[0].rms - by_hand).abs() <= 1e-12 * by_hand);
    assert!(
        m.notes
            .iter()
            .any(|n| n.contains("scatter between the 2 calibration tests, `accel_1`"))
    );
    assert!(m.notes.iter().any(|n| n.contains("aligned on their input")));
}

#[test]
fn malformed_lumped_files_are_refused_naming_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_drops(d);
    let head = "[model]\nkind = \"lumped\"\nfile = \"board.toml\"\n";
    let test = "[test]\ndata = \"drop1.csv\"\n";
    for (text, expected) in [
        (
            format!("[model]\nkind = \"lumped\"\n{test}"),
            "needs `file = \"system.toml\"`",
        ),
        (
            format!("{head}set = {{ v0 = 1.0 }}\n{test}"),
            "[model] set and end_time: not for a lumped model",
        ),
        (
            format!("{head}[space]\nbounds = \"b.csv\"\n{test}"),
            "[space]: not for a lumped model",
        ),
        (
            format!("{head}[held]\nx = 1.0\n{test}"),
            "[candidates] and [held]: not for a lumped model",
        ),
        (
            format!("{head}{test}map = \"map.csv\"\n"),
            "[test] map: a lumped model's outputs carry the test channel names",
        ),
        (
            format!("{head}{test}[holdout]\ndata = \"drop2.csv\"\nset = {{ v0 = 1.0 }}\n"),
            "[holdout] set: a lumped test's condition is its own input",
        ),
        (
            format!("[model]\nkind = \"drop-tower\"\n{test}repeats = [\"drop2.csv\"]\n"),
            "[test] repeats applies to `[model] kind = \"lumped\"`",
        ),
        (
            format!("[model]\nkind = \"drop-tower\"\nfile = \"board.toml\"\n{test}"),
            "[model] file applies to `[model] kind = \"lumped\"`",
        ),
        (
            format!("[model]\nkind = \"drop-tower\"\n{test}[holdout]\ndata = \"drop2.csv\"\n"),
            "[holdout] set: give the holdout's condition",
        ),
        (
            format!("[model]\nkind = \"lumpy\"\n{test}"),
            "the built-in models are \"drop-tower\", \"kolsky-bar\" and \"lumped\"",
        ),
        (
            format!("{head}{test}repeats = [\"drop2.csv\"]\n[holdout]\ndata = \"drop3.csv\"\n"),
            "1 holdout tests for 2 calibration tests",
        ),
        (
            format!("[model]\nkind = \"lumped\"\nfile = \"absent.toml\"\n{test}"),
            "absent.toml",
        ),
    ] {
        let e = refused(d, &text);
        assert!(e.contains(expected), "{text}\n-> {e}");
    }
    // A test without the base channel, and one without an output channel, name the test.
    std::fs::write(d.join("nobase.csv"), "time,accel_1\n0,0\n0.000001,1\n").unwrap();
    let e = refused(d, &format!("{head}[test]\ndata = \"nobase.csv\"\n"));
    assert!(e.contains("nobase.csv") && e.contains("bottom"), "{e}");
    std::fs::write(d.join("noout.csv"), "time,bottom\n0,0\n0.000001,1\n").unwrap();
    let e = parse(d, &format!("{head}[test]\ndata = \"noout.csv\"\n"))
        .measured()
        .unwrap_err()
        .to_string();
    assert!(e.contains("noout.csv") && e.contains("accel_1"), "{e}");
    // A system file with a fault names it and its key.
    std::fs::write(
        d.join("bad.toml"),
        SYSTEM.replace("board = 0.05", "board = -0.05"),
    )
    .unwrap();
    let e = refused(
        d,
        &format!("[model]\nkind = \"lumped\"\nfile = \"bad.toml\"\n{test}"),
    );
    assert!(e.contains("bad.toml") && e.contains("masses.board"), "{e}");
}
