//! The scalar test form against truth: a synthetic model with outputs in very different
//! units, a test made of its own outputs at a known point, and the bad inputs a user makes.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use std::collections::BTreeMap;

use impactcal_calibrate::CalibrateError;
use impactcal_calibrate::scalar::{
    Scalar, ScalarOptions, ScalarRuns, ScalarTest, calibrate, misfit_of,
};
use impactcal_core::sampling::sample;
use impactcal_core::{Parameter, ParameterSpace, SamplingMethod};

/// Three parameters (a thickness in mm, a yield stress in MPa, a friction coefficient).
fn space() -> ParameterSpace {
    ParameterSpace::new(vec![
        Parameter::new("t", 1.0, 3.0, 2.0).unwrap(),
        Parameter::new("sy", 300.0, 500.0, 400.0).unwrap(),
        Parameter::new("mu", 0.0, 0.4, 0.2).unwrap(),
    ])
    .unwrap()
}

const NAMES: [&str; 4] = ["dmax", "fmax", "vfin", "IE"];

/// Smooth outputs in the units of a crash: an intrusion (mm), a peak force (N), a final
/// velocity (mm/s, small beside the others) and an energy (N mm, ~1e8).
fn model(p: &[f64]) -> [f64; 4] {
    let (t, sy, mu) = (p[0], p[1] / 400.0, p[2]);
    [
        -900.0 / (t * sy.sqrt()) - 80.0 * mu,
        2.0e5 * t * sy + 1.0e5 * mu * t,
        -700.0 + 900.0 * mu - 150.0 * (t - 2.0) * sy,
        1.0e8 * (1.0 + 0.1 * (t - 2.0) + 0.05 * (sy - 1.0) + 0.2 * mu * mu),
    ]
}

fn outputs(y: [f64; 4]) -> BTreeMap<String, f64> {
    NAMES.iter().map(|n| n.to_string()).zip(y).collect()
}

fn runs(n: usize) -> ScalarRuns {
    let s = sample(&space(), SamplingMethod::ScrambledHalton, n, 7).unwrap();
    let points: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..3).map(|j| s.points[(i, j)]).collect())
        .collect();
    let values = points.iter().map(|p| model(p).to_vec()).collect();
    ScalarRuns {
        names: NAMES.iter().map(|n| n.to_string()).collect(),
        points,
        values,
    }
}

/// The test: the model's own outputs at a point away from the nominal one, each scalar's
/// scale its spread over the runs.
fn test_at(truth: &[f64], r: &ScalarRuns) -> ScalarTest {
    let y = model(truth);
    ScalarTest::new(
        NAMES
            .iter()
            .enumerate()
            .map(|(k, n)| {
                let col: Vec<f64> = r.values.iter().map(|v| v[k]).collect();
                let m = col.iter().sum::<f64>() / col.len() as f64;
                let sd = (col.iter().map(|v| (v - m).powi(2)).sum::<f64>()
                    / (col.len() - 1) as f64)
                    .sqrt();
                Scalar::new(*n, y[k], sd)
            })
            .collect(),
    )
    .unwrap()
}

#[test]
fn finds_the_known_point_from_outputs_in_mixed_units() {
    let truth = [2.6, 340.0, 0.1];
    let r = runs(40);
    let test = test_at(&truth, &r);
    let cal = calibrate(&space(), &test, &r, &ScalarOptions::default()).unwrap();
    // The true model at the nominal and calibrated points, judged against the test.
    let before = test
        .errors(&outputs(model(&space().nominal())), "nominal")
        .unwrap();
    let after = test
        .errors(&outputs(model(&cal.calibrated_point)), "calibrated")
        .unwrap();
    let (j0, j1) = (misfit_of(&before), misfit_of(&after));
    assert!(j0 > 1.0, "the nominal point is far from the test: J {j0}");
    assert!(j1 < 1e-3 * j0, "J {j0} -> {j1}");
    for e in &after {
        assert!(e.normalised.abs() < 0.02, "{e:?}");
    }
    let lower = space().lower();
    let upper = space().upper();
    for (k, (x, t)) in cal.calibrated_point.iter().zip(truth).enumerate() {
        let rel = (x - t).abs() / (upper[k] - lower[k]);
        assert!(rel < 0.02, "parameter {k}: {x} against {t}");
    }
    // The surrogates' errors agree with the model's where the runs are dense enough.
    assert!(cal.misfit_after < 1e-3 * cal.misfit_before);
    for (s, m) in cal.before.iter().zip(&before) {
        assert!((s.normalised - m.normalised).abs() < 0.05, "{s:?} {m:?}");
    }
    assert_eq!(cal.surrogates.len(), 4);
    assert_eq!(cal.runs, 40);
    assert_eq!(cal.evaluations, 1 + 40 + 200);
    assert_eq!(cal.calibrated["sy"], cal.calibrated_point[1]);
    // Same seed, same answer.
    let again = calibrate(&space(), &test, &r, &ScalarOptions::default()).unwrap();
    assert_eq!(again, cal);
}

