//! Tests of the impact-shape decomposition, M2 and expansion against analytic values and
//! invariants (reference values: shapes-efi notes §4.4).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use approx::assert_relative_eq;
use faer::{Mat, MatRef};
use impactcal_core::{CoreError, Histories};
use impactcal_shapes::{
    ContributionBasis, Expansion, ImpactShapes, Orthogonality, RandomizedSvd, ShapeOptions,
    ShapesError, SvdMethod, Truncation,
};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};

const L: usize = 200;

/// y = 3 u1 g1^T + 1 u2 g2^T with u1 = [1,1,1,1]/2, u2 = [1,-1,1,-1]/2 and g1, g2 the
/// normalised sine and cosine over one period.
fn two_shape_data() -> (Mat<f64>, [f64; 4], [f64; 4]) {
    let u1 = [0.5, 0.5, 0.5, 0.5];
    let u2 = [0.5, -0.5, 0.5, -0.5];
    let norm = (L as f64 / 2.0).sqrt();
    let g1 = |j: usize| (2.0 * std::f64::consts::PI * j as f64 / L as f64).sin() / norm;
    let g2 = |j: usize| (2.0 * std::f64::consts::PI * j as f64 / L as f64).cos() / norm;
    let y = Mat::from_fn(4, L, |i, j| 3.0 * u1[i] * g1(j) + u2[i] * g2(j));
    (y, u1, u2)
}

fn max_abs_diff(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> f64 {
    let mut d = 0.0f64;
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            d = d.max((a[(i, j)] - b[(i, j)]).abs());
        }
    }
    d
}

fn random_matrix(m: usize, n: usize, seed: u64) -> Mat<f64> {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    Mat::from_fn(m, n, |_, _| rng.random_range(-1.0..1.0))
}

#[test]
fn exact_low_rank_golden_values() {
    let (y, u1, u2) = two_shape_data();
    let s = ImpactShapes::from_matrix(y.as_ref(), &ShapeOptions::default()).unwrap();
    assert_eq!(s.len(), 2);
    assert_eq!(s.rank(), 2);
    assert_relative_eq!(s.singular_values()[0], 3.0, max_relative = 1e-12);
    assert_relative_eq!(s.singular_values()[1], 1.0, max_relative = 1e-12);
    let c = s.contributions();
    assert_relative_eq!(c[0], 0.75, epsilon = 1e-12);
    assert_relative_eq!(c[1], 0.25, epsilon = 1e-12);
    let e = s.energy_fractions();
    assert_relative_eq!(e[0], 0.9, epsilon = 1e-12);
    assert_relative_eq!(e[1], 0.1, epsilon = 1e-12);
    for (j, u) in [u1, u2].iter().enumerate() {
        let dot: f64 = (0..4).map(|i| s.shapes()[(i, j)] * u[i]).sum();
        assert_relative_eq!(dot.abs(), 1.0, epsilon = 1e-12);
    }
    // Sign rule: the largest-magnitude entry is positive (u1 all equal: first entry).
    assert!(s.shapes()[(0, 0)] > 0.0 && s.shapes()[(0, 1)] > 0.0);
    assert_eq!(s.contribution_basis(), ContributionBasis::AllSingularValues);
}

#[test]
fn sign_rule_is_deterministic_and_keeps_the_product() {
    let y = random_matrix(12, 40, 1);
    let neg = Mat::from_fn(12, 40, |i, j| -y[(i, j)]);
    let a = ImpactShapes::from_matrix(y.as_ref(), &ShapeOptions::default()).unwrap();
    let b = ImpactShapes::from_matrix(neg.as_ref(), &ShapeOptions::default()).unwrap();
    assert!(max_abs_diff(a.shapes(), b.shapes()) < 1e-10);
    let minus_g = Mat::from_fn(40, a.len(), |i, j| -a.time_functions()[(i, j)]);
    assert!(max_abs_diff(b.time_functions(), minus_g.as_ref()) < 1e-10);
    assert!(max_abs_diff(a.reconstruct(a.len()).as_ref(), y.as_ref()) < 1e-12);
    for j in 0..a.len() {
        let col = a.shapes().col(j);
        let (imax, _) = col.iter().enumerate().fold((0, 0.0f64), |acc, (i, x)| {
            if x.abs() > acc.1 { (i, x.abs()) } else { acc }
        });
        assert!(col[imax] > 0.0);
    }
}

