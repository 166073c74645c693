//! Stiffness-proportional damping, shell bulk viscosity, the damped penalty wall and
//! invariant node numbering, against closed forms and invariants.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

mod common;

use common::*;
use impactcal_shell::{
    BulkViscosity, InitialVelocity, PartStiffnessDamping, RigidWall, ShellModel, Simulation,
    VelocityTarget, WallMethod,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The simply supported plate of V5 (1 m, 10 mm), 6 x 6 quads, started in its first mode,
/// and its centre node.
fn plate_in_its_first_mode() -> (ShellModel, u64) {
    let n = 6;
    let mut m = simply_supported_plate_in_first_mode(1.0, 0.01, n);
    let centre = node_id(n, n / 2, n / 2);
    m.output.history_nodes = vec![centre];
    m.output.interval = 1e-5;
    (m, centre)
}

/// The centre deflection history of a run.
fn centre_deflection(m: &ShellModel, centre: u64) -> (Vec<f64>, impactcal_shell::RunResult) {
    let r = Simulation::new(m).unwrap().run().unwrap();
    let uz = r
        .displacement
        .as_ref()
        .unwrap()
        .channel_by_label(&format!("{centre}.z"))
        .unwrap()
        .to_vec();
    (uz, r)
}

/// Rayleigh damping `beta K` damps a mode of circular frequency `omega` at the fraction of
/// critical `zeta = beta omega / 2`: the centre deflection of the plate decays by the
/// logarithmic decrement `2 pi zeta / sqrt(1 - zeta^2)` per period; and the energy balance,
/// with the damping energy, still closes.
#[test]
fn stiffness_damping_decays_a_mode_at_beta_omega_over_two() {
    let (mut m, centre) = plate_in_its_first_mode();
    // First the undamped frequency of this mesh.
    m.control.end_time = 0.05;
    let (uz, _) = centre_deflection(&m, centre);
    let z = zero_crossings(&uz[5..], 1e-5);
    let omega = 2.0 * std::f64::consts::PI / (2.0 * (z[3] - z[0]) / 3.0);
    // 3 % of critical at that frequency.
    let zeta = 0.03;
    let beta = 2.0 * zeta / omega;
    m.stiffness_damping = vec![PartStiffnessDamping {
        part: 1,
        coef: -beta,
    }];
    m.control.end_time = 0.07;
    let (uz, r) = centre_deflection(&m, centre);
    // Successive maxima of |uz| (half periods).
    let mut peaks = Vec::new();
    for k in 1..uz.len() - 1 {
        if uz[k].abs() > uz[k - 1].abs() && uz[k].abs() >= uz[k + 1].abs() && uz[k].abs() > 1e-6 {
            peaks.push(uz[k].abs());
        }
    }
    assert!(peaks.len() >= 6, "{} peaks", peaks.len());
    let halves = (peaks.len() - 1) as f64;
    let delta = 2.0 * (peaks[0] / peaks[peaks.len() - 1]).ln() / halves;
    let measured =
        delta / (4.0 * std::f64::consts::PI * std::f64::consts::PI + delta * delta).sqrt();
    eprintln!("zeta measured {measured:.4} vs {zeta} (beta {beta:.3e}, omega {omega:.1})");
    assert!(rel(measured, zeta) < 0.08, "zeta {measured} vs {zeta}");
    // The energy balance closes with the damping energy booked.
    let e = r.summary.energies;
    assert!(e.damping > 0.5 * e.initial, "{e:?}");
    assert!(
        (r.summary.energy_ratio - 1.0).abs() < 2e-3,
        "{}",
        r.summary.energy_ratio
    );
    // The step shrinks by sqrt(1 + z^2) - z with z = beta / dt_e: for z >> 1, by 2 z.
    let dt_e = (1.0 / 6.0) / 2f64.sqrt() / (E / (RHO * (1.0 - NU * NU))).sqrt();
    let z = beta / dt_e;
    let expect = 0.9 * dt_e * ((1.0 + z * z).sqrt() - z);
    assert!(
        rel(r.summary.dt_first, expect) < 1e-9,
        "{} vs {expect}",
        r.summary.dt_first
    );
}

/// A free plate in rigid translation and spin keeps its kinetic energy: stiffness damping
/// and bulk viscosity act on deformation rates only.
#[test]
fn rigid_body_motion_is_not_damped() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let h = 0.01;
    let mut m = plate(6, 6, 0.06, 0.06, [0.0; 3]);
    with_section(&mut m, 0.001, aluminium(1));
    for p in m.nodes.iter_mut() {
        p.x[2] += rng.random_range(-0.05..0.05) * h;
    }
    let mut iv = InitialVelocity::translation(VelocityTarget::All, [3.0, -1.0, 2.0]);
    iv.omega = 40.0;
    iv.centre = [0.03, 0.03, 0.0];
    iv.axis = [0.3, 0.2, 1.0];
    m.initial_velocities.push(iv);
    m.stiffness_damping = vec![PartStiffnessDamping {
        part: 1,
        coef: 0.25,
    }];
    m.bulk_viscosity = Some(BulkViscosity::default());
    let mut sim = Simulation::new(&m).unwrap();
    let e0 = sim.energies().kinetic;
    for _ in 0..3000 {
        sim.step().unwrap();
    }
    let e = sim.energies();
    eprintln!("{e:?}");
    assert!(e.damping < 1e-6 * e0, "damping {} of {e0}", e.damping);
    assert!(((e.total() - e0) / e0).abs() < 1e-3);
}

