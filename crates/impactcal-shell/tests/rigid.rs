//! Rigid bodies, spot welds and prescribed motions against closed forms and invariants:
//! free flight (momentum, angular momentum, rigidity, energy), held bodies, prescribed
//! velocity, displacement and acceleration, and welded plates that move as one.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

mod common;

use common::{aluminium, plate, with_section};
use impactcal_shell::{
    Curve, InitialVelocity, Material, MaterialLaw, MotionKind, MotionTarget, NodeSet,
    PrescribedMotion, RigidConstraints, ShellModel, Simulation, SpotWeld, VelocityTarget,
    WeldNodes,
};

fn rigid_material(id: u64, constraints: RigidConstraints) -> Material {
    Material {
        id,
        density: 7850.0,
        youngs: 2.1e11,
        poisson: 0.3,
        law: MaterialLaw::Rigid { constraints },
    }
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// A rigid 4 x 3 plate thrown with a spin about an axis off its principal axes, under
/// gravity: the centre falls at g, the angular momentum about the centre is constant, the
/// nodes keep their distances, and the energy balance closes.
#[test]
fn a_free_rigid_body_keeps_its_momenta_shape_and_energy() {
    let mut m = plate(4, 3, 0.4, 0.3, [0.0, 0.0, 1.0]);
    with_section(
        &mut m,
        0.004,
        rigid_material(1, RigidConstraints::default()),
    );
    m.add_mass(1, 1, 3.0);
    let mut iv = InitialVelocity::translation(VelocityTarget::All, [1.0, 0.5, 2.0]);
    iv.omega = 12.0;
    iv.centre = [0.2, 0.15, 1.0];
    iv.axis = [0.3, 1.0, 0.6];
    m.initial_velocities.push(iv);
    m.set_gravity(9.81);
    m.control.end_time = 0.05;
    m.control.fixed_dt = Some(2e-5);
    let mut sim = Simulation::new(&m).unwrap();
    let x0: Vec<[f64; 3]> = sim.positions().to_vec();
    let masses = sim.masses().to_vec();
    let total: f64 = masses.iter().sum();
    let centre = |x: &[[f64; 3]]| -> [f64; 3] {
        let mut c = [0.0; 3];
        for (p, &mi) in x.iter().zip(&masses) {
            for d in 0..3 {
                c[d] += mi * p[d] / total;
            }
        }
        c
    };
    let c0 = centre(&x0);
    // The body's velocity: the momentum of the nodes' initial velocities over the mass.
    let mut v0 = [0.0; 3];
    for (v, &mi) in sim.velocities().iter().zip(&masses) {
        for d in 0..3 {
            v0[d] += mi * v[d] / total;
        }
    }
    let r = sim.run().unwrap();
    let x1 = sim.positions().to_vec();
    let c1 = centre(&x1);
    let t = sim.time();
    // Centre of mass: ballistic.
    let want = [
        c0[0] + v0[0] * t,
        c0[1] + v0[1] * t,
        c0[2] + v0[2] * t - 0.5 * 9.81 * t * t,
    ];
    for d in 0..3 {
        assert!(
            (c1[d] - want[d]).abs() < 1e-9,
            "axis {d}: {} vs {}",
            c1[d],
            want[d]
        );
    }
    // Rigidity: every distance between nodes kept.
    for i in 0..x0.len() {
        for j in (i + 1)..x0.len() {
            let (a, b) = (dist(x0[i], x0[j]), dist(x1[i], x1[j]));
            assert!((a - b).abs() < 1e-12, "{i}-{j}: {a} vs {b}");
        }
    }
    // The body turned (it is not a translation).
    assert!(dist(x1[0], x1[1]) > 0.0);
    let moved = (0..3)
        .map(|d| (x1[0][d] - x0[0][d]) - (c1[d] - c0[d]))
        .map(f64::abs)
        .sum::<f64>();
    assert!(moved > 1e-3);
    // Energy: kinetic changes by the work of gravity only.
    assert!(
        (r.summary.energy_ratio - 1.0).abs() < 1e-4,
        "{}",
        r.summary.energy_ratio
    );
}

/// A body held in every direction does not move; one held in z only keeps its height and
/// its x, y velocity.
#[test]
fn held_directions_hold() {
    let mut m = plate(2, 2, 0.2, 0.2, [0.0, 0.0, 1.0]);
    let all = RigidConstraints {
        translation: [true; 3],
        rotation: [true; 3],
    };
    with_section(&mut m, 0.004, rigid_material(1, all));
    m.initial_velocities.push(InitialVelocity::translation(
        VelocityTarget::All,
        [1.0, 0.0, -3.0],
    ));
    m.set_gravity(9.81);
    m.control.end_time = 0.01;
    // No deformable shell sets a step: without one the model is refused.
    let e = Simulation::new(&m).err().unwrap().to_string();
    assert!(e.contains("every part is rigid"), "{e}");
    m.control.fixed_dt = Some(1e-5);
    let mut sim = Simulation::new(&m).unwrap();
    let x0 = sim.positions().to_vec();
    sim.run().unwrap();
    assert_eq!(sim.positions(), &x0[..]);
    let z_only = RigidConstraints {
        translation: [false, false, true],
        rotation: [true; 3],
    };
    m.materials[0] = rigid_material(1, z_only);
    let mut sim = Simulation::new(&m).unwrap();
    sim.run().unwrap();
    let t = sim.time();
    for (a, b) in sim.positions().iter().zip(&x0) {
        assert!((a[2] - b[2]).abs() < 1e-12);
        assert!((a[0] - b[0] - t).abs() < 1e-9, "{} vs {t}", a[0] - b[0]);
    }
}

/// A strip whose left end is a rigid part driven at a prescribed velocity, the right part
/// elastic: the driven body follows the curve exactly, and the energy balance counts the
/// work of the drive.
#[test]
fn a_prescribed_rigid_body_follows_its_curve_and_its_work_is_booked() {
    let mut m = plate(8, 1, 0.4, 0.05, [0.0; 3]);
    with_section(&mut m, 0.002, aluminium(1));
    // Elements 1 and 2 (x < 0.1) rigid.
    m.parts.push(impactcal_shell::Part {
        id: 2,
        title: "grip".into(),
        section: 1,
        material: 2,
        hourglass: 0,
    });
    m.materials
        .push(rigid_material(2, RigidConstraints::default()));
    for s in m.shells.iter_mut().filter(|s| s.id <= 2) {
        s.part = 2;
    }
    // Velocity -x ramping to 2 m/s over 1 ms, then constant.
    m.curves
        .push(Curve::new(5, vec![(0.0, 0.0), (1e-3, 2.0), (1.0, 2.0)]));
    m.prescribed.push(PrescribedMotion {
        target: MotionTarget::Rigid(2),
        dof: 0,
        kind: MotionKind::Velocity,
        curve: 5,
        scale: -1.0,
        birth: 0.0,
        death: 1e28,
    });
    m.output.history_nodes = vec![1, 10, 9];
    m.output.interval = 1e-4;
    m.control.end_time = 3e-3;
    let mut sim = Simulation::new(&m).unwrap();
    let r = sim.run().unwrap();
    let v = r.velocity.as_ref().unwrap();
    let vx1 = v.channel_by_label("1.x").unwrap();
    for (k, &vx) in vx1.iter().enumerate() {
        let t = k as f64 * 1e-4;
        let want = -2.0 * (t / 1e-3).min(1.0);
        assert!((vx - want).abs() < 0.05, "t {t}: {vx} vs {want}");
    }
    // The far end has felt the pull.
    assert!(v.channel_by_label("9.x").unwrap().iter().any(|&x| x < -0.1));
    assert!(r.summary.energies.external_work > 0.0);
    assert!(
        (r.summary.energy_ratio - 1.0).abs() < 0.01,
        "{}",
        r.summary.energy_ratio
    );
}

/// Prescribed displacement, velocity and acceleration of nodes: the node's motion is the
/// curve's (displacement exact at the samples to the interpolation between cycles).
#[test]
fn prescribed_node_motions_follow_their_curves() {
    for kind in [
        MotionKind::Displacement,
        MotionKind::Velocity,
        MotionKind::Acceleration,
    ] {
        let mut m = plate(4, 1, 0.2, 0.05, [0.0; 3]);
        with_section(&mut m, 0.002, aluminium(1));
        m.node_sets.push(NodeSet {
            id: 3,
            nodes: vec![5, 10],
        });
        // Displacement A sin(w t); velocity and acceleration its derivatives.
        let (a, w) = (1e-3, 2000.0);
        let pts: Vec<(f64, f64)> = (0..=400)
            .map(|k| {
                let t = k as f64 * 1e-5;
                let v = match kind {
                    MotionKind::Displacement => a * (w * t).sin(),
                    MotionKind::Velocity => a * w * (w * t).cos(),
                    MotionKind::Acceleration => -a * w * w * (w * t).sin(),
                };
                (t, v)
            })
            .collect();
        m.curves.push(Curve::new(9, pts));
        if kind == MotionKind::Acceleration {
            // Start at the velocity of the motion, so it is A sin(w t) from rest position.
            for n in [5, 10] {
                m.initial_velocities.push(InitialVelocity::translation(
                    VelocityTarget::Node(n),
                    [0.0, 0.0, a * w],
                ));
            }
        }
        m.prescribed.push(PrescribedMotion {
            target: MotionTarget::NodeSet(3),
            dof: 2,
            kind,
            curve: 9,
            scale: 1.0,
            birth: 0.0,
            death: 1e28,
        });
        m.output.history_nodes = vec![5];
        m.output.interval = 1e-4;
        m.control.end_time = 3e-3;
        let r = Simulation::new(&m).unwrap().run().unwrap();
        let d = r.displacement.as_ref().unwrap();
        let z = d.channel_by_label("5.z").unwrap();
        let tol = match kind {
            MotionKind::Displacement => 1e-3 * a,
            _ => 2e-2 * a,
        };
        for (k, &u) in z.iter().enumerate() {
            let t = k as f64 * 1e-4;
            let want = a * (w * t).sin();
            assert!((u - want).abs() < tol, "{kind:?} t {t}: {u} vs {want}");
        }
        assert!(
            (r.summary.energy_ratio - 1.0).abs() < 0.02,
            "{kind:?}: {}",
            r.summary.energy_ratio
        );
    }
}

/// Two strips overlapping at their ends, joined by two spot welds: pulling one drags the
/// other; each welded pair keeps its distance.
#[test]
fn welded_strips_move_as_one_at_the_welds() {
    let mut m = ShellModel::new("lap joint");
    let a = plate(4, 1, 0.2, 0.04, [0.0, 0.0, 0.0]);
    let b = plate(4, 1, 0.2, 0.04, [0.15, 0.0, 0.002]);
    for n in &a.nodes {
        m.add_node(n.id, n.x);
    }
    for n in &b.nodes {
        m.add_node(100 + n.id, n.x);
    }
    for s in &a.shells {
        m.add_shell(s.id, 1, s.nodes);
    }
    for s in &b.shells {
        m.add_shell(100 + s.id, 1, s.nodes.map(|n| 100 + n));
    }
    m.add_part(1, 1, 1);
    with_section(&mut m, 0.002, aluminium(1));
    // Nodes of strip a at x = 0.2 (5, 10) over strip b at x = 0.2 (102, 107).
    m.spot_welds.push(SpotWeld {
        id: 1,
        nodes: WeldNodes::Pair([5, 102]),
    });
    m.node_sets.push(NodeSet {
        id: 8,
        nodes: vec![10, 107],
    });
    m.spot_welds.push(SpotWeld {
        id: 2,
        nodes: WeldNodes::Set(8),
    });
    m.node_sets.push(NodeSet {
        id: 9,
        nodes: vec![1, 6],
    });
    m.curves
        .push(Curve::new(1, vec![(0.0, 0.0), (5e-4, 1.0), (1.0, 1.0)]));
    m.prescribed.push(PrescribedMotion {
        target: MotionTarget::NodeSet(9),
        dof: 0,
        kind: MotionKind::Velocity,
        curve: 1,
        scale: -1.0,
        birth: 0.0,
        death: 1e28,
    });
    m.output.history_nodes = vec![105, 110];
    m.output.interval = 1e-4;
    m.control.end_time = 2e-3;
    let mut sim = Simulation::new(&m).unwrap();
    let ids = sim.node_ids().to_vec();
    let at = |id: u64| ids.iter().position(|&n| n == id).unwrap();
    let x0 = sim.positions().to_vec();
    let r = sim.run().unwrap();
    let x1 = sim.positions();
    for (p, q) in [(5, 102), (10, 107)] {
        let (d0, d1) = (dist(x0[at(p)], x0[at(q)]), dist(x1[at(p)], x1[at(q)]));
        assert!((d0 - d1).abs() < 1e-12, "{p}-{q}: {d0} vs {d1}");
    }
    // The far end of the pulled-on strip moves the way of the pull.
    let vx = r
        .velocity
        .as_ref()
        .unwrap()
        .channel_by_label("105.x")
        .unwrap()
        .to_vec();
    assert!(vx.iter().any(|&v| v < -0.05), "{vx:?}");
    assert!(
        (r.summary.energy_ratio - 1.0).abs() < 0.02,
        "{}",
        r.summary.energy_ratio
    );
    // Without the welds, the second strip stays put.
    m.spot_welds.clear();
    let r = Simulation::new(&m).unwrap().run().unwrap();
    let vx = r
        .velocity
        .as_ref()
        .unwrap()
        .channel_by_label("105.x")
        .unwrap()
        .to_vec();
    assert!(vx.iter().all(|&v| v == 0.0));
}

/// Constraints and drives on the nodes of a rigid body are refused with the node named.
#[test]
fn node_constraints_on_rigid_bodies_are_refused() {
    let mut m = plate(2, 1, 0.2, 0.1, [0.0; 3]);
    with_section(
        &mut m,
        0.004,
        rigid_material(1, RigidConstraints::default()),
    );
    m.spcs.push(impactcal_shell::Spc {
        target: impactcal_shell::NodeTarget::Node(2),
        dofs: [true, false, false, false, false, false],
    });
    let e = Simulation::new(&m).err().unwrap().to_string();
    assert!(e.contains("node 2 moves with a rigid body"), "{e}");
    m.spcs.clear();
    m.curves.push(Curve::new(1, vec![(0.0, 1.0), (1.0, 1.0)]));
    m.prescribed.push(PrescribedMotion {
        target: MotionTarget::Node(3),
        dof: 0,
        kind: MotionKind::Velocity,
        curve: 1,
        scale: 1.0,
        birth: 0.0,
        death: 1e28,
    });
    let e = Simulation::new(&m).err().unwrap().to_string();
    assert!(e.contains("node 3 moves with a rigid body"), "{e}");
}
