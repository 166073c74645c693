//! Runs the closed loop on the drop-tower model against a test with hidden structural damping
//! (measured late, with a wrong gain on one channel and 40 dB of white noise) and a holdout
//! at another drop speed, and writes the loop's report with its provenance. The
//! headless-browser check (`tests/browser/check_report.sh`) renders it; about 10 s.
//!
//! ```text
//! cargo run --example loop_report -- OUT_DIR
//! ```

use std::path::PathBuf;
use std::time::Instant;

use impactcal::calibrate::closeloop::document::report_with;
use impactcal::calibrate::closeloop::{Holdout, LoopOptions, run_loop};
use impactcal::calibrate::report::{self, Provenance};
use impactcal::calibrate::study::{Silent, TestData};
use impactcal::core::drop_tower::DropTower;
use impactcal::core::synthetic::{Measurement, measured};
use impactcal::core::{Enrichable, Model};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let started = Instant::now();
    let out: PathBuf = std::env::args()
        .nth(1)
        .ok_or("usage: loop_report OUT_DIR")?
        .into();
    let model = DropTower::new();
    let truth = model.at_condition(&[("damping".into(), 0.03)])?;
    let point = [75.0, 9e5];
    let measure = |m: &DropTower, seed: u64| {
        measured(
            &m.simulate(&point)?,
            &Measurement {
                time_shift: 3e-4,
                gains: vec![("a2".into(), 1.1)],
                snr_db: Some(40.0),
                seed,
                ..Measurement::default()
            },
        )
    };
    let set = [("v0".to_string(), 5.5)];
    let test = measure(&truth, 1)?;
    let holdout = measure(&truth.at_condition(&set)?, 1001)?;
    let journal = out.join("journal");
    std::fs::create_dir_all(&journal)?;
    let result = run_loop(
        &model,
        "drop tower",
        TestData {
            histories: &test,
            map: None,
            cfc: None,
        },
        Some(Holdout {
            histories: &holdout,
            set: &set,
        }),
        &LoopOptions::default(),
        &journal,
        &Silent,
    )?;
    let provenance = Provenance::now(
        std::env::args().collect::<Vec<_>>().join(" "),
        result.digest.clone(),
        result.seed,
        started.elapsed().as_secs_f64(),
    );
    let doc = report_with(&result, None, Some(&provenance));
    let files = report::write(&doc, &out)?;
    println!("{}", files.html.display());
    Ok(())
}
