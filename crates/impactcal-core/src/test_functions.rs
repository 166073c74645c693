//! Standard test functions with their published constants: the Dixon-Szego set of global
//! optimisation, Dixon-Price, and the Ishigami and G-functions of sensitivity analysis with
//! their exact Sobol' indices.
//!
//! One definition serves every crate's tests, benchmarks and accuracy records. The
//! constants are those of the literature:
//!
//! - Branin (Branin & Hoo 1972; Dixon & Szego 1978), on `[-5, 10] x [0, 15]`:
//!   `(x2 - 5.1 x1^2 / (4 pi^2) + 5 x1 / pi - 6)^2 + 10 (1 - 1 / (8 pi)) cos x1 + 10`,
//!   minimum `0.397887` at `(pi, 2.275)` and two other points.
//! - Goldstein-Price (Goldstein & Price 1971), on `[-2, 2]^2`, minimum 3 at `(0, -1)`.
//! - Hartmann-3 and Hartmann-6 (Hartman 1973, the coefficients of Dixon & Szego 1978), on
//!   the unit cube: `-sum_i alpha_i exp(-sum_j A_ij (x_j - P_ij)^2)`, `alpha = (1, 1.2, 3,
//!   3.2)`; the matrices `A` and `P` below (`P_41 = 0.0381` in three dimensions). Minima
//!   `-3.86278` at `(0.114614, 0.555649, 0.852547)` and `-3.32237` at `(0.20169, 0.150011,
//!   0.476874, 0.275332, 0.311652, 0.6573)`.
//! - Shekel-5, -7 and -10 (Shekel 1971; Dixon & Szego 1978), on `[0, 10]^4`:
//!   `-sum_{i<=m} 1 / (|x - a_i|^2 + c_i)`, minima `-10.1532`, `-10.4029`, `-10.5364` near
//!   `(4, 4, 4, 4)`.
//! - Dixon-Price (Dixon & Price 1989), on `[-10, 10]^d`:
//!   `(x1 - 1)^2 + sum_{i>=2} i (2 x_i^2 - x_{i-1})^2`, minimum 0 at
//!   `x_i = 2^(-(2^i - 2) / 2^i)`.
//! - Ishigami (Ishigami & Homma 1990) and the G-function (Saltelli & Sobol' 1995), with the
//!   analytic variance decompositions of [`ishigami_indices`] and [`g_function_indices`].
//!
//! The constants and minima agree with the Virtual Library of Simulation Experiments of
//! Surjanovic & Bingham (Simon Fraser University); the minima to more digits are the
//! function values at the best known minimisers.
//!
//! ```
//! use impactcal_core::test_functions::{BRANIN, HARTMANN3};
//!
//! let f = BRANIN.eval(&[std::f64::consts::PI, 2.275]);
//! assert!((f - BRANIN.minimum).abs() < 1e-6);
//! // The same point through the unit cube of the function's box.
//! let u = [(std::f64::consts::PI + 5.0) / 15.0, 2.275 / 15.0];
//! assert_eq!(BRANIN.eval_unit(&u), BRANIN.eval(&[-5.0 + u[0] * 15.0, u[1] * 15.0]));
//! assert!((HARTMANN3.eval(&[0.114614, 0.555649, 0.852547]) + 3.86278).abs() < 1e-5);
//! ```

use std::f64::consts::PI;

use crate::error::Result;
use crate::space::{Parameter, ParameterSpace};

/// A test function on its standard box, with its global minimum.
#[derive(Debug, Clone, Copy)]
pub struct TestFunction {
    /// Short machine name: `branin`, `goldstein-price`, `hartmann3`, `hartmann6`, `shekel5`,
    /// `shekel7`, `shekel10`, `dixon-price10`.
    pub name: &'static str,
    /// Name for reports: `Branin`, `Goldstein-Price`, `Hartmann-3`, ...
    pub title: &'static str,
    /// Number of inputs.
    pub dim: usize,
    /// Lower bound of each coordinate.
    pub lower: &'static [f64],
    /// Upper bound of each coordinate.
    pub upper: &'static [f64],
    /// The global minimum value `f*`.
    pub minimum: f64,
    f: fn(&[f64]) -> f64,
}

impl TestFunction {
    /// `f(x)` for `x` of length [`dim`](Self::dim) (in the function's box). Panics when `x`
    /// is shorter.
    pub fn eval(&self, x: &[f64]) -> f64 {
        (self.f)(x)
    }

