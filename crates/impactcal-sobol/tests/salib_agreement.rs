//! Agreement with SALib 1.6 on identical design rows and outputs
//! (tests/data/salib_ishigami.json, made by benches/peers/salib_fixture.py).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::float_cmp,
    clippy::needless_range_loop
)]

use faer::{ColRef, MatRef};
use impactcal_core::points::{from_row_major, from_rows, to_rows};
use impactcal_core::sampling::Method;
use impactcal_core::{CoreError, Parameter, ParameterSpace};
use impactcal_sobol::{DesignLayout, SaltelliDesign, SobolOptions, analyze};
use serde_json::Value;

fn fixture() -> Value {
    serde_json::from_str(include_str!("data/salib_ishigami.json")).unwrap()
}

fn matrix(v: &Value) -> Vec<Vec<f64>> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|r| {
            r.as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect()
        })
        .collect()
}

fn vector(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn point_estimates_equal_salib() {
    let f = fixture();
    let x = from_rows(&matrix(&f["x"]), "x").unwrap();
    let y = matrix(&f["y"]);
    let layout = DesignLayout::from_rows(x.nrows(), 3, true).unwrap();
    assert_eq!(layout.n(), 64);
    // SALib's rows have the structure our layout describes.
    layout.check_points(x.as_ref()).unwrap();
    let flat: Vec<f64> = y.iter().flatten().copied().collect();
    let options = SobolOptions {
        bootstrap: 100,
        ..SobolOptions::default()
    };
    let outputs = MatRef::from_row_major_slice(&flat, x.nrows(), 2);
    let s = analyze(&layout, outputs, &options).unwrap();
    let columns = f["columns"].as_array().unwrap();
    for (t, col) in columns.iter().enumerate() {
        let (s1, st, s2) = (vector(&col["S1"]), vector(&col["ST"]), matrix(&col["S2"]));
        for i in 0..3 {
            assert!(
                (s.first_order[t][i] - s1[i]).abs() < 1e-12,
                "S1 col {t} x{i}"
            );
            assert!((s.total[t][i] - st[i]).abs() < 1e-12, "ST col {t} x{i}");
            for k in i + 1..3 {
                let ours = s.second_order.as_ref().unwrap()[t][i][k];
                assert!((ours - s2[i][k]).abs() < 1e-12, "S2 col {t} x{i} x{k}");
            }
        }
        // SALib's `conf` is z * (bootstrap sd); the resamples differ, so the standard
        // errors agree only statistically.
        let z = 1.959_963_984_540_054;
        for (name, conf, ours) in [
            (
                "S1",
                vector(&col["S1_conf"]),
                s.first_order_se.as_ref().unwrap(),
            ),
            ("ST", vector(&col["ST_conf"]), s.total_se.as_ref().unwrap()),
        ] {
            for i in 0..3 {
                let ratio = ours[t][i] * z / conf[i];
                assert!(
                    (0.65..1.5).contains(&ratio),
                    "{name} se col {t} x{i}: ratio {ratio}"
                );
            }
        }
    }
}

#[test]
fn plain_design_equals_salib_rows() {
    let f = fixture();
    let salib = matrix(&f["plain_design_n8_d3_second_order"]);
    let space = ParameterSpace::new(
        ["a", "b", "c"]
            .iter()
            .map(|n| Parameter::new(*n, 0.0, 1.0, 0.5).unwrap())
            .collect(),
    )
    .unwrap();
    let ours = SaltelliDesign::generate(&space, 8, Method::Sobol, true, 0).unwrap();
    assert_eq!(to_rows(ours.points.as_ref()), salib);
}

#[test]
fn malformed_inputs_are_typed_errors() {
    use impactcal_sobol::SobolError as E;
    let f = fixture();
    let x = from_rows(&matrix(&f["x"]), "x").unwrap();
    let n = x.nrows();
    // 64 * 8 rows fit d = 3 only with second order; the error says so.
    let e = DesignLayout::from_rows(n, 3, false).unwrap_err();
    assert!(matches!(e, E::RowCount { .. }) && e.to_string().contains("with second order"));
    assert!(matches!(
        DesignLayout::new(64, 1, true),
        Err(E::TooSmallForSecondOrder { .. })
    ));
    let layout = DesignLayout::from_rows(n, 3, true).unwrap();
    // Swapping two rows breaks the pick-freeze structure.
    let mut rows = to_rows(x.as_ref());
    rows.swap(9, 10);
    let e = layout
        .check_points(from_rows(&rows, "x").unwrap().as_ref())
        .unwrap_err();
    assert!(matches!(e, E::DesignStructure { row: 9, .. }), "{e}");
    let mut y = vec![1.0; n];
    y[5] = 2.0;
    let column = |y: &[f64]| ColRef::from_slice(y).as_mat().to_owned();
    let short = column(&y[..n - 1]);
    assert!(matches!(
        analyze(&layout, short.as_ref(), &SobolOptions::default()),
        Err(E::RowCount { .. })
    ));
    y[17] = f64::NAN;
    let e = analyze(&layout, column(&y).as_ref(), &SobolOptions::default()).unwrap_err();
    assert!(
        matches!(
            &e,
            E::Core(CoreError::NonFinite { location, .. })
                if location == "row 17, column 0 (0-based)"
        ),
        "{e}"
    );
    y[17] = 1.0;
    for bad in [
        SobolOptions {
            confidence: 1.0,
            ..SobolOptions::default()
        },
        SobolOptions {
            bootstrap: 1,
            ..SobolOptions::default()
        },
        SobolOptions {
            parameter_names: Some(vec!["a".into()]),
            ..SobolOptions::default()
        },
    ] {
        assert!(analyze(&layout, column(&y).as_ref(), &bad).is_err());
    }
    assert!(from_row_major(10, 3, &y).is_err());
}
