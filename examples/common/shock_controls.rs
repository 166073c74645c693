//! The negative control and the planted rattle of the shock-test loop (docs/validation.md,
//! "Repeated shock tests"): synthetic drops of board 1 of `examples/shocktest/board.toml` (`board1.toml`)
//! driven by the measured input of drop 1 (repaired as the loop repairs it), with the
//! coloured noise measured on that board's accelerometer before the drop.
//!
//! - **Negative control**: the truth is the model itself at its nominal point; the loop
//!   must add nothing.
//! - **Planted rattle**: the truth has a two-sided gap contact between the board and the
//!   canister, of penalty stiffness 10 times the mount's and a clearance of a quarter of
//!   `d_s` (the mount's quasi-static stretch at the peak input, `a_pk m / k`; the board's
//!   travel in the nominal run is about 1.24 `d_s`, so the gap closes on every drop); the
//!   loop must find and add it.
//!
//! Both use the loop's default options but for the seed; the truth's stiffness and damping
//! are the file's nominal values, which the loop calibrates from its own start.

use std::path::{Path, PathBuf};

use impactcal::calibrate::closeloop::{LoopOptions, LoopResult, run_loop};
use impactcal::calibrate::study::{Silent, TestData};
use impactcal::core::quality::{QualityOptions, check};
use impactcal::core::{Enrichable, Histories, Model};
use impactcal::models::lumped::{LumpedModel, LumpedSystem};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// The board of the controls and its channel.
pub const BOARD: &str = "accel_1";

/// The shock-test example's folder.
pub fn folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/shocktest")
}

/// Drop 1 of the example's data.
fn drop1() -> Histories {
    Histories::read_csv(folder().join("data/drop1.csv")).expect("drop 1")
}

/// Board 1 of `board.toml` alone (`board1.toml`: the same base, mass, mount and output).
pub fn system() -> LumpedSystem {
    LumpedSystem::read(folder().join("board1.toml")).expect("board1.toml")
}

/// The model of board 1 driven by drop 1's bottom accelerometer, offset removed and spikes
/// bridged ([`impactcal::core::quality::RecordQuality::repaired`]).
pub fn model() -> LumpedModel {
    let record = drop1();
    let input = record.select(&["accel_bottom"]).expect("input");
    let repaired = check(&input, &QualityOptions::default())
        .and_then(|q| q.repaired(&input))
        .expect("repaired input");
    LumpedModel::new(system(), &repaired).expect("model")
}

/// The truth: the model at its nominal point, with the planted rattle or without.
pub fn truth(model: &LumpedModel, planted: bool) -> Histories {
    let m = if planted {
        let k = system().springs[0].stiffness;
        model
            .at_condition(&[
                ("rattle_mount1_c1_stiffness".into(), 10.0 * k),
                ("rattle_mount1_c1_gap".into(), 0.25 * model.reach()[0]),
            ])
            .expect("planted rattle")
    } else {
        model.clone()
    };
    m.simulate(&m.space().nominal()).expect("truth")
}

/// The truth plus a draw (seed `seed`) of the coloured noise measured on board 1's
/// accelerometer before drop 1 (its AR model, order by BIC).
pub fn measured(truth: &Histories, seed: u64) -> Histories {
    let board = drop1().select(&[BOARD]).expect("board channel");
    let q = check(&board, &QualityOptions::default()).expect("quality");
    let noise = q.channels[0]
        .noise_model
        .clone()
        .expect("a quiet part before the drop");
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let e = noise.generate(truth.samples(), &mut rng);
    let y: Vec<f64> = truth
        .channel(0)
        .iter()
        .zip(&e)
        .map(|(a, b)| a + b)
        .collect();
    Histories::from_channels(
        vec![BOARD.into()],
        vec![y],
        truth.dt(),
        truth.start(),
        truth.unit(),
    )
    .expect("measured")
}

/// The loop on the synthetic drop of `seed` (planted rattle or not), in `dir`.
pub fn run(planted: bool, seed: u64, dir: &Path) -> LoopResult {
    let model = model();
    let test = measured(&truth(&model, planted), seed);
    let options = LoopOptions {
        seed,
        ..LoopOptions::default()
    };
    let data = TestData {
        histories: &test,
        map: None,
        cfc: None,
    };
    run_loop(&model, "shock control", data, None, &options, dir, &Silent).expect("loop")
}

/// Why the first attribution's three best candidates were or were not added: name,
/// status, explained fraction.
#[allow(dead_code)]
pub fn reasons(r: &LoopResult) -> Vec<(String, String, f64)> {
    r.candidates
        .iter()
        .filter(|s| s.kind == "candidate")
        .take(3)
        .map(|s| (s.name.clone(), s.status.clone(), s.explained_fraction))
        .collect()
}

/// Whether a loop added a rattle of board 1 (its stiffness or its gap).
#[allow(dead_code)]
pub fn found_rattle(r: &LoopResult) -> bool {
    r.added.iter().any(|a| a.name.starts_with("rattle_mount1"))
}
