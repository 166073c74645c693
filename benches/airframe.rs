//! The parametric airframe: one explicit cycle in the middle of the crash (after 2 ms of
//! impact), coarse (about 2,000 shells) and fine (over 20,000 shells) meshes, 1 and 2
//! threads; divide the time per cycle by the shell count for microseconds per
//! element-cycle.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{Criterion, criterion_group, criterion_main};
use impactcal::shell::Simulation;
use impactcal::shell::airframe::{Airframe, AirframeOptions, AirframeValues, MeshDensity};

fn cycles(c: &mut Criterion) {
    for mesh in [MeshDensity::Coarse, MeshDensity::Fine] {
        let af = Airframe::new(AirframeOptions::new(mesh)).unwrap();
        let model = af.model(&AirframeValues::nominal()).unwrap();
        let mut g = c.benchmark_group(format!("airframe_cycle_{}_shells", af.shell_count()));
        g.sample_size(10);
        for threads in [1usize, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut sim = pool.install(|| {
                let mut sim = Simulation::new(&model).unwrap();
                while sim.time() < 0.004 {
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
}

criterion_group!(benches, cycles);
criterion_main!(benches);
