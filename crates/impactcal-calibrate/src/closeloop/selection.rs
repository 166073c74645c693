//! Forward selection (orthogonal matching pursuit with full nonlinear refits) and the
//! information criteria that decide when to stop.
//!
//! Round `r` holds the declared model with the candidates added so far, calibrated. When its
//! residual shows model-form error, the best eligible candidate of its attribution is added
//! (its range the candidate's admissible range, its nominal the held value) and the model
//! is recalibrated: CORS warm-started from the previous optimum (with the candidate at its
//! held value and at its linear estimate), its own budget, then the Gauss-Newton polish. The
//! addition is kept when the Bayesian information criterion falls by more than 2.
//!
//! With known noise (the weights and each channel's AR whitening, `closeloop::prewhiten`:
//! the residual is unit white noise under the noise model, so `RSS` is `-2` times its
//! Gaussian log-likelihood up to a constant), for `k` fitted quantities over `n` samples:
//! `AIC = RSS + 2 k`, `BIC = RSS + k ln n`; Akaike weights
//! `w_m = exp(-(AIC_m - AIC_min) / 2) / sum_j exp(-(AIC_j - AIC_min) / 2)`.
//!
//! When no candidate is eligible only because its linearised share of the residual is below
//! `min_explained`, the highest-scoring such candidate is tried all the same: the model is
//! recalibrated with it, and it is kept when the share the recalibration realises,
//! `1 - RSS_new / RSS_old`, reaches `min_explained` and BIC falls by more than 2. The
//! one-run share is measured at the calibrated point, where declared parameters may
//! already imitate part of the missing effect; the recalibration frees them together.
//!
//! Each addition is judged against a control: the same recalibration (budget, starting
//! optimum) without the candidate. The realised share and the BIC margin are measured
//! against the better of the previous fit and the control; a refused addition leaves the
//! control as the result when it fits better (one more round, without attribution).
//!
//! Every addition must also move its quantity away from the held value by more than the
//! noise can: the recalibrated value `v` is kept only when
//! `(v - held)^2 > z^2 (se^2 + v_model)`, `z^2` the `1 - alpha` quantile of `chi2_1`, `se`
//! the linearised standard error under the noise model and `v_model` the variance the
//! model's own noise adds, counted coherently from the jitter ensemble
//! (`closeloop::model_noise`). A crash model recalibrated with one more quantity can reach a
//! point where its own noise happens to match the test better; a change of the quantity no
//! larger than that noise makes is not evidence of the effect.
//!
//! Selection stops when no model-form error remains, when no candidate is eligible or
//! realises its share, when an addition is within the noise, when BIC does not fall by more than 2, or after `max_added`
//! additions.

use impactcal_core::{Enrichable, Parameter};

use super::attribution::{Attribution, Score, attribute};
use super::detection::{Detection, chi2_quantile, detect};
use super::fit::{Ctx, Fit, calibrate};
use super::options::LoopOptions;
use super::result::{ModelScore, Round};
use crate::error::Result;
use crate::progress::LoopRunEstimate;

/// What forward selection ends with.
pub(crate) struct Outcome {
    pub fit: Fit,
    pub added: Vec<Parameter>,
    pub rounds: Vec<Round>,
    pub models: Vec<ModelScore>,
    pub stopped: String,
}

/// The information criteria `(AIC, BIC)` of a fit with `k` quantities, whitened residual
/// sum of squares `rss` over `n` samples (see the module docs).
pub fn criteria(rss: f64, n: usize, k: usize) -> (f64, f64) {
    (rss + 2.0 * k as f64, rss + k as f64 * (n as f64).ln())
}

/// Akaike weights of a list of AIC values.
pub fn akaike_weights(aic: &[f64]) -> Vec<f64> {
    let min = aic.iter().copied().fold(f64::INFINITY, f64::min);
    let w: Vec<f64> = aic.iter().map(|a| (-(a - min) / 2.0).exp()).collect();
    let s: f64 = w.iter().sum();
    w.iter().map(|x| x / s).collect()
}

fn score(fit: &Fit, added: &[Parameter], n_nuisance: usize, kept: bool) -> ModelScore {
    let k = fit.point.len() + n_nuisance;
    let (aic, bic) = criteria(fit.rss, fit.residual.len(), k);
    ModelScore {
        added: added.iter().map(|p| p.name.clone()).collect(),
        k,
        rss: fit.rss,
        aic,
        bic,
        akaike_weight: 0.0,
        kept,
    }
}

/// One round's record: the quantities `added` so far, the calibrated `point` under the
/// space's `names`, its detection and attribution, the runs its fit used.
fn round(
    added: &[Parameter],
    names: &[&str],
    point: &[f64],
    detection: Detection,
    attribution: Option<Attribution>,
    runs: usize,
) -> Round {
    Round {
        added: added.iter().map(|p| p.name.clone()).collect(),
        calibrated: names
            .iter()
            .zip(point)
            .map(|(n, v)| (n.to_string(), *v))
            .collect(),
        detection,
        attribution,
        runs,
    }
}

