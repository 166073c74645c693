//! The integrator of a driven lumped system: exact for its linear part, symplectic for its
//! contacts and cubic springs.
//!
//! **Equations.** With `z` the displacements of the masses relative to the base (the base
//! at `z = 0`), `a_b(t)` the base acceleration, `M` the diagonal mass matrix, `K` and `C`
//! the stiffness and damping matrices assembled from the springs and dashpots (an element
//! to the base adds to the diagonal only), and `f(z)` the forces of the gap contacts and
//! of the springs' cubic terms,
//!
//! `M z'' + C z' + K z = -M 1 a_b(t) + f(z)`,
//!
//! and the absolute acceleration of mass `i` is `z_i'' + a_b = (f(z) - K z - C z')_i / m_i`.
//!
//! **Linear part: exact.** The state `y = [z; z']` obeys `y' = A y + b a_b(t) + ...` with
//! `A = [[0, I], [-M^-1 K, -M^-1 C]]` and `b = [0; -1]`. Over a step `h` in which the base
//! acceleration is linear, `a_b(t_0 + s) = u_0 + u' s` (the measured samples joined by
//! straight lines), `y(t_0 + h) = Phi y(t_0) + g_0 u_0 + g_1 u'` with `Phi = e^{A h}`,
//! `g_0 = int_0^h e^{A (h - s)} b ds` and `g_1 = int_0^h e^{A (h - s)} b s ds`, all three read
//! from the exponential of the augmented matrix `[[A, b, 0], [0, 0, 1], [0, 0, 0]] h`
//! (Van Loan 1978, IEEE Trans. Autom. Control 23, 395-404), computed by scaling and
//! squaring a Taylor series summed to round-off. So the linear response to the
//! piecewise-linear input is exact to round-off at every step size; what remains is the
//! difference between the true input and its straight-line interpolation.
//!
//! **Nonlinear part: symplectic.** The contact and cubic forces depend on positions only;
//! each step is split (Strang) into a half kick `z' += h/2 M^-1 f(z)`, the exact linear
//! flow over `h`, and another half kick. Each piece preserves phase-space volume, so with no
//! damping and no input the energy
//! `E = 1/2 z'^T M z' + sum_springs (k d^2 / 2 + k beta d^4 / 4) + sum_gaps k p^2 / 2`
//! stays within a bounded band and does not drift. A sample interval is cut into `s` equal
//! sub-steps so that the fastest contact or cubic stiffness `k_n` on a mass `m` is resolved:
//! `sqrt(k_n / m) h / s <= 0.2` (about 30 sub-steps per contact period; the splitting is
//! stable below 2).

use crate::error::{ModelsError, Result};
use crate::lumped::system::{GapSides, Node};

/// A linear spring with a cubic term: force `k (d + beta d^3)` on the stretch `d = u_b - u_a`,
/// pulling the ends together, and a dashpot `c` beside it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpringLink {
    /// Ends.
    pub ends: [Node; 2],
    /// Stiffness `k` (N/m).
    pub k: f64,
    /// Cubic coefficient `beta` (1/m^2); 0 for a linear spring.
    pub beta: f64,
    /// Dashpot coefficient `c` (N s/m) beside it.
    pub c: f64,
}

/// A penalty gap contact: force `k p` with `p` the penetration past `gap`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GapLink {
    /// Ends.
    pub ends: [Node; 2],
    /// Clearance (m).
    pub gap: f64,
    /// Penalty stiffness (N/m).
    pub k: f64,
    /// Which way it acts.
    pub sides: GapSides,
}

/// A lumped system at one set of values: what the integrator runs.
#[derive(Debug, Clone, PartialEq)]
pub struct Dynamics {
    /// Masses (kg).
    pub masses: Vec<f64>,
    /// Springs (with their dashpots).
    pub springs: Vec<SpringLink>,
    /// Dashpots alone: ends and coefficient (N s/m).
    pub dashpots: Vec<([Node; 2], f64)>,
    /// Gap contacts.
    pub gaps: Vec<GapLink>,
}

/// The states and outputs of a run, at the input's samples.
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    /// `z[i][k]`: displacement of mass `i` relative to the base at sample `k` (m).
    pub z: Vec<Vec<f64>>,
    /// `v[i][k]`: its velocity relative to the base (m/s).
    pub v: Vec<Vec<f64>>,
    /// `accel[i][k]`: its absolute acceleration (m/s^2).
    pub accel: Vec<Vec<f64>>,
    /// Sub-steps per sample interval.
    pub substeps: usize,
}

