//! Latin hypercubes, plain and symmetric.

use rand::Rng;
use rand::seq::SliceRandom;

use crate::error::{CoreError, Result};
use faer::Mat;

fn check(n: usize, dim: usize) -> Result<()> {
    if n == 0 || dim == 0 {
        return Err(CoreError::Invalid(format!(
            "a Latin hypercube needs at least one point and one dimension ({n} x {dim} asked)"
        )));
    }
    Ok(())
}

/// A Latin hypercube of `n` points in `[0, 1)^dim` (McKay, Beckman & Conover 1979), one per
/// row of an `n x dim` matrix.
///
/// Every dimension is cut into `n` strata `[k/n, (k+1)/n)`; each stratum holds exactly one
/// point, at a uniform random position inside it, and the strata of different dimensions
/// are paired by independent random permutations.
///
/// # Errors
/// [`CoreError::Invalid`] when `n` or `dim` is zero.
pub fn latin_hypercube(n: usize, dim: usize, rng: &mut impl Rng) -> Result<Mat<f64>> {
    check(n, dim)?;
    let mut data = vec![0.0; n * dim];
    let mut strata: Vec<usize> = (0..n).collect();
    let width = 1.0 / n as f64;
    for j in 0..dim {
        strata.shuffle(rng);
        for (i, &k) in strata.iter().enumerate() {
            data[i * dim + j] = ((k as f64 + rng.random::<f64>()) * width).min(super::BELOW_ONE);
        }
    }
    Ok(Mat::from_fn(n, dim, |i, j| data[i * dim + j]))
}

/// A symmetric Latin hypercube of `n` points in `(0, 1)^dim` (Ye, Li & Sudjianto 2000), one
/// per row of an `n x dim` matrix; the
/// initial design of the CORS-RBF optimiser (Regis & Shoemaker).
///
/// Points sit at the centres `(k + 1/2)/n` of the strata, one per stratum in every
/// dimension, and come in mirrored pairs: row `n - 1 - i` is `1 - row i`. For odd `n` the
/// middle row is the centre of the cube. The pairing is random: for each dimension the
/// first `n/2` rows get a random permutation of the lower half of the levels, each one
/// swapped with its mirror level with probability 1/2.
///
/// # Errors
/// [`CoreError::Invalid`] when `n` or `dim` is zero.
pub fn symmetric_latin_hypercube(n: usize, dim: usize, rng: &mut impl Rng) -> Result<Mat<f64>> {
    check(n, dim)?;
    let half = n / 2;
    let mut data = vec![0.0; n * dim];
    let mut levels: Vec<usize> = (0..half).collect();
    let centre = |k: usize| (k as f64 + 0.5) / n as f64;
    for j in 0..dim {
        levels.shuffle(rng);
        for (i, &k) in levels.iter().enumerate() {
            let k = if rng.random::<bool>() { n - 1 - k } else { k };
            data[i * dim + j] = centre(k);
            data[(n - 1 - i) * dim + j] = centre(n - 1 - k);
        }
        if n % 2 == 1 {
            data[half * dim + j] = 0.5;
        }
    }
    Ok(Mat::from_fn(n, dim, |i, j| data[i * dim + j]))
}
