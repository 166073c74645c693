//! End-to-end tests of `impactcal noise` on the shipped deck, on the airframe and on bad
//! input.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

mod common;
use common::{example_file, impactcal};

use impactcal::core::Model;
use impactcal::core::noise::{JitterOptions, SimulationNoise};
use impactcal::shell::DeckModel;
use impactcal::shell::keyword::read_deck;

fn read(path: &std::path::Path) -> SimulationNoise {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// The command's result on a deck is the library's jitter ensemble on the same deck,
/// number for number, and does not depend on the thread count.
#[test]
fn noise_of_a_deck_equals_the_library_ensemble() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("noise.json");
    let deck = example_file("decks", "strip_drop.k");
    let run = |threads: &str| {
        let o = impactcal(&[
            "noise",
            "--deck",
            deck.to_str().unwrap(),
            "--runs",
            "4",
            "--eps",
            "1e-3",
            "--seed",
            "5",
            "--cfc",
            "1000",
            "--threads",
            threads,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stderr).to_string()
    };
    let log = run("1");
    assert!(
        log.contains("relative spread") && log.contains("z, 2"),
        "{log}"
    );
    let one = read(&out);
    run("2");
    assert_eq!(read(&out), one);
    let model = DeckModel::new(read_deck(&deck).unwrap().model).unwrap();
    let options = JitterOptions::new(4, 1e-3, 5).with_cfc(impactcal::core::Cfc::Cfc1000);
    let lib = SimulationNoise::measure(&model, &model.space().nominal(), &options).unwrap();
    assert_eq!(one, lib);
    assert_eq!(one.labels, ["21.x", "21.y", "21.z", "42.x", "42.y", "42.z"]);
    assert_eq!(
        one.parameters,
        [
            "section.1.t",
            "material.1.E",
            "material.1.sigy",
            "material.1.Et"
        ]
    );
    assert!(one.spread.iter().flatten().any(|&s| s > 0.0));
}

/// The airframe with a preset: 1,215 channels, horizons grouped by part and axis.
#[test]
fn noise_of_the_airframe_groups_channels_by_part() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("af.json");
    let o = impactcal(&[
        "noise",
        "--model",
        "airframe",
        "--preset",
        "table2",
        "--end-time",
        "0.002",
        "--runs",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    let log = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{log}");
    let noise = read(&out);
    assert_eq!(noise.channels(), 1215);
    assert_eq!(noise.parameters.len(), 6);
    assert_eq!(noise.options.runs, 2);
    assert!(
        log.contains("belly_panel.z,") && log.contains("tail_boom.x,"),
        "{log}"
    );
}

#[test]
fn bad_input_exits_with_code_two_and_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("n.json");
    let out = out.to_str().unwrap();
    let deck = example_file("decks", "strip_drop.k");
    let deck = deck.to_str().unwrap();
    let no_history = dir.path().join("quiet.k");
    let text = std::fs::read_to_string(deck)
        .unwrap()
        .replace("*DATABASE_HISTORY_NODE\n        21        42\n", "");
    std::fs::write(&no_history, text).unwrap();
    // A deck the solver refuses is named with what is wrong, before any run and before
    // its zero modulus could make empty bounds.
    let soft = dir.path().join("soft.k");
    let text = std::fs::read_to_string(deck)
        .unwrap()
        .replace("2.1e+11", "0.0    ");
    std::fs::write(&soft, text).unwrap();
    for (args, needle) in [
        (
            vec!["--deck", soft.to_str().unwrap()],
            "soft.k: material 1, Young's modulus: must be finite and positive",
        ),
        (vec!["--deck", deck, "--runs", "1"], "at least 2 runs"),
        (vec!["--deck", deck, "--eps", "0"], "eps"),
        (vec!["--deck", deck, "--fraction", "0"], "--fraction"),
        (vec!["--deck", deck, "--cfc", "20000"], "not one of 60"),
        (
            vec!["--deck", no_history.to_str().unwrap()],
            "history nodes",
        ),
        (vec!["--model", "airframe", "--preset", "table9"], "table9"),
        (vec!["--model", "airframe", "--set", "belly.t=1"], "belly.t"),
    ] {
        let mut all = vec!["noise", "--out", out];
        all.extend(args);
        let o = impactcal(&all);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{all:?}: {err}");
        let errors: Vec<&str> = err.lines().filter(|l| !l.contains("warning")).collect();
        assert_eq!(errors.len(), 1, "{err}");
        assert!(err.contains(needle), "{all:?}: {err}");
    }
    // An unreadable deck is an I/O failure (exit 1), as for `simulate`.
    let o = impactcal(&["noise", "--out", out, "--deck", "missing.k"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("missing.k"));
}
