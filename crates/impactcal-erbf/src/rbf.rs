//! Classic radial basis function interpolants with a polynomial tail.
//!
//! Given `N` distinct points `x_k` in `R^d` and values `F` (`N x T`, one column per output),
//! the interpolant is
//!
//! ```text
//! s(x) = sum_i c_i phi(|x - x_i|) + sum_l a_l p_l(x)
//! ```
//!
//! with `p_l` the constant and (for a linear tail) the coordinates, and the coefficients
//! solving the augmented system
//!
//! ```text
//! [ K + lambda I   P ] [c]   [F]
//! [ P^T            0 ] [a] = [0]
//! ```
//!
//! where `K_ki = phi(|x_k - x_i|)`, `P_kl = p_l(x_k)` and `lambda >= 0` is the smoothing.
//! The system is factorised once by LU with partial pivoting and serves every output
//! column. The polynomial is evaluated in centred and scaled coordinates and its columns
//! are weighted to the magnitude of `K`, which changes the coefficients but not the
//! interpolant, and keeps the pivots balanced.

use faer::linalg::matmul::matmul;
use std::sync::OnceLock;

use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_unit_lower_triangular_in_place,
    solve_unit_upper_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Accum, Mat, MatRef, Par};
use impactcal_core::{CoreError, ParamGuard};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::buffer::{self, TrainingValues};
use crate::data::{
    StoredMat, check_queries, check_training, collect_rows, find_duplicate, mat_from_rows,
    stack_rows, without_row,
};
use crate::error::{ErbfError, Result};
use crate::loo::LooMethod;
use crate::lu::Lu;
use crate::radial::{PolyDegree, RadialFunction};
use impactcal_core::error::dimension_mismatch;

/// Options of a classic RBF interpolant, checked into [`ValidRbfOptions`] (by
/// [`ParamGuard::check`], or by [`RbfInterpolant::fit`] itself) before they reach a fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RbfOptions {
    /// The radial function.
    #[serde(alias = "kernel")]
    pub radial: RadialFunction,
    /// The polynomial tail; must be at least [`RadialFunction::min_degree`].
    pub degree: PolyDegree,
    /// Smoothing `lambda >= 0` added to the diagonal of `K`; 0 interpolates exactly.
    pub smoothing: f64,
    /// Two points closer than this fraction of the diameter of the training set's bounding
    /// box are rejected as duplicates.
    pub duplicate_tolerance: f64,
}

impl RbfOptions {
    /// Options for the radial function `radial` with its minimum tail
    /// ([`RadialFunction::min_degree`]: linear for cubic and thin-plate, constant for
    /// multiquadric, none for Gaussian), no smoothing and a duplicate tolerance of `1e-10`.
    pub fn new(radial: RadialFunction) -> Self {
        RbfOptions {
            radial,
            degree: radial.min_degree(),
            smoothing: 0.0,
            duplicate_tolerance: 1e-10,
        }
    }

    /// Cubic radial function with a linear tail, the usual choice of surrogate optimisers.
    pub fn cubic() -> Self {
        Self::new(RadialFunction::Cubic)
    }

    /// Thin-plate spline with a linear tail.
    pub fn thin_plate() -> Self {
        Self::new(RadialFunction::ThinPlate)
    }

    /// The same options with another tail.
    #[must_use]
    pub fn with_degree(mut self, degree: PolyDegree) -> Self {
        self.degree = degree;
        self
    }

    /// The same options with smoothing `lambda`.
    #[must_use]
    pub fn with_smoothing(mut self, lambda: f64) -> Self {
        self.smoothing = lambda;
        self
    }
}

impl ParamGuard for RbfOptions {
    type Checked = ValidRbfOptions;

    /// Checks every option.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for a bad shape parameter of the radial function, a tail
    /// below its minimum, a negative or non-finite smoothing, or a negative duplicate
    /// tolerance.
    fn check_ref(&self) -> impactcal_core::Result<()> {
        self.radial.validate()?;
        if self.degree < self.radial.min_degree() {
            return Err(CoreError::invalid_option(
                "polynomial degree",
                self.degree.as_i32(),
                format!(
                    "the {:?} radial function needs a tail of degree at least {}",
                    self.radial,
                    self.radial.min_degree().as_i32()
                ),
            ));
        }
        if !(self.smoothing.is_finite() && self.smoothing >= 0.0) {
            return Err(CoreError::invalid_option(
                "smoothing",
                self.smoothing,
                "must be finite and non-negative",
            ));
        }
        if !(self.duplicate_tolerance.is_finite() && self.duplicate_tolerance >= 0.0) {
            return Err(CoreError::invalid_option(
                "duplicate tolerance",
                self.duplicate_tolerance,
                "must be finite and non-negative",
            ));
        }
        Ok(())
    }