#[test]
fn truncation_rules() {
    let y = Mat::from_fn(6, 50, |i, j| {
        let t = j as f64 / 50.0;
        (0..6)
            .map(|k| 0.5f64.powi(k) * ((k + 1) as f64 * 3.0 * t + i as f64 * k as f64).sin())
            .sum::<f64>()
            * (i + 1) as f64
    });
    let full = ImpactShapes::from_matrix(y.as_ref(), &ShapeOptions::default()).unwrap();
    let c = full.contributions();
    let by_count = ImpactShapes::from_matrix(y.as_ref(), &ShapeOptions::count(3)).unwrap();
    assert_eq!(by_count.len(), 3);
    let target = c[0] + c[1] + 0.5 * c[2];
    let opts = ShapeOptions {
        truncation: Truncation::Contribution(target),
        method: SvdMethod::Full,
    };
    assert_eq!(
        ImpactShapes::from_matrix(y.as_ref(), &opts).unwrap().len(),
        3
    );
    let s = full.singular_values();
    let total: f64 = s.iter().map(|v| v * v).sum();
    let err2 = (s[2..].iter().map(|v| v * v).sum::<f64>() / total).sqrt();
    let opts = ShapeOptions {
        truncation: Truncation::ReconstructionError(err2 * 1.0001),
        method: SvdMethod::Full,
    };
    let two = ImpactShapes::from_matrix(y.as_ref(), &opts).unwrap();
    assert_eq!(two.len(), 2);
    let r = two.reconstruct(2);
    let diff = Mat::from_fn(6, 50, |i, j| y[(i, j)] - r[(i, j)]);
    assert_relative_eq!(diff.norm_l2() / y.norm_l2(), err2, max_relative = 1e-9);
}

#[test]
fn bad_input_is_a_typed_error() {
    let (y, _, _) = two_shape_data();
    assert!(matches!(
        ImpactShapes::from_matrix(y.as_ref(), &ShapeOptions::count(3)),
        Err(ShapesError::TooManyShapes {
            requested: 3,
            rank: 2
        })
    ));
    let mut bad = y.clone();
    bad[(2, 7)] = f64::NAN;
    assert!(matches!(
        ImpactShapes::from_matrix(bad.as_ref(), &ShapeOptions::default()),
        Err(ShapesError::Core(CoreError::NonFinite { location, .. }))
            if location == "row 2, column 7 (0-based)"
    ));
    let empty = Mat::<f64>::zeros(0, 3);
    assert!(matches!(
        ImpactShapes::from_matrix(empty.as_ref(), &ShapeOptions::default()),
        Err(ShapesError::Core(CoreError::Empty { .. }))
    ));
    for t in [
        Truncation::Count(0),
        Truncation::Contribution(1.5),
        Truncation::ReconstructionError(-0.1),
    ] {
        let o = ShapeOptions {
            truncation: t,
            method: SvdMethod::Auto,
        };
        assert!(matches!(
            ImpactShapes::from_matrix(y.as_ref(), &o),
            Err(ShapesError::Core(CoreError::InvalidOption { .. }))
        ));
    }
    let o = ShapeOptions {
        truncation: Truncation::All,
        method: SvdMethod::Randomized(RandomizedSvd::default()),
    };
    assert!(ImpactShapes::from_matrix(y.as_ref(), &o).is_err());
    let other = Mat::from_fn(5, 10, |i, j| (i + j) as f64);
    assert!(matches!(
        Orthogonality::from_matrices(y.as_ref(), other.as_ref()),
        Err(ShapesError::Core(CoreError::DimensionMismatch { .. }))
    ));
}

