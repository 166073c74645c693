//! The RBF surrogate of one CORS step: fitted by `impactcal-erbf`, evaluated by a compact
//! copy of its coefficients.
//!
//! `s(x) = sum_i c_i phi(|x - x_i|) + a_0 + a^T x` in the unit box. The interpolant of
//! `impactcal-erbf` solves the augmented system and exposes its kernel weights, centres and
//! tail coefficients in these coordinates. The copy evaluates value and gradient without
//! allocation, which the candidate screening (thousands of points) and the local polish
//! (hundreds of gradient steps) need.
//!
//! A study keeps the factorisation of its RBF system between steps and extends it by the
//! points added since the last one ([`BorderedRbf`], `O(n^2)` per point) instead of forming
//! it again (`O(n^3)`).

use std::sync::Mutex;

use faer::{ColRef, MatRef};
use impactcal_core::points::from_rows;
use impactcal_erbf::{BorderedRbf, RadialFunction, RbfCoefficients, RbfInterpolant, RbfOptions};

use crate::error::Result;
use crate::geometry::{Columns, min_of};
use crate::options::SurrogateKernel;

/// A fitted cubic or thin-plate RBF with a linear tail on the unit box: the surrogate of
/// one CORS step, as a compact copy of the coefficients of an `impactcal-erbf` interpolant.
#[derive(Debug, Clone)]
pub struct RbfSurrogate {
    kernel: RadialFunction,
    dim: usize,
    /// Centres, row-major `N x d`.
    centres: Vec<f64>,
    /// The same centres coordinate by coordinate, for evaluating many distances at once.
    columns: Columns,
    weights: Vec<f64>,
    a0: f64,
    a: Vec<f64>,
}

impl RbfSurrogate {
    /// Fits the interpolant to `points` (`N x d`, one point of the unit box per row,
    /// distinct, affinely spanning) and `values` (length `N`). When the system is
    /// numerically singular, a smoothing of `1e-10` of the largest radial-function value is
    /// tried once before giving up.
    ///
    /// # Errors
    /// The error of `impactcal-erbf` ([`impactcal_erbf::ErbfError`]) when the fit fails.
    pub fn fit(points: MatRef<'_, f64>, values: &[f64], kernel: SurrogateKernel) -> Result<Self> {
        let options = match kernel {
            SurrogateKernel::Cubic => RbfOptions::cubic(),
            SurrogateKernel::ThinPlate => RbfOptions::thin_plate(),
        };
        let f = ColRef::from_slice(values).as_mat();
        let rbf = match RbfInterpolant::fit(points, f, options) {
            Ok(r) => r,
            Err(first) => {
                let d = if points.nrows() == 0 {
                    1
                } else {
                    points.ncols()
                } as f64;
                let kmax = options.radial.value(d.sqrt()).abs().max(1.0);
                RbfInterpolant::fit(points, f, options.with_smoothing(1e-10 * kmax))
                    .map_err(|_| first)?
            }
        };
        Self::from_interpolant(&rbf)
    }

    /// The surrogate of coefficients solved by a bordered factorisation over `points`
    /// (row-major, as pushed to it).
    fn from_coefficients(
        kernel: RadialFunction,
        dim: usize,
        points: &[f64],
        coef: RbfCoefficients,
    ) -> Self {
        RbfSurrogate {
            kernel,
            dim,
            centres: points.to_vec(),
            columns: Columns::new(points, dim),
            weights: coef.weights,
            a0: coef.constant,
            a: coef.linear,
        }
    }

