//! Rigid walls and their force histories: the geometric cylinder keeps nodes outside, the
//! sampled force of each wall integrates to the momentum it gave, walls carry their ids.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

mod common;

use common::{aluminium, plate, with_section};
use impactcal_shell::keyword::parse_deck;
use impactcal_shell::{
    InitialVelocity, RigidWall, ShellModel, Simulation, VelocityTarget, WallShape,
};

/// A 12 x 4 aluminium plate at z = 0 falling at 5 m/s onto a horizontal cylinder of
/// radius 0.03 (axis along y under the plate's middle, top 1 mm below it).
fn draped(length: f64) -> ShellModel {
    let mut m = plate(12, 4, 0.24, 0.08, [-0.12, -0.04, 0.0]);
    with_section(&mut m, 0.002, aluminium(1));
    m.initial_velocities.push(InitialVelocity::translation(
        VelocityTarget::All,
        [0.0, 0.0, -5.0],
    ));
    m.walls.push(RigidWall {
        id: 7,
        shape: WallShape::Cylinder {
            radius: 0.03,
            length,
        },
        ..RigidWall::plane([0.0, -0.1, -0.031], [0.0, 0.1, -0.031])
    });
    m.output.interval = 2e-5;
    m.control.end_time = 3e-3;
    m
}

fn momentum(sim: &Simulation) -> [f64; 3] {
    let mut p = [0.0; 3];
    for (v, m) in sim.velocities().iter().zip(sim.masses()) {
        for d in 0..3 {
            p[d] += m * v[d];
        }
    }
    p
}

#[test]
fn a_cylinder_keeps_nodes_outside_and_its_force_integrates_to_the_momentum_given() {
    let m = draped(0.0);
    let mut sim = Simulation::new(&m).unwrap();
    let p0 = momentum(&sim);
    let axis = |x: [f64; 3]| ((x[0]).powi(2) + (x[2] + 0.031).powi(2)).sqrt();
    let mut closest = f64::INFINITY;
    while sim.time() < m.control.end_time {
        sim.step().unwrap();
        for x in sim.positions() {
            closest = closest.min(axis(*x));
        }
    }
    // Nodes stay outside the cylinder (to the kinematic constraint's round-off).
    assert!(closest > 0.03 - 1e-9, "{closest}");
    assert!(
        closest < 0.0301,
        "the plate reached the cylinder: {closest}"
    );
    // The sampled force: its integral is the momentum the wall gave, and it points up.
    let r = Simulation::new(&m).unwrap().run().unwrap();
    let w = r.walls.as_ref().unwrap();
    assert_eq!(w.labels(), ["7.fx", "7.fy", "7.fz", "7.f"]);
    let dt = w.dt();
    let impulse: Vec<f64> = (0..3)
        .map(|c| w.channel(c).iter().sum::<f64>() * dt)
        .collect();
    let mut sim = Simulation::new(&m).unwrap();
    let end = sim.run().unwrap();
    let p1 = momentum(&sim);
    assert!(end.summary.end_time >= m.control.end_time);
    for d in 0..3 {
        let dp = p1[d] - p0[d];
        assert!(
            (impulse[d] - dp).abs() < 1e-9 * p0[2].abs(),
            "axis {d}: impulse {} vs momentum change {dp}",
            impulse[d]
        );
    }
    assert!(impulse[2] > 0.0);
    // By symmetry about the axis the x force vanishes.
    let fx: f64 = w.channel(0).iter().map(|f| f.abs()).fold(0.0, f64::max);
    let fz: f64 = w.channel(2).iter().map(|f| f.abs()).fold(0.0, f64::max);
    assert!(fx < 1e-6 * fz, "{fx} vs {fz}");
    // The summary's peak is the sampled peak, not a cycle's.
    assert_eq!(
        r.summary.wall_peaks,
        [(7, w.channel(3).iter().fold(0.0, |a: f64, &b| a.max(b)))]
    );
    assert_eq!(r.summary.peak_wall_force, r.summary.wall_peaks[0].1);
}