/// A matrix with prescribed singular values `sigma_j` and random orthonormal factors.
fn decaying(m: usize, n: usize, sigma: &[f64], seed: u64) -> Mat<f64> {
    let u = random_matrix(m, sigma.len(), seed).qr().compute_thin_Q();
    let v = random_matrix(n, sigma.len(), seed + 1)
        .qr()
        .compute_thin_Q();
    let mut us = u.clone();
    for (j, s) in sigma.iter().enumerate() {
        us.col_mut(j).iter_mut().for_each(|x| *x *= s);
    }
    &us * v.transpose()
}

#[test]
fn randomized_solver_matches_full_svd_on_decaying_spectra() {
    let sigma: Vec<f64> = (0..120).map(|j| 0.8f64.powi(j)).collect();
    let y = decaying(600, 900, &sigma, 7);
    let full = ImpactShapes::from_matrix(
        y.as_ref(),
        &ShapeOptions {
            truncation: Truncation::Count(15),
            method: SvdMethod::Full,
        },
    )
    .unwrap();
    // Auto picks the randomized solver here (min(m, L) = 600 >= 400, 15 + 10 <= 150).
    let fast = ImpactShapes::from_matrix(y.as_ref(), &ShapeOptions::count(15)).unwrap();
    assert_eq!(fast.contribution_basis(), ContributionBasis::ComputedOnly);
    for (a, b) in fast.singular_values().iter().zip(full.singular_values()) {
        assert!((a - b).abs() <= 1e-6 * b, "{a} vs {b}");
    }
    let m2 = Orthogonality::from_matrices(fast.shapes(), full.shapes()).unwrap();
    for p in m2.pairs() {
        assert_eq!(p.analysis, p.test);
        assert!(p.value > 1.0 - 1e-8);
    }
    // Energy fractions are exact for both solvers.
    for (a, b) in fast.energy_fractions().iter().zip(full.energy_fractions()) {
        assert_relative_eq!(*a, b, max_relative = 1e-6);
    }
    // Same seed, same answer.
    let again = ImpactShapes::from_matrix(y.as_ref(), &ShapeOptions::count(15)).unwrap();
    assert_eq!(again.singular_values(), fast.singular_values());
}

#[test]
fn m2_of_rotated_basis_is_the_rotation() {
    let (y, _, _) = two_shape_data();
    let s = ImpactShapes::from_matrix(y.as_ref(), &ShapeOptions::default()).unwrap();
    let phi = s.shapes();
    let theta = 0.3f64;
    let (c, sn) = (theta.cos(), theta.sin());
    let rotated = Mat::from_fn(4, 2, |i, j| {
        if j == 0 {
            c * phi[(i, 0)] + sn * phi[(i, 1)]
        } else {
            -sn * phi[(i, 0)] + c * phi[(i, 1)]
        }
    });
    let m2 = Orthogonality::from_matrices(rotated.as_ref(), phi).unwrap();
    let expected = [[c, sn], [sn, c]];
    for (i, row) in expected.iter().enumerate() {
        for (j, v) in row.iter().enumerate() {
            assert_relative_eq!(m2.matrix()[(i, j)], *v, epsilon = 1e-12);
        }
    }
    // The subspaces coincide although the shapes rotate.
    for &pc in m2.principal_cosines() {
        assert_relative_eq!(pc, 1.0, epsilon = 1e-12);
    }
    assert_eq!(m2.matched_above(0.9), 2);
}

#[test]
fn hungarian_pairing_undoes_a_swap() {
    let y = random_matrix(10, 30, 3);
    let s = ImpactShapes::from_matrix(y.as_ref(), &ShapeOptions::count(4)).unwrap();
    let order = [2usize, 0, 3, 1];
    let swapped = Mat::from_fn(10, 4, |i, j| s.shapes()[(i, order[j])]);
    let m2 = Orthogonality::from_matrices(swapped.as_ref(), s.shapes()).unwrap();
    for p in m2.pairs() {
        assert_eq!(order[p.analysis], p.test);
        assert_relative_eq!(p.value, 1.0, epsilon = 1e-12);
    }
}