fn disp(z: &[f64], node: Node) -> f64 {
    match node {
        Node::Base => 0.0,
        Node::Mass(i) => z[i],
    }
}

/// Adds `w` times the element matrix of a link between `a` and `b` to the `n x n` matrix.
fn stamp(m: &mut [f64], n: usize, [a, b]: [Node; 2], w: f64) {
    if let Node::Mass(i) = a {
        m[i * n + i] += w;
    }
    if let Node::Mass(j) = b {
        m[j * n + j] += w;
    }
    if let (Node::Mass(i), Node::Mass(j)) = (a, b) {
        m[i * n + j] -= w;
        m[j * n + i] -= w;
    }
}

impl Dynamics {
    /// The number of masses.
    pub fn len(&self) -> usize {
        self.masses.len()
    }

    /// Whether there is no mass.
    pub fn is_empty(&self) -> bool {
        self.masses.is_empty()
    }

    /// The stiffness and damping matrices `K`, `C` (row-major, `n x n`).
    pub fn matrices(&self) -> (Vec<f64>, Vec<f64>) {
        let n = self.len();
        let (mut k, mut c) = (vec![0.0; n * n], vec![0.0; n * n]);
        for s in &self.springs {
            stamp(&mut k, n, s.ends, s.k);
            stamp(&mut c, n, s.ends, s.c);
        }
        for (ends, coef) in &self.dashpots {
            stamp(&mut c, n, *ends, *coef);
        }
        (k, c)
    }

    /// Adds the nonlinear forces `f(z)` (gap contacts, cubic terms) to `f`.
    fn nonlinear(&self, z: &[f64], f: &mut [f64]) {
        let mut push = |[a, b]: [Node; 2], force_on_b: f64| {
            if let Node::Mass(j) = b {
                f[j] += force_on_b;
            }
            if let Node::Mass(i) = a {
                f[i] -= force_on_b;
            }
        };
        for s in &self.springs {
            if s.beta != 0.0 {
                let d = disp(z, s.ends[1]) - disp(z, s.ends[0]);
                push(s.ends, -s.k * s.beta * d * d * d);
            }
        }
        for g in &self.gaps {
            let d = disp(z, g.ends[1]) - disp(z, g.ends[0]);
            let (p, sign) = g.sides.penetration(d, g.gap);
            if p > 0.0 {
                push(g.ends, sign * g.k * p);
            }
        }
    }

    /// Whether the system has nonlinear forces.
    fn is_nonlinear(&self) -> bool {
        !self.gaps.is_empty() || self.springs.iter().any(|s| s.beta != 0.0)
    }

    /// The energy `E` of the relative motion (see the module docs) at `z`, `v` (J).
    pub fn energy(&self, z: &[f64], v: &[f64]) -> f64 {
        let mut e: f64 = self
            .masses
            .iter()
            .zip(v)
            .map(|(m, v)| 0.5 * m * v * v)
            .sum();
        for s in &self.springs {
            let d = disp(z, s.ends[1]) - disp(z, s.ends[0]);
            e += 0.5 * s.k * d * d + 0.25 * s.k * s.beta * d.powi(4);
        }
        for g in &self.gaps {
            let d = disp(z, g.ends[1]) - disp(z, g.ends[0]);
            let (p, _) = g.sides.penetration(d, g.gap);
            if p > 0.0 {
                e += 0.5 * g.k * p * p;
            }
        }
        e
    }

    /// Sub-steps per interval `dt`: `ceil(w_n dt / 0.2)`, `w_n^2` the largest sum over a
    /// mass of its contact penalties and its springs' cubic tangents at `reach` (m, the
    /// largest stretch expected) divided by the mass.
    fn substeps(&self, dt: f64, reach: f64) -> usize {
        let n = self.len();
        let mut stiff = vec![0.0; n];
        let mut add = |[a, b]: [Node; 2], k: f64| {
            for node in [a, b] {
                if let Node::Mass(i) = node {
                    stiff[i] += k;
                }
            }
        };
        for g in &self.gaps {
            add(g.ends, g.k);
        }
        for s in &self.springs {
            if s.beta != 0.0 {
                add(s.ends, 3.0 * s.k * s.beta.abs() * reach * reach);
            }
        }
        let w = stiff
            .iter()
            .zip(&self.masses)
            .map(|(k, m)| (k / m).sqrt())
            .fold(0.0_f64, f64::max);
        ((w * dt / 0.2).ceil() as usize).clamp(1, 10_000)
    }

