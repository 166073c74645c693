//! Shell solver: whole explicit cycles on a 21,000-shell elastic-plastic plate (5 thickness
//! points), on 1 and 2 threads; divide the time per cycle by the element count for
//! microseconds per element-cycle.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use impactcal::shell::{
    InitialVelocity, Material, MaterialLaw, Section, ShellModel, Simulation, VelocityTarget,
};

const NX: u64 = 150;
const NY: u64 = 140;

fn model() -> ShellModel {
    let mut m = ShellModel::new("bench plate");
    let h = 0.01;
    for j in 0..=NY {
        for i in 0..=NX {
            let z = 0.002 * ((i as f64 * 0.3).sin() * (j as f64 * 0.2).cos());
            m.add_node(1 + i + j * (NX + 1), [h * i as f64, h * j as f64, z]);
        }
    }
    for j in 0..NY {
        for i in 0..NX {
            let n = 1 + i + j * (NX + 1);
            m.add_shell(1 + i + j * NX, 1, [n, n + 1, n + NX + 2, n + NX + 1]);
        }
    }
    m.add_part(1, 1, 1);
    m.sections.push(Section::new(1, 0.0015));
    m.materials.push(Material {
        id: 1,
        density: 2780.0,
        youngs: 73.1e9,
        poisson: 0.33,
        law: MaterialLaw::Plastic {
            yield_stress: 345e6,
            tangent_modulus: 1e9,
            rate: None,
        },
    });
    // A velocity field that bends and stretches the plate, so points yield.
    for p in m.nodes.clone() {
        let v = [
            20.0 * (p.x[1] * 7.0).sin(),
            0.0,
            -30.0 * (p.x[0] * 5.0).sin(),
        ];
        m.initial_velocities
            .push(InitialVelocity::translation(VelocityTarget::Node(p.id), v));
    }
    m.control.end_time = 1.0;
    m
}

fn cycles(c: &mut Criterion) {
    let m = model();
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

criterion_group!(benches, cycles);
criterion_main!(benches);