#[test]
fn labels_align_and_mismatch_is_reported() {
    let y = random_matrix(3, 20, 5);
    let labels = |l: &[&str]| l.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let rows = |m: &Mat<f64>| {
        (0..3)
            .map(|i| (0..20).map(|j| m[(i, j)]).collect())
            .collect()
    };
    let h =
        Histories::from_channels(labels(&["1.x", "1.y", "1.z"]), rows(&y), 0.1, 0.0, "").unwrap();
    let perm = [2usize, 0, 1];
    let yp = Mat::from_fn(3, 20, |i, j| y[(perm[i], j)]);
    let hp =
        Histories::from_channels(labels(&["1.z", "1.x", "1.y"]), rows(&yp), 0.1, 0.0, "").unwrap();
    let a = ImpactShapes::from_histories(&h, &ShapeOptions::default()).unwrap();
    let b = ImpactShapes::from_histories(&hp, &ShapeOptions::default()).unwrap();
    let m2 = Orthogonality::between(&a, &b).unwrap();
    for p in m2.pairs() {
        assert_relative_eq!(p.value, 1.0, epsilon = 1e-10);
    }
    let hq =
        Histories::from_channels(labels(&["1.z", "1.x", "2.y"]), rows(&yp), 0.1, 0.0, "").unwrap();
    let c = ImpactShapes::from_histories(&hq, &ShapeOptions::default()).unwrap();
    assert!(matches!(
        Orthogonality::between(&a, &c),
        Err(ShapesError::LabelMismatch { .. })
    ));
}

fn labelled(y: &Mat<f64>, names: &[String], dt: f64) -> Histories {
    let rows = (0..y.nrows())
        .map(|i| (0..y.ncols()).map(|j| y[(i, j)]).collect())
        .collect();
    Histories::from_channels(names.to_vec(), rows, dt, 0.0, "in/s").unwrap()
}

