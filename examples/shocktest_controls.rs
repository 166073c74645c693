//! Does the loop on the shock-test model invent effects? The ten-seed negative control and
//! planted rattle of docs/validation.md ("Repeated shock tests"), on board 1 driven by the
//! measured input of drop 1 with the measured coloured noise (see
//! `examples/common/shock_controls.rs`).
//!
//! ```text
//! cargo run --release --example shocktest_controls [-- --seeds 10] [--only negative|planted]
//! ```
//!
//! Prints, per seed, what the loop added and its verdict on the negative control (target:
//! nothing added in at least 9 of 10) and on the planted rattle (target: a rattle added in
//! at least 8 of 10), and the time each loop took.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

#[path = "common/shock_controls.rs"]
mod shock_controls;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let seeds: u64 = args
        .iter()
        .position(|a| a == "--seeds")
        .and_then(|i| args.get(i + 1))
        .map_or(10, |s| s.parse().expect("--seeds N"));
    let only = args
        .iter()
        .position(|a| a == "--only")
        .and_then(|i| args.get(i + 1))
        .cloned();
    for planted in [false, true] {
        let name = if planted { "planted" } else { "negative" };
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        let what = if planted {
            "planted rattle"
        } else {
            "negative control"
        };
        let mut good = 0;
        for seed in 0..seeds {
            let dir = std::env::temp_dir().join(format!(
                "impactcal-shock-controls-{}-{planted}-{seed}",
                std::process::id()
            ));
            let start = Instant::now();
            let r = shock_controls::run(planted, seed, &dir);
            std::fs::remove_dir_all(&dir).ok();
            let ok = if planted {
                shock_controls::found_rattle(&r)
            } else {
                r.added.is_empty()
            };
            good += usize::from(ok);
            let added: Vec<String> = r
                .added
                .iter()
                .map(|a| format!("{} = {:.4e}", a.name, a.value))
                .collect();
            println!(
                "{what}, seed {seed}: verdict {:?}, added [{}], best candidates {:?}, error \
                 {:.3} -> {:.3}, {:.1} s\n  stopped: {}",
                r.verdict,
                added.join(", "),
                shock_controls::reasons(&r),
                r.errors.calibration.calibrated,
                r.errors.calibration.enriched,
                start.elapsed().as_secs_f64(),
                r.stopped
            );
        }
        println!(
            "{what}: {good} of {seeds} {}",
            if planted {
                "found and added the rattle"
            } else {
                "added nothing"
            }
        );
    }
}
