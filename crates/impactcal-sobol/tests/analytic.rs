//! Indices against exact values of analytic test functions (sobol.md §3).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::float_cmp,
    clippy::needless_range_loop
)]

use std::f64::consts::PI;

use faer::{ColRef, Mat, MatRef};
use impactcal_core::points::{row, to_rows};
use impactcal_core::sampling::{Method, unit_sample};
use impactcal_core::test_functions::{
    g_function, g_function_indices, ishigami, ishigami_indices, linear_indices,
};
use impactcal_core::{Parameter, ParameterSpace};
use impactcal_sobol::{
    FirstOrderEstimator, GivenDataOptions, SaltelliDesign, SobolIndices, SobolOptions,
    TotalEstimator, analyze, given_data_first_order, replicate_spread,
};

/// One output per run, as a one-column matrix.
fn column(y: &[f64]) -> MatRef<'_, f64> {
    ColRef::from_slice(y).as_mat()
}

fn space(bounds: &[(f64, f64)]) -> ParameterSpace {
    ParameterSpace::new(
        bounds
            .iter()
            .enumerate()
            .map(|(i, &(l, u))| Parameter::new(format!("x{}", i + 1), l, u, l).unwrap())
            .collect(),
    )
    .unwrap()
}

fn ishigami_space() -> ParameterSpace {
    space(&[(-PI, PI); 3])
}

fn run(
    design: &SaltelliDesign,
    cols: usize,
    f: impl Fn(&[f64], &mut [f64]),
    options: &SobolOptions,
) -> SobolIndices {
    let rows = design.points.nrows();
    let mut y = vec![0.0; rows * cols];
    for (x, out) in to_rows(design.points.as_ref())
        .iter()
        .zip(y.chunks_exact_mut(cols))
    {
        f(x, out);
    }
    analyze(
        &design.layout,
        MatRef::from_row_major_slice(&y, rows, cols),
        options,
    )
    .unwrap()
}

fn assert_close(what: &str, got: &[f64], exact: &[f64], tol: f64) {
    for (i, (g, e)) in got.iter().zip(exact).enumerate() {
        assert!(
            (g - e).abs() < tol,
            "{what}[{i}] = {g}, exact {e} (tol {tol})"
        );
    }
}

/// The acceptance test: Ishigami (a = 7, b = 0.1), N = 2^13 scrambled Sobol', every
/// first-order and total index within 0.01 of the truth, for several scramblings.
#[test]
fn ishigami_within_001_at_n_8192() {
    let exact = ishigami_indices(7.0, 0.1);
    for seed in [1, 2, 3] {
        let d =
            SaltelliDesign::generate(&ishigami_space(), 8192, Method::ScrambledSobol, false, seed)
                .unwrap();
        let s = run(
            &d,
            1,
            |x, y| y[0] = ishigami(x, 7.0, 0.1),
            &SobolOptions::default(),
        );
        assert_close("S1", &s.first_order[0], &exact.first_order, 0.01);
        assert_close("ST", &s.total[0], &exact.total, 0.01);
        assert!((s.variance[0] - exact.variance).abs() < 0.01 * exact.variance);
    }
}

#[test]
fn ishigami_second_order_and_other_estimators() {
    let exact = ishigami_indices(7.0, 0.1);
    let d =
        SaltelliDesign::generate(&ishigami_space(), 8192, Method::ScrambledSobol, true, 5).unwrap();
    assert_eq!(d.points.nrows(), 8192 * 8);
    d.layout.check_points(d.points.as_ref()).unwrap();
    let firsts = [
        FirstOrderEstimator::Saltelli2010,
        FirstOrderEstimator::Jansen1999,
        FirstOrderEstimator::Janon2014,
        FirstOrderEstimator::Martinez2011,
    ];
    let totals = [
        TotalEstimator::Jansen1999,
        TotalEstimator::Sobol2007,
        TotalEstimator::Janon2014,
        TotalEstimator::Martinez2011,
    ];
    for (first, total) in firsts.into_iter().zip(totals) {
        let o = SobolOptions {
            first_order: first,
            total,
            ..SobolOptions::default()
        };
        let s = run(&d, 1, |x, y| y[0] = ishigami(x, 7.0, 0.1), &o);
        assert_close(
            &format!("S1 {first:?}"),
            &s.first_order[0],
            &exact.first_order,
            0.015,
        );
        assert_close(&format!("ST {total:?}"), &s.total[0], &exact.total, 0.015);
        let s2 = s.second_order.as_ref().unwrap();
        for i in 0..3 {
            assert!(s2[0][i][i].is_nan());
            for k in 0..3 {
                if i != k {
                    let (g, e) = (s2[0][i][k], exact.second_order[i][k]);
                    assert!((g - e).abs() < 0.03, "S{i}{k} = {g}, exact {e}");
                }
            }
        }
    }
}

