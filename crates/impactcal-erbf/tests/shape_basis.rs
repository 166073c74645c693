//! Surrogates of whole histories in the impact-shape basis: exact interpolation of the
//! training runs within the truncation error, the automatic shape count, held-out accuracy
//! against the full-history surrogate, serialisation and bad counts.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use impactcal_core::sampling::latin_hypercube;
use impactcal_core::{CoreError, Parameter, ParameterSpace};
use impactcal_erbf::{
    ErbfError, FitOptions, LooMethod, OutputBasis, ResponseSurrogate, SurrogateKind,
    SurrogateModel, Tuning,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const M: usize = 4;
const T: usize = 400;

fn space() -> ParameterSpace {
    ParameterSpace::new(
        (0..M)
            .map(|j| Parameter::new(format!("p{j}"), -1.0, 2.0 + j as f64, 0.0).unwrap())
            .collect(),
    )
    .unwrap()
}

/// An impact-like history family: damped sums of phase-shifted sines, exactly of rank
/// `2 M` around its mean (every term splits into a sine and a cosine in time).
fn histories(x: &Mat<f64>, space: &ParameterSpace) -> Mat<f64> {
    let u = space.to_unit_matrix(x.as_ref()).unwrap();
    Mat::from_fn(x.nrows(), T, |i, t| {
        let s: f64 = (0..M)
            .map(|j| (2.0 * u[(i, j)] + 0.02 * (t * (j + 1)) as f64).sin())
            .sum();
        s * (-0.004 * t as f64).exp()
    })
}

fn design(n: usize, seed: u64, space: &ParameterSpace) -> Mat<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let u = latin_hypercube(n, M, &mut rng).unwrap();
    space.from_unit_matrix(u.as_ref()).unwrap()
}

fn names() -> Vec<String> {
    (0..T).map(|t| format!("y{t}")).collect()
}

fn shapes(kind: SurrogateKind, count: Option<usize>) -> FitOptions {
    FitOptions {
        kind,
        basis: OutputBasis::Shapes { count },
        tuning: Tuning::Off,
        ..FitOptions::default()
    }
}

fn rel_frobenius(a: &Mat<f64>, b: &Mat<f64>) -> f64 {
    (a - b).norm_l2() / b.norm_l2()
}

/// Every kind reproduces its training runs to the truncation error of the shapes it keeps
/// (and to rounding when it keeps them all).
#[test]
fn training_runs_are_interpolated_within_the_truncation_error() {
    let space = space();
    let x = design(40, 1, &space);
    // Add a small full-rank part so that truncation really leaves something out.
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let mut f = histories(&x, &space);
    for v in f.col_iter_mut().flat_map(|c| c.iter_mut()) {
        *v += 1e-3 * (rng.random::<f64>() - 0.5);
    }
    for kind in [
        SurrogateKind::Erbf,
        SurrogateKind::Cubic,
        SurrogateKind::ThinPlate,
        SurrogateKind::Gaussian,
        SurrogateKind::Multiquadric,
    ] {
        for count in [3, 8, 20] {
            let s = ResponseSurrogate::fit_with(
                &space,
                x.as_ref(),
                f.as_ref(),
                names(),
                &shapes(kind, Some(count)),
            )
            .unwrap();
            let SurrogateModel::Components(c) = s.model() else {
                panic!("a shape-basis fit gives a component model");
            };
            let basis = c.basis().unwrap();
            assert_eq!(basis.len(), count);
            let centred = Mat::from_fn(40, T, |i, t| f[(i, t)] - basis.mean()[t]);
            let back = s.predict_batch(x.as_ref()).unwrap();
            let err = (&back - &f).norm_l2() / centred.norm_l2();
            let trunc = basis.truncation_error(count);
            assert!(
                (err - trunc).abs() <= 1e-8 + 1e-6 * trunc,
                "{kind:?}, {count} shapes: training error {err:e}, truncation {trunc:e}"
            );
        }
    }
}

/// Without noise the automatic count keeps the `2 M` shapes of the family and the
/// surrogate is as accurate on held-out runs as the same kind on the full histories.
#[test]
fn automatic_count_finds_the_rank_and_matches_the_full_surrogate() {
    let space = space();
    let x = design(60, 2, &space);
    let f = histories(&x, &space);
    let q = design(50, 3, &space);
    let truth = histories(&q, &space);
    for kind in [SurrogateKind::Cubic, SurrogateKind::Erbf] {
        let s = ResponseSurrogate::fit_with(
            &space,
            x.as_ref(),
            f.as_ref(),
            names(),
            &shapes(kind, None),
        )
        .unwrap();
        let SurrogateModel::Components(c) = s.model() else {
            panic!("component model expected");
        };
        let k = c.basis().unwrap().len();
        let sv = c.basis().unwrap().singular_values();
        assert!(
            c.basis().unwrap().truncation_error(k) < 1e-8,
            "{kind:?}: {k} shapes {sv:?} {}",
            c.basis().unwrap().truncation_error(k)
        );
        assert!((2 * M..=2 * M + 2).contains(&k), "{kind:?}: {k} shapes");
        let full = ResponseSurrogate::fit(&space, kind, x.as_ref(), f.as_ref(), names()).unwrap();
        let e_shapes = rel_frobenius(&s.predict_batch(q.as_ref()).unwrap(), &truth);
        let e_full = rel_frobenius(&full.predict_batch(q.as_ref()).unwrap(), &truth);
        assert!(
            e_shapes <= 1.01 * e_full + 1e-9,
            "{kind:?}: held-out {e_shapes:e} in the shape basis, {e_full:e} on full histories"
        );
        // The leave-one-out errors of the coordinates carry over to the histories.
        let loo = s.loo_errors(LooMethod::Closed).unwrap();
        assert_eq!((loo.nrows(), loo.ncols()), (60, T));
        assert!(loo.norm_l2() > 0.0);
    }
}

