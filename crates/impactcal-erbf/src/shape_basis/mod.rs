//! The impact-shape basis of an ensemble of histories: surrogates of shape coordinates
//! instead of every sample of a history.
//!
//! With training outputs `F` (`N x T`: one history of `T` samples per run) and their mean
//! history `f_bar` (the column means), the deviations `F - 1 f_bar^T` are decomposed by the
//! thin SVD of [`impactcal_shapes::ImpactShapes`] into `sum_i sigma_i u_i g_i^T`: the time
//! functions `g_i` (orthonormal, length `T`) are the ensemble's impact shapes over time, and
//! `a_ki = sigma_i u_ki` is run `k`'s coordinate on shape `i`. Keeping `k` shapes,
//!
//! ```text
//! F ~ 1 f_bar^T + A_k G_k^T,   ||F - 1 f_bar^T - A_k G_k^T||_F = sqrt(sum_{i>k} sigma_i^2),
//! ```
//!
//! and a surrogate of the `k` coordinates `a(x)` gives whole histories as
//! `f(x) = f_bar + G_k a(x)`, rebuilt only when asked for. Fitting `k` outputs instead of
//! `T` and rebuilding with a `Q x k x T` product instead of a `Q x N x T` one is what makes
//! the basis fast; the price is the truncation error, which [`ShapeBasis::truncation_error`]
//! reports and [`choose_count`] keeps below the surrogate's own leave-one-out error.

use faer::linalg::matmul::matmul;
use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::{Accum, Mat, MatRef, Par};
use impactcal_shapes::{ImpactShapes, ShapeOptions, SvdMethod, Truncation};
use rayon::prelude::*;

use crate::buffer;

mod sketch;
use crate::error::{ErbfError, Result};
use impactcal_core::{CoreError, check_finite_mat};

/// How far below the surrogate's own leave-one-out error the truncation error must stay
/// when the shape count is chosen automatically: `0.25`, so that the truncation adds at
/// most `sqrt(1 + 0.25^2) - 1 = 3 %` to the error of the history (the two are orthogonal).
pub const TRUNCATION_RATIO: f64 = 0.25;

/// Histories of at least this many samples per run (`T >= GRAM_RATIO N`) are decomposed
/// through the `N x N` Gram matrix of the runs ([`ShapeSpectrum`]); shorter ones by the
/// full thin SVD.
pub const GRAM_RATIO: usize = 2;

/// Time samples per block when the deviations from the mean are formed on the fly: the
/// unit of work of the Gram matrix and of the time functions.
const BLOCK: usize = 1024;

/// Most groups of blocks the Gram matrix is summed over (one partial `N x N` matrix each).
const GRAM_GROUPS: usize = 8;

/// Ensembles of at least this many runs are first sketched: below it, the Gram matrix
/// costs little more than the sketch's own pass.
pub const SKETCH_MIN_RUNS: usize = 2 * sketch::SKETCH_WIDTH;

/// The mean history and impact shapes (time functions) of an ensemble of histories.
#[derive(Debug, Clone)]
pub struct ShapeBasis {
    /// Mean history `f_bar` (length `T`).
    mean: Vec<f64>,
    /// `[G | f_bar]^T` (`(k + 1) x T`): the time functions kept (orthonormal rows) and the
    /// mean history last, so that a rebuild is one product and a block of samples is a
    /// block of columns.
    rows: Mat<f64>,
    /// Singular values of the deviations, all of them up to the numerical rank.
    sigma: Vec<f64>,
    /// `||F - 1 f_bar^T||_F^2`.
    total: f64,
}

