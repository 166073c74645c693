//! Accuracy of ERBF against Gaussian-only and cubic RBF surrogates on standard test
//! functions (the record in docs/validation.md).
//!
//! `cargo run --release --example erbf_accuracy [seeds]`

#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use impactcal::core::sampling::latin_hypercube;
use impactcal::core::test_functions::surrogate_accuracy_set;
use impactcal::core::{Parameter, ParameterSpace};
use impactcal::erbf::{Accuracy, Erbf, ErbfOptions, RadialFunction, RbfInterpolant, RbfOptions};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn main() {
    let seeds: u64 = std::env::args().nth(1).map_or(10, |s| s.parse().unwrap());
    let n_test = 1000;
    println!("| function | m | N | model | RAAE | RMAE | R^2 |");
    println!("|---|---|---|---|---|---|---|");
    let mut wins = 0;
    let mut overall = [0.0; 4];
    let mut cases = 0;
    for f in surrogate_accuracy_set() {
        let m = f.dim;
        let space = ParameterSpace::new(
            (0..m)
                .map(|j| Parameter::new(format!("x{j}"), 0.0, 1.0, 0.5).unwrap())
                .collect(),
        )
        .unwrap();
        for per_dim in [5, 10] {
            let n = per_dim * m;
            let mut sums = [[0.0; 3]; 4];
            for seed in 0..seeds {
                let mut rng = ChaCha8Rng::seed_from_u64(1000 * seed + n as u64);
                let x = latin_hypercube(n, m, &mut rng).unwrap();
                let q = Mat::from_fn(n_test, m, |_, _| rng.random::<f64>());
                let eval = |p: &Mat<f64>| {
                    Mat::from_fn(p.nrows(), 1, |i, _| {
                        f.eval_unit(&p.row(i).iter().copied().collect::<Vec<_>>())
                    })
                };
                let (fx, fq) = (eval(&x), eval(&q));
                let erbf = Erbf::fit(&space, x.as_ref(), fx.as_ref(), ErbfOptions::default())
                    .unwrap()
                    .predict_batch(q.as_ref())
                    .unwrap();
                let gauss = RbfInterpolant::fit(
                    x.as_ref(),
                    fx.as_ref(),
                    RbfOptions::new(RadialFunction::Gaussian { width: 0.15 }),
                )
                .unwrap()
                .predict_batch(q.as_ref())
                .unwrap();
                let cubic = RbfInterpolant::fit(x.as_ref(), fx.as_ref(), RbfOptions::cubic())
                    .unwrap()
                    .predict_batch(q.as_ref())
                    .unwrap();
                let centred = ErbfOptions {
                    center_outputs: true,
                    ..ErbfOptions::default()
                };
                let erbf_c = Erbf::fit(&space, x.as_ref(), fx.as_ref(), centred)
                    .unwrap()
                    .predict_batch(q.as_ref())
                    .unwrap();
                for (k, p) in [erbf, gauss, cubic, erbf_c].iter().enumerate() {
                    let a = Accuracy::new(p.as_ref(), fq.as_ref());
                    sums[k][0] += a.raae;
                    sums[k][1] += a.rmae;
                    sums[k][2] += a.r2;
                }
            }
            let names = [
                "ERBF",
                "Gaussian RBF (r_c 0.15)",
                "cubic RBF + linear",
                "ERBF, centred outputs",
            ];
            for (k, name) in names.iter().enumerate() {
                let s = seeds as f64;
                println!(
                    "| {} | {m} | {n} | {name} | {:.3} | {:.3} | {:.3} |",
                    f.title,
                    sums[k][0] / s,
                    sums[k][1] / s,
                    sums[k][2] / s
                );
            }
            for k in 0..4 {
                overall[k] += sums[k][0] / seeds as f64;
            }
            cases += 1;
            if sums[0][0] < sums[1][0] {
                wins += 1;
            }
        }
    }
    println!(
        "\nERBF has a lower mean RAAE than Gaussian-only in {wins} of {cases} cases \
         ({seeds} seeds, {n_test} test points, Latin hypercube designs)."
    );
    println!(
        "Mean RAAE over all cases: ERBF {:.3}, Gaussian-only {:.3}, cubic {:.3}, \
         ERBF centred {:.3}.",
        overall[0] / cases as f64,
        overall[1] / cases as f64,
        overall[2] / cases as f64,
        overall[3] / cases as f64
    );
}
