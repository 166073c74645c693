//! Step 4: a surrogate of whole histories. An ERBF model fitted to 30 runs predicts the z
//! velocity history of a node at new parameters in microseconds; its leave-one-out error
//! says how far to trust it.
//!
//! `cargo run --release --example step4_surrogate`

use faer::Mat;
use impactcal::core::sampling::sample;
use impactcal::erbf::ErrorSummary;
use impactcal::prelude::*;

#[path = "common/impact_model.rs"]
#[allow(dead_code)]
mod impact_model;
use impact_model::{ImpactModel, SAMPLES, TEST_POINT};

/// Runs the example.
pub fn main() -> impactcal::Result<()> {
    let model = ImpactModel::new()?;
    // Training design: 30 points of the parameter space, one per row.
    let x = sample(model.space(), SamplingMethod::LatinHypercube, 30, 3)?.points;
    let runs = model
        .simulate_batch(x.as_ref())
        .into_all()
        .map_err(|failure| failure.error)?;
    // Responses: one row per run, one column per time sample of channel 104.z.
    let histories: Vec<&[f64]> = runs
        .iter()
        .map(|h| h.channel_by_label("104.z"))
        .collect::<Result<_, _>>()?;
    let f = Mat::from_fn(runs.len(), SAMPLES, |i, k| histories[i][k]);
    let erbf = Erbf::fit(
        model.space(),
        x.as_ref(),
        f.as_ref(),
        ErbfOptions::default(),
    )?;
    let loo = ErrorSummary::new(erbf.loo_errors(LooMethod::Auto)?.as_ref(), f.as_ref());
    println!(
        "ERBF of {} runs x {} samples; leave-one-out rms error / std = {:.3}",
        runs.len(),
        SAMPLES,
        loo.relative_rms
    );
    // Against the model at the test's parameters, which no run used.
    let predicted = erbf.predict(&TEST_POINT)?;
    let truth = model.simulate(&TEST_POINT)?;
    let truth = truth.channel_by_label("104.z")?;
    let scale = truth.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let worst = predicted
        .iter()
        .zip(truth)
        .fold(0.0_f64, |m, (p, t)| m.max((p - t).abs()));
    println!(
        "at stiffness {}, damping {}: largest error {:.1} % of the peak",
        TEST_POINT[0],
        TEST_POINT[1],
        100.0 * worst / scale
    );
    Ok(())
}
