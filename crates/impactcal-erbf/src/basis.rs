//! The ERBF basis: for a scaled query `u` and scaled centres `x_i`, the vector `b(u)` of the
//! `M = N (3 m + 1)` basis values (the Gaussian radial functions first, then per centre `i`
//! and input `j` the values `phi_L`, `phi_R` and `xi` of `xi_ij = u^j - x_i^j`, each family
//! times its weight), and its derivatives.

use faer::{Mat, MatRef};
use rayon::prelude::*;

use crate::buffer;
use crate::nrbf::{LeftRight, dphi_l, dphi_r};
use crate::options::ErbfOptions;

/// The basis vectors of the queries `u` (`Q x m`, scaled) with respect to the centres
/// `centres` (`N x m`, scaled), as the columns of an `M x Q` matrix (built in parallel).
pub(crate) fn basis_matrix_t(
    u: MatRef<'_, f64>,
    centres: MatRef<'_, f64>,
    o: &ErbfOptions,
) -> Mat<f64> {
    let m = centres.ncols();
    let c = row_major(centres);
    let q = u.nrows();
    let u = row_major(u);
    // Small chunks: the matrix of a fit has only N columns to share between threads.
    const COLUMNS: usize = 16;
    let mut bt = buffer::zeros(centres.nrows() * (3 * m + 1), q);
    bt.par_col_chunks_mut(COLUMNS)
        .enumerate()
        .for_each(|(k, cols)| {
            let len = cols.ncols();
            fill_basis(&u[k * COLUMNS * m..(k * COLUMNS + len) * m], &c, m, o, cols);
        });
    bt
}

/// The entries of `a` (`r x m`) row by row.
pub(crate) fn row_major(a: MatRef<'_, f64>) -> Vec<f64> {
    (0..a.nrows())
        .flat_map(|i| (0..a.ncols()).map(move |j| a[(i, j)]))
        .collect()
}

/// Writes into the columns of `out` (`M x Q`) the basis vectors of the scaled queries `u`
/// (row-major, `Q x m`) with respect to the scaled centres `c` (row-major, `N x m`):
/// radial values first, then per centre and input `{phi_L, phi_R, xi}`, each family times
/// its weight.
pub(crate) fn fill_basis(
    u: &[f64],
    c: &[f64],
    m: usize,
    o: &ErbfOptions,
    mut out: faer::MatMut<'_, f64>,
) {
    impactcal_core::simd::clear_upper_registers();
    let lr = LeftRight::new(o.order as i32, o.gamma);
    let inv2rc2 = 0.5 / (o.rc * o.rc);
    let w = o.weights;
    let n = c.len() / m.max(1);
    for (q, x) in u.chunks_exact(m.max(1)).enumerate() {
        let Some(col) = out.as_mut().col_mut(q).try_as_col_major_mut() else {
            continue;
        };
        let col = col.as_slice_mut();
        let (radial, rest) = col.split_at_mut(n);
        for ((r, out3m), ci) in radial
            .iter_mut()
            .zip(rest.chunks_exact_mut(3 * m))
            .zip(c.chunks_exact(m))
        {
            let mut d2 = 0.0;
            for ((&xj, &cj), o3) in x.iter().zip(ci).zip(out3m.chunks_exact_mut(3)) {
                let xi = xj - cj;
                d2 += xi * xi;
                let (l, rr) = lr.values(xi);
                o3[0] = w.left_right * l;
                o3[1] = w.left_right * rr;
                o3[2] = w.beta * xi;
            }
            *r = w.radial * (-d2 * inv2rc2).exp();
        }
    }
}

/// Derivatives of the basis vector at the scaled point `u`: an `M x m` matrix whose column
/// `j` is `d b / d u^j`.
pub(crate) fn basis_gradient(u: &[f64], centres: MatRef<'_, f64>, o: &ErbfOptions) -> Mat<f64> {
    let n = centres.nrows();
    let m = centres.ncols();
    let order = o.order as i32;
    let w = o.weights;
    let mut db = Mat::<f64>::zeros(n * (3 * m + 1), m);
    for i in 0..n {
        let d2: f64 = (0..m).map(|j| (u[j] - centres[(i, j)]).powi(2)).sum();
        let psi = w.radial * (-0.5 * d2 / (o.rc * o.rc)).exp();
        for j in 0..m {
            let xi = u[j] - centres[(i, j)];
            db[(i, j)] = -xi / (o.rc * o.rc) * psi;
            let base = n + 3 * (i * m + j);
            db[(base, j)] = w.left_right * dphi_l(xi, order, o.gamma);
            db[(base + 1, j)] = w.left_right * dphi_r(xi, order, o.gamma);
            db[(base + 2, j)] = w.beta;
        }
    }
    db
}
