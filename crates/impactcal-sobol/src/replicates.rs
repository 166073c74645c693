//! Intervals from independent scramblings of the design (randomised quasi-Monte Carlo).

use serde::Serialize;

use crate::analysis::SobolIndices;
use crate::error::Result;
use crate::stats::{sample_sd, student_t_quantile};
use impactcal_core::error::{dimension_mismatch, invalid_option};

/// The spread of first-order and total indices over `R` analyses of independently
/// scrambled designs (same `N`, different seeds).
///
/// Each replicate is an unbiased estimate for scrambled Sobol' or Halton designs, so the
/// replicate mean is the estimate and `mean +- t_(R-1, (1+c)/2) s / sqrt(R)` is a
/// `c`-level interval, with `s` the standard deviation over replicates. Unlike the
/// bootstrap, this does not pretend that quasi-random rows are independent. The spread of
/// the estimates at a fixed `N` is also a direct convergence check.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReplicateSpread {
    /// Number of replicates `R`.
    pub replicates: usize,
    /// Interval level.
    pub confidence: f64,
    /// `first_order[t][i]`: mean over replicates.
    pub first_order: Vec<Vec<f64>>,
    /// `[lo, hi]` per output and parameter.
    pub first_order_ci: Vec<Vec<[f64; 2]>>,
    /// Standard error of the mean, `s / sqrt(R)`.
    pub first_order_se: Vec<Vec<f64>>,
    /// Mean total index.
    pub total: Vec<Vec<f64>>,
    /// Interval of the total index.
    pub total_ci: Vec<Vec<[f64; 2]>>,
    /// Standard error of the mean total index.
    pub total_se: Vec<Vec<f64>>,
}

/// Combines replicate analyses into means and t intervals (see [`ReplicateSpread`]).
///
/// # Errors
/// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) for fewer than 2
/// replicates or a confidence outside (0, 1);
/// [`CoreError::DimensionMismatch`](impactcal_core::CoreError::DimensionMismatch) when the
/// replicates differ in their numbers of outputs or parameters.
pub fn replicate_spread(results: &[SobolIndices], confidence: f64) -> Result<ReplicateSpread> {
    let r = results.len();
    if r < 2 {
        return Err(invalid_option(
            "replicates",
            r,
            "a replicate spread needs at least 2 replicates",
        ));
    }
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(invalid_option(
            "confidence",
            confidence,
            "the confidence level must lie in (0, 1)",
        ));
    }
    let (cols, d) = (results[0].first_order.len(), results[0].parameters.len());
    for res in results {
        if res.first_order.len() != cols || res.parameters.len() != d {
            return Err(dimension_mismatch(
                "outputs x parameters of a replicate",
                cols * d,
                res.first_order.len() * res.parameters.len(),
            ));
        }
    }
    let q = student_t_quantile(0.5 + 0.5 * confidence, (r - 1) as f64);
    let summarise = |get: &dyn Fn(&SobolIndices, usize, usize) -> f64| {
        let mut mean = vec![vec![0.0; d]; cols];
        let mut ci = vec![vec![[0.0; 2]; d]; cols];
        let mut se = vec![vec![0.0; d]; cols];
        for t in 0..cols {
            for i in 0..d {
                let v: Vec<f64> = results.iter().map(|res| get(res, t, i)).collect();
                let m = v.iter().sum::<f64>() / r as f64;
                let s = sample_sd(&v) / (r as f64).sqrt();
                mean[t][i] = m;
                se[t][i] = s;
                ci[t][i] = [m - q * s, m + q * s];
            }
        }
        (mean, ci, se)
    };
    let (first_order, first_order_ci, first_order_se) =
        summarise(&|res, t, i| res.first_order[t][i]);
    let (total, total_ci, total_se) = summarise(&|res, t, i| res.total[t][i]);
    Ok(ReplicateSpread {
        replicates: r,
        confidence,
        first_order,
        first_order_ci,
        first_order_se,
        total,
        total_ci,
        total_se,
    })
}
