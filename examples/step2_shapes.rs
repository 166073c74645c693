//! Step 2: impact shapes. The SVD of the histories gives the few spatial patterns (impact
//! shapes) that carry the response; M2 compares the shapes of test and model, and the
//! model's shapes expand a few measured channels to all the others.
//!
//! `cargo run --release --example step2_shapes`

use impactcal::prelude::*;

/// Runs the example.
pub fn main() -> impactcal::Result<()> {
    let analysis = Histories::read_csv("examples/data/analysis.csv")?;
    let test = Histories::read_csv("examples/data/test.csv")?;
    let options = ShapeOptions::count(3);
    let a = ImpactShapes::from_histories(&analysis, &options)?;
    let t = ImpactShapes::from_histories(&test, &options)?;
    let share: Vec<String> = a
        .contributions()
        .iter()
        .map(|c| format!("{:.3}", c))
        .collect();
    println!(
        "contributions of the 3 analysis shapes: {}",
        share.join(", ")
    );
    // M2: the cosine between each analysis shape and its test partner (1: same pattern).
    let m2 = Orthogonality::between(&a, &t)?;
    for p in m2.pairs() {
        println!(
            "analysis shape {} ~ test shape {}: |M2| = {:.4}",
            p.analysis + 1,
            p.test + 1,
            p.value
        );
    }
    // Eight measured test channels, expanded to all 24 through the model's shapes.
    let measured = Histories::read_csv("examples/data/measured.csv")?;
    let expansion = Expansion::compute(&a, &measured, None)?;
    let full = expansion.histories();
    let mut worst = 0.0_f64;
    let scale = test.data().iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for (c, label) in full.labels().iter().enumerate() {
        let truth = test.channel_by_label(label)?;
        for (x, y) in full.channel(c).iter().zip(truth) {
            worst = worst.max((x - y).abs());
        }
    }
    println!(
        "expanded {} unmeasured channels from {}: largest error {:.1} % of the peak",
        full.channels(),
        measured.channels(),
        100.0 * worst / scale
    );
    Ok(())
}
