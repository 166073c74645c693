//! ERBF with a smoothing (ridge) term: the filtered solve through the SVD of `R`.
//!
//! The interpolating ERBF takes the minimum-norm `c` with `A c = F`. With smoothing
//! `lambda > 0` it takes instead the minimiser of `||A c - F||^2 + lambda ||c||^2`,
//! `c = A^T (G + lambda I)^{-1} F` with the kernel matrix `G = A A^T = R^T R` (from the
//! thin QR `A^T = Q_1 R`). With the SVD `R = U S V^T` (`N x N`) every quantity the model
//! needs is a filter on the singular values, so one SVD serves every `lambda`:
//!
//! ```text
//! prediction   f(x) = F^T (G + lambda I)^{-1} R^T w = F^T V diag(s / (s^2 + lambda)) U^T w,
//!              w = Q_1^T b(x)        (F^T R^{-1} w at lambda = 0),
//! stored form  Z = U diag(s / (s^2 + lambda)) V^T F (R^{-T} F at lambda = 0),
//! LOO          e_k = ((G + lambda I)^{-1} F)_k / ((G + lambda I)^{-1})_kk,
//!              (G + lambda I)^{-1} = V diag(1 / (s^2 + lambda)) V^T.
//! ```
//!
//! The leave-one-out form is the exact one of kernel ridge regression with the kernel
//! matrix `G` held fixed (the removed sample's basis functions stay in the model, as in
//! ERBF's closed form without smoothing), and at `lambda = 0` it is that closed form.
//! `lambda` is given relative to the mean diagonal of `G`: `lambda = smoothing tr(G) / N`,
//! so that the same `smoothing` means the same thing whatever the radius and the family
//! weights. With smoothing the outputs are centred before the fit (the mean is not shrunk,
//! as the intercept of ridge regression).

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par};

use crate::error::{ErbfError, Result};

/// The SVD `R = U diag(s) V^T` of the triangular factor of an ERBF fit.
#[derive(Debug, Clone)]
pub(crate) struct RSvd {
    u: Mat<f64>,
    s: Vec<f64>,
    v: Mat<f64>,
    /// `tr(G) / N = ||R||_F^2 / N`, the unit of the relative smoothing.
    scale: f64,
}

impl RSvd {
    /// Decomposes `r` (`N x N`).
    ///
    /// # Errors
    /// [`ErbfError::Singular`] when the SVD does not converge.
    pub(crate) fn new(r: MatRef<'_, f64>) -> Result<Self> {
        let svd = r.thin_svd().map_err(|_| ErbfError::Singular {
            ratio: f64::NAN,
            threshold: 0.0,
        })?;
        let n = r.nrows().max(1);
        Ok(RSvd {
            u: svd.U().to_owned(),
            s: svd.S().column_vector().iter().copied().collect(),
            v: svd.V().to_owned(),
            scale: r.squared_norm_l2() / n as f64,
        })
    }

    /// The absolute ridge `lambda = smoothing tr(G) / N`.
    pub(crate) fn lambda(&self, smoothing: f64) -> f64 {
        smoothing * self.scale
    }

    /// `s_i / (s_i^2 + lambda)` (`1 / s_i` at `lambda = 0`; 0 for a zero singular value).
    fn filter(&self, lambda: f64) -> Vec<f64> {
        self.s
            .iter()
            .map(|&s| {
                let d = s * s + lambda;
                if d > 0.0 { s / d } else { 0.0 }
            })
            .collect()
    }

    /// `w <- V diag(filter) U^T w` (`w` is `N x q`): `R^{-1} w` at `lambda = 0`.
    pub(crate) fn solve(&self, lambda: f64, w: MatMut<'_, f64>) {
        apply(self.u.as_ref(), &self.filter(lambda), self.v.as_ref(), w);
    }

    /// `z <- U diag(filter) V^T z` (`z` is `N x T`): `R^{-T} z` at `lambda = 0`.
    pub(crate) fn solve_transpose(&self, lambda: f64, z: MatMut<'_, f64>) {
        apply(self.v.as_ref(), &self.filter(lambda), self.u.as_ref(), z);
    }

    /// Leave-one-out errors of the kernel ridge fit to `f` (`N x T`, the responses the
    /// model fits), `e_k = ((G + lambda I)^{-1} F)_k / ((G + lambda I)^{-1})_kk`.
    ///
    /// # Errors
    /// [`ErbfError::LooUndefined`] when a diagonal entry is not positive and finite (a
    /// singular `G` without smoothing).
    pub(crate) fn loo(&self, lambda: f64, f: MatRef<'_, f64>) -> Result<Mat<f64>> {
        let n = self.s.len();
        let inv: Vec<f64> = self.s.iter().map(|&s| 1.0 / (s * s + lambda)).collect();
        // alpha = V diag(inv) V^T F.
        let mut vt_f = self.v.transpose() * f;
        for (i, d) in inv.iter().enumerate() {
            vt_f.row_mut(i).iter_mut().for_each(|x| *x *= d);
        }
        let alpha = &self.v * &vt_f;
        let mut out = alpha;
        for k in 0..n {
            let h: f64 = (0..n).map(|j| self.v[(k, j)].powi(2) * inv[j]).sum();
            if !(h.is_finite() && h > 0.0) {
                return Err(ErbfError::LooUndefined {
                    sample: k,
                    message: "the kernel matrix is singular; add smoothing".into(),
                });
            }
            out.row_mut(k).iter_mut().for_each(|x| *x /= h);
        }
        Ok(out)
    }
}

/// `w <- right diag(d) left^T w`.
fn apply(left: MatRef<'_, f64>, d: &[f64], right: MatRef<'_, f64>, mut w: MatMut<'_, f64>) {
    let mut t = left.transpose() * w.as_ref();
    for (i, di) in d.iter().enumerate() {
        t.row_mut(i).iter_mut().for_each(|x| *x *= di);
    }
    matmul(w.as_mut(), Accum::Replace, right, t.as_ref(), 1.0, Par::Seq);
}
