//! ERBF against the properties it must have (reference notes on ERBF, section 6).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use approx::assert_relative_eq;
use faer::linalg::solvers::Solve;
use faer::{Mat, MatRef};
use impactcal_core::{CoreError, Parameter, ParameterSpace};
use impactcal_erbf::{Accuracy, Erbf, ErbfError, ErbfOptions, LooMethod};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn unit_space(m: usize) -> ParameterSpace {
    ParameterSpace::new(
        (0..m)
            .map(|j| Parameter::new(format!("p{j}"), 0.0, 1.0, 0.5).unwrap())
            .collect(),
    )
    .unwrap()
}

/// A space with unequal, offset bounds: `p_j` in `[-1 - j, 2 + 3 j]`.
fn raw_space(m: usize) -> ParameterSpace {
    ParameterSpace::new(
        (0..m)
            .map(|j| {
                let (lo, hi) = (-1.0 - j as f64, 2.0 + 3.0 * j as f64);
                Parameter::new(format!("p{j}"), lo, hi, 0.5 * (lo + hi)).unwrap()
            })
            .collect(),
    )
    .unwrap()
}

fn random_unit(n: usize, m: usize, seed: u64) -> Mat<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    Mat::from_fn(n, m, |_, _| rng.random::<f64>())
}

/// A Latin hypercube design in the unit cube: one point in each of `n` strata per input.
fn lhs(n: usize, m: usize, seed: u64) -> Mat<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut cols = Vec::new();
    for _ in 0..m {
        let mut perm: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            perm.swap(i, rng.random_range(0..=i));
        }
        cols.push(
            perm.iter()
                .map(|&s| (s as f64 + rng.random::<f64>()) / n as f64)
                .collect::<Vec<_>>(),
        );
    }
    Mat::from_fn(n, m, |i, j| cols[j][i])
}

fn to_raw(space: &ParameterSpace, unit: MatRef<'_, f64>) -> Mat<f64> {
    let p = space.parameters();
    Mat::from_fn(unit.nrows(), unit.ncols(), |i, j| {
        p[j].lower + unit[(i, j)] * p[j].width()
    })
}

fn smooth(u: &[f64]) -> f64 {
    u.iter()
        .enumerate()
        .map(|(j, v)| (3.0 * v + j as f64).sin() + 0.5 * v * v)
        .sum::<f64>()
        + 2.0
}

fn eval(unit: MatRef<'_, f64>, f: impl Fn(&[f64]) -> f64) -> Mat<f64> {
    Mat::from_fn(unit.nrows(), 1, |i, _| {
        f(&unit.row(i).iter().copied().collect::<Vec<_>>())
    })
}

fn row(m: MatRef<'_, f64>, i: usize) -> Vec<f64> {
    m.row(i).iter().copied().collect()
}

#[test]
fn interpolation_matrix_has_n_times_3m_plus_1_columns() {
    for (n, m) in [(1, 1), (5, 2), (12, 3), (7, 6)] {
        let x = random_unit(n, m, 1);
        let f = eval(x.as_ref(), smooth);
        let e = Erbf::fit(
            &unit_space(m),
            x.as_ref(),
            f.as_ref(),
            ErbfOptions::default(),
        )
        .unwrap();
        let a = e.interpolation_matrix();
        assert_eq!((a.nrows(), a.ncols()), (n, n * (3 * m + 1)));
        assert_eq!(e.n_basis(), n * (3 * m + 1));
        // Row k is b(x_k); A c reproduces F.
        let ac = &a * e.coefficients();
        for k in 0..n {
            assert_relative_eq!(ac[(k, 0)], f[(k, 0)], epsilon = 1e-10);
        }
    }
}

#[test]
fn reproduces_training_data_below_1e_10() {
    for m in [1, 2, 3, 5, 10] {
        for n in [10, 50, 150] {
            let space = raw_space(m);
            let u = lhs(n, m, (100 * m + n) as u64);
            let x = to_raw(&space, u.as_ref());
            let f = eval(u.as_ref(), smooth);
            let e = Erbf::fit(&space, x.as_ref(), f.as_ref(), ErbfOptions::default())
                .unwrap_or_else(|err| panic!("m = {m}, N = {n}: {err}"));
            let res = e.training_residual();
            assert!(res < 1e-10, "m = {m}, N = {n}: residual {res:e}");
        }
    }
}