    /// Copies the coefficients of a single-output interpolant with a linear tail.
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`](impactcal_core::CoreError::DimensionMismatch) when
    /// the interpolant has no linear tail or no output.
    pub fn from_interpolant(rbf: &RbfInterpolant) -> Result<Self> {
        let dim = rbf.dim();
        let n = rbf.n_samples();
        let pts: MatRef<'_, f64> = rbf.points();
        let mut centres = Vec::with_capacity(n * dim);
        for i in 0..n {
            centres.extend(pts.row(i).iter().copied());
        }
        let weights: Vec<f64> = rbf.radial_weights().col(0).iter().copied().collect();
        let tail = rbf.tail_coefficients();
        if tail.nrows() != dim + 1 || tail.ncols() == 0 {
            return Err(impactcal_core::CoreError::DimensionMismatch {
                what: "surrogate tail: linear terms".into(),
                expected: dim + 1,
                found: tail.nrows(),
            }
            .into());
        }
        let columns = Columns::new(&centres, dim);
        Ok(RbfSurrogate {
            kernel: rbf.options().radial,
            dim,
            centres,
            columns,
            weights,
            a0: tail[(0, 0)],
            a: (0..dim).map(|j| tail[(1 + j, 0)]).collect(),
        })
    }

    /// Dimension `d`.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// `sum_i c_i phi(|x - x_i|)`. The squared distances of a block of centres are formed
    /// coordinate by coordinate and the kernel values of the block at once, which
    /// vectorises across centres; every distance, every kernel value and the sum over
    /// centres (in order) keep the operations of the plain loop, bit for bit.
    /// Also returns the smallest squared distance from `x` to a centre (infinite for none).
    fn kernel_part(&self, x: &[f64]) -> (f64, f64) {
        match self.kernel {
            RadialFunction::Cubic => self.weighted_sum(x, |r| r * r * r),
            kernel => self.weighted_sum(x, |r| kernel.value(r)),
        }
    }

    /// `sum_i c_i phi(|x - x_i|)` for a kernel `phi` known at compile time, and the
    /// smallest squared distance to a centre.
    #[inline]
    fn weighted_sum(&self, x: &[f64], phi: impl Fn(f64) -> f64) -> (f64, f64) {
        let mut sum = -0.0;
        let mut nearest = f64::INFINITY;
        let mut k = [0.0; Columns::BLOCK];
        self.columns.for_each_block(x, |start, d2| {
            nearest = nearest.min(min_of(d2));
            let k = &mut k[..d2.len()];
            for (kv, d) in k.iter_mut().zip(d2) {
                *kv = phi(d.sqrt());
            }
            for (kv, w) in k.iter().zip(&self.weights[start..]) {
                sum += w * kv;
            }
        });
        (sum, nearest)
    }

    /// `s(x)`.
    pub fn value(&self, x: &[f64]) -> f64 {
        self.value_and_nearest(x).0
    }

    /// `s(x)` and the smallest squared distance from `x` to a centre (infinite for none),
    /// which the evaluation forms anyway.
    pub fn value_and_nearest(&self, x: &[f64]) -> (f64, f64) {
        let tail: f64 = self.a.iter().zip(x).map(|(a, v)| a * v).sum();
        let (kernel, nearest) = self.kernel_part(x);
        (kernel + self.a0 + tail, nearest)
    }

    /// The centres, row-major (`N x d`).
    pub fn centres(&self) -> &[f64] {
        &self.centres
    }

    /// `s(x)`, with `grad s(x)` written into `grad` (length `d`):
    /// `sum_i c_i (phi'(r_i) / r_i) (x - x_i) + a`. Distances and kernel terms are formed
    /// a block of centres at a time (as in [`value`](Self::value)); the sums over centres
    /// keep the order and the operations of the plain loop, bit for bit.
    pub fn value_gradient(&self, x: &[f64], grad: &mut [f64]) -> f64 {
        match self.kernel {
            RadialFunction::Cubic => self.value_gradient_with(x, grad, |r| r * r * r, |r| 3.0 * r),
            kernel => self.value_gradient_with(
                x,
                grad,
                |r| kernel.value(r),
                |r| kernel.derivative_over_r(r),
            ),
        }
    }

    /// [`value_gradient`](Self::value_gradient) for `phi` and `phi'(r) / r` known at
    /// compile time.
    #[inline]
    fn value_gradient_with(
        &self,
        x: &[f64],
        grad: &mut [f64],
        phi_of: impl Fn(f64) -> f64,
        slope_of: impl Fn(f64) -> f64,
    ) -> f64 {
        grad.copy_from_slice(&self.a);
        let mut v = self.a0 + self.a.iter().zip(x).map(|(a, v)| a * v).sum::<f64>();
        let (mut phi, mut g) = ([0.0; Columns::BLOCK], [0.0; Columns::BLOCK]);
        self.columns.for_each_block(x, |start, d2| {
            let len = d2.len();
            let weights = &self.weights[start..start + len];
            for ((d, w), (p, gk)) in d2.iter().zip(weights).zip(phi.iter_mut().zip(&mut g)) {
                let r = d.sqrt();
                *p = w * phi_of(r);
                *gk = w * slope_of(r);
            }
            let centres = self.centres[start * self.dim..].chunks_exact(self.dim);
            for ((c, p), gk) in centres.zip(&phi[..len]).zip(&g[..len]) {
                v += p;
                for ((gj, xj), cj) in grad.iter_mut().zip(x).zip(c) {
                    *gj += gk * (xj - cj);
                }
            }
        });
        v
    }
}

/// The bordered factorisation of a study's last surrogate, kept between steps: a memo
/// that never changes a result. A fit over points that extend the cached ones (the same
/// values, bit for bit, in the same order: the next step of the same run) pushes only the
/// new points; any other set (a restart, a study read back from a file, another kernel) is
/// factorised by pushing its points one by one from an empty model. Either way the
/// factors are those of the same sequence of pushes, so a resumed study fits exactly as
/// an uninterrupted one.
#[derive(Debug, Default)]
pub(crate) struct FitCache(Mutex<Option<BorderedRbf>>);

impl Clone for FitCache {
    fn clone(&self) -> Self {
        let inner = match self.0.lock() {
            Ok(g) => g.clone(),
            Err(poisoned) => poisoned.into_inner().clone(),
        };
        FitCache(Mutex::new(inner))
    }
}

impl FitCache {
    /// Fits the surrogate to `points` (distinct points of the unit box, affinely spanning)
    /// and `values`. When the bordered system is singular the fit of
    /// [`RbfSurrogate::fit`] (with its small smoothing) is tried instead.
    ///
    /// # Errors
    /// The error of `impactcal-erbf` when no fit succeeds.
    pub(crate) fn fit(
        &self,
        points: &[Vec<f64>],
        values: &[f64],
        kernel: SurrogateKernel,
    ) -> Result<RbfSurrogate> {
        let radial = radial_of(kernel);
        let dim = points.first().map_or(0, Vec::len);
        let mut guard = match self.0.lock() {
            Ok(g) => g,
            Err(poisoned) => poisoned.into_inner(),
        };
        let extends = |m: &BorderedRbf| {
            m.radial() == radial
                && m.dim() == dim
                && m.n_points() <= points.len()
                && m.points()
                    .chunks_exact(dim.max(1))
                    .zip(points)
                    .all(|(a, b)| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()))
        };
        let model = match guard.take() {
            Some(m) if extends(&m) => m,
            _ => BorderedRbf::new(radial, &vec![0.0; dim], &vec![1.0; dim])?,
        };
        let model = guard.insert(model);
        for p in &points[model.n_points()..] {
            model.push(p)?;
        }
        if model.is_factorised() {
            let coef = model.solve(values)?;
            return Ok(RbfSurrogate::from_coefficients(
                radial,
                dim,
                model.points(),
                coef,
            ));
        }
        drop(guard);
        let x = from_rows(points, "surrogate points")?;
        RbfSurrogate::fit(x.as_ref(), values, kernel)
    }
}

