//! The Belytschko-Lin-Tsay quad evaluated on blocks of [`LANES`] elements at once.
//!
//! The frame, the centre derivatives, the characteristic length, the hourglass control and
//! the warping projection are the quad's own; the rates, the section response and the
//! nodal forces are the shared pieces of [`super::resultants`], here on [`V`] lanes (see
//! [`crate::element`]'s module docs for the equations). Every lane is computed
//! independently with plain IEEE operations, so an element's result does not depend on the
//! block it sits in, the lane it occupies or the number of threads. Only the plastic
//! return, needed by few points, runs lane by lane.

pub(crate) use super::lanes::LANES;
use super::lanes::{Lane, V, cross3, dot3, sub3};
use super::output::{ElementFault, ElementOutput, KernelOptions};
use super::props::{PartProps, STATE_HEAD};
use super::resultants::{StateSlots, rates, section_response, to_global};
use crate::model::HourglassForm;

type V3 = [V; 3];

/// Where a block's data lives: the element node indices per lane, the lanes in use, and
/// each lane's element position in `state` / `out` (unused lanes repeat lane 0).
pub(crate) struct Block {
    pub nodes: [[u32; 4]; LANES],
    pub slot: [usize; LANES],
    pub active: usize,
}

/// Evaluates the quads of one block for a step `dt`: reads positions `x`, mid-step
/// velocities `v` and angular velocities `w` at the nodes, updates the element states
/// (`stride` values each in `state`, element `slot[l]` at `slot[l] * stride`) and writes
/// the outputs to `out[slot[l]]` and `fault[slot[l]]` for the active lanes.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(crate) fn quad_block(
    blk: &Block,
    x: &[[f64; 3]],
    v: &[[f64; 3]],
    w: &[[f64; 3]],
    props: &PartProps,
    state: &mut [f64],
    stride: usize,
    out: &mut [ElementOutput],
    faults: &mut [Option<ElementFault>],
    dt: f64,
    opts: KernelOptions,
) {
    // Gather.
    let load = |a: &[[f64; 3]], node: usize| -> V3 {
        let mut r = [V::default(); 3];
        for l in 0..LANES {
            let p = a[blk.nodes[l][node] as usize];
            for k in 0..3 {
                r[k].0[l] = p[k];
            }
        }
        r
    };
    let xs = [load(x, 0), load(x, 1), load(x, 2), load(x, 3)];

    // Frame.
    let mut fault = [None; LANES];
    let d31 = sub3(xs[2], xs[0]);
    let d42 = sub3(xs[3], xs[1]);
    let n3 = cross3(d31, d42);
    let len3 = dot3(n3, n3).sqrt();
    let mut a = [V::default(); 3];
    if opts.invariant {
        // Bisector of the two diagonals: the same frame, up to quarter turns, whichever
        // node is numbered first and whichever way the nodes run.
        let (i31, i42) = (1.0 / dot3(d31, d31).sqrt(), 1.0 / dot3(d42, d42).sqrt());
        for k in 0..3 {
            a[k] = d31[k] * i31 - d42[k] * i42;
        }
    } else {
        for k in 0..3 {
            a[k] = xs[1][k] - xs[0][k] + xs[2][k] - xs[3][k];
        }
    }
    let inv3 = 1.0 / len3;
    let e3 = [n3[0] * inv3, n3[1] * inv3, n3[2] * inv3];
    let an = dot3(a, e3);
    for k in 0..3 {
        a[k] -= an * e3[k];
    }
    let len1 = dot3(a, a).sqrt();
    let inv1 = 1.0 / len1;
    let e1 = [a[0] * inv1, a[1] * inv1, a[2] * inv1];
    let e2 = cross3(e3, e1);
    for l in 0..LANES {
        let ok = |n: f64| n > 0.0 && n.is_finite();
        if !(ok(len3.0[l]) && ok(len1.0[l])) {
            fault[l] = Some(ElementFault::Degenerate);
        }
    }

    // Local coordinates from the centroid.
    let mut c = [V::default(); 3];
    for k in 0..3 {
        c[k] = 0.25 * (xs[0][k] + xs[1][k] + xs[2][k] + xs[3][k]);
    }
    let mut r = [[V::default(); 3]; 4];
    for i in 0..4 {
        let d = sub3(xs[i], c);
        r[i] = [dot3(e1, d), dot3(e2, d), dot3(e3, d)];
    }
    let (x1, x2, x3, x4) = (r[0][0], r[1][0], r[2][0], r[3][0]);
    let (y1, y2, y3, y4) = (r[0][1], r[1][1], r[2][1], r[3][1]);
    let area = 0.5 * ((x3 - x1) * (y4 - y2) + (x2 - x4) * (y3 - y1));
    // Corner Jacobians in the element plane: all positive for a convex, non-inverted quad.
    let corner: [V; 4] = std::array::from_fn(|i| {
        let (p, n, q) = (r[(i + 3) % 4], r[(i + 1) % 4], r[i]);
        (n[0] - q[0]) * (p[1] - q[1]) - (n[1] - q[1]) * (p[0] - q[0])
    });
    for l in 0..LANES {
        if fault[l].is_none() {
            if !(area.0[l].abs() > 0.0) {
                fault[l] = Some(ElementFault::Degenerate);
            } else if opts.distortion_check && !corner.iter().all(|j| j.0[l] > 0.0) {
                fault[l] = Some(ElementFault::Inverted);
            }
        }
    }
    let s = 0.5 / area;
    let b1 = [s * (y2 - y4), s * (y3 - y1), s * (y4 - y2), s * (y1 - y3)];
    let b2 = [s * (x4 - x2), s * (x1 - x3), s * (x2 - x4), s * (x3 - x1)];

    // Local velocities and angular velocities.
    let mut u = [[V::default(); 3]; 4];
    let mut th = [[V::default(); 3]; 4];
    for i in 0..4 {
        let vi = load(v, i);
        let wi = load(w, i);
        u[i] = [dot3(e1, vi), dot3(e2, vi), dot3(e3, vi)];
        th[i] = [dot3(e1, wi), dot3(e2, wi), dot3(e3, wi)];
    }
    // Flanagan-Belytschko hourglass vector.
    let hx = x1 - x2 + x3 - x4;
    let hy = y1 - y2 + y3 - y4;
    const H: [f64; 4] = [1.0, -1.0, 1.0, -1.0];
    let gam: [V; 4] = std::array::from_fn(|i| H[i] - hx * b1[i] - hy * b2[i]);

    // Warping projection, applied through its effect. Strain and hourglass rates vanish on
    // rigid translations and, but for terms in the warp heights z_I, on rigid rotations.
    // In this frame both diagonals are normal to e3, so z = w (1, -1, 1, -1): B1.z = B2.z = 0
    // and the warp only reaches the membrane hourglass rates, through Zg = gamma.z. Removing
    // the rigid part of the velocities (rotation w = G^-1 (sum r_I x v_I + theta_I)) thus
    // shifts q_0 by -w_y Zg and q_1 by w_x Zg; on the forces, P f only removes the rotation
    // of the mode powers rho = (-hg_1 Zg, hg_0 Zg, 0).
    let warp = opts.projection.then(|| {
        let gi = gram_inverse(&r);
        let mut bs = [V::default(); 3];
        for i in 0..4 {
            let c = cross3(r[i], u[i]);
            for k in 0..3 {
                bs[k] += c[k] + th[i][k];
            }
        }
        let mut zg = V::default();
        for i in 0..4 {
            zg += gam[i] * r[i][2];
        }
        (gi, dot3(gi[0], bs), dot3(gi[1], bs), zg)
    });

    let rt = rates(&b1, &b2, &u, &th);
    let mat = &props.mat;
    let t = props.t;
    let g = mat.g;

    // Characteristic length: sqrt is monotonic, so the longest length is the root of the
    // largest square.
    let sq = |a: V3| dot3(a, a);
    let diag2 = sq(d31).max(sq(d42));
    let len2 = if opts.isdo_diagonal {
        diag2
    } else {
        sq(sub3(xs[1], xs[0]))
            .max(sq(sub3(xs[2], xs[1])))
            .max(sq(sub3(xs[3], xs[2])))
            .max(sq(sub3(xs[0], xs[3])))
            .max(diag2)
    };
    let len = area / len2.sqrt();

    // The section: thickness points, transverse shear, damping, bulk viscosity, forces.
    let base = blk.slot.map(|e| e * stride);
    let resp = section_response(
        &b1,
        &b2,
        area,
        &rt,
        len,
        props,
        &mut StateSlots {
            state: &mut *state,
            base: &base,
            active: blk.active,
        },
        dt,
    );
    let (mut f, mut damping, beta, dt_e) = (resp.f, resp.damping, resp.beta, resp.dt);
    let internal = resp.internal;
    // The hourglass generalised forces of the state.
    let mut head = [V::default(); STATE_HEAD];
    for l in 0..LANES {
        let st = &state[base[l]..base[l] + STATE_HEAD];
        for q in 2..STATE_HEAD {
            head[q].0[l] = st[q];
        }
    }

    // Hourglass rates: membrane x, y; out-of-plane w; rotation x, y.
    let mut q = [V::default(); 5];
    for i in 0..4 {
        q[0] += gam[i] * u[i][0];
        q[1] += gam[i] * u[i][1];
        q[2] += gam[i] * u[i][2];
        q[3] += gam[i] * th[i][0];
        q[4] += gam[i] * th[i][1];
    }
    if let Some((_, wx, wy, zg)) = warp {
        q[0] -= wy * zg;
        q[1] += wx * zg;
    }
    let [rm, rw, rb] = props.hg;
    let mut cc = [V::default(); 5];
    match props.hg_form {
        HourglassForm::Stiffness => {
            let mut bb = V::default();
            for i in 0..4 {
                bb += b1[i] * b1[i] + b2[i] * b2[i];
            }
            let t3 = t * t * t;
            cc[0] = (rm * mat.e * t / 8.0) * area * bb;
            cc[1] = cc[0];
            cc[2] = (rw * props.shear_factor * g * t3 / 12.0) * bb;
            cc[3] = (rb * mat.e * t3 / 192.0) * area * bb;
            cc[4] = cc[3];
        }
        HourglassForm::Viscous => {
            // Each mode's coefficient is r times its impedance sqrt(S m) (S its
            // stiffness-form coefficient at r = 1, m its nodal mass or rotary inertia),
            // scaled so that the membrane modes keep r rho c t sqrt(A) / 4.
            let root = area.sqrt();
            let base = 0.25 * mat.rho * mat.wave_speed * t * root;
            cc[0] = rm * base;
            cc[1] = cc[0];
            let w = (props.shear_factor / (3.0 * (1.0 + mat.nu))).sqrt();
            cc[2] = rw * w * t * base / root;
            let inertia = (area * 0.125).max(V::splat(t * t / 12.0));
            cc[3] = (rb * t) * base * (inertia * (1.0 / 24.0)).sqrt();
            cc[4] = cc[3];
        }
    }
    let mut hourglass = V::default();
    let mut hg = [V::default(); 5];
    for k in 0..5 {
        let old = head[2 + k];
        hg[k] = match props.hg_form {
            HourglassForm::Stiffness => old + cc[k] * dt * q[k],
            HourglassForm::Viscous => cc[k] * q[k],
        };
        hourglass += match props.hg_form {
            HourglassForm::Stiffness => 0.5 * (old + hg[k]) * dt * q[k],
            HourglassForm::Viscous => hg[k] * dt * q[k],
        };
    }
    for l in 0..blk.active {
        let st = &mut state[base[l]..base[l] + STATE_HEAD];
        for k in 0..5 {
            st[2 + k] = hg[k].0[l];
        }
    }
    // The stiffness damping also acts on the hourglass stiffness (stiffness form).
    if let (Some(beta), HourglassForm::Stiffness) = (beta, props.hg_form) {
        for k in 0..5 {
            let hd = beta * cc[k] * q[k];
            damping += dt * hd * q[k];
            hg[k] += hd;
        }
    }
    for i in 0..4 {
        for k in 0..5 {
            f[i][k] += gam[i] * hg[k];
        }
    }
    if let Some((gi, _, _, zg)) = warp {
        let rx = -(hg[1] * zg);
        let ry = hg[0] * zg;
        let wf = [
            gi[0][0] * rx + gi[0][1] * ry,
            gi[1][0] * rx + gi[1][1] * ry,
            gi[2][0] * rx + gi[2][1] * ry,
        ];
        for i in 0..4 {
            let c = cross3(wf, r[i]);
            for k in 0..3 {
                f[i][k] -= c[k];
                f[i][3 + k] -= wf[k];
            }
        }
    }

    // Back to the global frame, into the slots.
    let gf = to_global(&[e1, e2, e3], &f);
    for l in 0..blk.active {
        let o = &mut out[blk.slot[l]];
        for i in 0..4 {
            for k in 0..6 {
                o.f[i][k] = gf[i][k].0[l];
            }
        }
        o.dt = dt_e.0[l];
        o.internal = internal.0[l];
        o.hourglass = hourglass.0[l];
        o.damping = damping.0[l];
        faults[blk.slot[l]] = fault[l];
    }
}

