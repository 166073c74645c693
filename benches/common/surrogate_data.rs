//! The surrogate benchmark data shared by `benches/erbf.rs` and `benches/harness/erbf_peer.rs`, so
//! that the criterion figures and the scipy comparison use the same input.

use faer::Mat;
use impactcal::core::sampling::latin_hypercube;
use impactcal::core::{Parameter, ParameterSpace};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Training samples.
pub const N: usize = 150;
/// Parameters.
pub const M: usize = 10;
/// Output columns (a long time history).
pub const T: usize = 10_000;
/// Query points.
pub const Q: usize = 1000;

/// `(space, x N x M, f N x T, queries Q x M)`: a Latin hypercube (seed 42) on the unit cube,
/// damped sums of sines as outputs, uniform queries.
pub fn surrogate_data() -> (ParameterSpace, Mat<f64>, Mat<f64>, Mat<f64>) {
    let space = ParameterSpace::new(
        (0..M)
            .map(|j| Parameter::new(format!("p{j}"), 0.0, 1.0, 0.5).unwrap())
            .collect(),
    )
    .unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let x = latin_hypercube(N, M, &mut rng).unwrap();
    let f = family(&x);
    let q = Mat::from_fn(Q, M, |_, _| rng.random::<f64>());
    (space, x, f, q)
}

/// The history family at the rows of `x` (`n x M`): `n x T`, row `i` the damped sum
/// `sum_j sin(3 x_ij + 1e-3 (j + 1) t) exp(-2e-4 t)` (rank `2 M` around its mean).
#[allow(dead_code)]
pub fn family(x: &Mat<f64>) -> Mat<f64> {
    Mat::from_fn(x.nrows(), T, |i, t| {
        let s: f64 = (0..M)
            .map(|j| (3.0 * x[(i, j)] + 1e-3 * (t * (j + 1)) as f64).sin())
            .sum();
        s * (-2e-4 * t as f64).exp()
    })
}
