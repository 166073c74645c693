//! Analytic test functions with exact Sobol' indices, for validation and benchmarks.

use std::f64::consts::PI;

/// Exact indices of a test function.
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