#[test]
fn reproduces_dense_designs_that_break_normal_equations() {
    // 1-D: 150 equally spaced points (spacing r_c / 22); Gaussian kernel matrix alone is
    // numerically singular here.
    let x1 = Mat::from_fn(150, 1, |i, _| i as f64 / 149.0);
    let f1 = eval(x1.as_ref(), |u| (8.0 * u[0]).sin() + u[0]);
    let e1 = Erbf::fit(
        &unit_space(1),
        x1.as_ref(),
        f1.as_ref(),
        ErbfOptions::default(),
    )
    .unwrap();
    assert!(
        e1.training_residual() < 1e-10,
        "1-D: {:e}",
        e1.training_residual()
    );
    // 2-D: a 12 x 12 grid plus 6 random points (N = 150).
    let mut x2 = Mat::from_fn(150, 2, |i, j| {
        if i < 144 {
            (if j == 0 { i / 12 } else { i % 12 }) as f64 / 11.0
        } else {
            0.0
        }
    });
    let extra = random_unit(6, 2, 3);
    for i in 0..6 {
        for j in 0..2 {
            x2[(144 + i, j)] = 0.05 + 0.9 * extra[(i, j)];
        }
    }
    let f2 = eval(x2.as_ref(), smooth);
    let e2 = Erbf::fit(
        &unit_space(2),
        x2.as_ref(),
        f2.as_ref(),
        ErbfOptions::default(),
    )
    .unwrap();
    assert!(
        e2.training_residual() < 1e-10,
        "2-D: {:e}",
        e2.training_residual()
    );
}

#[test]
fn columns_fitted_together_equal_columns_fitted_alone_and_superpose() {
    let space = raw_space(3);
    let u = random_unit(40, 3, 4);
    let x = to_raw(&space, u.as_ref());
    // T = 60 > N exercises the factored prediction path; single columns the direct one.
    let f = Mat::from_fn(40, 60, |i, t| {
        let p = row(u.as_ref(), i);
        (0.1 * t as f64 * (1.0 + p[0])).sin() * smooth(&p) + p[1] * t as f64 * 0.01
    });
    let opts = ErbfOptions::default();
    let all = Erbf::fit(&space, x.as_ref(), f.as_ref(), opts).unwrap();
    let q = to_raw(&space, random_unit(25, 3, 5).as_ref());
    let p_all = all.predict_batch(q.as_ref()).unwrap();
    let x0 = row(q.as_ref(), 0);
    let g_all = all.predict_gradient(&x0).unwrap();
    for t in [0, 7, 33, 59] {
        let one = Erbf::fit(&space, x.as_ref(), f.as_ref().subcols(t, 1), opts).unwrap();
        let p = one.predict_batch(q.as_ref()).unwrap();
        for i in 0..25 {
            assert_relative_eq!(
                p_all[(i, t)],
                p[(i, 0)],
                epsilon = 1e-12,
                max_relative = 1e-12
            );
        }
        let g = one.predict_gradient(&x0).unwrap();
        for j in 0..3 {
            assert_relative_eq!(
                g_all[(t, j)],
                g[(0, j)],
                epsilon = 1e-10,
                max_relative = 1e-10
            );
        }
    }
    // fit(a F1 + b F2) = a fit(F1) + b fit(F2).
    let (a, b) = (2.5, -0.75);
    let f1 = f.as_ref().subcols(3, 1);
    let f2 = f.as_ref().subcols(40, 1);
    let combo = Mat::from_fn(40, 1, |i, _| a * f1[(i, 0)] + b * f2[(i, 0)]);
    let pc = Erbf::fit(&space, x.as_ref(), combo.as_ref(), opts)
        .unwrap()
        .predict_batch(q.as_ref())
        .unwrap();
    for i in 0..25 {
        assert_relative_eq!(
            pc[(i, 0)],
            a * p_all[(i, 3)] + b * p_all[(i, 40)],
            epsilon = 1e-11,
            max_relative = 1e-11
        );
    }
}

