//! The Dixon-Szego test set of global optimisation (Branin, Goldstein-Price, Hartmann 3 and
//! 6, Shekel 5, 7 and 10), with their standard boxes and known minima.
//!
//! The usual measure of a surrogate optimiser on them is the number of evaluations until
//! the relative error `(f_best - f*) / |f*|` falls below 1%.

use std::f64::consts::PI;

use impactcal_core::{Parameter, ParameterSpace};

use crate::error::Result;

/// A test function with its box and global minimum.
#[derive(Debug, Clone, Copy)]
pub struct TestFunction {
    /// Name (`branin`, `goldstein-price`, `hartmann3`, `hartmann6`, `shekel5`, `shekel7`,
    /// `shekel10`).
    pub name: &'static str,
    /// Dimension.
    pub dim: usize,
    /// Lower bound of every coordinate (per coordinate).
    pub lower: &'static [f64],
    /// Upper bound of every coordinate.
    pub upper: &'static [f64],
    /// The global minimum value `f*`.
    pub minimum: f64,
    f: fn(&[f64]) -> f64,
}

impl TestFunction {
    /// `f(x)` for `x` of length `dim`.
    pub fn eval(&self, x: &[f64]) -> f64 {
        (self.f)(x)
    }

    /// The relative error `(f - f*) / |f*|`.
    pub fn relative_error(&self, f: f64) -> f64 {
        (f - self.minimum) / self.minimum.abs()
    }

    /// The box as a parameter space (parameters `x1 .. xd`, nominal at the centre).
    ///
    /// # Errors
    /// None for the built-in functions (their boxes are valid).
    pub fn space(&self) -> Result<ParameterSpace> {
        let params = (0..self.dim)
            .map(|j| {
                let (l, u) = (self.lower[j], self.upper[j]);
                Parameter::new(format!("x{}", j + 1), l, u, 0.5 * (l + u))
            })
            .collect::<impactcal_core::Result<Vec<_>>>()?;
        Ok(ParameterSpace::new(params)?)
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

const H_ALPHA: [f64; 4] = [1.0, 1.2, 3.0, 3.2];

fn hartmann<const D: usize>(x: &[f64], a: &[[f64; D]; 4], p: &[[f64; D]; 4]) -> f64 {
    -(0..4)
        .map(|i| {
            let s: f64 = (0..D).map(|j| a[i][j] * (x[j] - p[i][j]).powi(2)).sum();
            H_ALPHA[i] * (-s).exp()
        })
        .sum::<f64>()
}

fn hartmann3(x: &[f64]) -> f64 {
    const A: [[f64; 3]; 4] = [
        [3.0, 10.0, 30.0],
        [0.1, 10.0, 35.0],
        [3.0, 10.0, 30.0],
        [0.1, 10.0, 35.0],
    ];
    const P: [[f64; 3]; 4] = [
        [0.3689, 0.1170, 0.2673],
        [0.4699, 0.4387, 0.7470],
        [0.1091, 0.8732, 0.5547],
        [0.03815, 0.5743, 0.8828],
    ];
    hartmann(x, &A, &P)
}

fn hartmann6(x: &[f64]) -> f64 {
    const A: [[f64; 6]; 4] = [
        [10.0, 3.0, 17.0, 3.5, 1.7, 8.0],
        [0.05, 10.0, 17.0, 0.1, 8.0, 14.0],
        [3.0, 3.5, 1.7, 10.0, 17.0, 8.0],
        [17.0, 8.0, 0.05, 10.0, 0.1, 14.0],
    ];
    const P: [[f64; 6]; 4] = [
        [0.1312, 0.1696, 0.5569, 0.0124, 0.8283, 0.5886],
        [0.2329, 0.4135, 0.8307, 0.3736, 0.1004, 0.9991],
        [0.2348, 0.1451, 0.3522, 0.2883, 0.3047, 0.6650],
        [0.4047, 0.8828, 0.8732, 0.5743, 0.1091, 0.0381],
    ];
    hartmann(x, &A, &P)
}

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
const SHEKEL_C: [f64; 10] = [0.1, 0.2, 0.2, 0.4, 0.4, 0.6, 0.3, 0.7, 0.5, 0.5];

fn shekel(x: &[f64], m: usize) -> f64 {
    -(0..m)
        .map(|i| {
            let s: f64 = (0..4).map(|j| (x[j] - SHEKEL_A[i][j]).powi(2)).sum();
            1.0 / (s + SHEKEL_C[i])
        })
        .sum::<f64>()
}

/// The seven Dixon-Szego functions, in the order Branin, Goldstein-Price, Hartmann3,
/// Hartmann6, Shekel5, Shekel7, Shekel10.
pub fn dixon_szego() -> [TestFunction; 7] {
    [
        TestFunction {
            name: "branin",
            dim: 2,
            lower: &[-5.0, 0.0],
            upper: &[10.0, 15.0],
            minimum: 0.397_887_357_729_738,
            f: branin,
        },
        TestFunction {
            name: "goldstein-price",
            dim: 2,
            lower: &[-2.0, -2.0],
            upper: &[2.0, 2.0],
            minimum: 3.0,
            f: goldstein_price,
        },
        TestFunction {
            name: "hartmann3",
            dim: 3,
            lower: &[0.0; 3],
            upper: &[1.0; 3],
            minimum: -3.862_782_147_820_756,
            f: hartmann3,
        },
        TestFunction {
            name: "hartmann6",
            dim: 6,
            lower: &[0.0; 6],
            upper: &[1.0; 6],
            minimum: -3.322_368_011_415_511,
            f: hartmann6,
        },
        TestFunction {
            name: "shekel5",
            dim: 4,
            lower: &[0.0; 4],
            upper: &[10.0; 4],
            minimum: -10.153_199_679_058_23,
            f: |x| shekel(x, 5),
        },
        TestFunction {
            name: "shekel7",
            dim: 4,
            lower: &[0.0; 4],
            upper: &[10.0; 4],
            minimum: -10.402_940_566_818_664,
            f: |x| shekel(x, 7),
        },
        TestFunction {
            name: "shekel10",
            dim: 4,
            lower: &[0.0; 4],
            upper: &[10.0; 4],
            minimum: -10.536_409_816_692_046,
            f: |x| shekel(x, 10),
        },
    ]
}

/// The Dixon-Szego function called `name`, if any.
pub fn by_name(name: &str) -> Option<TestFunction> {
    dixon_szego().into_iter().find(|f| f.name == name)
}
