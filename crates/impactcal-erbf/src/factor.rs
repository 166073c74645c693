//! The factorisation behind an ERBF fit: `A A^T = R^T R` for the `N x M` interpolation
//! matrix `A`, with the `M x N` matrix whose rows the prediction tables hold.
//!
//! Two routes give the same `R` (up to the signs of its rows) and the same model:
//!
//! - **Gram** (well-conditioned `A`, the usual case): the kernel matrix `K = A A^T`
//!   (`N x N`, `M N^2` multiply-adds, half of them by symmetry) and its Cholesky factor
//!   `K = R^T R`. The rows kept are those of `A^T` itself, so a query's projected basis is
//!   `Q_1^T b(x) = R^{-T} (A b(x))`: one extra triangular solve (`N^2 / 2`) per query.
//!   About four times fewer operations than the QR route, all in matrix products.
//! - **QR** (otherwise): the Householder factorisation `A^T = Q_1 R` of
//!   [`crate::thin_qr`], which keeps the orthonormal `Q_1`. It is as accurate as the data
//!   allow: errors grow with `kappa(A)`, where the Gram route's grow with
//!   `kappa(A)^2`.
//!
//! The Gram route is taken when the Cholesky factorisation succeeds and
//! `||K||_F ||K^{-1}||_F`, an upper bound on the 2-norm condition number
//! `kappa(K) = kappa(A)^2`, is at most [`GRAM_CONDITION_LIMIT`]: then `kappa(K) eps`, at
//! most `2.2e-10`, bounds the relative error the squared conditioning adds. The bound costs
//! `K^{-1} = R^{-1} R^{-T}` (`N^3 / 2`). Both routes' results do not depend on the number
//! of threads.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch};
use faer::linalg::matmul::triangular::{BlockStructure, matmul};
use faer::linalg::triangular_inverse::invert_lower_triangular;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Accum, Mat, MatMut, MatRef, Par};

use crate::basis::basis_matrix_t;
use crate::error::{ErbfError, Result};
use crate::options::ErbfOptions;
use crate::thin_qr::{ThinQr, thin_qr};

/// The largest bound `||K||_F ||K^{-1}||_F` on `kappa(K)` for which the fit takes the
/// Gram route (see the module documentation).
pub(crate) const GRAM_CONDITION_LIMIT: f64 = 1e6;

/// What the rows of the fit's `M x N` factor are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Rows {
    /// `Q_1` with orthonormal columns (`A^T = Q_1 R`).
    Orthonormal,
    /// `A^T` itself (`Q_1 = A^T R^{-1}`).
    Basis,
}

/// `P` (`M x N`, see [`Rows`]) and `R` (`N x N`, upper triangular) with `A A^T = R^T R`.
pub(crate) struct Factor {
    pub(crate) rows: Mat<f64>,
    pub(crate) kind: Rows,
    pub(crate) r: Mat<f64>,
    /// `min |R_ii| / max |R_ii|`.
    pub(crate) ratio: f64,
}

impl Factor {
    /// Factorises the interpolation matrix of the scaled samples `unit` (`N x m`);
    /// `parallel` lets the halves of the rows of `A^T` run side by side.
    ///
    /// # Errors
    /// [`ErbfError::Singular`] when `min |R_ii| / max |R_ii|` falls below `N eps` (or is
    /// NaN) without smoothing; with smoothing a (near-)singular kernel matrix is well posed.
    pub(crate) fn new(
        unit: MatRef<'_, f64>,
        options: &ErbfOptions,
        parallel: bool,
    ) -> Result<Self> {
        let n = unit.nrows();
        let at = basis_matrix_t(unit, unit, options);
        let gram =
            gram_factor(at.as_ref(), parallel).filter(|(_, kappa)| *kappa <= GRAM_CONDITION_LIMIT);
        let factor = match gram {
            Some((r, _)) => Factor {
                rows: at,
                kind: Rows::Basis,
                ratio: diagonal_ratio(r.as_ref()),
                r,
            },
            None => {
                let ThinQr { q1, r } = thin_qr(at, parallel);
                Factor {
                    rows: q1,
                    kind: Rows::Orthonormal,
                    ratio: diagonal_ratio(r.as_ref()),
                    r,
                }
            }
        };
        let threshold = n as f64 * f64::EPSILON;
        if factor.ratio.is_nan() || (factor.ratio <= threshold && options.smoothing <= 0.0) {
            return Err(ErbfError::Singular {
                ratio: factor.ratio,
                threshold,
            });
        }
        Ok(factor)
    }
}

