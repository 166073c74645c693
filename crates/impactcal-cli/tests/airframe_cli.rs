//! End-to-end tests of `impactcal airframe` and `impactcal simulate --model airframe`.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

mod common;
use common::impactcal;

use impactcal::core::Histories;

#[test]
fn list_and_presets() {
    let out = impactcal(&["airframe", "--list"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "name,group,nominal,lower,upper,unit,preset,description"
    );
    // 8 globals, 5 masses, 14 parts x 4 fields.
    assert_eq!(lines.count(), 8 + 5 + 14 * 4);
    assert!(text.contains("belly_panel.t,thickness,0.09,0.08,0.135,in,table2,"));
    assert!(text.contains("keel_beam_web.E,material,9880000,7904000,11856000,lbf/in^2,table1,"));
    assert!(text.contains("ground.friction,friction,0.3,0,0.8,,,"));
    assert!(text.contains("damping,damping,0,0,50,1/s,,"));
    assert!(text.contains("attitude.pitch,condition,0,-10,10,deg,,"));
    assert!(text.contains("mass.tail,mass,0.07,"));
    assert!(text.contains("rate.p,strain-rate,4,2,8,,,"));

    let out = impactcal(&["airframe", "--preset", "table1"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(text.lines().count(), 9);
    assert!(text.contains("lower_tail.Et,107360,161040,134200,lbf/in^2"));

    let out = impactcal(&["airframe", "--preset", "table3"]);
    assert_eq!(out.status.code(), Some(2));
    let out = impactcal(&["airframe"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn deck_and_model_runs_agree() {
    let dir = tempfile::tempdir().unwrap();
    let deck = dir.path().join("airframe.k");
    let svg = dir.path().join("parts.svg");
    let out = impactcal(&[
        "airframe",
        "--mesh",
        "coarse",
        "--end-time",
        "0.002",
        "--out",
        deck.to_str().unwrap(),
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let picture = std::fs::read_to_string(&svg).unwrap();
    assert!(picture.starts_with("<svg") && picture.contains("keel_beam_stiffener"));

    let h_deck = dir.path().join("deck.csv");
    let h_model = dir.path().join("model.csv");
    let out = impactcal(&[
        "simulate",
        "--deck",
        deck.to_str().unwrap(),
        "--out",
        h_deck.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = impactcal(&[
        "simulate",
        "--model",
        "airframe",
        "--mesh",
        "coarse",
        "--end-time",
        "0.002",
        "--out",
        h_model.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(summary.contains("1948 shells"), "{summary}");
    let a = Histories::read_csv(&h_deck).unwrap();
    let b = Histories::read_csv(&h_model).unwrap();
    assert_eq!(a.labels(), b.labels());
    assert_eq!(a.channels(), 3 * 405);
    assert_eq!(a.samples(), 21);
    for (x, y) in a.norm_history().iter().zip(b.norm_history()) {
        assert!((x - y).abs() <= 1e-4 * x.abs(), "{x} vs {y}");
    }
    // Initial vertical velocity of every sensor: 26 ft/s down.
    assert_eq!(b.value(2, 0), -312.0);

    // A thicker belly changes the response; a bad name is an input error.
    let h_set = dir.path().join("set.csv");
    let out = impactcal(&[
        "simulate",
        "--model",
        "airframe",
        "--end-time",
        "0.002",
        "--set",
        "belly_panel.t=0.135",
        "--set",
        "ground.friction=0.0",
        "--out",
        h_set.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let c = Histories::read_csv(&h_set).unwrap();
    assert_ne!(c.data(), b.data());
    let out = impactcal(&["simulate", "--model", "airframe", "--set", "belly.t=1"]);
    assert_eq!(out.status.code(), Some(2));
    let out = impactcal(&["simulate", "--model", "airframe", "--set", "roof.t=-1"]);
    assert_eq!(out.status.code(), Some(2));
}