    /// Runs the system from rest under the base acceleration `input` (m/s^2, sampled every
    /// `dt` s, joined by straight lines); `reach` (m) is the largest spring stretch the
    /// run is expected to reach, which sets the sub-steps a cubic spring needs (see the
    /// module docs).
    ///
    /// # Errors
    /// [`ModelsError::Invalid`] for a `dt` or `reach` that is not finite and positive, or an
    /// input with a non-finite sample (naming it); [`ModelsError::Numerical`] when the run
    /// becomes non-finite (a softening cubic spring driven past its turning point).
    pub fn run(&self, input: &[f64], dt: f64, reach: f64) -> Result<Trajectory> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(ModelsError::invalid(
                "dt",
                dt,
                "must be finite and positive",
            ));
        }
        if !(reach.is_finite() && reach > 0.0) {
            return Err(ModelsError::invalid(
                "reach",
                reach,
                "must be finite and positive",
            ));
        }
        if let Some(k) = input.iter().position(|x| !x.is_finite()) {
            return Err(ModelsError::invalid(
                format!("base acceleration sample {k}"),
                input[k],
                "must be finite",
            ));
        }
        let n = self.len();
        let samples = input.len();
        let substeps = if self.is_nonlinear() {
            self.substeps(dt, reach)
        } else {
            1
        };
        let h = dt / substeps as f64;
        let (k, c) = self.matrices();
        let step = LinearStep::new(&self.masses, &k, &c, h);
        let inv_m: Vec<f64> = self.masses.iter().map(|m| 1.0 / m).collect();
        let mut y = vec![0.0; 2 * n];
        let mut next = vec![0.0; 2 * n];
        let mut f = vec![0.0; n];
        let mut traj = Trajectory {
            z: vec![Vec::with_capacity(samples); n],
            v: vec![Vec::with_capacity(samples); n],
            accel: vec![Vec::with_capacity(samples); n],
            substeps,
        };
        let nonlinear = self.is_nonlinear();
        let record = |y: &[f64], f: &[f64], traj: &mut Trajectory| {
            for i in 0..n {
                let mut force = f[i];
                for j in 0..n {
                    force -= k[i * n + j] * y[j] + c[i * n + j] * y[n + j];
                }
                traj.z[i].push(y[i]);
                traj.v[i].push(y[n + i]);
                traj.accel[i].push(force * inv_m[i]);
            }
        };
        if samples == 0 {
            return Ok(traj);
        }
        record(&y, &f, &mut traj);
        for s in 0..samples - 1 {
            let slope = (input[s + 1] - input[s]) / dt;
            for j in 0..substeps {
                let u0 = input[s] + slope * (j as f64 * h);
                if nonlinear {
                    for i in 0..n {
                        y[n + i] += 0.5 * h * f[i] * inv_m[i];
                    }
                }
                step.apply(&y, u0, slope, &mut next);
                std::mem::swap(&mut y, &mut next);
                if nonlinear {
                    f.iter_mut().for_each(|x| *x = 0.0);
                    self.nonlinear(&y[..n], &mut f);
                    for i in 0..n {
                        y[n + i] += 0.5 * h * f[i] * inv_m[i];
                    }
                }
            }
            if y.iter().any(|x| !x.is_finite()) {
                return Err(ModelsError::Numerical {
                    what: "lumped system".into(),
                    message: format!(
                        "the run became non-finite at sample {} (a softening spring driven \
                         past its turning point?)",
                        s + 1
                    ),
                });
            }
            record(&y, &f, &mut traj);
        }
        Ok(traj)
    }
}

/// The exact step of the linear part: `y <- Phi y + g0 u0 + g1 u'`.
struct LinearStep {
    dim: usize,
    phi: Vec<f64>,
    g0: Vec<f64>,
    g1: Vec<f64>,
}