/// G-function, d = 6, a = (0, 0.5, 3, 9, 99, 99) (sobol.md §3.2).
#[test]
fn g_function_within_001() {
    let a = [0.0, 0.5, 3.0, 9.0, 99.0, 99.0];
    let exact = g_function_indices(&a);
    assert!((exact.variance - 0.568_071).abs() < 1e-6);
    assert!((exact.first_order[0] - 0.58678).abs() < 1e-5);
    let d = SaltelliDesign::generate(
        &space(&[(0.0, 1.0); 6]),
        8192,
        Method::ScrambledSobol,
        false,
        3,
    )
    .unwrap();
    let s = run(
        &d,
        1,
        |x, y| y[0] = g_function(x, &a),
        &SobolOptions::default(),
    );
    assert_close("S1", &s.first_order[0], &exact.first_order, 0.01);
    assert_close("ST", &s.total[0], &exact.total, 0.01);
}

/// Linear model on unequal boxes: S_i = ST_i, summing to 1; the given-data estimator on a
/// Latin hypercube agrees, and the normalised shares equal the indices.
#[test]
fn linear_model_sums_to_one() {
    let c = [1.0, -2.0, 0.5, 3.0];
    let bounds = [(0.0, 1.0), (-1.0, 1.0), (2.0, 6.0), (0.0, 0.5)];
    let widths: Vec<f64> = bounds.iter().map(|(l, u)| u - l).collect();
    let exact = linear_indices(&c, &widths);
    let sp = space(&bounds);
    let f = |x: &[f64]| x.iter().zip(&c).map(|(x, c)| x * c).sum::<f64>() + 100.0;
    let d = SaltelliDesign::generate(&sp, 4096, Method::ScrambledSobol, false, 8).unwrap();
    let s = run(&d, 1, |x, y| y[0] = f(x), &SobolOptions::default());
    assert_close("S1", &s.first_order[0], &exact.first_order, 0.01);
    assert_close("ST", &s.total[0], &exact.total, 0.01);
    assert!((s.first_order[0].iter().sum::<f64>() - 1.0).abs() < 0.01);
    assert!(s.interaction_share[0].abs() < 0.01);
    assert_close(
        "share",
        &s.normalised_first_order_share[0],
        &exact.first_order,
        0.01,
    );

    let lhs = impactcal_core::sampling::sample(&sp, Method::LatinHypercube, 4096, 2)
        .unwrap()
        .points;
    let y: Vec<f64> = to_rows(lhs.as_ref()).iter().map(|x| f(x)).collect();
    let g = given_data_first_order(lhs.as_ref(), column(&y), &GivenDataOptions::default()).unwrap();
    assert_eq!(g.bins, 16);
    assert_close("given-data S1", &g.first_order[0], &exact.first_order, 0.02);
    let sum: f64 = g.normalised_first_order_share[0].iter().sum();
    assert!((sum - 1.0).abs() < 1e-12);
}

/// The given-data estimator finds Ishigami's first-order indices from one scrambled Halton
/// sample, and its bias correction brings the inactive x3 near zero.
#[test]
fn given_data_on_ishigami() {
    let exact = ishigami_indices(7.0, 0.1);
    let x = impactcal_core::sampling::sample(&ishigami_space(), Method::ScrambledHalton, 8000, 4)
        .unwrap()
        .points;
    let y: Vec<f64> = to_rows(x.as_ref())
        .iter()
        .map(|x| ishigami(x, 7.0, 0.1))
        .collect();
    let g = given_data_first_order(x.as_ref(), column(&y), &GivenDataOptions::default()).unwrap();
    assert_close("S1", &g.first_order[0], &exact.first_order, 0.03);
    assert!(g.first_order[0][2].abs() < 0.005);
    assert!(g.first_order_uncorrected[0][2] > g.first_order[0][2]);
}