/// Inverse of the rigid-rotation Gram matrix `G = sum_I (|r_I|^2 1 - r_I r_I^T) + 4 1`
/// (symmetric), without its (z, z) entry (returned as 0).
#[inline(always)]
fn gram_inverse(r: &[V3; 4]) -> [V3; 3] {
    let (mut g00, mut g11, mut g22) = (V::splat(4.0), V::splat(4.0), V::splat(4.0));
    let (mut g01, mut g02, mut g12) = (V::default(), V::default(), V::default());
    for ri in r {
        let (x2, y2, z2) = (ri[0] * ri[0], ri[1] * ri[1], ri[2] * ri[2]);
        g00 += y2 + z2;
        g11 += x2 + z2;
        g22 += x2 + y2;
        g01 -= ri[0] * ri[1];
        g02 -= ri[0] * ri[2];
        g12 -= ri[1] * ri[2];
    }
    let c00 = g11 * g22 - g12 * g12;
    let c01 = g12 * g02 - g01 * g22;
    let c02 = g01 * g12 - g11 * g02;
    let c11 = g00 * g22 - g02 * g02;
    let c12 = g02 * g01 - g00 * g12;
    let inv = 1.0 / (g00 * c00 + g01 * c01 + g02 * c02);
    let (c00, c01, c02) = (c00 * inv, c01 * inv, c02 * inv);
    let (c11, c12) = (c11 * inv, c12 * inv);
    // The (z, z) entry is never needed: only rotations about the in-plane axes carry
    // strain on a warped element.
    [[c00, c01, c02], [c01, c11, c12], [c02, c12, V::default()]]
}