/// Why the recalibration `fit_n` with `p` added (the candidate `best` of the attribution,
/// `trial` when it only fell short of its share) is refused, if it is: a quantity the data
/// do not determine, a realised share below `min_explained` for a trial, a change no larger
/// than the model's own noise makes or than the noise allows (`z^2` the `1 - alpha` quantile
/// of `chi2_1`), or BIC not falling by more than 2 against `base_bic` (`bics` is
/// `(base_bic, bic)`). See the module docs.
///
/// # Errors
/// Numerical errors of the model-noise pass.
#[allow(clippy::too_many_arguments)]
fn refusal(
    ctx: &Ctx<'_>,
    p: &Parameter,
    best: &Score,
    trial: bool,
    fit_n: &Fit,
    realised: f64,
    (base_bic, bic): (f64, f64),
    options: &LoopOptions,
) -> Result<Option<String>> {
    let z2 = chi2_quantile(1.0, options.alpha)?;
    let last = fit_n.point.len() - 1;
    let value = fit_n.point[last];
    let draws = ctx.model_noise.stats(fit_n, &ctx.frame, None, None)?;
    let noise_var = draws.parameter_variances(fit_n.point.len())[last];
    let sd = (fit_n.se[last].powi(2) + noise_var).sqrt();
    let change = (value - p.nominal).abs() * best.response_per_unit;
    let by_itself = draws.largest();
    let why = if !sd.is_finite() {
        Some(format!(
            "`{}` recalibrated to {value:.6e} from its held {:.6e}, where the data do not \
             determine it: its direction lies in the span of the other fitted quantities \
             and nuisance terms (or it has no effect) at that point",
            p.name, p.nominal
        ))
    } else if trial && (realised.is_nan() || realised < options.min_explained) {
        Some(format!(
            "`{}` scored first but explains too little: {:.3} of the residual linearised, \
             {:.3} once recalibrated with it, against the recalibration without it \
             (min_explained {})",
            p.name, best.explained_fraction, realised, options.min_explained
        ))
    } else if change <= by_itself {
        Some(format!(
            "`{}` recalibrated to {value:.6e} from its held {:.6e}: that change moves the \
             whitened response by {change:.3e}, no more than the model moves it by itself \
             under a jitter of its parameters ({by_itself:.3e})",
            p.name, p.nominal
        ))
    } else if (value - p.nominal).powi(2) <= z2 * sd * sd {
        Some(format!(
            "`{}` recalibrated to {value:.6e} from its held {:.6e}: a change within what \
             the measurement noise and the model's own noise make (standard deviation \
             {sd:.3e}, of which the model's noise {:.3e})",
            p.name,
            p.nominal,
            noise_var.sqrt()
        ))
    } else if bic > base_bic - 2.0 {
        Some(format!(
            "adding `{}` did not lower BIC by more than 2 against the recalibration \
             without it ({base_bic:.1} -> {:.1})",
            p.name, bic
        ))
    } else {
        None
    };
    Ok(why)
}

