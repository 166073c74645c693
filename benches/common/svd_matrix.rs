//! The benchmark matrix shared by `benches/svd.rs` and `benches/harness/svd_timing.rs`, so that the
//! criterion figures and the numpy comparison use the same data.

use faer::Mat;
use rand::{Rng, SeedableRng};

/// `m x n` matrix with a decaying spectrum: 60 rank-one terms of weight 0.85^j plus uniform
/// noise of amplitude 1e-4.
pub fn benchmark_matrix(m: usize, n: usize, seed: u64) -> Mat<f64> {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let a = Mat::from_fn(m, 60, |_, j| {
        0.85f64.powi(j as i32) * rng.random_range(-1.0..1.0)
    });
    let b = Mat::from_fn(60, n, |_, _| rng.random_range(-1.0..1.0));
    let mut y = &a * &b;
    y.col_iter_mut().for_each(|c| {
        c.iter_mut()
            .for_each(|x| *x += 1e-4 * rng.random_range(-1.0..1.0))
    });
    y
}
