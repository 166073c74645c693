//! The study's answer under a noisy objective: the evaluated point where a smoothed RBF of
//! all successes is lowest, next to the luckiest sample.
//!
//! A crash model's objective carries simulation noise, so the lowest value seen is biased:
//! among many points near the minimum, the one with the most negative noise wins. A
//! smoothing RBF `s_lambda` averages neighbouring evaluations. With the cubic (or
//! thin-plate) kernel and a linear tail it solves
//! `[[Phi + lambda I, P], [P^T, 0]] [c; a] = [f; 0]` over the distinct successful points.
//! `lambda` is chosen among `phi(sqrt d) 10^(k/2)`, `k = -24 ..= 4`, and `0` by the
//! leave-one-out error (Rippa's closed form, exact for a smoothed system too): no smoothing
//! where the values are smooth (the answer is then the luckiest sample, as the interpolant
//! reproduces the values), more where neighbours disagree. The answer is the evaluated
//! point of lowest `s_lambda`: an argmin over evaluated points, so it never lies where the
//! surrogate only extrapolates.

use faer::{ColRef, Mat};
use impactcal_erbf::{LooMethod, RbfInterpolant, RbfOptions};
use serde::{Deserialize, Serialize};

use crate::design::affine_rank_of_rows;
use crate::error::Result;
use crate::geometry::distance;
use crate::options::SurrogateKernel;
use crate::state::{CorsState, DUPLICATE_TOL};

/// The evaluated point of lowest smoothed-surrogate value ([`Cors::surrogate_answer`]).
///
/// [`Cors::surrogate_answer`]: crate::Cors::surrogate_answer
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurrogateAnswer {
    /// Index of the point in the history ([`Cors::evaluations`](crate::Cors::evaluations));
    /// the first of near-coinciding evaluations.
    pub index: usize,
    /// The point (in the units of the parameter space).
    pub x: Vec<f64>,
    /// The smoothed surrogate's value there, in the objective's raw units.
    pub predicted: f64,
    /// The value observed there (the mean of near-coinciding evaluations).
    pub observed: f64,
    /// The smoothing `lambda` chosen by leave-one-out (0: the values looked smooth).
    pub smoothing: f64,
    /// Root mean square leave-one-out error of the chosen surrogate: an estimate of the
    /// noise's standard deviation where the function itself is well resolved.
    pub loo_rmse: f64,
}

/// Powers of `sqrt 10`, relative to the largest kernel value, tried as the smoothing.
const SMOOTHING_EXPONENTS: std::ops::RangeInclusive<i32> = -24..=4;

/// The answer of [`Cors::surrogate_answer`](crate::Cors::surrogate_answer); `None` when
/// the successes hold fewer than `d + 2` distinct points or do not span (the
/// leave-one-out error is then undefined).
///
/// # Errors
/// Mapping errors of the parameter space (not expected for a checked state).
pub(crate) fn surrogate_answer(state: &CorsState) -> Result<Option<SurrogateAnswer>> {
    let d = state.space.dim();
    let tol = DUPLICATE_TOL * (d as f64).sqrt();
    let mut pts: Vec<Vec<f64>> = Vec::new();
    let mut index: Vec<usize> = Vec::new();
    let mut sums: Vec<(f64, f64)> = Vec::new();
    for (k, e) in state.evaluations.iter().enumerate() {
        let Some(v) = e.value else { continue };
        let u = state.space.to_unit(&e.x)?;
        match pts.iter().position(|p| distance(p, &u) <= tol) {
            Some(j) => {
                sums[j].0 += v;
                sums[j].1 += 1.0;
            }
            None => {
                pts.push(u);
                index.push(k);
                sums.push((v, 1.0));
            }
        }
    }
    if pts.len() < d + 2 || affine_rank_of_rows(&pts) < d + 1 {
        return Ok(None);
    }
    let values: Vec<f64> = sums.iter().map(|(s, n)| s / n).collect();
    let x: Mat<f64> = impactcal_core::points::from_rows(&pts, "evaluated points")?;
    let f = ColRef::from_slice(&values).as_mat();
    let base = match state.options.kernel {
        SurrogateKernel::Cubic => RbfOptions::cubic(),
        SurrogateKernel::ThinPlate => RbfOptions::thin_plate(),
    };
    let kmax = base.radial.value((d as f64).sqrt()).abs().max(1.0);
    let lambdas = std::iter::once(0.0)
        .chain(SMOOTHING_EXPONENTS.map(|k| kmax * 10f64.powf(f64::from(k) / 2.0)));
    let mut chosen: Option<(RbfInterpolant, f64, f64)> = None;
    for lambda in lambdas {
        let Ok(rbf) = RbfInterpolant::fit(x.as_ref(), f, base.with_smoothing(lambda)) else {
            continue;
        };
        let Ok(e) = rbf.loo_errors(LooMethod::Closed) else {
            continue;
        };
        let rmse = (e.col(0).iter().map(|v| v * v).sum::<f64>() / e.nrows() as f64).sqrt();
        if rmse.is_finite() && chosen.as_ref().is_none_or(|(_, _, r)| rmse < *r) {
            chosen = Some((rbf, lambda, rmse));
        }
    }
    let Some((rbf, smoothing, loo_rmse)) = chosen else {
        return Ok(None);
    };
    let predicted = rbf.predict_batch(x.as_ref())?;
    let mut best = 0;
    for k in 1..pts.len() {
        if predicted[(k, 0)] < predicted[(best, 0)] {
            best = k;
        }
    }
    Ok(Some(SurrogateAnswer {
        index: index[best],
        x: state.evaluations[index[best]].x.clone(),
        predicted: predicted[(best, 0)],
        observed: values[best],
        smoothing,
        loo_rmse,
    }))
}