/// One quad on its own (all lanes of a block on the same element): the public
/// [`crate::element::quad`] path.
pub(crate) fn quad_single(
    x: &[[f64; 3]; 4],
    v: &[[f64; 3]; 4],
    omega: &[[f64; 3]; 4],
    props: &PartProps,
    state: &mut [f64],
    dt: f64,
    opts: KernelOptions,
) -> Result<ElementOutput, ElementFault> {
    let blk = Block {
        nodes: [[0, 1, 2, 3]; LANES],
        slot: [0; LANES],
        active: 1,
    };
    let mut out = [ElementOutput::default()];
    let mut fault = [None];
    let stride = state.len();
    quad_block(
        &blk, x, v, omega, props, state, stride, &mut out, &mut fault, dt, opts,
    );
    match fault[0] {
        Some(f) => Err(f),
        None => Ok(out[0]),
    }
}

/// Quads of one part in element order, in blocks of [`LANES`] (the batch path of
/// [`crate::element::quad_batch`]).
#[allow(clippy::too_many_arguments)]
pub(crate) fn quad_run(
    elems: &[[u32; 4]],
    x: &[[f64; 3]],
    v: &[[f64; 3]],
    w: &[[f64; 3]],
    props: &PartProps,
    state: &mut [f64],
    stride: usize,
    out: &mut [ElementOutput],
    faults: &mut [Option<ElementFault>],
    dt: f64,
    opts: KernelOptions,
) {
    for (b, chunk) in elems.chunks(LANES).enumerate() {
        let first = b * LANES;
        let mut blk = Block {
            nodes: [chunk[0]; LANES],
            slot: [first; LANES],
            active: chunk.len(),
        };
        for (l, e) in chunk.iter().enumerate() {
            blk.nodes[l] = *e;
            blk.slot[l] = first + l;
        }
        quad_block(&blk, x, v, w, props, state, stride, out, faults, dt, opts);
    }
}

