//! Input checks shared by the decomposition, comparison and expansion.

use faer::MatRef;

use crate::error::{Result, ShapesError};

/// Fails on an empty matrix or a non-finite entry, naming `what` and the position.
pub(crate) fn finite_nonempty(what: &str, a: MatRef<'_, f64>) -> Result<()> {
    if a.nrows() == 0 || a.ncols() == 0 {
        return Err(ShapesError::Empty { what: what.into() });
    }
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            if !a[(i, j)].is_finite() {
                return Err(ShapesError::NonFinite {
                    what: what.into(),
                    row: i,
                    column: j,
                });
            }
        }
    }
    Ok(())
}

/// Numerical rank of a matrix with singular values `s` (non-increasing) and shape
/// `m x n`: the count of `s_i > max(m, n) eps s_0` (the LAPACK/numpy default tolerance).
pub(crate) fn numerical_rank(s: &[f64], m: usize, n: usize) -> usize {
    let Some(&s0) = s.first() else { return 0 };
    let tol = m.max(n) as f64 * f64::EPSILON * s0;
    s.iter().take_while(|&&v| v > tol).count()
}
