//! Mesh builders shared by the verification tests.
#![allow(dead_code)]

use impactcal_shell::{
    InitialVelocity, Material, MaterialLaw, NodeSet, NodeTarget, Section, ShellModel, Spc,
    VelocityTarget,
};

/// Aluminium of the reference notes: E 70 GPa, rho 2700, nu 0.33.
pub const E: f64 = 70e9;
pub const RHO: f64 = 2700.0;
pub const NU: f64 = 0.33;

pub fn aluminium(id: u64) -> Material {
    Material {
        id,
        density: RHO,
        youngs: E,
        poisson: NU,
        law: MaterialLaw::Elastic,
    }
}

/// A flat `nx x ny` plate of quads in the x-y plane, `lx x ly`, origin at `(x0, y0, z0)`;
/// node id `1 + i + j (nx + 1)`, element id `1 + i + j nx`, all in part 1 (section 1,
/// material 1, which the caller adds).
pub fn plate(nx: u64, ny: u64, lx: f64, ly: f64, origin: [f64; 3]) -> ShellModel {
    let mut m = ShellModel::new("plate");
    for j in 0..=ny {
        for i in 0..=nx {
            m.add_node(
                1 + i + j * (nx + 1),
                [
                    origin[0] + lx * i as f64 / nx as f64,
                    origin[1] + ly * j as f64 / ny as f64,
                    origin[2],
                ],
            );
        }
    }
    for j in 0..ny {
        for i in 0..nx {
            let n = 1 + i + j * (nx + 1);
            m.add_shell(1 + i + j * nx, 1, [n, n + 1, n + nx + 2, n + nx + 1]);
        }
    }
    m.add_part(1, 1, 1);
    m
}

/// A simply supported square aluminium plate, side `a`, thickness `t`, `n x n` quads
/// (section 1 added), started in its first mode: centre velocity 0.1 with the consistent
/// rotations (no transverse shear), `omega_x = d vz / dy`, `omega_y = -d vz / dx`.
pub fn simply_supported_plate_in_first_mode(a: f64, t: f64, n: u64) -> ShellModel {
    let mut m = plate(n, n, a, a, [0.0; 3]);
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
        let (sx, cx) = (pi * p.x[0] / a).sin_cos();
        let (sy, cy) = (pi * p.x[1] / a).sin_cos();
        let mut iv =
            InitialVelocity::translation(VelocityTarget::Node(p.id), [0.0, 0.0, 0.1 * sx * sy]);
        iv.rotation = [0.1 * pi / a * sx * cy, -0.1 * pi / a * cx * sy, 0.0];
        m.initial_velocities.push(iv);
    }
    m
}

pub fn node_id(nx: u64, i: u64, j: u64) -> u64 {
    1 + i + j * (nx + 1)
}

/// A circular tube of radius `r`, length `l` along +z from z = 0, `nt` elements around
/// and `nz` along; node id `1 + i + k nt` (ring k), part 1.
pub fn tube(nt: u64, nz: u64, r: f64, l: f64) -> ShellModel {
    let mut m = ShellModel::new("tube");
    for k in 0..=nz {
        for i in 0..nt {
            let a = 2.0 * std::f64::consts::PI * i as f64 / nt as f64;
            m.add_node(
                1 + i + k * nt,
                [r * a.cos(), r * a.sin(), l * k as f64 / nz as f64],
            );
        }
    }
    for k in 0..nz {
        for i in 0..nt {
            let n1 = 1 + i + k * nt;
            let n2 = 1 + (i + 1) % nt + k * nt;
            m.add_shell(1 + i + k * nt, 1, [n1, n2, n2 + nt, n1 + nt]);
        }
    }
    m.add_part(1, 1, 1);
    m
}

pub fn with_section(m: &mut ShellModel, t: f64, mat: Material) {
    m.sections.push(Section::new(1, t));
    m.materials.push(mat);
}

/// Times at which `y` crosses zero (linear interpolation), for a uniformly sampled signal.
pub fn zero_crossings(y: &[f64], dt: f64) -> Vec<f64> {
    let mut out = Vec::new();
    for k in 1..y.len() {
        if (y[k - 1] < 0.0 && y[k] >= 0.0) || (y[k - 1] > 0.0 && y[k] <= 0.0) {
            let s = y[k - 1] / (y[k - 1] - y[k]);
            out.push((k as f64 - 1.0 + s) * dt);
        }
    }
    out
}

pub fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}