fn radial_of(kernel: SurrogateKernel) -> RadialFunction {
    match kernel {
        SurrogateKernel::Cubic => RadialFunction::Cubic,
        SurrogateKernel::ThinPlate => RadialFunction::ThinPlate,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn points(n: usize, dim: usize) -> (Vec<Vec<f64>>, Vec<f64>) {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let pts: Vec<Vec<f64>> = (0..n)
            .map(|_| (0..dim).map(|_| rng.random::<f64>()).collect())
            .collect();
        let vals = pts
            .iter()
            .map(|p| p.iter().map(|v| (4.0 * v).cos()).sum())
            .collect();
        (pts, vals)
    }

    /// A fit extended step by step through the cache equals, bit for bit, a fit of the
    /// same points through an empty cache (what a resumed study does), and agrees with the
    /// from-scratch interpolant of `impactcal-erbf`; a set that does not extend the cached
    /// one (a restart) is fitted afresh.
    #[test]
    fn cached_extension_equals_a_fresh_fit() {
        let (pts, vals) = points(60, 4);
        let cache = FitCache::default();
        for n in [12, 13, 20, 60] {
            cache
                .fit(&pts[..n], &vals[..n], SurrogateKernel::Cubic)
                .unwrap();
        }
        let extended = cache.fit(&pts, &vals, SurrogateKernel::Cubic).unwrap();
        let fresh = FitCache::default()
            .fit(&pts, &vals, SurrogateKernel::Cubic)
            .unwrap();
        let x = from_rows(&pts, "points").unwrap();
        let scratch = RbfSurrogate::fit(x.as_ref(), &vals, SurrogateKernel::Cubic).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        for _ in 0..20 {
            let q: Vec<f64> = (0..4).map(|_| rng.random::<f64>()).collect();
            assert_eq!(extended.value(&q).to_bits(), fresh.value(&q).to_bits());
            assert!((extended.value(&q) - scratch.value(&q)).abs() < 1e-9);
        }
        // A restart: other points, fitted afresh.
        let restart = cache
            .fit(&pts[30..], &vals[30..], SurrogateKernel::Cubic)
            .unwrap();
        for (p, v) in pts[30..].iter().zip(&vals[30..]) {
            assert!((restart.value(p) - v).abs() < 1e-10);
        }
    }
}
