//! Truncated SVD by a randomized range finder with power iterations
//! (Halko, Martinsson and Tropp, SIAM Review 53(2), 2011, Algorithms 4.4 and 5.1).

use faer::{Mat, MatRef};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

use crate::error::{Result, ShapesError};
use impactcal_core::error::invalid_option;

/// Settings of the randomized solver.
///
/// With `l = k + oversampling` Gaussian test vectors and `q = power_iterations`, the error of
/// the computed `sigma_i` is of order `sigma_{l+1} (sigma_{l+1} / sigma_k)^(2q)` relative
/// terms; at least one power iteration is required.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RandomizedSvd {
    /// Extra test vectors beyond the `k` shapes wanted (default 10).
    pub oversampling: usize,
    /// Power (subspace) iterations with re-orthonormalisation (default 4, at least 1).
    pub power_iterations: usize,
    /// Seed of the Gaussian test matrix; same seed, same result (default fixed).
    pub seed: u64,
}

impl Default for RandomizedSvd {
    fn default() -> Self {
        RandomizedSvd {
            oversampling: 10,
            power_iterations: 4,
            seed: 0x5eed_1a9e,
        }
    }
}

/// Top-`k` singular triplets of `a` (m x n): returns `(U m x k, sigma, V n x k)`.
///
/// Only `l = min(k + p, min(m, n))` singular values are computed, so every returned
/// `sigma` is from the small projected problem.
pub(crate) fn randomized_svd(
    a: MatRef<'_, f64>,
    k: usize,
    opts: &RandomizedSvd,
) -> Result<(Mat<f64>, Vec<f64>, Mat<f64>)> {
    if opts.power_iterations == 0 {
        return Err(invalid_option(
            "power_iterations",
            0,
            "the randomized solver needs at least one power iteration",
        ));
    }
    let (m, n) = a.shape();
    let l = (k + opts.oversampling).min(m.min(n));
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(opts.seed);
    let omega = Mat::from_fn(n, l, |_, _| -> f64 { StandardNormal.sample(&mut rng) });
    let mut q = orthonormal_basis(&(a * &omega));
    for _ in 0..opts.power_iterations {
        let z = orthonormal_basis(&(a.transpose() * &q));
        q = orthonormal_basis(&(a * &z));
    }
    let b = q.transpose() * a;
    let svd = b.thin_svd().map_err(|_| ShapesError::NoConvergence)?;
    let u = &q * svd.U();
    let sigma: Vec<f64> = svd.S().column_vector().iter().copied().collect();
    Ok((u, sigma, svd.V().to_owned()))
}

fn orthonormal_basis(y: &Mat<f64>) -> Mat<f64> {
    y.qr().compute_thin_Q()
}
