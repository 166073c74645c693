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
/// model-form error left after the last round is [`Verdict::Unattributed`] (with its low-rank discrepancy on `labels` over the samples of `test`,
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
    test: &impactcal_core::Histories,
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
        (test.samples(), test.start(), test.dt()),
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

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::closeloop::recalibration;
    use crate::closeloop::toy::{self, Toy};
    use impactcal_core::Enrichable;

    /// The detection stage on the toy: silent on the right model with white noise of the
    /// known sigma (reduced chi-square near 1); on a wave no candidate makes, of RMS
    /// `A / sqrt 2`, it fires with the reduced chi-square near `1 + A^2 / (2 sigma^2)` and
    /// ends unattributed, with the discrepancy's signature.
    #[test]
    fn detection_is_silent_on_the_right_model_and_fires_on_a_known_residual() {
        let model = Toy::new(0.0, 0.0, 1.0);
        let sigma = 0.01;
        let options = toy::options(sigma);
        let outcome_of = |extra: Option<&[f64]>| {
            let test = toy::measured(&model, 1.3, sigma, 11, extra);
            toy::with_setting(&model, &test, &options, |setting, nominal| {
                let (_, outcome) = recalibration(setting, &model, &nominal.point, &options)?;
                let det = outcome.rounds.last().unwrap().detection.clone();
                let (v, d) = verdict(&outcome, &det, &nominal.labels, &nominal.test)?;
                Ok((outcome, v, d))
            })
            .unwrap()
        };
        let (outcome, v, d) = outcome_of(None);
        let det = &outcome.rounds[0].detection;
        assert!(!det.model_form_error, "{det:?}");
        assert!((det.chi2_red - 1.0).abs() < 0.3, "{}", det.chi2_red);
        assert_eq!(v, Verdict::NoModelFormError);
        assert!(d.is_none() && outcome.added.is_empty());

        let amplitude = 0.05;
        let wave = toy::foreign_wave(amplitude);
        let (outcome, v, d) = outcome_of(Some(&wave));
        let det = &outcome.rounds[0].detection;
        assert!(det.model_form_error, "{det:?}");
        let expect = 1.0 + amplitude * amplitude / (2.0 * sigma * sigma);
        assert!(
            (det.chi2_red / expect - 1.0).abs() < 0.1,
            "{} vs {expect}",
            det.chi2_red
        );
        assert_eq!(v, Verdict::Unattributed);
        let d = d.unwrap();
        assert!(!d.components.is_empty());
    }

    /// The enrichment stage on a test carrying the held `c = 0.3`: forward selection adds
    /// exactly `c`, with the admissible range and held value the model lists, and the
    /// report gives its recalibrated value inside its interval around the truth; where the
    /// data do not determine it, the interval is the whole admissible range.
    #[test]
    fn enrichment_adds_exactly_the_chosen_candidate_with_its_range() {
        let model = Toy::new(0.0, 0.0, 1.0);
        let truth = Toy::new(0.3, 0.0, 1.0);
        let options = toy::options(0.01);
        let test = toy::measured(&truth, 1.3, 0.01, 5, None);
        toy::with_setting(&model, &test, &options, |setting, nominal| {
            let (_, outcome) = recalibration(setting, &model, &nominal.point, &options)?;
            let listed = model.candidates();
            let c = &listed.iter().find(|c| c.name() == "c").unwrap().parameter;
            assert_eq!(outcome.added, std::slice::from_ref(c));
            let ctx = &setting.ctx;
            let draws = ctx
                .model_noise
                .stats(&outcome.fit, &ctx.frame, None, None)?;
            let report = added(&outcome.fit, &outcome.added, 1, &draws);
            assert_eq!(report.len(), 1);
            let r = &report[0];
            assert_eq!(r.name, "c");
            assert_eq!(r.value.to_bits(), outcome.fit.point[1].to_bits());
            assert!(r.lower < 0.3 && 0.3 < r.upper, "{r:?}");
            assert!(r.lower < r.value && r.value < r.upper);
            let mut undetermined = outcome.fit.clone();
            undetermined.se[1] = f64::INFINITY;
            let r = &added(&undetermined, &outcome.added, 1, &draws)[0];
            assert_eq!((r.lower, r.upper), (c.lower, c.upper));
            Ok(())
        })
        .unwrap();
    }
}