    /// `f(lower + u (upper - lower))` for `u` in the unit cube (length `dim`): the function
    /// on its box seen from the unit cube, as accuracy studies sample it.
    pub fn eval_unit(&self, u: &[f64]) -> f64 {
        let x: Vec<f64> = u
            .iter()
            .zip(self.lower.iter().zip(self.upper))
            .map(|(v, (lo, hi))| lo + v * (hi - lo))
            .collect();
        self.eval(&x)
    }

    /// The relative error `(f - f*) / |f*|` of a value `f` (the absolute error when
    /// `f* = 0`).
    pub fn relative_error(&self, f: f64) -> f64 {
        if self.minimum == 0.0 {
            f
        } else {
            (f - self.minimum) / self.minimum.abs()
        }
    }

    /// The box as a parameter space: parameters `x1 .. xd`, nominal at the centre.
    ///
    /// # Errors
    /// None for the functions of this module (their boxes are valid).
    pub fn space(&self) -> Result<ParameterSpace> {
        let params = (0..self.dim)
            .map(|j| {
                let (l, u) = (self.lower[j], self.upper[j]);
                Parameter::new(format!("x{}", j + 1), l, u, 0.5 * (l + u))
            })
            .collect::<Result<Vec<_>>>()?;
        ParameterSpace::new(params)
    }
}

fn branin(x: &[f64]) -> f64 {
    let (x1, x2) = (x[0], x[1]);
    let b = 5.1 / (4.0 * PI * PI);
    let c = 5.0 / PI;
    let t = 1.0 / (8.0 * PI);
    (x2 - b * x1 * x1 + c * x1 - 6.0).powi(2) + 10.0 * (1.0 - t) * x1.cos() + 10.0
}

fn goldstein_price(x: &[f64]) -> f64 {
    let (x1, x2) = (x[0], x[1]);
    let a = 1.0
        + (x1 + x2 + 1.0).powi(2)
            * (19.0 - 14.0 * x1 + 3.0 * x1 * x1 - 14.0 * x2 + 6.0 * x1 * x2 + 3.0 * x2 * x2);
    let b = 30.0
        + (2.0 * x1 - 3.0 * x2).powi(2)
            * (18.0 - 32.0 * x1 + 12.0 * x1 * x1 + 48.0 * x2 - 36.0 * x1 * x2 + 27.0 * x2 * x2);
    a * b
}

/// `alpha` of the Hartmann functions.
const HARTMANN_ALPHA: [f64; 4] = [1.0, 1.2, 3.0, 3.2];

/// `A` of Hartmann-3.
const HARTMANN3_A: [[f64; 3]; 4] = [
    [3.0, 10.0, 30.0],
    [0.1, 10.0, 35.0],
    [3.0, 10.0, 30.0],
    [0.1, 10.0, 35.0],
];

/// `P` of Hartmann-3 (`10^-4` times 3689, 1170, 2673 / 4699, 4387, 7470 / 1091, 8732,
/// 5547 / 381, 5743, 8828).
const HARTMANN3_P: [[f64; 3]; 4] = [
    [0.3689, 0.1170, 0.2673],
    [0.4699, 0.4387, 0.7470],
    [0.1091, 0.8732, 0.5547],
    [0.0381, 0.5743, 0.8828],
];

/// `A` of Hartmann-6.
const HARTMANN6_A: [[f64; 6]; 4] = [
    [10.0, 3.0, 17.0, 3.5, 1.7, 8.0],
    [0.05, 10.0, 17.0, 0.1, 8.0, 14.0],
    [3.0, 3.5, 1.7, 10.0, 17.0, 8.0],
    [17.0, 8.0, 0.05, 10.0, 0.1, 14.0],
];

/// `P` of Hartmann-6 (`10^-4` times the integers of Dixon & Szego).
const HARTMANN6_P: [[f64; 6]; 4] = [
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
            HARTMANN_ALPHA[i] * (-s).exp()
        })
        .sum::<f64>()
}

fn hartmann3(x: &[f64]) -> f64 {
    hartmann(x, &HARTMANN3_A, &HARTMANN3_P)
}

fn hartmann6(x: &[f64]) -> f64 {
    hartmann(x, &HARTMANN6_A, &HARTMANN6_P)
}

