//! Input checks shared by the decomposition, comparison and expansion.

use faer::MatRef;
use impactcal_core::{CoreError, check_finite_mat};

use crate::error::Result;

/// Fails on an empty matrix or a non-finite entry, naming `what` and the position
/// ([`CoreError::Empty`], [`CoreError::NonFinite`]).
pub(crate) fn finite_nonempty(what: &str, a: MatRef<'_, f64>) -> Result<()> {
    if a.nrows() == 0 || a.ncols() == 0 {
        return Err(CoreError::Empty { what: what.into() }.into());
    }
    Ok(check_finite_mat(what, a)?)
}

/// Numerical rank of a matrix with singular values `s` (non-increasing) and shape
/// `m x n`: the count of `s_i > max(m, n) eps s_0` (the LAPACK/numpy default tolerance).
pub(crate) fn numerical_rank(s: &[f64], m: usize, n: usize) -> usize {
    let Some(&s0) = s.first() else { return 0 };
    let tol = m.max(n) as f64 * f64::EPSILON * s0;
    s.iter().take_while(|&&v| v > tol).count()
}
