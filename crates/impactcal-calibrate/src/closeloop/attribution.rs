//! Attribution: which candidate effect explains the residual, and which cannot be told
//! from what the model already fits.
//!
//! For each candidate `k` one run of the model with the candidate moved from its held value
//! by a finite step `h_k` (a fraction of its admissible range, inwards) gives its whitened
//! direction `g_k = L^-1 w (N(y_k) - N(y*)) / h_k` under the fitted nuisance terms `N`
//! (`w` the weights, `L^-1` each channel's AR filter of the noise, `closeloop::prewhiten`).
//!
//! A second run moves it to the end of its admissible range farther from the held value
//! (the secant over the range, `h_k` that distance). A small step sees only the effect's
//! linear regime: a phase-like effect (the dispersion of a bar, a wave's lag growing with
//! frequency) is, at small amplitude, mostly a delay the fitted offsets and wave speeds
//! imitate, and only near its full amplitude the ringing that nothing else makes; an effect
//! linear in its amplitude gives the same direction at either step. A candidate
//! identifiable at its small step (confounding ratio at most 0.9, below) is scored on
//! whichever of its two directions has the larger score statistic among the identifiable
//! ones; one that is not keeps its small step (the secant of a quantity the fitted ones
//! imitate locally carries only the curvature of their response). The Bonferroni count
//! below counts both directions of every candidate, so choosing the better one does not
//! inflate the significance. The step used is reported (`Score::step`).
//!
//! With `J` the whitened Jacobian of the calibrated parameters and nuisance terms and `P_J`
//! the orthogonal projector onto its columns (the whitening makes the noise unit white):
//!
//! - confounding ratio `kappa_k = ||P_J g_k|| / ||g_k||`; above 0.9 re-tuning what is
//!   already fitted imitates the effect: *not identifiable from these sensors*, never
//!   attributed;
//! - the part no fitted quantity can mimic, `g~_k = (I - P_J) g_k`, and the residual `r`:
//!   amplitude `phi_k = <g~_k, r> / <g~_k, g~_k>` (added to the held value), standard error
//!   `sqrt(1 / <g~_k, g~_k>)`, and a 95 % interval of 1.96 standard errors; explained
//!   fraction `c_k = <g~_k, r>^2 / (<g~_k, g~_k> <r, r>)`; score statistic
//!   `LM_k = <g~_k, r>^2 / <g~_k, g~_k>`, `chi2_1` under "effect absent", significant
//!   above the `1 - alpha / K` quantile (Bonferroni over the `K` directions made: both of
//!   every candidate, and the signatures);
//! - the model's own noise, counted coherently (`closeloop::model_noise`): the jitter
//!   ensemble's whitened draws `d_j` give the amplitude the model's noise alone produces,
//!   `a_j = <g~_k, d_j> / <g~_k, g~_k>`, of variance `v_k = sum_j a_j^2 / m`; the interval
//!   is `phi_k +- 1.96 sqrt(1 / <g~_k, g~_k> + v_k)`, and a significant candidate whose
//!   `phi_k^2 / (1 / <g~_k, g~_k> + v_k)` does not pass the same quantile is *within the
//!   model's noise* and never added (on a smooth model `v_k = 0`);
//! - admissibility: the interval must meet the candidate's admissible range (a damping that
//!   only a negative coefficient would explain is rejected);
//! - mutual coherence `|<g~_i, g~_j>| / (||g~_i|| ||g~_j||)` above 0.9 names pairs these
//!   sensors cannot tell apart;
//! - a sensor pattern per candidate: its share of `<g~_k, r>` on each channel.
//!
//! A drift is zero outside its channel; it is held as its channel's values and projected
//! in the factored form (`closeloop::jacobian`: `T + r_a` numbers per drift instead of a
//! vector over the whole test), and its sensor pattern is its share on its own channel.
//!
//! Beside the candidates, signature directions that need no run: the time scaling
//! `t' y'(t)` about the impact (a stiffness-mass scaling) and a drift `t'` per channel. They
//! are scored the same way and reported; they name no physical parameter and are never added.

use std::collections::BTreeMap;

use impactcal_core::{Candidate, Enrichable};
use serde::{Deserialize, Serialize};