/// Time-dependent Ishigami (sobol.md §3.3): y(t) = sin x1 + a(t) sin^2 x2 + b(t) x3^4 sin x1
/// with a(t) = 7 sin^2(pi t), b(t) = 0.1 + 0.2 t on 21 steps, plus a constant column. Exact
/// indices at every step, exact aggregated indices, the constant column flagged.
#[test]
fn time_dependent_ishigami() {
    let steps = 21;
    let ab = |k: usize| {
        let t = k as f64 / (steps - 1) as f64;
        (7.0 * (PI * t).sin().powi(2), 0.1 + 0.2 * t)
    };
    let d = SaltelliDesign::generate(&ishigami_space(), 8192, Method::ScrambledSobol, false, 21)
        .unwrap();
    let options = SobolOptions {
        bootstrap: 50,
        seed: 4,
        ..SobolOptions::default()
    };
    let s = run(
        &d,
        steps + 1,
        |x, y| {
            for (k, v) in y.iter_mut().take(steps).enumerate() {
                let (a, b) = ab(k);
                *v = ishigami(x, a, b);
            }
            y[steps] = 3.25;
        },
        &options,
    );
    let (mut num_first, mut num_total, mut den) = ([0.0; 3], [0.0; 3], 0.0);
    for k in 0..steps {
        let (a, b) = ab(k);
        let exact = ishigami_indices(a, b);
        assert_close(
            &format!("S1(t{k})"),
            &s.first_order[k],
            &exact.first_order,
            0.012,
        );
        assert_close(&format!("ST(t{k})"), &s.total[k], &exact.total, 0.012);
        for i in 0..3 {
            num_first[i] += exact.first_order[i] * exact.variance;
            num_total[i] += exact.total[i] * exact.variance;
        }
        den += exact.variance;
        // Each point estimate lies inside its bootstrap interval.
        let ci = &s.first_order_ci.as_ref().unwrap()[k];
        for i in 0..3 {
            assert!(ci[i][0] <= s.first_order[k][i] && s.first_order[k][i] <= ci[i][1]);
        }
    }
    let agg_first: Vec<f64> = num_first.iter().map(|n| n / den).collect();
    let agg_total: Vec<f64> = num_total.iter().map(|n| n / den).collect();
    assert_close("aggregated S1", &s.aggregated.first_order, &agg_first, 0.01);
    assert_close("aggregated ST", &s.aggregated.total, &agg_total, 0.01);
    assert_eq!(s.low_variance_outputs, vec![format!("y{}", steps + 1)]);
    assert!(s.first_order[steps].iter().all(|v| v.is_nan()));
    let agg_ci = s.aggregated.first_order_ci.as_ref().unwrap();
    for i in 0..3 {
        assert!(agg_ci[i][0] <= s.aggregated.first_order[i]);
        assert!(s.aggregated.first_order[i] <= agg_ci[i][1]);
    }
}

/// Bootstrap intervals cover the truth about as often as they claim (over 40 independent
/// Monte Carlo designs), shrink like 1/sqrt(N), and are bit-identical for any number of
/// threads and for the same seed.
#[test]
fn bootstrap_intervals_are_coherent_and_reproducible() {
    let exact = ishigami_indices(7.0, 0.1);
    let options = SobolOptions {
        bootstrap: 200,
        seed: 9,
        ..SobolOptions::default()
    };
    let (mut covered, mut total) = (0u32, 0u32);
    let mut widths = [0.0; 2];
    for seed in 0..40 {
        for (k, n) in [256, 4096].into_iter().enumerate() {
            if k == 1 && seed >= 4 {
                continue;
            }
            let d = SaltelliDesign::generate(&ishigami_space(), n, Method::Random, false, seed)
                .unwrap();
            let s = run(&d, 1, |x, y| y[0] = ishigami(x, 7.0, 0.1), &options);
            let (c1, ct) = (
                s.first_order_ci.as_ref().unwrap(),
                s.total_ci.as_ref().unwrap(),
            );
            for i in 0..3 {
                for (ci, e) in [(c1[0][i], exact.first_order[i]), (ct[0][i], exact.total[i])] {
                    covered += u32::from(ci[0] < e && e < ci[1]);
                    total += 1;
                }
            }
            widths[k] += ct[0][1][1] - ct[0][1][0];
        }
    }
    let coverage = f64::from(covered) / f64::from(total);
    assert!(
        (0.85..=1.0).contains(&coverage),
        "coverage {coverage} of nominal 0.95"
    );
    // 16 times the rows: intervals 4 times narrower (mean widths over the first 4 seeds
    // at N = 256 are estimated from 40 seeds, so scale).
    let ratio = (widths[0] / 40.0) / (widths[1] / 4.0);
    assert!(
        (3.0..5.5).contains(&ratio),
        "width ratio {ratio} (expect 4)"
    );

    let d =
        SaltelliDesign::generate(&ishigami_space(), 256, Method::ScrambledSobol, true, 3).unwrap();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let four = rayon::ThreadPoolBuilder::new()
        .num_threads(4)
        .build()
        .unwrap();
    let f = |x: &[f64], y: &mut [f64]| {
        y[0] = ishigami(x, 7.0, 0.1);
        y[1] = x[0] * x[1];
    };
    let a = one.install(|| run(&d, 2, f, &options));
    let b = four.install(|| run(&d, 2, f, &options));
    let ja = serde_json::to_string(&a).unwrap();
    assert_eq!(ja, serde_json::to_string(&b).unwrap());
    assert!(ja.contains("\"second_order_ci\""));
}