#[test]
fn a_finite_cylinder_leaves_the_nodes_beyond_its_length_free() {
    // The cylinder ends at y = -0.1 + 0.05 = -0.05, short of the plate (y >= -0.04).
    let m = draped(0.05);
    let r = Simulation::new(&m).unwrap().run().unwrap();
    let w = r.walls.as_ref().unwrap();
    assert!(w.channel(3).iter().all(|&f| f == 0.0));
    // Nodes starting inside a cylinder are refused with the node named.
    let mut m = draped(0.0);
    m.walls[0].point[2] = 0.0;
    m.walls[0].head[2] = 0.0;
    let e = Simulation::new(&m).err().unwrap().to_string();
    assert!(
        e.contains("rigid wall 7") && e.contains("behind the wall"),
        "{e}"
    );
}

#[test]
fn walls_read_from_a_deck_keep_their_ids_and_forces_apart() {
    let mut text = String::from(
        "*KEYWORD\n*CONTROL_TERMINATION\n    3.0e-3\n*CONTROL_HOURGLASS\n         4      0.05\n*DATABASE_NODOUT\n    2.0e-5\n",
    );
    text += "*SECTION_SHELL\n         1         2       0.0         2\n     0.002\n*MAT_ELASTIC\n         1    2700.0    7.0e10      0.33\n*PART\nplate\n         1         1         1\n";
    let base = plate(12, 4, 0.24, 0.08, [-0.12, -0.04, 0.0]);
    text += "*NODE\n";
    for n in &base.nodes {
        text += &format!("{:8}{:16.6}{:16.6}{:16.6}\n", n.id, n.x[0], n.x[1], n.x[2]);
    }
    text += "*ELEMENT_SHELL\n";
    for s in &base.shells {
        text += &format!(
            "{:8}{:8}{:8}{:8}{:8}{:8}\n",
            s.id, 1, s.nodes[0], s.nodes[1], s.nodes[2], s.nodes[3]
        );
    }
    text += "*INITIAL_VELOCITY\n         0\n       0.0       0.0      -5.0\n";
    // A floor under the right half's ends (tilted so it touches late) and the cylinder.
    text += "*RIGIDWALL_PLANAR_ID\n        11floor\n         0\n       0.0       0.0    -0.004       0.0       0.0       1.0\n";
    text += "*RIGIDWALL_GEOMETRIC_CYLINDER_DISPLAY_ID\n        12post\n         0\n       0.0      -0.1    -0.031       0.0       0.1    -0.031\n      0.03       0.0         0\n";
    text += "*END\n";
    let deck = parse_deck(&text, "walls.k").unwrap();
    assert!(deck.warnings.is_empty(), "{:?}", deck.warnings);
    let mut sim = Simulation::new(&deck.model).unwrap();
    let p0 = momentum(&sim);
    let r = sim.run().unwrap();
    let p1 = momentum(&sim);
    let w = r.walls.as_ref().unwrap();
    assert_eq!(
        w.labels(),
        [
            "11.fx", "11.fy", "11.fz", "11.f", "12.fx", "12.fy", "12.fz", "12.f"
        ]
    );
    let dt = w.dt();
    let floor: f64 = w.channel(2).iter().sum::<f64>() * dt;
    let post: f64 = w.channel(6).iter().sum::<f64>() * dt;
    assert!(floor > 0.0 && post > 0.0, "{floor} {post}");
    assert!((floor + post - (p1[2] - p0[2])).abs() < 1e-9 * p0[2].abs());
    // The total of the sampled histories against the cycle-by-cycle total in the energies.
    let peaks: Vec<u64> = r.summary.wall_peaks.iter().map(|p| p.0).collect();
    assert_eq!(peaks, [11, 12]);
}
