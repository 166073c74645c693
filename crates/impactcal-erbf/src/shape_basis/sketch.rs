//! The sketch route of [`ShapeSpectrum::new`] for large ensembles of low rank (see
//! [`ShapeSpectrum`]): a sparse sketch at sampled times finds the rank and the range of the
//! deviations, one pass over the runs projects them onto it, and an energy check proves
//! that the range holds all of them.

use std::sync::Mutex;

use faer::linalg::matmul::matmul;
use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::{Accum, Mat, MatRef, Par};
use rayon::prelude::*;

use super::{ShapeSpectrum, column_sum, fix_signs, kept_rows, leading_roots, symmetric_eigen};
use crate::buffer;
use crate::error::Result;

/// Columns of the sparse sketch `Y = P D_S Omega` that tests an ensemble for low rank.
pub(super) const SKETCH_WIDTH: usize = 64;

/// Samples per block (and task) of the pass that projects the runs onto the sketch's range:
/// scratch small enough to stay in cache.
const SKETCH_BLOCK: usize = 64;

/// Samples per task when the projections onto the sketch's range are rotated into the time
/// functions.
const ROTATION_BLOCK: usize = 512;

/// Sampled times per run in the sketch: `SKETCH_SAMPLES_PER_RUN N` of the `T` samples,
/// evenly spaced.
const SKETCH_SAMPLES_PER_RUN: usize = 4;

/// Nonzero entries (random signs, random columns) in each row of the sketching matrix
/// `Omega` (`T x SKETCH_WIDTH`).
const SKETCH_NONZEROS: usize = 2;

impl ShapeSpectrum {
    /// The decomposition through a sparse sketch when the deviations are of numerically
    /// low rank (see the type's documentation); `None` when they are not, or when the
    /// data are not finite (the Gram route then names the bad entry).
    pub(super) fn by_sketch(values: MatRef<'_, f64>) -> Result<Option<Self>> {
        let n = values.nrows();
        let sketch = sampled_sketch(values);
        if !sketch.is_all_finite() {
            return Ok(None);
        }
        let Some(range) = low_rank_range(centre_columns(sketch)) else {
            return Ok(None);
        };
        let r = range.ncols();
        let Projection {
            mut rows,
            gram,
            total,
        } = project(values, range.as_ref());
        let mean: Vec<f64> = rows.row(r).iter().copied().collect();
        if !total.is_finite() || !mean.iter().all(|m| m.is_finite()) {
            return Ok(None);
        }
        let captured: f64 = (0..r).map(|i| gram[(i, i)]).sum();
        if total - captured > 10.0 * n as f64 * f64::EPSILON * total {
            return Ok(None);
        }
        let (lambda, vectors) = symmetric_eigen(gram.as_ref())?;
        let (sigma, order) = leading_roots(&lambda, n);
        let mut rotation = Mat::from_fn(r, order.len(), |i, j| vectors[(i, order[j])]);
        let mut left = Mat::<f64>::zeros(n, order.len());
        matmul(
            left.as_mut(),
            Accum::Replace,
            range.as_ref(),
            rotation.as_ref(),
            1.0,
            Par::Seq,
        );
        let signs = fix_signs(left.as_mut());
        for (j, s) in signs.iter().enumerate() {
            rotation.col_mut(j).iter_mut().for_each(|w| *w *= s);
        }
        // G^T = diag(sigma)^{-1} W^T B, in place of B.
        let mut scaled = Mat::from_fn(order.len(), r, |j, i| rotation[(i, j)] / sigma[j]);
        buffer::zero_padding(&mut scaled);
        rows.par_col_chunks_mut(ROTATION_BLOCK).for_each_init(
            || Mat::<f64>::zeros(scaled.nrows(), ROTATION_BLOCK),
            |product, chunk| {
                let width = chunk.ncols();
                let mut product = product.as_mut().subcols_mut(0, width);
                matmul(
                    product.as_mut(),
                    Accum::Replace,
                    scaled.as_ref(),
                    chunk.as_ref().subrows(0, r),
                    1.0,
                    Par::Seq,
                );
                chunk.subrows_mut(0, scaled.nrows()).copy_from(product);
            },
        );
        let rows = if sigma.len() < r {
            kept_rows(rows.as_ref(), sigma.len())
        } else {
            rows
        };
        Ok(Some(ShapeSpectrum {
            mean,
            sigma,
            left,
            functions: Some(rows),
            total,
        }))
    }
}

