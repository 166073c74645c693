//! One run of a driven lumped system over 5,000 samples at 1 MHz (the length of one drop
//! tower record): a board on its mount (one mass), the same with a second mode hung from it
//! (two masses), and the pair rattling in a two-sided gap contact (two masses, contact
//! sub-steps). Each run includes assembling the system and the step's matrix exponential.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::f64::consts::PI;

use criterion::{Criterion, criterion_group, criterion_main};
use impactcal_models::lumped::{Dynamics, GapLink, GapSides, Node, SpringLink};

fn link(ends: [Node; 2], m: f64, f: f64, zeta: f64) -> SpringLink {
    let k = m * (2.0 * PI * f).powi(2);
    SpringLink {
        ends,
        k,
        beta: 0.0,
        c: 2.0 * zeta * (k * m).sqrt(),
    }
}

fn systems() -> Vec<(&'static str, Dynamics)> {
    let one = Dynamics {
        masses: vec![0.05],
        springs: vec![link([Node::Base, Node::Mass(0)], 0.05, 6000.0, 0.05)],
        dashpots: vec![],
        gaps: vec![],
    };
    let mut two = one.clone();
    two.masses.push(0.01);
    two.springs
        .push(link([Node::Mass(0), Node::Mass(1)], 0.01, 15000.0, 0.05));
    let mut rattle = two.clone();
    rattle.gaps.push(GapLink {
        ends: [Node::Mass(0), Node::Mass(1)],
        gap: 1e-6,
        k: 100.0 * rattle.springs[1].k,
        sides: GapSides::Both,
    });
    vec![
        ("one mass", one),
        ("two masses", two),
        ("two masses rattling", rattle),
    ]
}

fn bench(c: &mut Criterion) {
    let dt = 1e-6;
    // A 60 kg_n (5.9e5 m/s^2) half-sine of 100 us, then the free response.
    let input: Vec<f64> = (0..5000)
        .map(|k| {
            let t = k as f64 * dt;
            if t < 1e-4 {
                5.9e5 * (PI * t / 1e-4).sin()
            } else {
                0.0
            }
        })
        .collect();
    let mut group = c.benchmark_group("lumped run, 5000 samples");
    for (name, sys) in systems() {
        let run = sys.run(&input, dt, 1e-3).unwrap();
        eprintln!("{name}: {} sub-steps", run.substeps);
        group.bench_function(name, |b| b.iter(|| sys.run(&input, dt, 1e-3).unwrap()));
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