/// The centres `a_i` of the Shekel functions.
const SHEKEL_A: [[f64; 4]; 10] = [
    [4.0, 4.0, 4.0, 4.0],
    [1.0, 1.0, 1.0, 1.0],
    [8.0, 8.0, 8.0, 8.0],
    [6.0, 6.0, 6.0, 6.0],
    [3.0, 7.0, 3.0, 7.0],
    [2.0, 9.0, 2.0, 9.0],
    [5.0, 5.0, 3.0, 3.0],
    [8.0, 1.0, 8.0, 1.0],
    [6.0, 2.0, 6.0, 2.0],
    [7.0, 3.6, 7.0, 3.6],
];

/// The widths `c_i` of the Shekel functions.
const SHEKEL_C: [f64; 10] = [0.1, 0.2, 0.2, 0.4, 0.4, 0.6, 0.3, 0.7, 0.5, 0.5];

fn shekel(x: &[f64], m: usize) -> f64 {
    -(0..m)
        .map(|i| {
            let s: f64 = (0..4).map(|j| (x[j] - SHEKEL_A[i][j]).powi(2)).sum();
            1.0 / (s + SHEKEL_C[i])
        })
        .sum::<f64>()
}

fn dixon_price(x: &[f64]) -> f64 {
    let mut f = (x[0] - 1.0).powi(2);
    for i in 1..x.len() {
        f += (i + 1) as f64 * (2.0 * x[i] * x[i] - x[i - 1]).powi(2);
    }
    f
}

/// Branin on `[-5, 10] x [0, 15]`.
pub const BRANIN: TestFunction = TestFunction {
    name: "branin",
    title: "Branin",
    dim: 2,
    lower: &[-5.0, 0.0],
    upper: &[10.0, 15.0],
    minimum: 0.397_887_357_729_738,
    f: branin,
};

/// Goldstein-Price on `[-2, 2]^2`.
pub const GOLDSTEIN_PRICE: TestFunction = TestFunction {
    name: "goldstein-price",
    title: "Goldstein-Price",
    dim: 2,
    lower: &[-2.0, -2.0],
    upper: &[2.0, 2.0],
    minimum: 3.0,
    f: goldstein_price,
};

/// Hartmann-3 on `[0, 1]^3`.
pub const HARTMANN3: TestFunction = TestFunction {
    name: "hartmann3",
    title: "Hartmann-3",
    dim: 3,
    lower: &[0.0; 3],
    upper: &[1.0; 3],
    minimum: -3.862_782_147_820_756,
    f: hartmann3,
};

/// Hartmann-6 on `[0, 1]^6`.
pub const HARTMANN6: TestFunction = TestFunction {
    name: "hartmann6",
    title: "Hartmann-6",
    dim: 6,
    lower: &[0.0; 6],
    upper: &[1.0; 6],
    minimum: -3.322_368_011_415_511,
    f: hartmann6,
};

/// Shekel with 5 terms on `[0, 10]^4`.
pub const SHEKEL5: TestFunction = TestFunction {
    name: "shekel5",
    title: "Shekel-5",
    dim: 4,
    lower: &[0.0; 4],
    upper: &[10.0; 4],
    minimum: -10.153_199_679_058_23,
    f: |x| shekel(x, 5),
};

/// Shekel with 7 terms on `[0, 10]^4`.
pub const SHEKEL7: TestFunction = TestFunction {
    name: "shekel7",
    title: "Shekel-7",
    dim: 4,
    lower: &[0.0; 4],
    upper: &[10.0; 4],
    minimum: -10.402_940_566_818_664,
    f: |x| shekel(x, 7),
};

/// Shekel with 10 terms on `[0, 10]^4`.
pub const SHEKEL10: TestFunction = TestFunction {
    name: "shekel10",
    title: "Shekel-10",
    dim: 4,
    lower: &[0.0; 4],
    upper: &[10.0; 4],
    minimum: -10.536_409_816_692_046,
    f: |x| shekel(x, 10),
};

/// Dixon-Price in 10 dimensions on `[-10, 10]^10`.
pub const DIXON_PRICE10: TestFunction = TestFunction {
    name: "dixon-price10",
    title: "Dixon-Price-10",
    dim: 10,
    lower: &[-10.0; 10],
    upper: &[10.0; 10],
    minimum: 0.0,
    f: dixon_price,
};