/// A flat plate landing on a penalty wall: every node is the oscillator
/// `m x'' = max(0, -k x - c x')` while it penetrates, with `k = alpha m / dt_ref^2` and
/// `c = 2 zeta sqrt(k m)`. The rebound velocity converges to that of the oscillator
/// (integrated here with small steps) as the step shrinks, at second order: the contact
/// stiffness does not change with TSSFAC.
#[test]
fn damped_penalty_wall_rebounds_like_a_spring_dashpot() {
    let (alpha, zeta, v0) = (0.1, 0.2, 5.0);
    let base = {
        let mut m = plate(4, 4, 0.1, 0.1, [0.0, 0.0, 1e-3]);
        with_section(&mut m, 0.002, aluminium(1));
        m.initial_velocities.push(InitialVelocity::translation(
            VelocityTarget::All,
            [0.0, 0.0, -v0],
        ));
        m.walls.push(RigidWall {
            id: 0,
            shape: impactcal_shell::WallShape::Plane,
            nodes: None,
            point: [0.0; 3],
            head: [0.0, 0.0, 1.0],
            friction: 0.0,
            method: WallMethod::Penalty {
                alpha,
                damping: zeta,
            },
        });
        m.output.history_nodes = vec![13];
        m
    };
    // dt_ref: the undamped element step of the undeformed plate, TSSFAC 1.
    let mut probe = base.clone();
    probe.control.tssfac = 1.0;
    let dt_ref = Simulation::new(&probe).unwrap().dt();
    let w = alpha.sqrt() / dt_ref;
    // The oscillator, from contact to separation, by RK4 with 1e4 steps per contact.
    let (mut x, mut v) = (0.0f64, -v0);
    let h = 1e-4 * std::f64::consts::PI / w;
    let acc = |x: f64, v: f64| {
        if x < 0.0 {
            (-w * w * x - 2.0 * zeta * w * v).max(0.0)
        } else {
            0.0
        }
    };
    let mut steps = 0;
    while x <= 0.0 || v < 0.0 {
        let (k1x, k1v) = (v, acc(x, v));
        let (k2x, k2v) = (v + 0.5 * h * k1v, acc(x + 0.5 * h * k1x, v + 0.5 * h * k1v));
        let (k3x, k3v) = (v + 0.5 * h * k2v, acc(x + 0.5 * h * k2x, v + 0.5 * h * k2v));
        let (k4x, k4v) = (v + h * k3v, acc(x + h * k3x, v + h * k3v));
        x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        steps += 1;
        assert!(steps < 1_000_000);
    }
    let e_expected = v / v0;
    assert!(e_expected > 0.3 && e_expected < 0.8, "{e_expected}");
    let mut errors = Vec::new();
    for tssfac in [0.9, 0.45] {
        let mut m = base.clone();
        m.control.tssfac = tssfac;
        m.control.end_time = 1e-3 / v0 + 20.0 / w;
        let r = Simulation::new(&m).unwrap().run().unwrap();
        let vz = r
            .velocity
            .unwrap()
            .channel_by_label("13.z")
            .unwrap()
            .to_vec();
        let rebound = *vz.last().unwrap() / v0;
        eprintln!("TSSFAC {tssfac}: rebound {rebound:.4} vs {e_expected:.4}");
        errors.push(rel(rebound, e_expected));
        // Energy: what the wall took is the kinetic energy lost.
        let e = r.summary.energies;
        assert!((r.summary.energy_ratio - 1.0).abs() < 1e-3, "{e:?}");
    }
    assert!(errors[0] < 0.04 && errors[1] < 0.01, "{errors:?}");
    assert!(errors[1] < errors[0] / 3.0, "{errors:?}");
}

