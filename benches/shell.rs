//! Shell solver on a 21,000-shell elastic-plastic plate (5 thickness points,
//! `benches/common/shell_plate.rs`): the element kernel alone (all quads evaluated for one
//! step with the blocked kernel, one thread) and whole explicit cycles on 1 and 2 threads.
//! Divide the time per iteration by the element count for microseconds per element-cycle.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use impactcal::shell::element::{ElementOutput, KernelOptions, PartProps, quad_batch};
use impactcal::shell::{Hourglass, Simulation};

#[path = "common/shell_plate.rs"]
mod shell_plate;

/// The element kernel alone: every quad of the plate, one step of the cycle's size, on one
/// thread (no gather, no time integration). The state carries over between iterations, so
/// after the warm-up the strain keeps growing and most points are on the yield surface.
fn kernel(c: &mut Criterion) {
    let m = shell_plate::plate();
    let n = m.shells.len();
    let props = PartProps::new(&m.sections[0], &m.materials[0], &Hourglass::default()).unwrap();
    let index = |id: u64| (id - 1) as u32;
    let elems: Vec<[u32; 4]> = m.shells.iter().map(|s| s.nodes.map(index)).collect();
    let x: Vec<[f64; 3]> = m.nodes.iter().map(|p| p.x).collect();
    let v: Vec<[f64; 3]> = m
        .initial_velocities
        .iter()
        .map(|iv| iv.translation)
        .collect();
    let w = vec![[0.0; 3]; x.len()];
    let stride = props.state_len();
    let mut state = vec![0.0; stride * n];
    let mut out = vec![ElementOutput::default(); n];
    let opts = KernelOptions {
        projection: true,
        isdo_diagonal: false,
        invariant: false,
        distortion_check: true,
    };
    let dt = Simulation::new(&m).unwrap().dt();
    for _ in 0..20 {
        quad_batch(
            &elems, &x, &v, &w, &props, &mut state, stride, &mut out, dt, opts,
        )
        .unwrap();
    }
    let mut g = c.benchmark_group(format!("shell_element_kernel_{n}_quads"));
    g.sample_size(20);
    g.bench_function("1_thread", |b| {
        b.iter(|| {
            quad_batch(
                &elems, &x, &v, &w, &props, &mut state, stride, &mut out, dt, opts,
            )
            .unwrap()
        })
    });
    g.finish();
}

/// Whole cycles (element loop, gather, walls and constraints, velocity update, energies).
fn cycles(c: &mut Criterion) {
    let m = shell_plate::plate();
    let n = m.shells.len();
    assert!(n >= 20_000);
    let mut g = c.benchmark_group(format!("shell_cycle_{n}_shells"));
    g.sample_size(10);
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut sim = pool.install(|| {
            let mut sim = Simulation::new(&m).unwrap();
            // Warm up into the plastic range.
            for _ in 0..20 {
                sim.step().unwrap();
            }
            sim
        });
        g.bench_function(format!("{threads}_threads"), |b| {
            b.iter(|| pool.install(|| sim.step().unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, kernel, cycles);
criterion_main!(benches);