#[cfg(test)]
mod tests {
    use super::super::props::STATE_PER_POINT;
    use super::*;
    use crate::material::MaterialProps;
    use crate::model::{Material, MaterialLaw};

    fn props() -> PartProps {
        let t = 0.002;
        PartProps {
            t,
            z: vec![-0.45 * t, -0.25 * t, 0.0, 0.25 * t, 0.45 * t],
            w: vec![0.1, 0.2, 0.4, 0.2, 0.1],
            shear_factor: 5.0 / 6.0,
            mat: MaterialProps::new(&Material {
                id: 1,
                density: 2700.0,
                youngs: 70e9,
                poisson: 0.3,
                law: MaterialLaw::Plastic {
                    yield_stress: 200e6,
                    tangent_modulus: 1e9,
                    rate: None,
                },
            }),
            hg_form: HourglassForm::Stiffness,
            hg: [0.05, 0.05, 0.05],
            stiffness_damping: 0.0,
            z_moments: [0.0, 0.1 * 0.2025 * t * t * 2.0 + 0.2 * 0.0625 * t * t * 2.0],
            bulk: [0.0, 0.0],
            rigid: false,
            section: crate::model::Section::new(1, t),
            hourglass: crate::model::Hourglass::default(),
        }
    }

    /// A pseudo-random number in [-1, 1) from an index (golden-ratio sequence).
    fn h(i: usize) -> f64 {
        2.0 * ((i as f64 * 0.618_033_988_749_895).fract() - 0.5)
    }

