//! The compact surrogate copy agrees with the `impactcal-erbf` interpolant it comes from.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use impactcal_core::points::from_rows;
use impactcal_cors::SurrogateKernel;
use impactcal_cors::surrogate::RbfSurrogate;
use impactcal_erbf::{RbfInterpolant, RbfOptions};
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn value_and_gradient_match_erbf(
        pts in prop::collection::vec(prop::collection::vec(0.0f64..1.0, 3), 8..20),
        q in prop::collection::vec(0.0f64..1.0, 3),
        thin in any::<bool>(),
    ) {
        let vals: Vec<f64> = pts.iter().map(|p| (3.0 * p[0]).sin() + p[1] * p[2]).collect();
        let (kernel, opts) = if thin {
            (SurrogateKernel::ThinPlate, RbfOptions::thin_plate())
        } else {
            (SurrogateKernel::Cubic, RbfOptions::cubic())
        };
        let Ok(rbf) = RbfInterpolant::fit_rows(&pts, &vals, opts) else {
            return Ok(()); // random points can be nearly degenerate
        };
        prop_assume!(rbf.pivot_ratio() > 1e-10);
        let x = from_rows(&pts, "points").unwrap();
        let s = RbfSurrogate::fit(x.as_ref(), &vals, kernel).unwrap();
        let scale = vals.iter().map(|v| v.abs()).fold(1.0, f64::max);
        let v = rbf.predict(&q).unwrap()[0];
        prop_assert!((s.value(&q) - v).abs() < 1e-8 * scale, "{} vs {v}", s.value(&q));
        let g = rbf.predict_gradient(&q).unwrap();
        let mut grad = vec![0.0; 3];
        let v2 = s.value_gradient(&q, &mut grad);
        prop_assert!((v2 - v).abs() < 1e-8 * scale);
        for j in 0..3 {
            prop_assert!((grad[j] - g[(0, j)]).abs() < 1e-6 * scale, "{grad:?}");
        }
        // Interpolation at the data.
        for (p, f) in pts.iter().zip(&vals) {
            prop_assert!((s.value(p) - f).abs() < 1e-7 * scale);
        }
    }
}

/// More centres than one evaluation block (64) and a remainder block.
#[test]
fn value_matches_erbf_with_many_centres() {
    let pts: Vec<Vec<f64>> = (0..150)
        .map(|i| {
            let t = i as f64;
            vec![
                (2f64.sqrt() * t).fract(),
                (3f64.sqrt() * t + 0.2).fract(),
                (5f64.sqrt() * t + 0.7).fract(),
            ]
        })
        .collect();
    let vals: Vec<f64> = pts
        .iter()
        .map(|p| (3.0 * p[0]).sin() + p[1] * p[2])
        .collect();
    let rbf = RbfInterpolant::fit_rows(&pts, &vals, RbfOptions::cubic()).unwrap();
    let x = from_rows(&pts, "points").unwrap();
    let s = RbfSurrogate::fit(x.as_ref(), &vals, SurrogateKernel::Cubic).unwrap();
    for q in [[0.5, 0.5, 0.5], [0.01, 0.99, 0.3], [0.9, 0.1, 0.75]] {
        let v = rbf.predict(&q).unwrap()[0];
        assert!((s.value(&q) - v).abs() < 1e-9, "{} vs {v}", s.value(&q));
    }
}
