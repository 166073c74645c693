//! Attribution: which candidate effect explains the residual, and which cannot be told
//! from what the model already fits.
//!
//! For each candidate `k` one run of the model with the candidate moved from its held value
//! by a finite step `h_k` (a fraction of its admissible range, inwards) gives its whitened
//! direction `g_k = w (N(y_k) - N(y*)) / h_k` under the fitted nuisance terms `N`. With `J`
//! the whitened Jacobian of the calibrated parameters and nuisance terms and `P_J` the
//! orthogonal projector onto its columns (whitening makes `W = I`):
//!
//! - confounding ratio `kappa_k = ||P_J g_k|| / ||g_k||`; above 0.9 re-tuning what is
//!   already fitted imitates the effect: *not identifiable from these sensors*, never
//!   attributed;
//! - the part no fitted quantity can mimic, `g~_k = (I - P_J) g_k`, and the residual `r`:
//!   amplitude `phi_k = <g~_k, r> / <g~_k, g~_k>` (added to the held value), standard error
//!   `sqrt(c / <g~_k, g~_k>)` with `c = (1 + rho_0) / (1 - rho_0)` for noise of lag-one
//!   correlation `rho_0`, and a 95 % interval of 1.96 standard errors; explained fraction
//!   `c_k = <g~_k, r>^2 / (<g~_k, g~_k> <r, r>)`; score statistic
//!   `LM_k = <g~_k, r>^2 / (<g~_k, g~_k> c)`, `chi2_1` under "effect absent", significant
//!   above the `1 - alpha / K` quantile (Bonferroni over the `K` directions);
//! - the model's own noise, counted coherently (`closeloop::model_noise`): the jitter
//!   ensemble's whitened draws `d_j` give the amplitude the model's noise alone produces,
//!   `a_j = <g~_k, d_j> / <g~_k, g~_k>`, of variance `v_k = sum_j a_j^2 / m`; the interval
//!   is `phi_k +- 1.96 sqrt(c / <g~_k, g~_k> + v_k)`, and a significant candidate whose
//!   `phi_k^2 / (c / <g~_k, g~_k> + v_k)` does not pass the same quantile is *within the
//!   model's noise* and never added (on a smooth model `v_k = 0`);
//! - admissibility: the interval must meet the candidate's admissible range (a damping that
//!   only a negative coefficient would explain is rejected);
//! - mutual coherence `|<g~_i, g~_j>| / (||g~_i|| ||g~_j||)` above 0.9 names pairs these
//!   sensors cannot tell apart;
//! - a sensor pattern per candidate: its share of `<g~_k, r>` on each channel.
//!
//! Beside the candidates, signature directions that need no run: the time scaling
//! `t' y'(t)` about the impact (a stiffness-mass scaling) and a drift `t'` per channel. They
//! are scored the same way and reported; they name no physical parameter and are never added.

use std::collections::BTreeMap;

use impactcal_core::{Candidate, Enrichable};
use serde::{Deserialize, Serialize};

use super::detection::chi2_quantile;
use super::fit::{Ctx, Fit};
use super::linalg::dot;
use super::nuisance;
use crate::error::Result;
use crate::study::execute::histories_of;

/// Confounding ratio above which a candidate is not identifiable.
pub const KAPPA_MAX: f64 = 0.9;
/// Mutual coherence above which two candidates are indistinguishable.
pub const COHERENCE_MAX: f64 = 0.9;

/// An amplitude with its 95 % interval.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Amplitude {
    /// Estimated value of the quantity (held value plus the fitted change).
    pub value: f64,
    /// Lower end of the interval.
    pub lower: f64,
    /// Upper end of the interval.
    pub upper: f64,
}

/// One scored direction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Score {
    /// Candidate or signature name.
    pub name: String,
    /// `candidate` (a model quantity) or `signature` (a shape with no parameter).
    pub kind: String,
    /// The candidate's group.
    pub group: String,
    /// Confounding ratio.
    pub kappa: f64,
    /// `kappa <= 0.9`.
    pub identifiable: bool,
    /// Explained fraction of the residual.
    pub explained_fraction: f64,
    /// Score statistic `LM`.
    pub score: f64,
    /// Above the Bonferroni-corrected `chi2_1` quantile.
    pub significant: bool,
    /// Amplitude (none when not identifiable); its interval counts the measurement noise
    /// and the model's own noise (see `model_noise_sd`).
    pub amplitude: Option<Amplitude>,
    /// Standard deviation of the amplitude the model's own noise alone produces: the
    /// jitter ensemble's draws regressed on the direction (`closeloop::model_noise`).
    #[serde(default)]
    pub model_noise_sd: f64,
    /// Norm of the part of the whitened direction no fitted quantity can mimic, per unit of
    /// the quantity, with the model's own noise taken out: `sqrt(||g~_k||^2 - E / h_k^2)`,
    /// `E` the mean energy of the jitter draws outside the fitted span and `h_k` the finite
    /// step (the candidate's run carries one draw of the model's noise, divided by the
    /// step); 0 for a signature or a candidate that is not identifiable. A change `a` of the
    /// quantity changes the whitened response beyond what re-tuning can undo by about
    /// `|a|` times this.
    #[serde(default)]
    pub response_per_unit: f64,
    /// The interval meets the admissible range.
    pub admissible: bool,
    /// What the loop makes of it: `best`, `eligible`, `not identifiable`, `inadmissible
    /// sign`, `not significant`, `within the model's noise`, `explains too little`,
    /// `signature`.
    pub status: String,
    /// Share of `<g~, r>` per channel.
    pub sensor_pattern: BTreeMap<String, f64>,
}

