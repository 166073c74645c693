//! ISO/TS 18571 against objective-rating-metrics 1.3 on the 33 curve pairs of
//! `tests/data/iso18571_pairs.json` (time shifts, scalings, noise, changed shapes, curves
//! against themselves), written by `benches/peers/testdata_metrics.sh --write-fixtures`.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use impactcal_calibrate::metrics::Iso18571;
use serde_json::Value;

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn rating_and_scores_equal_objective_rating_metrics() {
    let text = include_str!("data/iso18571_pairs.json");
    let data: Value = serde_json::from_str(text).unwrap();
    let dt = data["dt"].as_f64().unwrap();
    let cases = data["cases"].as_array().unwrap();
    assert!(cases.len() >= 30);
    let iso = Iso18571::new();
    for c in cases {
        let reference = floats(&data["references"][c["reference"].as_str().unwrap()]);
        let r = iso.rate(&reference, &floats(&c["comparison"]), dt).unwrap();
        let peer = &c["peer"];
        for (name, ours) in [
            ("r", r.r),
            ("corridor", r.corridor),
            ("phase", r.phase),
            ("magnitude", r.magnitude),
            ("slope", r.slope),
        ] {
            let theirs = peer[name].as_f64().unwrap();
            assert!(
                (ours - theirs).abs() < 1e-12,
                "{}: {name} {ours} vs {theirs}",
                c["name"]
            );
        }
        // The peer's published figure is R rounded to three digits.
        let rounded = peer["r_rounded"].as_f64().unwrap();
        assert!((r.r - rounded).abs() <= 5e-4 + 1e-12, "{}", c["name"]);
    }
}
