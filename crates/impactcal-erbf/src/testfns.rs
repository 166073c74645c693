//! Standard test functions for surrogate accuracy studies, and a Latin hypercube design.
//!
//! Each function is defined on its usual box; [`TestFunction::eval_unit`] evaluates it at
//! a point of the unit cube mapped affinely onto that box, which is how the accuracy
//! record in `docs/validation.md` samples them.

use std::f64::consts::PI;

use faer::Mat;
use rand::Rng;

/// The test functions of the accuracy record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TestFunction {
    /// Branin, 2-D on `[-5, 10] x [0, 15]`.
    Branin,
    /// Goldstein-Price, 2-D on `[-2, 2]^2`.
    GoldsteinPrice,
    /// Hartmann-3 on `[0, 1]^3`.
    Hartmann3,
    /// Hartmann-6 on `[0, 1]^6`.
    Hartmann6,
    /// Dixon-Price, 10-D on `[-10, 10]^10`.
    DixonPrice10,
}

impl TestFunction {
    /// All functions, in the order of the record.
    pub const ALL: [TestFunction; 5] = [
        TestFunction::Branin,
        TestFunction::GoldsteinPrice,
        TestFunction::Hartmann3,
        TestFunction::Hartmann6,
        TestFunction::DixonPrice10,
    ];

    /// Number of inputs.
    pub fn dim(self) -> usize {
        match self {
            TestFunction::Branin | TestFunction::GoldsteinPrice => 2,
            TestFunction::Hartmann3 => 3,
            TestFunction::Hartmann6 => 6,
            TestFunction::DixonPrice10 => 10,
        }
    }

    /// A short name.
    pub fn name(self) -> &'static str {
        match self {
            TestFunction::Branin => "Branin",
            TestFunction::GoldsteinPrice => "Goldstein-Price",
            TestFunction::Hartmann3 => "Hartmann-3",
            TestFunction::Hartmann6 => "Hartmann-6",
            TestFunction::DixonPrice10 => "Dixon-Price-10",
        }
    }

    /// The function at `u` in the unit cube (length [`dim`](Self::dim)), mapped onto the
    /// function's box.
    pub fn eval_unit(self, u: &[f64]) -> f64 {
        let map = |lo: f64, hi: f64| -> Vec<f64> { u.iter().map(|v| lo + v * (hi - lo)).collect() };
        match self {
            TestFunction::Branin => {
                let (x1, x2) = (-5.0 + 15.0 * u[0], 15.0 * u[1]);
                let b = 5.1 / (4.0 * PI * PI);
                let c = 5.0 / PI;
                (x2 - b * x1 * x1 + c * x1 - 6.0).powi(2)
                    + 10.0 * (1.0 - 1.0 / (8.0 * PI)) * x1.cos()
                    + 10.0
            }
            TestFunction::GoldsteinPrice => {
                let x = map(-2.0, 2.0);
                let (a, b) = (x[0], x[1]);
                let p = 1.0
                    + (a + b + 1.0).powi(2)
                        * (19.0 - 14.0 * a + 3.0 * a * a - 14.0 * b + 6.0 * a * b + 3.0 * b * b);
                let q = 30.0
                    + (2.0 * a - 3.0 * b).powi(2)
                        * (18.0 - 32.0 * a + 12.0 * a * a + 48.0 * b - 36.0 * a * b + 27.0 * b * b);
                p * q
            }
            TestFunction::Hartmann3 => hartmann(u, &H3_A, &H3_P),
            TestFunction::Hartmann6 => hartmann(u, &H6_A, &H6_P),
            TestFunction::DixonPrice10 => {
                let x = map(-10.0, 10.0);
                let mut f = (x[0] - 1.0).powi(2);
                for i in 1..x.len() {
                    f += (i + 1) as f64 * (2.0 * x[i] * x[i] - x[i - 1]).powi(2);
                }
                f
            }
        }
    }
}

