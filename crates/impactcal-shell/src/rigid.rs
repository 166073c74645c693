//! Rigid bodies: rigid parts (`*MAT_RIGID`) and spot welds, joined where they share nodes.
//!
//! A body is its nodes with their lumped masses `m_i` and rotary inertias `I_i`: mass
//! `M = sum m_i`, centre `c = sum m_i x_i / M`, inertia about the centre
//! `J = sum m_i (|r_i|^2 1 - r_i r_i^T) + sum I_i 1` (`r_i = x_i - c`), so that the nodal
//! kinetic energy of a rigid motion is exactly the body's `M |V|^2 / 2 + w.J w / 2`. Each
//! cycle the forces on its nodes (of the deformable shells around it, gravity, damping)
//! give `F = sum m_i a_i`, `T = sum r_i x m_i a_i + sum I_i alpha_i`; central differences
//! advance `V += dt F / M` and the angular momentum `L += dt T`, `w = J(t)^-1 L` with
//! `J(t) = R J0 R^T`; the pose advances exactly, `c += dt V`, `R = exp(dt [w]x) R`
//! (Rodrigues), and each node is given the velocity that takes it to `c + R r0_i` at the
//! end of the next step, so the body never stretches. Held directions (`*MAT_RIGID` CMO 1)
//! zero the matching components of `V` and `w`; a prescribed motion sets them.

use crate::error::{Result, ShellError};
use crate::model::{MaterialLaw, RigidConstraints, ShellModel};

/// A 3 x 3 matrix, rows first.
pub(crate) type M3 = [[f64; 3]; 3];

/// A rigid body as built: its nodes, the rigid parts in it, its held directions, mass,
/// initial centre, inertia about the centre in the initial orientation and the initial
/// offsets of its nodes from the centre.
#[derive(Debug, Clone)]
pub(crate) struct RigidDef {
    pub nodes: Vec<u32>,
    pub parts: Vec<usize>,
    pub constraints: RigidConstraints,
    pub mass: f64,
    pub centre: [f64; 3],
    pub inertia: M3,
    pub offsets: Vec<[f64; 3]>,
}

/// The state of a rigid body: centre, orientation, velocity and angular velocity (the
/// velocities of the half step ahead).
#[derive(Debug, Clone, Copy)]
pub(crate) struct RigidState {
    pub centre: [f64; 3],
    pub rotation: M3,
    pub v: [f64; 3],
    pub w: [f64; 3],
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// The rigid bodies of `groups` (node indices, and the part index of a rigid part), joined
/// where groups share nodes.
///
/// # Errors
/// [`ShellError::Value`] for a body without mass.
pub(crate) fn rigid_bodies(
    model: &ShellModel,
    groups: &[(Vec<u32>, Option<usize>)],
    x0: &[[f64; 3]],
    mass: &[f64],
    inertia: &[f64],
) -> Result<Vec<RigidDef>> {
    let n = groups.len();
    let mut parent: Vec<usize> = (0..n).collect();
    let mut owner: std::collections::HashMap<u32, usize> = std::collections::HashMap::new();
    for (g, (nodes, _)) in groups.iter().enumerate() {
        for &i in nodes {
            match owner.get(&i) {
                Some(&h) => {
                    let (a, b) = (find(&mut parent, g), find(&mut parent, h));
                    parent[a.max(b)] = a.min(b);
                }
                None => {
                    owner.insert(i, g);
                }
            }
        }
    }
    let mut out: Vec<RigidDef> = Vec::new();
    let mut index: Vec<usize> = vec![usize::MAX; n];
    for g in 0..n {
        let root = find(&mut parent, g);
        if index[root] == usize::MAX {
            index[root] = out.len();
            out.push(RigidDef {
                nodes: Vec::new(),
                parts: Vec::new(),
                constraints: RigidConstraints::default(),
                mass: 0.0,
                centre: [0.0; 3],
                inertia: [[0.0; 3]; 3],
                offsets: Vec::new(),
            });
        }
        let body = &mut out[index[root]];
        body.nodes.extend(&groups[g].0);
        if let Some(k) = groups[g].1 {
            body.parts.push(k);
            let mid = model.parts[k].material;
            if let Some(MaterialLaw::Rigid { constraints }) =
                model.materials.iter().find(|m| m.id == mid).map(|m| m.law)
            {
                for d in 0..3 {
                    body.constraints.translation[d] |= constraints.translation[d];
                    body.constraints.rotation[d] |= constraints.rotation[d];
                }
            }
        }
    }
    for (b, body) in out.iter_mut().enumerate() {
        body.nodes.sort_unstable();
        body.nodes.dedup();
        let m: f64 = body.nodes.iter().map(|&i| mass[i as usize]).sum();
        if !(m > 0.0) {
            return Err(ShellError::value(
                format!(
                    "rigid body {} (node {})",
                    b + 1,
                    model.nodes[body.nodes[0] as usize].id
                ),
                "has no mass (a rigid part needs a density, a weld nodes with mass)",
            ));
        }
        let mut c = [0.0; 3];
        for &i in &body.nodes {
            for d in 0..3 {
                c[d] += mass[i as usize] * x0[i as usize][d] / m;
            }
        }
        let mut j = [[0.0; 3]; 3];
        for &i in &body.nodes {
            let r = sub(x0[i as usize], c);
            let mi = mass[i as usize];
            let r2 = dot(r, r);
            for a in 0..3 {
                for bb in 0..3 {
                    j[a][bb] += mi * (if a == bb { r2 } else { 0.0 } - r[a] * r[bb]);
                }
                j[a][a] += inertia[i as usize];
            }
            body.offsets.push(r);
        }
        body.mass = m;
        body.centre = c;
        body.inertia = j;
    }
    Ok(out)
}

pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `m v`.
pub(crate) fn mul(m: &M3, v: [f64; 3]) -> [f64; 3] {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

/// `a b`.
pub(crate) fn matmul(a: &M3, b: &M3) -> M3 {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    c
}

pub(crate) fn transpose(a: &M3) -> M3 {
    let mut t = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            t[i][j] = a[j][i];
        }
    }
    t
}

