//! The pieces both shell elements share, written once on [`Lane`] values: the strain and
//! curvature rates from the centre derivatives, the Cowper-Symonds rate factor, the
//! material update through the thickness, the transverse shear, the stiffness-proportional
//! damping, the bulk viscosity and the nodal forces of the resultants (steps 4 to 6 of
//! [`crate::element`]'s module docs).
//!
//! The quad path evaluates them on blocks of elements ([`super::lanes::V`]), the triangle on
//! one element (`f64`, one lane); the arithmetic is the same expression by expression.

use super::lanes::{L3, Lane};
use super::props::{PartProps, STATE_HEAD, STATE_PER_POINT};

/// The membrane, bending and transverse shear rates of an element (step 4).
#[derive(Clone, Copy)]
pub(crate) struct Rates<L> {
    pub dxx: L,
    pub dyy: L,
    pub gxy: L,
    pub kxx: L,
    pub kyy: L,
    pub kxy: L,
    pub gxz: L,
    pub gyz: L,
}

/// The rates of an `N`-node element from its centre derivatives `b1`, `b2` and the local
/// velocities `u` and angular velocities `th` of its nodes:
/// `d_xx = B1.v_x`, `d_yy = B2.v_y`, `g_xy = B2.v_x + B1.v_y`, `k_xx = B1.th_y`,
/// `k_yy = -B2.th_x`, `k_xy = B2.th_y - B1.th_x`, `g_xz = B1.v_z + mean(th_y)`,
/// `g_yz = B2.v_z - mean(th_x)`.
#[inline(always)]
pub(crate) fn rates<L: Lane, const N: usize>(
    b1: &[L; N],
    b2: &[L; N],
    u: &[L3<L>; N],
    th: &[L3<L>; N],
) -> Rates<L> {
    let z = L::default();
    let (mut dxx, mut dyy, mut gxy) = (z, z, z);
    let (mut kxx, mut kyy, mut kxy) = (z, z, z);
    let (mut gxz, mut gyz) = (z, z);
    let (mut thx, mut thy) = (z, z);
    for i in 0..N {
        let [vx, vy, vz] = u[i];
        let [tx, ty, _] = th[i];
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
    Rates {
        dxx,
        dyy,
        gxy,
        kxx,
        kyy,
        kxy,
        gxz,
        gyz,
    }
}

/// The Cowper-Symonds factor on the yield stress for the effective strain rate
/// `sqrt(4/3 m + t^2/9 b)` of the membrane (`m`) and bending (`b`) rate invariants
/// (1 without rate scaling).
#[inline(always)]
fn rate_factor<L: Lane>(props: &PartProps, r: &Rates<L>) -> L {
    let mat = &props.mat;
    if mat.rate.0 > 0.0 {
        let t = props.t;
        let (dxx, dyy, gxy) = (r.dxx, r.dyy, r.gxy);
        let (kxx, kyy, kxy) = (r.kxx, r.kyy, r.kxy);
        let m = dxx * dxx + dyy * dyy + dxx * dyy + gxy * 0.25 * gxy;
        let b = kxx * kxx + kyy * kyy + kxx * kyy + kxy * 0.25 * kxy;
        let eff = (m * (4.0 / 3.0) + b * (t * t / 9.0)).map(|q| q.max(0.0).sqrt());
        eff.map(|q| mat.rate_factor(q))
    } else {
        L::splat(1.0)
    }
}

/// What the section of an element returns for one cycle.
pub(crate) struct SectionResponse<L, const N: usize> {
    /// Local nodal forces and moments `[fx, fy, fz, mx, my, mz]` (step 6).
    pub f: [[L; 6]; N],
    /// Internal energy increment.
    pub internal: L,
    /// Energy removed by stiffness damping and bulk viscosity.
    pub damping: L,
    /// Stable step with bulk viscosity and stiffness damping.
    pub dt: L,
    /// Rayleigh `beta` of the stiffness damping (`None`: none on this part).
    pub beta: Option<L>,
}

/// Where the elements of a group keep their state: lane `l` at `state[base[l]..]`
/// (`base.len() == L::WIDTH`); only the first `active` lanes are written.
pub(crate) struct StateSlots<'a> {
    pub state: &'a mut [f64],
    pub base: &'a [usize],
    pub active: usize,
}

