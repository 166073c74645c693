//! Time-dependent Sobol' indices of `Q(t)`, estimated from surrogate evaluations on a
//! Saltelli design, and the parameter that dominates each time window (the paper's Fig. 9).

use std::collections::BTreeMap;

use impactcal_core::{ParameterSpace, SamplingMethod};
use impactcal_sobol::{SaltelliDesign, SobolOptions, analyze};
use serde::{Deserialize, Serialize};

use super::surrogates::Fitted;
use crate::error::Result;

/// Number of equal time windows the dominant parameter is reported for.
pub const WINDOWS: usize = 8;

/// The parameter that explains most of the variance of `Q` in a window.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Dominant {
    /// Window start (s).
    pub start: f64,
    /// Window end (s).
    pub end: f64,
    /// The parameter with the largest variance-weighted mean first-order index.
    pub parameter: String,
    /// That index.
    pub first_order: f64,
}

/// Sensitivity of `Q(t)` over time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sensitivity {
    /// Estimators, named: first order and total.
    pub estimator: String,
    /// Base rows of the Saltelli design and the surrogate evaluations `n (d + 2)`.
    pub base_samples: usize,
    /// Surrogate evaluations.
    pub evaluations: usize,
    /// Sample times.
    pub time: Vec<f64>,
    /// First-order index per parameter, one value per time (0 where `Q` does not vary).
    pub first_order: BTreeMap<String, Vec<f64>>,
    /// Total index per parameter and time.
    pub total: BTreeMap<String, Vec<f64>>,
    /// Variance of `Q` per time over the design.
    pub variance: Vec<f64>,
    /// Parameters by variance-weighted total index, most important first.
    pub ranking: Vec<String>,
    /// Variance-weighted total index per parameter over the whole window.
    pub aggregated_total: BTreeMap<String, f64>,
    /// The dominant parameter per window.
    pub dominant: Vec<Dominant>,
}

/// Sobol' indices of the surrogate `q` of `Q(t)` (outputs = the samples at `time`) on a
/// scrambled-Sobol' Saltelli design of `n` base rows.
///
/// # Errors
/// Design, surrogate and analysis errors.
pub fn sensitivity(
    space: &ParameterSpace,
    q: &Fitted,
    time: &[f64],
    n: usize,
    seed: u64,
) -> Result<Sensitivity> {
    let design = SaltelliDesign::generate(space, n, SamplingMethod::ScrambledSobol, false, seed)?;
    let y = q.predict_batch(design.points.as_ref())?;
    let names: Vec<String> = space.names().iter().map(|s| s.to_string()).collect();
    let options = SobolOptions {
        parameter_names: Some(names.clone()),
        ..SobolOptions::default()
    };
    let s = analyze(&design.layout, y.as_ref(), &options)?;
    let clean = |v: f64| if v.is_finite() { v } else { 0.0 };
    let series =
        |m: &Vec<Vec<f64>>, i: usize| -> Vec<f64> { m.iter().map(|row| clean(row[i])).collect() };
    let first_order: BTreeMap<String, Vec<f64>> = names
        .iter()
        .enumerate()
        .map(|(i, n)| (n.clone(), series(&s.first_order, i)))
        .collect();
    let total: BTreeMap<String, Vec<f64>> = names
        .iter()
        .enumerate()
        .map(|(i, n)| (n.clone(), series(&s.total, i)))
        .collect();
    let aggregated_total: BTreeMap<String, f64> = names
        .iter()
        .zip(&s.aggregated.total)
        .map(|(n, v)| (n.clone(), clean(*v)))
        .collect();
    let mut ranking = names.clone();
    ranking.sort_by(|a, b| aggregated_total[b].total_cmp(&aggregated_total[a]));
    let variance: Vec<f64> = s.variance.iter().map(|v| clean(*v)).collect();
    let t = time.len();
    let dominant = (0..WINDOWS.min(t))
        .filter_map(|w| {
            let (a, b) = (w * t / WINDOWS.min(t), (w + 1) * t / WINDOWS.min(t));
            let vsum: f64 = variance[a..b].iter().sum();
            let weighted = |name: &String| -> f64 {
                let s1 = &first_order[name];
                if vsum > 0.0 {
                    (a..b).map(|k| variance[k] * s1[k]).sum::<f64>() / vsum
                } else {
                    0.0
                }
            };
            let best = names
                .iter()
                .max_by(|x, y| weighted(x).total_cmp(&weighted(y)))?;
            Some(Dominant {
                start: time[a],
                end: time[b - 1],
                parameter: best.clone(),
                first_order: weighted(best),
            })
        })
        .collect();
    Ok(Sensitivity {
        estimator: format!(
            "first order {}, total {} (pick-freeze on a scrambled Sobol' Saltelli design)",
            estimator_name(&s.first_order_estimator),
            estimator_name(&s.total_estimator)
        ),
        base_samples: n,
        evaluations: design.points.nrows(),
        time: time.to_vec(),
        first_order,
        total,
        variance,
        ranking,
        aggregated_total,
        dominant,
    })
}

fn estimator_name<T: Serialize + std::fmt::Debug>(e: &T) -> String {
    serde_json::to_value(e)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_else(|| format!("{e:?}"))
}
