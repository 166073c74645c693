//! Allocation of large output matrices.
//!
//! A batch prediction of `Q` points and `T` outputs writes a fresh `Q x T` matrix (80 MB
//! for 1000 time histories of 10^4 samples). Touching that much new memory costs one page
//! fault per 4 KiB page, which on virtual machines dominates the arithmetic: 40-50 ms for
//! 80 MB, against 18 ms for the matrix product that fills it. Like numpy, we ask Linux for
//! transparent huge pages (2 MiB) on such buffers before their first touch, which cuts the
//! faults 512-fold.
//!
//! A fresh result that is zero-filled first and then overwritten by a product is written
//! twice; [`by_column_blocks`] writes it once, block by block, while each block is in
//! cache.
//!
//! This module holds the crate's only `unsafe` code: one `madvise(2)` call on memory the
//! matrix owns, and the block-wise initialisation of [`by_column_blocks`].

use faer::{Mat, MatMut, MatRef};
use rayon::prelude::*;

/// Buffers of at least this many bytes are advised to use huge pages. glibc serves smaller
/// blocks from its heap and recycles them between calls; from 32 MiB (its largest mmap
/// threshold) every allocation is a fresh mapping whose pages fault on first touch.
const HUGE_PAGE_THRESHOLD: usize = 32 << 20;

/// A zero-filled `nrows x ncols` matrix; on Linux, buffers of 32 MiB or more (the
/// threshold above) are first advised to use transparent huge pages (`MADV_HUGEPAGE`), so
/// that filling them costs a few hundred page faults rather than hundreds of thousands.
///
/// The advice is a hint: where the kernel ignores it (huge pages disabled, another
/// operating system), the result is the same zero matrix, allocated as by
/// [`Mat::zeros`].
pub fn zeros(nrows: usize, ncols: usize) -> Mat<f64> {
    let mut m = Mat::<f64>::with_capacity(nrows, ncols);
    let bytes = nrows.saturating_mul(ncols).saturating_mul(size_of::<f64>());
    if bytes >= HUGE_PAGE_THRESHOLD {
        advise_huge_pages(m.as_ptr_mut().cast::<u8>(), bytes);
    }
    m.resize_with(nrows, ncols, |_, _| 0.0);
    m
}

/// Training outputs handed to a fit that keeps them: borrowed, and copied by the fit, or
/// owned, and moved into the model without a copy (an `N x T` ensemble of long histories
/// is megabytes, whose fresh pages cost more than the arithmetic of a shape-basis fit).
///
/// Built by `From` from a [`MatRef`], a `&Mat` or a [`Mat`].
#[derive(Debug)]
pub enum TrainingValues<'a> {
    /// Outputs the caller keeps; the fit stores a [`copy`].
    Borrowed(MatRef<'a, f64>),
    /// Outputs the caller gives away; the fit stores them as they are.
    Owned(Mat<f64>),
}

impl TrainingValues<'_> {
    /// A view of the outputs.
    pub fn view(&self) -> MatRef<'_, f64> {
        match self {
            TrainingValues::Borrowed(m) => *m,
            TrainingValues::Owned(m) => m.as_ref(),
        }
    }

    /// The outputs as an owned matrix: moved when owned, a [`copy`] when borrowed.
    pub fn into_owned(self) -> Mat<f64> {
        match self {
            TrainingValues::Borrowed(m) => copy(m),
            TrainingValues::Owned(m) => m,
        }
    }
}

impl<'a> From<MatRef<'a, f64>> for TrainingValues<'a> {
    fn from(m: MatRef<'a, f64>) -> Self {
        TrainingValues::Borrowed(m)
    }
}

impl<'a> From<&'a Mat<f64>> for TrainingValues<'a> {
    fn from(m: &'a Mat<f64>) -> Self {
        TrainingValues::Borrowed(m.as_ref())
    }
}

impl From<Mat<f64>> for TrainingValues<'_> {
    fn from(m: Mat<f64>) -> Self {
        TrainingValues::Owned(m)
    }
}

