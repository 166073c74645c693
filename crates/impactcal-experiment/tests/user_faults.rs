//! Faults users met with study and loop files, each checked against what should happen:
//! a deck's `*PARAMETER` names declare its parameters, bounds equal to the model's range up
//! to round-off are accepted (the rank note: `impactcal-calibrate`'s `study::sensors` tests).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use impactcal_core::{Enrichable, Model};
use impactcal_experiment::Experiment;

fn strip_deck() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/decks/strip_drop.k"
    ))
    .unwrap()
}

/// The strip deck with its shell thickness a `*PARAMETER` `thk` = 0.1 and its yield stress
/// a `*PARAMETER` `sy`.
fn parameterised(dir: &Path) -> PathBuf {
    let text = strip_deck()
        .replacen(
            "*SECTION_SHELL\n         1         2    0.8333         5\n     0.002     0.002     0.002     0.002",
            "*PARAMETER\nR thk     0.1\n*SECTION_SHELL\n         1         2    0.8333         5\n      &thk      &thk      &thk      &thk",
            1,
        );
    assert!(text.contains("&thk"));
    let p = dir.join("param.k");
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn a_parameterised_deck_is_declared_by_its_own_names_with_round_off_bounds() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    parameterised(d);
    std::fs::write(d.join("test.csv"), "time,21.z\n0,0\n0.001,1\n").unwrap();
    // Exactly -20 % and +20 % of 0.1: the deck's own range is [0.8 * 0.1, 1.2 * 0.1] in
    // floating point, [0.08000000000000002, 0.12].
    std::fs::write(
        d.join("bounds.csv"),
        "name,lower,upper,nominal\nthk,0.08,0.12,0.1\n",
    )
    .unwrap();
    let text = "[model]\ndeck = \"param.k\"\n[space]\nbounds = \"bounds.csv\"\n[test]\ndata = \"test.csv\"\n";
    let e = Experiment::parse(text, d.join("study.toml")).unwrap();
    let built = e.build().unwrap();
    assert_eq!(built.space.names(), ["thk"]);
    let model = built.model.unwrap();
    // The lower bound itself runs (the subspace moves it onto the model's range).
    let h = model.simulate(&[0.08]).unwrap();
    assert!(h.samples() > 1);
    // The same thickness through the deck's own model: the same histories, bit for bit.
    let deck = impactcal_shell::keyword::read_deck(d.join("param.k")).unwrap();
    let direct = impactcal_shell::DeckModel::from_deck(deck, None).unwrap();
    let g = direct.simulate(&[0.08000000000000002]).unwrap();
    assert_eq!(h.data(), g.data());
    // A bound beyond round-off is still refused, naming the range.
    std::fs::write(
        d.join("bounds.csv"),
        "name,lower,upper,nominal\nthk,0.07,0.12,0.1\n",
    )
    .unwrap();
    let err = e.build().unwrap_err().to_string();
    assert!(err.contains("outside what the model accepts"), "{err}");
    // A name the deck does not have lists the closest ones.
    std::fs::write(
        d.join("bounds.csv"),
        "name,lower,upper,nominal\nthick,0.08,0.12,0.1\n",
    )
    .unwrap();
    let err = e.build().unwrap_err().to_string();
    assert!(
        err.contains("study.toml") && err.contains("closest"),
        "{err}"
    );
}

#[test]
fn an_unparameterised_deck_keeps_its_quantities_and_candidates() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("strip.k"), strip_deck()).unwrap();
    std::fs::write(d.join("test.csv"), "time,21.z\n0,0\n0.001,1\n").unwrap();
    let text = "[model]\ndeck = \"strip.k\"\n[parameters]\nthickness = \"section.1.t\"\n[test]\ndata = \"test.csv\"\n";
    let built = Experiment::parse(text, d.join("s.toml"))
        .unwrap()
        .build()
        .unwrap();
    assert_eq!(built.space.names(), ["thickness"]);
    let model = built.model.unwrap();
    let names: Vec<String> = model
        .candidates()
        .iter()
        .map(|c| c.name().to_string())
        .collect();
    assert!(names.iter().any(|n| n == "material.1.E"), "{names:?}");
    assert!(names.iter().any(|n| n == "damping"), "{names:?}");
}
