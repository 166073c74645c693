//! The thin QR factorisation `A^T = Q_1 R` behind the ERBF fit.
//!
//! `A^T` is tall and narrow (`M = N (3 m + 1)` rows, `N` columns). On such shapes faer's
//! parallel Householder QR is slower than its sequential one, so the factorisation splits
//! the rows in two halves instead (a two-block TSQR): each half is factorised on its own
//! thread, `[A_1; A_2] = [Q_a R_a; Q_b R_b]`; the stacked triangles are factorised again,
//! `[R_a; R_b] = Q_s R`; and `Q_1 = [Q_a Q_s,top; Q_b Q_s,bottom]`, formed by applying each
//! half's reflectors to its block of `Q_s`. This is as stable as one Householder QR (every
//! step is orthogonal) and its result does not depend on the number of threads.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::householder::{
    apply_block_householder_sequence_on_the_left_in_place_scratch,
    apply_block_householder_sequence_on_the_left_in_place_with_conj,
};
use faer::linalg::qr::no_pivoting::factor::{
    qr_in_place, qr_in_place_scratch, recommended_block_size,
};
use faer::{Conj, Mat, MatMut, MatRef, Par};

use crate::buffer;

/// `Q_1` (`M x N`, orthonormal columns) and `R` (`N x N`, upper triangular).
pub(crate) struct ThinQr {
    pub(crate) q1: Mat<f64>,
    pub(crate) r: Mat<f64>,
}

/// Below this many multiply-adds (`M N^2`) one sequential Householder QR is used.
const SPLIT_WORK: usize = 1 << 21;

/// Factorises `a` (`M x N`, `M >= N`), overwriting it. With `parallel` and enough work the
/// two halves run side by side; otherwise one sequential Householder QR.
pub(crate) fn thin_qr(mut a: Mat<f64>, parallel: bool) -> ThinQr {
    let (m, n) = a.shape();
    if !parallel || m < 2 * n || m.saturating_mul(n * n) < SPLIT_WORK {
        let h = householder_qr(a.as_mut());
        let r = upper(a.as_ref().subrows(0, n));
        let mut q1 = buffer::zeros(m, n);
        q1.diagonal_mut().fill(1.0);
        apply_reflectors(a.as_ref(), h.as_ref(), q1.as_mut());
        return ThinQr { q1, r };
    }
    let half = m / 2;
    let (h_top, h_bottom) = {
        let (top, bottom) = a.as_mut().split_at_row_mut(half);
        rayon::join(move || householder_qr(top), move || householder_qr(bottom))
    };
    let mut stacked = Mat::<f64>::zeros(2 * n, n);
    stacked
        .as_mut()
        .subrows_mut(0, n)
        .copy_from(upper(a.as_ref().subrows(0, n)));
    stacked
        .as_mut()
        .subrows_mut(n, n)
        .copy_from(upper(a.as_ref().subrows(half, n)));
    let h_stacked = householder_qr(stacked.as_mut());
    let r = upper(stacked.as_ref().subrows(0, n));
    let mut q_stacked = Mat::<f64>::zeros(2 * n, n);
    q_stacked.diagonal_mut().fill(1.0);
    apply_reflectors(stacked.as_ref(), h_stacked.as_ref(), q_stacked.as_mut());
    let mut q1 = buffer::zeros(m, n);
    q1.as_mut()
        .subrows_mut(0, n)
        .copy_from(q_stacked.as_ref().subrows(0, n));
    q1.as_mut()
        .subrows_mut(half, n)
        .copy_from(q_stacked.as_ref().subrows(n, n));
    {
        let (a_top, a_bottom) = a.as_ref().split_at_row(half);
        let (q_top, q_bottom) = q1.as_mut().split_at_row_mut(half);
        rayon::join(
            move || apply_reflectors(a_top, h_top.as_ref(), q_top),
            move || apply_reflectors(a_bottom, h_bottom.as_ref(), q_bottom),
        );
    }
    ThinQr { q1, r }
}

/// Sequential Householder QR of `a` in place (`R` above the diagonal, reflectors below);
/// returns the block coefficients of the reflectors.
fn householder_qr(a: MatMut<'_, f64>) -> Mat<f64> {
    let (m, n) = a.shape();
    let block = recommended_block_size::<f64>(m, n);
    let mut h = Mat::<f64>::zeros(block, n.min(m));
    qr_in_place(
        a,
        h.as_mut(),
        Par::Seq,
        MemStack::new(&mut MemBuffer::new(qr_in_place_scratch::<f64>(
            m,
            n,
            block,
            Par::Seq,
            Default::default(),
        ))),
        Default::default(),
    );
    h
}

/// `x <- Q x` for the reflectors stored in `basis` with block coefficients `h`.
fn apply_reflectors(basis: MatRef<'_, f64>, h: MatRef<'_, f64>, x: MatMut<'_, f64>) {
    let (m, k) = (x.nrows(), x.ncols());
    apply_block_householder_sequence_on_the_left_in_place_with_conj(
        basis,
        h,
        Conj::No,
        x,
        Par::Seq,
        MemStack::new(&mut MemBuffer::new(
            apply_block_householder_sequence_on_the_left_in_place_scratch::<f64>(m, h.nrows(), k),
        )),
    );
}

/// The upper triangle of a square matrix.
fn upper(a: MatRef<'_, f64>) -> Mat<f64> {
    Mat::from_fn(
        a.nrows(),
        a.ncols(),
        |i, j| if i <= j { a[(i, j)] } else { 0.0 },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(m: usize, n: usize, parallel: bool) {
        let a = Mat::from_fn(m, n, |i, j| {
            ((i * 31 + j * 17) % 23) as f64 / 23.0 - 0.4 + if i == j { 2.0 } else { 0.0 }
        });
        let ThinQr { q1, r } = thin_qr(a.clone(), parallel);
        let recon = &q1 * &r;
        let gram = q1.transpose() * &q1;
        for j in 0..n {
            for i in 0..m {
                assert!(
                    (recon[(i, j)] - a[(i, j)]).abs() < 1e-12,
                    "A = Q R at ({i}, {j})"
                );
            }
            for i in 0..n {
                let e = if i == j { 1.0 } else { 0.0 };
                assert!((gram[(i, j)] - e).abs() < 1e-12, "Q^T Q = I at ({i}, {j})");
                if i > j {
                    assert!(r[(i, j)] == 0.0, "R is upper triangular");
                }
            }
        }
    }

    #[test]
    fn both_paths_give_an_orthonormal_factor_and_a_triangle_that_reproduce_the_matrix() {
        check(40, 7, false);
        check(40, 7, true);
        check(4650, 150, true);
        check(4650, 150, false);
        check(301, 150, true);
    }
}
