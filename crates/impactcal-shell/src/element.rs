//! The shell element kernels: the Belytschko-Lin-Tsay quad and the C0 triangle.
//!
//! Both are one-point (in the plane) velocity-strain elements in a corotational frame, with
//! `nip` points through the thickness. Per cycle and element:
//!
//! 1. Frame. Quad: `e3 = (x3 - x1) x (x4 - x2) / |.|`, `e1` along
//!    `(x2 - x1) + (x3 - x4)` projected on the plane normal to `e3`, `e2 = e3 x e1`.
//!    Triangle: `e1` along `x2 - x1`, `e3` along `(x2 - x1) x (x3 - x1)`.
//!    Local coordinates `(x^, y^, z^)` of the nodes are taken from the centroid of the nodes;
//!    `z^` measures the warp of a quad.
//! 2. Geometry. Quad area `A = (x31 y42 + x24 y31) / 2` and centre derivatives
//!    `B1 = [y24, y31, y42, y13] / 2A`, `B2 = [x42, x13, x24, x31] / 2A` (`xIJ = x^I - x^J`);
//!    triangle `B1 = [y23, y31, y12] / 2A`, `B2 = [x32, x13, x21] / 2A`.
//! 3. Local velocities `v^ = R v`, `theta^ = R omega`. For quads the six rigid-body modes
//!    (three translations, three rotations about the centroid) are projected out of the
//!    24 local velocities (warping projection), so that a rigid motion of a warped element
//!    gives exactly no strain; the same projector is applied to the nodal forces, which are
//!    therefore self-equilibrated.
//! 4. Rates (kinematics `v = v_mid - zeta e3 x theta`): membrane
//!    `d_xx = B1.v_x`, `d_yy = B2.v_y`, `g_xy = B2.v_x + B1.v_y`; curvature
//!    `k_xx = B1.th_y`, `k_yy = -B2.th_x`, `k_xy = B2.th_y - B1.th_x`; transverse shear
//!    `g_xz = B1.v_z + mean(th_y)`, `g_yz = B2.v_z - mean(th_x)`.
//! 5. At each thickness point `z_k`: `de = dt (d + z_k k)`, plane-stress material update,
//!    resultants `N = t sum w_k s_k`, `M = t sum w_k z_k s_k`; transverse shear resultants
//!    updated elastically, `Q += k_s G t dt g`.
//! 6. Nodal forces from the internal power `A (N:d + M:k + Q.g)`:
//!    `f_xI = A (B1_I N_xx + B2_I N_xy)`, `f_yI = A (B2_I N_yy + B1_I N_xy)`,
//!    `f_zI = A (B1_I Q_x + B2_I Q_y)`, `m_xI = A (-B2_I M_yy - B1_I M_xy - Q_y / n)`,
//!    `m_yI = A (B1_I M_xx + B2_I M_xy + Q_x / n)` with `n` the node count.
//! 7. Quad hourglass control with the Flanagan-Belytschko vector
//!    `gamma_I = h_I - (h.x^) B1_I - (h.y^) B2_I`, `h = (1, -1, 1, -1)`, on the membrane,
//!    out-of-plane and two rotational modes (see [`crate::model::Hourglass`]).
//! 8. Forces rotated back to the global frame; the element time step is `L / c_p` with
//!    `L = A / max(longest side, longest diagonal)` (quads, ISDO 0),
//!    `A / longest diagonal` (ISDO 1) or `2A / longest side` (triangles), and
//!    `c_p = sqrt(E / (rho (1 - nu^2)))`.
//!
//! The returned forces are internal forces: the nodal equation is `m a = f_ext - f_int`.

use crate::geometry::{cross, dot, norm, sub, thickness_rule};
use crate::material::MaterialProps;
use crate::model::{Hourglass, HourglassForm, Material, Section, ThicknessRule};

