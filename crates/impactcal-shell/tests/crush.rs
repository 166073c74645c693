//! V10 (shell-solver.md section 5): progressive axial crushing of a square steel tube.
//!
//! A 50 x 50 x 1.5 mm steel tube, 100 mm long, elastic-perfectly plastic with flow stress
//! sigma_0 = 250 MPa, stands on the rigid floor; its top ring carries a 100 kg striker
//! moving down at 10 m/s (the top and bottom rings are held square: only axial motion).
//! A quarter of the tube is modelled (symmetry planes x = 0 and y = 0), 3.1 mm elements,
//! over 30 mm of crush (about one and a half folds). The mean crushing force after the
//! first buckle (from 5 mm of crush on, work of the wall force over the striker's travel)
//! is compared with the Wierzbicki-Abramowicz super-folding-element estimate
//! `P_m = 9.56 sigma_0 t^(5/3) b^(1/3)` (17.3 kN here), tolerance 20 %. There is no
//! self-contact in the solver, so the crush is kept short of the folds stacking up.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::rel;
use impactcal_shell::{
    InitialVelocity, Material, MaterialLaw, NodeTarget, RigidWall, Section, ShellModel, Simulation,
    Spc, VelocityTarget, WallMethod,
};

const B: f64 = 0.05;
const T: f64 = 0.0015;
const SIGMA0: f64 = 250e6;
const L: f64 = 0.1;

/// A quarter of the square tube (x >= 0, y <= 0: from the middle of the face y = -b/2
/// round the corner to the middle of the face x = b/2), `m` elements per half face, `nz`
/// along the length; node id `1 + i + k (2 m + 1)` (ring k). A small dent pattern
/// (amplitude `0.05 t`, adjacent faces in and out, half-wavelength the fold length) seeds the
/// symmetric folding mode.
fn quarter_tube(m_half: u64, nz: u64) -> ShellModel {
    let mut m = ShellModel::new("square tube crush, quarter");
    let ring = 2 * m_half + 1;
    let h = 0.5 * B / m_half as f64;
    let fold = 0.99 * T.powf(1.0 / 3.0) * B.powf(2.0 / 3.0);
    for k in 0..=nz {
        let z = L * k as f64 / nz as f64;
        for i in 0..ring {
            // Face 0 (normal -y) from its middle to the corner, then face 1 (normal +x).
            let (s, mut x, mut y, nx, ny, sign) = if i <= m_half {
                let s = i as f64 * h;
                (s, s, -0.5 * B, 0.0, -1.0, 1.0)
            } else {
                let s = 0.5 * B - (i - m_half) as f64 * h;
                (s, 0.5 * B, -s, 1.0, 0.0, -1.0)
            };
            let across = (std::f64::consts::PI * (s + 0.5 * B) / B).sin();
            let along = (std::f64::consts::PI * z / fold).sin();
            let d = 0.05 * T * sign * across * along;
            x += d * nx;
            y += d * ny;
            m.add_node(1 + i + k * ring, [x, y, z]);
        }
    }
    for k in 0..nz {
        for i in 0..ring - 1 {
            let n1 = 1 + i + k * ring;
            m.add_shell(1 + i + k * ring, 1, [n1, n1 + 1, n1 + 1 + ring, n1 + ring]);
        }
    }
    m.add_part(1, 1, 1);
    m.sections.push(Section::new(1, T));
    m.materials.push(Material {
        id: 1,
        density: 7850.0,
        youngs: 210e9,
        poisson: 0.3,
        law: MaterialLaw::Plastic {
            yield_stress: SIGMA0,
            tangent_modulus: 0.0,
            rate: None,
        },
    });
    m
}

