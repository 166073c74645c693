//! Benchmarks of quasi-random sampling and of Sobol' index estimation on vector outputs.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use faer::MatRef;
use impactcal::core::points::to_rows;
use impactcal::core::sampling::{Method, seeded_rng, symmetric_latin_hypercube, unit_sample};
use impactcal::core::test_functions;
use impactcal::core::{Parameter, ParameterSpace};
use impactcal::sobol::{SaltelliDesign, SobolOptions, analyze};
use std::hint::black_box;

fn sampling(c: &mut Criterion) {
    let mut g = c.benchmark_group("sampling");
    g.sample_size(10);
    for method in [
        Method::ScrambledSobol,
        Method::Sobol,
        Method::ScrambledHalton,
    ] {
        g.bench_function(format!("{method:?} 16384 x 12"), |b| {
            b.iter(|| unit_sample(black_box(method), 16_384, 12, 1).unwrap())
        });
    }
    g.bench_function("symmetric LHS 1000 x 20", |b| {
        b.iter(|| symmetric_latin_hypercube(1000, 20, &mut seeded_rng(1)).unwrap())
    });
    g.finish();
}

fn design_outputs(n: usize, d: usize, cols: usize, second: bool) -> (SaltelliDesign, Vec<f64>) {
    let space = ParameterSpace::new(
        (0..d)
            .map(|i| Parameter::new(format!("x{i}"), 0.0, 1.0, 0.5).unwrap())
            .collect(),
    )
    .unwrap();
    let design = SaltelliDesign::generate(&space, n, Method::ScrambledSobol, second, 1).unwrap();
    let a: Vec<f64> = (0..d)
        .map(|i| [0.0, 0.5, 3.0, 9.0][i.min(3)] + i as f64)
        .collect();
    let mut y = Vec::with_capacity(design.points.nrows() * cols);
    for x in to_rows(design.points.as_ref()) {
        let g = test_functions::g_function(&x, &a);
        y.extend((0..cols).map(|t| g * (1.0 + t as f64 / cols as f64) + x[0] * t as f64));
    }
    (design, y)
}

fn indices(c: &mut Criterion) {
    let mut g = c.benchmark_group("sobol_analyze");
    g.sample_size(10);
    let (design, y) = design_outputs(4096, 6, 256, false);
    let view = MatRef::from_row_major_slice(&y, design.points.nrows(), 256);
    for resamples in [0, 100] {
        let options = SobolOptions {
            bootstrap: resamples,
            ..SobolOptions::default()
        };
        g.bench_function(format!("N 4096, d 6, T 256, B {resamples}"), |b| {
            b.iter(|| analyze(&design.layout, view, &options).unwrap())
        });
    }
    let (design, y) = design_outputs(4096, 6, 64, true);
    let view = MatRef::from_row_major_slice(&y, design.points.nrows(), 64);
    g.bench_function("N 4096, d 6, T 64, second order, B 0", |b| {
        b.iter(|| analyze(&design.layout, view, &SobolOptions::default()).unwrap())
    });
    g.finish();
}

criterion_group!(benches, sampling, indices);
criterion_main!(benches);
