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

//!
//! Code layout: the arithmetic of steps 4 to 6 is written once, on lane values
//! (`resultants`, on `lanes`' `f64` or the block vector), and used by the quad path on
//! blocks of elements (`quad_lanes`) and by the triangle on one lane (`triangle`).

mod lanes;
mod output;
mod props;
pub(crate) mod quad_lanes;
mod resultants;
mod triangle;

pub use output::{ElementFault, ElementOutput, KernelOptions};
pub use props::{PartProps, STATE_HEAD, STATE_PER_POINT};

use crate::geometry::{cross, dot, norm, sub};

fn normalise(a: [f64; 3]) -> Option<[f64; 3]> {
    let n = norm(a);
    (n > 0.0 && n.is_finite()).then(|| [a[0] / n, a[1] / n, a[2] / n])
}

/// The area of a quad in its frame (step 1 and 2 of the module docs), for build-time
/// checks: degenerate when the frame or the area vanishes, inverted when a corner Jacobian
/// in the element plane is not positive.
fn quad_area(x: &[[f64; 3]; 4]) -> Result<f64, ElementFault> {
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
    let c: [f64; 3] = std::array::from_fn(|k| x.iter().map(|p| p[k] / 4.0).sum());
    let r: [[f64; 2]; 4] = std::array::from_fn(|i| {
        let d = sub(x[i], c);
        [dot(e1, d), dot(e2, d)]
    });
    let (x1, x2, x3, x4) = (r[0][0], r[1][0], r[2][0], r[3][0]);
    let (y1, y2, y3, y4) = (r[0][1], r[1][1], r[2][1], r[3][1]);
    let area = 0.5 * ((x3 - x1) * (y4 - y2) + (x2 - x4) * (y3 - y1));
    if !(area.abs() > 0.0) {
        return Err(ElementFault::Degenerate);
    }
    for i in 0..4 {
        let (p, n, q) = (r[(i + 3) % 4], r[(i + 1) % 4], r[i]);
        let j = (n[0] - q[0]) * (p[1] - q[1]) - (n[1] - q[1]) * (p[0] - q[0]);
        if !(j > 0.0) {
            return Err(ElementFault::Inverted);
        }
    }
    Ok(area)
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
    quad_lanes::quad_single(x, v, omega, props, state, dt, opts)
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
    quad_lanes::quad_run(
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
    triangle::evaluate(x, v, omega, props, state, dt, opts)
}

/// Area of the current geometry of a quad or triangle and whether it is usable, for
/// build-time checks: the area in the element frame (negative when inverted).
pub(crate) fn signed_area(x: &[[f64; 3]], triangle: bool) -> Result<f64, ElementFault> {
    if triangle {
        triangle::tri_local(&[x[0], x[1], x[2]]).map(|l| l.area)
    } else {
        quad_area(&[x[0], x[1], x[2], x[3]])
    }
}