use super::detection::chi2_quantile;
use super::fit::{Ctx, Fit};
use super::jacobian::Jacobian;
use super::linalg::dot;
use super::model_noise::DrawStats;
use super::nuisance::{self, Frame};
use crate::error::Result;

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
    /// The finite step of the direction scored, in units of the quantity (signed): the
    /// small step (`candidate_step` of the range) or the secant to the far end of the range,
    /// whichever scored higher; 0 for a signature.
    #[serde(default)]
    pub step: f64,
    /// The interval meets the admissible range.
    pub admissible: bool,
    /// What the loop makes of it: `best`, `eligible`, `not identifiable`, `inadmissible
    /// sign`, `not significant`, `within the model's noise`, `explains too little`,
    /// `signature`.
    pub status: String,
    /// Share of `<g~, r>` per channel (a drift's: on its own channel only).
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

/// A whitened direction before the fitted span is taken out: a vector over the whole test,
/// or the `T` values of a direction that is zero outside one channel (a drift).
enum Shape {
    Dense(Vec<f64>),
    Channel(usize, Vec<f64>),
}

/// A direction with the fitted span taken out, `g~ = (I - P_J) g`: a whole vector, or for a
/// direction `g` on channel `s` alone the pair `l = (I - P_Bs) g_s` (channel `s`'s rows)
/// and `c = U_a^T g`, with `g~ = l - U_a c` (`closeloop::jacobian`; `U_a` is orthogonal to
/// the channels' nuisance columns, so `U_a^T l = c`). The pair is `T + r_a` numbers where
/// the vector would be `S T`.
enum Unfitted {
    Dense(Vec<f64>),
    Channel { s: usize, l: Vec<f64>, c: Vec<f64> },
}

impl Unfitted {
    /// `g~ = (I - P_J) g` of the direction `g`, with `||g||^2` and `||P_J g||^2`.
    fn of(shape: Shape, jac: &Jacobian) -> (f64, f64, Self) {
        match shape {
            Shape::Dense(g) => {
                let pg = jac.project(&g);
                let gg = dot(&g, &g);
                let pgg = dot(&pg, &pg);
                let gt: Vec<f64> = g.iter().zip(&pg).map(|(a, b)| a - b).collect();
                (gg, pgg, Unfitted::Dense(gt))
            }
            Shape::Channel(s, g) => {
                let l = jac.channel_unfitted(s, &g);
                let c = jac.coefficients_channel(s, &g);
                let pb: f64 = g.iter().zip(&l).map(|(a, b)| (a - b).powi(2)).sum();
                (dot(&g, &g), pb + dot(&c, &c), Unfitted::Channel { s, l, c })
            }
        }
    }

    /// `<g~, y>`, given `y` and its coefficients `U_a^T y`.
    fn dot(&self, y: &[f64], uty: &[f64], t: usize) -> f64 {
        match self {
            Unfitted::Dense(g) => dot(g, y),
            Unfitted::Channel { s, l, c } => dot(l, &y[s * t..(s + 1) * t]) - dot(c, uty),
        }
    }

    /// `<g~_a, g~_b>` (`uty_dense` holds `U_a^T g~` of a dense one: zero to round-off).
    fn inner(a: (&Self, &[f64]), b: (&Self, &[f64]), t: usize) -> f64 {
        match (a.0, b.0) {
            (Unfitted::Dense(x), Unfitted::Dense(y)) => dot(x, y),
            (Unfitted::Dense(x), Unfitted::Channel { s, l, c })
            | (Unfitted::Channel { s, l, c }, Unfitted::Dense(x)) => {
                let ux = if matches!(a.0, Unfitted::Dense(_)) {
                    a.1
                } else {
                    b.1
                };
                dot(&x[s * t..(s + 1) * t], l) - dot(c, ux)
            }
            (
                Unfitted::Channel {
                    s: si,
                    l: li,
                    c: ci,
                },
                Unfitted::Channel {
                    s: sj,
                    l: lj,
                    c: cj,
                },
            ) => {
                let same = if si == sj { dot(li, lj) } else { 0.0 };
                same - dot(ci, cj)
            }
        }
    }
}

