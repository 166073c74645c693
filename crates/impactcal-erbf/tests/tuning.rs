//! Shape parameters and smoothing chosen by leave-one-out: the smoothing grows with the
//! noise, noiseless data stay interpolated, a Gaussian of unsuitable width is repaired, and
//! the linear trend's leave-one-out errors are those of refits.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use impactcal_core::sampling::latin_hypercube;
use impactcal_core::{Parameter, ParameterSpace};
use impactcal_erbf::{
    ComponentOptions, FitOptions, LooMethod, OutputBasis, ResponseSurrogate, SurrogateKind,
    SurrogateModel, Tuning, linear_trend_loo,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

fn space(m: usize) -> ParameterSpace {
    ParameterSpace::new(
        (0..m)
            .map(|j| Parameter::new(format!("p{j}"), 0.0, 1.0, 0.5).unwrap())
            .collect(),
    )
    .unwrap()
}

/// A smooth function of `m` inputs.
fn smooth(x: &Mat<f64>, i: usize) -> f64 {
    let m = x.ncols();
    (0..m)
        .map(|j| (1.0 + j as f64 * 0.3) * (2.0 * x[(i, j)]).sin())
        .sum::<f64>()
        + x[(i, 0)] * x[(i, m - 1)]
}

fn data(n: usize, m: usize, noise: f64, seed: u64) -> (Mat<f64>, Mat<f64>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let x = latin_hypercube(n, m, &mut rng).unwrap();
    let normal = Normal::new(0.0, 1.0).unwrap();
    let f = Mat::from_fn(n, 1, |i, _| smooth(&x, i) + noise * normal.sample(&mut rng));
    (x, f)
}

fn auto(kind: SurrogateKind, tuning: Tuning) -> FitOptions {
    FitOptions {
        kind,
        basis: OutputBasis::Full,
        tuning,
        ..FitOptions::default()
    }
}

fn chosen(s: &ResponseSurrogate) -> ComponentOptions {
    let SurrogateModel::Components(c) = s.model() else {
        panic!("a tuned fit gives a component model");
    };
    c.column_options()[0]
}

fn smoothing(o: ComponentOptions) -> f64 {
    match o {
        ComponentOptions::Rbf(r) => r.smoothing,
        ComponentOptions::Erbf(e) => e.smoothing,
    }
}

fn held_out_rel(s: &ResponseSurrogate, m: usize) -> f64 {
    let (q, _) = data(300, m, 0.0, 99);
    let p = s.predict_batch(q.as_ref()).unwrap();
    let truth: Vec<f64> = (0..300).map(|i| smooth(&q, i)).collect();
    let mean = truth.iter().sum::<f64>() / 300.0;
    let sse: f64 = (0..300).map(|i| (p[(i, 0)] - truth[i]).powi(2)).sum();
    let sst: f64 = truth.iter().map(|t| (t - mean).powi(2)).sum();
    (sse / sst).sqrt()
}

/// More noise, more smoothing; and the smoothed fit predicts the noiseless function better
/// than the interpolant of the noisy samples.
#[test]
fn chosen_smoothing_grows_with_the_noise() {
    let m = 3;
    let sp = space(m);
    let names = vec!["y".to_string()];
    for kind in [
        SurrogateKind::Cubic,
        SurrogateKind::Gaussian,
        SurrogateKind::Multiquadric,
        SurrogateKind::Erbf,
    ] {
        let mut last = -1.0;
        for noise in [0.0, 0.05, 0.5] {
            let (x, f) = data(80, m, noise, 3);
            let s = ResponseSurrogate::fit_with(
                &sp,
                x.as_ref(),
                f.as_ref(),
                names.clone(),
                &auto(kind, Tuning::Parameters),
            )
            .unwrap();
            let lambda = smoothing(chosen(&s));
            assert!(
                lambda > last,
                "{kind:?}: noise {noise}: smoothing {lambda:e} after {last:e}"
            );
            last = lambda;
            if noise == 0.0 && kind == SurrogateKind::Erbf {
                // ERBF's widest radius makes its kernel matrix so ill-conditioned that the
                // smallest smoothing of the grid (1e-9 of its mean diagonal) can lower the
                // leave-one-out error as a numerical regularisation; no more than that is
                // chosen, and the fit stays close to interpolating.
                assert!(
                    lambda <= 1e-9,
                    "{kind:?}: smoothing {lambda:e} without noise"
                );
                assert!(
                    s.training_residual() < 1e-3,
                    "{kind:?}: {:e} with {:?}",
                    s.training_residual(),
                    chosen(&s)
                );
            } else if noise == 0.0 {
                // Noiseless data stay interpolated.
                assert!(
                    s.training_residual() < 1e-5,
                    "{kind:?}: {:e} with {:?}",
                    s.training_residual(),
                    chosen(&s)
                );
            } else {
                let plain =
                    ResponseSurrogate::fit(&sp, kind, x.as_ref(), f.as_ref(), names.clone())
                        .unwrap();
                assert!(
                    held_out_rel(&s, m) < held_out_rel(&plain, m),
                    "{kind:?}, noise {noise}: tuned {} vs plain {}",
                    held_out_rel(&s, m),
                    held_out_rel(&plain, m)
                );
            }
        }
    }
}

/// In 9 dimensions the default Gaussian width (0.15 in the unit cube) is far below the
/// sample spacing and the interpolant collapses to spikes; the tuned width repairs it, and
/// the leave-one-out error says which is which.
#[test]
fn tuned_gaussian_width_repairs_the_default_in_nine_dimensions() {
    let m = 9;
    let sp = space(m);
    let (x, f) = data(120, m, 0.0, 4);
    let names = vec!["y".to_string()];
    let plain = ResponseSurrogate::fit(
        &sp,
        SurrogateKind::Gaussian,
        x.as_ref(),
        f.as_ref(),
        names.clone(),
    )
    .unwrap();
    let tuned = ResponseSurrogate::fit_with(
        &sp,
        x.as_ref(),
        f.as_ref(),
        names,
        &auto(SurrogateKind::Gaussian, Tuning::Parameters),
    )
    .unwrap();
    let (e_plain, e_tuned) = (held_out_rel(&plain, m), held_out_rel(&tuned, m));
    assert!(e_plain > 0.5, "{e_plain}");
    assert!(e_tuned < 0.2 * e_plain, "{e_tuned} vs {e_plain}");
    let loo_rel = |s: &ResponseSurrogate| {
        let e = s.loo_errors(LooMethod::Closed).unwrap();
        e.norm_l2()
    };
    let trend = linear_trend_loo(x.as_ref(), f.as_ref()).unwrap().norm_l2();
    assert!(
        loo_rel(&plain) > trend,
        "the default's LOO must flag it as worse than a line"
    );
    assert!(loo_rel(&tuned) < trend);
}

/// Competing kinds: on noisy data the choice is at least as good, on held-out points, as
/// the linear trend within a small margin, and as every untuned kind.
#[test]
fn kind_choice_is_no_worse_than_a_linear_trend_on_noisy_data() {
    let m = 5;
    let sp = space(m);
    let (x, f) = data(100, m, 0.3, 5);
    let names = vec!["y".to_string()];
    let s = ResponseSurrogate::fit_with(
        &sp,
        x.as_ref(),
        f.as_ref(),
        names.clone(),
        &auto(SurrogateKind::Cubic, Tuning::Kinds),
    )
    .unwrap();
    let e_auto = held_out_rel(&s, m);
    for kind in [
        SurrogateKind::Cubic,
        SurrogateKind::ThinPlate,
        SurrogateKind::Gaussian,
        SurrogateKind::Multiquadric,
    ] {
        let plain =
            ResponseSurrogate::fit(&sp, kind, x.as_ref(), f.as_ref(), names.clone()).unwrap();
        assert!(e_auto <= held_out_rel(&plain, m), "{kind:?}");
    }
}