/// The attribution of one residual.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Attribution {
    /// Every direction, eligible ones first, each group by descending score.
    pub ranked: Vec<Score>,
    /// Pairs with mutual coherence above 0.9: `(a, b, mu)`.
    pub indistinguishable: Vec<(String, String, f64)>,
}

impl Attribution {
    /// The best eligible candidate, if any.
    pub fn best(&self) -> Option<&Score> {
        self.ranked.first().filter(|s| s.status == "best")
    }

    /// When no candidate is eligible, the highest-scoring one that fails only the
    /// explained-fraction rule (identifiable, admissible, significant): its one-run
    /// linearised share, measured where the declared parameters may already imitate part of
    /// the effect, understates what a recalibration with it freed removes; forward
    /// selection tries that recalibration and applies the rule to the share it realises.
    pub fn short_of_share(&self) -> Option<&Score> {
        if self.best().is_some() {
            return None;
        }
        self.ranked
            .iter()
            .filter(|s| s.status == "explains too little")
            .max_by(|a, b| a.score.total_cmp(&b.score))
    }
}

/// A direction to score: name, kind, group, whitened direction, and for a candidate its
/// held value, admissible range and finite step.
type Direction = (
    String,
    String,
    String,
    Vec<f64>,
    Option<(f64, f64, f64, f64)>,
);