/// The spectrum of an ensemble before the shape count is chosen: mean history, singular
/// values and run coordinates of every resolved shape, and the `T`-long time functions
/// only when the decomposition made them (else [`ShapeSpectrum::basis`] computes them for
/// the shapes kept only).
///
/// For long histories (`T >= GRAM_RATIO N`) it is the method of snapshots: with the
/// deviations `C = F - 1 f_bar^T` (`N x T`, never stored), the Gram
/// matrix `K = C C^T = U diag(sigma^2) U^T` (`N x N`, `O(N^2 T)`) gives the singular values
/// and the left singular vectors `U`, hence the coordinates `A = U diag(sigma)`; the time
/// functions of the `k` shapes kept are `G_k = C^T U_k diag(sigma_k)^{-1}` (`O(N k T)`).
/// The mean and `K` come from one pass over the runs: the deviations from the first run,
/// `D = F - 1 f_1^T`, formed block by block, give `D D^T`, and since `C = P D` with the
/// centring projector `P = I - 1 1^T / N`, `K = P (D D^T) P`. `D` is of the size of `C`
/// (`|d_k| <= |c_k| + |c_1|`), so the rounding of `K` stays of the order `eps sigma_1^2`.
/// Whatever the accuracy of `U`, the rebuilt training runs
/// `1 f_bar^T + A_k G_k^T = 1 f_bar^T + U_k U_k^T C` are the exact orthogonal projection of
/// the runs onto the `k` coordinates. Squaring `C` costs precision for weak shapes only:
/// eigenvalues of `K` are accurate to about `eps sigma_1^2`, so shapes with
/// `sigma_i^2 <= 10 N eps sigma_1^2` (`sigma_i / sigma_1` below about `4e-7` for `N = 100`)
/// are treated as numerically zero; truncation errors below that level are not resolved.
/// Shorter histories use the full thin SVD of `C`, which resolves down to
/// `max(N, T) eps sigma_1`.
///
/// Large ensembles (`N >= SKETCH_MIN_RUNS`, 128) of long histories whose deviations are of
/// numerically low rank skip the Gram matrix. A sparse sketch `Y = P D_S Omega`
/// (`N x 64`) of the deviations at `4 N` evenly spaced sample times `S` (`Omega` has two
/// random `+-1` entries per row; `O(N^2)` work) shows the rank `r`: the eigenvalues of
/// `Y^T Y` above `10 N eps` times the largest. When `r <= 32` (as many sketch columns to
/// spare as directions found), an orthonormal `Q` (`N x r`) spans the range of `Y`, and one
/// pass over the runs gives `B = Q^T C` (`r x T`, `O(r N T)`), `||C||_F^2` and
/// `B B^T = W diag(sigma^2) W^T`; then `U = Q W` and `G^T = diag(sigma)^{-1} W^T B`. The
/// route checks what it claims: the energy of `C` outside `Q`, `||C||_F^2 - ||B||_F^2`,
/// must be at most `10 N eps ||C||_F^2`, or the Gram matrix is formed after all (a shape
/// that the sampled times miss is caught here). For such data it is the same
/// decomposition as the method of snapshots, to rounding, for about `r N T` multiply-adds
/// instead of `N^2 T / 2 + k N T`.
#[derive(Debug, Clone)]
pub struct ShapeSpectrum {
    mean: Vec<f64>,
    sigma: Vec<f64>,
    /// `U` (`N x r`), orthonormal columns, signs fixed as in
    /// [`ImpactShapes`] (the largest-magnitude entry of each column positive).
    left: Mat<f64>,
    /// The time functions of every shape and the mean history, `[G | f_bar]^T`
    /// (`(r + 1) x T`, the layout of [`ShapeBasis`]), when the full SVD or the sketch
    /// computed them.
    functions: Option<Mat<f64>>,
    total: f64,
}

impl ShapeSpectrum {
    /// Decomposes the training outputs `values` (`N x T`): mean history, singular values of
    /// the deviations up to the numerical rank `r` (at least one) and the left singular
    /// vectors. Cost `O(N^2 T)` (one `N x N x T` product for long histories).
    ///
    /// # Errors
    /// [`CoreError::NonFinite`] naming the entry or
    /// [`CoreError::Empty`] for bad data;
    /// [`ShapesError::NoConvergence`](impactcal_shapes::ShapesError::NoConvergence) (under
    /// [`ErbfError::Shapes`]) when the eigen- or singular value decomposition fails.
    pub fn new(values: MatRef<'_, f64>) -> Result<Self> {
        let (n, t) = values.shape();
        if n == 0 || t == 0 {
            return Err(CoreError::Empty {
                what: "outputs of the shape basis".into(),
            }
            .into());
        }
        if t < GRAM_RATIO * n {
            return Self::by_svd(values, column_means(values)?);
        }
        if n >= SKETCH_MIN_RUNS
            && let Some(low_rank) = Self::by_sketch(values)?
        {
            return Ok(low_rank);
        }
        Self::by_gram(values)
    }

    /// The method of snapshots: the eigenvectors of the `N x N` Gram matrix of the runs.
    fn by_gram(values: MatRef<'_, f64>) -> Result<Self> {
        let n = values.nrows();
        let (gram, sums) = deviation_gram(values, Reference::FirstRun);
        let scale = 1.0 / n as f64;
        let mean: Vec<f64> = sums.iter().map(|s| s * scale).collect();
        let (mean, gram) = if mean.iter().all(|m| m.is_finite()) && gram_is_finite(&gram) {
            (mean, gram)
        } else {
            // A bad entry (named here), or finite entries whose sums overflow: the
            // deviations from the mean, which is then found from scaled entries.
            let mean = column_means(values)?;
            let (gram, _) = deviation_gram(values, Reference::History(&mean));
            (mean, gram)
        };
        let gram = centre_gram(gram);
        let total = (0..n).map(|i| gram[(i, i)]).sum();
        let (lambda, vectors) = symmetric_eigen(gram.as_ref())?;
        let (sigma, order) = leading_roots(&lambda, n);
        let mut left = Mat::from_fn(n, order.len(), |k, j| vectors[(k, order[j])]);
        fix_signs(left.as_mut());
        Ok(ShapeSpectrum {
            mean,
            sigma,
            left,
            functions: None,
            total,
        })
    }

    /// The full thin SVD of the deviations (short histories).
    fn by_svd(values: MatRef<'_, f64>, mean: Vec<f64>) -> Result<Self> {
        let mut centred = buffer::copy(values);
        for (col, &m) in centred.col_iter_mut().zip(&mean) {
            col.iter_mut().for_each(|v| *v -= m);
        }
        let total = centred.squared_norm_l2();
        let options = ShapeOptions {
            truncation: Truncation::All,
            method: SvdMethod::Full,
        };
        let shapes = ImpactShapes::from_matrix(centred.as_ref(), &options)?;
        Ok(ShapeSpectrum {
            sigma: shapes.singular_values().to_vec(),
            left: shapes.shapes().to_owned(),
            functions: Some(functions_and_mean(shapes.time_functions(), &mean)),
            mean,
            total,
        })
    }

