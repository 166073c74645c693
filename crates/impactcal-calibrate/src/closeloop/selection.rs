//! Forward selection (orthogonal matching pursuit with full nonlinear refits) and the
//! information criteria that decide when to stop.
//!
//! Round `r` holds the declared model with the candidates added so far, calibrated. When its
//! residual shows model-form error, the best eligible candidate of its attribution is added
//! (its range the candidate's admissible range, its nominal the held value) and the model
//! is recalibrated: CORS warm-started from the previous optimum (with the candidate at its
//! held value, at its linear estimate and at the far end of its range), its own budget, then the Gauss-Newton polish. The
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

use std::ops::ControlFlow;

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

/// The criteria of `fit` (with `added` quantities) over the `n` samples in the likelihood.
fn score(fit: &Fit, added: &[Parameter], n_nuisance: usize, n: usize, kept: bool) -> ModelScore {
    let k = fit.point.len() + n_nuisance;
    let (aic, bic) = criteria(fit.rss, n, k);
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

/// Runs forward selection from the calibrated declared model `fit0`: round by round,
/// attribution of the residual ([`Selection::attribution`]), the choice of a candidate
/// ([`State::choice`]), its recalibration and control ([`Selection::recalibrations`]) and
/// the decision ([`Selection::conclude`]), until a stopping rule holds (see the module docs).
///
/// # Errors
/// Run, journal and numerical errors of the fits and attributions.
pub(crate) fn forward<M: Enrichable>(
    ctx: &Ctx<'_>,
    model: &M,
    fit0: Fit,
    options: &LoopOptions,
    onset: usize,
    n_nuisance: usize,
    noise_dof: Option<f64>,
) -> Result<Outcome> {
    let selection = Selection {
        ctx,
        model,
        options,
        onset,
        n_nuisance,
        noise_dof,
    };
    let det = selection.detect(&fit0)?;
    let cur = model.enrich(&[])?;
    let models = vec![score(&fit0, &[], n_nuisance, ctx.frame.compared(), true)];
    let mut state = State {
        fit: fit0,
        det,
        cur,
        added: Vec::new(),
        rounds: Vec::new(),
        models,
    };
    let stopped = loop {
        let attribution = selection.attribution(&state)?;
        state.record(attribution.clone());
        let (best, trial, p) = match state.choice(attribution.as_ref(), options.max_added) {
            ControlFlow::Continue(choice) => choice,
            ControlFlow::Break(why) => break why,
        };
        let next_round = state.rounds.len();
        let d = state.cur.space().dim();
        ctx.runner
            .replan(|e| e.recalibrations(d) + e.holdout_runs());
        let tried = selection.recalibrations(&state, p, best, next_round)?;
        if let Some(why) = selection.conclude(&mut state, tried, best, trial)? {
            break why;
        }
    };
    ctx.runner.replan(LoopRunEstimate::holdout_runs);
    Ok(state.outcome(stopped))
}

/// What forward selection runs under: the loop's context, the declared model, the options,
/// the impact's sample `onset`, the number of nuisance terms and the degrees of freedom of
/// the measured noise level.
struct Selection<'s, 'a, M> {
    ctx: &'s Ctx<'a>,
    model: &'s M,
    options: &'s LoopOptions,
    onset: usize,
    n_nuisance: usize,
    noise_dof: Option<f64>,
}

/// Where forward selection stands: the model `cur` (the declared one with `added`), its
/// fit and the detection on its residual, and the rounds and model scores so far.
struct State<M> {
    fit: Fit,
    det: Detection,
    cur: M,
    added: Vec<Parameter>,
    rounds: Vec<Round>,
    models: Vec<ModelScore>,
}

/// One candidate tried: the parameter `p`, the model `next` with `added` (the quantities
/// added so far and `p`), its recalibration `fit`, and the `control`, the same
/// recalibration without `p`.
struct Tried<M> {
    p: Parameter,
    added: Vec<Parameter>,
    next: M,
    fit: Fit,
    control: Fit,
}

impl<M: Enrichable> Selection<'_, '_, M> {
    /// Detection on the residual of `fit` (with `k` the fitted quantities and nuisance
    /// terms), with the chi-square the model's own noise reaches at that `k`.
    ///
    /// # Errors
    /// Numerical errors of the detection and the model-noise pass.
    fn detect(&self, fit: &Fit) -> Result<Detection> {
        let ctx = self.ctx;
        let p = fit.point.len() + self.n_nuisance;
        let frame = &ctx.frame;
        let d = detect(
            &frame.labels,
            &fit.residual,
            Some(&frame.masked()),
            frame.samples,
            p,
            self.options.alpha,
            self.noise_dof,
        )?;
        let floor = ctx
            .model_noise
            .stats(fit, frame, Some(p), None)?
            .largest_chi2();
        Ok(d.with_model_noise(floor))
    }

    /// The attribution of the current residual (journal stage `r<round>-candidates`), in
    /// the first round and whenever model-form error remains; `None` otherwise.
    ///
    /// # Errors
    /// Those of [`attribute`].
    fn attribution(&self, state: &State<M>) -> Result<Option<Attribution>> {
        let r = state.rounds.len();
        let o = self.options;
        let attributes = r == 0 || state.det.model_form_error;
        let may_add = state.det.model_form_error && state.added.len() < o.max_added;
        let allowed = state
            .cur
            .candidates()
            .iter()
            .filter(|c| o.allows(c.name()))
            .count();
        let d = state.cur.space().dim();
        self.ctx
            .runner
            .replan(|e| e.rest_of_round(d, if attributes { allowed } else { 0 }, may_add));
        if !attributes {
            return Ok(None);
        }
        self.ctx.runner.observer.step("attribution");
        attribute(
            self.ctx,
            &state.cur,
            &state.fit,
            &format!("r{r}"),
            o.candidate_step,
            o.alpha,
            o.min_explained,
            self.onset,
            &|n| o.allows(n),
        )
        .map(Some)
    }

    /// The model with `p` (of the attribution's score `best`) added, recalibrated from the
    /// current optimum (journal stages `r<round>-...`) and the control without it
    /// (`r<round>-control-...`), each with the options' recalibration budget and polish.
    ///
    /// # Errors
    /// The model's `enrich` errors; run, journal and numerical errors of the fits.
    fn recalibrations(
        &self,
        state: &State<M>,
        p: Parameter,
        best: &Score,
        round: usize,
    ) -> Result<Tried<M>> {
        let (ctx, o) = (self.ctx, self.options);
        let mut added = state.added.clone();
        added.push(p.clone());
        let next = self.model.enrich(&added)?;
        let start = starts(&state.fit.point, &p, best);
        ctx.runner
            .observer
            .step(&format!("recalibration with `{}`", p.name));
        let fit = calibrate(
            ctx,
            &next,
            &format!("r{round}"),
            &start,
            o.recalibrate,
            o.polish,
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
            &state.cur,
            &format!("r{round}-control"),
            std::slice::from_ref(&state.fit.point),
            o.recalibrate,
            o.polish,
        )?;
        Ok(Tried {
            p,
            added,
            next,
            fit,
            control,
        })
    }

    /// Keeps the candidate `tried` (of the attribution's score `best`; `trial` when it only
    /// fell short of its share) or refuses it ([`refusal`]), against the better of the
    /// current fit and the control. A kept candidate becomes the current model; a refusal
    /// returns its reason, with the control as the result when it fits better (recorded as
    /// one more round, without an attribution).
    ///
    /// # Errors
    /// Numerical errors of the refusal's model-noise pass and of the detection.
    fn conclude(
        &self,
        state: &mut State<M>,
        tried: Tried<M>,
        best: &Score,
        trial: bool,
    ) -> Result<Option<String>> {
        let n_nuisance = self.n_nuisance;
        let n = self.ctx.frame.compared();
        let s = score(&tried.fit, &tried.added, n_nuisance, n, true);
        let control_score = score(&tried.control, &state.added, n_nuisance, n, true);
        let prev_bic = state.models.last().map_or(f64::INFINITY, |m| m.bic);
        let (base_rss, base_bic) = comparison_base(
            state.fit.rss,
            prev_bic,
            tried.control.rss,
            control_score.bic,
        );
        let realised = 1.0 - tried.fit.rss / base_rss;
        let bics = (base_bic, s.bic);
        let why = refusal(
            self.ctx,
            &tried.p,
            best,
            trial,
            &tried.fit,
            realised,
            bics,
            self.options,
        )?;
        if let Some(why) = why {
            state.models.push(ModelScore { kept: false, ..s });
            if tried.control.rss < state.fit.rss {
                // The control is the better fit of the model as it stands: the result.
                state.models.push(control_score);
                state.det = self.detect(&tried.control)?;
                state.fit = tried.control;
                state.record(None);
            }
            return Ok(Some(why));
        }
        state.models.push(s);
        if trial
            && let Some(entry) = state
                .rounds
                .last_mut()
                .and_then(|round| round.attribution.as_mut())
                .and_then(|a| a.ranked.iter_mut().find(|c| c.name == tried.p.name))
        {
            entry.status = format!("best once recalibrated (explains {realised:.3})");
        }
        state.det = self.detect(&tried.fit)?;
        state.fit = tried.fit;
        state.cur = tried.next;
        state.added = tried.added;
        Ok(None)
    }
}

impl<M: Enrichable> State<M> {
    /// Records the current model as a round, with the attribution of its residual.
    fn record(&mut self, attribution: Option<Attribution>) {
        let names = self.cur.space().names();
        self.rounds.push(round(
            &self.added,
            &names,
            &self.fit.point,
            self.det.clone(),
            attribution,
            self.fit.runs,
        ));
    }

    /// The candidate to try next, from the current round's `attribution`: its score, whether
    /// it is only a trial (it fell short of its share), and its parameter; or why selection
    /// stops (no model-form error remains, `max_added` reached, no candidate to try, or one
    /// the model no longer lists).
    fn choice<'b>(
        &self,
        attribution: Option<&'b Attribution>,
        max_added: usize,
    ) -> ControlFlow<String, (&'b Score, bool, Parameter)> {
        if !self.det.model_form_error {
            return ControlFlow::Break(
                "no model-form error remains (chi-square at the noise floor or no coherent \
                 residual)"
                    .to_string(),
            );
        }
        if self.added.len() >= max_added {
            return ControlFlow::Break(format!("max_added ({max_added}) reached"));
        }
        let chosen = attribution.and_then(|a| {
            a.best()
                .map(|s| (s, false))
                .or_else(|| a.short_of_share().map(|s| (s, true)))
        });
        let Some((best, trial)) = chosen else {
            return ControlFlow::Break(
                "no candidate is identifiable, admissible, significant and explains enough \
                 of the residual"
                    .to_string(),
            );
        };
        match self
            .cur
            .candidates()
            .into_iter()
            .find(|c| c.name() == best.name)
        {
            Some(c) => ControlFlow::Continue((best, trial, c.parameter)),
            None => ControlFlow::Break(format!(
                "candidate `{}` vanished from the model's list",
                best.name
            )),
        }
    }

    /// The outcome, with each model's Akaike weight.
    fn outcome(mut self, stopped: String) -> Outcome {
        let weights = akaike_weights(&self.models.iter().map(|m| m.aic).collect::<Vec<_>>());
        for (m, w) in self.models.iter_mut().zip(weights) {
            m.akaike_weight = w;
        }
        Outcome {
            fit: self.fit,
            added: self.added,
            rounds: self.rounds,
            models: self.models,
            stopped,
        }
    }
}