/// Number of state values ahead of the thickness points: transverse shear resultants
/// `Q_x, Q_y`, then the five hourglass generalised forces (membrane x, y, out-of-plane w,
/// rotation x, y).
pub const STATE_HEAD: usize = 7;
/// State values per thickness point: `s_xx, s_yy, s_xy`, equivalent plastic strain.
pub const STATE_PER_POINT: usize = 4;

/// Section and material constants of a part, prepared for the element loop.
#[derive(Debug, Clone, PartialEq)]
pub struct PartProps {
    /// Thickness.
    pub t: f64,
    /// Heights of the thickness points (physical, from the mid-surface).
    pub z: Vec<f64>,
    /// Weights of the thickness points, summing to 1.
    pub w: Vec<f64>,
    /// Transverse shear factor.
    pub shear_factor: f64,
    /// Material constants.
    pub mat: MaterialProps,
    /// Hourglass form.
    pub hg_form: HourglassForm,
    /// Hourglass coefficients (membrane, out-of-plane, rotation).
    pub hg: [f64; 3],
    /// Stiffness-proportional damping coefficient in the sign convention of
    /// [`crate::model::PartStiffnessDamping::coef`] (0: none).
    pub stiffness_damping: f64,
    /// Moments of the thickness rule `[sum w_k z_k, sum w_k z_k^2]` (physical heights), which
    /// turn strain rates into the resultants of the stiffness damping.
    pub z_moments: [f64; 2],
    /// Shell bulk viscosity coefficients `[Q1, Q2]` (`[0, 0]`: none), see
    /// [`crate::model::BulkViscosity`].
    pub bulk: [f64; 2],
}

impl PartProps {
    /// Prepares the constants of a part from its section, material and the hourglass
    /// control (the values are assumed validated, as [`crate::Simulation::new`] does:
    /// positive thickness, 1 to 10 points, Lobatto with at least 2).
    pub fn new(section: &Section, material: &Material, hourglass: &Hourglass) -> Self {
        let (zeta, w) = thickness_rule(section.nip, section.rule == ThicknessRule::Lobatto);
        let z: Vec<f64> = zeta.iter().map(|z| 0.5 * z * section.thickness).collect();
        let z_moments = [
            z.iter().zip(&w).map(|(z, w)| w * z).sum(),
            z.iter().zip(&w).map(|(z, w)| w * z * z).sum(),
        ];
        PartProps {
            t: section.thickness,
            z,
            w,
            shear_factor: section.shear_factor,
            mat: MaterialProps::new(material),
            hg_form: hourglass.form,
            hg: [hourglass.membrane, hourglass.transverse, hourglass.rotation],
            stiffness_damping: 0.0,
            z_moments,
            bulk: [0.0, 0.0],
        }
    }

    /// The same part with stiffness-proportional damping `coef` (see
    /// [`crate::model::PartStiffnessDamping`]).
    #[must_use]
    pub fn with_stiffness_damping(mut self, coef: f64) -> Self {
        self.stiffness_damping = coef;
        self
    }

    /// The Rayleigh coefficient `beta` of an element whose undamped stable step is `dt_e`,
    /// and the factor `sqrt(1 + zeta^2) - zeta` on its stable step, `zeta = beta / dt_e`
    /// (the fraction of critical damping at the element's highest frequency `2 / dt_e`).
    #[inline]
    pub fn damping_beta(&self, dt_e: f64) -> (f64, f64) {
        let c = self.stiffness_damping;
        let beta = if c > 0.0 { c * dt_e } else { -c };
        let zeta = beta / dt_e;
        (beta, (1.0 + zeta * zeta).sqrt() - zeta)
    }

