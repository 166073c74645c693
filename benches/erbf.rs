//! Criterion benchmarks of the ERBF and cubic RBF surrogates at N = 150 samples, n_p = 10
//! parameters and T = 10^4 outputs (a long time history): fit, one-point predict and a
//! 1000-point batch predict; and the cubic RBF in the impact-shape basis (shape count chosen
//! automatically): fit, and 1000 predictions of whole histories.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use impactcal::erbf::{
    Erbf, ErbfOptions, FitOptions, OutputBasis, RbfInterpolant, RbfOptions, ResponseSurrogate,
    SurrogateKind, Tuning,
};

#[path = "common/surrogate_data.rs"]
mod surrogate_data;
use surrogate_data::surrogate_data as data;

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
    let names: Vec<String> = (0..f.ncols()).map(|t| format!("y{t}")).collect();
    let shapes = FitOptions {
        kind: SurrogateKind::Cubic,
        basis: OutputBasis::Shapes { count: None },
        tuning: Tuning::Off,
        ..FitOptions::default()
    };
    let fit_shapes =
        || ResponseSurrogate::fit_with(&space, x.as_ref(), f.as_ref(), names.clone(), &shapes);
    g.bench_function("shapes_cubic_fit", |b| b.iter(|| fit_shapes().unwrap()));
    let shaped = fit_shapes().unwrap();
    g.bench_function("shapes_cubic_predict_1000", |b| {
        b.iter(|| shaped.predict_batch(q.as_ref()).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
