//! Criterion benchmarks of the impact-shape solvers: faer's full thin SVD and the randomized
//! truncated solver (top 20 shapes) on 1215x1000, 1215x3000 and 12150x3000 matrices with a
//! decaying spectrum, the sizes of a 405-node (1215-DOF) airframe and ten times that.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use impactcal::shapes::{ImpactShapes, ShapeOptions, SvdMethod, Truncation};
#[path = "common/svd_matrix.rs"]
mod svd_matrix;
use svd_matrix::benchmark_matrix;

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
