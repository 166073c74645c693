//! End to end through the facade: a `Model` simulated over an ensemble in parallel, impact
//! shapes of the ensemble, M2 between a perturbed "test" and the nominal model, and the
//! expansion of a few measured channels of the test to all others.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use impactcal::prelude::*;

/// A beam of `n` nodes whose z velocity is a sum of two damped modes with stiffness scale
/// `k` and a mass scale `m`.
struct Beam {
    space: ParameterSpace,
    nodes: usize,
}

impl Model for Beam {
    fn space(&self) -> &ParameterSpace {
        &self.space
    }

    fn simulate(&self, p: &[f64]) -> impactcal::core::Result<Histories> {
        let (k, m) = (p[0], p[1]);
        let labels = (0..self.nodes).map(|i| format!("{}.z", i + 1)).collect();
        let channels = (0..self.nodes)
            .map(|i| {
                let s = (i as f64 + 0.5) / self.nodes as f64;
                (0..300)
                    .map(|j| {
                        let t = j as f64 * 1e-4;
                        (1..=2)
                            .map(|mode| {
                                let w = 2.0
                                    * std::f64::consts::PI
                                    * 60.0
                                    * mode as f64
                                    * (k / m).sqrt();
                                (std::f64::consts::PI * s * mode as f64).sin()
                                    * (-0.05 * w * t).exp()
                                    * (w * t).sin()
                                    / mode as f64
                            })
                            .sum()
                    })
                    .collect()
            })
            .collect();
        Histories::from_channels(labels, channels, 1e-4, 0.0, "in/s")
    }
}

#[test]
fn ensemble_shapes_metric_and_expansion() {
    let beam = Beam {
        space: ParameterSpace::new(vec![
            Parameter::new("k", 0.8, 1.2, 1.0).unwrap(),
            Parameter::new("m", 0.9, 1.1, 1.0).unwrap(),
        ])
        .unwrap(),
        nodes: 20,
    };
    let points: Vec<Vec<f64>> = (0..16)
        .map(|i| {
            beam.space()
                .from_unit(&[(i as f64 + 0.5) / 16.0, 0.5])
                .unwrap()
        })
        .collect();
    let runs = beam.simulate_batch(&points).into_all().unwrap();
    assert_eq!(runs.len(), 16);
    // Parallel batch results equal sequential runs.
    assert_eq!(runs[5], beam.simulate(&points[5]).unwrap());

    let nominal = beam.simulate(&beam.space().nominal()).unwrap();
    let test = beam.simulate(&[1.1, 0.95]).unwrap();
    let a = ImpactShapes::from_histories(&nominal, &ShapeOptions::count(2)).unwrap();
    let t = ImpactShapes::from_histories(&test, &ShapeOptions::count(2)).unwrap();
    // The spatial patterns do not depend on k and m: M2 pairs them perfectly.
    let m2 = Orthogonality::between(&a, &t).unwrap();
    assert_eq!(m2.matched_above(0.9), 2);
    for p in m2.pairs() {
        assert!(p.value > 0.99, "{p:?}");
    }
    // Six measured channels determine the two shapes; expansion recovers the rest exactly.
    let measured = test
        .select(&["2.z", "5.z", "9.z", "12.z", "16.z", "19.z"])
        .unwrap();
    let e = Expansion::compute(&a, &measured, None).unwrap();
    for (c, label) in e.histories().labels().iter().enumerate() {
        let truth = test.channel_by_label(label).unwrap();
        for (x, y) in e.histories().channel(c).iter().zip(truth) {
            assert!((x - y).abs() < 1e-9, "{label}: {x} vs {y}");
        }
    }
}