/// With the basis fixed and every shape kept, the cubic RBF's leave-one-out errors of the
/// histories are exactly those of the full-history cubic RBF (the map to coordinates is
/// linear and orthogonal, and Rippa's formula is exact).
#[test]
fn loo_with_every_shape_equals_the_full_surrogates() {
    let space = space();
    let x = design(30, 4, &space);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let f = Mat::from_fn(30, 50, |_, _| rng.random::<f64>());
    let names: Vec<String> = (0..50).map(|t| format!("y{t}")).collect();
    let rank = 29; // deviations of 30 random runs from their mean
    let s = ResponseSurrogate::fit_with(
        &space,
        x.as_ref(),
        f.as_ref(),
        names.clone(),
        &shapes(SurrogateKind::Cubic, Some(rank)),
    )
    .unwrap();
    let full = ResponseSurrogate::fit(&space, SurrogateKind::Cubic, x.as_ref(), f.as_ref(), names)
        .unwrap();
    let a = s.loo_errors(LooMethod::Closed).unwrap();
    let b = full.loo_errors(LooMethod::Closed).unwrap();
    assert!(
        (&a - &b).norm_max() < 1e-9 * b.norm_max(),
        "{:e}",
        (&a - &b).norm_max()
    );
}

#[test]
fn saved_model_predicts_the_same() {
    let space = space();
    let x = design(25, 6, &space);
    let f = histories(&x, &space);
    let q = design(7, 7, &space);
    let s = ResponseSurrogate::fit_with(
        &space,
        x.as_ref(),
        f.as_ref(),
        names(),
        &shapes(SurrogateKind::Multiquadric, None),
    )
    .unwrap();
    let json = serde_json::to_string(&s).unwrap();
    let back: ResponseSurrogate = serde_json::from_str(&json).unwrap();
    let (a, b) = (
        s.predict_batch(q.as_ref()).unwrap(),
        back.predict_batch(q.as_ref()).unwrap(),
    );
    assert!((&a - &b).norm_max() <= 1e-12 * b.norm_max());
    assert_eq!(back.kind(), SurrogateKind::Multiquadric);
    // A tampered shape count is refused with a message, not a panic.
    let bad = json.replacen("\"shapes\":", "\"shapes\":1000,\"old\":", 1);
    let err = serde_json::from_str::<ResponseSurrogate>(&bad).unwrap_err();
    assert!(err.to_string().contains("shapes"), "{err}");
}

#[test]
fn shape_counts_out_of_range_are_invalid_options() {
    let space = space();
    let x = design(12, 8, &space);
    let f = histories(&x, &space);
    for k in [0, 500] {
        let e = ResponseSurrogate::fit_with(
            &space,
            x.as_ref(),
            f.as_ref(),
            names(),
            &shapes(SurrogateKind::Cubic, Some(k)),
        )
        .unwrap_err();
        assert!(
            matches!(e, ErbfError::Core(CoreError::InvalidOption { .. })),
            "{k}: {e}"
        );
    }
}

/// Outputs given to the fit (moved in) and outputs lent to it (copied) make the same model,
/// bit for bit, with and without tuning; an owned matrix's storage becomes the model's.
#[test]
fn owned_and_borrowed_outputs_fit_the_same_model() {
    let space = space();
    let x = design(20, 11, &space);
    let f = histories(&x, &space);
    let q = design(9, 12, &space);
    let cases = [
        (
            SurrogateKind::Cubic,
            OutputBasis::Shapes { count: None },
            Tuning::Off,
        ),
        (
            SurrogateKind::Cubic,
            OutputBasis::Shapes { count: None },
            Tuning::Parameters,
        ),
        // The full-output kernels keep the outputs too.
        (SurrogateKind::Cubic, OutputBasis::Full, Tuning::Off),
        (SurrogateKind::Erbf, OutputBasis::Full, Tuning::Off),
    ];
    for (kind, basis, tuning) in cases {
        let options = FitOptions {
            kind,
            basis,
            tuning,
            ..FitOptions::default()
        };
        let borrowed =
            ResponseSurrogate::fit_with(&space, x.as_ref(), f.as_ref(), names(), &options).unwrap();
        let by_ref =
            ResponseSurrogate::fit_with(&space, x.as_ref(), &f, names(), &options).unwrap();
        let given = f.clone();
        let storage = given.as_ptr();
        let owned =
            ResponseSurrogate::fit_with(&space, x.as_ref(), given, names(), &options).unwrap();
        assert_eq!(owned.values().as_ptr(), storage, "moved, not copied");
        assert_ne!(borrowed.values().as_ptr(), f.as_ptr(), "copied");
        let p = borrowed.predict_batch(q.as_ref()).unwrap();
        for other in [&by_ref, &owned] {
            assert_eq!(other.values(), f.as_ref());
            let o = other.predict_batch(q.as_ref()).unwrap();
            assert!(
                (0..p.nrows())
                    .all(|i| (0..p.ncols()).all(|j| p[(i, j)].to_bits() == o[(i, j)].to_bits())),
                "{kind:?} {basis:?} {tuning:?}: the predictions differ"
            );
        }
    }
}