/// A copy of `a`: in a buffer allocated as by [`zeros`] from the threshold above, written
/// once by [`MatRef::to_owned`] below it.
pub fn copy(a: MatRef<'_, f64>) -> Mat<f64> {
    let bytes = a
        .nrows()
        .saturating_mul(a.ncols())
        .saturating_mul(size_of::<f64>());
    if bytes < HUGE_PAGE_THRESHOLD {
        return a.to_owned();
    }
    let mut m = zeros(a.nrows(), a.ncols());
    m.copy_from(a);
    m
}

/// Output columns per task when a prediction writes its result with [`by_column_blocks`]
/// (fixed, so results do not depend on the number of threads).
pub(crate) const RESULT_BLOCK: usize = 512;

/// A `nrows x ncols` matrix written block by block in parallel: the columns are cut into
/// blocks of `block` (the last one shorter; `block` is at least 1) and `fill(first, cols)`
/// writes the block of columns `first ..`, as one rayon task (on the calling thread when
/// there is only one block). Each block is zero when
/// `fill` sees it, and so is the padding of its columns ([`zero_padding`]): the task
/// zeroes it right before, so a product written with
/// [`Accum::Replace`](faer::Accum::Replace) touches the memory once, in cache, instead of
/// after a separate zero-fill of the whole matrix. Buffers of 32 MiB or more are advised
/// to use huge pages as by [`zeros`].
///
/// The result equals that of `zeros(nrows, ncols)` followed by `fill` on each block in
/// turn; when `fill` writes each block from its inputs alone, it does not depend on the
/// number of threads. A panic in `fill` propagates, and the partly written matrix is
/// freed.
pub fn by_column_blocks(
    nrows: usize,
    ncols: usize,
    block: usize,
    fill: impl Fn(usize, MatMut<'_, f64>) + Sync,
) -> Mat<f64> {
    by_column_blocks_with(
        nrows,
        ncols,
        block,
        || (),
        |(), first, cols| fill(first, cols),
    )
}

/// As [`by_column_blocks`], with a scratch value for the blocks: `init` makes one per rayon
/// task that runs several blocks (as [`rayon::iter::ParallelIterator::for_each_init`]), and
/// `fill(scratch, first, cols)` may use it as it likes. The result must not depend on what
/// an earlier block left in the scratch, or it would depend on the number of threads.
pub fn by_column_blocks_with<S>(
    nrows: usize,
    ncols: usize,
    block: usize,
    init: impl Fn() -> S + Sync + Send,
    fill: impl Fn(&mut S, usize, MatMut<'_, f64>) + Sync,
) -> Mat<f64> {
    /// The matrix's storage, shared by the tasks; each writes only its own columns.
    struct Storage(*mut f64);
    // SAFETY: the tasks write disjoint column ranges of one allocation that outlives them.
    #[allow(unsafe_code)]
    unsafe impl Sync for Storage {}
    impl Storage {
        fn first(&self) -> *mut f64 {
            self.0
        }
    }

    let block = block.max(1);
    let mut m = Mat::<f64>::with_capacity(nrows, ncols);
    let stride = m.col_stride().unsigned_abs();
    let bytes = stride
        .saturating_mul(ncols)
        .saturating_mul(size_of::<f64>());
    if bytes >= HUGE_PAGE_THRESHOLD {
        advise_huge_pages(m.as_ptr_mut().cast::<u8>(), bytes);
    }
    let storage = Storage(m.as_ptr_mut());
    let write = |scratch: &mut S, b: usize| {
        let start = b * block;
        let len = block.min(ncols - start);
        // SAFETY: `with_capacity` allocated `stride >= nrows` rows for each of the `ncols`
        // columns, so columns `start .. start + len` (`start + len <= ncols`) lie inside the
        // allocation; no other task touches them. They are initialised (zeroed, raw writes
        // with no reference formed) before the view over them is created, padding rows
        // included (see [`zero_padding`]).
        #[allow(unsafe_code)]
        let cols = unsafe {
            let first = storage.first().add(start * stride);
            for j in 0..len {
                std::ptr::write_bytes(first.add(j * stride), 0, stride);
            }
            MatMut::from_raw_parts_mut(first, nrows, len, 1, stride as isize)
        };
        fill(scratch, start, cols);
    };
    let blocks = ncols.div_ceil(block);
    if blocks <= 1 {
        // One block (a single prediction, say): no task for the pool.
        (0..blocks).for_each(|b| write(&mut init(), b));
    } else {
        (0..blocks).into_par_iter().for_each_init(init, write);
    }
    // SAFETY: every column `0 .. ncols` was zeroed by its block's `write` above (the loop
    // has returned), and `nrows x ncols` is within the capacity reserved.
    #[allow(unsafe_code)]
    unsafe {
        m.set_dims(nrows, ncols);
    }
    m
}

/// Zeroes the padding of `m`: the rows between `m.nrows()` and its column stride, which
/// faer allocates (to align the columns) but leaves uninitialised, even in
/// [`Mat::zeros`]. Call it on a matrix that becomes the column-major left operand of a
/// product.
///
/// Why: faer's matrix product loads whole SIMD tiles of such an operand, its padding rows
/// included, and discards those rows of the result. When the memory left there by earlier
/// work happens to hold subnormal numbers, every multiply-add on that tile takes a
/// microcode assist and the product runs 10 to 80 times slower, with a correct result:
/// measured on this crate's machine, a `25 x 32` by `32 x 1024` product 22 us with zero
/// padding against 1,183 us with subnormal padding, and the airframe's shape-basis fit
/// about 35 ms instead of 4 in one fit of twenty. Zeroed padding costs nothing. A matrix
/// without padding is left as it is; the entries of `m` are never changed.
pub fn zero_padding(m: &mut Mat<f64>) {
    let (nrows, ncols) = m.shape();
    let stride = m.col_stride().unsigned_abs();
    if ncols == 0 || stride <= nrows {
        return;
    }
    let base = m.as_ptr_mut();
    // SAFETY: an owned faer matrix stores column `j` at `base + j * stride`, with `stride`
    // its row capacity (at least `nrows`), inside one allocation of at least
    // `stride * ncols` values (the layout `by_column_blocks_with` relies on as well).
    // Rows `nrows .. stride` of each column are padding that no view exposes; raw writes
    // of zeros there form no reference and change no entry of the matrix.
    #[allow(unsafe_code)]
    unsafe {
        for j in 0..ncols {
            std::ptr::write_bytes(base.add(j * stride + nrows), 0, stride - nrows);
        }
    }
}

/// A vector of `len` zeros, advised to use huge pages as by [`zeros`].
pub fn zeros_vec(len: usize) -> Vec<f64> {
    let mut v = Vec::<f64>::with_capacity(len);
    let bytes = len.saturating_mul(size_of::<f64>());
    if bytes >= HUGE_PAGE_THRESHOLD {
        advise_huge_pages(v.as_mut_ptr().cast::<u8>(), bytes);
    }
    v.resize(len, 0.0);
    v
}

/// Advises the kernel to back the 2 MiB-aligned part of `[start, start + len)` with huge
/// pages. `start .. start + len` must lie inside one live allocation.
#[cfg(target_os = "linux")]
#[allow(unsafe_code)]
fn advise_huge_pages(start: *mut u8, len: usize) {
    const HUGE_PAGE: usize = 2 << 20;
    let begin = start as usize;
    let Some(end) = begin.checked_add(len) else {
        return;
    };
    let aligned = begin.div_ceil(HUGE_PAGE) * HUGE_PAGE;
    if aligned >= end {
        return;
    }
    let aligned_len = (end - aligned) / HUGE_PAGE * HUGE_PAGE;
    if aligned_len == 0 {
        return;
    }
    // SAFETY: the range [aligned, aligned + aligned_len) lies inside the matrix's own
    // allocation (`begin <= aligned` and `aligned + aligned_len <= end`). MADV_HUGEPAGE
    // only changes how the kernel backs the pages, never their contents or validity, so
    // no Rust invariant can be broken; a failure (EINVAL where THP is unavailable) leaves
    // the memory as it was, and is deliberately ignored.
    unsafe {
        libc::madvise(
            aligned as *mut libc::c_void,
            aligned_len,
            libc::MADV_HUGEPAGE,
        );
    }
}

#[cfg(not(target_os = "linux"))]
fn advise_huge_pages(_start: *mut u8, _len: usize) {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_and_small_buffers_are_zero_matrices_of_the_requested_shape() {
        for (r, c) in [(0, 0), (3, 0), (0, 5), (7, 3), (1000, 700)] {
            let m = zeros(r, c);
            assert_eq!((m.nrows(), m.ncols()), (r, c));
            assert!(m.col_iter().all(|col| col.iter().all(|&v| v == 0.0)));
        }
        for len in [0, 5, 1 << 20] {
            let v = zeros_vec(len);
            assert_eq!(v.len(), len);
            assert!(v.iter().all(|&x| x == 0.0));
        }
    }

    /// Whether every padding entry of `m` (rows `nrows .. stride`) is zero.
    #[allow(unsafe_code)]
    fn padding_is_zero(m: &Mat<f64>) -> bool {
        let (r, c) = m.shape();
        let stride = m.col_stride().unsigned_abs();
        let base = m.as_ptr();
        // SAFETY: as in `zero_padding`: the padding lies inside the matrix's allocation;
        // it was written (by `zero_padding` or by the test) before it is read here.
        (0..c).all(|j| (r..stride).all(|i| unsafe { *base.add(j * stride + i) } == 0.0))
    }

    /// Garbage planted in the padding (subnormal numbers, as earlier work may leave
    /// there) is zeroed and the entries are untouched; a matrix with no padding, or
    /// empty, is accepted.
    #[test]
    #[allow(unsafe_code)]
    fn padding_is_zeroed_and_entries_kept() {
        let value = |i: usize, j: usize| (i * 31 + j) as f64 - 7.5;
        for (r, c) in [(21, 5), (25, 32), (150, 3), (8, 4), (0, 3), (5, 0)] {
            let mut m = Mat::from_fn(r, c, value);
            let stride = m.col_stride().unsigned_abs();
            let base = m.as_ptr_mut();
            for j in 0..c {
                for i in r..stride {
                    // SAFETY: padding inside the allocation, as in `zero_padding`.
                    unsafe { *base.add(j * stride + i) = 1e-310 };
                }
            }
            if stride > r && c > 0 {
                assert!(!padding_is_zero(&m), "{r} x {c}: garbage planted");
            }
            zero_padding(&mut m);
            assert!(padding_is_zero(&m), "{r} x {c}");
            assert_eq!(m, Mat::from_fn(r, c, value));
        }
        // Matrices written block by block come with zero padding.
        let m = by_column_blocks(21, 1000, 64, |_, _| {});
        assert!(m.col_stride().unsigned_abs() > 21 && padding_is_zero(&m));
    }

    /// Block-wise writing equals a zero-fill followed by the same writes, for every block
    /// size, including empty matrices, one-column blocks and a block wider than the matrix.
    #[test]
    fn blocks_are_written_once_and_completely() {
        let value = |i: usize, j: usize| (i * 31 + j) as f64 - 7.5;
        for (r, c) in [(0, 0), (0, 5), (4, 0), (7, 3), (1000, 700), (3, 4500)] {
            for block in [0, 1, 64, 512, 10_000] {
                let m = by_column_blocks(r, c, block, |first, mut cols| {
                    assert!(
                        cols.as_ref()
                            .col_iter()
                            .all(|col| col.iter().all(|&v| v == 0.0))
                    );
                    for j in 0..cols.ncols() {
                        // Every other row written: the rest must stay zero.
                        for i in (0..cols.nrows()).step_by(2) {
                            cols[(i, j)] = value(i, first + j);
                        }
                    }
                });
                assert_eq!((m.nrows(), m.ncols()), (r, c));
                let expected =
                    Mat::from_fn(r, c, |i, j| if i % 2 == 0 { value(i, j) } else { 0.0 });
                assert_eq!(m, expected, "{r} x {c}, block {block}");
            }
        }
    }

    #[test]
    fn copies_are_exact() {
        let a = Mat::from_fn(700, 900, |i, j| (i * 900 + j) as f64 * 0.5 - 1e3);
        let b = copy(a.as_ref());
        assert_eq!(a, b);
    }
}