    fn check(self) -> impactcal_core::Result<ValidRbfOptions> {
        ValidRbfOptions::checked(self)
    }
}

impactcal_core::valid_options! {
    /// [`RbfOptions`] that passed their checks: the only form a fit works with. Read the
    /// options through `Deref`; serialises as the plain options and is checked again when
    /// read.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct ValidRbfOptions(RbfOptions);
}

/// A fitted classic RBF interpolant of `T` outputs over `R^d`.
///
/// Build with [`fit`](Self::fit) (or [`fit_rows`](Self::fit_rows) for one output), grow
/// with [`add_points`](Self::add_points). Serialises as its options and training data; a
/// deserialised model is refitted, which reproduces the same predictions.
#[derive(Debug, Clone)]
pub struct RbfInterpolant {
    options: ValidRbfOptions,
    points: Mat<f64>,
    values: Mat<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    shift: Vec<f64>,
    /// Polynomial basis: `[w, w (x - shift) / scale]`.
    scale: f64,
    tail_weight: f64,
    system: Mat<f64>,
    lu: Lu,
    /// The coefficients `[c; a]` (`n x T`): solved at fit time when `T <= n`, on first
    /// use otherwise (see [`predict_batch`](Self::predict_batch)).
    coef: OnceLock<Mat<f64>>,
    pivot_ratio: f64,
}