/// Steps 5 and 6 for a group of elements: the material update at every thickness point
/// for the strain increment `dt (d + z_k k)`, the resultants `N = t sum w_k s_k`,
/// `M = t sum w_k z_k s_k`, the elastic transverse shear `Q += k_s G t dt g` (stored with
/// the point states in `slots`), the stiffness damping `beta C (rates)` and the bulk
/// viscosity of an element of characteristic length `len`, and the local nodal forces of
/// the internal power `A (N:d + M:k + Q.g)`. `area` is the element area, `b1`, `b2` its
/// centre derivatives.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn section_response<L: Lane, const N: usize>(
    b1: &[L; N],
    b2: &[L; N],
    area: L,
    r: &Rates<L>,
    len: L,
    props: &PartProps,
    slots: &mut StateSlots<'_>,
    dt: f64,
) -> SectionResponse<L, N> {
    let mat = &props.mat;
    let t = props.t;
    let Rates {
        dxx,
        dyy,
        gxy,
        kxx,
        kyy,
        kxy,
        gxz,
        gyz,
    } = *r;
    let factor = rate_factor(props, r);
    let mut dt_e = len / mat.wave_speed;
    // Stiffness-proportional damping: Rayleigh beta per lane and the damped stable step.
    let mut step_factor = L::splat(1.0);
    let beta = (props.stiffness_damping != 0.0).then(|| {
        let mut beta = L::default();
        for l in 0..L::WIDTH {
            let (b, s) = props.damping_beta(dt_e.lane(l));
            beta.set_lane(l, b);
            step_factor.set_lane(l, s);
        }
        beta
    });

    // Through the thickness.
    let state = &mut *slots.state;
    let base = slots.base;
    let (c11, c12, g) = (mat.c11, mat.nu * mat.c11, mat.g);
    let plastic = mat.is_plastic();
    let z = L::default();
    let (mut nxx, mut nyy, mut nxy) = (z, z, z);
    let (mut mxx, mut myy, mut mxy) = (z, z, z);
    let mut work = z;
    for (k, (&zk, &wk)) in props.z.iter().zip(&props.w).enumerate() {
        let off = STATE_HEAD + STATE_PER_POINT * k;
        let mut old = [z; STATE_PER_POINT];
        for l in 0..L::WIDTH {
            let st = &state[base[l] + off..base[l] + off + STATE_PER_POINT];
            for q in 0..STATE_PER_POINT {
                old[q].set_lane(l, st[q]);
            }
        }
        let de0 = (dxx + kxx * zk) * dt;
        let de1 = (dyy + kyy * zk) * dt;
        let de2 = (gxy + kxy * zk) * dt;
        // Elastic predictor, as in `MaterialProps::update`.
        let mut sx = old[0] + de0 * c11 + de1 * c12;
        let mut sy = old[1] + de0 * c12 + de1 * c11;
        let mut txy = old[2] + de2 * g;
        let mut p = old[3];
        if plastic {
            let ss = sx + sy;
            let dd = sx - sy;
            let vm2 = ss * 0.25 * ss + (dd * 0.75 * dd + txy * 3.0 * txy);
            let sy0 = (p * mat.hardening + mat.yield0) * factor;
            for l in 0..L::WIDTH {
                let y = sy0.lane(l);
                if vm2.lane(l) > y * y {
                    let mut e = p.lane(l);
                    let trial = [sx.lane(l), sy.lane(l), txy.lane(l)];
                    let sig = mat.plastic_return(trial, &mut e, factor.lane(l));
                    sx.set_lane(l, sig[0]);
                    sy.set_lane(l, sig[1]);
                    txy.set_lane(l, sig[2]);
                    p.set_lane(l, e);
                }
            }
        }
        for l in 0..slots.active {
            let st = &mut state[base[l] + off..base[l] + off + STATE_PER_POINT];
            st[0] = sx.lane(l);
            st[1] = sy.lane(l);
            st[2] = txy.lane(l);
            st[3] = p.lane(l);
        }
        work += ((old[0] + sx) * de0 + (old[1] + sy) * de1 + (old[2] + txy) * de2) * wk;
        let wz = wk * zk;
        nxx += sx * wk;
        nyy += sy * wk;
        nxy += txy * wk;
        mxx += sx * wz;
        myy += sy * wz;
        mxy += txy * wz;
    }
    let mut internal = work * 0.5 * t * area;

    // Transverse shear, elastic, as resultants.
    let (mut qx0, mut qy0) = (z, z);
    for l in 0..L::WIDTH {
        qx0.set_lane(l, state[base[l]]);
        qy0.set_lane(l, state[base[l] + 1]);
    }
    let ks = props.shear_factor * g * t * dt;
    let qx = qx0 + gxz * ks;
    let qy = qy0 + gyz * ks;
    internal += area * 0.5 * dt * ((qx0 + qx) * gxz + (qy0 + qy) * gyz);
    for l in 0..slots.active {
        state[base[l]] = qx.lane(l);
        state[base[l] + 1] = qy.lane(l);
    }

    // Damping resultants beta C (rates), added to the forces, not to the state.
    let mut damping = z;
    let (mut qxf, mut qyf) = (qx, qy);
    if let Some(beta) = beta {
        let [z1, z2] = props.z_moments;
        let sm = [dxx * c11 + dyy * c12, dxx * c12 + dyy * c11, gxy * g];
        let sb = [kxx * c11 + kyy * c12, kxx * c12 + kyy * c11, kxy * g];
        let n_d = [0, 1, 2].map(|k| beta * (sm[k] + sb[k] * z1));
        let m_d = [0, 1, 2].map(|k| beta * (sm[k] * z1 + sb[k] * z2));
        // The two elements have always grouped this product differently; both groupings
        // are kept so that their results stay bit for bit what they were.
        let qs = if L::WIDTH == 1 {
            beta * props.shear_factor * g * t
        } else {
            beta * (props.shear_factor * g * t)
        };
        let (qdx, qdy) = (qs * gxz, qs * gyz);
        let power = (n_d[0] * dxx + n_d[1] * dyy + n_d[2] * gxy) * t
            + (m_d[0] * kxx + m_d[1] * kyy + m_d[2] * kxy) * t
            + qdx * gxz
            + qdy * gyz;
        damping = area * dt * power;
        nxx += n_d[0];
        nyy += n_d[1];
        nxy += n_d[2];
        mxx += m_d[0];
        myy += m_d[1];
        mxy += m_d[2];
        qxf += qdx;
        qyf += qdy;
    }
    // Bulk viscosity: an in-plane pressure while the area shrinks, and its smaller step.
    if props.bulk != [0.0, 0.0] {
        let rate = dxx + dyy;
        for l in 0..L::WIDTH {
            let (q, dt_b) = props.bulk_pressure(rate.lane(l), len.lane(l));
            dt_e.set_lane(l, dt_b);
            damping.set_lane(
                l,
                damping.lane(l) - dt * area.lane(l) * t * q * rate.lane(l),
            );
            nxx.set_lane(l, nxx.lane(l) - q);
            nyy.set_lane(l, nyy.lane(l) - q);
        }
    }
    dt_e = dt_e * step_factor;

    let ta = area * t;
    let (nxx, nyy, nxy) = (ta * nxx, ta * nyy, ta * nxy);
    let (mxx, myy, mxy) = (ta * mxx, ta * myy, ta * mxy);
    let inv_n = 1.0 / N as f64;
    let (qxa, qya) = (area * qxf * inv_n, area * qyf * inv_n);
    // Plain loops rather than `array::from_fn`, whose closure the compiler does not always
    // inline in this hot path.
    let mut f = [[z; 6]; N];
    for i in 0..N {
        f[i] = [
            b1[i] * nxx + b2[i] * nxy,
            b2[i] * nyy + b1[i] * nxy,
            area * (b1[i] * qxf + b2[i] * qyf),
            -b2[i] * myy - b1[i] * mxy - qya,
            b1[i] * mxx + b2[i] * mxy + qxa,
            z,
        ];
    }
    SectionResponse {
        f,
        internal,
        damping,
        dt: dt_e,
        beta,
    }
}

/// Local forces `f` of the frame `e = [e1, e2, e3]` (rows) in the global frame, `N` nodes.
#[inline(always)]
pub(crate) fn to_global<L: Lane, const N: usize>(e: &[L3<L>; 3], f: &[[L; 6]; N]) -> [[L; 6]; N] {
    let [e1, e2, e3] = e;
    let mut g = [[L::default(); 6]; N];
    for i in 0..N {
        for k in 0..3 {
            g[i][k] = e1[k] * f[i][0] + e2[k] * f[i][1] + e3[k] * f[i][2];
            g[i][3 + k] = e1[k] * f[i][3] + e2[k] * f[i][4] + e3[k] * f[i][5];
        }
    }
    g
}
