//! The extended radial basis function (ERBF) metamodel of Mullur and Messac.
//!
//! Inputs are first mapped to the unit cube by the bounds of a [`ParameterSpace`],
//! `x^j = (q^j - lo_j) / (hi_j - lo_j)`; the widths `r_c` and `gamma` are meant in that
//! scaled space. With samples `x_1..x_N` and `m` inputs the model is
//!
//! ```text
//! f(x) = sum_i sigma_i psi_i(x)
//!      + sum_i sum_j [ aL_ij phi_L(xi_ij) + aR_ij phi_R(xi_ij) + b_ij xi_ij ],
//! psi_i(x) = exp(-|x - x_i|^2 / (2 r_c^2)),   xi_ij = x^j - x_i^j,
//! ```
//!
//! with `phi_L`, `phi_R` the non-radial functions of [`crate::nrbf`]: `M = N (3 m + 1)`
//! coefficients for `N` interpolation conditions. Writing `b(x)` for the `M` basis values
//! (radial first, then ordered by sample `i`, input `j` and `{L, R, beta}`, each family
//! multiplied by its weight of [`FamilyWeights`](crate::FamilyWeights)), the conditions
//! read `A c = F` with `A` the `N x M` matrix whose row `k` is `b(x_k)^T`, and `F` the
//! `N x T` responses.
//!
//! The system is under-determined; the fit takes its minimum-norm solution
//! `c = A^T (A A^T)^{-1} F` through a triangular factor `A A^T = R^T R` (`R` is `N x N`
//! upper triangular) and never forms `c` for long histories. The factor comes by one of two
//! routes (see `factor.rs`):
//! - usually the Gram route: the kernel matrix `K = A A^T` and its Cholesky factor, when a
//!   bound on `kappa(K)` shows that the squared conditioning costs at most `2.2e-10` in
//!   relative accuracy; the `M x N` matrix `P` the model keeps is `A^T` itself, and
//!   `Q_1 = A^T R^{-1}`;
//! - otherwise a Householder QR factorisation `A^T = Q_1 R` (`Q_1` is `M x N` with
//!   orthonormal columns; computed by a two-block TSQR), which keeps `P = Q_1`.
//!
//! Either way `c = Q_1 Z` with `R^T Z = F`. One factorisation serves all `T` columns, and
//! the solution is linear in `F`.
//!
//! A prediction is `f(x) = (Q_1^T b(x))^T Z = (R^{-1} Q_1^T b(x))^T F`. For time histories
//! (`T >> N`) the model keeps `P`, `R` and `F` and never forms `c` (`M x T`) or `Z`: per
//! query it computes `P^T b(x)` from prefix sums of the rows of `P` tabulated at fit time,
//! which the piecewise-linear N-RBFs allow (about `N^2 + 2 gamma m N^2` operations instead
//! of the `M N` of the direct product), turns it into `w = Q_1^T b(x)` (a solve with `R^T`
//! on the Gram route, `N^2 / 2`), solves `R v = w` (`N^2 / 2`), and takes `v^T F` (`N T`).
//! The fit costs one factorisation and no work proportional to `T` beyond copying `F`. When
//! `T` is so small that `b(x)^T c` is cheaper, the model stores `c` instead.
//!
//! With [`ErbfOptions::smoothing`] above zero the model stops interpolating and solves the
//! ridge problem of `smoothing.rs`: the solves with `R` become filters on its
//! singular values.

use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Accum, Mat, MatMut, MatRef, Par};
use impactcal_core::{ParamGuard, ParameterSpace};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::basis::{basis_gradient, basis_matrix_t, fill_basis, row_major};
use crate::buffer::{self, TrainingValues};
use crate::data::{
    StoredMat, check_queries, check_training, collect_rows, reject_duplicates, without_row,
};
use crate::error::{ErbfError, Result};
use crate::factor::{Factor, Rows, orthonormalise, q1_times};
use crate::loo::LooMethod;
use crate::options::{ErbfOptions, ValidErbfOptions};
use crate::projection::Projection;
use crate::rbf::{condition_number, relative_max_error};
use crate::smoothing::RSvd;

