//! The calibration path end to end, on the examples' toy model and its "test": compare,
//! place sensors on the shapes of an ensemble, fit a surrogate of the histories at the
//! sensors, rank the parameters by sensitivity, let CORS-RBF find the parameters on the
//! surrogate, and check the result with the model itself, before and after.
//!
//! `cargo run --release --example calibration`

use faer::Mat;
use impactcal::core::sampling::sample;
use impactcal::prelude::*;

#[path = "common/impact_model.rs"]
#[allow(dead_code)]
mod impact_model;
use impact_model::ImpactModel;

/// Root mean square difference of two equally long vectors.
fn rms(a: &[f64], b: &[f64]) -> f64 {
    let sum: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum();
    (sum / a.len() as f64).sqrt()
}

/// Runs the example.
pub fn main() -> impactcal::Result<()> {
    calibrate().map(|_| ())
}

/// The calibration path; returns the parameters it finds.
pub fn calibrate() -> impactcal::Result<Vec<f64>> {
    let test = Histories::read_csv("examples/data/test.csv")?;
    let model = ImpactModel::new()?;
    let space = model.space().clone();

    // 1. An ensemble of the model; its impact shapes place three triaxial sensors.
    let x = sample(&space, SamplingMethod::LatinHypercube, 40, 7)?.points;
    let runs = model
        .simulate_batch(x.as_ref())
        .into_all()
        .map_err(|failure| failure.error)?;
    let sensors = PlacementOptions::new(3).grouping(Grouping::Node);
    let placed = place_from_histories(&runs, &ShapeOptions::count(3), &sensors)?;
    let channels = placed.placement.selected.clone();
    println!("sensors at nodes {}", placed.placement.nodes.join(", "));

    // 2. The measured histories at the sensors, and the same channels of every run side by
    //    side (one row per run) for a surrogate of all of them at once.
    let measured: Vec<f64> = test.select(&channels)?.data().to_vec();
    let at_sensors =
        |h: &Histories| -> impactcal::Result<Vec<f64>> { Ok(h.select(&channels)?.data().to_vec()) };
    let rows: Vec<Vec<f64>> = runs.iter().map(at_sensors).collect::<Result<_, _>>()?;
    let f = Mat::from_fn(rows.len(), measured.len(), |i, k| rows[i][k]);
    let surrogate = Erbf::fit(&space, x.as_ref(), f.as_ref(), ErbfOptions::default())?;

    // 3. Sensitivity of the misfit's ingredients, on the surrogate (no more model runs).
    let design = SaltelliDesign::generate(&space, 512, SamplingMethod::ScrambledSobol, false, 8)?;
    let predicted = surrogate.predict_batch(design.points.as_ref())?;
    let s = analyze(&design.layout, predicted.as_ref(), &SobolOptions::default())?;
    println!(
        "aggregated total indices at the sensors: stiffness {:.2}, damping {:.2}",
        s.aggregated.total[0], s.aggregated.total[1]
    );

    // 4. CORS-RBF on the surrogate's misfit, then the model at the point it found.
    let misfit = |p: &[f64]| match surrogate.predict(p) {
        Ok(y) => rms(&y, &measured),
        Err(_) => f64::NAN,
    };
    let mut study = Cors::new(space.clone(), CorsOptions::with_seed(9))?;
    let found = study.minimize(misfit, 60)?.best.map(|e| e.x);
    let found = found.unwrap_or_else(|| space.nominal());

    // 5. Before and after, with the model: misfit at the sensors and M2 of all channels.
    let test_shapes = ImpactShapes::from_histories(&test, &ShapeOptions::count(3))?;
    for (name, p) in [("before", space.nominal()), ("after", found.clone())] {
        let h = model.simulate(&p)?;
        let shapes = ImpactShapes::from_histories(&h, &ShapeOptions::count(3))?;
        let m2 = Orthogonality::between(&shapes, &test_shapes)?;
        let worst = m2.pairs().iter().map(|q| q.value).fold(1.0, f64::min);
        println!(
            "{name}: stiffness {:.3}, damping {:.3}; misfit at the sensors {:.2} in/s; \
             smallest paired |M2| {:.4}",
            p[0],
            p[1],
            rms(&at_sensors(&h)?, &measured),
            worst
        );
    }
    Ok(found)
}
