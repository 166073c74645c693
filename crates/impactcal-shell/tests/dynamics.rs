//! Verification of the solver against analytic results (shell-solver.md section 5).

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::float_cmp,
    clippy::needless_range_loop
)]

mod common;

use common::*;
use impactcal_shell::{
    InitialVelocity, NodeSet, NodeTarget, RigidWall, Simulation, Spc, VelocityTarget, WallMethod,
};

fn floor(normal: [f64; 3], mu: f64) -> RigidWall {
    RigidWall {
        id: 0,
        shape: impactcal_shell::WallShape::Plane,
        nodes: None,
        point: [0.0; 3],
        head: normal,
        friction: mu,
        method: WallMethod::Kinematic,
    }
}

/// V2 + V9: a free strip hits the wall end-on. The compressive wave reaches the free end at
/// L/c0 (the free end's velocity reverses then), the wall force plateau is rho c0 A v0 and
/// the contact lasts 2 L / c0; the strip leaves with -v0.
#[test]
fn strip_end_impact_wave_speed_force_plateau_and_duration() {
    let (l, w, t, v0) = (0.5, 0.01, 0.001, 1.0);
    let mut m = plate(50, 1, l, w, [0.0; 3]);
    with_section(&mut m, t, aluminium(1));
    m.initial_velocities.push(InitialVelocity::translation(
        VelocityTarget::All,
        [-v0, 0.0, 0.0],
    ));
    m.walls.push(floor([1.0, 0.0, 0.0], 0.0));
    m.control.end_time = 3e-4;
    m.output.interval = 5e-7;
    let free_end = node_id(50, 50, 0);
    m.output.history_nodes = vec![free_end];
    let mut sim = Simulation::new(&m).unwrap();
    let r = sim.run().unwrap();
    let c0 = (E / RHO).sqrt();
    let dt = r.energies.dt();

    // V2: the free end keeps -v0 until the wave arrives, then reverses.
    let vx = r
        .velocity
        .as_ref()
        .unwrap()
        .channel_by_label(&format!("{free_end}.x"))
        .unwrap();
    let arrival = zero_crossings(vx, dt)[0];
    assert!(
        rel(arrival, l / c0) < 0.03,
        "arrival {arrival:.4e} vs L/c0 {:.4e}",
        l / c0
    );

    // V9: plateau and duration of the wall force.
    let f = r.energies.channel_by_label("wall_force").unwrap();
    let plateau = RHO * c0 * w * t * v0;
    let on: Vec<usize> = (0..f.len()).filter(|&k| f[k] > 0.05 * plateau).collect();
    let duration = (on[on.len() - 1] - on[0]) as f64 * dt;
    assert!(
        rel(duration, 2.0 * l / c0) < 0.03,
        "duration {duration:.4e} vs {:.4e}",
        2.0 * l / c0
    );
    let mid: Vec<f64> = on[on.len() / 4..3 * on.len() / 4]
        .iter()
        .map(|&k| f[k])
        .collect();
    let mean = mid.iter().sum::<f64>() / mid.len() as f64;
    assert!(
        rel(mean, plateau) < 0.05,
        "plateau {mean:.2} N vs {plateau:.2} N"
    );
    // Exact reversal: the strip leaves with +v0 (momentum over mass).
    let p: f64 = sim
        .velocities()
        .iter()
        .zip(sim.masses())
        .map(|(v, m)| m * v[0])
        .sum();
    let mass: f64 = sim.masses().iter().sum();
    assert!(
        rel(p / mass, v0) < 0.03,
        "rebound velocity {} vs {v0}",
        p / mass
    );
}

