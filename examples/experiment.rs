//! A study file and a loop file run through the library, as a program of one's own would
//! run them: `Experiment::from_file(..)?.study(out)?` and `.close_loop(out)?`.
//!
//! `cargo run --release --example experiment [-- STUDY.toml LOOP.toml OUT]`
//!
//! Without arguments it runs `examples/study/local.toml` (the strip drop, its thickness and
//! drop speed declared, against a test dropped at -5.2 in/s) and `examples/loop/local.toml`
//! (the drop tower against a test with contact damping the model holds at zero) into
//! `target/experiment-example/`.

use std::path::{Path, PathBuf};

use impactcal::calibrate::closeloop::LoopResult;
use impactcal::calibrate::study::StudyResult;
use impactcal::experiment::{Experiment, Finished};

/// Runs the study file `study` into `out/study` and the loop file `closed_loop` into
/// `out/loop`, printing what each found.
pub fn run(
    study: &Path,
    closed_loop: &Path,
    out: &Path,
) -> impactcal::Result<(Finished<StudyResult>, Finished<LoopResult>)> {
    let s = Experiment::from_file(study)?.study(out.join("study"))?;
    println!("study: M1 {}", s.result.m1.verdict.as_str());
    // A screening study (`screen_only`) stops after M1: no reconciliation to show.
    if let (Some(errors), Some(reconcile)) = (&s.result.errors, &s.result.reconcile) {
        println!(
            "study: prediction error {:.1} % at the nominal point, {:.1} % calibrated at {:?}",
            100.0 * errors.baseline.prediction_error,
            100.0 * errors.calibrated.prediction_error,
            reconcile.calibrated
        );
    }
    println!("study: wrote {}", s.json.display());

    let l = Experiment::from_file(closed_loop)?.close_loop(out.join("loop"))?;
    println!("loop: {}", l.report.lead.join(" "));
    for added in &l.result.added {
        println!(
            "loop: added {} = {:.4} in [{:.4}, {:.4}]",
            added.name, added.value, added.lower, added.upper
        );
    }
    println!("loop: wrote {}", l.json.display());
    Ok((s, l))
}

/// Runs the example.
pub fn main() -> impactcal::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (study, closed_loop, out) = match args.as_slice() {
        [s, l, o] => (PathBuf::from(s), PathBuf::from(l), PathBuf::from(o)),
        _ => (
            PathBuf::from("examples/study/local.toml"),
            PathBuf::from("examples/loop/local.toml"),
            PathBuf::from("target/experiment-example"),
        ),
    };
    run(&study, &closed_loop, &out)?;
    Ok(())
}