    /// Singular values of the deviations up to the numerical rank, non-increasing.
    pub fn singular_values(&self) -> &[f64] {
        &self.sigma
    }

    /// The coordinates of the training runs on every shape, `A = U diag(sigma)` (`N x r`).
    pub fn coordinates(&self) -> Mat<f64> {
        Mat::from_fn(self.left.nrows(), self.sigma.len(), |k, i| {
            self.sigma[i] * self.left[(k, i)]
        })
    }

    /// The basis of the first `k` shapes (`k` clamped to `1..=r`), their time functions
    /// computed from `values`, the same `N x T` outputs the spectrum was made from
    /// (`O(N k T)`), unless the spectrum holds them already.
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`] when
    /// `values` is not `N x T`.
    pub fn basis(&self, values: MatRef<'_, f64>, k: usize) -> Result<ShapeBasis> {
        // Only the rows kept are copied: `into_basis` then moves them.
        let kept = k.clamp(1, self.sigma.len().max(1));
        ShapeSpectrum {
            mean: self.mean.clone(),
            sigma: self.sigma.clone(),
            left: self.left.clone(),
            functions: self
                .functions
                .as_ref()
                .map(|rows| kept_rows(rows.as_ref(), kept)),
            total: self.total,
        }
        .into_basis(values, k)
    }

    /// As [`basis`](Self::basis), consuming the spectrum: time functions it holds already
    /// (from the full SVD or the sketch) move into the basis instead of being copied.
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`] when
    /// `values` is not `N x T`.
    pub fn into_basis(self, values: MatRef<'_, f64>, k: usize) -> Result<ShapeBasis> {
        let (n, t) = (self.left.nrows(), self.mean.len());
        if values.shape() != (n, t) {
            return Err(impactcal_core::error::dimension_mismatch(
                "outputs of the shape basis (N x T)",
                n * t,
                values.nrows() * values.ncols(),
            ));
        }
        let k = k.clamp(1, self.sigma.len().max(1));
        let mean = &self.mean;
        let rows = match self.functions {
            Some(rows) if k + 1 == rows.nrows() => rows,
            Some(rows) => kept_rows(rows.as_ref(), k),
            None => {
                // G_k^T = diag(sigma_k)^{-1} U_k^T C, one block of samples per task, each
                // its own columns: the result does not depend on the number of threads.
                let mut scaled = Mat::from_fn(k, n, |j, i| self.left[(i, j)] / self.sigma[j]);
                buffer::zero_padding(&mut scaled);
                buffer::by_column_blocks_with(
                    k + 1,
                    t,
                    BLOCK,
                    || Mat::<f64>::zeros(n, BLOCK.min(t)),
                    |scratch, first, mut cols| {
                        let width = cols.ncols();
                        let c =
                            centre_block(values, Reference::History(mean), first, width, scratch);
                        matmul(
                            cols.as_mut().subrows_mut(0, k),
                            Accum::Replace,
                            scaled.as_ref(),
                            c,
                            1.0,
                            Par::Seq,
                        );
                        cols.row_mut(k)
                            .iter_mut()
                            .zip(&mean[first..])
                            .for_each(|(g, m)| *g = *m);
                    },
                )
            }
        };
        Ok(ShapeBasis {
            mean: self.mean,
            rows,
            sigma: self.sigma,
            total: self.total,
        })
    }
}

/// The column means of `values` (`N x T`), checked for finiteness in the same pass: a
/// column whose sum is finite has only finite entries (one infinite or NaN entry makes the
/// sum infinite or NaN).
///
/// # Errors
/// [`CoreError::NonFinite`] naming the first bad entry.
fn column_means(values: MatRef<'_, f64>) -> Result<Vec<f64>> {
    let (n, t) = values.shape();
    let scale = 1.0 / n as f64;
    let mean: Vec<f64> = (0..t).map(|c| column_sum(values, c) * scale).collect();
    if mean.iter().all(|m| m.is_finite()) {
        return Ok(mean);
    }
    check_finite_mat("outputs of the shape basis", values)?;
    // Finite entries whose sum overflows: average the scaled entries instead.
    Ok((0..t)
        .map(|c| values.col(c).iter().map(|v| v * scale).sum())
        .collect())
}

/// The sum of column `c` of `values` in four interleaved partial sums (entry `i` into sum
/// `i mod 4`, then `(s_0 + s_1) + (s_2 + s_3)`): the same bits for any layout, and
/// four independent chains of additions instead of one, which the processor overlaps.
fn column_sum(values: MatRef<'_, f64>, c: usize) -> f64 {
    let mut acc = [0.0f64; 4];
    match values.col(c).try_as_col_major() {
        Some(col) => {
            let xs = col.as_slice();
            let mut chunks = xs.chunks_exact(4);
            for ch in &mut chunks {
                for (a, x) in acc.iter_mut().zip(ch) {
                    *a += x;
                }
            }
            for (a, x) in acc.iter_mut().zip(chunks.remainder()) {
                *a += x;
            }
        }
        None => {
            for (i, x) in values.col(c).iter().enumerate() {
                acc[i % 4] += x;
            }
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3])
}