    /// Shell bulk viscosity for the areal strain rate `rate` (`d_xx + d_yy`) of an element
    /// of characteristic length `len`: the in-plane pressure
    /// `q = rho len (Q1^2 len rate^2 - Q2 c rate)` while the area shrinks (`rate < 0`, else
    /// 0) and the stable step `len / (Q + sqrt(Q^2 + c^2))`, `Q = Q1^2 len |rate| + Q2 c`.
    #[inline]
    pub fn bulk_pressure(&self, rate: f64, len: f64) -> (f64, f64) {
        let c = self.mat.wave_speed;
        if !(rate < 0.0) || self.bulk == [0.0, 0.0] {
            return (0.0, len / c);
        }
        let [q1, q2] = self.bulk;
        let a = q1 * q1 * len * rate.abs();
        let q = self.mat.rho * len * (a * rate.abs() + q2 * c * rate.abs());
        let big_q = a + q2 * c;
        (q, len / (big_q + (big_q * big_q + c * c).sqrt()))
    }
}

/// What one element returns for one cycle.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ElementOutput {
    /// Internal nodal forces and moments `[fx, fy, fz, mx, my, mz]` in the global frame, one
    /// row per node (row 3 unused for triangles).
    pub f: [[f64; 6]; 4],
    /// Stable time step of the element (before the safety factor).
    pub dt: f64,
    /// Internal (strain) energy increment of the cycle.
    pub internal: f64,
    /// Hourglass energy increment of the cycle.
    pub hourglass: f64,
    /// Energy removed by stiffness-proportional damping in the cycle.
    pub damping: f64,
}

/// Why an element could not be evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ElementFault {
    /// Zero area or coincident nodes.
    Degenerate,
    /// Negative area in the element frame (the element turned inside out).
    Inverted,
}

impl std::fmt::Display for ElementFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ElementFault::Degenerate => f.write_str("degenerate element (zero area)"),
            ElementFault::Inverted => f.write_str("inverted element (negative area)"),
        }
    }
}

/// Options of the element kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KernelOptions {
    /// Apply the rigid-body (warping) projection to quads.
    pub projection: bool,
    /// ISDO 1: characteristic length = area / longest diagonal.
    pub isdo_diagonal: bool,
    /// Invariant node numbering (LS-DYNA INN 2): the quad frame's first axis bisects the
    /// diagonals instead of following the edges 1-2 and 4-3.
    pub invariant: bool,
}

/// Frame and centre derivatives of an element on its current geometry.
struct Local<const N: usize> {
    rot: [[f64; 3]; 3],
    b1: [f64; N],
    b2: [f64; N],
    area: f64,
}

fn normalise(a: [f64; 3]) -> Option<[f64; 3]> {
    let n = norm(a);
    (n > 0.0 && n.is_finite()).then(|| [a[0] / n, a[1] / n, a[2] / n])
}

fn local_coords<const N: usize>(x: &[[f64; 3]; N], rot: &[[f64; 3]; 3]) -> [[f64; 3]; N] {
    let mut c = [0.0; 3];
    for xi in x {
        for k in 0..3 {
            c[k] += xi[k] / N as f64;
        }
    }
    let mut r = [[0.0; 3]; N];
    for i in 0..N {
        let d = sub(x[i], c);
        r[i] = [dot(rot[0], d), dot(rot[1], d), dot(rot[2], d)];
    }
    r
}