/// Writes the deviations `d_k = x_k - r` of a column from a reference value `r` into `out`
/// and returns `sum_k (d_k - c)^2` (in eight interleaved partial sums: independent chains
/// of additions, which the processor overlaps).
fn deviations(x: faer::ColRef<'_, f64>, r: f64, c: f64, out: &mut [f64]) -> f64 {
    let mut acc = [0.0f64; 8];
    let mut add = |i: usize, d: f64, out: &mut f64| {
        *out = d;
        acc[i % 8] += (d - c) * (d - c);
    };
    match x.try_as_col_major() {
        Some(x) => {
            for (i, (o, v)) in out.iter_mut().zip(x.as_slice()).enumerate() {
                add(i, v - r, o);
            }
        }
        None => {
            for (i, (o, v)) in out.iter_mut().zip(x.iter()).enumerate() {
                add(i, v - r, o);
            }
        }
    }
    acc.iter().sum()
}

/// The sparse sketch `Y = D_S Omega` (`N x SKETCH_WIDTH`) of the deviations
/// `D = F - 1 f_1^T` from the first run, at the sampled times `S`: every
/// `stride`-th sample, `min(T, SKETCH_SAMPLES_PER_RUN N)` of them, so that the sketch reads
/// a small part of `F`. Row `j` of `Omega` has [`SKETCH_NONZEROS`] entries `+-1` in columns
/// drawn by [`sketch_entry`] from `j` alone. Cost `SKETCH_NONZEROS N |S|` additions.
fn sampled_sketch(values: MatRef<'_, f64>) -> Mat<f64> {
    let (n, t) = values.shape();
    let stride = t.div_ceil(SKETCH_SAMPLES_PER_RUN * n).max(1);
    let mut sketch = Mat::<f64>::zeros(n, SKETCH_WIDTH);
    let mut deviations = vec![0.0; n];
    for j in (0..t).step_by(stride) {
        let m = values[(0, j)];
        deviations
            .iter_mut()
            .zip(values.col(j).iter())
            .for_each(|(d, v)| *d = v - m);
        for p in 0..SKETCH_NONZEROS {
            let (target, sign) = sketch_entry(j, p);
            let y = sketch.col_as_slice_mut(target);
            if sign > 0.0 {
                y.iter_mut().zip(&deviations).for_each(|(y, d)| *y += d);
            } else {
                y.iter_mut().zip(&deviations).for_each(|(y, d)| *y -= d);
            }
        }
    }
    sketch
}

/// Entry `p` of row `sample` of the sketching matrix: its column and its sign, from the
/// SplitMix64 finaliser of `SKETCH_NONZEROS sample + p` (a fixed pseudo-random function:
/// the same sketch on every call).
fn sketch_entry(sample: usize, p: usize) -> (usize, f64) {
    let mut z = ((sample * SKETCH_NONZEROS + p) as u64)
        .wrapping_add(1)
        .wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    let column = ((z >> 32) % SKETCH_WIDTH as u64) as usize;
    (column, if z & 1 == 0 { 1.0 } else { -1.0 })
}

/// `P Y` with the centring projector `P = I - 1 1^T / N`: each column minus its mean.
fn centre_columns(mut y: Mat<f64>) -> Mat<f64> {
    let scale = 1.0 / y.nrows() as f64;
    for col in y.col_iter_mut() {
        let m = col.as_ref().iter().sum::<f64>() * scale;
        col.iter_mut().for_each(|v| *v -= m);
    }
    y
}

/// The orthonormal range `Q` (`N x r`) of a sketch `Y` (`N x w`) of numerical rank
/// `r <= w / 2`; `None` when the rank is higher, or the sketch zero or not decomposable.
///
/// The rank counts the eigenvalues of `Y^T Y = V diag(s^2) V^T` (`w x w`, `O(N w^2)`)
/// above `10 N eps s_1^2`, the floor of the Gram route; `Q` is the (sequential) Householder
/// orthonormalisation of `Y V_r`.
fn low_rank_range(sketch: Mat<f64>) -> Option<Mat<f64>> {
    let (n, w) = sketch.shape();
    let mut gram = Mat::<f64>::zeros(w, w);
    triangular::matmul(
        gram.as_mut(),
        BlockStructure::TriangularLower,
        Accum::Replace,
        sketch.transpose(),
        BlockStructure::Rectangular,
        sketch.as_ref(),
        BlockStructure::Rectangular,
        1.0,
        Par::Seq,
    );
    let (lambda, vectors) = symmetric_eigen(gram.as_ref()).ok()?;
    let (roots, order) = leading_roots(&lambda, n);
    if roots.first().is_none_or(|&s| s <= 0.0) || order.len() > w / 2 {
        return None;
    }
    let directions = Mat::from_fn(w, order.len(), |i, j| vectors[(i, order[j])]);
    let mut spanning = Mat::<f64>::zeros(n, order.len());
    matmul(
        spanning.as_mut(),
        Accum::Replace,
        sketch.as_ref(),
        directions.as_ref(),
        1.0,
        Par::Seq,
    );
    Some(crate::thin_qr::thin_qr(spanning, false).q1)
}