/// The lower triangle of the Gram matrix `D D^T` of the deviations
/// `D = F - 1 r^T` from a reference history `r` (`N x N`; the upper triangle is zero), and
/// the column sums of `F` (length `T`, by [`column_sum`]), in one pass over `F`.
///
/// The samples are split into at most [`GRAM_GROUPS`] contiguous groups of whole blocks of
/// [`BLOCK`] samples, independent of the number of threads; each group accumulates its
/// blocks' products in its own matrix (in parallel across groups, sequentially inside), and
/// the groups are summed in order, so the result does not depend on the number of threads.
fn deviation_gram(values: MatRef<'_, f64>, reference: Reference<'_>) -> (Mat<f64>, Vec<f64>) {
    let (n, t) = values.shape();
    let blocks = t.div_ceil(BLOCK);
    let groups = blocks.clamp(1, GRAM_GROUPS);
    let per_group = blocks.div_ceil(groups);
    let parts: Vec<(Mat<f64>, Vec<f64>)> = (0..groups)
        .into_par_iter()
        .map(|g| {
            let mut gram = Mat::<f64>::zeros(n, n);
            let mut sums = Vec::new();
            let mut deviations = Mat::<f64>::zeros(n, BLOCK.min(t));
            // The deviations are the left operand of the product below.
            buffer::zero_padding(&mut deviations);
            for b in g * per_group..((g + 1) * per_group).min(blocks) {
                let start = b * BLOCK;
                let len = BLOCK.min(t - start);
                sums.extend((start..start + len).map(|c| column_sum(values, c)));
                let d = centre_block(values, reference, start, len, &mut deviations);
                // Only the lower triangle: the eigensolver reads no more.
                triangular::matmul(
                    gram.as_mut(),
                    BlockStructure::TriangularLower,
                    Accum::Add,
                    d,
                    BlockStructure::Rectangular,
                    d.transpose(),
                    BlockStructure::Rectangular,
                    1.0,
                    Par::Seq,
                );
            }
            (gram, sums)
        })
        .collect();
    let mut gram = Mat::<f64>::zeros(n, n);
    let mut sums = Vec::with_capacity(t);
    for (g, s) in parts {
        gram += &g;
        sums.extend(s);
    }
    (gram, sums)
}

/// The eigenvalues (non-decreasing) and eigenvectors of a symmetric matrix from its lower
/// triangle, on this thread: on the small matrices here faer's parallel tridiagonalisation
/// costs more than it saves.
///
/// # Errors
/// [`ShapesError::NoConvergence`](impactcal_shapes::ShapesError::NoConvergence) when the
/// eigensolver does not converge.
fn symmetric_eigen(lower: MatRef<'_, f64>) -> Result<(Vec<f64>, Mat<f64>)> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::evd::{self, ComputeEigenvectors};
    let n = lower.nrows();
    let mut vectors = Mat::<f64>::zeros(n, n);
    let mut values = faer::diag::Diag::<f64>::zeros(n);
    let scratch = evd::self_adjoint_evd_scratch::<f64>(
        n,
        ComputeEigenvectors::Yes,
        Par::Seq,
        Default::default(),
    );
    evd::self_adjoint_evd(
        lower,
        values.as_mut(),
        Some(vectors.as_mut()),
        Par::Seq,
        MemStack::new(&mut MemBuffer::new(scratch)),
        Default::default(),
    )
    .map_err(|_| ErbfError::Shapes(impactcal_shapes::ShapesError::NoConvergence))?;
    Ok((values.column_vector().iter().copied().collect(), vectors))
}

/// The square roots of the eigenvalues `lambda` of a Gram matrix (non-decreasing, as the
/// eigensolver gives them) above `10 n eps lambda_max`, largest first, and their indices;
/// the largest alone when none is (all runs equal).
fn leading_roots(lambda: &[f64], n: usize) -> (Vec<f64>, Vec<usize>) {
    let m = lambda.len();
    let top = lambda.iter().copied().fold(0.0_f64, f64::max);
    let floor = 10.0 * n as f64 * f64::EPSILON * top;
    let order: Vec<usize> = (0..m)
        .rev()
        .filter(|&i| lambda[i] > floor && lambda[i] > 0.0)
        .collect();
    let order = if order.is_empty() { vec![m - 1] } else { order };
    let sigma = order.iter().map(|&i| lambda[i].max(0.0).sqrt()).collect();
    (sigma, order)
}

/// Whether the lower triangle of `gram` is finite.
fn gram_is_finite(gram: &Mat<f64>) -> bool {
    (0..gram.ncols()).all(|j| gram.col(j).iter().skip(j).all(|v| v.is_finite()))
}

