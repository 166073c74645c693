//! An RBF interpolant with a linear tail whose factorisation grows one point at a time.
//!
//! The interpolant `s(x) = sum_i c_i phi(|x - x_i|) + a_0 + a^T x` solves the augmented
//! system, written here with the tail first so that every new point appends a row and a
//! column:
//!
//! ```text
//! A = [ 0  P^T ]      A [b; c] = [0; f],    P_il = w t_l(x_i),
//!     [ P  K   ]
//! ```
//!
//! with `K_ik = phi(|x_i - x_k|)` and the tail basis `t = (1, (x - m) / h)` scaled by the
//! weight `w`. The centre `m`, the half-width `h` and `w = max(|phi(diameter)|, 1)` are
//! fixed from a box given at construction (the unit cube for CORS), never from the points,
//! so that adding a point changes no existing entry of `A`.
//!
//! The factorisation is `P_0 A = L U` (`L` unit lower triangular, `U` upper triangular,
//! `P_0` a row permutation of the leading block only). The first factorisation is an LU with
//! partial pivoting of the whole system, taken as soon as it is regular (pivot ratio above
//! `m eps`, `m` the size of the system). Each later point `p` borders it: with
//! `a = A[.., p]` (its kernel and tail entries against the `m` rows so far) and
//! `alpha = phi(0)`,
//!
//! ```text
//! L u = P_0 a,    U^T l = a,    delta = alpha - l^T u,
//! L' = [L 0; l^T 1],   U' = [U u; 0 delta],
//! ```
//!
//! two triangular solves, `O(m^2)` instead of the `O(m^3)` of a new factorisation. No row
//! exchange is possible past the leading block; this is stable here because, with the tail
//! and a unisolvent set of points in the leading block, the bordered pivots `delta` are the
//! diagonal of the Schur complement of a conditionally positive definite kernel (cubic,
//! thin-plate spline) on the null space of the tail, a definite matrix, so they do not grow
//! and keep one sign. When a pivot is too small all the same (`|delta|` at most `1e-10`
//! times the largest pivot so far: a point nearly coincident with another or a system near
//! singularity), the whole system is factorised again with partial pivoting, which becomes
//! the new leading block ([`BorderedRbf::refactorisations`] counts these).
//!
//! The factors are a function of the ordered sequence of points alone: a model rebuilt by
//! pushing the same points in the same order holds the same factors, bit for bit, whether it
//! was built in one go or extended over many sessions.

use faer::Mat;
use impactcal_core::CoreError;
use impactcal_core::error::{check_finite, dimension_mismatch};

use crate::error::{ErbfError, Result};
use crate::radial::RadialFunction;
use crate::rbf::distance;

/// A bordered pivot at most this fraction of the largest pivot triggers a full
/// factorisation with partial pivoting.
const BORDER_TOL: f64 = 1e-10;

/// The coefficients of a fitted interpolant in the coordinates of its points:
/// `s(x) = sum_i weights_i phi(|x - x_i|) + constant + linear^T x`.
#[derive(Debug, Clone, PartialEq)]
pub struct RbfCoefficients {
    /// `c_i`, one per point, in the order the points were pushed.
    pub weights: Vec<f64>,
    /// `a_0`.
    pub constant: f64,
    /// `a`, one per coordinate.
    pub linear: Vec<f64>,
}

/// The cubic or thin-plate (any radial function with a linear tail) RBF system of a growing
/// point set, factorised by bordering (see the [module documentation](self)).
#[derive(Debug, Clone)]
pub struct BorderedRbf {
    radial: RadialFunction,
    dim: usize,
    centre: Vec<f64>,
    half_width: f64,
    tail_weight: f64,
    /// Points, row-major, in the order pushed.
    points: Vec<f64>,
    factors: Option<Factors>,
    refactorisations: usize,
}

/// `P_0 A = L U`, packed: row `i` of `L` below the diagonal, column `j` of `U` down to the
/// diagonal.
#[derive(Debug, Clone)]
struct Factors {
    /// `(P_0 b)_i = b[perm[i]]` for `i < perm.len()`, the identity beyond.
    perm: Vec<usize>,
    /// Row `i` of `L` (`i` entries) at offset `i (i - 1) / 2`.
    l_rows: Vec<f64>,
    /// Column `j` of `U` (`j + 1` entries) at offset `j (j + 1) / 2`.
    u_cols: Vec<f64>,
    /// Size `m` of the factorised system.
    size: usize,
    /// Largest pivot magnitude.
    max_pivot: f64,
}

impl Factors {
    fn l_row(&self, i: usize) -> &[f64] {
        let o = i * i.saturating_sub(1) / 2;
        &self.l_rows[o..o + i]
    }

    fn u_col(&self, j: usize) -> &[f64] {
        let o = j * (j + 1) / 2;
        &self.u_cols[o..=o + j]
    }

