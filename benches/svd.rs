//! Criterion benchmarks of the impact-shape solvers: faer's full thin SVD and the randomized
//! truncated solver (top 20 shapes) on 1215x1000, 1215x3000 and 12150x3000 matrices with a
//! decaying spectrum, the sizes of a 405-node (1215-DOF) airframe and ten times that.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use faer::Mat;
use impactcal::shapes::{ImpactShapes, ShapeOptions, SvdMethod, Truncation};
use rand::{Rng, SeedableRng};

fn benchmark_matrix(m: usize, n: usize, seed: u64) -> Mat<f64> {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let a = Mat::from_fn(m, 60, |_, j| {
        0.85f64.powi(j as i32) * rng.random_range(-1.0..1.0)
    });
    let b = Mat::from_fn(60, n, |_, _| rng.random_range(-1.0..1.0));
    let mut y = &a * &b;
    y.col_iter_mut().for_each(|c| {
        c.iter_mut()
            .for_each(|x| *x += 1e-4 * rng.random_range(-1.0..1.0))
    });
    y
}

fn svd(c: &mut Criterion) {
    let mut g = c.benchmark_group("impact_shapes");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    let full = ShapeOptions {
        truncation: Truncation::All,
        method: SvdMethod::Full,
    };
    for (m, n) in [(1215, 1000), (1215, 3000), (12150, 3000)] {
        let y = benchmark_matrix(m, n, 42);
        let id = format!("{m}x{n}");
        g.bench_with_input(BenchmarkId::new("thin_svd", &id), &y, |b, y| {
            b.iter(|| ImpactShapes::from_matrix(y.as_ref(), &full).unwrap())
        });
        g.bench_with_input(BenchmarkId::new("top20_randomized", &id), &y, |b, y| {
            b.iter(|| ImpactShapes::from_matrix(y.as_ref(), &ShapeOptions::count(20)).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, svd);
criterion_main!(benches);