#[test]
fn invariant_to_sample_order_and_to_raw_versus_scaled_inputs() {
    let m = 4;
    let u = random_unit(30, m, 6);
    let f = eval(u.as_ref(), smooth);
    let qu = random_unit(20, m, 7);
    let scaled = Erbf::fit(
        &unit_space(m),
        u.as_ref(),
        f.as_ref(),
        ErbfOptions::default(),
    )
    .unwrap()
    .predict_batch(qu.as_ref())
    .unwrap();
    let space = raw_space(m);
    let raw = Erbf::fit(
        &space,
        to_raw(&space, u.as_ref()).as_ref(),
        f.as_ref(),
        ErbfOptions::default(),
    )
    .unwrap()
    .predict_batch(to_raw(&space, qu.as_ref()).as_ref())
    .unwrap();
    let perm: Vec<usize> = (0..30).map(|i| (7 * i + 3) % 30).collect();
    let up = Mat::from_fn(30, m, |i, j| u[(perm[i], j)]);
    let fp = Mat::from_fn(30, 1, |i, _| f[(perm[i], 0)]);
    let permuted = Erbf::fit(
        &unit_space(m),
        up.as_ref(),
        fp.as_ref(),
        ErbfOptions::default(),
    )
    .unwrap()
    .predict_batch(qu.as_ref())
    .unwrap();
    for i in 0..20 {
        assert_relative_eq!(raw[(i, 0)], scaled[(i, 0)], epsilon = 1e-10);
        assert_relative_eq!(permuted[(i, 0)], scaled[(i, 0)], epsilon = 1e-10);
    }
}

#[test]
fn gradient_matches_central_differences_in_all_regions() {
    let space = raw_space(2);
    let u = random_unit(15, 2, 8);
    let x = to_raw(&space, u.as_ref());
    let f = Mat::from_fn(15, 3, |i, t| smooth(&row(u.as_ref(), i)) * (1.0 + t as f64));
    for opts in [
        ErbfOptions::default(),
        ErbfOptions {
            order: 6,
            gamma: 0.3,
            rc: 0.2,
            ..ErbfOptions::default()
        },
    ] {
        let e = Erbf::fit(&space, x.as_ref(), f.as_ref(), opts).unwrap();
        // Inside (offsets in all four regions to the various centres) and outside the box.
        let queries = [
            [0.31, 0.62],
            [0.05, 0.93],
            [0.77, 0.18],
            [-0.4, 0.5],
            [1.6, -0.3],
        ];
        for qu in queries {
            let q: Vec<f64> = space.from_unit(&qu).unwrap();
            let g = e.predict_gradient(&q).unwrap();
            for j in 0..2 {
                let h = 1e-6 * space.parameters()[j].width();
                let mut a = q.clone();
                let mut b = q.clone();
                a[j] += h;
                b[j] -= h;
                let pa = e.predict(&a).unwrap();
                let pb = e.predict(&b).unwrap();
                for t in 0..3 {
                    let fd = (pa[t] - pb[t]) / (2.0 * h);
                    assert!(
                        (g[(t, j)] - fd).abs() < 1e-5 * (1.0 + fd.abs()),
                        "q = {qu:?}, j = {j}, t = {t}: {} vs {fd}",
                        g[(t, j)]
                    );
                }
            }
        }
    }
}

#[test]
fn extrapolates_linearly_far_outside() {
    let space = unit_space(3);
    let u = random_unit(30, 3, 9);
    let f = eval(u.as_ref(), smooth);
    let e = Erbf::fit(&space, u.as_ref(), f.as_ref(), ErbfOptions::default()).unwrap();
    let dir = [0.6, -0.3, 0.74];
    let at = |s: f64| -> f64 {
        let p: Vec<f64> = (0..3).map(|j| 0.5 + s * dir[j]).collect();
        e.predict(&p).unwrap()[0]
    };
    // Beyond s = 3 every offset exceeds gamma + 1 and the Gaussians are below 1e-40.
    let h = 1.0;
    let (f0, f1, f2) = (at(5.0), at(5.0 + h), at(5.0 + 2.0 * h));
    let slope = (f1 - f0).abs();
    assert!(slope > 1e-3, "the model should have a trend outside");
    assert!((f2 - 2.0 * f1 + f0).abs() < 1e-10 * slope.max(1.0));
    assert!(e.is_outside(&[0.5, 1.2, 0.5]));
    assert!(!e.is_outside(&[0.5, 1.0, 0.0]));
}

#[test]
fn centring_reproduces_a_constant_exactly_everywhere() {
    let u = random_unit(20, 2, 10);
    let f = Mat::from_fn(20, 2, |_, t| 3.0 + t as f64);
    let opts = ErbfOptions {
        center_outputs: true,
        ..ErbfOptions::default()
    };
    let e = Erbf::fit(&unit_space(2), u.as_ref(), f.as_ref(), opts).unwrap();
    let p = e.predict(&[1.7, -0.4]).unwrap();
    assert_relative_eq!(p[0], 3.0, epsilon = 1e-14);
    assert_relative_eq!(p[1], 4.0, epsilon = 1e-14);
}