/// The starting points of a recalibration with `p` added to the optimum `point`: `p` at
/// its held value, at the attribution's estimate (clamped to its range) and at the end of
/// its range farther from the held value, each when it differs from those before it by
/// more than `1e-12` of the range. The local search cannot leave the basin it starts in; an
/// effect whose response is far from linear in its amplitude (a phase growing with
/// frequency) may have its optimum in another basin than the held value's and the linear
/// estimate's, and the far end of the admissible range starts a search there (the same
/// misfit keeps the best, `closeloop::fit::calibrate`).
fn starts(point: &[f64], p: &Parameter, best: &Score) -> Vec<Vec<f64>> {
    let estimate = best
        .amplitude
        .as_ref()
        .map_or(p.nominal, |a| a.value.clamp(p.lower, p.upper));
    let far = if p.upper - p.nominal >= p.nominal - p.lower {
        p.upper
    } else {
        p.lower
    };
    let mut values: Vec<f64> = Vec::new();
    for v in [p.nominal, estimate, far] {
        if values.iter().all(|u| (u - v).abs() > 1e-12 * p.width()) {
            values.push(v);
        }
    }
    values
        .into_iter()
        .map(|v| {
            let mut x = point.to_vec();
            x.push(v);
            x
        })
        .collect()
}