fn quad_local(x: &[[f64; 3]; 4]) -> Result<Local<4>, ElementFault> {
    let e3 = normalise(cross(sub(x[2], x[0]), sub(x[3], x[1]))).ok_or(ElementFault::Degenerate)?;
    let mut a = [0.0; 3];
    for k in 0..3 {
        a[k] = x[1][k] - x[0][k] + x[2][k] - x[3][k];
    }
    let an = dot(a, e3);
    for k in 0..3 {
        a[k] -= an * e3[k];
    }
    let e1 = normalise(a).ok_or(ElementFault::Degenerate)?;
    let e2 = cross(e3, e1);
    let rot = [e1, e2, e3];
    let r = local_coords(x, &rot);
    let (x1, x2, x3, x4) = (r[0][0], r[1][0], r[2][0], r[3][0]);
    let (y1, y2, y3, y4) = (r[0][1], r[1][1], r[2][1], r[3][1]);
    let area = 0.5 * ((x3 - x1) * (y4 - y2) + (x2 - x4) * (y3 - y1));
    if !(area.abs() > 0.0) {
        return Err(ElementFault::Degenerate);
    }
    // Corner Jacobians in the element plane: all positive for a convex, non-inverted quad.
    for i in 0..4 {
        let (p, n) = (r[(i + 3) % 4], r[(i + 1) % 4]);
        let c = r[i];
        let j = (n[0] - c[0]) * (p[1] - c[1]) - (n[1] - c[1]) * (p[0] - c[0]);
        if !(j > 0.0) {
            return Err(ElementFault::Inverted);
        }
    }
    let s = 0.5 / area;
    Ok(Local {
        rot,
        b1: [s * (y2 - y4), s * (y3 - y1), s * (y4 - y2), s * (y1 - y3)],
        b2: [s * (x4 - x2), s * (x1 - x3), s * (x2 - x4), s * (x3 - x1)],
        area,
    })
}

fn tri_local(x: &[[f64; 3]; 3]) -> Result<Local<3>, ElementFault> {
    let d21 = sub(x[1], x[0]);
    let e3 = normalise(cross(d21, sub(x[2], x[0]))).ok_or(ElementFault::Degenerate)?;
    let e1 = normalise(d21).ok_or(ElementFault::Degenerate)?;
    let e2 = cross(e3, e1);
    tri_local_in(x, [e1, e2, e3])
}

/// The triangle's frame turned in its plane by the rotation of the polar decomposition of
/// its in-plane deformation gradient since the reference configuration, so that the frame
/// follows the mean rotation of the material rather than the edge 1-2. The reference
/// configuration (node 1 at the origin, edge 1-2 along x: `[x2, x3, y3]`) is kept in
/// `reference`; all zero means "not yet recorded": the current configuration is recorded
/// and the frame is the edge frame.
fn tri_local_invariant(x: &[[f64; 3]; 3], reference: &mut [f64]) -> Result<Local<3>, ElementFault> {
    let edge = tri_local(x)?;
    let [e1, e2, e3] = edge.rot;
    let d2 = sub(x[1], x[0]);
    let d3 = sub(x[2], x[0]);
    let (a, b, c) = (dot(d2, e1), dot(d3, e1), dot(d3, e2));
    if reference[0] == 0.0 {
        reference[0] = a;
        reference[1] = b;
        reference[2] = c;
        return Ok(edge);
    }
    let (x2, x3, y3) = (reference[0], reference[1], reference[2]);
    // F = [[a, b], [0, c]] [[x2, x3], [0, y3]]^-1; polar angle atan2(F21 - F12, F11 + F22).
    let f11 = a / x2;
    let f12 = b / y3 - a * x3 / (x2 * y3);
    let f22 = c / y3;
    let psi = (-f12).atan2(f11 + f22);
    let (s, co) = psi.sin_cos();
    let r1 = [
        co * e1[0] + s * e2[0],
        co * e1[1] + s * e2[1],
        co * e1[2] + s * e2[2],
    ];
    tri_local_in(x, [r1, cross(e3, r1), e3])
}

fn tri_local_in(x: &[[f64; 3]; 3], rot: [[f64; 3]; 3]) -> Result<Local<3>, ElementFault> {
    let r = local_coords(x, &rot);
    let (x1, x2, x3) = (r[0][0], r[1][0], r[2][0]);
    let (y1, y2, y3) = (r[0][1], r[1][1], r[2][1]);
    let area = 0.5 * ((x2 - x1) * (y3 - y1) - (x3 - x1) * (y2 - y1));
    if !(area > 0.0) {
        return Err(ElementFault::Degenerate);
    }
    let s = 0.5 / area;
    Ok(Local {
        rot,
        b1: [s * (y2 - y3), s * (y3 - y1), s * (y1 - y2)],
        b2: [s * (x3 - x2), s * (x1 - x3), s * (x2 - x1)],
        area,
    })
}