/// Scores the candidates of `model` (and the signature directions) against the residual of
/// `fit` (see the module docs). `step` is the finite step as a fraction of each range.
///
/// # Errors
/// Run and journal errors; the model's `enrich` errors.
#[allow(clippy::too_many_arguments)]
pub(crate) fn attribute<M: Enrichable>(
    ctx: &Ctx<'_>,
    model: &M,
    fit: &Fit,
    prefix: &str,
    step: f64,
    alpha: f64,
    min_explained: f64,
    inflation: f64,
    onset: usize,
    allowed: &dyn Fn(&str) -> bool,
) -> Result<Attribution> {
    let cands: Vec<Candidate> = model
        .candidates()
        .into_iter()
        .filter(|c| allowed(c.name()))
        .collect();
    let frame = &ctx.frame;
    let base = nuisance::apply(&fit.y, frame, &fit.terms);
    let mut dirs: Vec<Direction> = Vec::new();
    if !cands.is_empty() {
        let params: Vec<_> = cands.iter().map(|c| c.parameter.clone()).collect();
        let full = model.enrich(&params)?;
        let mut centre = fit.point.clone();
        centre.extend(params.iter().map(|p| p.nominal));
        let d = fit.point.len();
        let mut steps = Vec::new();
        let points: Vec<Vec<f64>> = params
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let h = step * p.width();
                let h = if p.nominal + h > p.upper { -h } else { h };
                steps.push(h);
                let mut x = centre.clone();
                x[d + k] += h;
                x
            })
            .collect();
        let outs = ctx
            .runner
            .stage(&full, &format!("{prefix}-candidates"), &points)?;
        for (k, o) in outs.iter().enumerate() {
            let yk = ctx.y_of(&histories_of(
                o,
                &format!("candidate `{}`", params[k].name),
            )?)?;
            let mk = nuisance::apply(&yk, frame, &fit.terms);
            let g: Vec<f64> = mk
                .iter()
                .zip(&base)
                .zip(&frame.weights)
                .map(|((a, b), w)| w * (a - b) / steps[k])
                .collect();
            let p = &params[k];
            dirs.push((
                p.name.clone(),
                "candidate".into(),
                cands[k].group.clone(),
                g,
                Some((p.nominal, p.lower, p.upper, steps[k])),
            ));
        }
    }
    // Signature directions.
    let t = frame.samples;
    let ys = nuisance::shifted(&fit.y, frame, fit.terms.tau);
    let t0 = onset as f64 + fit.terms.tau / frame.dt;
    let mut scale = vec![0.0; ys.len()];
    for s in 0..frame.labels.len() {
        for k in 0..t {
            let (lo, hi) = (k.saturating_sub(1), (k + 1).min(t - 1));
            let dy = (ys[s * t + hi] - ys[s * t + lo]) / (hi - lo).max(1) as f64;
            let tt = (k as f64 - t0).max(0.0);
            scale[s * t + k] = frame.weights[s * t + k] * fit.terms.gains[s] * tt * dy;
        }
    }
    dirs.push((
        "time_scale".into(),
        "signature".into(),
        "signature".into(),
        scale,
        None,
    ));
    for (s, l) in frame.labels.iter().enumerate() {
        let mut g = vec![0.0; ys.len()];
        for k in 0..t {
            g[s * t + k] = frame.weights[s * t + k] * (k as f64 - t0).max(0.0);
        }
        dirs.push((
            format!("drift:{l}"),
            "signature".into(),
            "signature".into(),
            g,
            None,
        ));
    }

    let draws = ctx.model_noise.draws(fit, frame)?;
    let lsq = draws.lsq();
    let draws_energy = draws.unfitted_energy();
    let r = &fit.residual;
    let rr = dot(r, r);
    let crit = chi2_quantile(1.0, alpha / dirs.len() as f64)?;
    let mut scores = Vec::new();
    let mut tilde: Vec<(usize, Vec<f64>)> = Vec::new();
    for (i, (name, kind, group, g, range)) in dirs.iter().enumerate() {
        let gg = dot(g, g);
        let pg = lsq.project(g);
        let kappa = if gg > 0.0 {
            (dot(&pg, &pg) / gg).sqrt()
        } else {
            1.0
        };
        let gt: Vec<f64> = g.iter().zip(&pg).map(|(a, b)| a - b).collect();
        let gtt = dot(&gt, &gt);
        let identifiable = kappa <= KAPPA_MAX && gtt > 0.0;
        let gr = dot(&gt, r);
        let (explained, lm) = if identifiable && rr > 0.0 {
            (gr * gr / (gtt * rr), gr * gr / (gtt * inflation))
        } else {
            (0.0, 0.0)
        };
        let noise_var = if identifiable {
            draws.amplitude_variance(&gt)
        } else {
            0.0
        };
        let total_var = if identifiable {
            inflation / gtt + noise_var
        } else {
            f64::INFINITY
        };
        let amplitude = (identifiable).then(|| {
            let held = range.map_or(0.0, |r| r.0);
            let v = held + gr / gtt;
            let se = total_var.sqrt();
            Amplitude {
                value: v,
                lower: v - 1.96 * se,
                upper: v + 1.96 * se,
            }
        });
        let admissible = match (&amplitude, range) {
            (Some(a), Some((_, lo, hi, _))) => a.upper >= *lo && a.lower <= *hi,
            _ => true,
        };
        let mut pattern = BTreeMap::new();
        for (s, l) in frame.labels.iter().enumerate() {
            let part: f64 = (s * t..(s + 1) * t).map(|j| gt[j] * r[j]).sum();
            pattern.insert(l.clone(), if gr != 0.0 { part / gr } else { 0.0 });
        }
        let significant = lm > crit;
        let above_model_noise = identifiable && (gr / gtt).powi(2) / total_var > crit;
        let status = if kind == "signature" {
            "signature"
        } else if !identifiable {
            "not identifiable"
        } else if !admissible {
            "inadmissible sign"
        } else if !significant {
            "not significant"
        } else if !above_model_noise {
            "within the model's noise"
        } else if explained < min_explained {
            "explains too little"
        } else {
            "eligible"
        };
        if identifiable {
            tilde.push((i, gt));
        }
        scores.push(Score {
            name: name.clone(),
            kind: kind.clone(),
            group: group.clone(),
            kappa,
            identifiable,
            explained_fraction: explained,
            score: lm,
            significant,
            amplitude,
            model_noise_sd: noise_var.sqrt(),
            response_per_unit: match range {
                Some((_, _, _, h)) if identifiable => {
                    (gtt - draws_energy / (h * h)).max(0.0).sqrt()
                }
                _ => 0.0,
            },
            admissible,
            status: status.into(),
            sensor_pattern: pattern,
        });
    }
    let mut indistinguishable = Vec::new();
    for (a, (i, gi)) in tilde.iter().enumerate() {
        for (j, gj) in &tilde[a + 1..] {
            let mu = dot(gi, gj).abs() / (dot(gi, gi) * dot(gj, gj)).sqrt();
            if mu > COHERENCE_MAX {
                indistinguishable.push((scores[*i].name.clone(), scores[*j].name.clone(), mu));
            }
        }
    }
    let order = |s: &Score| match s.status.as_str() {
        "eligible" => 0,
        "signature" => 2,
        _ if s.kind == "candidate" && s.identifiable => 1,
        _ => 3,
    };
    scores.sort_by(|a, b| order(a).cmp(&order(b)).then(b.score.total_cmp(&a.score)));
    if let Some(first) = scores.first_mut()
        && first.status == "eligible"
    {
        first.status = "best".into();
    }
    Ok(Attribution {
        ranked: scores,
        indistinguishable,
    })
}
