//! Step 1 of the calibration path: time histories. Read a test, run a model at its nominal
//! point and over an ensemble, and run the built-in explicit solver on a deck.
//!
//! `cargo run --release --example step1_histories`

use impactcal::core::NodalQuantity;
use impactcal::core::sampling::sample;
use impactcal::prelude::*;
use impactcal::shell::keyword::read_deck;

#[path = "common/impact_model.rs"]
#[allow(dead_code)]
mod impact_model;
use impact_model::ImpactModel;

/// Runs the example.
pub fn main() -> impactcal::Result<()> {
    // Measured data: wide CSV `time,<node>.<axis>,...` on a uniform time step.
    let test = Histories::read_csv("examples/data/test.csv")?;
    println!(
        "test: {} channels x {} samples, dt = {} s",
        test.channels(),
        test.samples(),
        test.dt()
    );
    // A model maps a parameter vector to histories; here the examples' toy model.
    let model = ImpactModel::new()?;
    let nominal = model.simulate(&model.space().nominal())?;
    // The z velocity of node 104 at 10 ms (sample 50), test against model.
    let at_10ms =
        |h: &Histories| -> impactcal::Result<f64> { Ok(h.channel_by_label("104.z")?[50]) };
    println!(
        "104.z at 10 ms: test {:.1}, model at nominal {:.1} in/s",
        at_10ms(&test)?,
        at_10ms(&nominal)?
    );
    // An ensemble: a Latin hypercube of 16 points (one per row), run in parallel.
    let points = sample(model.space(), SamplingMethod::LatinHypercube, 16, 1)?.points;
    let runs = model
        .simulate_batch(points.as_ref())
        .into_all()
        .map_err(|failure| failure.error)?;
    let values: Vec<f64> = runs.iter().map(at_10ms).collect::<Result<_, _>>()?;
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    println!(
        "ensemble of {}: 104.z at 10 ms from {lo:.1} to {hi:.1} in/s",
        runs.len()
    );
    // The built-in explicit solver gives histories the same way, from an LS-DYNA deck.
    let deck = read_deck("examples/decks/strip_drop.k")?;
    let run = Simulation::new(&deck.model)?.run()?;
    if let Some(v) = run.histories(NodalQuantity::Velocity) {
        let vz = v.channel_by_label("21.z")?;
        println!(
            "strip drop: node 21 lands at {:.2} m/s and ends at {:.2} m/s",
            vz[0],
            vz[vz.len() - 1]
        );
    }
    Ok(())
}