/// V8: a 100 kg ballast on an elastic tube dropped on the wall at 0.2 m/s behaves as a
/// spring-mass system: peak force v0 sqrt(k M), contact time pi sqrt(M / k), k = E A / L.
#[test]
fn ballast_drop_on_an_elastic_tube_is_a_spring_mass_system() {
    let (r_t, t, l, mass, v0) = (0.05, 0.0015, 0.3, 100.0, 0.2);
    let (nt, nz) = (16, 10);
    let mut m = tube(nt, nz, r_t, l);
    with_section(&mut m, t, aluminium(1));
    for i in 0..nt {
        m.add_mass(1000 + i, 1 + i + nz * nt, mass / nt as f64);
    }
    m.initial_velocities.push(InitialVelocity::translation(
        VelocityTarget::All,
        [0.0, 0.0, -v0],
    ));
    m.walls.push(floor([0.0, 0.0, 1.0], 0.0));
    m.control.end_time = 4.5e-3;
    m.output.interval = 1e-5;
    m.output.history_nodes = vec![1 + nz * nt];
    let r = Simulation::new(&m).unwrap().run().unwrap();
    let k = E * 2.0 * std::f64::consts::PI * r_t * t / l;
    let f_peak = v0 * (k * mass).sqrt();
    let duration = std::f64::consts::PI * (mass / k).sqrt();
    assert!(rel(f_peak, 21.0e3) < 0.005 && rel(duration, 3.0e-3) < 0.005);
    let f = r.energies.channel_by_label("wall_force").unwrap();
    let dt = r.energies.dt();
    let peak = f.iter().cloned().fold(0.0, f64::max);
    assert!(
        rel(peak, f_peak) < 0.05,
        "peak {peak:.0} N vs {f_peak:.0} N"
    );
    let on: Vec<usize> = (0..f.len()).filter(|&k| f[k] > 0.02 * f_peak).collect();
    let dur = (on[on.len() - 1] - on[0]) as f64 * dt;
    assert!(
        rel(dur, duration) < 0.05,
        "duration {dur:.4e} vs {duration:.4e}"
    );
    // Rebound velocity of the ballast close to +v0.
    let vz = r
        .velocity
        .as_ref()
        .unwrap()
        .channel_by_label(&format!("{}.z", 1 + nz * nt))
        .unwrap();
    let v_end = *vz.last().unwrap();
    assert!(rel(v_end, v0) < 0.05, "rebound {v_end} vs {v0}");
}

/// V12: a plate with a point mass slides on the wall under gravity and stops after
/// v0^2 / (2 mu g).
#[test]
fn coulomb_sliding_stops_at_v0_squared_over_two_mu_g() {
    let (v0, mu, g) = (2.0, 0.3, 9.81);
    let mut m = plate(2, 2, 0.1, 0.1, [0.0; 3]);
    let mut soft = aluminium(1);
    soft.youngs = 1e6;
    soft.density = 1000.0;
    with_section(&mut m, 0.01, soft);
    m.add_mass(100, node_id(2, 1, 1), 1.0);
    m.set_gravity(g);
    m.initial_velocities.push(InitialVelocity::translation(
        VelocityTarget::All,
        [v0, 0.0, 0.0],
    ));
    m.walls.push(floor([0.0, 0.0, 1.0], mu));
    m.control.end_time = 0.9;
    m.output.interval = 1e-3;
    let centre = node_id(2, 1, 1);
    m.output.history_nodes = vec![centre];
    let r = Simulation::new(&m).unwrap().run().unwrap();
    let ux = r
        .displacement
        .as_ref()
        .unwrap()
        .channel_by_label(&format!("{centre}.x"))
        .unwrap();
    let expected = v0 * v0 / (2.0 * mu * g);
    let stop = *ux.last().unwrap();
    assert!(
        rel(stop, expected) < 0.02,
        "stopping distance {stop} vs {expected}"
    );
    let vx = r
        .velocity
        .as_ref()
        .unwrap()
        .channel_by_label(&format!("{centre}.x"))
        .unwrap();
    assert!(vx.last().unwrap().abs() < 1e-9);
    // All the kinetic energy went into friction.
    let e = r.summary.energies;
    assert!(
        rel(e.friction, e.initial) < 0.02,
        "friction {} vs {}",
        e.friction,
        e.initial
    );
}