/// The lower triangle of `P G P`, `P = I - 1 1^T / N`, from the lower triangle of a
/// symmetric `G` (`N x N`): `(P G P)_ij = G_ij - g_i - g_j + g`, with `g_i` the row means
/// of `G` and `g` their mean. For the Gram matrix of the deviations from any one history it
/// is the Gram matrix of the deviations from the mean history.
fn centre_gram(lower: Mat<f64>) -> Mat<f64> {
    let n = lower.nrows();
    let full = |i: usize, j: usize| if i >= j { lower[(i, j)] } else { lower[(j, i)] };
    let scale = 1.0 / n as f64;
    let row_means: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|j| full(i, j)).sum::<f64>() * scale)
        .collect();
    let grand = row_means.iter().sum::<f64>() * scale;
    Mat::from_fn(n, n, |i, j| {
        if i >= j {
            lower[(i, j)] - row_means[i] - row_means[j] + grand
        } else {
            0.0
        }
    })
}

/// The history deviations are taken from.
#[derive(Clone, Copy)]
enum Reference<'a> {
    /// The first run, read from each column as it is used: gathering row 0 of a
    /// column-major `F` up front touches one cache line (and page) per sample.
    FirstRun,
    /// A given history, such as the mean (length `T`).
    History(&'a [f64]),
}

impl Reference<'_> {
    /// The reference's sample `j` (`j < T`).
    fn at(self, values: MatRef<'_, f64>, j: usize) -> f64 {
        match self {
            Reference::FirstRun => values[(0, j)],
            Reference::History(h) => h[j],
        }
    }
}

/// The deviations `F_b - 1 r_b^T` from a reference history `r` of the block of `len`
/// samples starting at `start`, formed in `buffer` (`N x len` at least).
fn centre_block<'a>(
    values: MatRef<'_, f64>,
    reference: Reference<'_>,
    start: usize,
    len: usize,
    buffer: &'a mut Mat<f64>,
) -> MatRef<'a, f64> {
    for j in 0..len {
        let m = reference.at(values, start + j);
        let d = buffer.col_as_slice_mut(j);
        let v = values.col(start + j);
        match v.try_as_col_major() {
            Some(v) => d.iter_mut().zip(v.as_slice()).for_each(|(d, v)| *d = v - m),
            None => d.iter_mut().zip(v.iter()).for_each(|(d, v)| *d = v - m),
        }
    }
    buffer.as_ref().subcols(0, len)
}

/// `[G | f_bar]^T` (`(r + 1) x T`) from the time functions `G` (`T x r`) and the mean
/// history `f_bar`.
fn functions_and_mean(functions: MatRef<'_, f64>, mean: &[f64]) -> Mat<f64> {
    let r = functions.ncols();
    Mat::from_fn(r + 1, mean.len(), |i, j| {
        if i < r { functions[(j, i)] } else { mean[j] }
    })
}

/// The rows `0 .. k` and the last of `rows` (`(r + 1) x T`, time functions then the mean
/// history): the layout of a basis of `k` shapes.
fn kept_rows(rows: MatRef<'_, f64>, k: usize) -> Mat<f64> {
    let last = rows.nrows() - 1;
    Mat::from_fn(k + 1, rows.ncols(), |i, j| {
        rows[(if i < k { i } else { last }, j)]
    })
}

/// Makes the largest-magnitude entry of every column of `u` positive (the first on ties),
/// the rule of [`ImpactShapes`], and returns the signs applied (`+-1` per column); the time
/// functions, computed from `u`, follow.
fn fix_signs(mut u: faer::MatMut<'_, f64>) -> Vec<f64> {
    (0..u.ncols())
        .map(|j| {
            let mut best = 0.0f64;
            let mut sign = 1.0;
            for &x in u.as_ref().col(j).iter() {
                if x.abs() > best {
                    best = x.abs();
                    sign = x.signum();
                }
            }
            if sign < 0.0 {
                u.as_mut().col_mut(j).iter_mut().for_each(|x| *x = -*x);
            }
            sign
        })
        .collect()
}

impl ShapeBasis {
    /// Decomposes the training outputs `values` (`N x T`) and returns the basis with every
    /// shape up to the numerical rank `r` of the deviations (at least one), and the
    /// training coordinates `A` (`N x r`, `A_ki = sigma_i u_ki`): [`ShapeSpectrum::new`]
    /// then [`ShapeSpectrum::basis`] with all `r` shapes.
    ///
    /// # Errors
    /// As [`ShapeSpectrum::new`].
    pub fn new(values: MatRef<'_, f64>) -> Result<(Self, Mat<f64>)> {
        let spectrum = ShapeSpectrum::new(values)?;
        let basis = spectrum.basis(values, spectrum.singular_values().len())?;
        Ok((basis, spectrum.coordinates()))
    }

    /// Number of shapes kept `k`.
    pub fn len(&self) -> usize {
        self.rows.nrows() - 1
    }

    /// Whether no shape is kept (never true for a basis from [`new`](Self::new)).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Number of samples `T` of a history.
    pub fn samples(&self) -> usize {
        self.mean.len()
    }

    /// The singular values of the deviations from the mean, all of them up to the
    /// numerical rank (also those not kept), non-increasing.
    pub fn singular_values(&self) -> &[f64] {
        &self.sigma
    }

    /// The mean history `f_bar`.
    pub fn mean(&self) -> &[f64] {
        &self.mean
    }

