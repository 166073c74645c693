//! Criterion benchmarks of effective-independence sensor placement (impactcal-sensors).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use faer::Mat;
use impactcal::sensors::{CandidateShapes, Grouping, PlacementOptions, place};
use rand::{Rng, SeedableRng, rngs::StdRng};
use rand_distr::StandardNormal;

fn candidates(s: usize, k: usize, seed: u64) -> CandidateShapes {
    let mut rng = StdRng::seed_from_u64(seed);
    let phi = Mat::from_fn(s, k, |_, _| rng.sample::<f64, _>(StandardNormal));
    let labels = (0..s)
        .map(|i| format!("{}.{}", i / 3 + 1, ["x", "y", "z"][i % 3]))
        .collect();
    CandidateShapes::new(labels, phi.as_ref()).unwrap()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("efi");
    g.sample_size(10);
    let small = candidates(1215, 20, 1);
    g.bench_function("1215x20_to_41", |b| {
        b.iter(|| place(&small, &PlacementOptions::new(41)).unwrap())
    });
    g.bench_function("1215x20_to_34_nodes", |b| {
        b.iter(|| place(&small, &PlacementOptions::new(34).grouping(Grouping::Node)).unwrap())
    });
    let large = candidates(12150, 30, 2);
    g.bench_function("12150x30_to_100", |b| {
        b.iter(|| place(&large, &PlacementOptions::new(100)).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