/// `w <- Q_1^T b` from `w = P^T b` (`N x k`): `R^{-T} w` for [`Rows::Basis`], nothing for
/// [`Rows::Orthonormal`].
pub(crate) fn orthonormalise(kind: Rows, r: MatRef<'_, f64>, w: MatMut<'_, f64>) {
    if kind == Rows::Basis {
        solve_lower_triangular_in_place(r.transpose(), w, Par::Seq);
    }
}

/// `Q_1 z` (`M x k`) for `z` (`N x k`): `P z`, or `P (R^{-1} z)` for [`Rows::Basis`].
pub(crate) fn q1_times(
    kind: Rows,
    rows: MatRef<'_, f64>,
    r: MatRef<'_, f64>,
    mut z: Mat<f64>,
) -> Mat<f64> {
    if kind == Rows::Basis {
        solve_upper_triangular_in_place(r, z.as_mut(), Par::Seq);
    }
    rows * z
}

/// `R` with `A A^T = R^T R` for `at = A^T` (`M x N`) by the Gram route, and the bound
/// `||K||_F ||K^{-1}||_F >= kappa(K)`; `None` when the Cholesky factorisation fails or the
/// bound is not finite.
fn gram_factor(at: MatRef<'_, f64>, parallel: bool) -> Option<(Mat<f64>, f64)> {
    let (m, n) = at.shape();
    let mut k = Mat::<f64>::zeros(n, n);
    if parallel && m >= 2 * n {
        // Two halves of the rows, summed in a fixed order: the same bits on any number of
        // threads.
        let (top, bottom) = at.split_at_row(m / 2);
        let mut lower = Mat::<f64>::zeros(n, n);
        rayon::join(
            || lower_gram(k.as_mut(), top),
            || lower_gram(lower.as_mut(), bottom),
        );
        k += lower;
    } else {
        lower_gram(k.as_mut(), at);
    }
    let k_norm = lower_frobenius(k.as_ref());
    let par = Par::Seq;
    let info = cholesky_in_place(
        k.as_mut(),
        Default::default(),
        par,
        MemStack::new(&mut MemBuffer::new(cholesky_in_place_scratch::<f64>(
            n,
            par,
            Default::default(),
        ))),
        Default::default(),
    );
    info.ok()?;
    let l = Mat::from_fn(n, n, |i, j| if i >= j { k[(i, j)] } else { 0.0 });
    let mut l_inv = Mat::<f64>::zeros(n, n);
    invert_lower_triangular(l_inv.as_mut(), l.as_ref(), par);
    // K^{-1} = L^{-T} L^{-1}; its lower triangle suffices for the norm.
    let mut k_inv = Mat::<f64>::zeros(n, n);
    matmul(
        k_inv.as_mut(),
        BlockStructure::TriangularLower,
        Accum::Replace,
        l_inv.transpose(),
        BlockStructure::TriangularUpper,
        l_inv.as_ref(),
        BlockStructure::TriangularLower,
        1.0,
        par,
    );
    let kappa = k_norm * lower_frobenius(k_inv.as_ref());
    if !kappa.is_finite() {
        return None;
    }
    Some((l.transpose().to_owned(), kappa))
}