/// V4: cantilever strip 200 x 20 x 2 mm, 20 x 2 quads, first bending frequency 41.1 Hz
/// (beam; 43.6 Hz with the plate-strip factor).
#[test]
fn cantilever_strip_first_frequency() {
    let (l, b, t) = (0.2, 0.02, 0.002);
    let (nx, ny) = (20, 2);
    let mut m = plate(nx, ny, l, b, [0.0; 3]);
    with_section(&mut m, t, aluminium(1));
    m.node_sets.push(NodeSet {
        id: 1,
        nodes: (0..=ny).map(|j| node_id(nx, 0, j)).collect(),
    });
    m.spcs.push(Spc {
        target: NodeTarget::NodeSet(1),
        dofs: [true; 6],
    });
    for n in m.nodes.clone() {
        let s = n.x[0] / l;
        let mut iv =
            InitialVelocity::translation(VelocityTarget::Node(n.id), [0.0, 0.0, 0.01 * s * s]);
        iv.rotation = [0.0, -0.02 * s / l, 0.0];
        m.initial_velocities.push(iv);
    }
    m.control.end_time = 0.06;
    m.output.interval = 2e-5;
    let tip = node_id(nx, nx, 1);
    m.output.history_nodes = vec![tip];
    let r = Simulation::new(&m).unwrap().run().unwrap();
    let uz = r
        .displacement
        .as_ref()
        .unwrap()
        .channel_by_label(&format!("{tip}.z"))
        .unwrap();
    let z = zero_crossings(&uz[5..], r.energies.dt());
    let period = 2.0 * (z[3] - z[0]) / 3.0;
    let f = 1.0 / period;
    let beam = 1.8751f64.powi(2) / (2.0 * std::f64::consts::PI * l * l)
        * (E * t * t / (12.0 * RHO)).sqrt();
    assert!(rel(beam, 41.1) < 0.005);
    eprintln!("cantilever f1 = {f:.3} Hz (beam {beam:.3} Hz)");
    assert!(rel(f, beam) < 0.03, "f1 = {f:.2} Hz vs {beam:.2} Hz");
    // V13: over more than 10^4 cycles of this elastic vibration the energy balance drifts
    // by less than 0.1 %.
    assert!(r.summary.cycles > 10_000, "{} cycles", r.summary.cycles);
    let ratio = r.energies.channel_by_label("energy_ratio").unwrap();
    let worst = ratio.iter().map(|q| (q - 1.0).abs()).fold(0.0, f64::max);
    assert!(worst < 1e-3, "energy ratio drifts by {worst:.2e}");
}

/// V5: simply supported 1 m x 1 m x 10 mm plate, f11 = 48.9 Hz (12 x 12 quads); the energy
/// balance holds to 0.1 %.
#[test]
fn simply_supported_plate_frequency_and_energy_conservation() {
    let (a, t) = (1.0, 0.01);
    let n = 12;
    let mut m = simply_supported_plate_in_first_mode(a, t, n);
    let pi = std::f64::consts::PI;
    m.control.end_time = 0.05;
    m.output.interval = 2e-5;
    let centre = node_id(n, n / 2, n / 2);
    m.output.history_nodes = vec![centre];
    let mut sim = Simulation::new(&m).unwrap();
    let r = sim.run().unwrap();
    let uz = r
        .displacement
        .as_ref()
        .unwrap()
        .channel_by_label(&format!("{centre}.z"))
        .unwrap();
    let z = zero_crossings(&uz[5..], r.energies.dt());
    let f = 1.0 / (2.0 * (z[3] - z[0]) / 3.0);
    let d = E * t.powi(3) / (12.0 * (1.0 - NU * NU));
    let exact = pi / 2.0 * 2.0 / (a * a) * (d / (RHO * t)).sqrt();
    assert!(rel(exact, 48.9) < 0.005);
    eprintln!(
        "plate f11 = {f:.3} Hz (exact {exact:.3} Hz), {} cycles",
        r.summary.cycles
    );
    assert!(rel(f, exact) < 0.03, "f11 = {f:.2} Hz vs {exact:.2} Hz");
    let ratio = r.energies.channel_by_label("energy_ratio").unwrap();
    let worst = ratio.iter().map(|q| (q - 1.0).abs()).fold(0.0, f64::max);
    assert!(worst < 1e-3, "energy ratio drifts by {worst:.2e}");
}