/// Independent scramblings give a t interval that covers the truth.
#[test]
fn replicates_over_scramblings() {
    let exact = ishigami_indices(7.0, 0.1);
    let reps: Vec<SobolIndices> = (0..8)
        .map(|seed| {
            let d = SaltelliDesign::generate(
                &ishigami_space(),
                1024,
                Method::ScrambledSobol,
                false,
                seed,
            )
            .unwrap();
            run(
                &d,
                1,
                |x, y| y[0] = ishigami(x, 7.0, 0.1),
                &SobolOptions::default(),
            )
        })
        .collect();
    let spread = replicate_spread(&reps, 0.99).unwrap();
    for i in 0..3 {
        let (c, t) = (spread.first_order_ci[0][i], spread.total_ci[0][i]);
        assert!(
            c[0] < exact.first_order[i] && exact.first_order[i] < c[1],
            "S{i}: {c:?}"
        );
        assert!(
            t[0] < exact.total[i] && exact.total[i] < t[1],
            "ST{i}: {t:?}"
        );
        assert!(spread.first_order_se[0][i] < 0.01);
    }
    assert!(replicate_spread(&reps[..1], 0.9).is_err());
}

#[test]
fn unit_space_design_matches_plain_sequence() {
    // With plain Sobol' the A and B blocks are the first and last d coordinates of one
    // 2d-dimensional sequence.
    let sp = space(&[(0.0, 1.0); 2]);
    let d = SaltelliDesign::generate(&sp, 8, Method::Sobol, true, 0).unwrap();
    let base: Mat<f64> = unit_sample(Method::Sobol, 8, 4, 0).unwrap().points;
    let p = d.points.as_ref();
    for j in 0..8 {
        let r = row(base.as_ref(), j);
        let (a, b) = (r[..2].to_vec(), r[2..].to_vec());
        assert_eq!(row(p, d.layout.a_row(j)), a);
        assert_eq!(row(p, d.layout.b_row(j)), b);
        assert_eq!(row(p, d.layout.ab_row(j, 1)), [a[0], b[1]]);
        assert_eq!(row(p, d.layout.ba_row(j, 1)), [b[0], a[1]]);
    }
}

/// Outputs in different units side by side (a final velocity of order 1 beside an energy
/// of order 1e13, as in a crash study's output file): each column is judged by its own
/// scale, so both get the indices they get alone, while a constant column (here a large
/// constant, 9e12) and one whose spread is below float resolution of its values are still
/// flagged. A test of the column's own criterion: against the largest column's variance,
/// the velocity (variance ~10) sat 1e-23 below the energy's (~1e24) and was nulled.
#[test]
fn low_variance_is_judged_per_column_in_mixed_units() {
    let d = SaltelliDesign::generate(&ishigami_space(), 1024, Method::ScrambledSobol, false, 3)
        .unwrap();
    let mixed = |x: &[f64], y: &mut [f64]| {
        let v = ishigami(x, 7.0, 0.1);
        y[0] = 0.1 * v; // a velocity, variance ~0.14
        y[1] = 9.0e12 + 1.0e11 * v; // an energy, variance ~1.4e23
        y[2] = 9.0e12; // a constant
        y[3] = 9.0e12 * (1.0 + 1e-15 * v.signum()); // a spread at the float resolution
    };
    let s = run(&d, 4, mixed, &SobolOptions::default());
    assert_eq!(s.low_variance_outputs, vec!["y3", "y4"]);
    let alone = run(
        &d,
        1,
        |x, y| y[0] = ishigami(x, 7.0, 0.1),
        &SobolOptions::default(),
    );
    for c in 0..2 {
        for i in 0..3 {
            assert!(
                (s.first_order[c][i] - alone.first_order[0][i]).abs() < 1e-6,
                "column {c}, parameter {i}: {} against {}",
                s.first_order[c][i],
                alone.first_order[0][i]
            );
            assert!((s.total[c][i] - alone.total[0][i]).abs() < 1e-6);
        }
    }

    // The given-data estimator judges its columns the same way.
    let x = impactcal_core::sampling::sample(&ishigami_space(), Method::LatinHypercube, 2048, 5)
        .unwrap()
        .points;
    let rows = to_rows(x.as_ref());
    let mut y = Vec::new();
    for r in &rows {
        let mut out = [0.0; 4];
        mixed(r, &mut out);
        y.extend(out);
    }
    let g = given_data_first_order(
        x.as_ref(),
        MatRef::from_row_major_slice(&y, rows.len(), 4),
        &GivenDataOptions::default(),
    )
    .unwrap();
    assert_eq!(g.low_variance_outputs, vec!["y3", "y4"]);
    for i in 0..3 {
        assert!((g.first_order[0][i] - g.first_order[1][i]).abs() < 1e-6);
        assert!(g.first_order[0][i].is_finite());
    }
}