#[test]
fn expansion_is_exact_in_the_span_and_reports_rank_deficiency() {
    // Model data: 12 channels, rank 3. Test data: other time functions, same shapes.
    let names: Vec<String> = (0..12).map(|i| format!("{}.z", i + 1)).collect();
    let basis = random_matrix(12, 3, 11);
    let model = &basis * random_matrix(3, 80, 12);
    let truth = &basis * random_matrix(3, 50, 13);
    let shapes =
        ImpactShapes::from_histories(&labelled(&model, &names, 1e-4), &ShapeOptions::count(3))
            .unwrap();
    let measured_idx = [0usize, 3, 5, 8, 10];
    let measured = labelled(&truth, &names, 1e-4)
        .select(
            &measured_idx
                .iter()
                .map(|&i| names[i].as_str())
                .collect::<Vec<_>>(),
        )
        .unwrap();
    let e = Expansion::compute(&shapes, &measured, None).unwrap();
    assert_eq!(e.histories().channels(), 7);
    assert!(e.condition() >= 1.0 && e.condition().is_finite());
    let full = labelled(&truth, &names, 1e-4);
    for (c, label) in e.histories().labels().iter().enumerate() {
        let expect = full.channel_by_label(label).unwrap();
        for (a, b) in e.histories().channel(c).iter().zip(expect) {
            assert!(
                (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
                "{label}: {a} vs {b}"
            );
        }
    }
    // Two measured channels cannot determine three shapes.
    let few = full.select(&["1.z", "2.z"]).unwrap();
    assert!(matches!(
        Expansion::compute(&shapes, &few, None),
        Err(ShapesError::RankDeficient { .. })
    ));
    // A measured channel that the model lacks.
    let foreign =
        Histories::from_channels(vec!["99.x".into()], vec![vec![0.0; 50]], 1e-4, 0.0, "").unwrap();
    assert!(matches!(
        Expansion::compute(&shapes, &foreign, None),
        Err(ShapesError::LabelMismatch { .. })
    ));
}

#[test]
fn expansion_detects_rank_deficient_measured_rows() {
    // Shapes that vanish together on channels 0..3 except along one direction.
    let names: Vec<String> = (0..6).map(|i| format!("{i}.y")).collect();
    let basis = Mat::from_fn(6, 2, |i, j| match (i < 3, j) {
        (true, 0) => 1.0,
        (true, _) => 0.0,
        (false, 0) => 0.3 * i as f64,
        (false, _) => 1.0 + i as f64,
    });
    let model = &basis * random_matrix(2, 30, 4);
    let shapes =
        ImpactShapes::from_histories(&labelled(&model, &names, 0.01), &ShapeOptions::count(2))
            .unwrap();
    let measured = labelled(&model, &names, 0.01)
        .select(&["0.y", "1.y", "2.y"])
        .unwrap();
    match Expansion::compute(&shapes, &measured, None) {
        Err(ShapesError::RankDeficient { rank, shapes, .. }) => {
            assert_eq!((rank, shapes), (1, 2));
        }
        other => panic!("expected rank deficiency, got {other:?}"),
    }
}

fn matrix_strategy() -> impl Strategy<Value = Mat<f64>> {
    (2usize..9, 2usize..15, any::<u64>()).prop_map(|(m, n, seed)| random_matrix(m, n, seed))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn decomposition_invariants(y in matrix_strategy()) {
        let s = ImpactShapes::from_matrix(y.as_ref(), &ShapeOptions::default()).unwrap();
        let k = s.len();
        let utu = s.shapes().transpose() * s.shapes();
        let vtv = s.time_functions().transpose() * s.time_functions();
        prop_assert!(max_abs_diff(utu.as_ref(), Mat::<f64>::identity(k, k).as_ref()) < 1e-12);
        prop_assert!(max_abs_diff(vtv.as_ref(), Mat::<f64>::identity(k, k).as_ref()) < 1e-12);
        prop_assert!(s.singular_values().windows(2).all(|w| w[0] >= w[1]));
        let r = s.reconstruct(k);
        prop_assert!(max_abs_diff(r.as_ref(), y.as_ref()) < 1e-12 * (1.0 + y.norm_l2()));
        let c: f64 = s.contributions().iter().sum();
        prop_assert!((c - 1.0).abs() < 1e-12);
    }

    #[test]
    fn m2_invariances(y in matrix_strategy(), flips in proptest::collection::vec(any::<bool>(), 15), seed in any::<u64>()) {
        let s = ImpactShapes::from_matrix(y.as_ref(), &ShapeOptions::default()).unwrap();
        let (m, k) = s.shapes().shape();
        let own = Orthogonality::from_matrices(s.shapes(), s.shapes()).unwrap();
        prop_assert!(max_abs_diff(own.matrix(), Mat::<f64>::identity(k, k).as_ref()) < 1e-12);
        let other = random_matrix(m, k, seed);
        let base = Orthogonality::from_matrices(s.shapes(), other.as_ref()).unwrap();
        let flipped = Mat::from_fn(m, k, |i, j| if flips[j] { -s.shapes()[(i, j)] } else { s.shapes()[(i, j)] });
        let f = Orthogonality::from_matrices(flipped.as_ref(), other.as_ref()).unwrap();
        prop_assert!(max_abs_diff(f.matrix(), base.matrix()) < 1e-14);
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let mut perm: Vec<usize> = (0..m).collect();
        for i in (1..m).rev() { perm.swap(i, rng.random_range(0..=i)); }
        let pa = Mat::from_fn(m, k, |i, j| s.shapes()[(perm[i], j)]);
        let pb = Mat::from_fn(m, k, |i, j| other[(perm[i], j)]);
        let p = Orthogonality::from_matrices(pa.as_ref(), pb.as_ref()).unwrap();
        prop_assert!(max_abs_diff(p.matrix(), base.matrix()) < 1e-12);
    }

    #[test]
    fn expansion_exact_for_data_in_span(seed in any::<u64>(), k in 1usize..4) {
        let basis = random_matrix(10, k, seed);
        let coords = random_matrix(k, 25, seed ^ 0xabc);
        let y = &basis * &coords;
        let phi = basis.subrows(0, 6);
        let kr = basis.subrows(6, 4);
        let (ye, _, cond, _) = impactcal_shapes::expand_matrix(phi, kr, y.subrows(0, 6)).unwrap();
        prop_assert!(cond >= 1.0);
        prop_assert!(max_abs_diff(ye.as_ref(), y.subrows(6, 4)) < 1e-9 * (1.0 + cond) * (1.0 + y.norm_l2()));
    }
}