/// A fitted ERBF model of `T` outputs over a parameter space of `m` inputs.
///
/// Serialises as its space, options and training data; a deserialised model is refitted
/// (milliseconds) and predicts the same.
#[derive(Debug, Clone)]
pub struct Erbf {
    space: ParameterSpace,
    options: ValidErbfOptions,
    points: Mat<f64>,
    unit: Mat<f64>,
    values: Mat<f64>,
    mean: Vec<f64>,
    /// The tables that evaluate `P^T b(x)` quickly, for the fit's `M x N` factor `P`
    /// (`Q_1` or `A^T`, see [`Rows`]).
    projection: Projection,
    /// What `P` is.
    rows: Rows,
    r: Mat<f64>,
    /// The responses less their column means, kept only when outputs are centred.
    centred: Option<Mat<f64>>,
    /// `c = Q_1 Z` (`M x T`), kept when `T` is so small that `b(x)^T c` is the cheaper
    /// prediction (see [`direct_is_cheaper`]).
    coef: Option<Mat<f64>>,
    r_ratio: f64,
    /// With smoothing: the SVD of `R` and the absolute ridge `lambda`
    /// (`smoothing.rs`).
    smoother: Option<Box<(RSvd, f64)>>,
}

impl Erbf {
    /// Fits the model to samples `points` (`N x m`, raw parameter values, one sample per
    /// row, columns in the order of `space`) and responses `values` (`N x T`, one row per
    /// sample). Takes [`ErbfOptions`] (checked here) or [`ValidErbfOptions`]. The model
    /// keeps the responses: lent (`MatRef`, `&Mat`) they are copied, given (`Mat`) they
    /// are moved in ([`TrainingValues`]; a failed fit drops them with its error).
    ///
    /// Cost: `O(N^2 m)` to build `A`, `O(M N^2)` to factorise (`M N^2 / 2` multiply-adds
    /// on the Gram route, four times that on the QR route), `O(m N^2)` for the
    /// prediction tables, a copy of `values` when lent, and a centred copy when outputs
    /// are centred; `O(N^2 T)` more only when `T` is small enough that the coefficients
    /// `c` are stored.
    ///
    /// # Errors
    /// Under [`ErbfError::Core`]:
    /// - [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) for invalid
    ///   options;
    /// - [`CoreError::Empty`](impactcal_core::CoreError::Empty) for `N = 0`;
    /// - [`CoreError::DimensionMismatch`](impactcal_core::CoreError::DimensionMismatch) when
    ///   `points` has not `m` columns or `values` has not `N` rows;
    /// - [`CoreError::NonFinite`](impactcal_core::CoreError::NonFinite) for NaN or infinite
    ///   entries, naming row and column.
    ///
    /// And [`ErbfError::DuplicateSamples`] for two samples closer than the tolerance in
    /// scaled inputs, naming both; [`ErbfError::Singular`] when `min |R_ii| / max |R_ii|`
    /// falls below `N eps` without smoothing (with smoothing the problem stays well posed).
    pub fn fit<'a>(
        space: &ParameterSpace,
        points: MatRef<'_, f64>,
        values: impl Into<TrainingValues<'a>>,
        options: impl ParamGuard<Checked = ValidErbfOptions>,
    ) -> Result<Self> {
        let options = options.check()?;
        let training = values.into();
        let values = training.view();
        check_training(points, values, Some(space.dim()))?;
        let unit = space.to_unit_matrix(points)?;
        reject_duplicates(unit.as_ref(), options.duplicate_tolerance)?;
        let t = values.ncols();
        let centre = options.center_outputs || options.smoothing > 0.0;
        let mean: Vec<f64> = if centre {
            (0..t)
                .map(|c| values.col(c).iter().sum::<f64>() / values.nrows() as f64)
                .collect()
        } else {
            vec![0.0; t]
        };
        let centred = centre.then(|| {
            let mut f = buffer::copy(values);
            for (col, &m) in f.col_iter_mut().zip(&mean) {
                col.iter_mut().for_each(|v| *v -= m);
            }
            f
        });
        let factor = Factor::new(unit.as_ref(), &options, true)?;
        let smoother = if options.smoothing > 0.0 {
            let svd = RSvd::new(factor.r.as_ref())?;
            let lambda = svd.lambda(options.smoothing);
            Some(Box::new((svd, lambda)))
        } else {
            None
        };
        let coef = direct_is_cheaper(unit.nrows(), unit.ncols(), t, options.gamma).then(|| {
            let mut z = centred.as_ref().map_or(values, |f| f.as_ref()).to_owned();
            solve_rt(factor.r.as_ref(), smoother.as_deref(), z.as_mut());
            q1_times(factor.kind, factor.rows.as_ref(), factor.r.as_ref(), z)
        });
        let projection = Projection::new(factor.rows, unit.as_ref(), &options);
        Ok(Erbf {
            space: space.clone(),
            options,
            points: points.to_owned(),
            unit,
            values: training.into_owned(),
            mean,
            projection,
            rows: factor.kind,
            r: factor.r,
            centred,
            coef,
            r_ratio: factor.ratio,
            smoother,
        })
    }

    /// Fits one output from rows of raw parameter values.
    ///
    /// # Errors
    /// As [`fit`](Self::fit);
    /// [`CoreError::DimensionMismatch`](impactcal_core::CoreError::DimensionMismatch) for
    /// ragged rows or a `values` length different from the number of rows.
    pub fn fit_rows(
        space: &ParameterSpace,
        points: &[Vec<f64>],
        values: &[f64],
        options: impl ParamGuard<Checked = ValidErbfOptions>,
    ) -> Result<Self> {
        let x = crate::data::mat_from_rows(points, "training points")?;
        let f = MatRef::from_column_major_slice(values, values.len(), 1);
        Self::fit(space, x.as_ref(), f, options)
    }

    /// The parameter space whose bounds scale the inputs.
    pub fn space(&self) -> &ParameterSpace {
        &self.space
    }

    /// The options.
    pub fn options(&self) -> &ErbfOptions {
        &self.options
    }

    /// Number of inputs `m`.
    pub fn dim(&self) -> usize {
        self.points.ncols()
    }

    /// Number of training samples `N`.
    pub fn n_samples(&self) -> usize {
        self.points.nrows()
    }

    /// Number of outputs `T`.
    pub fn n_outputs(&self) -> usize {
        self.values.ncols()
    }

    /// Number of basis functions (coefficients per output), `M = N (3 m + 1)`.
    pub fn n_basis(&self) -> usize {
        self.n_samples() * (3 * self.dim() + 1)
    }

    /// The training points (raw), `N x m`.
    pub fn points(&self) -> MatRef<'_, f64> {
        self.points.as_ref()
    }

    /// The training responses, `N x T`.
    pub fn values(&self) -> MatRef<'_, f64> {
        self.values.as_ref()
    }

    /// The interpolation matrix `A` (`N x M`, row `k` = `b(x_k)^T`), rebuilt on demand.
    pub fn interpolation_matrix(&self) -> Mat<f64> {
        basis_matrix_t(self.unit.as_ref(), self.unit.as_ref(), &self.options)
            .transpose()
            .to_owned()
    }

    /// The coefficients `c = Q_1 Z` (`M x T`) with `R^T Z = F` (`Q_1 = A^T R^{-1}` on the
    /// Gram route), formed on demand (`O(M N T)` time and `M T` memory; large for long
    /// histories).
    pub fn coefficients(&self) -> Mat<f64> {
        match &self.coef {
            Some(c) => c.clone(),
            None => q1_times(self.rows, self.projection.rows(), self.r.as_ref(), self.z()),
        }
    }

    /// Keeps only the first `k` outputs (`k` capped at `T`): the model of those columns,
    /// without refitting (every output column is solved independently with the same
    /// factorisation).
    pub(crate) fn keep_outputs(&mut self, k: usize) {
        let k = k.min(self.n_outputs());
        self.values = self.values.subcols(0, k).to_owned();
        self.mean.truncate(k);
        if let Some(c) = &mut self.centred {
            *c = c.subcols(0, k).to_owned();
        }
        if let Some(c) = &mut self.coef {
            *c = c.subcols(0, k).to_owned();
        }
    }

    /// `Z = R^{-T} F` (`N x T`), formed on demand.
    fn z(&self) -> Mat<f64> {
        let mut z = self.responses().to_owned();
        solve_rt(self.r.as_ref(), self.smoother.as_deref(), z.as_mut());
        z
    }

    /// The responses the model interpolates: `F`, less the column means when centred.
    fn responses(&self) -> MatRef<'_, f64> {
        self.centred
            .as_ref()
            .map_or(self.values.as_ref(), |f| f.as_ref())
    }

    /// `min |R_ii| / max |R_ii|` of the factor `A A^T = R^T R`: a cheap conditioning
    /// indicator (near `1e-16` means `A` is close to rank deficient).
    pub fn r_diagonal_ratio(&self) -> f64 {
        self.r_ratio
    }

    /// The 2-norm condition number of `A` (the ratio of the extreme singular values of
    /// `R`), computed on demand in `O(N^3)`.
    ///
    /// # Errors
    /// [`ErbfError::Singular`] when the singular value decomposition does not converge.
    pub fn condition_number(&self) -> Result<f64> {
        condition_number(self.r.as_ref())
    }

    /// Whether `x` (raw) lies outside the bounds of the parameter space, where the model
    /// extrapolates linearly.
    pub fn is_outside(&self, x: &[f64]) -> bool {
        !self.space.contains(x)
    }

    /// The prediction at `x` (raw parameters): `T` values.
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`](impactcal_core::CoreError::DimensionMismatch) or
    /// [`CoreError::NonFinite`](impactcal_core::CoreError::NonFinite) for a bad `x`.
    pub fn predict(&self, x: &[f64]) -> Result<Vec<f64>> {
        let out = self.predict_batch(MatRef::from_row_major_slice(x, 1, x.len()))?;
        Ok(out.row(0).iter().copied().collect())
    }

    /// Predictions at the rows of `points` (`Q x m`, raw): a `Q x T` matrix.
    ///
    /// The queries are processed in fixed chunks of 64, in parallel: for each chunk the
    /// projected basis `W = Q_1^T B` (`N x 64`) is evaluated from the fit's tables (with a
    /// solve by `R^T` on the Gram route) and `V = R^{-1} W` solved; one product `V^T F`
    /// then gives all `T` outputs. Cost about `Q (N^2 (1 + 2 gamma m) + N T)`; memory
    /// `Q N` besides the result. When the model stores `c` (few outputs) each chunk
    /// multiplies `B^T c` directly. The product is taken in fixed blocks of 512 output
    /// columns, one task each, which also adds the mean and writes its block of the result
    /// once. The result does not depend on the number of threads.
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`](impactcal_core::CoreError::DimensionMismatch) or
    /// [`CoreError::NonFinite`](impactcal_core::CoreError::NonFinite) for bad points.
    pub fn predict_batch(&self, points: MatRef<'_, f64>) -> Result<Mat<f64>> {
        check_queries(points, self.dim())?;
        let q = points.nrows();
        let m = self.dim();
        let unit = row_major(self.space.to_unit_matrix(points)?.as_ref());
        let out = match &self.coef {
            Some(c) => {
                let mut out = buffer::zeros(q, self.n_outputs());
                let centres = row_major(self.unit.as_ref());
                out.par_row_chunks_mut(CHUNK)
                    .enumerate()
                    .for_each(|(k, mut rows)| {
                        let len = rows.nrows();
                        let u = &unit[k * CHUNK * m..(k * CHUNK + len) * m];
                        let mut bt = Mat::<f64>::zeros(self.n_basis(), len);
                        fill_basis(u, &centres, m, &self.options, bt.as_mut());
                        matmul(
                            rows.as_mut(),
                            Accum::Replace,
                            bt.transpose(),
                            c.as_ref(),
                            1.0,
                            Par::Seq,
                        );
                    });
                add_means(out.as_mut(), &self.mean);
                out
            }
            None => {
                // V = R^{-1} Q_1^T B chunk by chunk, then out = V^T F: the same as
                // B^T Q_1 Z with Z = R^{-T} F, without forming Z (N x T).
                let mut v = Mat::<f64>::zeros(self.n_samples(), q);
                v.par_col_chunks_mut(CHUNK)
                    .enumerate()
                    .for_each(|(k, mut cols)| {
                        let len = cols.ncols();
                        let u = &unit[k * CHUNK * m..(k * CHUNK + len) * m];
                        self.projection.project(u, cols.as_mut());
                        orthonormalise(self.rows, self.r.as_ref(), cols.as_mut());
                        solve_r(self.r.as_ref(), self.smoother.as_deref(), cols);
                    });
                // out = V^T F + 1 mean^T in fixed blocks of output columns, one rayon task
                // each with a sequential product: no thread waits for another at a barrier
                // (which on a loaded machine costs more than the product), each block is
                // written once while in cache, and the result does not depend on the
                // number of threads.
                let f = self.responses();
                buffer::by_column_blocks(
                    q,
                    self.n_outputs(),
                    buffer::RESULT_BLOCK,
                    |first, mut cols| {
                        let len = cols.ncols();
                        matmul(
                            cols.as_mut(),
                            Accum::Replace,
                            v.transpose(),
                            f.subcols(first, len),
                            1.0,
                            Par::Seq,
                        );
                        add_means(cols, &self.mean[first..first + len]);
                    },
                )
            }
        };
        Ok(out)
    }

    /// The gradient of every output with respect to the raw parameters at `x`: a `T x m`
    /// matrix whose row `t` is `grad f_t(x)`.
    ///
    /// With `u` the scaled input, `d psi_i / d u^j = -(u^j - x_i^j) / r_c^2 psi_i`, the
    /// N-RBF derivatives of [`crate::nrbf`], `d xi / d u^j = 1`, and the chain rule
    /// `d / d q^j = (1 / (hi_j - lo_j)) d / d u^j`.
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`](impactcal_core::CoreError::DimensionMismatch) or
    /// [`CoreError::NonFinite`](impactcal_core::CoreError::NonFinite) for a bad `x`.
    pub fn predict_gradient(&self, x: &[f64]) -> Result<Mat<f64>> {
        check_queries(MatRef::from_row_major_slice(x, 1, x.len()), self.dim())?;
        let m = self.dim();
        let u = self.space.to_unit(x)?;
        let db = basis_gradient(&u, self.unit.as_ref(), &self.options);
        let mut g = Mat::<f64>::zeros(m, self.n_outputs());
        self.apply(db.as_ref(), g.as_mut());
        let p = self.space.parameters();
        Ok(Mat::from_fn(self.n_outputs(), m, |t, j| {
            g[(j, t)] / p[j].width()
        }))
    }

    /// Leave-one-out errors `e_kt = F_kt - f^{(-k)}_t(x_k)`, an `N x T` matrix.
    ///
    /// [`LooMethod::Refit`] is exact: for each `k` the model is refitted without sample `k`
    /// and its basis functions (`O(M N^2 + N T)` per sample, in parallel).
    /// [`LooMethod::Closed`] uses the kernel view `G = A A^T = R^T R`:
    /// `e_k ~ (G^{-1} F)_k / (G^{-1})_kk`, `O(N^3 + N^2 T)`; it is approximate because the
    /// basis functions centred at `x_k` stay in the model. [`LooMethod::Auto`] refits up to
    /// 200 samples.
    ///
    /// # Errors
    /// [`ErbfError::LooUndefined`] for a single sample, or when a reduced problem is
    /// singular.
    pub fn loo_errors(&self, method: LooMethod) -> Result<Mat<f64>> {
        let n = self.n_samples();
        let t = self.n_outputs();
        if n < 2 {
            return Err(ErbfError::LooUndefined {
                sample: 0,
                message: "needs at least two samples".into(),
            });
        }
        let exact = match method {
            LooMethod::Refit => true,
            LooMethod::Closed => false,
            LooMethod::Auto => n <= 200,
        };
        let f = self.responses();
        if !exact {
            if let Some((svd, lambda)) = self.smoother.as_deref() {
                return svd.loo(*lambda, f);
            }
            // alpha = G^{-1} F = R^{-1} Z; (G^{-1})_kk = |row k of R^{-1}|^2.
            let mut rinv = Mat::<f64>::identity(n, n);
            solve_upper_triangular_in_place(self.r.as_ref(), rinv.as_mut(), par());
            let mut alpha = self.z();
            solve_upper_triangular_in_place(self.r.as_ref(), alpha.as_mut(), par());
            return Ok(Mat::from_fn(n, t, |k, c| {
                let h: f64 = rinv.row(k).iter().map(|v| v * v).sum();
                alpha[(k, c)] / h
            }));
        }
        let rows: Vec<Result<Vec<f64>>> = (0..n)
            .into_par_iter()
            .map(|k| {
                let undefined = |message: String| ErbfError::LooUndefined { sample: k, message };
                let unit = without_row(self.unit.as_ref(), k);
                let factor = Factor::new(unit.as_ref(), &self.options, false)
                    .map_err(|e| undefined(e.to_string()))?;
                let uk = Mat::from_fn(1, self.dim(), |_, j| self.unit[(k, j)]);
                let b = basis_matrix_t(uk.as_ref(), unit.as_ref(), &self.options);
                // w = R^{-1} Q_1^T b (filtered with smoothing, the same lambda), so that
                // f^{(-k)}(x_k) = F_{-k}^T w.
                let mut w = factor.rows.transpose() * &b;
                orthonormalise(factor.kind, factor.r.as_ref(), w.as_mut());
                let smoother = match self.smoother.as_deref() {
                    Some((_, lambda)) => Some((
                        RSvd::new(factor.r.as_ref()).map_err(|e| undefined(e.to_string()))?,
                        *lambda,
                    )),
                    None => None,
                };
                solve_r(factor.r.as_ref(), smoother.as_ref(), w.as_mut());
                let fk = without_row(f.as_ref(), k);
                Ok((0..t)
                    .map(|c| {
                        let p: f64 = (0..n - 1).map(|i| fk[(i, c)] * w[(i, 0)]).sum();
                        f[(k, c)] - p
                    })
                    .collect())
            })
            .collect();
        collect_rows(rows, t)
    }

    /// The SVD of this fit's triangular factor, which scores every smoothing with
    /// [`loo_smoothed`](Self::loo_smoothed).
    pub(crate) fn r_svd(&self) -> Result<RSvd> {
        match self.smoother.as_deref() {
            Some((svd, _)) => Ok(svd.clone()),
            None => RSvd::new(self.r.as_ref()),
        }
    }

    /// Closed-form (kernel-view) leave-one-out errors of the model with the same basis and
    /// `smoothing > 0` instead of this fit's: centred outputs, `svd` from
    /// [`r_svd`](Self::r_svd). Equal to `loo_errors(LooMethod::Closed)` of that model,
    /// without refitting it.
    pub(crate) fn loo_smoothed(&self, svd: &RSvd, smoothing: f64) -> Result<Mat<f64>> {
        let (n, t) = self.values.shape();
        let mut f = self.values.clone();
        for c in 0..t {
            let m = f.col(c).iter().sum::<f64>() / n as f64;
            f.col_mut(c).iter_mut().for_each(|v| *v -= m);
        }
        svd.loo(svd.lambda(smoothing), f.as_ref())
    }

    /// `max_k |f(x_k) - F_k| / max |F|` over all outputs: the reproduction error of the
    /// training data (near `1e-14` for a well-posed fit without smoothing).
    pub fn training_residual(&self) -> f64 {
        match self.predict_batch(self.points.as_ref()) {
            Ok(p) => relative_max_error(p.as_ref(), self.values.as_ref()),
            Err(_) => f64::NAN,
        }
    }

    /// `out = B^T c` for a block of basis vectors `B` (`M x Q`), through the stored `c` or
    /// as `(R^{-1} Q_1^T B)^T F`.
    fn apply(&self, bt: MatRef<'_, f64>, out: faer::MatMut<'_, f64>) {
        match &self.coef {
            Some(c) => matmul(out, Accum::Replace, bt.transpose(), c.as_ref(), 1.0, par()),
            None => {
                let mut v = self.projection.rows().transpose() * bt;
                orthonormalise(self.rows, self.r.as_ref(), v.as_mut());
                solve_r(self.r.as_ref(), self.smoother.as_deref(), v.as_mut());
                matmul(
                    out,
                    Accum::Replace,
                    v.transpose(),
                    self.responses(),
                    1.0,
                    par(),
                );
            }
        }
    }
}

/// `w <- R^{-1} w`, or its filtered form with smoothing ([`RSvd::solve`]).
fn solve_r(r: MatRef<'_, f64>, smoother: Option<&(RSvd, f64)>, w: faer::MatMut<'_, f64>) {
    match smoother {
        Some((svd, lambda)) => svd.solve(*lambda, w),
        None => solve_upper_triangular_in_place(r, w, Par::Seq),
    }
}

/// `z <- R^{-T} z`, or its filtered form with smoothing ([`RSvd::solve_transpose`]).
fn solve_rt(r: MatRef<'_, f64>, smoother: Option<&(RSvd, f64)>, z: faer::MatMut<'_, f64>) {
    match smoother {
        Some((svd, lambda)) => svd.solve_transpose(*lambda, z),
        None => solve_lower_triangular_in_place(r.transpose(), z, par()),
    }
}

/// Whether predicting `T` outputs as `b(x)^T c` (`M (T + 1)` operations per query) is
/// cheaper than through the projection, `w = Q_1^T b(x)` then `w^T Z` (about
/// `N^2 + m N (2 gamma N + 4) + N T`).
fn direct_is_cheaper(n: usize, m: usize, t: usize, gamma: f64) -> bool {
    let (n, m, t) = (n as f64, m as f64, t as f64);
    let direct = n * (3.0 * m + 1.0) * (t + 1.0);
    let projected = n * n + m * n * ((2.0 * gamma).min(1.0) * n + 4.0) + n * t;
    direct <= projected
}

/// Queries per chunk of batch prediction (fixed, so results do not depend on threads).
const CHUNK: usize = 64;

/// Adds `means[j]` to column `j` of `out` (the columns whose mean is zero are left alone).
fn add_means(out: MatMut<'_, f64>, means: &[f64]) {
    for (col, &mean) in out.col_iter_mut().zip(means) {
        if mean != 0.0 {
            col.iter_mut().for_each(|v| *v += mean);
        }
    }
}

fn par() -> Par {
    faer::get_global_parallelism()
}

/// The serialised form of an [`Erbf`]: space, options and training data.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct ErbfData {
    space: ParameterSpace,
    options: ErbfOptions,
    points: StoredMat,
    values: StoredMat,
}

impl Serialize for Erbf {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        ErbfData {
            space: self.space.clone(),
            options: *self.options,
            points: StoredMat::from_mat(self.points.as_ref()),
            values: StoredMat::from_mat(self.values.as_ref()),
        }
        .serialize(s)
    }
}

impl<'de> Deserialize<'de> for Erbf {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let data = ErbfData::deserialize(d)?;
        let build = || -> Result<Self> {
            let points = data.points.to_mat("points")?;
            let values = data.values.to_mat("values")?;
            Erbf::fit(&data.space, points.as_ref(), values.as_ref(), data.options)
        };
        build().map_err(serde::de::Error::custom)
    }
}