#[test]
fn a_subset_of_the_outputs_and_extra_columns() {
    // Two scalars only: the runs' other outputs are ignored, and the test's order is kept.
    let truth = [1.5, 450.0, 0.3];
    let r = runs(30);
    let full = test_at(&truth, &r);
    let test = ScalarTest::new(vec![full.scalars()[3].clone(), full.scalars()[0].clone()]).unwrap();
    let cal = calibrate(&space(), &test, &r, &ScalarOptions::default()).unwrap();
    assert_eq!(test.names(), ["IE", "dmax"]);
    assert_eq!(cal.after[0].name, "IE");
    let after = test
        .misfit(&outputs(model(&cal.calibrated_point)), "calibrated")
        .unwrap();
    let before = test
        .misfit(&outputs(model(&space().nominal())), "nominal")
        .unwrap();
    assert!(after < 1e-2 * before, "J {before} -> {after}");
}

#[test]
fn relative_error_is_absent_for_a_zero_test_value() {
    let test = ScalarTest::new(vec![
        Scalar::new("v", 0.0, 2.0),
        Scalar::new("f", 10.0, 1.0),
    ])
    .unwrap();
    let o: BTreeMap<String, f64> = [("v".to_string(), 1.0), ("f".to_string(), 12.0)].into();
    let e = test.errors(&o, "run").unwrap();
    assert_eq!(e[0].relative, None);
    assert_eq!(e[0].normalised, 0.5);
    assert!((e[1].relative.unwrap() - 0.2).abs() < 1e-15);
    assert_eq!(test.misfit(&o, "run").unwrap(), 0.25 + 4.0);
}

#[test]
fn bad_tests_are_refused_by_name() {
    let bad = |s: Vec<Scalar>| ScalarTest::new(s).unwrap_err();
    match bad(vec![Scalar::new("fmax", 1.0, 0.0)]) {
        CalibrateError::NonPositiveScale { scalar, scale } => {
            assert_eq!((scalar.as_str(), scale), ("fmax", 0.0));
        }
        e => panic!("{e}"),
    }
    assert!(matches!(
        bad(vec![Scalar::new("fmax", 1.0, -3.0)]),
        CalibrateError::NonPositiveScale { .. }
    ));
    let e = bad(vec![Scalar::new("IE", f64::NAN, 1.0)]);
    assert!(
        matches!(&e, CalibrateError::NonFiniteScalar { scalar, .. } if scalar == "IE"),
        "{e}"
    );
    assert!(e.to_string().contains("the test's value"), "{e}");
    let e = bad(vec![Scalar::new("IE", 1.0, f64::INFINITY)]);
    assert!(e.to_string().contains("the scale"), "{e}");
    let e = bad(vec![Scalar::new("a", 1.0, 1.0), Scalar::new("a", 2.0, 1.0)]);
    assert!(e.to_string().contains("given twice"), "{e}");
    assert!(bad(vec![]).to_string().contains("no scalar"));
    assert!(
        bad(vec![Scalar::new(" ", 1.0, 1.0)])
            .to_string()
            .contains("blank")
    );
}

#[test]
fn unknown_missing_and_nan_scalars_are_named() {
    let r = runs(12);
    let test = ScalarTest::new(vec![
        Scalar::new("dmax", -500.0, 50.0),
        Scalar::new("Ie", 1e8, 1e6),
    ])
    .unwrap();
    let e = calibrate(&space(), &test, &r, &ScalarOptions::default()).unwrap_err();
    match &e {
        CalibrateError::UnknownScalar { scalar, available } => {
            assert_eq!(scalar, "Ie");
            assert_eq!(available.len(), 4);
        }
        e => panic!("{e}"),
    }
    assert!(e.to_string().contains("dmax, fmax, vfin, IE"), "{e}");

    let test = ScalarTest::new(vec![Scalar::new("dmax", -500.0, 50.0)]).unwrap();
    let o: BTreeMap<String, f64> = [("fmax".to_string(), 1.0)].into();
    let e = test.errors(&o, "run at the calibrated point").unwrap_err();
    assert!(matches!(e, CalibrateError::MissingScalar { .. }), "{e}");
    assert!(
        e.to_string()
            .starts_with("run at the calibrated point: no output `dmax`")
    );
    let o: BTreeMap<String, f64> = [("dmax".to_string(), f64::NAN)].into();
    assert!(matches!(
        test.errors(&o, "run").unwrap_err(),
        CalibrateError::NonFiniteScalar { .. }
    ));

    // A NaN in a run is refused, naming the run and the output (never dropped silently).
    let mut r = runs(12);
    r.values[5][2] = f64::NAN;
    let e = calibrate(&space(), &test, &r, &ScalarOptions::default()).unwrap_err();
    assert!(
        matches!(&e, CalibrateError::NonFiniteScalar { scalar, origin, .. }
            if scalar == "vfin" && origin == "run 5"),
        "{e}"
    );
}

#[test]
fn runs_of_the_wrong_shape_are_refused() {
    let test = ScalarTest::new(vec![Scalar::new("dmax", -500.0, 50.0)]).unwrap();
    let opts = ScalarOptions::default();
    let mut r = runs(12);
    r.points[3].pop();
    let e = calibrate(&space(), &test, &r, &opts).unwrap_err();
    assert!(e.to_string().contains("scalar run 3: 2 parameters"), "{e}");
    let mut r = runs(12);
    r.values[0].push(1.0);
    assert!(calibrate(&space(), &test, &r, &opts).is_err());
    let r = runs(4);
    let e = calibrate(&space(), &test, &r, &opts).unwrap_err();
    assert!(e.to_string().contains("at least 5"), "{e}");
    let r = runs(12);
    let zero = ScalarOptions {
        budget: 0,
        ..ScalarOptions::default()
    };
    assert!(calibrate(&space(), &test, &r, &zero).is_err());
}
