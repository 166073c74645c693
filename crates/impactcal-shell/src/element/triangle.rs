//! The C0 triangle: its frame (edge frame, or the polar-rotation frame of invariant
//! numbering), centre derivatives and characteristic length; the rates, section response
//! and nodal forces are the shared pieces of [`super::resultants`] on one lane (`f64`).

use super::output::{ElementFault, ElementOutput, KernelOptions};
use super::props::PartProps;
use super::resultants::{StateSlots, rates, section_response, to_global};
use crate::geometry::{cross, dot, norm, sub};

/// Frame (rows `e1, e2, e3`) and centre derivatives of a triangle on its current geometry.
pub(crate) struct TriLocal {
    pub rot: [[f64; 3]; 3],
    pub b1: [f64; 3],
    pub b2: [f64; 3],
    pub area: f64,
}

fn normalise(a: [f64; 3]) -> Option<[f64; 3]> {
    let n = norm(a);
    (n > 0.0 && n.is_finite()).then(|| [a[0] / n, a[1] / n, a[2] / n])
}

/// The edge frame: `e1` along `x2 - x1`, `e3` along `(x2 - x1) x (x3 - x1)`.
pub(crate) fn tri_local(x: &[[f64; 3]; 3]) -> Result<TriLocal, ElementFault> {
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
fn tri_local_invariant(x: &[[f64; 3]; 3], reference: &mut [f64]) -> Result<TriLocal, ElementFault> {
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

/// Local coordinates from the centroid in the frame `rot`, the area
/// `A = ((x2 - x1)(y3 - y1) - (x3 - x1)(y2 - y1)) / 2` and the centre derivatives
/// `B1 = [y23, y31, y12] / 2A`, `B2 = [x32, x13, x21] / 2A`.
fn tri_local_in(x: &[[f64; 3]; 3], rot: [[f64; 3]; 3]) -> Result<TriLocal, ElementFault> {
    let mut c = [0.0; 3];
    for xi in x {
        for k in 0..3 {
            c[k] += xi[k] / 3.0;
        }
    }
    let r: [[f64; 3]; 3] = std::array::from_fn(|i| {
        let d = sub(x[i], c);
        [dot(rot[0], d), dot(rot[1], d), dot(rot[2], d)]
    });
    let (x1, x2, x3) = (r[0][0], r[1][0], r[2][0]);
    let (y1, y2, y3) = (r[0][1], r[1][1], r[2][1]);
    let area = 0.5 * ((x2 - x1) * (y3 - y1) - (x3 - x1) * (y2 - y1));
    if !(area > 0.0) {
        return Err(ElementFault::Degenerate);
    }
    let s = 0.5 / area;
    Ok(TriLocal {
        rot,
        b1: [s * (y2 - y3), s * (y3 - y1), s * (y1 - y2)],
        b2: [s * (x3 - x2), s * (x1 - x3), s * (x2 - x1)],
        area,
    })
}

/// One triangle for one cycle (see [`crate::element::triangle`]).
pub(crate) fn evaluate(
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
    let rot = loc.rot;
    let u: [[f64; 3]; 3] =
        std::array::from_fn(|i| [dot(rot[0], v[i]), dot(rot[1], v[i]), dot(rot[2], v[i])]);
    let th: [[f64; 3]; 3] = std::array::from_fn(|i| {
        [
            dot(rot[0], omega[i]),
            dot(rot[1], omega[i]),
            dot(rot[2], omega[i]),
        ]
    });
    let d = |i: usize, j: usize| norm(sub(x[i], x[j]));
    let side = d(0, 1).max(d(1, 2)).max(d(2, 0));
    let len = 2.0 * loc.area / side;
    let r = rates(&loc.b1, &loc.b2, &u, &th);
    let resp = section_response(
        &loc.b1,
        &loc.b2,
        loc.area,
        &r,
        len,
        props,
        &mut StateSlots {
            state,
            base: &[0],
            active: 1,
        },
        dt,
    );
    let g = to_global(&rot, &resp.f);
    Ok(ElementOutput {
        f: [g[0], g[1], g[2], [0.0; 6]],
        dt: resp.dt,
        internal: resp.internal,
        hourglass: 0.0,
        damping: resp.damping,
    })
}
