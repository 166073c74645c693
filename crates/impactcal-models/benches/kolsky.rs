//! One run of the Kolsky bar model on the Los Alamos copper record (the record resampled to
//! 0.4 us, a window of 392 samples): plain, with dispersion, with inertia.
//!
//! `cargo bench -p impactcal-models --bench kolsky`

#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use criterion::{Criterion, criterion_group, criterion_main};
use impactcal_core::Model;
use impactcal_core::enrich::rebuild;
use impactcal_core::testdata::LanlBarRecord;
use impactcal_models::kolsky::{DispersionCurve, KolskyModel, LanlOptions, from_lanl};

fn copper() -> KolskyModel {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/kolsky/20061201_1148HE_CuOFE_273K.raw"
    );
    let record = LanlBarRecord::read(path).unwrap();
    KolskyModel::new(&from_lanl(&record, &LanlOptions::default()).unwrap().test).unwrap()
}

fn runs(c: &mut Criterion) {
    let model = copper();
    let point = vec![60.0, 450.0, 0.45, 40.0, 4865.9, 0.0, 0.0];
    let names = |extra: &str| {
        let mut n: Vec<String> = model
            .space()
            .names()
            .iter()
            .map(|s| s.to_string())
            .collect();
        n.push(extra.to_string());
        n
    };
    c.bench_function("kolsky copper run (plain)", |b| {
        b.iter(|| model.simulate(&point).unwrap())
    });
    let dispersed = rebuild(&model, &names("dispersion"), &[]).unwrap();
    let mut p = point.clone();
    p.push(1.0);
    dispersed.simulate(&p).unwrap(); // solve the curves once
    c.bench_function("kolsky copper run (dispersion)", |b| {
        b.iter(|| dispersed.simulate(&p).unwrap())
    });
    let inertia = rebuild(&model, &names("inertia"), &[]).unwrap();
    c.bench_function("kolsky copper run (inertia)", |b| {
        b.iter(|| inertia.simulate(&p).unwrap())
    });
    // What the first dispersed run of a model adds: the copper bar's curve up to the
    // Nyquist frequency of 0.4 us (k a up to 15.3).
    c.bench_function("kolsky dispersion curve solve (once per model)", |b| {
        b.iter(|| DispersionCurve::solve(0.330302, 15.3, 0.02).unwrap())
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = runs
}
criterion_main!(benches);
