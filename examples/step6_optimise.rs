//! Step 6: calibration by optimisation. CORS-RBF minimises the misfit between the model's
//! histories and the test's over the parameter space, spending few model runs.
//!
//! `cargo run --release --example step6_optimise`

use impactcal::prelude::*;

#[path = "common/impact_model.rs"]
#[allow(dead_code)]
mod impact_model;
use impact_model::{ImpactModel, TEST_POINT};

/// Runs the example.
pub fn main() -> impactcal::Result<()> {
    let test = Histories::read_csv("examples/data/test.csv")?;
    let model = ImpactModel::new()?;
    // Misfit: root mean square difference over every channel and sample (in/s). A failed
    // run is NaN, which the optimiser records and keeps away from.
    let misfit = |x: &[f64]| match model.simulate(x) {
        Ok(h) => {
            let n = h.data().len() as f64;
            let sum: f64 = h
                .data()
                .iter()
                .zip(test.data())
                .map(|(a, b)| (a - b).powi(2))
                .sum();
            (sum / n).sqrt()
        }
        Err(_) => f64::NAN,
    };
    let mut study = Cors::new(model.space().clone(), CorsOptions::with_seed(5))?;
    let outcome = study.minimize(misfit, 40)?;
    let before = misfit(&model.space().nominal());
    if let Some(best) = outcome.best {
        println!(
            "after {} runs: stiffness {:.4}, damping {:.4} (the test's: {}, {}); \
             misfit {:.3} in/s, at the nominal point {:.1}",
            outcome.evaluations,
            best.x[0],
            best.x[1],
            TEST_POINT[0],
            TEST_POINT[1],
            best.value.unwrap_or(f64::NAN),
            before
        );
    }
    Ok(())
}