#[test]
fn exact_loo_equals_brute_force_refits() {
    let space = raw_space(2);
    let u = random_unit(12, 2, 11);
    let x = to_raw(&space, u.as_ref());
    let f = Mat::from_fn(12, 2, |i, t| {
        smooth(&row(u.as_ref(), i)) + t as f64 * u[(i, 0)]
    });
    let e = Erbf::fit(&space, x.as_ref(), f.as_ref(), ErbfOptions::default()).unwrap();
    let loo = e.loo_errors(LooMethod::Refit).unwrap();
    for k in [0, 5, 11] {
        let keep: Vec<usize> = (0..12).filter(|&i| i != k).collect();
        let xk = Mat::from_fn(11, 2, |i, j| x[(keep[i], j)]);
        let fk = Mat::from_fn(11, 2, |i, t| f[(keep[i], t)]);
        let model = Erbf::fit(&space, xk.as_ref(), fk.as_ref(), ErbfOptions::default()).unwrap();
        let p = model.predict(&row(x.as_ref(), k)).unwrap();
        for t in 0..2 {
            assert_relative_eq!(loo[(k, t)], f[(k, t)] - p[t], epsilon = 1e-10);
        }
    }
    let approx = e.loo_errors(LooMethod::Closed).unwrap();
    assert!(approx.col(0).iter().all(|v| v.is_finite()));
}

#[test]
fn serde_round_trip_predicts_the_same() {
    let space = raw_space(2);
    let u = random_unit(15, 2, 12);
    let x = to_raw(&space, u.as_ref());
    let f = Mat::from_fn(15, 30, |i, t| {
        smooth(&row(u.as_ref(), i)) * (t as f64).cos()
    });
    let e = Erbf::fit(&space, x.as_ref(), f.as_ref(), ErbfOptions::default()).unwrap();
    let back: Erbf = serde_json::from_str(&serde_json::to_string(&e).unwrap()).unwrap();
    let q = space.from_unit(&[0.3, 0.8]).unwrap();
    let (a, b) = (e.predict(&q).unwrap(), back.predict(&q).unwrap());
    for t in 0..30 {
        assert_relative_eq!(a[t], b[t], epsilon = 1e-13);
    }
    assert_eq!(back.options(), e.options());
}

#[test]
fn invalid_input_is_a_typed_error() {
    let space = unit_space(2);
    let u = random_unit(10, 2, 13);
    let f = eval(u.as_ref(), smooth);
    let fit = |x: MatRef<'_, f64>, f: MatRef<'_, f64>, o: ErbfOptions| Erbf::fit(&space, x, f, o);
    let d = ErbfOptions::default();
    let empty = Mat::<f64>::zeros(0, 2);
    assert!(matches!(
        fit(empty.as_ref(), Mat::<f64>::zeros(0, 1).as_ref(), d),
        Err(ErbfError::Core(CoreError::Empty { .. }))
    ));
    let mut dup = u.clone();
    dup[(6, 0)] = u[(1, 0)];
    dup[(6, 1)] = u[(1, 1)];
    assert!(matches!(
        fit(dup.as_ref(), f.as_ref(), d),
        Err(ErbfError::DuplicateSamples {
            first: 1,
            second: 6,
            ..
        })
    ));
    let mut nan = u.clone();
    nan[(3, 1)] = f64::NAN;
    assert!(matches!(
        fit(nan.as_ref(), f.as_ref(), d),
        Err(ErbfError::Core(CoreError::NonFinite { location, .. }))
            if location == "row 3, column 1 (0-based)"
    ));
    let mut inf = f.clone();
    inf[(2, 0)] = f64::INFINITY;
    assert!(matches!(
        fit(u.as_ref(), inf.as_ref(), d),
        Err(ErbfError::Core(CoreError::NonFinite { .. }))
    ));
    let three = random_unit(10, 3, 14);
    assert!(matches!(
        fit(three.as_ref(), f.as_ref(), d),
        Err(ErbfError::Core(CoreError::DimensionMismatch { .. }))
    ));
    assert!(matches!(
        fit(u.as_ref(), f.as_ref().subrows(0, 9), d),
        Err(ErbfError::Core(CoreError::DimensionMismatch { .. }))
    ));
    for bad in [
        ErbfOptions { gamma: 0.0, ..d },
        ErbfOptions { gamma: -0.1, ..d },
        ErbfOptions { rc: 0.0, ..d },
        ErbfOptions { rc: f64::NAN, ..d },
        ErbfOptions { order: 3, ..d },
        ErbfOptions { order: 0, ..d },
    ] {
        assert!(matches!(
            fit(u.as_ref(), f.as_ref(), bad),
            Err(ErbfError::Core(CoreError::InvalidOption { .. }))
        ));
    }
    let e = fit(u.as_ref(), f.as_ref(), d).unwrap();
    assert!(e.predict(&[0.5]).is_err());
    assert!(e.predict(&[0.5, f64::NAN]).is_err());
}

