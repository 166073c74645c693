//! Criterion benchmarks of the ERBF and cubic RBF surrogates at N = 150 samples, n_p = 10
//! parameters and T = 10^4 outputs (a long time history): fit, one-point predict and a
//! 1000-point batch predict.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use faer::Mat;
use impactcal::core::{Parameter, ParameterSpace};
use impactcal::erbf::testfns::latin_hypercube;
use impactcal::erbf::{Erbf, ErbfOptions, RbfInterpolant, RbfOptions};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const N: usize = 150;
const M: usize = 10;
const T: usize = 10_000;

fn data() -> (ParameterSpace, Mat<f64>, Mat<f64>, Mat<f64>) {
    let space = ParameterSpace::new(
        (0..M)
            .map(|j| Parameter::new(format!("p{j}"), 0.0, 1.0, 0.5).unwrap())
            .collect(),
    )
    .unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let x = latin_hypercube(N, M, &mut rng);
    let f = Mat::from_fn(N, T, |i, t| {
        let s: f64 = (0..M)
            .map(|j| (3.0 * x[(i, j)] + 1e-3 * (t * (j + 1)) as f64).sin())
            .sum();
        s * (-2e-4 * t as f64).exp()
    });
    let q = Mat::from_fn(1000, M, |_, _| rng.random::<f64>());
    (space, x, f, q)
}

fn bench(c: &mut Criterion) {
    let (space, x, f, q) = data();
    let mut g = c.benchmark_group("surrogate_n150_np10_t1e4");
    g.sample_size(10);
    g.bench_function("erbf_fit", |b| {
        b.iter(|| Erbf::fit(&space, x.as_ref(), f.as_ref(), ErbfOptions::default()).unwrap())
    });
    let erbf = Erbf::fit(&space, x.as_ref(), f.as_ref(), ErbfOptions::default()).unwrap();
    let one: Vec<f64> = q.row(0).iter().copied().collect();
    g.bench_function("erbf_predict_1", |b| b.iter(|| erbf.predict(&one).unwrap()));
    g.bench_function("erbf_predict_1000", |b| {
        b.iter(|| erbf.predict_batch(q.as_ref()).unwrap())
    });
    g.bench_function("cubic_fit", |b| {
        b.iter(|| RbfInterpolant::fit(x.as_ref(), f.as_ref(), RbfOptions::cubic()).unwrap())
    });
    let cubic = RbfInterpolant::fit(x.as_ref(), f.as_ref(), RbfOptions::cubic()).unwrap();
    g.bench_function("cubic_predict_1", |b| {
        b.iter(|| cubic.predict(&one).unwrap())
    });
    g.bench_function("cubic_predict_1000", |b| {
        b.iter(|| cubic.predict_batch(q.as_ref()).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