impl RbfInterpolant {
    /// Fits the interpolant to `points` (`N x d`, one sample per row) and `values`
    /// (`N x T`, one output per column). The interpolant keeps the values: lent
    /// (`MatRef`, `&Mat`) they are copied, given (`Mat`) they are moved in
    /// ([`TrainingValues`]; a failed fit drops them with its error).
    ///
    /// Cost: `O(N^2 d)` to assemble, `O(n^3)` to factorise (`n = N + ` tail terms), and
    /// `O(n^2 T)` to solve for the coefficients when `T <= n`; for longer outputs the
    /// coefficients are not formed (see [`predict_batch`](Self::predict_batch)) and are
    /// solved for only if [`radial_weights`](Self::radial_weights),
    /// [`tail_coefficients`](Self::tail_coefficients) or the closed-form leave-one-out
    /// errors ask for them.
    ///
    /// # Errors
    /// Takes [`RbfOptions`] (checked here) or [`ValidRbfOptions`].
    ///
    /// # Errors
    /// - [`CoreError::InvalidOption`] for invalid options;
    /// - [`CoreError::Empty`] for `N = 0`;
    /// - [`CoreError::DimensionMismatch`] when `values` has not `N` rows, or fewer samples
    ///   than tail terms;
    /// - [`CoreError::NonFinite`] for NaN or infinite entries (naming row and column);
    /// - [`ErbfError::DuplicateSamples`] for two (nearly) coincident points, naming both;
    /// - [`ErbfError::Singular`] when the factorisation has a pivot below `n * eps` of the
    ///   largest (for example points on a hyperplane with a linear tail).
    ///
    /// The [`CoreError`]s come wrapped as [`ErbfError::Core`].
    pub fn fit<'a>(
        points: MatRef<'_, f64>,
        values: impl Into<TrainingValues<'a>>,
        options: impl ParamGuard<Checked = ValidRbfOptions>,
    ) -> Result<Self> {
        let options = options.check()?;
        let values = values.into();
        check_training(points, values.view(), None)?;
        let d = points.ncols();
        let q = options.degree.terms(d);
        if points.nrows() < q {
            return Err(dimension_mismatch(
                format!(
                    "number of samples for a tail of degree {} in {d} dimensions, at least",
                    options.degree.as_i32()
                ),
                q,
                points.nrows(),
            ));
        }
        let (lower, upper) = bounding_box(points);
        let diameter = distance(&lower, &upper);
        let tol = options.duplicate_tolerance * diameter;
        if let Some((first, second, distance)) = find_duplicate(points, tol) {
            return Err(ErbfError::DuplicateSamples {
                first,
                second,
                distance,
                tolerance: tol,
            });
        }
        let kernel_block = radial_matrix(&options, points);
        Self::assemble(
            options,
            points.to_owned(),
            values.into_owned(),
            kernel_block,
        )
    }

    /// Fits one output from rows: `points[k]` is sample `k` (all of length `d`) and
    /// `values[k]` its value.
    ///
    /// # Errors
    /// As [`fit`](Self::fit); [`CoreError::DimensionMismatch`] for ragged rows or a
    /// `values` length that differs from the number of points.
    pub fn fit_rows(
        points: &[Vec<f64>],
        values: &[f64],
        options: impl ParamGuard<Checked = ValidRbfOptions>,
    ) -> Result<Self> {
        let x = mat_from_rows(points, "training points")?;
        let f = MatRef::from_column_major_slice(values, values.len(), 1);
        Self::fit(x.as_ref(), f, options)
    }

    /// Builds the system from a kernel block `K + lambda I` of the given points, factorises
    /// and solves.
    fn assemble(
        options: ValidRbfOptions,
        points: Mat<f64>,
        values: Mat<f64>,
        kernel_block: Mat<f64>,
    ) -> Result<Self> {
        let n_pts = points.nrows();
        let d = points.ncols();
        let q = options.degree.terms(d);
        let n = n_pts + q;
        let (lower, upper) = bounding_box(points.as_ref());
        let shift: Vec<f64> = lower
            .iter()
            .zip(&upper)
            .map(|(l, u)| 0.5 * (l + u))
            .collect();
        let half_range = lower
            .iter()
            .zip(&upper)
            .map(|(l, u)| 0.5 * (u - l))
            .fold(0.0, f64::max);
        let scale = if half_range > 0.0 { half_range } else { 1.0 };
        let kmax = kernel_block
            .col_iter()
            .flat_map(|c| c.iter().copied())
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        let tail_weight = if kmax > 0.0 { kmax } else { 1.0 };

        let mut system = Mat::<f64>::zeros(n, n);
        system
            .as_mut()
            .submatrix_mut(0, 0, n_pts, n_pts)
            .copy_from(kernel_block.as_ref());
        let mut tail = vec![0.0; q];
        for k in 0..n_pts {
            let x: Vec<f64> = points.row(k).iter().copied().collect();
            tail_row(options.degree, &x, &shift, scale, tail_weight, &mut tail);
            for (l, &p) in tail.iter().enumerate() {
                system[(k, n_pts + l)] = p;
                system[(n_pts + l, k)] = p;
            }
        }
        let lu = Lu::new(system.clone());
        let pivot_ratio = pivot_ratio(lu.upper());
        let threshold = n as f64 * f64::EPSILON;
        if pivot_ratio.is_nan() || pivot_ratio <= threshold {
            return Err(ErbfError::Singular {
                ratio: pivot_ratio,
                threshold,
            });
        }
        let coef = OnceLock::new();
        if coefficients_first(values.ncols(), n) {
            let _ = coef.set(lu_solve(&lu, values.as_ref(), n));
        }
        Ok(RbfInterpolant {
            options,
            points,
            values,
            lower,
            upper,
            shift,
            scale,
            tail_weight,
            system,
            lu,
            coef,
            pivot_ratio,
        })
    }

    /// Adds samples and refits: `points` is `k x d`, `values` is `k x T`.
    ///
    /// The kernel entries among the existing samples are reused, so the cost is `O(N k d)`
    /// for the new entries plus one factorisation `O((N + k)^3)`; for the sizes of a
    /// surrogate optimiser (a few hundred samples) this is milliseconds.
    ///
    /// # Errors
    /// As [`fit`](Self::fit), with duplicates checked between the new samples and all
    /// existing ones (indices in the grown set). On error the interpolant is unchanged.
    pub fn add_points(&mut self, points: MatRef<'_, f64>, values: MatRef<'_, f64>) -> Result<()> {
        check_training(points, values, Some(self.dim()))?;
        if values.ncols() != self.n_outputs() {
            return Err(dimension_mismatch(
                "new values: number of columns (outputs)",
                self.n_outputs(),
                values.ncols(),
            ));
        }
        let all_points = stack_rows(self.points.as_ref(), points);
        let all_values = stack_rows(self.values.as_ref(), values);
        let (lower, upper) = bounding_box(all_points.as_ref());
        let tol = self.options.duplicate_tolerance * distance(&lower, &upper);
        let n_old = self.points.nrows();
        let n_all = all_points.nrows();
        for j in n_old..n_all {
            for i in 0..j {
                let dist = distance(all_points.row(i).iter(), all_points.row(j).iter());
                if dist <= tol {
                    return Err(ErbfError::DuplicateSamples {
                        first: i,
                        second: j,
                        distance: dist,
                        tolerance: tol,
                    });
                }
            }
        }
        let radial = self.options.radial;
        let smoothing = self.options.smoothing;
        let old = self.system.as_ref().submatrix(0, 0, n_old, n_old);
        let kernel_block = Mat::from_fn(n_all, n_all, |i, j| {
            if i < n_old && j < n_old {
                old[(i, j)]
            } else {
                let r = distance(all_points.row(i).iter(), all_points.row(j).iter());
                radial.value(r) + if i == j { smoothing } else { 0.0 }
            }
        });
        *self = Self::assemble(self.options, all_points, all_values, kernel_block)?;
        Ok(())
    }

    /// Adds one sample of a single-output interpolant.
    ///
    /// # Errors
    /// As [`add_points`](Self::add_points).
    pub fn add_point(&mut self, x: &[f64], value: f64) -> Result<()> {
        let p = MatRef::from_row_major_slice(x, 1, x.len());
        let v = [value];
        self.add_points(p, MatRef::from_column_major_slice(&v, 1, 1))
    }

    /// Dimension `d` of the input space.
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

    /// The options the model was fitted with.
    pub fn options(&self) -> &RbfOptions {
        &self.options
    }

    /// The training points, `N x d`.
    pub fn points(&self) -> MatRef<'_, f64> {
        self.points.as_ref()
    }

    /// The training values, `N x T`.
    pub fn values(&self) -> MatRef<'_, f64> {
        self.values.as_ref()
    }

    /// The weights `c` of the radial functions, `N x T` (row `i` belongs to row `i` of
    /// [`points`](Self::points)); with [`tail_coefficients`](Self::tail_coefficients) they
    /// give the interpolant explicitly.
    pub fn radial_weights(&self) -> MatRef<'_, f64> {
        self.coef().as_ref().subrows(0, self.n_samples())
    }

    /// The coefficients of the polynomial tail in the original coordinates, a `q x T`
    /// matrix: row 0 is the constant term and, for a linear tail, row `1 + j` the
    /// coefficient of `x_j`, so that
    ///
    /// ```text
    /// s_t(x) = sum_i W_it phi(|x - x_i|) + A_0t + sum_j A_(1+j)t x_j
    /// ```
    ///
    /// with `W` the [`radial_weights`](Self::radial_weights) and `x_i` the rows of
    /// [`points`](Self::points). `q` is 0 without a tail, 1 for a constant one, `d + 1` for
    /// a linear one. (Internally the tail is solved in centred, scaled and weighted
    /// coordinates; this converts it back.)
    pub fn tail_coefficients(&self) -> Mat<f64> {
        let n_pts = self.n_samples();
        let d = self.dim();
        let t = self.n_outputs();
        let q = self.options.degree.terms(d);
        let w = self.tail_weight;
        let mut a = Mat::<f64>::zeros(q, t);
        let coef = self.coef();
        for c in 0..t {
            match self.options.degree {
                PolyDegree::None => {}
                PolyDegree::Constant => a[(0, c)] = w * coef[(n_pts, c)],
                PolyDegree::Linear => {
                    let mut constant = w * coef[(n_pts, c)];
                    for j in 0..d {
                        let b = w * coef[(n_pts + 1 + j, c)] / self.scale;
                        a[(1 + j, c)] = b;
                        constant -= b * self.shift[j];
                    }
                    a[(0, c)] = constant;
                }
            }
        }
        a
    }

    /// Smallest over largest pivot magnitude of the LU factorisation: a cheap indicator of
    /// conditioning (values near `1e-16` mean the system is close to singular).
    pub fn pivot_ratio(&self) -> f64 {
        self.pivot_ratio
    }

    /// The 2-norm condition number of the augmented system matrix (ratio of its extreme
    /// singular values), computed on demand in `O(n^3)`.
    ///
    /// # Errors
    /// [`ErbfError::Singular`] when the singular value decomposition does not converge.
    pub fn condition_number(&self) -> Result<f64> {
        condition_number(self.system.as_ref())
    }

    /// Whether `x` lies outside the bounding box of the training points, where the
    /// interpolant extrapolates (its tail dominates far away).
    pub fn is_outside(&self, x: &[f64]) -> bool {
        outside_box(&self.lower, &self.upper, x)
    }

    /// The prediction at `x` (length `d`): `T` values.
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`] or [`CoreError::NonFinite`] for a bad `x`.
    pub fn predict(&self, x: &[f64]) -> Result<Vec<f64>> {
        let q = MatRef::from_row_major_slice(x, 1, x.len());
        let out = self.predict_batch(q)?;
        Ok(out.row(0).iter().copied().collect())
    }

    /// Predictions at the rows of `points` (`Q x d`): a `Q x T` matrix.
    ///
    /// With `B` the `Q x n` basis rows of the queries and `S` the system matrix, the
    /// prediction is `B S^{-1} [F; 0]`. For few outputs (`T <= n`) it is `B [c; a]` with the
    /// coefficients solved at fit time. For long histories (`T > n`) the same product is
    /// taken the other way round, `(S^{-T} B^T)^T [F; 0]`: a solve with `Q` right-hand
    /// sides instead of `T`, then one `Q x N x T` product with the training values, so the
    /// coefficients (`n x T`) are never formed; that product is written once, in blocks of
    /// 512 output columns, one task each. Basis rows are built in parallel and the queries
    /// processed in blocks of 4096; the result does not depend on the number of threads.
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`] or [`CoreError::NonFinite`] for bad points.
    pub fn predict_batch(&self, points: MatRef<'_, f64>) -> Result<Mat<f64>> {
        check_queries(points, self.dim())?;
        let q = points.nrows();
        let t = self.n_outputs();
        if !coefficients_first(t, self.system.nrows()) {
            // Long histories: the left operands of every block of queries (`N x Q` in all,
            // less than the result), then the result written once, block of output
            // columns by block, while in cache.
            let parts: Vec<(usize, Mat<f64>)> = (0..q)
                .step_by(BLOCK)
                .map(|start| {
                    let len = BLOCK.min(q - start);
                    (
                        start,
                        self.apply_operands(self.basis_columns(points, start, len))
                            .0,
                    )
                })
                .collect();
            let f = self.values.as_ref();
            return Ok(buffer::by_column_blocks(
                q,
                t,
                buffer::RESULT_BLOCK,
                |first, mut cols| {
                    let width = cols.ncols();
                    for (start, lhs) in &parts {
                        matmul(
                            cols.as_mut().subrows_mut(*start, lhs.ncols()),
                            Accum::Replace,
                            lhs.transpose(),
                            f.subcols(first, width),
                            1.0,
                            Par::Seq,
                        );
                    }
                },
            ));
        }
        let mut out = buffer::zeros(q, t);
        let par = faer::get_global_parallelism();
        for start in (0..q).step_by(BLOCK) {
            let len = BLOCK.min(q - start);
            let (lhs, rhs) = self.apply_operands(self.basis_columns(points, start, len));
            matmul(
                out.as_mut().subrows_mut(start, len),
                Accum::Replace,
                lhs.transpose(),
                rhs,
                1.0,
                par,
            );
        }
        Ok(out)
    }

    /// The basis rows of queries `start .. start + len` as columns (`n x len`), built in
    /// parallel.
    fn basis_columns(&self, points: MatRef<'_, f64>, start: usize, len: usize) -> Mat<f64> {
        let n = self.system.nrows();
        let mut basis_t = Mat::<f64>::zeros(n, len);
        basis_t
            .par_col_chunks_mut(1)
            .enumerate()
            .for_each(|(i, mut col)| {
                impactcal_core::simd::clear_upper_registers();
                let x: Vec<f64> = points.row(start + i).iter().copied().collect();
                let mut buf = vec![0.0; n];
                self.basis_row(&x, &mut buf);
                for (k, v) in buf.into_iter().enumerate() {
                    col[(k, 0)] = v;
                }
            });
        basis_t
    }

    /// For basis columns `basis_t` (`n x k`), the operands `(L, R)` with
    /// `basis_t^T S^{-1} [F; 0] = L^T R`: `(basis_t, [c; a])` when the coefficients are
    /// kept, else `(V, F)` with `V` the first `N` rows of `S^{-T} basis_t`.
    fn apply_operands(&self, basis_t: Mat<f64>) -> (Mat<f64>, MatRef<'_, f64>) {
        if coefficients_first(self.n_outputs(), self.system.nrows()) {
            return (basis_t, self.coef().as_ref());
        }
        let n_pts = self.n_samples();
        let mut z = basis_t;
        // S = P^T L U, so S^T v = b is U^T L^T P v = b.
        solve_lower_triangular_in_place(self.lu.upper().transpose(), z.as_mut(), Par::Seq);
        solve_unit_upper_triangular_in_place(self.lu.lower().transpose(), z.as_mut(), Par::Seq);
        let forward = self.lu.forward();
        let mut v = Mat::<f64>::zeros(n_pts, z.ncols());
        for (i, &p) in forward.iter().enumerate() {
            if p < n_pts {
                v.row_mut(p).copy_from(z.row(i));
            }
        }
        (v, self.values.as_ref())
    }

    /// The gradient of every output at `x`: a `T x d` matrix whose row `t` is
    /// `grad s_t(x)`.
    ///
    /// `grad phi(|x - x_i|) = (phi'(r_i) / r_i) (x - x_i)`, plus the tail's constant
    /// gradient.
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`] or [`CoreError::NonFinite`] for a bad `x`.
    pub fn predict_gradient(&self, x: &[f64]) -> Result<Mat<f64>> {
        check_queries(MatRef::from_row_major_slice(x, 1, x.len()), self.dim())?;
        let n_pts = self.n_samples();
        let d = self.dim();
        let n = self.system.nrows();
        // db[(k, j)] = d basis_k / d x_j.
        let mut db = Mat::<f64>::zeros(n, d);
        for i in 0..n_pts {
            let xi = self.points.row(i);
            let r = (0..d).map(|j| (x[j] - xi[j]).powi(2)).sum::<f64>().sqrt();
            let g = self.options.radial.derivative_over_r(r);
            for j in 0..d {
                db[(i, j)] = g * (x[j] - xi[j]);
            }
        }
        if self.options.degree == PolyDegree::Linear {
            for j in 0..d {
                db[(n_pts + 1 + j, j)] = self.tail_weight / self.scale;
            }
        }
        let (lhs, rhs) = self.apply_operands(db);
        Ok(rhs.transpose() * lhs)
    }

    /// Value and gradient of output 0 at `x`: convenient for single-objective optimisers.
    ///
    /// # Errors
    /// As [`predict_gradient`](Self::predict_gradient).
    pub fn value_and_gradient(&self, x: &[f64]) -> Result<(f64, Vec<f64>)> {
        let v = self.predict(x)?[0];
        let g = self.predict_gradient(x)?;
        Ok((v, g.row(0).iter().copied().collect()))
    }

    /// Leave-one-out errors `e_kt = F_kt - s^{(-k)}_t(x_k)`, an `N x T` matrix, where
    /// `s^{(-k)}` is the interpolant fitted without sample `k`.
    ///
    /// [`LooMethod::Closed`] uses Rippa's exact identity `e_k = c_k / (M^{-1})_kk` with `M`
    /// the augmented system (valid with smoothing too), `O(n^3 + N T)`.
    /// [`LooMethod::Refit`] refits `N` times (in parallel), `O(N n^3)`.
    /// [`LooMethod::Auto`] is `Closed`.
    ///
    /// # Errors
    /// [`ErbfError::LooUndefined`] when removing a sample leaves an ill-posed problem (for
    /// example fewer than `d + 2` samples with a linear tail).
    pub fn loo_errors(&self, method: LooMethod) -> Result<Mat<f64>> {
        let n_pts = self.n_samples();
        let t = self.n_outputs();
        match method {
            LooMethod::Closed | LooMethod::Auto => {
                let inv = self.lu.inverse();
                let coef = self.coef();
                let hmax = (0..n_pts).map(|k| inv[(k, k)].abs()).fold(0.0, f64::max);
                let mut e = Mat::<f64>::zeros(n_pts, t);
                for k in 0..n_pts {
                    let h = inv[(k, k)];
                    if h.is_nan() || h.abs() <= 1e3 * f64::EPSILON * hmax {
                        return Err(ErbfError::LooUndefined {
                            sample: k,
                            message: "the diagonal of the inverse system vanishes; the \
                                      remaining samples do not determine the tail"
                                .into(),
                        });
                    }
                    for c in 0..t {
                        e[(k, c)] = coef[(k, c)] / h;
                    }
                }
                Ok(e)
            }
            LooMethod::Refit => {
                let rows: Vec<Result<Vec<f64>>> = (0..n_pts)
                    .into_par_iter()
                    .map(|k| {
                        let x = without_row(self.points.as_ref(), k);
                        let f = without_row(self.values.as_ref(), k);
                        let model =
                            Self::fit(x.as_ref(), f.as_ref(), self.options).map_err(|e| {
                                ErbfError::LooUndefined {
                                    sample: k,
                                    message: e.to_string(),
                                }
                            })?;
                        let xk: Vec<f64> = self.points.row(k).iter().copied().collect();
                        let p = model.predict(&xk)?;
                        Ok((0..t).map(|c| self.values[(k, c)] - p[c]).collect())
                    })
                    .collect();
                collect_rows(rows, t)
            }
        }
    }

    /// Largest deviation from the training values at the training points, relative to the
    /// largest training value: `max |s(x_k) - F_k| / max |F|` (0 when `F = 0`). Near
    /// machine precision without smoothing.
    pub fn training_residual(&self) -> f64 {
        match self.predict_batch(self.points.as_ref()) {
            Ok(p) => relative_max_error(p.as_ref(), self.values.as_ref()),
            Err(_) => f64::NAN,
        }
    }

    /// Keeps only the first `k` outputs (`k` capped at `T`), without refitting: every
    /// output column is solved independently with the same factorisation.
    pub(crate) fn keep_outputs(&mut self, k: usize) {
        let k = k.min(self.n_outputs());
        self.values = self.values.subcols(0, k).to_owned();
        let coef = self.coef.take().map(|c| c.subcols(0, k).to_owned());
        if let Some(c) = coef {
            let _ = self.coef.set(c);
        }
    }

    /// The coefficients `[c; a]`, solving for them on first use.
    fn coef(&self) -> &Mat<f64> {
        self.coef
            .get_or_init(|| lu_solve(&self.lu, self.values.as_ref(), self.system.nrows()))
    }

    /// Writes the basis row at `x` into `out` (length `n`): kernel values, then the tail.
    fn basis_row(&self, x: &[f64], out: &mut [f64]) {
        let n_pts = self.n_samples();
        for (i, o) in out.iter_mut().enumerate().take(n_pts) {
            let r = distance(x, self.points.row(i).iter());
            *o = self.options.radial.value(r);
        }
        tail_row(
            self.options.degree,
            x,
            &self.shift,
            self.scale,
            self.tail_weight,
            &mut out[n_pts..],
        );
    }
}

/// Query rows per block of batch prediction (bounds the basis matrix to `n x 4096`).
const BLOCK: usize = 4096;

/// Whether the coefficients `[c; a]` (`n x t`) are solved at fit time and predictions
/// multiply them (`t <= n`); for longer outputs the product is taken the other way round
/// ([`RbfInterpolant::predict_batch`]).
fn coefficients_first(t: usize, n: usize) -> bool {
    t <= n
}

/// Solves `S X = [F; 0]` for the `n x n` system `S` factorised as `P S = L U`, where `F`
/// (`N x T`) fills the first `N` rows of the right-hand side: the permutation is applied
/// while gathering `F` (in parallel over columns), then the two triangular solves run on
/// all columns at once. Equal, bit for bit, to faer's `solve_in_place`, whose
/// row permutation of a wide right-hand side is several times slower.
fn lu_solve(lu: &Lu, f: MatRef<'_, f64>, n: usize) -> Mat<f64> {
    let forward = lu.forward();
    let n_pts = f.nrows();
    let mut x = Mat::<f64>::zeros(n, f.ncols());
    x.par_col_chunks_mut(64)
        .enumerate()
        .for_each(|(k, mut cols)| {
            for j in 0..cols.ncols() {
                let src = f.col(k * 64 + j);
                for (i, &p) in forward.iter().enumerate() {
                    if p < n_pts {
                        cols[(i, j)] = src[p];
                    }
                }
            }
        });
    let par = crate::lu::parallelism(n);
    solve_unit_lower_triangular_in_place(lu.lower(), x.as_mut(), par);
    solve_upper_triangular_in_place(lu.upper(), x.as_mut(), par);
    x
}

/// The serialised form of an [`RbfInterpolant`]: options and training data.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct RbfData {
    options: RbfOptions,
    points: StoredMat,
    values: StoredMat,
}

impl Serialize for RbfInterpolant {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        RbfData {
            options: *self.options,
            points: StoredMat::from_mat(self.points.as_ref()),
            values: StoredMat::from_mat(self.values.as_ref()),
        }
        .serialize(s)
    }
}

impl<'de> Deserialize<'de> for RbfInterpolant {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let data = RbfData::deserialize(d)?;
        let build = || -> Result<Self> {
            let points = data.points.to_mat("points")?;
            let values = data.values.to_mat("values")?;
            RbfInterpolant::fit(points.as_ref(), values.as_ref(), data.options)
        };
        build().map_err(serde::de::Error::custom)
    }
}

/// `K + lambda I`: the radial function at every pair of training points, plus the
/// smoothing on the diagonal.
fn radial_matrix(options: &RbfOptions, points: MatRef<'_, f64>) -> Mat<f64> {
    let n = points.nrows();
    let mut k = Mat::<f64>::zeros(n, n);
    k.par_col_chunks_mut(1)
        .enumerate()
        .for_each(|(j, mut col)| {
            for i in 0..n {
                let r = distance(points.row(i).iter(), points.row(j).iter());
                col[(i, 0)] =
                    options.radial.value(r) + if i == j { options.smoothing } else { 0.0 };
            }
        });
    k
}

fn tail_row(degree: PolyDegree, x: &[f64], shift: &[f64], scale: f64, w: f64, out: &mut [f64]) {
    match degree {
        PolyDegree::None => {}
        PolyDegree::Constant => out[0] = w,
        PolyDegree::Linear => {
            out[0] = w;
            for j in 0..x.len() {
                out[1 + j] = w * (x[j] - shift[j]) / scale;
            }
        }
    }
}

pub(crate) fn bounding_box(points: MatRef<'_, f64>) -> (Vec<f64>, Vec<f64>) {
    let d = points.ncols();
    let mut lo = vec![f64::INFINITY; d];
    let mut hi = vec![f64::NEG_INFINITY; d];
    for i in 0..points.nrows() {
        for j in 0..d {
            lo[j] = lo[j].min(points[(i, j)]);
            hi[j] = hi[j].max(points[(i, j)]);
        }
    }
    (lo, hi)
}

pub(crate) fn outside_box(lo: &[f64], hi: &[f64], x: &[f64]) -> bool {
    x.len() != lo.len()
        || x.iter().zip(lo.iter().zip(hi)).any(|(&v, (&l, &h))| {
            let slack = 1e-12 * (h - l).abs().max(1.0);
            !(v >= l - slack && v <= h + slack)
        })
}

/// Euclidean distance `||a - b||_2` of two points given as coordinate sequences of one
/// length (slices, or faer rows through `.iter()`).
pub(crate) fn distance<'a>(
    a: impl IntoIterator<Item = &'a f64>,
    b: impl IntoIterator<Item = &'a f64>,
) -> f64 {
    a.into_iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

fn pivot_ratio(u: MatRef<'_, f64>) -> f64 {
    let n = u.nrows().min(u.ncols());
    let (mut lo, mut hi) = (f64::INFINITY, 0.0_f64);
    for i in 0..n {
        let v = u[(i, i)].abs();
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if hi > 0.0 { lo / hi } else { 0.0 }
}

pub(crate) fn condition_number(m: MatRef<'_, f64>) -> Result<f64> {
    let s = m.singular_values().map_err(|_| ErbfError::Singular {
        ratio: f64::NAN,
        threshold: 0.0,
    })?;
    let hi = s.iter().copied().fold(0.0, f64::max);
    let lo = s.iter().copied().fold(f64::INFINITY, f64::min);
    Ok(if lo > 0.0 { hi / lo } else { f64::INFINITY })
}

/// `max |a - b| / max |b|` over all entries (the absolute maximum when `b = 0`).
pub(crate) fn relative_max_error(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> f64 {
    let mut err = 0.0_f64;
    let mut scale = 0.0_f64;
    for j in 0..b.ncols() {
        for i in 0..b.nrows() {
            err = err.max((a[(i, j)] - b[(i, j)]).abs());
            scale = scale.max(b[(i, j)].abs());
        }
    }
    if scale > 0.0 { err / scale } else { err }
}