/// What one pass over the runs gives for a range `Q` ([`project`]).
struct Projection {
    /// `[B ; f_bar^T]` (`(r + 1) x T`).
    rows: Mat<f64>,
    /// The lower triangle of `B B^T` (`r x r`).
    gram: Mat<f64>,
    /// `||C||_F^2`.
    total: f64,
}

/// One pass over the runs `values` (`N x T`) for a range `Q` (`N x r`, orthonormal columns
/// orthogonal to `1`): `[B ; f_bar^T]`, `B B^T` and `||C||_F^2`.
///
/// `f_bar` is the mean history (column sums by [`column_sum`], as the Gram route), `C` the
/// deviations from it, and `B = Q^T C`, formed as `Q^T D` from the deviations
/// `D = F - 1 f_1^T` from the first run: `C = P D` and `Q^T P = Q^T` for `Q` orthogonal to
/// `1`, and `D` is of the size of `C`, so no large mean enters the product. Each block of
/// samples is its own task and columns (the result does not depend on the number of
/// threads); the energies `sum (d_kj - dbar_j)^2` and the products `B_b B_b^T` of the
/// blocks are summed in order.
fn project(values: MatRef<'_, f64>, range: MatRef<'_, f64>) -> Projection {
    let (n, t) = values.shape();
    let r = range.ncols();
    let scale = 1.0 / n as f64;
    let blocks: Vec<Mutex<(f64, Mat<f64>)>> = (0..t.div_ceil(SKETCH_BLOCK))
        .map(|_| Mutex::new((0.0, Mat::new())))
        .collect();
    let rows = buffer::by_column_blocks_with(
        r + 1,
        t,
        SKETCH_BLOCK,
        || Mat::<f64>::zeros(n, SKETCH_BLOCK.min(t)),
        |scratch, start, mut cols| {
            let width = cols.ncols();
            let mut energy = 0.0;
            for j in 0..width {
                let mean = column_sum(values, start + j) * scale;
                cols[(r, j)] = mean;
                let x = values.col(start + j);
                energy += deviations(x, x[0], mean - x[0], scratch.col_as_slice_mut(j));
            }
            let d = scratch.as_ref().subcols(0, width);
            matmul(
                cols.as_mut().subrows_mut(0, r),
                Accum::Replace,
                range.transpose(),
                d,
                1.0,
                Par::Seq,
            );
            let b = cols.as_ref().subrows(0, r);
            let mut gram = Mat::<f64>::zeros(r, r);
            triangular::matmul(
                gram.as_mut(),
                BlockStructure::TriangularLower,
                Accum::Replace,
                b,
                BlockStructure::Rectangular,
                b.transpose(),
                BlockStructure::Rectangular,
                1.0,
                Par::Seq,
            );
            if let Ok(mut slot) = blocks[start / SKETCH_BLOCK].lock() {
                *slot = (energy, gram);
            }
        },
    );
    let mut total = 0.0;
    let mut gram = Mat::<f64>::zeros(r, r);
    for block in blocks {
        let (energy, part) = block.into_inner().unwrap_or_else(|e| e.into_inner());
        total += energy;
        if part.nrows() == r {
            gram += &part;
        }
    }
    Projection { rows, gram, total }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{low_rank_ensemble, same_on_one_two_and_three_threads};
    use super::super::{SKETCH_MIN_RUNS, ShapeSpectrum};
    use super::*;
    use approx::assert_relative_eq;

    /// On a large ensemble of low rank the sketch route gives the decomposition of the
    /// method of snapshots: the same mean (bits), singular values to `1e-12 sigma_1`,
    /// coordinates, time functions and rebuilt runs to `1e-9`, and the training runs back
    /// exactly (the truncation error of all `r` shapes is zero).
    #[test]
    fn the_sketch_route_matches_the_gram_route_on_low_rank_ensembles() {
        let (n, t, r) = (150, 3000, 12);
        let f = low_rank_ensemble(n, t, r, 5);
        let sketch = ShapeSpectrum::new(f.as_ref()).unwrap();
        assert!(
            sketch.functions.is_some(),
            "a low-rank ensemble takes the sketch route"
        );
        let gram = ShapeSpectrum::by_gram(f.as_ref()).unwrap();
        assert_eq!(sketch.mean, gram.mean);
        let (ss, sg) = (sketch.singular_values(), gram.singular_values());
        assert_eq!(ss.len(), r);
        assert_eq!(sg.len(), r);
        for (a, b) in ss.iter().zip(sg) {
            assert!((a - b).abs() <= 1e-12 * sg[0], "{a} vs {b}");
        }
        assert_relative_eq!(sketch.total, gram.total, max_relative = 1e-12);
        let (cs, cg) = (sketch.coordinates(), gram.coordinates());
        assert!((&cs - &cg).norm_max() <= 1e-9 * sg[0]);
        let bs = sketch.clone().into_basis(f.as_ref(), r).unwrap();
        let bg = gram.basis(f.as_ref(), r).unwrap();
        assert!((bs.functions() - bg.functions()).norm_max() <= 1e-9);
        assert_relative_eq!(bs.truncation_error(r), 0.0);
        let rebuilt = bs.rebuild(cs.as_ref());
        assert!((&rebuilt - &f).norm_max() <= 1e-12 * f.norm_max());
        // Fewer shapes: the first rows of the same functions.
        let three = sketch.basis(f.as_ref(), 3).unwrap();
        assert_eq!(three.len(), 3);
        assert_eq!(three.functions(), bs.functions().subcols(0, 3));
        assert_eq!(three.mean(), bs.mean());
    }

    /// Deviations of full rank leave the sketch route at once: the method of snapshots.
    #[test]
    fn full_rank_ensembles_take_the_gram_route() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let f = Mat::from_fn(SKETCH_MIN_RUNS + 2, 700, |_, _| rng.random::<f64>());
        let s = ShapeSpectrum::new(f.as_ref()).unwrap();
        assert!(s.functions.is_none());
        assert_eq!(s.singular_values().len(), SKETCH_MIN_RUNS + 1);
    }

    /// A shape that lives between the sampled times is invisible to the sketch; the energy
    /// check finds what the range misses and the Gram route decomposes the runs, with the
    /// extra shape.
    #[test]
    fn a_shape_the_sketch_misses_sends_the_runs_to_the_gram_route() {
        let (n, t, r) = (130, 2000, 6);
        let mut f = low_rank_ensemble(n, t, r, 7);
        let stride = t.div_ceil(SKETCH_SAMPLES_PER_RUN * n);
        assert!(stride > 1);
        for k in 0..n {
            f[(k, 1)] += 1e-3 * ((k * 37 % 11) as f64 - 5.0);
        }
        let s = ShapeSpectrum::new(f.as_ref()).unwrap();
        assert!(s.functions.is_none(), "the Gram route");
        assert_eq!(s.singular_values().len(), r + 1);
        let without = ShapeSpectrum::new(low_rank_ensemble(n, t, r, 7).as_ref()).unwrap();
        assert!(without.functions.is_some(), "the sketch route");
    }

    /// The sketch route's blocks are fixed: the same bits on 1, 2 or 3 threads.
    #[test]
    fn the_sketch_route_does_not_depend_on_the_thread_count() {
        let f = low_rank_ensemble(SKETCH_MIN_RUNS, 5 * ROTATION_BLOCK + 37, 9, 3);
        same_on_one_two_and_three_threads(|| {
            let s = ShapeSpectrum::new(f.as_ref()).unwrap();
            assert!(s.functions.is_some());
            (s.sigma, s.left, s.functions, s.total.to_bits())
        });
    }

    /// A mean history far above the deviations: the sketch route still applies and loses
    /// no more than the input's own rounding (`eps 1e4` per entry, `1e-9` of `sigma_1` in
    /// all). A mean of `1e8` would make the rounding itself a shape above the resolved
    /// floor, and send the runs to the Gram route, as it should.
    #[test]
    fn a_large_mean_history_costs_the_sketch_route_no_precision() {
        let f = low_rank_ensemble(SKETCH_MIN_RUNS, 1500, 8, 13);
        let mut shifted = f.clone();
        shifted
            .col_iter_mut()
            .for_each(|c| c.iter_mut().for_each(|v| *v += 1e4));
        let (a, b) = (
            ShapeSpectrum::new(f.as_ref()).unwrap(),
            ShapeSpectrum::new(shifted.as_ref()).unwrap(),
        );
        assert!(a.functions.is_some() && b.functions.is_some());
        let s1 = a.singular_values()[0];
        assert_eq!(a.singular_values().len(), b.singular_values().len());
        for (x, y) in a.singular_values().iter().zip(b.singular_values()) {
            assert!((x - y).abs() <= 1e-8 * s1, "{x} vs {y}");
        }
        assert_relative_eq!(a.total, b.total, max_relative = 1e-8);
    }

    /// A bad entry in a large ensemble is named as in a small one.
    #[test]
    fn bad_outputs_of_large_ensembles_are_named() {
        let mut f = low_rank_ensemble(SKETCH_MIN_RUNS, 600, 5, 1);
        f[(70, 301)] = f64::INFINITY;
        let e = ShapeSpectrum::new(f.as_ref()).unwrap_err();
        assert!(e.to_string().contains("row 70"), "{e}");
        f[(70, 301)] = f64::NAN;
        let e = ShapeSpectrum::new(f.as_ref()).unwrap_err();
        assert!(e.to_string().contains("row 70"), "{e}");
    }
}