/// Displacement of a damped oscillator released with velocity `v0`:
/// `x(t) = v0 / w_d exp(-zeta w t) sin(w_d t)`.
fn oscillator(p: &[f64], times: &[f64]) -> Vec<f64> {
    let (k, c, m, v0) = (p[0], p[1], p[2], p[3]);
    let w = (k / m).sqrt();
    let zeta = c / (2.0 * (k * m).sqrt());
    let wd = w * (1.0 - zeta * zeta).sqrt();
    times
        .iter()
        .map(|&t| v0 / wd * (-zeta * w * t).exp() * (wd * t).sin())
        .collect()
}

fn oscillator_space() -> ParameterSpace {
    ParameterSpace::new(vec![
        Parameter::new("k", 800.0, 1200.0, 1000.0).unwrap(),
        Parameter::new("c", 2.0, 8.0, 5.0).unwrap(),
        Parameter::new("m", 0.8, 1.2, 1.0).unwrap(),
        Parameter::new("v0", 1.0, 3.0, 2.0).unwrap(),
    ])
    .unwrap()
}

#[test]
fn oscillator_time_histories() {
    let space = oscillator_space();
    let times: Vec<f64> = (0..500).map(|i| i as f64 * 2e-4).collect();
    let histories = |x: MatRef<'_, f64>| {
        let rows: Vec<Vec<f64>> = (0..x.nrows())
            .map(|i| oscillator(&row(x, i), &times))
            .collect();
        Mat::from_fn(x.nrows(), times.len(), |i, t| rows[i][t])
    };
    let test = to_raw(&space, random_unit(200, 4, 15).as_ref());
    let truth = histories(test.as_ref());
    let mut raae = Vec::new();
    for n in [50, 150] {
        let x = to_raw(&space, random_unit(n, 4, 16 + n as u64).as_ref());
        let f = histories(x.as_ref());
        let e = Erbf::fit(&space, x.as_ref(), f.as_ref(), ErbfOptions::default()).unwrap();
        assert!(
            e.training_residual() < 1e-10,
            "N = {n}: {:e}",
            e.training_residual()
        );
        let acc = Accuracy::new(
            e.predict_batch(test.as_ref()).unwrap().as_ref(),
            truth.as_ref(),
        );
        raae.push(acc.raae);
        assert!(acc.r2 > 0.9, "N = {n}: {acc:?}");
    }
    // More samples, better surrogate.
    assert!(raae[1] < raae[0], "RAAE {raae:?}");
}

/// One and two samples with a long output (the tabulated projection path) still reproduce
/// the training data and predict finite values everywhere.
#[test]
fn tiny_designs_with_long_outputs() {
    let space = raw_space(3);
    for n in [1, 2] {
        let u = random_unit(n, 3, 21);
        let x = to_raw(&space, u.as_ref());
        let f = Mat::from_fn(n, 50, |i, t| (i + 1) as f64 * (0.1 * t as f64).sin() + 2.0);
        let model = Erbf::fit(&space, x.as_ref(), f.as_ref(), ErbfOptions::default()).unwrap();
        assert!(model.training_residual() < 1e-10, "N = {n}");
        let q = to_raw(&space, random_unit(7, 3, 22).as_ref());
        let p = model.predict_batch(q.as_ref()).unwrap();
        assert!(p.col_iter().all(|c| c.iter().all(|v| v.is_finite())));
    }
}