const ALPHA: [f64; 4] = [1.0, 1.2, 3.0, 3.2];
const H3_A: [[f64; 3]; 4] = [
    [3.0, 10.0, 30.0],
    [0.1, 10.0, 35.0],
    [3.0, 10.0, 30.0],
    [0.1, 10.0, 35.0],
];
const H3_P: [[f64; 3]; 4] = [
    [0.3689, 0.1170, 0.2673],
    [0.4699, 0.4387, 0.7470],
    [0.1091, 0.8732, 0.5547],
    [0.0381, 0.5743, 0.8828],
];
const H6_A: [[f64; 6]; 4] = [
    [10.0, 3.0, 17.0, 3.5, 1.7, 8.0],
    [0.05, 10.0, 17.0, 0.1, 8.0, 14.0],
    [3.0, 3.5, 1.7, 10.0, 17.0, 8.0],
    [17.0, 8.0, 0.05, 10.0, 0.1, 14.0],
];
const H6_P: [[f64; 6]; 4] = [
    [0.1312, 0.1696, 0.5569, 0.0124, 0.8283, 0.5886],
    [0.2329, 0.4135, 0.8307, 0.3736, 0.1004, 0.9991],
    [0.2348, 0.1451, 0.3522, 0.2883, 0.3047, 0.6650],
    [0.4047, 0.8828, 0.8732, 0.5743, 0.1091, 0.0381],
];

/// `-sum_i alpha_i exp(-sum_j A_ij (x_j - P_ij)^2)`.
fn hartmann<const D: usize>(x: &[f64], a: &[[f64; D]; 4], p: &[[f64; D]; 4]) -> f64 {
    -(0..4)
        .map(|i| {
            let s: f64 = (0..D).map(|j| a[i][j] * (x[j] - p[i][j]).powi(2)).sum();
            ALPHA[i] * (-s).exp()
        })
        .sum::<f64>()
}

/// A Latin hypercube design of `n` points in `[0, 1]^m`: in every input, each of the `n`
/// strata `[k/n, (k+1)/n)` holds exactly one point, placed uniformly inside it; the strata
/// are matched across inputs by independent random permutations.
pub fn latin_hypercube(n: usize, m: usize, rng: &mut impl Rng) -> Mat<f64> {
    let mut out = Mat::<f64>::zeros(n, m);
    for j in 0..m {
        let mut perm: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            perm.swap(i, rng.random_range(0..=i));
        }
        for (i, &s) in perm.iter().enumerate() {
            out[(i, j)] = (s as f64 + rng.random::<f64>()) / n as f64;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn published_minima() {
        // Branin: 0.397887 at (pi, 2.275); Goldstein-Price: 3 at (0, -1);
        // Hartmann-3: -3.86278 at (0.114614, 0.555649, 0.852547);
        // Hartmann-6: -3.32237 at (0.20169, 0.150011, 0.476874, 0.275332, 0.311652, 0.6573);
        // Dixon-Price: 0 at x_i = 2^(-(2^i - 2) / 2^i).
        let branin = TestFunction::Branin.eval_unit(&[(PI + 5.0) / 15.0, 2.275 / 15.0]);
        assert_relative_eq!(branin, 0.397887, epsilon = 1e-6);
        let gp = TestFunction::GoldsteinPrice.eval_unit(&[0.5, 0.25]);
        assert_relative_eq!(gp, 3.0, epsilon = 1e-12);
        let h3 = TestFunction::Hartmann3.eval_unit(&[0.114614, 0.555649, 0.852547]);
        assert_relative_eq!(h3, -3.86278, epsilon = 1e-5);
        let h6 = TestFunction::Hartmann6
            .eval_unit(&[0.20169, 0.150011, 0.476874, 0.275332, 0.311652, 0.6573]);
        assert_relative_eq!(h6, -3.32237, epsilon = 1e-5);
        let u: Vec<f64> = (1..=10)
            .map(|i| {
                let x = 2f64.powf(-(2f64.powi(i) - 2.0) / 2f64.powi(i));
                (x + 10.0) / 20.0
            })
            .collect();
        assert!(TestFunction::DixonPrice10.eval_unit(&u).abs() < 1e-10);
    }

    #[test]
    fn latin_hypercube_fills_every_stratum_once() {
        use rand::SeedableRng;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let d = latin_hypercube(17, 3, &mut rng);
        for j in 0..3 {
            let mut seen = [false; 17];
            for i in 0..17 {
                let s = (d[(i, j)] * 17.0).floor() as usize;
                assert!(!seen[s]);
                seen[s] = true;
            }
        }
    }
}