    /// Every lane of a block, full or partial, gives bit for bit the result of the same
    /// element evaluated alone, plastic points included.
    #[test]
    fn a_block_lane_matches_the_element_alone() {
        let props = props();
        let stride = STATE_HEAD + STATE_PER_POINT * 5;
        let ne = 7;
        let mut x = Vec::new();
        let mut v = Vec::new();
        let mut w = Vec::new();
        for e in 0..ne {
            let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
            for (c, p) in corners.iter().enumerate() {
                let i = 4 * e + c;
                x.push([
                    0.01 * (p[0] + 0.1 * h(3 * i)),
                    0.01 * (p[1] + 0.1 * h(3 * i + 1)),
                    0.001 * h(3 * i + 2),
                ]);
                v.push([50.0 * h(7 * i), 50.0 * h(7 * i + 1), 80.0 * h(7 * i + 2)]);
                w.push([3e3 * h(11 * i), 3e3 * h(11 * i + 1), 1e3 * h(11 * i + 2)]);
            }
        }
        let mut state0 = vec![0.0; stride * ne];
        for (i, s) in state0.iter_mut().enumerate() {
            let j = i % stride;
            let plastic_strain = j >= STATE_HEAD && (j - STATE_HEAD) % STATE_PER_POINT == 3;
            *s = if plastic_strain {
                0.0
            } else {
                2.5e8 * h(13 * i)
            };
        }
        let opts = KernelOptions {
            projection: true,
            isdo_diagonal: false,
            invariant: false,
            distortion_check: true,
        };
        let dt = 2e-6;
        // Full and partial blocks in turn, elements in reverse lane order.
        let mut blocks = Vec::new();
        let mut start = 0;
        while start < ne {
            let want = if blocks.len() % 2 == 0 {
                LANES
            } else {
                LANES - 1
            };
            let len = want.max(1).min(ne - start);
            blocks.push((start, len));
            start += len;
        }
        let mut state = state0.clone();
        let mut out = vec![ElementOutput::default(); ne];
        let mut faults = vec![None; ne];
        for (start, len) in blocks {
            let mut blk = Block {
                nodes: [[0; 4]; LANES],
                slot: [start + len - 1; LANES],
                active: len,
            };
            for l in 0..len {
                let e = start + len - 1 - l;
                blk.nodes[l] = std::array::from_fn(|c| (4 * e + c) as u32);
                blk.slot[l] = e;
            }
            for l in len..LANES {
                blk.nodes[l] = blk.nodes[0];
            }
            quad_block(
                &blk,
                &x,
                &v,
                &w,
                &props,
                &mut state,
                stride,
                &mut out,
                &mut faults,
                dt,
                opts,
            );
        }
        let mut yielded = 0;
        for e in 0..ne {
            let g = |a: &[[f64; 3]]| -> [[f64; 3]; 4] { std::array::from_fn(|c| a[4 * e + c]) };
            let mut st = state0[e * stride..(e + 1) * stride].to_vec();
            let alone = quad_single(&g(&x), &g(&v), &g(&w), &props, &mut st, dt, opts);
            assert_eq!(faults[e], None);
            assert_eq!(alone.unwrap(), out[e], "element {e}");
            assert_eq!(st, &state[e * stride..(e + 1) * stride], "element {e}");
            for k in 0..5 {
                let off = e * stride + STATE_HEAD + STATE_PER_POINT * k + 3;
                if state[off] > 0.0 {
                    yielded += 1;
                }
            }
        }
        assert!(yielded > 0, "no point yielded");
    }
    /// Rigid-body projection `u - vbar - w x r`, `theta - w` with
    /// `w = G^-1 (sum r x u + sum theta)`, in the global frame (r from the centroid).
    fn project_global(x: &[[f64; 3]; 4], t: &mut [[f64; 3]; 4], m: &mut [[f64; 3]; 4]) {
        let c: [f64; 3] = std::array::from_fn(|k| 0.25 * (x[0][k] + x[1][k] + x[2][k] + x[3][k]));
        let r: [[f64; 3]; 4] = std::array::from_fn(|i| std::array::from_fn(|k| x[i][k] - c[k]));
        let mut g = [[0.0; 3]; 3];
        let mut b = [0.0; 3];
        let mut tbar = [0.0; 3];
        for i in 0..4 {
            let rr: f64 = r[i].iter().map(|a| a * a).sum();
            for a in 0..3 {
                for bb in 0..3 {
                    g[a][bb] -= r[i][a] * r[i][bb];
                }
                g[a][a] += rr + 1.0;
            }
            let cr = [
                r[i][1] * t[i][2] - r[i][2] * t[i][1],
                r[i][2] * t[i][0] - r[i][0] * t[i][2],
                r[i][0] * t[i][1] - r[i][1] * t[i][0],
            ];
            for k in 0..3 {
                b[k] += cr[k] + m[i][k];
                tbar[k] += 0.25 * t[i][k];
            }
        }
        // Solve G w = b by Cramer's rule.
        let det = |a: [[f64; 3]; 3]| {
            a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
                - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
        };
        let d = det(g);
        let w: [f64; 3] = std::array::from_fn(|k| {
            let mut a = g;
            for row in 0..3 {
                a[row][k] = b[row];
            }
            det(a) / d
        });
        for i in 0..4 {
            let wr = [
                w[1] * r[i][2] - w[2] * r[i][1],
                w[2] * r[i][0] - w[0] * r[i][2],
                w[0] * r[i][1] - w[1] * r[i][0],
            ];
            for k in 0..3 {
                t[i][k] -= tbar[k] + wr[k];
                m[i][k] -= w[k];
            }
        }
    }