    /// The time functions kept, `T x k`, orthonormal columns (a view with row stride
    /// `k + 1`).
    pub fn functions(&self) -> MatRef<'_, f64> {
        self.rows.as_ref().subrows(0, self.len()).transpose()
    }

    /// Relative truncation error of `k` shapes on the training data,
    /// `||F - 1 f_bar^T - A_k G_k^T||_F / ||F - 1 f_bar^T||_F
    /// = sqrt(sum_{i>k} sigma_i^2 / sum_i sigma_i^2)` (0 when the runs are all equal).
    pub fn truncation_error(&self, k: usize) -> f64 {
        if self.total <= 0.0 {
            return 0.0;
        }
        // Summing the discarded singular values (all of them are kept up to the numerical
        // rank) avoids the cancellation of `total - kept`.
        let tail: f64 = self.sigma.iter().skip(k).map(|s| s * s).sum();
        (tail / self.total).sqrt()
    }

    /// Keeps the first `k` shapes (`k` is capped at the number kept; at least one).
    pub fn truncate(&mut self, k: usize) {
        let k = k.clamp(1, self.len().max(1));
        if k < self.len() {
            self.rows = kept_rows(self.rows.as_ref(), k);
        }
    }

    /// Histories from coordinates: `f_bar + G a` for every row `a` of `coords`
    /// (`Q x k`): a `Q x T` matrix, `O(Q k T)`, written once in blocks of 512 samples (the
    /// result does not depend on the number of threads).
    pub fn rebuild(&self, coords: MatRef<'_, f64>) -> Mat<f64> {
        let q = coords.nrows();
        let k = coords.ncols().min(self.len());
        // [a | 1] [G_k | f_bar]^T: the mean rides along as one more coordinate.
        let mut ext = Mat::<f64>::zeros(q, k + 1);
        ext.as_mut()
            .subcols_mut(0, k)
            .copy_from(coords.subcols(0, k));
        ext.col_mut(k).iter_mut().for_each(|v| *v = 1.0);
        buffer::zero_padding(&mut ext);
        let fewer = (k < self.len()).then(|| kept_rows(self.rows.as_ref(), k));
        let basis = fewer.as_ref().map_or(self.rows.as_ref(), |b| b.as_ref());
        // Written once, in blocks of output samples, one task each.
        buffer::by_column_blocks(
            q,
            self.samples(),
            buffer::RESULT_BLOCK,
            |first, mut cols| {
                let width = cols.ncols();
                matmul(
                    cols.as_mut(),
                    Accum::Replace,
                    ext.as_ref(),
                    basis.subcols(first, width),
                    1.0,
                    Par::Seq,
                );
            },
        )
    }

    /// The part of the training outputs that `k` shapes miss, `F - 1 f_bar^T - A_k G_k^T`
    /// (`N x T`), for training coordinates `coords` (`N x r`, `r >= k`).
    pub fn residual(&self, values: MatRef<'_, f64>, coords: MatRef<'_, f64>) -> Mat<f64> {
        let rebuilt = self.rebuild(coords);
        Mat::from_fn(values.nrows(), values.ncols(), |i, j| {
            values[(i, j)] - rebuilt[(i, j)]
        })
    }
}

