//! Criterion benchmark of the ISO/TS 18571 rating on 1,215 channel pairs of 801 samples
//! (target: under 1 s on 2 cores), and of the CFC filter on the same channels.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use impactcal::calibrate::metrics::Iso18571;
use impactcal::core::Cfc;

#[path = "common/metric_pairs.rs"]
mod metric_pairs;
use metric_pairs::{DT, metric_pairs};

fn bench(c: &mut Criterion) {
    let pairs = metric_pairs();
    let iso = Iso18571::new();
    let mut g = c.benchmark_group("metrics_1215x801");
    g.sample_size(10);
    g.bench_function("iso18571_all_pairs", |b| {
        b.iter(|| iso.rate_many(&pairs, DT).unwrap())
    });
    g.bench_function("cfc180_all_channels", |b| {
        b.iter(|| {
            pairs
                .iter()
                .map(|(r, _)| Cfc::Cfc180.filter(r, DT, "bench").unwrap())
                .collect::<Vec<_>>()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
