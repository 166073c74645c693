//! Segment contact kernels at 2k, 8k and 32k shells: the bucket sort (the candidate lists of
//! every checked node) and one force pass (penetration against the candidates, penalty,
//! the forces added in node order), on one thread and on two.
//!
//! The model: two square steel plates of 10 mm quads (2 mm thick), one 2.5 mm above the
//! other, flying at each other at 5 m/s each in one single-surface contact, run until the
//! gap has closed to about 1.96 mm, so that every node of the facing plates is in contact
//! (the contact reach is 2 mm; the penalty springs part the plates again within about 8 us);
//! the kernels are then timed on that state. Each size doubles the plates' side, so the work per shell is what
//! stays constant when the search is linear. Divide the time per iteration by the shell
//! count for the cost per shell and cycle.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use impactcal::shell::{
    Contact, ContactSurface, InitialVelocity, Material, MaterialLaw, PartSet, Section, ShellModel,
    Simulation, VelocityTarget,
};

/// Two `n x n` plates of 10 mm quads in a single-surface contact, 2.5 mm apart, closing at
/// 10 m/s; `2 n^2` shells.
fn plates(n: u64) -> ShellModel {
    let h = 0.01;
    let mut m = ShellModel::new("contact benchmark plates");
    let per = (n + 1) * (n + 1);
    for (part, z) in [(1u64, 0.0), (2, 0.0025)] {
        let base = (part - 1) * per;
        for j in 0..=n {
            for i in 0..=n {
                m.add_node(base + 1 + i + j * (n + 1), [h * i as f64, h * j as f64, z]);
            }
        }
        let ebase = (part - 1) * n * n;
        for j in 0..n {
            for i in 0..n {
                let c = base + 1 + i + j * (n + 1);
                m.add_shell(
                    ebase + 1 + i + j * n,
                    part,
                    [c, c + 1, c + n + 2, c + n + 1],
                );
            }
        }
        m.add_part(part, 1, 1);
        m.initial_velocities.push(InitialVelocity::translation(
            VelocityTarget::Part(part),
            [0.0, 0.0, if part == 1 { 5.0 } else { -5.0 }],
        ));
    }
    m.sections.push(Section::new(1, 0.002));
    m.materials.push(Material {
        id: 1,
        density: 7850.0,
        youngs: 210e9,
        poisson: 0.3,
        law: MaterialLaw::Elastic,
    });
    m.part_sets.push(PartSet {
        id: 1,
        parts: vec![1, 2],
    });
    m.contacts
        .push(Contact::single_surface(ContactSurface::PartSet(1)));
    m.control.end_time = 1.0;
    m
}

/// The plates run until every facing node is within reach: 4 us after the gap closed to the
/// reach (half the time the penalty springs take to part them).
fn in_contact(n: u64) -> Simulation {
    let m = plates(n);
    let mut sim = Simulation::new(&m).unwrap();
    while sim.time() < 5.4e-5 {
        sim.step().unwrap();
    }
    assert!(sim.contact_pass() > 0.0, "the plates are not in contact");
    sim
}

/// A timed kernel on a simulation caught in contact.
type Kernel = fn(&mut Simulation) -> f64;

fn kernels(c: &mut Criterion) {
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let kernels: [(&str, Kernel); 2] = [
            ("search", |s| s.contact_search() as f64),
            ("forces", Simulation::contact_pass),
        ];
        for (name, kernel) in kernels {
            let mut g = c.benchmark_group(format!("contact_{name}_{threads}_thread"));
            g.sample_size(20);
            for n in [32u64, 64, 128] {
                let mut sim = pool.install(|| in_contact(n));
                g.bench_with_input(BenchmarkId::from_parameter(2 * n * n), &n, |b, _| {
                    b.iter(|| pool.install(|| kernel(&mut sim)))
                });
            }
            g.finish();
        }
    }
}

criterion_group!(benches, kernels);
criterion_main!(benches);