/// The fewest shapes `k` whose truncation error stays below [`TRUNCATION_RATIO`] times the
/// surrogate's own leave-one-out error over those shapes:
///
/// ```text
/// sum_{i>k} sigma_i^2 <= TRUNCATION_RATIO^2 sum_{i<=k} l_i,
/// ```
///
/// where `l_i` is the sum of squared leave-one-out errors of coordinate `i` and
/// `sigma_i^2` its energy. All `r = sigma.len()` shapes when no smaller count qualifies
/// (data the surrogate predicts almost exactly); `loo_energy` shorter than `sigma` counts
/// the missing entries as zero.
pub fn choose_count(sigma: &[f64], loo_energy: &[f64]) -> usize {
    let r = sigma.len();
    let mut loo = 0.0;
    for k in 1..=r {
        let tail: f64 = sigma[k..].iter().map(|s| s * s).sum();
        loo += loo_energy.get(k - 1).copied().unwrap_or(0.0);
        if tail <= TRUNCATION_RATIO * TRUNCATION_RATIO * loo {
            return k;
        }
    }
    r.max(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn rank_two_ensemble_is_rebuilt_exactly_from_two_shapes() {
        // F_kt = 1 + x_k sin(t) + x_k^2 cos(t): mean plus a rank-2 deviation.
        let f = Mat::from_fn(12, 200, |k, t| {
            let x = k as f64 / 11.0;
            let t = t as f64 * 0.05;
            1.0 + x * t.sin() + x * x * t.cos()
        });
        let (mut basis, coords) = ShapeBasis::new(f.as_ref()).unwrap();
        assert_eq!(coords.ncols(), basis.len());
        assert!(basis.truncation_error(2) < 1e-12);
        assert!(basis.truncation_error(1) > 1e-3);
        basis.truncate(2);
        let back = basis.rebuild(coords.as_ref());
        for i in 0..12 {
            for j in 0..200 {
                assert_relative_eq!(back[(i, j)], f[(i, j)], epsilon = 1e-12);
            }
        }
        // The residual of one shape has exactly the norm the truncation error reports.
        let mut one = basis.clone();
        one.truncate(1);
        let r = one.residual(f.as_ref(), coords.as_ref());
        let mut centred = f.clone();
        for j in 0..200 {
            let m = one.mean()[j];
            centred.col_mut(j).iter_mut().for_each(|v| *v -= m);
        }
        assert_relative_eq!(
            r.norm_l2() / centred.norm_l2(),
            one.truncation_error(1),
            max_relative = 1e-10
        );
    }

    /// `F = 1 m^T + P diag(s) Q^T` (`N x T`): the mean history `m_j = 5 + sin(0.01 j)` and
    /// deviations of rank `r` with singular values `s_i = 10^(-decay i)` (`P` orthonormal
    /// and orthogonal to `1`, so that the mean of the runs is exactly `m`; `Q`
    /// orthonormal; both random from `seed`).
    pub(super) fn ensemble(n: usize, t: usize, r: usize, decay: f64, seed: u64) -> Mat<f64> {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut random = |r: usize, c: usize| Mat::from_fn(r, c, |_, _| rng.random::<f64>() - 0.5);
        let mut p = random(n, r);
        for j in 0..r {
            let m = p.col(j).iter().sum::<f64>() / n as f64;
            p.col_mut(j).iter_mut().for_each(|v| *v -= m);
        }
        let mut p = p.qr().compute_thin_Q();
        let q = random(t, r).qr().compute_thin_Q();
        for (j, col) in p.col_iter_mut().enumerate() {
            let s = 10f64.powf(-decay * j as f64);
            col.iter_mut().for_each(|v| *v *= s);
        }
        let mut f = &p * q.transpose();
        for (j, col) in f.col_iter_mut().enumerate() {
            let m = 5.0 + (j as f64 * 0.01).sin();
            col.iter_mut().for_each(|v| *v += m);
        }
        f
    }

    /// An `N x T` ensemble whose deviations have the singular values `10^(-i/2)`,
    /// `i = 0..N-1` (so the weaker half is below what the Gram route resolves).
    pub(super) fn graded_ensemble(n: usize, t: usize) -> Mat<f64> {
        ensemble(n, t, n - 1, 0.5, 11)
    }

    /// An ensemble of exact rank `r` (singular values `10^(-i/4)`).
    pub(super) fn low_rank_ensemble(n: usize, t: usize, r: usize, seed: u64) -> Mat<f64> {
        ensemble(n, t, r, 0.25, seed)
    }

    /// The Gram route (method of snapshots) and the full thin SVD agree: singular values to
    /// `1e-10 sigma_1`, the time functions of the kept shapes to `1e-8`, the rebuilt runs
    /// to `1e-10` relative; the training runs are rebuilt to the truncation error.
    #[test]
    fn gram_route_matches_the_full_svd() {
        let (n, t, k) = (30, 600, 8);
        let f = graded_ensemble(n, t);
        let mean: Vec<f64> = (0..t)
            .map(|c| f.col(c).iter().sum::<f64>() / n as f64)
            .collect();
        let gram = ShapeSpectrum::new(f.as_ref()).unwrap();
        assert!(gram.functions.is_none(), "T >= 2 N takes the Gram route");
        let svd = ShapeSpectrum::by_svd(f.as_ref(), mean).unwrap();
        let (sg, ss) = (gram.singular_values(), svd.singular_values());
        // The Gram route resolves sigma_i / sigma_1 down to about sqrt(10 N eps) = 2.6e-7.
        assert!((12..=14).contains(&sg.len()), "{} resolved", sg.len());
        for (a, b) in sg.iter().zip(ss) {
            assert!((a - b).abs() <= 1e-10 * ss[0], "{a} vs {b}");
        }
        let bg = gram.basis(f.as_ref(), k).unwrap();
        let bs = svd.basis(f.as_ref(), k).unwrap();
        let (gg, gs) = (bg.functions(), bs.functions());
        for j in 0..k {
            for i in 0..t {
                assert_relative_eq!(gg[(i, j)], gs[(i, j)], epsilon = 1e-8);
            }
        }
        let rg = bg.rebuild(gram.coordinates().as_ref());
        let rs = bs.rebuild(svd.coordinates().as_ref());
        let centred_norm = bs.total.sqrt();
        assert!((&rg - &rs).norm_l2() <= 1e-10 * centred_norm);
        // Training runs back to the truncation error (the orthogonal projection).
        let miss = (&rg - &f).norm_l2() / centred_norm;
        assert_relative_eq!(miss, bg.truncation_error(k), max_relative = 1e-6);
        assert_relative_eq!(bg.truncation_error(k), 10f64.powi(-4), max_relative = 0.01);
    }

    /// The Gram route sums fixed groups of sample blocks: the same bits on 1, 2 or 3
    /// threads, with histories long enough for several groups and a partial last block.
    #[test]
    fn spectrum_does_not_depend_on_the_thread_count() {
        let f = graded_ensemble(12, 9 * BLOCK + 37);
        same_on_one_two_and_three_threads(|| {
            let s = ShapeSpectrum::new(f.as_ref()).unwrap();
            let b = s.basis(f.as_ref(), 5).unwrap();
            let rebuilt = b.rebuild(s.coordinates().as_ref());
            (
                s.singular_values().to_vec(),
                s.left.clone(),
                b.rows,
                rebuilt,
            )
        });
    }

    /// Runs `work` in pools of 1, 2 and 3 threads and checks that it returns the same.
    pub(super) fn same_on_one_two_and_three_threads<R: PartialEq + std::fmt::Debug + Send>(
        work: impl Fn() -> R + Sync,
    ) {
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(&work)
        };
        let one = run(1);
        for threads in [2, 3] {
            assert_eq!(one, run(threads), "{threads} threads");
        }
    }

    /// Finite outputs whose column sums overflow still give finite means, on both routes
    /// (the Gram route falls back to the deviations from the mean).
    #[test]
    fn means_of_huge_finite_outputs_are_finite() {
        let f = Mat::from_fn(4, 3, |i, j| if j == 1 { 1e308 } else { (i + j) as f64 });
        let mean = column_means(f.as_ref()).unwrap();
        assert_relative_eq!(mean[1], 1e308, max_relative = 1e-15);
        assert_relative_eq!(mean[2], 3.5);
        let mut g = graded_ensemble(6, 40);
        g.col_mut(7).iter_mut().for_each(|v| *v = 1e308);
        let s = ShapeSpectrum::new(g.as_ref()).unwrap();
        assert_relative_eq!(s.mean[7], 1e308, max_relative = 1e-15);
        let plain = ShapeSpectrum::new(graded_ensemble(6, 40).as_ref()).unwrap();
        // Column 7 is now constant: the spectrum loses its share of the deviations only.
        assert!(s.singular_values()[0] <= plain.singular_values()[0] * (1.0 + 1e-12));
        assert!(
            s.singular_values()
                .iter()
                .all(|v| v.is_finite() && *v > 0.0)
        );
    }

    /// The one-pass Gram matrix is centred exactly: a mean history of `1e8` (deviations of
    /// order 1) leaves the spectrum as it is to the precision the input carries
    /// (`eps 1e8 ~ 2e-8` per entry). A Gram matrix of the raw runs centred afterwards would
    /// carry errors of `eps 1e16 ~ 2` on eigenvalues of order 1.
    #[test]
    fn a_large_mean_history_costs_no_precision() {
        let f = graded_ensemble(20, 3 * BLOCK + 5);
        let mut shifted = f.clone();
        shifted
            .col_iter_mut()
            .for_each(|c| c.iter_mut().for_each(|v| *v += 1e8));
        let (a, b) = (
            ShapeSpectrum::new(f.as_ref()).unwrap(),
            ShapeSpectrum::new(shifted.as_ref()).unwrap(),
        );
        let s1 = a.singular_values()[0];
        for (x, y) in a.singular_values().iter().zip(b.singular_values()).take(6) {
            assert!((x - y).abs() <= 1e-6 * s1, "{x} vs {y}");
        }
        assert_relative_eq!(a.total, b.total, max_relative = 1e-6);
    }

    /// Column sums do not depend on the layout of the matrix (contiguous or strided
    /// columns): the same four partial sums in the same order.
    #[test]
    fn column_sums_are_the_same_bits_for_any_layout() {
        let f = graded_ensemble(13, 30);
        let t = f.transpose().to_owned();
        let strided = t.transpose();
        assert!(strided.col(0).try_as_col_major().is_none());
        for c in 0..30 {
            assert_eq!(
                column_sum(f.as_ref(), c).to_bits(),
                column_sum(strided, c).to_bits()
            );
            let naive: f64 = f.col(c).iter().sum();
            assert_relative_eq!(column_sum(f.as_ref(), c), naive, max_relative = 1e-13);
        }
    }

    #[test]
    fn bad_outputs_are_named() {
        let mut f = graded_ensemble(6, 40);
        f[(2, 17)] = f64::NAN;
        let e = ShapeSpectrum::new(f.as_ref()).unwrap_err();
        assert!(e.to_string().contains("row 2"), "{e}");
        let empty = Mat::<f64>::zeros(0, 5);
        assert!(ShapeSpectrum::new(empty.as_ref()).is_err());
    }

    #[test]
    fn count_keeps_truncation_below_the_loo_error() {
        let sigma = [10.0, 3.0, 1.0, 0.1, 0.01];
        // Coordinates predicted to 1 % of their size: truncation must fall below 0.25 of
        // that.
        let loo: Vec<f64> = sigma.iter().map(|s| (0.01 * s) * (0.01 * s)).collect();
        let k = choose_count(&sigma, &loo);
        let tail = |k: usize| sigma[k..].iter().map(|s| s * s).sum::<f64>();
        let own = |k: usize| loo[..k].iter().sum::<f64>();
        assert!(tail(k) <= 0.0625 * own(k));
        assert!(tail(k - 1) > 0.0625 * own(k - 1));
        assert_eq!(k, 4);
        // Coordinates the surrogate cannot predict at all: few shapes suffice.
        let bad: Vec<f64> = sigma.iter().map(|s| s * s).collect();
        assert_eq!(choose_count(&sigma, &bad), 2);
        // Exact predictions: every shape.
        assert_eq!(choose_count(&sigma, &[0.0; 5]), 5);
    }
}
