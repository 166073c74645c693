//! The shock-test loop invents no effect: two seeds of the negative control of
//! `examples/shocktest_controls.rs` (board 1 of `examples/shocktest/board.toml` driven by the
//! measured input of drop 1, the measured coloured noise, no hidden effect) end with no
//! model-form error and nothing added. The ten-seed figures are in docs/validation.md
//! ("Repeated shock tests").
#![allow(clippy::unwrap_used, clippy::expect_used)]

use impactcal::calibrate::closeloop::Verdict;

#[path = "../examples/common/shock_controls.rs"]
mod shock_controls;

#[test]
fn the_negative_control_adds_nothing() {
    for seed in [0, 1] {
        let dir = std::env::temp_dir().join(format!(
            "impactcal-shock-negative-{}-{seed}",
            std::process::id()
        ));
        let r = shock_controls::run(false, seed, &dir);
        std::fs::remove_dir_all(&dir).ok();
        assert!(r.added.is_empty(), "seed {seed}: added {:?}", r.added);
        assert_eq!(r.verdict, Verdict::NoModelFormError, "seed {seed}");
        // The calibrated model reproduces the truth to the noise's level (its relative
        // L2 on the synthetic drop is the noise's share, under 1 %).
        assert!(
            r.errors.calibration.calibrated < 0.01,
            "seed {seed}: {:?}",
            r.errors
        );
    }
}