/// The fit an addition is judged against, as `(rss, bic)`: the control (residual sum of
/// squares `control_rss`, BIC `control_bic`) when it fits better than the current fit
/// (`fit_rss`), with the lower of its BIC and the current model's `prev_bic`; the current
/// fit otherwise.
fn comparison_base(fit_rss: f64, prev_bic: f64, control_rss: f64, control_bic: f64) -> (f64, f64) {
    if control_rss < fit_rss {
        (control_rss, control_bic.min(prev_bic))
    } else {
        (fit_rss, prev_bic)
    }
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

    fn scored(amplitude: Option<f64>) -> Score {
        Score {
            name: "c".into(),
            kind: "candidate".into(),
            group: "damping".into(),
            kappa: 0.1,
            identifiable: true,
            explained_fraction: 0.9,
            score: 50.0,
            significant: true,
            amplitude: amplitude.map(|value| crate::closeloop::Amplitude {
                value,
                lower: value - 0.1,
                upper: value + 0.1,
            }),
            model_noise_sd: 0.0,
            response_per_unit: 1.0,
            step: 0.1,
            admissible: true,
            status: "best".into(),
            sensor_pattern: Default::default(),
        }
    }

    /// A recalibration starts from the candidate at its held value, at the attribution's
    /// estimate clamped to the admissible range when it differs, and at the far end of the
    /// range when that differs from both.
    #[test]
    fn a_recalibration_starts_at_the_held_value_the_clamped_estimate_and_the_far_end() {
        let p = Parameter::new("c", 0.0, 2.0, 0.5).unwrap();
        let point = [1.0, 3.0];
        assert_eq!(
            starts(&point, &p, &scored(Some(1.25))),
            vec![
                vec![1.0, 3.0, 0.5],
                vec![1.0, 3.0, 1.25],
                vec![1.0, 3.0, 2.0]
            ]
        );
        // An estimate beyond the range is clamped to its end, which is the far end too.
        assert_eq!(
            starts(&point, &p, &scored(Some(7.0))),
            vec![vec![1.0, 3.0, 0.5], vec![1.0, 3.0, 2.0]]
        );
        // No estimate, or one at the held value: the held value and the far end.
        assert_eq!(
            starts(&point, &p, &scored(None)),
            vec![vec![1.0, 3.0, 0.5], vec![1.0, 3.0, 2.0]]
        );
        assert_eq!(
            starts(&point, &p, &scored(Some(0.5))),
            vec![vec![1.0, 3.0, 0.5], vec![1.0, 3.0, 2.0]]
        );
        // Held near the upper end: the far end is the lower one.
        let q = Parameter::new("g", 0.3, 3.0, 2.5).unwrap();
        assert_eq!(
            starts(&point, &q, &scored(None)),
            vec![vec![1.0, 3.0, 2.5], vec![1.0, 3.0, 0.3]]
        );
    }

    /// An addition is judged against the control only when the control fits better, and
    /// then against the lower of the two BICs.
    #[test]
    fn the_comparison_base_is_the_better_of_the_fit_and_the_control() {
        assert_eq!(comparison_base(100.0, 120.0, 90.0, 125.0), (90.0, 120.0));
        assert_eq!(comparison_base(100.0, 120.0, 90.0, 110.0), (90.0, 110.0));
        assert_eq!(comparison_base(100.0, 120.0, 100.0, 110.0), (100.0, 120.0));
        assert_eq!(comparison_base(100.0, 120.0, 130.0, 90.0), (100.0, 120.0));
    }
}