    /// The projection applied through its effect on the rates and forces equals the
    /// explicit projection of the velocities before, and of the forces after, an
    /// unprojected evaluation (up to rounding), on a strongly warped quad.
    #[test]
    fn the_warping_projection_by_its_effect_equals_the_explicit_projection() {
        let props = props();
        let stride = STATE_HEAD + STATE_PER_POINT * 5;
        for case in 0..20 {
            let h0 = 100 * case;
            let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
            let x: [[f64; 3]; 4] = std::array::from_fn(|c| {
                let i = h0 + 3 * c;
                [
                    0.01 * (corners[c][0] + 0.15 * h(i)),
                    0.01 * (corners[c][1] + 0.15 * h(i + 1)),
                    0.003 * h(i + 2),
                ]
            });
            // A deformation plus a large rigid rotation about an in-plane axis.
            let spin = [30000.0, -20000.0, 5000.0];
            let v: [[f64; 3]; 4] = std::array::from_fn(|c| {
                let p = x[c];
                let rot = [
                    spin[1] * p[2] - spin[2] * p[1],
                    spin[2] * p[0] - spin[0] * p[2],
                    spin[0] * p[1] - spin[1] * p[0],
                ];
                std::array::from_fn(|k| 5.0 * h(h0 + 31 + 3 * c + k) + rot[k])
            });
            let w: [[f64; 3]; 4] = std::array::from_fn(|c| {
                std::array::from_fn(|k| 300.0 * h(h0 + 61 + 3 * c + k) + spin[k])
            });
            let on = KernelOptions {
                projection: true,
                isdo_diagonal: false,
                invariant: false,
                distortion_check: true,
            };
            let off = KernelOptions {
                projection: false,
                ..on
            };
            let dt = 1e-7;
            let mut st_on = vec![0.0; stride];
            let f_on = quad_single(&x, &v, &w, &props, &mut st_on, dt, on).unwrap();
            let (mut vp, mut wp) = (v, w);
            project_global(&x, &mut vp, &mut wp);
            let mut st_off = vec![0.0; stride];
            let f_off = quad_single(&x, &vp, &wp, &props, &mut st_off, dt, off).unwrap();
            let smax = st_on.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            for (a, b) in st_on.iter().zip(&st_off) {
                assert!(
                    (a - b).abs() <= 1e-9 * smax,
                    "case {case}: state {a} vs {b}"
                );
            }
            let mut ft: [[f64; 3]; 4] =
                std::array::from_fn(|i| [f_off.f[i][0], f_off.f[i][1], f_off.f[i][2]]);
            let mut fm: [[f64; 3]; 4] =
                std::array::from_fn(|i| [f_off.f[i][3], f_off.f[i][4], f_off.f[i][5]]);
            project_global(&x, &mut ft, &mut fm);
            let fmax = f_on.f.iter().flatten().fold(0.0f64, |a, b| a.max(b.abs()));
            for i in 0..4 {
                for k in 0..3 {
                    let (a, b) = (f_on.f[i][k], ft[i][k]);
                    assert!(
                        (a - b).abs() <= 1e-9 * fmax,
                        "case {case}: force {a} vs {b}"
                    );
                    let (a, b) = (f_on.f[i][3 + k], fm[i][k]);
                    assert!(
                        (a - b).abs() <= 1e-9 * fmax,
                        "case {case}: moment {a} vs {b}"
                    );
                }
            }
            // The projection matters here: without it, the rotation of the warped quad
            // loads its membrane hourglass modes (state values 2 and 3).
            let mut st_raw = vec![0.0; stride];
            quad_single(&x, &v, &w, &props, &mut st_raw, dt, off).unwrap();
            let hg_on = st_on[2].abs().max(st_on[3].abs());
            let diff = (st_on[2] - st_raw[2])
                .abs()
                .max((st_on[3] - st_raw[3]).abs());
            assert!(
                diff > hg_on,
                "case {case}: projection changes little ({diff} vs {hg_on})"
            );
        }
    }
}