/// A direction to score: name, kind, group, whitened direction, and for a candidate its
/// held value, admissible range and finite step.
type Direction = (String, String, String, Shape, Option<(f64, f64, f64, f64)>);

/// The pairs among the identifiable directions `tilde` whose unfitted parts have mutual
/// coherence above [`COHERENCE_MAX`]: `(a, b, mu)`.
fn coherent_pairs(
    scores: &[Score],
    tilde: &[usize],
    unfitted: &[Unfitted],
    uty: &[Vec<f64>],
    norms: &[f64],
    t: usize,
) -> Vec<(String, String, f64)> {
    let mut indistinguishable = Vec::new();
    for (a, &i) in tilde.iter().enumerate() {
        for &j in &tilde[a + 1..] {
            let gij = Unfitted::inner((&unfitted[i], &uty[i]), (&unfitted[j], &uty[j]), t);
            let mu = gij.abs() / (norms[i] * norms[j]).sqrt();
            if mu > COHERENCE_MAX {
                indistinguishable.push((scores[i].name.clone(), scores[j].name.clone(), mu));
            }
        }
    }
    indistinguishable
}

/// The scores ranked: eligible candidates first, then the other identifiable candidates,
/// the signatures, the rest, each group by descending score; the first eligible one is
/// marked `best`.
fn ranked(mut scores: Vec<Score>) -> Vec<Score> {
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
    scores
}

/// The directions to score, whitened: two runs per candidate in `cands` (journal stage
/// `<prefix>-candidates`: each moved from its held value by `step` of its range, inwards,
/// then each at the far end of its range, see the module docs), each candidate's better
/// direction kept ([`probe`]), then the signatures: the time scaling about the impact
/// (`onset`, shifted by the trigger offset) and a drift per channel. Returns the directions
/// and the number of candidate directions that were made (for the Bonferroni count).
///
/// # Errors
/// Run and journal errors; the model's `enrich` errors.
fn directions<M: Enrichable>(
    ctx: &Ctx<'_>,
    model: &M,
    fit: &Fit,
    cands: &[Candidate],
    prefix: &str,
    step: f64,
    onset: usize,
) -> Result<(Vec<Direction>, usize)> {
    let frame = &ctx.frame;
    let t = frame.samples;
    let base = nuisance::apply(&fit.y, frame, &fit.terms);
    let mut dirs: Vec<Direction> = Vec::new();
    let mut made = 0;
    if !cands.is_empty() {
        let params: Vec<_> = cands.iter().map(|c| c.parameter.clone()).collect();
        let full = model.enrich(&params)?;
        let mut centre = fit.point.clone();
        centre.extend(params.iter().map(|p| p.nominal));
        let d = fit.point.len();
        let steps: Vec<(f64, Option<f64>)> = params.iter().map(|p| steps_of(p, step)).collect();
        let mut points = Vec::new();
        for (k, (h, _)) in steps.iter().enumerate() {
            let mut x = centre.clone();
            x[d + k] += h;
            points.push(x);
        }
        let mut far_index = Vec::new();
        for (k, (_, far)) in steps.iter().enumerate() {
            if let Some(h) = far {
                far_index.push(Some(points.len()));
                let mut x = centre.clone();
                x[d + k] += h;
                points.push(x);
            } else {
                far_index.push(None);
            }
        }
        let outs = ctx
            .runner
            .stage(&full, &format!("{prefix}-candidates"), &points)?;
        let direction = |i: usize, h: f64, what: &str| -> Result<Vec<f64>> {
            let yk = ctx.y_of(&outs.histories(i, what)?)?;
            Ok(nuisance::direction(&yk, &base, frame, &fit.terms, h))
        };
        for (k, p) in params.iter().enumerate() {
            let (h, far) = steps[k];
            let g = direction(k, h, &format!("candidate `{}`", p.name))?;
            made += 1;
            let (g, h) = match (far, far_index[k]) {
                (Some(hf), Some(i)) => {
                    let gf = direction(i, hf, &format!("candidate `{}` at its far end", p.name))?;
                    made += 1;
                    probe((g, h), (gf, hf), &fit.jac, &fit.residual)
                }
                _ => (g, h),
            };
            dirs.push((
                p.name.clone(),
                "candidate".into(),
                cands[k].group.clone(),
                Shape::Dense(g),
                Some((p.nominal, p.lower, p.upper, h)),
            ));
        }
    }
    // Signature directions.
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
    drop(ys);
    dirs.push((
        "time_scale".into(),
        "signature".into(),
        "signature".into(),
        Shape::Dense(frame.whitener.whiten(&scale)),
        None,
    ));
    for (s, l) in frame.labels.iter().enumerate() {
        let g: Vec<f64> = (0..t)
            .map(|k| frame.weights[s * t + k] * (k as f64 - t0).max(0.0))
            .collect();
        let g = frame.whitener.whiten_channel(s, &g);
        dirs.push((
            format!("drift:{l}"),
            "signature".into(),
            "signature".into(),
            Shape::Channel(s, g),
            None,
        ));
    }
    Ok((dirs, made))
}