/// The seven Dixon-Szego functions, in the order Branin, Goldstein-Price, Hartmann-3,
/// Hartmann-6, Shekel-5, Shekel-7, Shekel-10.
pub fn dixon_szego() -> [TestFunction; 7] {
    [
        BRANIN,
        GOLDSTEIN_PRICE,
        HARTMANN3,
        HARTMANN6,
        SHEKEL5,
        SHEKEL7,
        SHEKEL10,
    ]
}

/// The functions of the surrogate accuracy record (docs/validation.md), in its order:
/// Branin, Goldstein-Price, Hartmann-3, Hartmann-6, Dixon-Price-10.
pub fn surrogate_accuracy_set() -> [TestFunction; 5] {
    [BRANIN, GOLDSTEIN_PRICE, HARTMANN3, HARTMANN6, DIXON_PRICE10]
}

/// The function of this module called `name` ([`TestFunction::name`]), if any.
pub fn by_name(name: &str) -> Option<TestFunction> {
    dixon_szego()
        .into_iter()
        .chain([DIXON_PRICE10])
        .find(|f| f.name == name)
}

/// Exact Sobol' indices of a test function of sensitivity analysis.
#[derive(Debug, Clone, PartialEq)]
pub struct ExactIndices {
    /// Output variance `V`.
    pub variance: f64,
    /// First-order indices `S_i`.
    pub first_order: Vec<f64>,
    /// Total indices `ST_i`.
    pub total: Vec<f64>,
    /// Closed second-order indices `S_ik` (symmetric, zero diagonal).
    pub second_order: Vec<Vec<f64>>,
}

/// Ishigami & Homma (1990): `y = sin x1 + a sin^2 x2 + b x3^4 sin x1`, `x_i ~ U(-pi, pi)`.
/// Panics when `x` has fewer than 3 entries.
pub fn ishigami(x: &[f64], a: f64, b: f64) -> f64 {
    x[0].sin() * (1.0 + b * x[2].powi(4)) + a * x[1].sin().powi(2)
}

/// Exact indices of [`ishigami`]: `V1 = (1 + b pi^4 / 5)^2 / 2`, `V2 = a^2 / 8`,
/// `V13 = b^2 pi^8 (1/18 - 1/50)`, `V = V1 + V2 + V13`; with `a = 7, b = 0.1`,
/// `S = (0.3139, 0.4424, 0)`, `ST = (0.5576, 0.4424, 0.2437)`.
pub fn ishigami_indices(a: f64, b: f64) -> ExactIndices {
    let v1 = 0.5 * (1.0 + b * PI.powi(4) / 5.0).powi(2);
    let v2 = a * a / 8.0;
    let v13 = b * b * PI.powi(8) * (1.0 / 18.0 - 1.0 / 50.0);
    let v = v1 + v2 + v13;
    let mut second = vec![vec![0.0; 3]; 3];
    second[0][2] = v13 / v;
    second[2][0] = v13 / v;
    ExactIndices {
        variance: v,
        first_order: vec![v1 / v, v2 / v, 0.0],
        total: vec![(v1 + v13) / v, v2 / v, v13 / v],
        second_order: second,
    }
}

/// Sobol' G-function: `y = prod_i (|4 x_i - 2| + a_i) / (1 + a_i)`, `x_i ~ U(0, 1)`.
pub fn g_function(x: &[f64], a: &[f64]) -> f64 {
    x.iter()
        .zip(a)
        .map(|(&xi, &ai)| ((4.0 * xi - 2.0).abs() + ai) / (1.0 + ai))
        .product()
}

/// Exact indices of [`g_function`]: `V_i = 1 / (3 (1 + a_i)^2)`, `V = prod (1 + V_i) - 1`,
/// `S_i = V_i / V`, `ST_i = V_i prod_(k != i) (1 + V_k) / V`, `S_ik = V_i V_k / V`.
pub fn g_function_indices(a: &[f64]) -> ExactIndices {
    let vi: Vec<f64> = a
        .iter()
        .map(|ai| 1.0 / (3.0 * (1.0 + ai).powi(2)))
        .collect();
    let prod: f64 = vi.iter().map(|v| 1.0 + v).product();
    let v = prod - 1.0;
    let d = a.len();
    let mut second = vec![vec![0.0; d]; d];
    for i in 0..d {
        for k in 0..d {
            if i != k {
                second[i][k] = vi[i] * vi[k] / v;
            }
        }
    }
    ExactIndices {
        variance: v,
        first_order: vi.iter().map(|x| x / v).collect(),
        total: vi.iter().map(|x| x * prod / (1.0 + x) / v).collect(),
        second_order: second,
    }
}