/// With smoothing the fit solves the ridge problem `min ||A c - F_c||^2 + lambda ||c||^2`
/// on centred outputs (`lambda = smoothing tr(A A^T) / N`): its stationarity condition
/// `A^T (F_c - A c) = lambda c` holds; its closed-form leave-one-out errors equal explicit
/// kernel ridge refits with the kernel matrix `G = A A^T` held fixed; and the exact refits
/// (`LooMethod::Refit`) lie close to them.
#[test]
fn smoothing_solves_the_ridge_problem_and_its_loo_is_exact() {
    let (n, m) = (25, 2);
    let u = random_unit(n, m, 17);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let f = Mat::from_fn(n, 2, |i, c| {
        (3.0 * u[(i, 0)]).sin() + c as f64 * u[(i, 1)] + 0.1 * (rng.random::<f64>() - 0.5)
    });
    let smoothing = 1e-2;
    let opts = ErbfOptions {
        smoothing,
        ..ErbfOptions::default()
    };
    let e = Erbf::fit(&unit_space(m), u.as_ref(), f.as_ref(), opts).unwrap();
    let a = e.interpolation_matrix();
    let g = &a * a.transpose();
    let lambda = smoothing * (0..n).map(|k| g[(k, k)]).sum::<f64>() / n as f64;
    let mut fc = f.clone();
    for c in 0..2 {
        let mean = f.col(c).iter().sum::<f64>() / n as f64;
        fc.col_mut(c).iter_mut().for_each(|v| *v -= mean);
    }
    let c = e.coefficients();
    let lhs = a.transpose() * (&fc - &a * &c);
    let rhs = &c * lambda;
    assert!(
        (&lhs - &rhs).norm_max() <= 1e-9 * rhs.norm_max(),
        "ridge condition"
    );
    // The fit no longer interpolates.
    assert!(e.training_residual() > 1e-4);
    // Kernel ridge refits without each sample, G fixed.
    let loo = e.loo_errors(LooMethod::Closed).unwrap();
    for k in 0..n {
        let keep: Vec<usize> = (0..n).filter(|&i| i != k).collect();
        let gk = Mat::from_fn(n - 1, n - 1, |i, j| {
            g[(keep[i], keep[j])] + if i == j { lambda } else { 0.0 }
        });
        let fk = Mat::from_fn(n - 1, 2, |i, c| fc[(keep[i], c)]);
        let alpha = gk.partial_piv_lu().solve(&fk);
        for c in 0..2 {
            let pred: f64 = (0..n - 1).map(|i| g[(k, keep[i])] * alpha[(i, c)]).sum();
            assert_relative_eq!(loo[(k, c)], fc[(k, c)] - pred, epsilon = 1e-8);
        }
    }
    let refit = e.loo_errors(LooMethod::Refit).unwrap();
    let gap = (&refit - &loo).norm_l2() / loo.norm_l2();
    assert!(gap < 0.5, "refit and kernel-view LOO differ by {gap}");
    // Bad smoothing is refused.
    for bad in [-1.0, f64::NAN, f64::INFINITY] {
        let o = ErbfOptions {
            smoothing: bad,
            ..ErbfOptions::default()
        };
        assert!(matches!(
            Erbf::fit(&unit_space(m), u.as_ref(), f.as_ref(), o),
            Err(ErbfError::Core(CoreError::InvalidOption { .. }))
        ));
    }
}

/// Long outputs (several blocks of the product `V^T F` and a partial last one): the batch
/// prediction is the same, bit for bit, on 1 and 3 threads, and at the training points
/// equals `A c` with the explicit coefficients.
#[test]
fn long_output_predictions_do_not_depend_on_threads() {
    let (n, m, t) = (24, 3, 1300);
    let space = unit_space(m);
    let x = lhs(n, m, 5);
    let f = Mat::from_fn(n, t, |i, c| {
        let u = row(x.as_ref(), i);
        (smooth(&u) * (1.0 + 0.01 * c as f64)).sin()
    });
    let model = Erbf::fit(&space, x.as_ref(), f.as_ref(), ErbfOptions::default()).unwrap();
    let q = random_unit(70, m, 6);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| model.predict_batch(q.as_ref()).unwrap())
    };
    assert_eq!(run(1), run(3));
    // At the training points the batch product equals the explicit form A c.
    let explicit = model.interpolation_matrix() * model.coefficients();
    let batch = model.predict_batch(x.as_ref()).unwrap();
    for i in 0..n {
        for col in 0..t {
            assert_relative_eq!(batch[(i, col)], explicit[(i, col)], epsilon = 1e-9);
        }
    }
}