/// `||S||_F` of the symmetric matrix whose lower triangle `s` holds.
fn lower_frobenius(s: MatRef<'_, f64>) -> f64 {
    let mut sum = 0.0;
    for j in 0..s.ncols() {
        sum += s[(j, j)] * s[(j, j)];
        sum += 2.0 * s.col(j).subrows(j + 1, s.nrows() - j - 1).squared_norm_l2();
    }
    sum.sqrt()
}

/// The lower triangle of `a^T a` into `dst` (`N x N`; the strict upper part is left).
fn lower_gram(dst: MatMut<'_, f64>, a: MatRef<'_, f64>) {
    matmul(
        dst,
        BlockStructure::TriangularLower,
        Accum::Replace,
        a.transpose(),
        BlockStructure::Rectangular,
        a,
        BlockStructure::Rectangular,
        1.0,
        Par::Seq,
    );
}

/// `min |R_ii| / max |R_ii|` (0 for a zero diagonal).
fn diagonal_ratio(r: MatRef<'_, f64>) -> f64 {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0_f64);
    for i in 0..r.nrows() {
        lo = lo.min(r[(i, i)].abs());
        hi = hi.max(r[(i, i)].abs());
    }
    if hi > 0.0 { lo / hi } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::Projection;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn samples(n: usize, m: usize, seed: u64) -> Mat<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        Mat::from_fn(n, m, |_, _| rng.random::<f64>())
    }

    fn max_abs(a: MatRef<'_, f64>) -> f64 {
        a.col_iter()
            .flat_map(|c| c.iter().copied())
            .fold(0.0, |m: f64, v| m.max(v.abs()))
    }

    /// The prediction weights `R^{-1} Q_1^T b(u)` of `factor` at the scaled queries `u`
    /// (`Q x m`), through the fast projection as a prediction computes them.
    fn weights(factor: &Factor, unit: MatRef<'_, f64>, u: MatRef<'_, f64>) -> Mat<f64> {
        let o = ErbfOptions::default();
        let projection = Projection::new(factor.rows.clone(), unit, &o);
        let rows: Vec<f64> = (0..u.nrows())
            .flat_map(|i| (0..u.ncols()).map(move |j| u[(i, j)]))
            .collect();
        let mut w = Mat::<f64>::zeros(unit.nrows(), u.nrows());
        projection.project(&rows, w.as_mut());
        orthonormalise(factor.kind, factor.r.as_ref(), w.as_mut());
        solve_upper_triangular_in_place(factor.r.as_ref(), w.as_mut(), Par::Seq);
        w
    }

    #[test]
    fn gram_and_qr_routes_give_the_same_triangle_weights_and_coefficients() {
        let o = ErbfOptions::default();
        for (n, m, seed) in [(40, 6, 1), (150, 10, 2), (60, 8, 3)] {
            let unit = samples(n, m, seed);
            let gram = Factor::new(unit.as_ref(), &o, true).unwrap();
            assert_eq!(gram.kind, Rows::Basis, "N = {n}, m = {m}");
            let at = basis_matrix_t(unit.as_ref(), unit.as_ref(), &o);
            let ThinQr { q1, r } = thin_qr(at.clone(), false);
            let qr = Factor {
                rows: q1,
                kind: Rows::Orthonormal,
                ratio: diagonal_ratio(r.as_ref()),
                r,
            };
            // R_gram = D R_qr with D = diag(sign(R_qr,ii)).
            let scale = max_abs(qr.r.as_ref());
            for i in 0..n {
                let sign = qr.r[(i, i)].signum();
                for j in 0..n {
                    let err = (gram.r[(i, j)] - sign * qr.r[(i, j)]).abs() / scale;
                    assert!(err < 1e-12, "R at ({i}, {j}): {err:e}");
                }
            }
            assert!((gram.ratio - qr.ratio).abs() < 1e-12 * qr.ratio);
            let queries = Mat::from_fn(30, m, |i, j| {
                if i < 5 {
                    unit[(i, j)]
                } else {
                    ((i * 7 + j * 3) % 17) as f64 / 12.0 - 0.2
                }
            });
            let (wg, wq) = (
                weights(&gram, unit.as_ref(), queries.as_ref()),
                weights(&qr, unit.as_ref(), queries.as_ref()),
            );
            let scale = max_abs(wq.as_ref());
            let err = max_abs((&wg - &wq).as_ref()) / scale;
            assert!(err < 1e-10, "weights: {err:e}");
            // At a training sample the weights are the unit vector: interpolation.
            for i in 0..5 {
                for k in 0..n {
                    let e = if k == i { 1.0 } else { 0.0 };
                    assert!((wg[(k, i)] - e).abs() < 1e-10, "sample {i}, weight {k}");
                }
            }
            let z = Mat::from_fn(n, 2, |i, j| (i + 3 * j) as f64 / n as f64);
            let (cg, cq) = (
                q1_times(gram.kind, gram.rows.as_ref(), gram.r.as_ref(), {
                    let mut z = z.clone();
                    solve_lower_triangular_in_place(gram.r.transpose(), z.as_mut(), Par::Seq);
                    z
                }),
                q1_times(qr.kind, qr.rows.as_ref(), qr.r.as_ref(), {
                    let mut z = z.clone();
                    solve_lower_triangular_in_place(qr.r.transpose(), z.as_mut(), Par::Seq);
                    z
                }),
            );
            // The minimum-norm coefficients c = A^T K^{-1} F solve A c = F.
            let err = max_abs((&cg - &cq).as_ref()) / max_abs(cq.as_ref());
            assert!(err < 1e-10, "coefficients: {err:e}");
            let back = at.transpose() * &cg;
            assert!(max_abs((&back - &z).as_ref()) < 1e-10);
        }
    }

    #[test]
    fn the_condition_bound_is_an_upper_bound_and_ill_conditioned_samples_take_the_qr_route() {
        let o = ErbfOptions::default();
        for (n, m, seed) in [(30, 6, 4), (60, 8, 5), (30, 2, 7)] {
            let mut unit = samples(n, m, seed);
            for close in [None, Some(1e-3), Some(1e-6)] {
                if let Some(d) = close {
                    for j in 0..m {
                        unit[(1, j)] = unit[(0, j)] + d;
                    }
                }
                let at = basis_matrix_t(unit.as_ref(), unit.as_ref(), &o);
                let k = at.transpose() * &at;
                let eig = k.self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
                let exact = eig[eig.len() - 1] / eig[0];
                let factor = Factor::new(unit.as_ref(), &o, true).unwrap();
                match gram_factor(at.as_ref(), true) {
                    Some((_, bound)) => {
                        // Where the eigenvalues themselves are resolved.
                        if exact < 1e10 {
                            assert!(bound >= exact * (1.0 - 1e-6), "{bound:e} < {exact:e}");
                        }
                        let expected = if bound <= GRAM_CONDITION_LIMIT {
                            Rows::Basis
                        } else {
                            Rows::Orthonormal
                        };
                        assert_eq!(factor.kind, expected, "{close:?}: bound {bound:e}");
                    }
                    None => assert_eq!(factor.kind, Rows::Orthonormal),
                }
                if close == Some(1e-6) {
                    assert_eq!(factor.kind, Rows::Orthonormal, "kappa(K) = {exact:e}");
                }
                if close.is_none() && m > 2 {
                    assert_eq!(factor.kind, Rows::Basis, "kappa(K) = {exact:e}");
                }
            }
        }
    }

    #[test]
    fn the_factor_is_the_same_on_one_and_two_threads() {
        let o = ErbfOptions::default();
        let unit = samples(150, 10, 6);
        let on = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| Factor::new(unit.as_ref(), &o, true).unwrap())
        };
        let (one, two) = (on(1), on(2));
        assert_eq!(one.kind, Rows::Basis);
        assert!(one.r == two.r && one.rows == two.rows);
    }
}
