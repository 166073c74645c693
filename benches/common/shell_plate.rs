//! The benchmark plate shared by `benches/shell.rs` and `benches/harness/shell_timing.rs`: a
//! 150 x 140 mesh of 21,000 mildly warped Belytschko-Lin-Tsay quads, elastic-plastic
//! aluminium, 5 Gauss points, driven by a velocity field that bends and stretches it into
//! the plastic range.

use impactcal::shell::{
    InitialVelocity, Material, MaterialLaw, Section, ShellModel, VelocityTarget,
};

/// Quads along x.
pub const NX: u64 = 150;
/// Quads along y.
pub const NY: u64 = 140;

/// The benchmark model.
pub fn plate() -> ShellModel {
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
            80.0 * (p.x[1] * 7.0).sin(),
            0.0,
            -120.0 * (p.x[0] * 5.0).sin(),
        ];
        m.initial_velocities
            .push(InitialVelocity::translation(VelocityTarget::Node(p.id), v));
    }
    m.control.end_time = 1.0;
    m
}