/// Evaluates one quad for one cycle: updates its `state` (length
/// `STATE_HEAD + STATE_PER_POINT * nip`) for the strain increment of `dt` and returns its
/// internal forces, time step and energy increments.
///
/// `x` are the current (end-of-step) coordinates, `v` and `omega` the mid-step velocities
/// and angular velocities of the four nodes.
///
/// # Errors
/// [`ElementFault`] when the current geometry is degenerate or inverted.
pub fn quad(
    x: &[[f64; 3]; 4],
    v: &[[f64; 3]; 4],
    omega: &[[f64; 3]; 4],
    props: &PartProps,
    state: &mut [f64],
    dt: f64,
    opts: KernelOptions,
) -> Result<ElementOutput, ElementFault> {
    crate::kernel::quad_single(x, v, omega, props, state, dt, opts)
}

/// Evaluates many quads of one part for one cycle, as [`quad`] does one by one, with the
/// blocked kernel of the solver (several elements per instruction): element `e` has the
/// node indices `elems[e]` into the nodal arrays `x`, `v` (mid-step velocities) and
/// `omega` (mid-step angular velocities), its state at `state[e * stride..][..stride]`
/// (`stride >= STATE_HEAD + STATE_PER_POINT * nip`) and its output in `out[e]`.
///
/// # Errors
/// The index and the fault of the first degenerate or inverted element; the outputs and
/// states of the others are written all the same.
///
/// # Panics
/// When a node index is out of range of the nodal arrays, or `state` / `out` hold fewer
/// than `elems.len()` elements.
#[allow(clippy::too_many_arguments)]
pub fn quad_batch(
    elems: &[[u32; 4]],
    x: &[[f64; 3]],
    v: &[[f64; 3]],
    omega: &[[f64; 3]],
    props: &PartProps,
    state: &mut [f64],
    stride: usize,
    out: &mut [ElementOutput],
    dt: f64,
    opts: KernelOptions,
) -> Result<(), (usize, ElementFault)> {
    let mut faults = vec![None; elems.len()];
    crate::kernel::quad_run(
        elems,
        x,
        v,
        omega,
        props,
        state,
        stride,
        out,
        &mut faults,
        dt,
        opts,
    );
    match faults.iter().position(Option::is_some) {
        Some(e) => Err((e, faults[e].unwrap_or(ElementFault::Degenerate))),
        None => Ok(()),
    }
}

/// Evaluates one C0 triangle for one cycle (as [`quad`], without hourglass control or
/// projection; row 3 of the forces is zero). With `opts.invariant` the frame follows the
/// polar rotation of the element since its first evaluation (recorded in the state's
/// unused hourglass slots), so the result does not depend on the node numbering.
///
/// # Errors
/// [`ElementFault::Degenerate`] when the current geometry has no area or is inverted.
pub fn triangle(
    x: &[[f64; 3]; 3],
    v: &[[f64; 3]; 3],
    omega: &[[f64; 3]; 3],
    props: &PartProps,
    state: &mut [f64],
    dt: f64,
    opts: KernelOptions,
) -> Result<ElementOutput, ElementFault> {
    let loc = if opts.invariant {
        tri_local_invariant(x, &mut state[2..5])?
    } else {
        tri_local(x)?
    };
    let mut u = [[0.0; 6]; 3];
    for i in 0..3 {
        for k in 0..3 {
            u[i][k] = dot(loc.rot[k], v[i]);
            u[i][3 + k] = dot(loc.rot[k], omega[i]);
        }
    }
    let d = |i: usize, j: usize| norm(sub(x[i], x[j]));
    let side = d(0, 1).max(d(1, 2)).max(d(2, 0));
    let len = 2.0 * loc.area / side;
    let dt_e = len / props.mat.wave_speed;
    let (beta, factor) = if props.stiffness_damping == 0.0 {
        (0.0, 1.0)
    } else {
        props.damping_beta(dt_e)
    };
    let (f, internal, damping, dt_bulk) = resultant_forces(&loc, &u, props, state, dt, beta, len);
    let dt_out = dt_bulk * factor;
    let g = to_global(&loc.rot, &f);
    Ok(ElementOutput {
        f: [g[0], g[1], g[2], [0.0; 6]],
        dt: dt_out,
        internal,
        hourglass: 0.0,
        damping,
    })
}