/// The two finite steps of candidate `p` from its held value: `fraction` of its range,
/// inwards, and the secant to the end of its range farther from the held value (none when
/// that is no longer than the small step).
fn steps_of(p: &impactcal_core::Parameter, fraction: f64) -> (f64, Option<f64>) {
    let h = fraction * p.width();
    let h = if p.nominal + h > p.upper { -h } else { h };
    let far = if p.upper - p.nominal >= p.nominal - p.lower {
        p.upper - p.nominal
    } else {
        p.lower - p.nominal
    };
    (h, (far.abs() > h.abs() * (1.0 + 1e-9)).then_some(far))
}

/// Of a candidate's small-step direction `(g, h)` and its secant over the range
/// `(g_far, h_far)`, the one with the larger score statistic `<g~, r>^2 / <g~, g~>` against
/// the residual `r` among those with confounding ratio at most [`KAPPA_MAX`]; the small
/// step when it is not identifiable itself, when neither is, or on a tie.
///
/// The confounding ratio is a linear test: the fitted span is the Jacobian's, the tangent
/// of the fitted quantities at the calibrated point. A candidate the fitted quantities
/// imitate locally (a stiffness scale beside the modulus: the same model) has a secant
/// whose part outside that span is the curvature of their own response over a large
/// change, which re-tuning them would follow; it is no evidence of the effect, so the
/// secant is scored only for a candidate identifiable at its small step.
fn probe(
    near: (Vec<f64>, f64),
    far: (Vec<f64>, f64),
    jac: &Jacobian,
    r: &[f64],
) -> (Vec<f64>, f64) {
    let lm = |g: &[f64]| -> Option<f64> {
        let pg = jac.project(g);
        let gg = dot(g, g);
        let gt: Vec<f64> = g.iter().zip(&pg).map(|(a, b)| a - b).collect();
        let gtt = dot(&gt, &gt);
        let kappa = if gg > 0.0 {
            (dot(&pg, &pg) / gg).sqrt()
        } else {
            1.0
        };
        (kappa <= KAPPA_MAX && gtt > 0.0).then(|| dot(&gt, r).powi(2) / gtt)
    };
    match (lm(&near.0), lm(&far.0)) {
        (Some(n), Some(f)) if f > n => far,
        _ => near,
    }
}

