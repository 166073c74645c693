//! Step 5: sensitivity over time. Sobol' indices of the velocity-norm history say, at every
//! time step and aggregated over the whole history, how much of its variance each parameter
//! explains.
//!
//! `cargo run --release --example step5_sensitivity`

use faer::Mat;
use impactcal::prelude::*;

#[path = "common/impact_model.rs"]
#[allow(dead_code)]
mod impact_model;
use impact_model::{DT, ImpactModel, SAMPLES};

/// Runs the example.
pub fn main() -> impactcal::Result<()> {
    let model = ImpactModel::new()?;
    // Saltelli design: 256 base rows, 256 (d + 2) = 1024 runs, one per row.
    let design =
        SaltelliDesign::generate(model.space(), 256, SamplingMethod::ScrambledSobol, false, 4)?;
    let runs = model
        .simulate_batch(design.points.as_ref())
        .into_all()
        .map_err(|failure| failure.error)?;
    // Outputs: one row per run, one column per time step of the norm history |v(t)|.
    let norms: Vec<Vec<f64>> = runs.iter().map(Histories::norm_history).collect();
    let outputs = Mat::from_fn(runs.len(), SAMPLES, |i, k| norms[i][k]);
    let options = SobolOptions {
        parameter_names: Some(
            model
                .space()
                .names()
                .iter()
                .map(|s| s.to_string())
                .collect(),
        ),
        ..SobolOptions::default()
    };
    let s = analyze(&design.layout, outputs.as_ref(), &options)?;
    for (i, name) in s.parameters.iter().enumerate() {
        println!(
            "{name}: aggregated first-order {:.3}, total {:.3}",
            s.aggregated.first_order[i], s.aggregated.total[i]
        );
    }
    for k in [25, 100, 300] {
        println!(
            "t = {:.3} s: S1 = [{:.2}, {:.2}]",
            k as f64 * DT,
            s.first_order[k][0],
            s.first_order[k][1]
        );
    }
    Ok(())
}
