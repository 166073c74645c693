//! Classic RBF interpolants against analytic truths and invariants.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use approx::assert_relative_eq;
use faer::{Mat, MatRef};
use impactcal_core::CoreError;
use impactcal_erbf::{
    ErbfError, LooMethod, PolyDegree, RadialFunction, RbfInterpolant, RbfOptions,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn random_points(n: usize, d: usize, seed: u64) -> Mat<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    Mat::from_fn(n, d, |_, _| rng.random::<f64>())
}

fn smooth(x: &[f64]) -> f64 {
    x.iter()
        .enumerate()
        .map(|(j, v)| ((j + 1) as f64 * v).sin() + v * v)
        .sum()
}

fn eval(points: MatRef<'_, f64>, f: impl Fn(&[f64]) -> f64) -> Mat<f64> {
    Mat::from_fn(points.nrows(), 1, |i, _| {
        f(&points.row(i).iter().copied().collect::<Vec<_>>())
    })
}

fn all_options() -> Vec<RbfOptions> {
    vec![
        RbfOptions::cubic(),
        RbfOptions::thin_plate(),
        RbfOptions::new(RadialFunction::Gaussian { width: 0.3 }),
        RbfOptions::new(RadialFunction::Gaussian { width: 0.3 }).with_degree(PolyDegree::Linear),
        RbfOptions::new(RadialFunction::Multiquadric { c: 0.2 }),
    ]
}

#[test]
fn reproduces_training_values_for_every_kernel() {
    let x = random_points(40, 3, 1);
    let f = eval(x.as_ref(), smooth);
    for opts in all_options() {
        let s = RbfInterpolant::fit(x.as_ref(), f.as_ref(), opts).unwrap();
        assert!(
            s.training_residual() < 1e-10,
            "{opts:?}: {}",
            s.training_residual()
        );
    }
}

/// More outputs than system rows (`T > n`) switches prediction to the transposed solve;
/// each column must still equal the interpolant of that column alone, values and gradients.
#[test]
fn long_outputs_predict_as_their_columns_fitted_alone() {
    let x = random_points(30, 3, 11);
    let q = random_points(12, 3, 12);
    let f = Mat::from_fn(30, 80, |i, t| {
        let p: Vec<f64> = x.row(i).iter().copied().collect();
        smooth(&p) * (0.05 * t as f64).cos() + t as f64 * p[2]
    });
    for opts in all_options() {
        let all = RbfInterpolant::fit(x.as_ref(), f.as_ref(), opts).unwrap();
        let p_all = all.predict_batch(q.as_ref()).unwrap();
        let q0: Vec<f64> = q.row(0).iter().copied().collect();
        let g_all = all.predict_gradient(&q0).unwrap();
        for t in [0, 41, 79] {
            let one = RbfInterpolant::fit(x.as_ref(), f.as_ref().subcols(t, 1), opts).unwrap();
            let p = one.predict_batch(q.as_ref()).unwrap();
            for i in 0..12 {
                assert_relative_eq!(
                    p_all[(i, t)],
                    p[(i, 0)],
                    epsilon = 1e-10,
                    max_relative = 1e-10
                );
            }
            let g = one.predict_gradient(&q0).unwrap();
            for j in 0..3 {
                assert_relative_eq!(
                    g_all[(t, j)],
                    g[(0, j)],
                    epsilon = 1e-9,
                    max_relative = 1e-9
                );
            }
            let w = one.radial_weights();
            for i in 0..30 {
                assert_relative_eq!(
                    all.radial_weights()[(i, t)],
                    w[(i, 0)],
                    epsilon = 1e-9,
                    max_relative = 1e-9
                );
            }
        }
        assert!(all.training_residual() < 1e-10, "{opts:?}");
    }
}

