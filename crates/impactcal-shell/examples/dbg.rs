#![allow(missing_docs, clippy::unwrap_used)]
use impactcal_shell::*;
#[path = "../tests/common/mod.rs"]
mod common;
use common::*;
fn main() {
    let case: u32 = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(0);
    let (l, w, t) = (0.5, 0.01, 0.001);
    let mut m = plate(50, 1, l, w, [0.0; 3]);
    with_section(&mut m, t, aluminium(1));
    if case == 3 {
        m.initial_velocities.push(InitialVelocity::translation(
            VelocityTarget::All,
            [-1.0, 0.0, 0.0],
        ));
        m.walls.push(RigidWall {
            nodes: None,
            point: [0.0; 3],
            head: [1.0, 0.0, 0.0],
            friction: 0.0,
            method: WallMethod::Kinematic,
        });
    }
    for n in m.nodes.clone() {
        if case == 3 {
            break;
        }
        let v = match case {
            0 => [n.x[0], 0.0, 0.0],
            1 => [0.0, 0.0, n.x[0] * n.x[0]],
            _ => [0.0, n.x[0], 0.0],
        };
        m.initial_velocities
            .push(InitialVelocity::translation(VelocityTarget::Node(n.id), v));
    }
    m.control.end_time = 2e-4;
    m.output.interval = 1e-5;
    if case == 4 {
        let (a, t) = (1.0, 0.01);
        let n = 10;
        m = plate(n, n, a, a, [0.0; 3]);
        with_section(&mut m, t, aluminium(1));
        let edge: Vec<u64> = m
            .nodes
            .iter()
            .filter(|p| p.x[0] < 1e-9 || p.x[1] < 1e-9 || p.x[0] > a - 1e-9 || p.x[1] > a - 1e-9)
            .map(|p| p.id)
            .collect();
        m.node_sets.push(NodeSet { id: 1, nodes: edge });
        m.spcs.push(Spc {
            target: NodeTarget::NodeSet(1),
            dofs: [false, false, true, false, false, false],
        });
        let pi = std::f64::consts::PI;
        for p in m.nodes.clone() {
            let s = (pi * p.x[0] / a).sin() * (pi * p.x[1] / a).sin();
            m.initial_velocities.push(InitialVelocity::translation(
                VelocityTarget::Node(p.id),
                [0.0, 0.0, 0.1 * s],
            ));
        }
    }
    let mut sim = Simulation::new(&m).unwrap();
    for k in 0..(if case == 4 { 4000 } else { 200 }) {
        sim.step().unwrap();
        let e = sim.energies();
        if k % (if case == 4 { 200 } else { 4 }) == 0 {
            println!(
                "{k} t={:.3e} ke={:.4e} ie={:.4e} hg={:.4e} c={:.4e} tot={:.5e} ratio={:.5} wf={:?}",
                sim.time(),
                e.kinetic,
                e.internal,
                e.hourglass,
                e.contact,
                e.total(),
                e.ratio(),
                sim.wall_force()
            );
        }
    }
}
