//! The bordered (point-by-point) factorisation against a from-scratch fit.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use impactcal_erbf::{BorderedRbf, RadialFunction, RbfCoefficients, RbfInterpolant, RbfOptions};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `n` points of the unit cube, `close` of them within `gap` to `close * gap` of an earlier
/// point.
fn point_set(seed: u64, dim: usize, n: usize, close: usize, gap: f64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut pts: Vec<Vec<f64>> = (0..n)
        .map(|_| (0..dim).map(|_| rng.random::<f64>()).collect())
        .collect();
    for k in 0..close.min(n.saturating_sub(dim + 2)) {
        let i = n - 1 - k;
        let j = rng.random_range(0..i);
        let dir: Vec<f64> = (0..dim).map(|_| rng.random::<f64>() - 0.5).collect();
        let norm = dir.iter().map(|v| v * v).sum::<f64>().sqrt();
        pts[i] = pts[j]
            .iter()
            .zip(&dir)
            .map(|(p, v)| {
                let step = gap * (1.0 + k as f64) * v / norm;
                if (0.0..=1.0).contains(&(p + step)) {
                    p + step
                } else {
                    p - step
                }
            })
            .collect();
    }
    pts
}

fn objective(x: &[f64]) -> f64 {
    x.iter()
        .enumerate()
        .map(|(j, v)| (3.0 * v + j as f64).sin() + v * v)
        .sum()
}

fn build(radial: RadialFunction, pts: &[Vec<f64>]) -> BorderedRbf {
    let dim = pts[0].len();
    let mut model = BorderedRbf::new(radial, &vec![0.0; dim], &vec![1.0; dim]).unwrap();
    for p in pts {
        model.push(p).unwrap();
    }
    model
}

/// The largest interpolation residual, and the largest difference between the bordered fit
/// and `RbfInterpolant::fit` at the points and at random queries, both over the larger of
/// `max |f|` and `sum |c_i|` (the kernel sum whose rounding bounds how closely
/// any two solvers can agree: 1 to 10 times `max |f|` for well-spread points, up to 10^4
/// times with points 1e-4 apart); and the number of full refactorisations.
fn errors(radial: RadialFunction, pts: &[Vec<f64>], seed: u64) -> (f64, f64, usize) {
    let dim = pts[0].len();
    let values: Vec<f64> = pts.iter().map(|p| objective(p)).collect();
    let model = build(radial, pts);
    let coef: RbfCoefficients = model
        .solve(&values)
        .unwrap_or_else(|e| panic!("{e} for {radial:?} at {pts:?}"));
    let scale = values.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    // The size of the kernel sum relative to the values: rounding in any evaluation of
    // `sum c_i phi_i` is of the order of eps times it, and it grows as points close in.
    let growth = (coef.weights.iter().map(|c| c.abs()).sum::<f64>() / scale).max(1.0);
    let residual = pts
        .iter()
        .zip(&values)
        .map(|(p, v)| (coef.value(radial, model.points(), p) - v).abs())
        .fold(0.0, f64::max)
        / scale
        / growth;
    let x = Mat::from_fn(pts.len(), dim, |i, j| pts[i][j]);
    let f = Mat::from_fn(pts.len(), 1, |i, _| values[i]);
    // On some 1-D sets the from-scratch fit finds an exactly zero pivot (its tail scaling
    // depends on the points); there is then nothing to compare with.
    let Ok(scratch) = RbfInterpolant::fit(x.as_ref(), f.as_ref(), RbfOptions::new(radial)) else {
        assert_eq!(dim, 1, "from-scratch fit failed in {dim} dimensions");
        return (residual, 0.0, model.refactorisations());
    };
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5EED);
    let queries: Vec<Vec<f64>> = (0..50)
        .map(|_| (0..dim).map(|_| rng.random::<f64>()).collect())
        .chain(pts.iter().cloned())
        .collect();
    let mismatch = queries
        .iter()
        .map(|q| (coef.value(radial, model.points(), q) - scratch.predict(q).unwrap()[0]).abs())
        .fold(0.0, f64::max)
        / scale;
    (residual, mismatch / growth, model.refactorisations())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Random point sets, some with points within 1e-4 to 1e-3 of another (CORS keeps its
    /// points at least `1e-3 sqrt(d)` apart): the bordered
    /// interpolant interpolates to 1e-10 and equals a from-scratch fit to 1e-9, both relative
    /// to the larger of the largest value and the kernel sum `sum |c_i|` (the same for
    /// well-spread points), for the cubic and the thin-plate spline.
    #[test]
    fn bordered_fit_matches_a_fit_from_scratch(
        seed in any::<u64>(),
        dim in 1usize..=6,
        extra in 1usize..60,
        close in 0usize..4,
        gap_exp in -4.0f64..-3.0,
        thin_plate in any::<bool>(),
    ) {
        let radial = if thin_plate { RadialFunction::ThinPlate } else { RadialFunction::Cubic };
        let pts = point_set(seed, dim, dim + 1 + extra, close, 10f64.powf(gap_exp));
        let (residual, mismatch, _) = errors(radial, &pts, seed);
        prop_assert!(residual <= 1e-10, "residual {residual:e}");
        prop_assert!(mismatch <= 1e-9, "mismatch {mismatch:e}");
    }
}