/// Scores the candidates of `model` (and the signature directions) against the residual of
/// `fit` (see the module docs). `step` is the small finite step as a fraction of each
/// range; each candidate is also probed at the far end of its range.
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
    onset: usize,
    allowed: &dyn Fn(&str) -> bool,
) -> Result<Attribution> {
    let cands: Vec<Candidate> = model
        .candidates()
        .into_iter()
        .filter(|c| allowed(c.name()))
        .collect();
    if let Some(plan) = ctx.runner.plan {
        plan.check(super::plan::ATTRIBUTION, &format!("{prefix}-candidates"))?;
    }
    let frame = &ctx.frame;
    let t = frame.samples;
    let (dirs, made) = directions(ctx, model, fit, &cands, prefix, step, onset)?;
    let tests = dirs.len() - cands.len() + made;
    let parts = Parts::of(dirs, &fit.jac, t);

    // One pass over the model's noise draws: each direction's inner products with them.
    let products = |d: &[f64], utd: &[f64]| -> Vec<f64> {
        parts.unfitted.iter().map(|u| u.dot(d, utd, t)).collect()
    };
    let draws = ctx.model_noise.stats(fit, frame, None, Some(&products))?;
    let r = &fit.residual;
    let scoring = Scoring {
        frame,
        jac: &fit.jac,
        residual: r,
        utr: fit.jac.coefficients(r),
        rr: dot(r, r),
        crit: chi2_quantile(1.0, alpha / tests as f64)?,
        min_explained,
        draws: &draws,
        draws_energy: draws.unfitted_energy(),
    };
    let mut scores = Vec::with_capacity(parts.described.len());
    let mut tilde: Vec<usize> = Vec::new();
    for (i, described) in parts.described.iter().enumerate() {
        let s = scoring.score(
            i,
            described,
            parts.kappas[i],
            parts.norms[i],
            &parts.unfitted[i],
        );
        if s.identifiable {
            tilde.push(i);
        }
        scores.push(s);
    }
    let indistinguishable = coherent_pairs(
        &scores,
        &tilde,
        &parts.unfitted,
        &parts.uty,
        &parts.norms,
        t,
    );
    Ok(Attribution {
        ranked: ranked(scores),
        indistinguishable,
    })
}

/// A direction as the report names it: name, kind, group, and for a candidate its held
/// value, admissible range and finite step.
type Described = (String, String, String, Option<(f64, f64, f64, f64)>);

/// The directions with their fitted parts taken out, index by index: `g~`
/// ([`Unfitted`]), the confounding ratio `kappa = ||P_J g|| / ||g||` (1 for a zero
/// direction), `U_a^T g~` of a dense one (empty for a channel's), `||g~||^2`, and how
/// each is named.
struct Parts {
    unfitted: Vec<Unfitted>,
    kappas: Vec<f64>,
    uty: Vec<Vec<f64>>,
    norms: Vec<f64>,
    described: Vec<Described>,
}

impl Parts {
    /// The parts of `dirs` against the fitted span of `jac` (`t` samples per channel).
    fn of(dirs: Vec<Direction>, jac: &Jacobian, t: usize) -> Parts {
        let mut unfitted = Vec::with_capacity(dirs.len());
        let mut kappas = Vec::with_capacity(dirs.len());
        let mut described = Vec::with_capacity(dirs.len());
        for (name, kind, group, shape, range) in dirs {
            let (gg, pgg, u) = Unfitted::of(shape, jac);
            kappas.push(if gg > 0.0 { (pgg / gg).sqrt() } else { 1.0 });
            unfitted.push(u);
            described.push((name, kind, group, range));
        }
        let uty: Vec<Vec<f64>> = unfitted
            .iter()
            .map(|u| match u {
                Unfitted::Dense(g) => jac.coefficients(g),
                Unfitted::Channel { .. } => Vec::new(),
            })
            .collect();
        let norms: Vec<f64> = unfitted
            .iter()
            .zip(&uty)
            .map(|(u, c)| Unfitted::inner((u, c), (u, c), t).max(0.0))
            .collect();
        Parts {
            unfitted,
            kappas,
            uty,
            norms,
            described,
        }
    }
}

/// What every direction is scored against: the residual `r` (whitened), its coefficients
/// `U_a^T r` and `<r, r>`, the Bonferroni-corrected `chi2_1` quantile `crit`, the smallest
/// explained fraction, and the model's noise draws with their mean energy outside the
/// fitted span.
struct Scoring<'s> {
    frame: &'s Frame,
    jac: &'s Jacobian,
    residual: &'s [f64],
    utr: Vec<f64>,
    rr: f64,
    crit: f64,
    min_explained: f64,
    draws: &'s DrawStats,
    draws_energy: f64,
}