/// Runs forward selection from the calibrated declared model `fit0`.
///
/// # Errors
/// Run, journal and numerical errors of the fits and attributions.
#[allow(clippy::too_many_arguments)]
pub(crate) fn forward<M: Enrichable>(
    ctx: &Ctx<'_>,
    model: &M,
    fit0: Fit,
    options: &LoopOptions,
    onset: usize,
    n_nuisance: usize,
    noise_dof: Option<f64>,
) -> Result<Outcome> {
    let labels = ctx.frame.labels.clone();
    let t = ctx.frame.samples;
    let detect_fit = |fit: &Fit| -> Result<Detection> {
        let p = fit.point.len() + n_nuisance;
        let d = detect(&labels, &fit.residual, t, p, options.alpha, noise_dof)?;
        let floor = ctx
            .model_noise
            .stats(fit, &ctx.frame, Some(p), None)?
            .largest_chi2();
        Ok(d.with_model_noise(floor))
    };
    let mut fit = fit0;
    let mut det = detect_fit(&fit)?;
    let mut runs = fit.runs;
    let mut cur = model.enrich(&[])?;
    let mut added: Vec<Parameter> = Vec::new();
    let mut rounds = Vec::new();
    let mut models = vec![score(&fit, &added, n_nuisance, true)];
    let stopped;
    loop {
        let r = rounds.len();
        let attributes = r == 0 || det.model_form_error;
        let may_add = det.model_form_error && added.len() < options.max_added;
        let allowed = cur
            .candidates()
            .iter()
            .filter(|c| options.allows(c.name()))
            .count();
        let d = cur.space().dim();
        ctx.runner
            .replan(|e| e.rest_of_round(d, if attributes { allowed } else { 0 }, may_add));
        let attribution = if attributes {
            ctx.runner.observer.step("attribution");
            Some(attribute(
                ctx,
                &cur,
                &fit,
                &format!("r{r}"),
                options.candidate_step,
                options.alpha,
                options.min_explained,
                onset,
                &|n| options.allows(n),
            )?)
        } else {
            None
        };
        let names = cur.space().names();
        rounds.push(round(
            &added,
            &names,
            &fit.point,
            det.clone(),
            attribution.clone(),
            runs,
        ));
        if !det.model_form_error {
            stopped = "no model-form error remains (chi-square at the noise floor or no \
                       coherent residual)"
                .to_string();
            break;
        }
        if added.len() >= options.max_added {
            stopped = format!("max_added ({}) reached", options.max_added);
            break;
        }
        let chosen = attribution.as_ref().and_then(|a| {
            a.best()
                .map(|s| (s, false))
                .or_else(|| a.short_of_share().map(|s| (s, true)))
        });
        let Some((best, trial)) = chosen else {
            stopped = "no candidate is identifiable, admissible, significant and explains \
                       enough of the residual"
                .to_string();
            break;
        };
        let Some(cand) = cur.candidates().into_iter().find(|c| c.name() == best.name) else {
            stopped = format!("candidate `{}` vanished from the model's list", best.name);
            break;
        };
        ctx.runner
            .replan(|e| e.recalibrations(d) + e.holdout_runs());
        let p = cand.parameter.clone();
        let mut trial_added = added.clone();
        trial_added.push(p.clone());
        let next = model.enrich(&trial_added)?;
        let estimate = best
            .amplitude
            .as_ref()
            .map_or(p.nominal, |a| a.value.clamp(p.lower, p.upper));
        let mut at_held = fit.point.clone();
        at_held.push(p.nominal);
        let mut at_estimate = fit.point.clone();
        at_estimate.push(estimate);
        let mut start = vec![at_held];
        if (estimate - p.nominal).abs() > 1e-12 * p.width() {
            start.push(at_estimate);
        }
        ctx.runner
            .observer
            .step(&format!("recalibration with `{}`", p.name));
        let fit_n = calibrate(
            ctx,
            &next,
            &format!("r{}", r + 1),
            &start,
            options.recalibrate,
            options.polish,
        )?;
        // The control: the same recalibration without the candidate. A recalibration that
        // goes on from the previous optimum may lower the residual by itself (a search
        // that had not converged, or a point whose own noise matches the test better);
        // the addition is judged against what the control reaches.
        ctx.runner
            .observer
            .step(&format!("recalibration without `{}` (control)", p.name));
        let control = calibrate(
            ctx,
            &cur,
            &format!("r{}-control", r + 1),
            std::slice::from_ref(&fit.point),
            options.recalibrate,
            options.polish,
        )?;
        let s = score(&fit_n, &trial_added, n_nuisance, true);
        let control_score = score(&control, &added, n_nuisance, true);
        let prev_bic = models.last().map_or(f64::INFINITY, |m| m.bic);
        let (base_rss, base_bic) = if control.rss < fit.rss {
            (control.rss, control_score.bic.min(prev_bic))
        } else {
            (fit.rss, prev_bic)
        };
        let realised = 1.0 - fit_n.rss / base_rss;
        let refusal = refusal(
            ctx,
            &p,
            best,
            trial,
            &fit_n,
            realised,
            (base_bic, s.bic),
            options,
        )?;
        if let Some(why) = refusal {
            models.push(ModelScore { kept: false, ..s });
            stopped = why;
            if control.rss < fit.rss {
                // The control is the better fit of the model as it stands: it is the result.
                // Recorded as one more round, without an attribution.
                models.push(control_score);
                let detection = detect_fit(&control)?;
                rounds.push(round(
                    &added,
                    &names,
                    &control.point,
                    detection,
                    None,
                    control.runs,
                ));
                fit = control;
            }
            break;
        }
        models.push(s);
        if trial
            && let Some(entry) = rounds
                .last_mut()
                .and_then(|round| round.attribution.as_mut())
                .and_then(|a| a.ranked.iter_mut().find(|c| c.name == p.name))
        {
            entry.status = format!("best once recalibrated (explains {realised:.3})");
        }
        runs = fit_n.runs;
        det = detect_fit(&fit_n)?;
        fit = fit_n;
        cur = next;
        added = trial_added;
    }
    ctx.runner.replan(LoopRunEstimate::holdout_runs);
    let weights = akaike_weights(&models.iter().map(|m| m.aic).collect::<Vec<_>>());
    for (m, w) in models.iter_mut().zip(weights) {
        m.akaike_weight = w;
    }
    Ok(Outcome {
        fit,
        added,
        rounds,
        models,
        stopped,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_one_and_favour_the_smallest() {
        let w = akaike_weights(&[10.0, 12.0, 30.0]);
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        // exp(-1) relative weight for a difference of 2.
        assert!((w[1] / w[0] - (-1.0f64).exp()).abs() < 1e-12);
        let (aic, bic) = criteria(100.0, 1000, 3);
        assert!((aic - 106.0).abs() < 1e-12);
        assert!((bic - (100.0 + 3.0 * 1000f64.ln())).abs() < 1e-12);
    }
}