/// Long histories over more queries than one block of 4096 and more outputs than one
/// block of 512: every row and column lands where it belongs (against columns fitted
/// alone, which take the coefficient route), on any number of threads.
#[test]
fn long_outputs_over_several_blocks_land_in_place_on_any_thread_count() {
    let x = random_points(30, 3, 21);
    let q = random_points(4100, 3, 22);
    let f = Mat::from_fn(30, 1300, |i, t| {
        let p: Vec<f64> = x.row(i).iter().copied().collect();
        smooth(&p) * (0.01 * t as f64).cos() + t as f64 * 1e-3 * p[1]
    });
    let all = RbfInterpolant::fit(x.as_ref(), f.as_ref(), RbfOptions::cubic()).unwrap();
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| all.predict_batch(q.as_ref()).unwrap())
    };
    let p_all = run(1);
    assert_eq!(p_all, run(3));
    for t in [0, 511, 512, 1299] {
        let one =
            RbfInterpolant::fit(x.as_ref(), f.as_ref().subcols(t, 1), RbfOptions::cubic()).unwrap();
        let p = one.predict_batch(q.as_ref()).unwrap();
        for i in [0, 1, 4095, 4096, 4099] {
            assert_relative_eq!(
                p_all[(i, t)],
                p[(i, 0)],
                epsilon = 1e-10,
                max_relative = 1e-10
            );
        }
    }
}

#[test]
fn linear_tail_reproduces_affine_functions() {
    let x = random_points(25, 3, 2);
    let affine = |p: &[f64]| 1.5 - 2.0 * p[0] + 0.5 * p[1] + 3.0 * p[2];
    let f = eval(x.as_ref(), affine);
    for opts in [RbfOptions::cubic(), RbfOptions::thin_plate()] {
        let s = RbfInterpolant::fit(x.as_ref(), f.as_ref(), opts).unwrap();
        for v in s.radial_weights().col(0).iter() {
            assert!(v.abs() < 1e-9, "kernel weight {v}");
        }
        let q = random_points(50, 3, 3);
        let far = [5.0, -4.0, 2.0];
        assert_relative_eq!(s.predict(&far).unwrap()[0], affine(&far), epsilon = 1e-8);
        let p = s.predict_batch(q.as_ref()).unwrap();
        for i in 0..50 {
            let qi: Vec<f64> = q.row(i).iter().copied().collect();
            assert_relative_eq!(p[(i, 0)], affine(&qi), epsilon = 1e-10);
        }
    }
}