/// Exact indices of the linear model `y = sum_i c_i x_i` with `x_i ~ U(l_i, u_i)`:
/// `S_i = ST_i = c_i^2 w_i^2 / sum_k c_k^2 w_k^2`, `w_i = u_i - l_i`.
pub fn linear_indices(c: &[f64], widths: &[f64]) -> ExactIndices {
    let parts: Vec<f64> = c
        .iter()
        .zip(widths)
        .map(|(c, w)| c * c * w * w / 12.0)
        .collect();
    let v: f64 = parts.iter().sum();
    let s: Vec<f64> = parts.iter().map(|p| p / v).collect();
    ExactIndices {
        variance: v,
        first_order: s.clone(),
        total: s,
        second_order: vec![vec![0.0; c.len()]; c.len()],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The published minima, evaluated at the published minimisers.
    #[test]
    fn published_minima() {
        // Branin: 0.397887 at (pi, 2.275); Goldstein-Price: 3 at (0, -1);
        // Hartmann-3: -3.86278 at (0.114614, 0.555649, 0.852547);
        // Hartmann-6: -3.32237 at (0.20169, 0.150011, 0.476874, 0.275332, 0.311652, 0.6573);
        // Dixon-Price: 0 at x_i = 2^(-(2^i - 2) / 2^i).
        let branin = BRANIN.eval_unit(&[(PI + 5.0) / 15.0, 2.275 / 15.0]);
        assert_relative_eq!(branin, 0.397887, epsilon = 1e-6);
        let gp = GOLDSTEIN_PRICE.eval_unit(&[0.5, 0.25]);
        assert_relative_eq!(gp, 3.0, epsilon = 1e-12);
        let h3 = HARTMANN3.eval_unit(&[0.114614, 0.555649, 0.852547]);
        assert_relative_eq!(h3, -3.86278, epsilon = 1e-5);
        let h6 = HARTMANN6.eval_unit(&[0.20169, 0.150011, 0.476874, 0.275332, 0.311652, 0.6573]);
        assert_relative_eq!(h6, -3.32237, epsilon = 1e-5);
        let u: Vec<f64> = (1..=10)
            .map(|i| {
                let x = 2f64.powf(-(2f64.powi(i) - 2.0) / 2f64.powi(i));
                (x + 10.0) / 20.0
            })
            .collect();
        assert!(DIXON_PRICE10.eval_unit(&u).abs() < 1e-10);
        for (f, m) in [
            (SHEKEL5, -10.1532),
            (SHEKEL7, -10.4029),
            (SHEKEL10, -10.5364),
        ] {
            // The minimisers lie within 0.01 of (4, 4, 4, 4).
            assert_relative_eq!(f.eval(&[4.0; 4]), m, epsilon = 2e-3);
            assert_relative_eq!(f.minimum, m, epsilon = 1e-4);
        }
    }

    /// Every recorded minimum is no larger than the function at its known minimiser and
    /// no smaller than the best of a fine random search (it is a true lower value).
    #[test]
    fn minima_are_attained_and_not_beaten() {
        use rand::Rng;
        let mut rng = crate::sampling::seeded_rng(11);
        for f in dixon_szego() {
            let best = (0..20_000)
                .map(|_| {
                    let u: Vec<f64> = (0..f.dim).map(|_| rng.random::<f64>()).collect();
                    f.eval_unit(&u)
                })
                .fold(f64::INFINITY, f64::min);
            assert!(
                best >= f.minimum - 1e-9,
                "{}: {best} < {}",
                f.name,
                f.minimum
            );
            assert!(f.relative_error(best) >= -1e-12);
        }
    }

    #[test]
    fn names_and_spaces() {
        assert_eq!(by_name("hartmann3").map(|f| f.dim), Some(3));
        assert_eq!(by_name("dixon-price10").map(|f| f.dim), Some(10));
        assert!(by_name("rosenbrock").is_none());
        let s = BRANIN.space().unwrap();
        assert_eq!(s.upper(), vec![10.0, 15.0]);
        assert_eq!(s.names(), vec!["x1", "x2"]);
        let ish = ishigami_indices(7.0, 0.1);
        assert_relative_eq!(ish.first_order[0], 0.3139, epsilon = 1e-4);
        assert_relative_eq!(ish.total[2], 0.2437, epsilon = 1e-4);
    }
}
