//! The closed loop on an external solver: a deck template (`examples/loop/external/drop.k`)
//! whose thickness is calibrated while its damping and floor friction are declared
//! candidates and its drop speed a held test condition, each run `impactcal simulate` as a
//! separate program on the process pool, against a test with a hidden damping. The loop
//! attributes the damping and cuts the error on the test and on a holdout at another drop
//! speed, with the same `loop.json` as the same deck run in process as a built-in model
//! with the same declarations (apart from the line that names the model).

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::path::{Path, PathBuf};

use common::impactcal;
use impactcal::core::synthetic::{Measurement, measured};
use impactcal::core::{Enrichable, Model};
use impactcal::experiment::Experiment;

/// The shipped example `examples/loop/external/<name>`.
fn example(name: &str) -> PathBuf {
    common::example_file("loop/external", name)
}

/// The hidden damping of the example's data (1/s) and the strip's thickness (mm).
const DAMPING: f64 = 150.0;
const THICKNESS: f64 = 2.1;

/// The example's data are what its comment says: the deck with damping 150 1/s, which the
/// model holds at 0, and a 2.1 mm strip, at 5 and 4 m/s, its x and z channels, white noise
/// at 40 dB (seeds 7 and 8).
#[test]
fn the_example_data_are_the_deck_with_hidden_damping() {
    let deck = Experiment::from_file(example("deck.toml")).unwrap();
    let model = deck.build().unwrap().model.unwrap();
    let truth = model.at_condition(&[("damp".into(), DAMPING)]).unwrap();
    for (file, vz, seed) in [("test.csv", -5.0, 7), ("holdout.csv", -4.0, 8)] {
        let y = truth
            .at_condition(&[("vz".into(), vz)])
            .unwrap()
            .simulate(&[THICKNESS])
            .unwrap();
        // The lateral (y) channels carry only the strip's numerical asymmetry: left out.
        let planar: Vec<String> = y
            .labels()
            .iter()
            .filter(|l| !l.ends_with(".y"))
            .cloned()
            .collect();
        let y = y.select(&planar).unwrap();
        let meas = Measurement {
            snr_db: Some(40.0),
            seed,
            ..Measurement::default()
        };
        let mut text = Vec::new();
        measured(&y, &meas)
            .unwrap()
            .write_csv_to(&mut text, file)
            .unwrap();
        if std::env::var_os("IMPACTCAL_WRITE_EXAMPLE").is_some() {
            std::fs::write(example(file), &text).unwrap();
        }
        assert_eq!(std::fs::read(example(file)).unwrap(), text, "{file}");
    }
}

/// `examples/loop/external/<name>` written into `dir` with its data, bounds and deck named
/// by absolute paths, its `[executor]` table (the last) replaced by `executor`, and
/// `extra` after `[solver]`.
fn configured(dir: &Path, name: &str, extra: &str, executor: &str) -> PathBuf {
    let text = std::fs::read_to_string(example(name)).unwrap();
    let body = match text.find("\n[executor]\n") {
        Some(at) => &text[..=at],
        None => &text,
    };
    let mut body = body.to_string();
    for f in ["test.csv", "holdout.csv", "bounds.csv", "drop.k"] {
        body = body.replace(&format!("\"{f}\""), &format!("{:?}", example(f)));
    }
    let body = body.replace("[solver]\n", &format!("[solver]\n{extra}"));
    let p = dir.join(name);
    std::fs::write(&p, format!("{body}{executor}")).unwrap();
    p
}

