//! Step 3: sensor placement. The impact shapes of an ensemble of simulations choose the
//! nodes where triaxial sensors tell the shapes apart best (Kammer's effective
//! independence).
//!
//! `cargo run --release --example step3_sensors`

use impactcal::core::sampling::sample;
use impactcal::prelude::*;

#[path = "common/impact_model.rs"]
#[allow(dead_code)]
mod impact_model;
use impact_model::ImpactModel;

/// Runs the example.
pub fn main() -> impactcal::Result<()> {
    let model = ImpactModel::new()?;
    let points = sample(model.space(), SamplingMethod::LatinHypercube, 8, 2)?.points;
    let runs = model
        .simulate_batch(points.as_ref())
        .into_all()
        .map_err(|failure| failure.error)?;
    // Three triaxial sensors (whole nodes) for the three dominant shapes of the ensemble.
    let options = PlacementOptions::new(3).grouping(Grouping::Node);
    let result = place_from_histories(&runs, &ShapeOptions::count(3), &options)?;
    let p = &result.placement;
    println!("sensor nodes: {}", p.nodes.join(", "));
    println!(
        "information kept: {:.3} of all 24 channels; condition number {:.2}; largest \
         off-diagonal AutoMAC {:.3}",
        p.determinant_ratio, p.condition_number, p.max_auto_mac
    );
    Ok(())
}