/// The inverse of a symmetric positive semi-definite matrix; a singular one (a body whose
/// nodes lie on a line and carry no rotary inertia) is regularised by `1e-12` of its trace
/// on the diagonal.
pub(crate) fn inverse(a: &M3) -> M3 {
    let tr = a[0][0] + a[1][1] + a[2][2];
    let mut m = *a;
    let det = |m: &M3| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    if !(det(&m).abs() > 1e-24 * tr * tr * tr) {
        for d in 0..3 {
            m[d][d] += 1e-12 * tr.max(f64::MIN_POSITIVE);
        }
    }
    let dt = det(&m);
    let mut inv = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let (i1, i2) = ((j + 1) % 3, (j + 2) % 3);
            let (j1, j2) = ((i + 1) % 3, (i + 2) % 3);
            inv[i][j] = (m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]) / dt;
        }
    }
    inv
}

/// The rotation by the vector `phi` (axis `phi / |phi|`, angle `|phi|`), by Rodrigues'
/// formula.
pub(crate) fn rotation(phi: [f64; 3]) -> M3 {
    let th = dot(phi, phi).sqrt();
    let mut r = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    if !(th > 0.0) {
        return r;
    }
    let k = [phi[0] / th, phi[1] / th, phi[2] / th];
    let (s, c) = th.sin_cos();
    let kx = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] += s * kx[i][j] + (1.0 - c) * (k[i] * k[j] - if i == j { 1.0 } else { 0.0 });
        }
    }
    r
}

impl RigidState {
    /// The initial state of a body: its centre and unit orientation, with the velocity and
    /// angular velocity whose rigid motion has the momentum and angular momentum of the
    /// nodes' initial velocities `v0` and angular velocities `w0`.
    pub(crate) fn initial(
        def: &RigidDef,
        mass: &[f64],
        inertia: &[f64],
        v0: &[[f64; 3]],
        w0: &[[f64; 3]],
    ) -> Self {
        let mut p = [0.0; 3];
        let mut l = [0.0; 3];
        for (k, &i) in def.nodes.iter().enumerate() {
            let i = i as usize;
            let mv = [mass[i] * v0[i][0], mass[i] * v0[i][1], mass[i] * v0[i][2]];
            let rl = cross(def.offsets[k], mv);
            for d in 0..3 {
                p[d] += mv[d];
                l[d] += rl[d] + inertia[i] * w0[i][d];
            }
        }
        let mut st = RigidState {
            centre: def.centre,
            rotation: rotation([0.0; 3]),
            v: [p[0] / def.mass, p[1] / def.mass, p[2] / def.mass],
            w: mul(&inverse(&def.inertia), l),
        };
        st.hold(&def.constraints);
        st
    }

    /// Zeroes the held components of the velocities.
    pub(crate) fn hold(&mut self, c: &RigidConstraints) {
        for d in 0..3 {
            if c.translation[d] {
                self.v[d] = 0.0;
            }
            if c.rotation[d] {
                self.w[d] = 0.0;
            }
        }
    }

    /// The inertia about the centre in the current orientation, `R J0 R^T`.
    pub(crate) fn inertia(&self, def: &RigidDef) -> M3 {
        matmul(
            &matmul(&self.rotation, &def.inertia),
            &transpose(&self.rotation),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotations_and_inverses_are_exact_to_rounding() {
        let r = rotation([0.3, -0.2, 0.5]);
        let i = matmul(&r, &transpose(&r));
        for a in 0..3 {
            for b in 0..3 {
                let want = if a == b { 1.0 } else { 0.0 };
                assert!((i[a][b] - want).abs() < 1e-15);
            }
        }
        // A quarter turn about z takes x to y.
        let q = rotation([0.0, 0.0, std::f64::consts::FRAC_PI_2]);
        let y = mul(&q, [1.0, 0.0, 0.0]);
        assert!((y[0]).abs() < 1e-15 && (y[1] - 1.0).abs() < 1e-15);
        let a = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]];
        let p = matmul(&a, &inverse(&a));
        for x in 0..3 {
            for z in 0..3 {
                let want = if x == z { 1.0 } else { 0.0 };
                assert!((p[x][z] - want).abs() < 1e-14);
            }
        }
    }
}