fn to_global<const N: usize>(rot: &[[f64; 3]; 3], f: &[[f64; 6]; N]) -> [[f64; 6]; 4] {
    let mut g = [[0.0; 6]; 4];
    for i in 0..N {
        for k in 0..3 {
            g[i][k] = rot[0][k] * f[i][0] + rot[1][k] * f[i][1] + rot[2][k] * f[i][2];
            g[i][3 + k] = rot[0][k] * f[i][3] + rot[1][k] * f[i][4] + rot[2][k] * f[i][5];
        }
    }
    g
}

/// Strain rates, material update through the thickness, resultants and local nodal forces,
/// with stiffness-proportional damping `beta` (0: none) and the bulk viscosity of an element
/// of characteristic length `len`. Returns the local forces, the internal energy increment,
/// the damping energy increment (stiffness damping and bulk viscosity) and the stable step
/// with the bulk viscosity (`len / c` without it).
fn resultant_forces<const N: usize>(
    loc: &Local<N>,
    u: &[[f64; 6]; N],
    props: &PartProps,
    state: &mut [f64],
    dt: f64,
    beta: f64,
    len: f64,
) -> ([[f64; 6]; N], f64, f64, f64) {
    let (b1, b2) = (&loc.b1, &loc.b2);
    let (mut dxx, mut dyy, mut gxy) = (0.0, 0.0, 0.0);
    let (mut kxx, mut kyy, mut kxy) = (0.0, 0.0, 0.0);
    let (mut gxz, mut gyz) = (0.0, 0.0);
    let (mut thx, mut thy) = (0.0, 0.0);
    for i in 0..N {
        let [vx, vy, vz, tx, ty, _] = u[i];
        dxx += b1[i] * vx;
        dyy += b2[i] * vy;
        gxy += b2[i] * vx + b1[i] * vy;
        kxx += b1[i] * ty;
        kyy -= b2[i] * tx;
        kxy += b2[i] * ty - b1[i] * tx;
        gxz += b1[i] * vz;
        gyz += b2[i] * vz;
        thx += tx;
        thy += ty;
    }
    let inv_n = 1.0 / N as f64;
    gxz += thy * inv_n;
    gyz -= thx * inv_n;

    let mat = &props.mat;
    let t = props.t;
    let factor = if mat.rate.0 > 0.0 {
        let m = dxx * dxx + dyy * dyy + dxx * dyy + 0.25 * gxy * gxy;
        let b = kxx * kxx + kyy * kyy + kxx * kyy + 0.25 * kxy * kxy;
        mat.rate_factor((4.0 / 3.0 * m + t * t / 9.0 * b).max(0.0).sqrt())
    } else {
        1.0
    };

    let (mut nxx, mut nyy, mut nxy) = (0.0, 0.0, 0.0);
    let (mut mxx, mut myy, mut mxy) = (0.0, 0.0, 0.0);
    let mut work = 0.0;
    let (head, points) = state.split_at_mut(STATE_HEAD);
    for ((zk, wk), s) in props
        .z
        .iter()
        .zip(&props.w)
        .zip(points.chunks_exact_mut(STATE_PER_POINT))
    {
        let de = [
            dt * (dxx + zk * kxx),
            dt * (dyy + zk * kyy),
            dt * (gxy + zk * kxy),
        ];
        let old = [s[0], s[1], s[2]];
        let mut sig = old;
        let mut p = s[3];
        mat.update(&mut sig, &mut p, de, factor);
        s[0] = sig[0];
        s[1] = sig[1];
        s[2] = sig[2];
        s[3] = p;
        work += wk
            * ((old[0] + sig[0]) * de[0] + (old[1] + sig[1]) * de[1] + (old[2] + sig[2]) * de[2]);
        nxx += wk * sig[0];
        nyy += wk * sig[1];
        nxy += wk * sig[2];
        mxx += wk * zk * sig[0];
        myy += wk * zk * sig[1];
        mxy += wk * zk * sig[2];
    }
    let a = loc.area;
    let mut internal = 0.5 * work * t * a;
    // Transverse shear, elastic, as resultants.
    let ks = props.shear_factor * mat.g * t * dt;
    let (qx0, qy0) = (head[0], head[1]);
    let qx = qx0 + ks * gxz;
    let qy = qy0 + ks * gyz;
    head[0] = qx;
    head[1] = qy;
    internal += 0.5 * a * dt * ((qx0 + qx) * gxz + (qy0 + qy) * gyz);

    // Stiffness-proportional damping: beta times the elastic resultants of the rates.
    let mut damping = 0.0;
    let (mut qx, mut qy) = (qx, qy);
    if beta > 0.0 {
        let c12 = mat.nu * mat.c11;
        let [z1, z2] = props.z_moments;
        let sm = [
            mat.c11 * dxx + c12 * dyy,
            c12 * dxx + mat.c11 * dyy,
            mat.g * gxy,
        ];
        let sb = [
            mat.c11 * kxx + c12 * kyy,
            c12 * kxx + mat.c11 * kyy,
            mat.g * kxy,
        ];
        let n_d = [0, 1, 2].map(|k| beta * (sm[k] + z1 * sb[k]));
        let m_d = [0, 1, 2].map(|k| beta * (z1 * sm[k] + z2 * sb[k]));
        let qs = beta * props.shear_factor * mat.g * t;
        let (qdx, qdy) = (qs * gxz, qs * gyz);
        let power = t * (n_d[0] * dxx + n_d[1] * dyy + n_d[2] * gxy)
            + t * (m_d[0] * kxx + m_d[1] * kyy + m_d[2] * kxy)
            + qdx * gxz
            + qdy * gyz;
        damping = dt * a * power;
        nxx += n_d[0];
        nyy += n_d[1];
        nxy += n_d[2];
        mxx += m_d[0];
        myy += m_d[1];
        mxy += m_d[2];
        qx += qdx;
        qy += qdy;
    }
    let (qb, dt_bulk) = props.bulk_pressure(dxx + dyy, len);
    if qb > 0.0 {
        damping -= dt * a * t * qb * (dxx + dyy);
        nxx -= qb;
        nyy -= qb;
    }

    let (nxx, nyy, nxy) = (t * a * nxx, t * a * nyy, t * a * nxy);
    let (mxx, myy, mxy) = (t * a * mxx, t * a * myy, t * a * mxy);
    let (qxa, qya) = (a * qx * inv_n, a * qy * inv_n);
    let mut f = [[0.0; 6]; N];
    for i in 0..N {
        f[i] = [
            b1[i] * nxx + b2[i] * nxy,
            b2[i] * nyy + b1[i] * nxy,
            a * (b1[i] * qx + b2[i] * qy),
            -b2[i] * myy - b1[i] * mxy - qya,
            b1[i] * mxx + b2[i] * mxy + qxa,
            0.0,
        ];
    }
    (f, internal, damping, dt_bulk)
}

/// Area of the current geometry of a quad or triangle and whether it is usable, for
/// build-time checks: the area in the element frame (negative when inverted).
pub(crate) fn signed_area(x: &[[f64; 3]], triangle: bool) -> Result<f64, ElementFault> {
    if triangle {
        tri_local(&[x[0], x[1], x[2]]).map(|l| l.area)
    } else {
        quad_local(&[x[0], x[1], x[2], x[3]]).map(|l| l.area)
    }
}