impl LinearStep {
    fn new(masses: &[f64], k: &[f64], c: &[f64], h: f64) -> LinearStep {
        let n = masses.len();
        let dim = 2 * n;
        let big = dim + 2;
        let mut a = vec![0.0; big * big];
        for i in 0..n {
            a[i * big + n + i] = h;
            for j in 0..n {
                a[(n + i) * big + j] = -k[i * n + j] / masses[i] * h;
                a[(n + i) * big + n + j] = -c[i * n + j] / masses[i] * h;
            }
            a[(n + i) * big + dim] = -h;
        }
        a[dim * big + dim + 1] = h;
        let e = expm(&a, big);
        let mut phi = vec![0.0; dim * dim];
        let (mut g0, mut g1) = (vec![0.0; dim], vec![0.0; dim]);
        for i in 0..dim {
            phi[i * dim..(i + 1) * dim].copy_from_slice(&e[i * big..i * big + dim]);
            g0[i] = e[i * big + dim];
            g1[i] = e[i * big + dim + 1];
        }
        LinearStep { dim, phi, g0, g1 }
    }

    fn apply(&self, y: &[f64], u0: f64, slope: f64, out: &mut [f64]) {
        let d = self.dim;
        for (i, o) in out.iter_mut().enumerate() {
            let row = &self.phi[i * d..(i + 1) * d];
            let mut s = self.g0[i] * u0 + self.g1[i] * slope;
            for (p, x) in row.iter().zip(y) {
                s += p * x;
            }
            *o = s;
        }
    }
}

/// `C = A B` for `n x n` row-major matrices.
fn matmul(a: &[f64], b: &[f64], n: usize) -> Vec<f64> {
    let mut c = vec![0.0; n * n];
    for i in 0..n {
        for l in 0..n {
            let x = a[i * n + l];
            if x != 0.0 {
                for j in 0..n {
                    c[i * n + j] += x * b[l * n + j];
                }
            }
        }
    }
    c
}

/// `e^A` of an `n x n` row-major matrix: scaled by `2^-s` to a 1-norm of at most 1/2, the
/// Taylor series summed until a term falls below the round-off of the sum's largest entry,
/// then squared `s` times.
pub(crate) fn expm(a: &[f64], n: usize) -> Vec<f64> {
    let norm = (0..n)
        .map(|j| (0..n).map(|i| a[i * n + j].abs()).sum::<f64>())
        .fold(0.0_f64, f64::max);
    let s = if norm > 0.5 {
        (norm / 0.5).log2().ceil() as i32
    } else {
        0
    };
    let scale = 0.5_f64.powi(s);
    let x: Vec<f64> = a.iter().map(|v| v * scale).collect();
    let mut sum = vec![0.0; n * n];
    for i in 0..n {
        sum[i * n + i] = 1.0;
    }
    let mut term = sum.clone();
    for q in 1..40 {
        term = matmul(&term, &x, n);
        let inv = 1.0 / q as f64;
        term.iter_mut().for_each(|t| *t *= inv);
        let mut largest_sum: f64 = 0.0;
        let mut largest_term: f64 = 0.0;
        for (acc, t) in sum.iter_mut().zip(&term) {
            *acc += t;
            largest_sum = largest_sum.max(acc.abs());
            largest_term = largest_term.max(t.abs());
        }
        // Below a quarter of the round-off of the largest entry: no entry moves further.
        if largest_term <= 0.25 * f64::EPSILON * largest_sum {
            break;
        }
    }
    for _ in 0..s {
        sum = matmul(&sum, &sum, n);
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expm_of_a_rotation_and_a_nilpotent() {
        // e^{[[0, w], [-w, 0]]} = [[cos w, sin w], [-sin w, cos w]], with a large w
        // that needs squarings.
        let w = 7.3;
        let e = expm(&[0.0, w, -w, 0.0], 2);
        let want = [w.cos(), w.sin(), -w.sin(), w.cos()];
        for (a, b) in e.iter().zip(want) {
            assert!((a - b).abs() < 1e-13, "{e:?}");
        }
        // e^{[[0, 1, 0], [0, 0, 1], [0, 0, 0]] t} = [[1, t, t^2/2], [0, 1, t], [0, 0, 1]].
        let t = 3.0;
        let e = expm(&[0.0, t, 0.0, 0.0, 0.0, t, 0.0, 0.0, 0.0], 3);
        let want = [1.0, t, t * t / 2.0, 0.0, 1.0, t, 0.0, 0.0, 1.0];
        for (a, b) in e.iter().zip(want) {
            assert!((a - b).abs() < 1e-13, "{e:?}");
        }
    }
}
