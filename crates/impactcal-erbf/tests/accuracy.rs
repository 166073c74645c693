//! ERBF beats the Gaussian-only RBF of the same radius on average (the full record is
//! produced by `cargo run --release --example erbf_accuracy`).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use impactcal_core::sampling::latin_hypercube;
use impactcal_core::test_functions::{DIXON_PRICE10, HARTMANN3};
use impactcal_core::{Parameter, ParameterSpace};
use impactcal_erbf::{Accuracy, Erbf, ErbfOptions, RadialFunction, RbfInterpolant, RbfOptions};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[test]
fn erbf_beats_gaussian_only_on_average() {
    let mut erbf_raae = 0.0;
    let mut gauss_raae = 0.0;
    for (f, n) in [(HARTMANN3, 30), (DIXON_PRICE10, 50)] {
        let m = f.dim;
        let space = ParameterSpace::new(
            (0..m)
                .map(|j| Parameter::new(format!("x{j}"), 0.0, 1.0, 0.5).unwrap())
                .collect(),
        )
        .unwrap();
        for seed in 0..3 {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let x = latin_hypercube(n, m, &mut rng).unwrap();
            let q = Mat::from_fn(300, m, |_, _| rng.random::<f64>());
            let eval = |p: &Mat<f64>| {
                Mat::from_fn(p.nrows(), 1, |i, _| {
                    f.eval_unit(&p.row(i).iter().copied().collect::<Vec<_>>())
                })
            };
            let (fx, fq) = (eval(&x), eval(&q));
            let e = Erbf::fit(&space, x.as_ref(), fx.as_ref(), ErbfOptions::default()).unwrap();
            let g = RbfInterpolant::fit(
                x.as_ref(),
                fx.as_ref(),
                RbfOptions::new(RadialFunction::Gaussian { width: 0.15 }),
            )
            .unwrap();
            erbf_raae +=
                Accuracy::new(e.predict_batch(q.as_ref()).unwrap().as_ref(), fq.as_ref()).raae;
            gauss_raae +=
                Accuracy::new(g.predict_batch(q.as_ref()).unwrap().as_ref(), fq.as_ref()).raae;
        }
    }
    assert!(
        erbf_raae < 0.8 * gauss_raae,
        "ERBF {erbf_raae} vs Gaussian {gauss_raae}"
    );
}