impl Scoring<'_> {
    /// The score of direction `i`, named by `described`, with confounding ratio `kappa`,
    /// `gtt = ||g~||^2` and unfitted part `u` (see the module docs).
    fn score(&self, i: usize, described: &Described, kappa: f64, gtt: f64, u: &Unfitted) -> Score {
        let (name, kind, group, range) = described;
        let range = *range;
        let identifiable = kappa <= KAPPA_MAX && gtt > 0.0;
        let gr = u.dot(self.residual, &self.utr, self.frame.samples);
        let (explained, lm) = if identifiable && self.rr > 0.0 {
            (gr * gr / (gtt * self.rr), gr * gr / gtt)
        } else {
            (0.0, 0.0)
        };
        let noise_var = if identifiable {
            self.draws.amplitude_variance(i, gtt)
        } else {
            0.0
        };
        let total_var = if identifiable {
            1.0 / gtt + noise_var
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
            (Some(a), Some((_, lo, hi, _))) => a.upper >= lo && a.lower <= hi,
            _ => true,
        };
        let significant = lm > self.crit;
        let above_model_noise = identifiable && (gr / gtt).powi(2) / total_var > self.crit;
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
        } else if explained < self.min_explained {
            "explains too little"
        } else {
            "eligible"
        };
        Score {
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
                    (gtt - self.draws_energy / (h * h)).max(0.0).sqrt()
                }
                _ => 0.0,
            },
            step: range.map_or(0.0, |r| r.3),
            admissible,
            status: status.into(),
            sensor_pattern: self.sensor_pattern(u, gr),
        }
    }

    /// The share of `<g~, r>` (`gr`) on each channel of the unfitted part `u` (a drift's:
    /// on its own channel only); 0 where `gr` is 0.
    fn sensor_pattern(&self, u: &Unfitted, gr: f64) -> BTreeMap<String, f64> {
        let (frame, r, t) = (self.frame, self.residual, self.frame.samples);
        let share = |part: f64| if gr != 0.0 { part / gr } else { 0.0 };
        let mut pattern = BTreeMap::new();
        match u {
            Unfitted::Dense(gt) => {
                for (s, l) in frame.labels.iter().enumerate() {
                    let part: f64 = (s * t..(s + 1) * t).map(|j| gt[j] * r[j]).sum();
                    pattern.insert(l.clone(), share(part));
                }
            }
            Unfitted::Channel { s, l, c } => {
                let rs = &r[s * t..(s + 1) * t];
                let part = dot(l, rs) - dot(c, &self.jac.coefficients_channel(*s, rs));
                pattern.insert(frame.labels[*s].clone(), share(part));
            }
        }
        pattern
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// A Jacobian of 4 channels of 30 samples: two dense columns, a bias and a gain per
    /// channel.
    fn jacobian() -> (Jacobian, usize, usize) {
        let (channels, t) = (4, 30);
        let n = channels * t;
        let w: Vec<f64> = (0..n).map(|i| 1.0 + 0.3 * (i as f64 * 0.7).sin()).collect();
        let gain: Vec<f64> = (0..n)
            .map(|i| w[i] * ((i % t) as f64 * 0.2 + (i / t) as f64).cos())
            .collect();
        let dense = vec![
            (0..n).map(|i| w[i] * (i as f64 * 0.05).sin()).collect(),
            (0..n)
                .map(|i| w[i] * ((i % t) as f64 / t as f64).powi(2))
                .collect(),
        ];
        (Jacobian::new(t, dense, &[&w, &gain]).unwrap(), channels, t)
    }

    fn scatter(s: usize, g: &[f64], channels: usize, t: usize) -> Vec<f64> {
        let mut v = vec![0.0; channels * t];
        v[s * t..(s + 1) * t].copy_from_slice(g);
        v
    }

    /// A drift held as its channel's values gives the numbers of the same direction held
    /// over the whole test: size, confounding ratio, `<g~, y>`, `<g~_a, g~_b>` with another
    /// drift and with a dense direction.
    #[test]
    fn a_direction_on_one_channel_gives_the_whole_vector_numbers() {
        let (jac, channels, t) = jacobian();
        let n = channels * t;
        let drift =
            |s: usize| -> Vec<f64> { (0..t).map(|k| (k as f64 + s as f64) * 0.1).collect() };
        let y: Vec<f64> = (0..n).map(|i| (i as f64 * 1.3).cos()).collect();
        let dense: Vec<f64> = (0..n).map(|i| (i as f64 * 0.11).sin().powi(3)).collect();
        let (_, _, hd) = Unfitted::of(Shape::Dense(dense.clone()), &jac);
        let hd_ut = match &hd {
            Unfitted::Dense(g) => jac.coefficients(g),
            Unfitted::Channel { .. } => unreachable!(),
        };
        let mut local = Vec::new();
        for s in [1, 3] {
            let g = drift(s);
            let whole = scatter(s, &g, channels, t);
            let (gg, pgg, u) = Unfitted::of(Shape::Channel(s, g), &jac);
            let (gg_w, pgg_w, u_w) = Unfitted::of(Shape::Dense(whole.clone()), &jac);
            assert!((gg - gg_w).abs() <= 1e-12 * gg_w);
            assert!((pgg - pgg_w).abs() <= 1e-10 * gg_w, "{pgg} vs {pgg_w}");
            let gt = match &u_w {
                Unfitted::Dense(g) => g.clone(),
                Unfitted::Channel { .. } => unreachable!(),
            };
            let norm = Unfitted::inner((&u, &[]), (&u, &[]), t);
            assert!((norm - dot(&gt, &gt)).abs() <= 1e-10 * gg_w);
            let a = u.dot(&y, &jac.coefficients(&y), t);
            assert!((a - dot(&gt, &y)).abs() <= 1e-10 * (gg_w * dot(&y, &y)).sqrt());
            let hd_dot = Unfitted::inner((&hd, &hd_ut), (&u, &[]), t);
            let expect = match &hd {
                Unfitted::Dense(h) => dot(h, &gt),
                Unfitted::Channel { .. } => unreachable!(),
            };
            assert!((hd_dot - expect).abs() <= 1e-10 * (gg_w * dot(&dense, &dense)).sqrt());
            local.push((u, gt));
        }
        let cross = Unfitted::inner((&local[0].0, &[]), (&local[1].0, &[]), t);
        let expect = dot(&local[0].1, &local[1].1);
        assert!(
            expect.abs() > 1e-6,
            "the two drifts must share something for the test"
        );
        assert!((cross - expect).abs() <= 1e-10 * expect.abs().max(1.0));
    }

    /// The test carries `c = 0.3` that the model holds at 0: after calibrating `k`, the
    /// residual is the part of `c`'s signature `k` cannot absorb, so `c` ranks first, explains
    /// nearly all of it, and its amplitude's interval holds 0.3; `m` does not.
    #[test]
    fn a_candidate_whose_signature_is_the_residual_ranks_first() {
        use crate::closeloop::fit::calibrate;
        use crate::closeloop::toy::{self, Toy};
        let model = Toy::new(0.0, 0.0, 1.0);
        let truth = Toy::new(0.3, 0.0, 1.0);
        let test = toy::measured(&truth, 1.3, 0.01, 3, None);
        let options = toy::options(0.01);
        toy::with_setting(&model, &test, &options, |setting, nominal| {
            let ctx = &setting.ctx;
            let fit = calibrate(
                ctx,
                &model,
                "r0",
                std::slice::from_ref(&nominal.point),
                8,
                8,
            )?;
            let a = attribute(
                ctx,
                &model,
                &fit,
                "r0",
                options.candidate_step,
                options.alpha,
                options.min_explained,
                setting.onset,
                &|_| true,
            )?;
            let first = &a.ranked[0];
            assert_eq!(first.name, "c");
            assert_eq!(first.status, "best");
            assert_eq!(a.best().map(|s| s.name.as_str()), Some("c"));
            assert!(first.explained_fraction > 0.95, "{first:?}");
            let amp = first.amplitude.as_ref().unwrap();
            assert!(amp.lower < 0.3 && 0.3 < amp.upper, "{amp:?}");
            let m = a.ranked.iter().find(|s| s.name == "m").unwrap();
            assert!(m.explained_fraction < first.explained_fraction);
            assert_ne!(m.status, "best");
            // Signatures are scored, never eligible.
            assert!(
                a.ranked
                    .iter()
                    .filter(|s| s.kind == "signature")
                    .all(|s| s.status == "signature")
            );
            // Restricted to `m`, the residual has no best candidate named `c`.
            let only_m = attribute(
                ctx,
                &model,
                &fit,
                "r0m",
                options.candidate_step,
                options.alpha,
                options.min_explained,
                setting.onset,
                &|n| n == "m",
            )?;
            assert!(only_m.ranked.iter().all(|s| s.name != "c"));
            Ok(())
        })
        .unwrap();
    }
}