/// The same warped, distorted mesh numbered three ways (as given, each element starting at
/// another node, each element's nodes in reverse order with the mesh mirrored): with
/// invariant numbering the runs agree to round-off, without it they do not.
#[test]
fn invariant_numbering_makes_results_independent_of_node_order() {
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let h = 0.01;
    let mut m = plate(6, 6, 0.06, 0.06, [0.0, 0.0, 0.002]);
    with_section(&mut m, 0.001, aluminium(1));
    for p in m.nodes.iter_mut() {
        p.x[0] += rng.random_range(-0.2..0.2) * h;
        p.x[1] += rng.random_range(-0.2..0.2) * h;
        p.x[2] += rng.random_range(0.0..0.3) * h;
    }
    // A triangle too: split the last quad.
    let last = m.shells.pop().unwrap();
    let [a, b, c, d] = last.nodes;
    m.add_shell(last.id, 1, [a, b, c, c]);
    m.add_shell(last.id + 1, 1, [a, c, d, d]);
    m.initial_velocities.push(InitialVelocity::translation(
        VelocityTarget::All,
        [2.0, 1.0, -20.0],
    ));
    m.walls.push(RigidWall {
        id: 0,
        shape: impactcal_shell::WallShape::Plane,
        nodes: None,
        point: [0.0; 3],
        head: [0.0, 0.0, 1.0],
        friction: 0.3,
        method: WallMethod::Kinematic,
    });
    m.control.end_time = 4e-4;
    m.output.history_nodes = m.nodes.iter().map(|n| n.id).collect();
    m.output.interval = 2e-5;
    let shifted = {
        let mut s = m.clone();
        for e in s.shells.iter_mut() {
            let n = e.nodes;
            e.nodes = if e.is_triangle() {
                [n[1], n[2], n[0], n[0]]
            } else {
                [n[1], n[2], n[3], n[0]]
            };
        }
        s
    };
    // Mirror y -> -y and reverse every element (so that it stays non-inverted).
    let mirrored = {
        let mut s = m.clone();
        for p in s.nodes.iter_mut() {
            p.x[1] = -p.x[1];
        }
        for e in s.shells.iter_mut() {
            let n = e.nodes;
            e.nodes = if e.is_triangle() {
                [n[0], n[2], n[1], n[1]]
            } else {
                [n[0], n[3], n[2], n[1]]
            };
        }
        for iv in s.initial_velocities.iter_mut() {
            iv.translation[1] = -iv.translation[1];
        }
        s
    };
    let velocities = |model: &ShellModel, invariant: bool, mirror: bool| -> Vec<f64> {
        let mut model = model.clone();
        model.control.invariant_numbering = invariant;
        let r = Simulation::new(&model).unwrap().run().unwrap();
        let h = r.velocity.unwrap();
        (0..h.channels())
            .flat_map(|c| {
                let sign = if mirror && h.labels()[c].ends_with(".y") {
                    -1.0
                } else {
                    1.0
                };
                h.channel(c)
                    .iter()
                    .map(move |v| sign * v)
                    .collect::<Vec<_>>()
            })
            .collect()
    };
    let diff = |a: &[f64], b: &[f64]| {
        let scale = a.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        a.iter()
            .zip(b)
            .fold(0.0f64, |s, (x, y)| s.max((x - y).abs()))
            / scale
    };
    for invariant in [true, false] {
        let a = velocities(&m, invariant, false);
        let b = velocities(&shifted, invariant, false);
        let c = velocities(&mirrored, invariant, true);
        let (ab, ac) = (diff(&a, &b), diff(&a, &c));
        eprintln!("invariant {invariant}: renumbered {ab:.2e}, mirrored {ac:.2e}");
        if invariant {
            assert!(ab < 1e-9 && ac < 1e-9, "{ab} {ac}");
        } else {
            assert!(ab > 1e-6 && ac > 1e-6, "{ab} {ac}");
        }
    }
}