#[test]
fn explicit_coefficients_give_the_interpolant() {
    // An affine function: the tail is the function itself, in the original coordinates.
    let x = Mat::from_fn(30, 2, |i, j| 10.0 * random_points(30, 2, 7)[(i, j)] - 3.0);
    let affine = |p: &[f64]| 1.5 - 2.0 * p[0] + 0.5 * p[1];
    let f = eval(x.as_ref(), affine);
    let s = RbfInterpolant::fit(x.as_ref(), f.as_ref(), RbfOptions::cubic()).unwrap();
    let a = s.tail_coefficients();
    assert_eq!((a.nrows(), a.ncols()), (3, 1));
    assert_relative_eq!(a[(0, 0)], 1.5, epsilon = 1e-8);
    assert_relative_eq!(a[(1, 0)], -2.0, epsilon = 1e-8);
    assert_relative_eq!(a[(2, 0)], 0.5, epsilon = 1e-8);
    // Any data, every tail: weights, centres and tail reproduce the predictions.
    let x = random_points(35, 3, 8);
    let f = Mat::from_fn(35, 2, |i, c| {
        let p: Vec<f64> = x.row(i).iter().copied().collect();
        smooth(&p) * (1.0 + c as f64)
    });
    for opts in all_options() {
        let s = RbfInterpolant::fit(x.as_ref(), f.as_ref(), opts).unwrap();
        let a = s.tail_coefficients();
        assert_eq!(a.nrows(), opts.degree.terms(3));
        let q = random_points(20, 3, 9);
        let p = s.predict_batch(q.as_ref()).unwrap();
        for i in 0..20 {
            for c in 0..2 {
                let mut v = 0.0;
                for k in 0..35 {
                    let r = (0..3)
                        .map(|j| (q[(i, j)] - x[(k, j)]).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    v += s.radial_weights()[(k, c)] * opts.radial.value(r);
                }
                if a.nrows() > 0 {
                    v += a[(0, c)];
                }
                for j in 0..a.nrows().saturating_sub(1) {
                    v += a[(1 + j, c)] * q[(i, j)];
                }
                assert_relative_eq!(v, p[(i, c)], epsilon = 1e-9, max_relative = 1e-9);
            }
        }
    }
}

/// Natural cubic spline through (t_k, y_k), evaluated at `x`: the independent truth for a
/// 1-D cubic RBF with a linear tail, which is that spline.
fn natural_spline(t: &[f64], y: &[f64], x: f64) -> f64 {
    let n = t.len();
    // Second derivatives m_k with m_0 = m_{n-1} = 0 (tridiagonal, Thomas algorithm).
    let h: Vec<f64> = (0..n - 1).map(|k| t[k + 1] - t[k]).collect();
    let mut a = vec![0.0; n];
    let mut b = vec![1.0; n];
    let mut c = vec![0.0; n];
    let mut r = vec![0.0; n];
    for k in 1..n - 1 {
        a[k] = h[k - 1];
        b[k] = 2.0 * (h[k - 1] + h[k]);
        c[k] = h[k];
        r[k] = 6.0 * ((y[k + 1] - y[k]) / h[k] - (y[k] - y[k - 1]) / h[k - 1]);
    }
    for k in 1..n {
        let w = a[k] / b[k - 1];
        b[k] -= w * c[k - 1];
        r[k] -= w * r[k - 1];
    }
    let mut m = vec![0.0; n];
    m[n - 1] = r[n - 1] / b[n - 1];
    for k in (0..n - 1).rev() {
        m[k] = (r[k] - c[k] * m[k + 1]) / b[k];
    }
    let k = (0..n - 1).find(|&k| x <= t[k + 1]).unwrap_or(n - 2);
    let (u, v) = (t[k + 1] - x, x - t[k]);
    m[k] * u.powi(3) / (6.0 * h[k])
        + m[k + 1] * v.powi(3) / (6.0 * h[k])
        + (y[k] / h[k] - m[k] * h[k] / 6.0) * u
        + (y[k + 1] / h[k] - m[k + 1] * h[k] / 6.0) * v
}

#[test]
fn cubic_rbf_in_one_dimension_is_the_natural_cubic_spline() {
    let t = [0.0, 0.3, 0.5, 0.9, 1.4, 2.0];
    let y = [1.0, -0.5, 0.2, 2.0, 1.1, -1.0];
    let pts: Vec<Vec<f64>> = t.iter().map(|&v| vec![v]).collect();
    let s = RbfInterpolant::fit_rows(&pts, &y, RbfOptions::cubic()).unwrap();
    for i in 0..=40 {
        let x = 2.0 * i as f64 / 40.0;
        assert_relative_eq!(
            s.predict(&[x]).unwrap()[0],
            natural_spline(&t, &y, x),
            epsilon = 1e-10
        );
    }
}

#[test]
fn closed_form_loo_equals_refitting() {
    let x = random_points(30, 2, 4);
    let f = eval(x.as_ref(), smooth);
    let mut opts = all_options();
    opts.push(RbfOptions::cubic().with_smoothing(1e-3));
    opts.push(RbfOptions::new(RadialFunction::Gaussian { width: 0.3 }).with_smoothing(1e-2));
    for o in opts {
        let s = RbfInterpolant::fit(x.as_ref(), f.as_ref(), o).unwrap();
        let closed = s.loo_errors(LooMethod::Closed).unwrap();
        let refit = s.loo_errors(LooMethod::Refit).unwrap();
        let scale = refit.col(0).iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        assert!(scale > 1e-6, "{o:?}: LOO errors should not vanish");
        for k in 0..30 {
            assert!(
                (closed[(k, 0)] - refit[(k, 0)]).abs() < 1e-7 * scale,
                "{o:?} sample {k}: {} vs {}",
                closed[(k, 0)],
                refit[(k, 0)]
            );
        }
    }
}

#[test]
fn gradient_matches_central_differences() {
    let x = random_points(30, 3, 5);
    let f = eval(x.as_ref(), smooth);
    let q = random_points(6, 3, 6);
    for o in all_options() {
        let s = RbfInterpolant::fit(x.as_ref(), f.as_ref(), o).unwrap();
        for i in 0..q.nrows() {
            let p: Vec<f64> = q.row(i).iter().copied().collect();
            let g = s.predict_gradient(&p).unwrap();
            for j in 0..3 {
                let h = 1e-6;
                let mut a = p.clone();
                let mut b = p.clone();
                a[j] += h;
                b[j] -= h;
                let fd = (s.predict(&a).unwrap()[0] - s.predict(&b).unwrap()[0]) / (2.0 * h);
                assert!((g[(0, j)] - fd).abs() < 1e-6 * (1.0 + fd.abs()), "{o:?}");
            }
        }
        // At a training point the kernel term of that centre has zero gradient.
        let x0: Vec<f64> = x.row(0).iter().copied().collect();
        assert!(s.predict_gradient(&x0).unwrap()[(0, 0)].is_finite());
    }
}

#[test]
fn growing_equals_fitting_all_at_once() {
    let x = random_points(30, 2, 7);
    let f = eval(x.as_ref(), smooth);
    let first = x.as_ref().subrows(0, 20);
    let mut s = RbfInterpolant::fit(first, f.as_ref().subrows(0, 20), RbfOptions::cubic()).unwrap();
    s.add_points(x.as_ref().subrows(20, 9), f.as_ref().subrows(20, 9))
        .unwrap();
    let last: Vec<f64> = x.row(29).iter().copied().collect();
    s.add_point(&last, f[(29, 0)]).unwrap();
    let full = RbfInterpolant::fit(x.as_ref(), f.as_ref(), RbfOptions::cubic()).unwrap();
    let q = random_points(40, 2, 8);
    let a = s.predict_batch(q.as_ref()).unwrap();
    let b = full.predict_batch(q.as_ref()).unwrap();
    for i in 0..40 {
        assert_relative_eq!(a[(i, 0)], b[(i, 0)], epsilon = 1e-11);
    }
    // A duplicate of an existing sample is rejected, naming both, and leaves s unchanged.
    let dup: Vec<f64> = x.row(3).iter().copied().collect();
    match s.add_point(&dup, 0.0) {
        Err(ErbfError::DuplicateSamples { first, second, .. }) => {
            assert_eq!((first, second), (3, 30));
        }
        other => panic!("expected a duplicate error, got {other:?}"),
    }
    assert_eq!(s.n_samples(), 30);
}

#[test]
fn outputs_fitted_together_equal_outputs_fitted_alone() {
    let x = random_points(30, 2, 9);
    let f = Mat::from_fn(30, 3, |i, c| {
        let p = [x[(i, 0)], x[(i, 1)]];
        smooth(&p) * (c as f64 + 1.0) + (c as f64 * p[0]).cos()
    });
    let q = random_points(20, 2, 10);
    let together = RbfInterpolant::fit(x.as_ref(), f.as_ref(), RbfOptions::thin_plate())
        .unwrap()
        .predict_batch(q.as_ref())
        .unwrap();
    for c in 0..3 {
        let alone = RbfInterpolant::fit(
            x.as_ref(),
            f.as_ref().subcols(c, 1),
            RbfOptions::thin_plate(),
        )
        .unwrap()
        .predict_batch(q.as_ref())
        .unwrap();
        for i in 0..20 {
            assert_relative_eq!(
                together[(i, c)],
                alone[(i, 0)],
                epsilon = 1e-12,
                max_relative = 1e-12
            );
        }
    }
}

#[test]
fn serde_round_trip_predicts_the_same() {
    let x = random_points(20, 2, 11);
    let f = eval(x.as_ref(), smooth);
    let s = RbfInterpolant::fit(
        x.as_ref(),
        f.as_ref(),
        RbfOptions::new(RadialFunction::Multiquadric { c: 0.5 }),
    )
    .unwrap();
    let json = serde_json::to_string(&s).unwrap();
    let back: RbfInterpolant = serde_json::from_str(&json).unwrap();
    let q = [0.4, 0.7];
    assert_relative_eq!(
        back.predict(&q).unwrap()[0],
        s.predict(&q).unwrap()[0],
        epsilon = 1e-14
    );
    assert_eq!(back.options(), s.options());
    let broken = json.replace("\"nrows\":20", "\"nrows\":21");
    assert!(serde_json::from_str::<RbfInterpolant>(&broken).is_err());
}

#[test]
fn invalid_input_is_a_typed_error() {
    let x = random_points(10, 2, 12);
    let f = eval(x.as_ref(), smooth);
    let empty = Mat::<f64>::zeros(0, 2);
    assert!(matches!(
        RbfInterpolant::fit(
            empty.as_ref(),
            Mat::<f64>::zeros(0, 1).as_ref(),
            RbfOptions::cubic()
        ),
        Err(ErbfError::Core(CoreError::Empty { .. }))
    ));
    let mut bad = x.clone();
    bad[(4, 1)] = f64::NAN;
    assert!(matches!(
        RbfInterpolant::fit(bad.as_ref(), f.as_ref(), RbfOptions::cubic()),
        Err(ErbfError::Core(CoreError::NonFinite { location, .. }))
            if location == "row 4, column 1 (0-based)"
    ));
    assert!(matches!(
        RbfInterpolant::fit(x.as_ref(), f.as_ref().subrows(0, 9), RbfOptions::cubic()),
        Err(ErbfError::Core(CoreError::DimensionMismatch { .. }))
    ));
    let mut dup = x.clone();
    dup[(7, 0)] = x[(2, 0)];
    dup[(7, 1)] = x[(2, 1)] + 1e-13;
    assert!(matches!(
        RbfInterpolant::fit(dup.as_ref(), f.as_ref(), RbfOptions::cubic()),
        Err(ErbfError::DuplicateSamples {
            first: 2,
            second: 7,
            ..
        })
    ));
    let low = RbfOptions::cubic().with_degree(PolyDegree::Constant);
    assert!(matches!(
        RbfInterpolant::fit(x.as_ref(), f.as_ref(), low),
        Err(ErbfError::Core(CoreError::InvalidOption { .. }))
    ));
    let bad_width = RbfOptions::new(RadialFunction::Gaussian { width: 0.0 });
    assert!(RbfInterpolant::fit(x.as_ref(), f.as_ref(), bad_width).is_err());
    assert!(
        RbfInterpolant::fit(
            x.as_ref(),
            f.as_ref(),
            RbfOptions::cubic().with_smoothing(-1.0)
        )
        .is_err()
    );
    // Collinear points in 2-D cannot determine a linear tail.
    let line = Mat::from_fn(6, 2, |i, j| if j == 0 { i as f64 } else { 2.0 * i as f64 });
    let fl = Mat::from_fn(6, 1, |i, _| (i as f64).sin());
    assert!(matches!(
        RbfInterpolant::fit(line.as_ref(), fl.as_ref(), RbfOptions::cubic()),
        Err(ErbfError::Singular { .. })
    ));
    let s = RbfInterpolant::fit(x.as_ref(), f.as_ref(), RbfOptions::cubic()).unwrap();
    assert!(s.predict(&[0.5]).is_err());
    assert!(s.predict(&[0.5, f64::INFINITY]).is_err());
    assert!(s.is_outside(&[1.5, 0.5]));
    assert!(!s.is_outside(&[x[(0, 0)], x[(0, 1)]]));
}

#[test]
fn conditioning_diagnostics_flag_a_dense_gaussian() {
    let x = Mat::from_fn(40, 1, |i, _| i as f64 / 39.0);
    let f = Mat::from_fn(40, 1, |i, _| (6.0 * x[(i, 0)]).sin());
    let wide = RbfOptions::new(RadialFunction::Gaussian { width: 0.15 });
    match RbfInterpolant::fit(x.as_ref(), f.as_ref(), wide) {
        Err(ErbfError::Singular { .. }) => {}
        Ok(s) => assert!(s.condition_number().unwrap() > 1e12),
        Err(e) => panic!("unexpected {e}"),
    }
    let s = RbfInterpolant::fit(x.as_ref(), f.as_ref(), RbfOptions::cubic()).unwrap();
    let cond = s.condition_number().unwrap();
    assert!(cond > 1.0 && cond < 1e12, "cond {cond}");
    assert!(s.pivot_ratio() > 0.0 && s.pivot_ratio() <= 1.0);
}