/// The factors depend on the sequence of points only: a model extended in two sessions
/// (cloned in between) solves bit for bit like one built in one go.
#[test]
fn extension_equals_replay_bit_for_bit() {
    let pts = point_set(7, 4, 120, 3, 1e-5);
    let values: Vec<f64> = pts.iter().map(|p| objective(p)).collect();
    let whole = build(RadialFunction::Cubic, &pts);
    let mut first = build(RadialFunction::Cubic, &pts[..40]);
    let saved = first.clone();
    for p in &pts[40..] {
        first.push(p).unwrap();
    }
    let a = whole.solve(&values).unwrap();
    let b = first.solve(&values).unwrap();
    assert_eq!(a, b);
    assert_eq!(saved.n_points(), 40);
}

/// A point almost on top of another makes the bordered pivot vanish: the model falls back
/// to a full factorisation and stays exact.
#[test]
fn a_nearly_coincident_point_refactorises() {
    let mut pts = point_set(11, 3, 30, 0, 0.0);
    let mut near = pts[5].clone();
    near[0] += 1e-6;
    pts.push(near);
    pts.push(vec![0.3, 0.6, 0.9]);
    let (residual, mismatch, refactorisations) = errors(RadialFunction::Cubic, &pts, 11);
    assert!(refactorisations >= 1, "no full factorisation");
    assert!(residual <= 1e-10, "residual {residual:e}");
    assert!(mismatch <= 1e-6, "mismatch {mismatch:e}");
}

/// Fewer than `d + 1` points or points on a hyperplane: no factorisation, a typed error.
#[test]
fn degenerate_sets_are_not_factorised() {
    let mut model = BorderedRbf::new(RadialFunction::Cubic, &[0.0, 0.0], &[1.0, 1.0]).unwrap();
    for t in [0.1, 0.4, 0.7, 0.9] {
        model.push(&[t, t]).unwrap();
    }
    assert!(!model.is_factorised());
    assert!(model.solve(&[1.0, 2.0, 3.0, 4.0]).is_err());
    model.push(&[0.2, 0.8]).unwrap();
    assert!(model.is_factorised());
    assert!(model.solve(&[1.0, 2.0, 3.0, 4.0, 5.0]).is_ok());
    assert!(model.push(&[0.2]).is_err());
    assert!(model.push(&[f64::NAN, 0.1]).is_err());
    assert!(model.solve(&[1.0, 2.0]).is_err());
    assert!(model.solve(&[1.0, 2.0, 3.0, 4.0, f64::INFINITY]).is_err());
    assert_eq!(model.n_points(), 5);
    assert!(BorderedRbf::new(RadialFunction::Cubic, &[0.0, 1.0], &[1.0, 0.0]).is_err());
    assert!(BorderedRbf::new(RadialFunction::Cubic, &[0.0], &[1.0, 1.0]).is_err());
}
