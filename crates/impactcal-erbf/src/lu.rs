//! LU factorisation with partial pivoting, `P A = L U`, on the calling thread for the
//! small systems of RBF fits.
//!
//! faer's `partial_piv_lu` and its inverse use the global thread pool at every size. For
//! the systems of an RBF fit (`N + q` unknowns, a few hundred at most in a study) the
//! pool's hand-offs cost more than they save: on 161 unknowns the parallel factorisation
//! and inverse took 0.32-0.44 and 0.59-0.67 ms against 0.12-0.19 and 0.30-0.33 ms on one
//! thread (2-core machine). The arithmetic is the same either way: both give the same bits.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::{factor, inverse};
use faer::perm::PermRef;
use faer::{Mat, MatRef, Par};

/// Systems of fewer unknowns than this are factorised and inverted on the calling thread.
pub(crate) const SEQUENTIAL_BELOW: usize = 512;

/// The parallelism for an `n x n` factorisation: none below [`SEQUENTIAL_BELOW`], else
/// faer's global setting.
pub(crate) fn parallelism(n: usize) -> Par {
    if n < SEQUENTIAL_BELOW {
        Par::Seq
    } else {
        faer::get_global_parallelism()
    }
}

/// `P A = L U` of a square matrix: `L` unit lower triangular, `U` upper triangular, `P`
/// the row permutation (row `i` of `P A` is row `forward[i]` of `A`).
#[derive(Debug, Clone)]
pub(crate) struct Lu {
    lower: Mat<f64>,
    upper: Mat<f64>,
    forward: Vec<usize>,
    backward: Vec<usize>,
}

impl Lu {
    /// Factorises the square matrix `a` (overwritten). Never fails: a singular matrix gives
    /// a zero pivot, which the callers test through [`upper`](Self::upper).
    pub(crate) fn new(mut a: Mat<f64>) -> Self {
        let n = a.nrows();
        let par = parallelism(n);
        let mut forward = vec![0usize; n];
        let mut backward = vec![0usize; n];
        let scratch = factor::lu_in_place_scratch::<usize, f64>(n, n, par, Default::default());
        factor::lu_in_place(
            a.as_mut(),
            &mut forward,
            &mut backward,
            par,
            MemStack::new(&mut MemBuffer::new(scratch)),
            Default::default(),
        );
        let mut upper = Mat::<f64>::zeros(n, n);
        upper.copy_from_triangular_upper(a.as_ref());
        let mut lower = a;
        for j in 0..n {
            lower.col_mut(j).iter_mut().take(j).for_each(|x| *x = 0.0);
            lower[(j, j)] = 1.0;
        }
        Lu {
            lower,
            upper,
            forward,
            backward,
        }
    }

    /// `L` (`n x n`, unit lower triangular).
    pub(crate) fn lower(&self) -> MatRef<'_, f64> {
        self.lower.as_ref()
    }

    /// `U` (`n x n`, upper triangular).
    pub(crate) fn upper(&self) -> MatRef<'_, f64> {
        self.upper.as_ref()
    }

    /// The row permutation: row `i` of `P A` is row `forward()[i]` of `A`.
    pub(crate) fn forward(&self) -> &[usize] {
        &self.forward
    }

    /// `A^{-1}` (`n x n`).
    pub(crate) fn inverse(&self) -> Mat<f64> {
        let n = self.upper.nrows();
        let par = parallelism(n);
        let mut out = Mat::<f64>::zeros(n, n);
        // `lu_in_place` wrote a permutation and its inverse; the check cannot fail.
        let perm = PermRef::new_checked(&self.forward, &self.backward, n);
        let scratch = inverse::inverse_scratch::<usize, f64>(n, par);
        inverse::inverse(
            out.as_mut(),
            self.lower(),
            self.upper(),
            perm,
            par,
            MemStack::new(&mut MemBuffer::new(scratch)),
        );
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::linalg::solvers::DenseSolveCore;

    fn system(n: usize) -> Mat<f64> {
        Mat::from_fn(n, n, |i, j| {
            let x = ((i * 7919 + j * 104_729) % 1000) as f64 / 1000.0 - 0.5;
            x * x * x + if i == j { 0.01 } else { 0.0 }
        })
    }

    #[test]
    fn factors_and_inverse_are_faers_bit_for_bit() {
        for n in [1, 12, 161, SEQUENTIAL_BELOW + 3] {
            let a = system(n);
            let ours = Lu::new(a.clone());
            let faers = a.partial_piv_lu();
            assert!(ours.lower() == faers.L(), "L, n = {n}");
            assert!(ours.upper() == faers.U(), "U, n = {n}");
            assert_eq!(ours.forward(), faers.P().arrays().0, "P, n = {n}");
            assert!(ours.inverse() == faers.inverse(), "inverse, n = {n}");
        }
    }

    #[test]
    fn the_inverse_inverts() {
        let a = system(40);
        let product = &a * Lu::new(a.clone()).inverse();
        let identity = Mat::<f64>::identity(40, 40);
        let error = (&product - &identity).norm_max();
        assert!(error < 1e-10, "max |A A^-1 - I| = {error:e}");
    }
}