#[test]
fn square_tube_mean_crush_force_matches_wierzbicki_abramowicz() {
    let (m_half, nz) = (8, 32);
    let ring = 2 * m_half + 1;
    let mut m = quarter_tube(m_half, nz);
    let (striker, v0) = (100.0, 10.0);
    let top: Vec<u64> = (0..ring).map(|i| 1 + i + nz * ring).collect();
    let bottom: Vec<u64> = (0..ring).map(|i| 1 + i).collect();
    for (j, &id) in top.iter().enumerate() {
        m.add_mass(10_000 + j as u64, id, 0.25 * striker / ring as f64);
        m.initial_velocities.push(InitialVelocity::translation(
            VelocityTarget::Node(id),
            [0.0, 0.0, -v0],
        ));
    }
    // Ends held square (axial motion only); symmetry on the planes x = 0 and y = 0.
    for &id in top.iter().chain(&bottom) {
        m.spcs.push(Spc {
            target: NodeTarget::Node(id),
            dofs: [true, true, false, true, true, true],
        });
    }
    for k in 0..=nz {
        m.spcs.push(Spc {
            target: NodeTarget::Node(1 + k * ring),
            dofs: [true, false, false, false, true, true],
        });
        m.spcs.push(Spc {
            target: NodeTarget::Node(ring + k * ring),
            dofs: [false, true, false, true, false, true],
        });
    }
    m.walls.push(RigidWall {
        id: 0,
        shape: impactcal_shell::WallShape::Plane,
        nodes: None,
        point: [0.0; 3],
        head: [0.0, 0.0, 1.0],
        friction: 0.0,
        method: WallMethod::Kinematic,
    });
    let crush = 0.03;
    m.control.end_time = crush / (0.95 * v0);
    m.output.interval = 2e-5;
    m.output.history_nodes = vec![top[0]];
    let r = Simulation::new(&m).unwrap().run().unwrap();
    let e = &r.energies;
    let f: Vec<f64> = e
        .channel_by_label("wall_force")
        .unwrap()
        .iter()
        .map(|f| 4.0 * f)
        .collect();
    let internal = e.channel_by_label("internal").unwrap();
    let hourglass = e.channel_by_label("hourglass").unwrap();
    let uz = r
        .displacement
        .as_ref()
        .unwrap()
        .channel_by_label(&format!("{}.z", top[0]))
        .unwrap();
    let vz = r
        .velocity
        .as_ref()
        .unwrap()
        .channel_by_label(&format!("{}.z", top[0]))
        .unwrap();
    let last = f.len() - 1;
    let du = -uz[last];
    // Work of the wall force along the top's travel, after the first buckle (u > 5 mm).
    let mut work = 0.0;
    let mut u_start = None;
    for k in 1..f.len() {
        if -uz[k] > 0.005 {
            u_start.get_or_insert(-uz[k - 1]);
            work += 0.5 * (f[k] + f[k - 1]) * (uz[k - 1] - uz[k]);
        }
    }
    let p_wall = work / (du - u_start.unwrap());
    let p_energy = 4.0 * (internal[last] + hourglass[last]) / du;
    let peak = f.iter().cloned().fold(0.0, f64::max);
    let wa = 9.56 * SIGMA0 * T.powf(5.0 / 3.0) * B.powf(1.0 / 3.0);
    eprintln!(
        "crush {du:.4} m, v_end {:.2}, P_wall {p_wall:.0} N, P_energy {p_energy:.0} N, peak {peak:.0} N, WA {wa:.0} N, hourglass/internal {:.3}, cycles {}, dt first {:.3e} min {:.3e}",
        vz[last],
        hourglass[last] / internal[last],
        r.summary.cycles,
        r.summary.dt_first,
        r.summary.dt_min
    );
    assert!(rel(wa, 17.3e3) < 0.005);
    assert!(
        rel(p_wall, wa) < 0.2,
        "mean crush force {p_wall:.0} N vs {wa:.0} N"
    );
    // The striker is still crushing at the end, and the fold is not an hourglass pattern.
    assert!(
        du > 0.028 && vz[last] < -8.0,
        "crush {du} m, v_end {}",
        vz[last]
    );
    assert!(hourglass[last] < 0.25 * internal[last]);
}