    /// Solves `L y = P_0 b` (`b` of length `size`).
    fn forward(&self, b: &[f64]) -> Vec<f64> {
        let mut y: Vec<f64> = (0..self.size)
            .map(|i| self.perm.get(i).map_or(b[i], |&p| b[p]))
            .collect();
        for i in 1..self.size {
            let s: f64 = self.l_row(i).iter().zip(&y[..i]).map(|(l, v)| l * v).sum();
            y[i] -= s;
        }
        y
    }

    /// Solves `U^T l = a`.
    fn forward_transposed(&self, a: &[f64]) -> Vec<f64> {
        let mut l = vec![0.0; self.size];
        for j in 0..self.size {
            let col = self.u_col(j);
            let s: f64 = col[..j].iter().zip(&l[..j]).map(|(u, v)| u * v).sum();
            l[j] = (a[j] - s) / col[j];
        }
        l
    }

    /// Solves `U x = y` in place.
    fn backward(&self, y: &mut [f64]) {
        for j in (0..self.size).rev() {
            let col = self.u_col(j);
            y[j] /= col[j];
            let xj = y[j];
            for (yk, u) in y[..j].iter_mut().zip(&col[..j]) {
                *yk -= u * xj;
            }
        }
    }
}

impl BorderedRbf {
    /// An empty model for points of the box `[lower, upper]` (which fixes the scaling of the
    /// tail; points outside it are allowed but the box should hold them).
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`] for bounds of different lengths or none;
    /// [`CoreError::InvalidOption`] for non-finite bounds or `lower > upper`, or an invalid
    /// radial function.
    pub fn new(radial: RadialFunction, lower: &[f64], upper: &[f64]) -> Result<Self> {
        radial.validate()?;
        let dim = lower.len();
        if dim == 0 || upper.len() != dim {
            return Err(dimension_mismatch(
                "box: upper bounds",
                dim.max(1),
                upper.len(),
            ));
        }
        if lower
            .iter()
            .zip(upper)
            .any(|(l, u)| !(l.is_finite() && u.is_finite() && l <= u))
        {
            return Err(CoreError::invalid_option(
                "box",
                format!("{lower:?} to {upper:?}"),
                "bounds must be finite with lower <= upper",
            )
            .into());
        }
        let centre = lower
            .iter()
            .zip(upper)
            .map(|(l, u)| 0.5 * (l + u))
            .collect();
        let half = lower
            .iter()
            .zip(upper)
            .map(|(l, u)| 0.5 * (u - l))
            .fold(0.0, f64::max);
        let diameter = distance(lower, upper);
        Ok(BorderedRbf {
            radial,
            dim,
            centre,
            half_width: if half > 0.0 { half } else { 1.0 },
            tail_weight: radial.value(diameter).abs().max(1.0),
            points: Vec::new(),
            factors: None,
            refactorisations: 0,
        })
    }

    /// Dimension `d`.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// The radial function.
    pub fn radial(&self) -> RadialFunction {
        self.radial
    }

    /// Number of points pushed.
    pub fn n_points(&self) -> usize {
        self.points.len() / self.dim
    }

    /// The points pushed, row-major (`n_points x d`), in order.
    pub fn points(&self) -> &[f64] {
        &self.points
    }

    /// Whether the system of the points so far is factorised (it is from the first point
    /// at which it is regular: at least `d + 1` affinely independent distinct points).
    pub fn is_factorised(&self) -> bool {
        self.factors.is_some()
    }

    /// How many times a full factorisation with partial pivoting was taken after the
    /// first one, because a bordered pivot was too small or the system had been singular.
    pub fn refactorisations(&self) -> usize {
        self.refactorisations
    }

    /// Adds a point: borders the factorisation in `O(m^2)`, or factorises the whole system
    /// again (`O(m^3)`) when the bordered pivot is too small or there was no factorisation
    /// yet. The point is kept even when the system stays singular (for example while the
    /// points are fewer than `d + 1` or on a hyperplane).
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`] or [`CoreError::NonFinite`] for a bad point; the
    /// model is then unchanged.
    pub fn push(&mut self, x: &[f64]) -> Result<()> {
        if x.len() != self.dim {
            return Err(dimension_mismatch("point: coordinates", self.dim, x.len()));
        }
        check_finite("point coordinates", x)?;
        let column = self.column(x);
        self.points.extend_from_slice(x);
        let bordered = self.factors.as_ref().and_then(|f| {
            let u = f.forward(&column);
            let l = f.forward_transposed(&column);
            let delta = self.radial.value(0.0) - l.iter().zip(&u).map(|(a, b)| a * b).sum::<f64>();
            (delta.is_finite() && delta.abs() > BORDER_TOL * f.max_pivot).then_some((l, u, delta))
        });
        match (bordered, self.factors.as_mut()) {
            (Some((l, u, delta)), Some(f)) => {
                f.l_rows.extend_from_slice(&l);
                f.u_cols.extend_from_slice(&u);
                f.u_cols.push(delta);
                f.size += 1;
                f.max_pivot = f.max_pivot.max(delta.abs());
            }
            _ => {
                if self.factors.is_some() {
                    self.refactorisations += 1;
                }
                self.factors = self.factorise();
            }
        }
        Ok(())
    }

    /// Solves for the coefficients interpolating `values` (one per point, in order).
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`] when `values` has not one entry per point;
    /// [`CoreError::NonFinite`] for a NaN or infinite value; [`ErbfError::Singular`] when
    /// the system is not factorised (too few or degenerate points).
    pub fn solve(&self, values: &[f64]) -> Result<RbfCoefficients> {
        let n = self.n_points();
        if values.len() != n {
            return Err(dimension_mismatch("values: one per point", n, values.len()));
        }
        check_finite("values (one per point)", values)?;
        let Some(f) = &self.factors else {
            return Err(ErbfError::Singular {
                ratio: 0.0,
                threshold: self.threshold(),
            });
        };
        let q = self.dim + 1;
        let mut rhs = vec![0.0; q];
        rhs.extend_from_slice(values);
        let mut x = f.forward(&rhs);
        f.backward(&mut x);
        let (w, h) = (self.tail_weight, self.half_width);
        let linear: Vec<f64> = x[1..q].iter().map(|b| b * w / h).collect();
        let constant = x[0] * w
            - linear
                .iter()
                .zip(&self.centre)
                .map(|(a, m)| a * m)
                .sum::<f64>();
        Ok(RbfCoefficients {
            weights: x[q..].to_vec(),
            constant,
            linear,
        })
    }

    /// The column of `A` of a new point `x` against the rows so far: tail, then kernel.
    fn column(&self, x: &[f64]) -> Vec<f64> {
        let mut a = Vec::with_capacity(self.dim + 1 + self.n_points());
        self.tail_row(x, &mut a);
        for p in self.points.chunks_exact(self.dim) {
            a.push(self.radial.value(distance(x, p)));
        }
        a
    }

    /// Appends `w (1, (x - m) / h)`.
    fn tail_row(&self, x: &[f64], out: &mut Vec<f64>) {
        let w = self.tail_weight;
        out.push(w);
        out.extend(
            x.iter()
                .zip(&self.centre)
                .map(|(v, m)| w * (v - m) / self.half_width),
        );
    }

    /// Pivot ratio below which the whole system counts as singular.
    fn threshold(&self) -> f64 {
        (self.dim + 1 + self.n_points()) as f64 * f64::EPSILON
    }

    /// LU with partial pivoting of the whole system; `None` while it is singular.
    fn factorise(&self) -> Option<Factors> {
        let q = self.dim + 1;
        let n = self.n_points();
        if n < q {
            return None;
        }
        let m = q + n;
        let pts: Vec<&[f64]> = self.points.chunks_exact(self.dim).collect();
        let mut tail = Vec::with_capacity(q);
        let mut a = Mat::<f64>::zeros(m, m);
        for (i, p) in pts.iter().enumerate() {
            tail.clear();
            self.tail_row(p, &mut tail);
            for (l, t) in tail.iter().enumerate() {
                a[(l, q + i)] = *t;
                a[(q + i, l)] = *t;
            }
            for (k, r) in pts.iter().enumerate() {
                a[(q + i, q + k)] = self.radial.value(distance(*p, *r));
            }
        }
        let lu = crate::lu::Lu::new(a);
        let (lower, upper) = (lu.lower(), lu.upper());
        let pivots: Vec<f64> = (0..m).map(|i| upper[(i, i)].abs()).collect();
        let max_pivot = pivots.iter().copied().fold(0.0, f64::max);
        let min_pivot = pivots.iter().copied().fold(f64::INFINITY, f64::min);
        if !(max_pivot > 0.0 && min_pivot / max_pivot > self.threshold()) {
            return None;
        }
        let mut l_rows = Vec::with_capacity(m * (m - 1) / 2);
        let mut u_cols = Vec::with_capacity(m * (m + 1) / 2);
        for i in 0..m {
            l_rows.extend((0..i).map(|k| lower[(i, k)]));
            u_cols.extend((0..=i).map(|k| upper[(k, i)]));
        }
        Some(Factors {
            perm: lu.forward().to_vec(),
            l_rows,
            u_cols,
            size: m,
            max_pivot,
        })
    }
}

impl RbfCoefficients {
    /// `s(x)` for the interpolant over `points` (row-major, as given to the model).
    pub fn value(&self, radial: RadialFunction, points: &[f64], x: &[f64]) -> f64 {
        let dim = x.len();
        let kernel: f64 = points
            .chunks_exact(dim.max(1))
            .zip(&self.weights)
            .map(|(p, c)| c * radial.value(distance(x, p)))
            .sum();
        kernel + self.constant + self.linear.iter().zip(x).map(|(a, v)| a * v).sum::<f64>()
    }
}