/// `loop.json` of `out` as JSON, with its `model` line taken out (and returned) and its
/// configuration `digest` removed (the two files differ by their model).
fn loop_json(out: &Path) -> (serde_json::Value, String) {
    let text = std::fs::read_to_string(out.join("loop.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let model = v["model"].as_str().unwrap().to_string();
    v.as_object_mut().unwrap().remove("model");
    v.as_object_mut().unwrap().remove("digest");
    (v, model)
}

fn close_loop(config: &Path, out: &Path) -> std::process::Output {
    impactcal(&[
        "close-loop",
        "--config",
        config.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ])
}

#[test]
fn an_external_solvers_loop_on_a_process_pool_attributes_the_hidden_damping() {
    let dir = tempfile::tempdir().unwrap();
    let bin = env!("CARGO_BIN_EXE_impactcal");
    let command = format!(
        "command = [{bin:?}, \"simulate\", \"--deck\", \"drop.k\", \"--out\", \"out.csv\"]\n"
    );
    let external = configured(
        dir.path(),
        "processes.toml",
        &command,
        "[executor]\nkind = \"processes\"\njobs = 2\ntimeout = 120\n",
    );
    let deck = configured(dir.path(), "deck.toml", "", "");
    let (a, b) = (dir.path().join("external"), dir.path().join("deck"));
    for (config, out) in [(&external, &a), (&deck, &b)] {
        let o = close_loop(config, out);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let ((ext, ext_model), (inp, inp_model)) = (loop_json(&a), loop_json(&b));
    assert!(ext_model.starts_with("solver "), "{ext_model}");
    assert!(inp_model.starts_with("deck "), "{inp_model}");
    assert_eq!(
        ext, inp,
        "the external loop differs from the loop in process"
    );

    assert_eq!(ext["verdict"], "attributed", "{ext:#}");
    let added = &ext["added"][0];
    assert_eq!(added["name"], "damp");
    let (value, lower, upper) = (
        added["value"].as_f64().unwrap(),
        added["lower"].as_f64().unwrap(),
        added["upper"].as_f64().unwrap(),
    );
    assert!(
        (value - DAMPING).abs() < 0.1 * DAMPING && lower < upper,
        "damp {value} [{lower}, {upper}] for {DAMPING}"
    );
    let t = ext["calibrated"]["tmm"].as_f64().unwrap();
    assert!((t - THICKNESS).abs() < 0.05, "tmm {t} for {THICKNESS}");
    for stages in [&ext["errors"]["calibration"], &ext["errors"]["holdout"]] {
        let (before, after) = (
            stages["calibrated"].as_f64().unwrap(),
            stages["enriched"].as_f64().unwrap(),
        );
        assert!(after < 0.5 * before, "error {before} -> {after}");
    }

    // Each run was the template rendered into its directory and run as a program: the
    // drop speed at the holdout's condition, the damping freed, the friction held.
    let run = a.join("runs/holdout-enriched/0");
    let deck_text = std::fs::read_to_string(run.join("drop.k")).unwrap();
    assert!(deck_text.contains("R vz,-4\n"), "{deck_text:.400}");
    assert!(deck_text.contains("R fric,0.3\n"), "{deck_text:.400}");
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("params.json")).unwrap()).unwrap();
    assert_eq!(record["names"], serde_json::json!(["tmm", "damp"]));
    assert_eq!(record["set"]["vz"], -4.0);
    assert!(run.join("stdout.txt").is_file());
}

/// The faults a user makes declaring a template's quantities are refused before any run,
/// each naming the file, the key and (where the file has it) its line.
#[test]
fn declarations_that_do_not_fit_are_refused_naming_file_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &str, &str); 6] = [
        (
            "[candidates.damp]\nlower = 0.0\nupper = 1000.0\nheld = 0.0\n",
            "[candidates.tmm]\nlower = 1.0\nupper = 3.0\nheld = 2.0\n",
            "`tmm` is also a parameter of [space]",
        ),
        (
            "[candidates.damp]\nlower = 0.0\nupper = 1000.0\nheld = 0.0\n",
            "[candidates.fric]\nlower = 0.0\nupper = 0.8\nheld = 0.9\n",
            "[candidates.fric] held: 0.9: outside the admissible range [0, 0.8]",
        ),
        (
            "[candidates.damp]\nlower = 0.0\nupper = 1000.0\nheld = 0.0\n",
            "[candidates.fric]\nlower = 0.8\nupper = 0.8\nheld = 0.8\n",
            "[candidates.fric] upper: 0.8: must exceed lower = 0.8",
        ),
        (
            "[candidates.damp]\nlower = 0.0\nupper = 1000.0\nheld = 0.0\n",
            "",
            "`<<fric>>` is neither a parameter of [space], a [candidates] entry nor a [held]",
        ),
        (
            "[candidates.damp]\nlower = 0.0\nupper = 1000.0\nheld = 0.0\n\
             [candidates.fric]\nlower = 0.0\nupper = 0.8\nheld = 0.3\n",
            "[holdout]\ndata = \"holdout.csv\"\nset = { speed = -4.0 }\n",
            "[holdout] set: `speed` is neither a [candidates] entry nor a [held] quantity",
        ),
        (
            "[candidates.damp]\nlower = 0.0\nupper = 1000.0\nheld = 0.0\n\
             [candidates.fric]\nlower = 0.0\nupper = 0.8\nheld = 0.3\n",
            "[candidates.mass]\nlower = 0.0\nupper = 1.0\nheld = 0.5\n",
            "[candidates.mass]: `mass` appears nowhere in the template",
        ),
    ];
    // A template with <<fric>> as a placeholder, the other quantities *PARAMETERs.
    let template = std::fs::read_to_string(example("drop.k"))
        .unwrap()
        .replace("R fric, 0.3\n", "")
        .replace("     &fric\n", "  <<fric>>\n");
    std::fs::write(dir.path().join("drop.k"), template).unwrap();
    std::fs::copy(example("bounds.csv"), dir.path().join("bounds.csv")).unwrap();
    std::fs::write(dir.path().join("test.csv"), "time,a\n0,1\n1,2\n").unwrap();
    for (declared, extra, needle) in cases {
        let config = dir.path().join("loop.toml");
        let holdout = if extra.starts_with("[holdout]") {
            ""
        } else {
            "[holdout]\ndata = \"test.csv\"\nset = { vz = -4.0 }\n"
        };
        std::fs::write(
            &config,
            format!(
                "[solver]\ntemplate = \"drop.k\"\n\n[space]\nbounds = \"bounds.csv\"\n\n\
                 {declared}{extra}\n[held]\nvz = -5.0\n\n[test]\ndata = \"test.csv\"\n{holdout}"
            ),
        )
        .unwrap();
        let out = dir.path().join("out");
        let o = close_loop(&config, &out);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{needle}: {err}");
        assert!(err.contains("loop.toml"), "{needle}: {err}");
        assert!(err.contains(needle), "{needle}: {err}");
        assert!(!out.join("runs").exists(), "{needle}: runs were started");
    }
}