/// Damping, bulk viscosity, the damped penalty wall and invariant numbering keep the
/// results bit-identical for 1, 2 and 3 threads.
#[test]
fn new_options_are_bit_identical_for_any_thread_count() {
    let mut m = tube(16, 12, 0.03, 0.1);
    with_section(&mut m, 0.001, aluminium(1));
    m.initial_velocities.push(InitialVelocity::translation(
        VelocityTarget::All,
        [1.0, 0.0, -15.0],
    ));
    let mut tilted = m.clone();
    for p in tilted.nodes.iter_mut() {
        p.x[2] += 0.002 + 0.05 * p.x[0];
    }
    let mut m = tilted;
    m.walls.push(RigidWall {
        id: 0,
        shape: impactcal_shell::WallShape::Plane,
        nodes: None,
        point: [0.0; 3],
        head: [0.0, 0.0, 1.0],
        friction: 0.2,
        method: WallMethod::Penalty {
            alpha: 0.2,
            damping: 0.3,
        },
    });
    m.stiffness_damping = vec![PartStiffnessDamping { part: 1, coef: 0.1 }];
    m.bulk_viscosity = Some(BulkViscosity::default());
    m.control.invariant_numbering = true;
    m.control.end_time = 1e-3;
    m.output.history_nodes = vec![1, 50, 150];
    m.output.interval = 2e-5;
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| Simulation::new(&m).unwrap().run().unwrap())
    };
    let a = run(1);
    assert!(a.summary.energies.damping > 0.0);
    for threads in [2, 3] {
        let b = run(threads);
        assert_eq!(a.velocity, b.velocity);
        assert_eq!(a.energies, b.energies);
        assert_eq!(a.parts, b.parts);
    }
}

/// In an elastic vibration all the internal energy is recoverable: the stored elastic
/// energy computed from the stresses equals the internal energy accumulated from the work
/// increments.
#[test]
fn elastic_energy_is_the_internal_energy_of_an_elastic_plate() {
    let (m, _) = plate_in_its_first_mode();
    let mut sim = Simulation::new(&m).unwrap();
    let mut worst: f64 = 0.0;
    let mut peak: f64 = 0.0;
    for k in 0..600 {
        sim.step().unwrap();
        if k % 50 == 0 {
            let (ie, el) = (sim.energies().internal, sim.elastic_energy());
            peak = peak.max(ie);
            worst = worst.max((ie - el).abs());
        }
    }
    assert!(peak > 0.0);
    assert!(worst < 2e-3 * peak, "{worst} of {peak}");
}
