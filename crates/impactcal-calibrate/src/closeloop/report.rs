//! What the loop reads from forward selection's outcome: the verdict of the last detection
//! with the unattributed discrepancy when error remains, the first round's attribution, and
//! the added quantities with their values and intervals.

use impactcal_core::Parameter;

use super::attribution::Score;
use super::detection::Detection;
use super::discrepancy::{self, Discrepancy};
use super::fit::Fit;
use super::model_noise::DrawStats;
use super::result::{Added, Verdict};
use super::selection::Outcome;
use crate::error::Result;

/// The detection stage's conclusion from `det`, the detection on the outcome's fit:
/// model-form error left after the last round is [`Verdict::Unattributed`] (with its low-rank discrepancy on `labels` over `samples`,
/// the closest three candidates of the last attribution named beside it), none with
/// nothing added is [`Verdict::NoModelFormError`], none after additions
/// [`Verdict::Attributed`].
///
/// # Errors
/// Numerical errors of the discrepancy's SVD.
pub(super) fn verdict(
    outcome: &Outcome,
    det: &Detection,
    labels: &[String],
    samples: usize,
) -> Result<(Verdict, Option<Discrepancy>)> {
    let verdict = if det.model_form_error {
        Verdict::Unattributed
    } else if outcome.added.is_empty() {
        Verdict::NoModelFormError
    } else {
        Verdict::Attributed
    };
    if verdict != Verdict::Unattributed {
        return Ok((verdict, None));
    }
    let closest = outcome
        .rounds
        .iter()
        .rev()
        .find_map(|r| r.attribution.as_ref())
        .map(|a| {
            a.ranked
                .iter()
                .take(3)
                .map(|s| (s.name.clone(), s.explained_fraction))
                .collect()
        })
        .unwrap_or_default();
    let d = discrepancy::fit(
        labels,
        &outcome.fit.residual,
        samples,
        det.coherent_rank,
        closest,
    )?;
    Ok((verdict, Some(d)))
}

/// The first round's attribution (on the calibrated declared model): every direction
/// ranked, and the pairs these sensors cannot tell apart; empty when it did not run.
pub(super) fn first_attribution(outcome: &Outcome) -> (Vec<Score>, Vec<(String, String, f64)>) {
    outcome
        .rounds
        .first()
        .and_then(|r| r.attribution.as_ref())
        .map(|a| (a.ranked.clone(), a.indistinguishable.clone()))
        .unwrap_or_default()
}

/// The enrichment stage's report: each quantity `added` (in the order added, after the
/// `d0` declared parameters of `fit`) with its calibrated value and a 95 % interval
/// `value +- 1.96 sqrt(se^2 + v_model + se^2 R + pending^2)` (`se` the linearised standard
/// error, `v_model` the variance the model's noise adds, `R` the objective's roughness
/// from `draws`, `pending` the Gauss-Newton step left); an interval the data do not
/// determine (`se` not finite) is the candidate's whole admissible range.
pub(super) fn added(fit: &Fit, added: &[Parameter], d0: usize, draws: &DrawStats) -> Vec<Added> {
    let noise_var = draws.parameter_variances(fit.point.len());
    let roughness = draws.objective_noise();
    added
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let v = fit.point[d0 + i];
            let pending = fit.pending[d0 + i];
            let rough_var = fit.se[d0 + i].powi(2) * roughness;
            let se =
                (fit.se[d0 + i].powi(2) + noise_var[d0 + i] + rough_var + pending * pending).sqrt();
            // Not determined by the data at the end point: the interval is the whole range.
            let (lower, upper, roughness_sd) = if se.is_finite() {
                (v - 1.96 * se, v + 1.96 * se, rough_var.sqrt())
            } else {
                (p.lower, p.upper, 0.0)
            };
            Added {
                name: p.name.clone(),
                value: v,
                lower,
                upper,
                model_noise_sd: noise_var[d0 + i].sqrt(),
                roughness_sd,
                pending_step: pending,
            }
        })
        .collect()
}
