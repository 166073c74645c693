//! The step of a CORS-RBF study, as a pure function of its state: which points to evaluate
//! next, and the plan of the run they belong to. The driver ([`Cors`](crate::Cors)) applies
//! the proposal; nothing here changes the state.
//!
//! The restart decision is [`advance_plan`], the only place that decides it: the step calls
//! it before proposing, and rebuilding a study from its history
//! ([`Cors::from_history`](crate::Cors::from_history)) calls it at every row.

use crate::design::affine_rank_of_rows;
use crate::error::Result;
use crate::geometry::{distance, stream};
use crate::options::{AdaptiveRegion, Converged, CorsOptions, InitialDesign};
use crate::region::{LocalWidth, SUCCESS_IMPROVEMENT, adaptive_width};
use crate::schedule::pattern_position;
use crate::stall::StallRule;
use crate::state::{
    CorsState, DUPLICATE_TOL, FillReason, MATCH_TOL, Mode, Origin, Plan, Suggestion, best_of,
};
use crate::subproblem::{Blockers, Region, StepSettings, cors_step, maximin};
use crate::surrogate::RbfSurrogate;

/// What a step proposes: the plan of the run (new at the first suggestion or a restart)
/// and the suggestions, in order, with consecutive ids from the state's next id.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Proposal {
    pub(crate) plan: Plan,
    pub(crate) suggestions: Vec<Suggestion>,
}

/// The plan fixed at the first suggestion: the mode (design or existing evaluations, by
/// [`InitialDesign`]) and the start of the `beta` cycle after the initial set.
///
/// # Errors
/// [`CorsError::InsufficientInitialSet`](crate::CorsError::InsufficientInitialSet) under
/// [`InitialDesign::Existing`] when the evaluations do not span.
pub(crate) fn initial_plan(state: &CorsState) -> Result<Plan> {
    let design = state.run_design(0)?;
    let spans = state.successes_span()?;
    let mode = match state.options.initial {
        InitialDesign::Design => Mode::Design,
        InitialDesign::Existing => {
            state.require_span()?;
            Mode::Existing
        }
        InitialDesign::Auto if spans => Mode::Existing,
        InitialDesign::Auto => Mode::Design,
    };
    let n = state.evaluations.len() + state.pending.len();
    let cycle_origin = match mode {
        Mode::Existing => n,
        Mode::Design => n + design.len(),
    };
    Ok(Plan {
        mode,
        design,
        cycle_origin,
        run_start: 0,
        restarts: 0,
        excluded: Vec::new(),
    })
}

/// The restart decision before the point at history index `index`, seeing the first `upto`
/// evaluations: when a restart rule is set, the point lies past the run's initial set and
/// the run stagnates, `plan` becomes a new run starting at `index` (a new design drawn from
/// the seed and the restart count, the cycle after it). Returns whether it restarted.
///
/// # Errors
/// Those of the sampler (not expected for a checked state).
pub(crate) fn advance_plan(
    state: &CorsState,
    plan: &mut Plan,
    index: usize,
    upto: usize,
) -> Result<bool> {
    let due =
        index >= plan.cycle_origin
            && (state.options.restart.as_ref().is_some_and(|rule| {
                plan.stagnates(&state.evaluations, upto, rule, state.space.dim())
            }) || converged_restart(state, plan, upto));
    if due {
        if keeps_outside(state) {
            plan.excluded.push(run_best(state, plan, upto)?);
        }
        plan.restarts += 1;
        plan.design = state.run_design(plan.restarts)?;
        plan.mode = Mode::Design;
        plan.run_start = index;
        plan.cycle_origin = index + plan.design.len();
    }
    Ok(due)
}

/// Whether restarts keep the earlier runs' points outside their converged basins
/// ([`Converged::RestartOutside`]).
fn keeps_outside(state: &CorsState) -> bool {
    state
        .options
        .adaptive_region
        .is_some_and(|r| r.on_converged == Converged::RestartOutside)
}

/// The best successful point (unit box) of the current run among the first `upto`
/// evaluations (ties to the earlier); the centre of the box when it has none.
///
/// # Errors
/// Mapping errors of the parameter space (not expected).
fn run_best(state: &CorsState, plan: &Plan, upto: usize) -> Result<Vec<f64>> {
    let end = upto.min(state.evaluations.len());
    let start = plan.run_start.min(end);
    match best_of(&state.evaluations[start..end]) {
        Some(e) => Ok(state.space.to_unit(&e.x)?),
        None => Ok(vec![0.5; state.space.dim()]),
    }
}

/// The successes of earlier runs (unit box, with their values) that the current run's
/// surrogate and distance constraints keep: those outside every excluded box, under
/// [`Converged::RestartOutside`]; none otherwise.
///
/// # Errors
/// Mapping errors of the parameter space (not expected).
fn kept_from_earlier(state: &CorsState, plan: &Plan) -> Result<Vec<(Vec<f64>, f64)>> {
    if !keeps_outside(state) {
        return Ok(Vec::new());
    }
    let half = state.options.local_region.unwrap_or(0.3);
    let start = plan.run_start.min(state.evaluations.len());
    let mut kept = Vec::new();
    for e in &state.evaluations[..start] {
        let Some(v) = e.value else { continue };
        let u = state.space.to_unit(&e.x)?;
        if plan.excluded.iter().all(|c| outside_box(&u, c, half)) {
            kept.push((u, v));
        }
    }
    Ok(kept)
}

/// Whether the local region of the run, seeing the first `upto` evaluations, has converged
/// under [`Converged::Restart`] or [`Converged::RestartOutside`].
fn converged_restart(state: &CorsState, plan: &Plan, upto: usize) -> bool {
    let Some(rule) = state.options.adaptive_region.as_ref().filter(|r| {
        matches!(
            r.on_converged,
            Converged::Restart | Converged::RestartOutside
        )
    }) else {
        return false;
    };
    run_width(state, plan, rule, upto).converged > 0
}

/// The adaptive width of the current run after its evaluations before index `upto`.
fn run_width(state: &CorsState, plan: &Plan, rule: &AdaptiveRegion, upto: usize) -> LocalWidth {
    let end = upto.min(state.evaluations.len());
    let start = plan.run_start.min(end);
    adaptive_width(
        rule,
        state.options.local_region.unwrap_or(1.0),
        &state.evaluations[start..end],
        plan.cycle_origin.saturating_sub(start),
        state.space.dim(),
    )
}

/// Proposes `q` distinct points to evaluate next (see [`Cors::suggest`](crate::Cors::suggest)).
///
/// # Errors
/// As [`initial_plan`]; mapping errors of the parameter space (not expected).
pub(crate) fn propose(state: &CorsState, q: usize) -> Result<Proposal> {
    let mut plan = match &state.plan {
        Some(p) => p.clone(),
        None => initial_plan(state)?,
    };
    let evaluated = state.evaluations.len();
    advance_plan(state, &mut plan, evaluated + state.pending.len(), evaluated)?;
    let d = state.space.dim();
    let mut out: Vec<Suggestion> = Vec::with_capacity(q);
    let next_id = |out: &Vec<Suggestion>| state.next_id + out.len() as u64;
    if plan.mode == Mode::Design {
        let tol = MATCH_TOL * (d as f64).sqrt();
        let mut seen = state.units(
            state.evaluations[plan.run_start.min(evaluated)..]
                .iter()
                .map(|e| e.x.as_slice()),
        )?;
        seen.extend(state.units(state.pending.iter().map(|p| p.x.as_slice()))?);
        for u in &plan.design {
            if out.len() == q {
                break;
            }
            if seen.iter().any(|s| distance(s, u) <= tol) {
                continue;
            }
            out.push(Suggestion {
                id: next_id(&out),
                x: state.unit_to_space(u)?,
                origin: Origin::Design,
                beta: None,
                delta: None,
                predicted: None,
                fill_reason: None,
            });
        }
    }
    if out.len() == q {
        return Ok(Proposal {
            plan,
            suggestions: out,
        });
    }
    let width = local_width(state, &plan);
    let earlier = kept_from_earlier(state, &plan)?;
    let fitted = fit_surrogate(state, &plan, &earlier, width.rank)?;
    let root_d = (d as f64).sqrt();
    while out.len() < q {
        let index = evaluated + state.pending.len() + out.len();
        let mut rng = stream(state.options.seed, index);
        let blockers = blockers(state, &plan, &earlier, &out)?;
        // Evaluations after the run's initial set before this one.
        let m = index.saturating_sub(plan.cycle_origin);
        let position = run_position(state, &plan, index);
        let per_dim = match &state.options.candidate_decay {
            Some(decay) => decay.per_dim(state.options.candidates_per_dim, m),
            None => state.options.candidates_per_dim,
        };
        let n_cand = per_dim * d;
        let s = match &fitted {
            Ok(Fitted {
                surrogate,
                best,
                centre,
                second,
            }) => {
                let k = state.options.pattern.len();
                let beta = state.options.pattern[position % k];
                let searched = cycle_search(position / k, &state.options);
                let local = searched != CycleSearch::Whole;
                let centre = if searched == CycleSearch::Second {
                    second
                } else {
                    centre
                };
                let (region, best, sigma_scale) = match state.options.local_region {
                    Some(initial) if local => (
                        Region::around(centre, width.boxed),
                        centre,
                        width.half / initial,
                    ),
                    _ => (Region::unit(d), best, 1.0),
                };
                let settings = StepSettings {
                    beta,
                    floor: state.options.min_distance * root_d,
                    failure_radius: state.options.failure_radius * root_d,
                    candidates: n_cand,
                    local_candidates: state.options.local_candidates_per_dim * d,
                    polish_starts: state.options.polish_starts,
                    perturb: state.options.perturbation.filter(|_| local).map(|p| {
                        let horizon = p.horizon_for(state.options.budget, plan.cycle_origin);
                        p.probability(m, d, horizon)
                    }),
                    merit_weight: state.options.merit_weights.as_ref().map(|w| w[m % w.len()]),
                    sigma_scale,
                };
                let c = cors_step(surrogate, best, &blockers, &settings, &region, &mut rng);
                Suggestion {
                    id: next_id(&out),
                    x: state.unit_to_space(&c.x)?,
                    origin: Origin::Cors,
                    beta: Some(beta),
                    delta: Some(c.delta),
                    predicted: Some(c.predicted),
                    fill_reason: None,
                }
            }
            Err(reason) => {
                let (u, delta) = if blockers.is_empty() {
                    (vec![0.5; d], f64::INFINITY)
                } else {
                    maximin(&blockers, n_cand, &mut rng)
                };
                Suggestion {
                    id: next_id(&out),
                    x: state.unit_to_space(&u)?,
                    origin: Origin::Fill,
                    beta: None,
                    delta: delta.is_finite().then_some(delta),
                    predicted: None,
                    fill_reason: Some(reason.clone()),
                }
            }
        };
        out.push(s);
    }
    Ok(Proposal {
        plan,
        suggestions: out,
    })
}

/// The pattern position of the step at history index `index` ([`pattern_position`] over
/// the current run).
fn run_position(state: &CorsState, plan: &Plan, index: usize) -> usize {
    let end = state.evaluations.len();
    let start = plan.run_start.min(end);
    pattern_position(
        &state.options,
        &state.evaluations[start..end],
        plan.cycle_origin.saturating_sub(start),
        index.saturating_sub(start),
    )
}

/// Where a cycle of the `beta` pattern searches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum CycleSearch {
    /// The whole unit box, with `Delta` the maximin distance in it.
    Whole,
    /// The local box around the first centre (the best point, or the escape's basin).
    First,
    /// The local box around the second region's centre.
    Second,
}

/// Where cycle `cycle` (counted from the run's initial set) searches. Without
/// `local_region`, always the whole box. With it, cycles alternate between the whole box
/// (even) and the first local region (odd); with `second_region` as well, every second
/// whole-box cycle gives way to the second region, so that the pattern of four is whole,
/// first, second, first. `local_first` shifts the pattern by one cycle.
fn cycle_search(cycle: usize, options: &CorsOptions) -> CycleSearch {
    if options.local_region.is_none() {
        return CycleSearch::Whole;
    }
    let c = cycle + usize::from(options.local_first);
    match (c % 4, options.second_region.is_some()) {
        (1 | 3, _) => CycleSearch::First,
        (2, true) => CycleSearch::Second,
        _ => CycleSearch::Whole,
    }
}

/// The local region of the next step: its half-width (`local_region`, or under
/// [`CorsOptions::adaptive_region`](crate::CorsOptions::adaptive_region) as the step-size
/// rule has made it) and the basin its centre lies in ([`escape_rank`], or the
/// convergences under [`Converged::Escape`]).
fn local_width(state: &CorsState, plan: &Plan) -> LocalWidth {
    let initial = state.options.local_region.unwrap_or(1.0);
    let Some(rule) = &state.options.adaptive_region else {
        return LocalWidth {
            half: initial,
            boxed: initial,
            rank: escape_rank(state, plan),
            converged: 0,
        };
    };
    let mut width = run_width(state, plan, rule, state.evaluations.len());
    if rule.on_converged != Converged::Escape {
        width.rank = escape_rank(state, plan);
    }
    width
}

/// Which basin the local cycles search
/// ([`CorsOptions::local_escape`](crate::CorsOptions::local_escape)): 0 (the best point's)
/// until the run has stalled for `patience` evaluations after its initial set, then 1, 2,
/// ... for every further `patience` evaluations without improvement.
fn escape_rank(state: &CorsState, plan: &Plan) -> usize {
    let Some(patience) = state.options.local_escape else {
        return 0;
    };
    let end = state.evaluations.len();
    let start = plan.run_start.min(end);
    let rule = StallRule {
        min_improvement: SUCCESS_IMPROVEMENT,
        floor: 0.0,
    };
    let stall = rule.stall_length(
        &state.evaluations[start..end],
        plan.cycle_origin.saturating_sub(start),
    );
    stall / patience.max(1)
}

/// The centre of the local cycles for `rank` ([`escape_rank`]): the successes sorted by
/// value (ties by order) are grouped greedily into basins, a point opening a new basin when
/// it lies outside the box of half-width `half` around every earlier basin's first point;
/// the centre is the first point of basin `rank` (cyclically).
fn basin_centre<'a>(pts: &'a [Vec<f64>], vals: &[f64], half: f64, rank: usize) -> &'a [f64] {
    let mut order: Vec<usize> = (0..pts.len()).collect();
    order.sort_by(|&a, &b| vals[a].total_cmp(&vals[b]).then(a.cmp(&b)));
    let mut basins: Vec<usize> = Vec::new();
    for k in order {
        if basins.iter().all(|&j| outside_box(&pts[k], &pts[j], half)) {
            basins.push(k);
        }
    }
    &pts[basins[rank % basins.len()]]
}

/// The centre of the second local region
/// ([`CorsOptions::second_region`](crate::CorsOptions::second_region)): the best of `pts`
/// (lowest value, ties to the earlier) outside the box of half-width `half` around
/// `centre`; `centre` itself when every point lies inside.
fn second_centre<'a>(pts: &'a [Vec<f64>], vals: &[f64], centre: &'a [f64], half: f64) -> &'a [f64] {
    let mut best: Option<usize> = None;
    for (k, p) in pts.iter().enumerate() {
        if outside_box(p, centre, half) && best.is_none_or(|b| vals[k] < vals[b]) {
            best = Some(k);
        }
    }
    best.map_or(centre, |k| &pts[k])
}

/// Whether `p` lies outside the box of half-width `half` around `centre` (farther than
/// `half` in some coordinate).
fn outside_box(p: &[f64], centre: &[f64], half: f64) -> bool {
    p.iter().zip(centre).any(|(a, b)| (a - b).abs() > half)
}

/// The surrogate of a step and the points it searches around (unit box).
struct Fitted {
    surrogate: RbfSurrogate,
    /// The best successful point of the run.
    best: Vec<f64>,
    /// The centre of the local cycles (the best point, or the escape's basin).
    centre: Vec<f64>,
    /// The centre of the second region ([`second_centre`]; `centre` without one).
    second: Vec<f64>,
}

/// The surrogate fitted to `earlier` (the earlier runs' successes it keeps,
/// [`kept_from_earlier`]) and the successes of the current run (near-duplicates merged,
/// lower value kept, values transformed), the best successful point in the unit
/// box, the centre of the local cycles (the best point, or with `escape_rank > 0` the
/// first point of another basin, [`basin_centre`]) and that of the second region
/// ([`second_centre`]); or why none can be fitted.
///
/// # Errors
/// Mapping errors of the parameter space (not expected).
fn fit_surrogate(
    state: &CorsState,
    plan: &Plan,
    earlier: &[(Vec<f64>, f64)],
    escape_rank: usize,
) -> Result<std::result::Result<Fitted, FillReason>> {
    let d = state.space.dim();
    let tol = DUPLICATE_TOL * (d as f64).sqrt();
    // Successes of earlier runs kept in this run's surrogate first ([`kept_from_earlier`]).
    let kept = earlier.len();
    let mut pts: Vec<Vec<f64>> = earlier.iter().map(|(u, _)| u.clone()).collect();
    let mut vals: Vec<f64> = earlier.iter().map(|&(_, v)| v).collect();
    let start = plan.run_start.min(state.evaluations.len());
    for e in &state.evaluations[start..] {
        let Some(v) = e.value else { continue };
        let u = state.space.to_unit(&e.x)?;
        match pts.iter().position(|p| distance(p, &u) <= tol) {
            Some(k) => vals[k] = vals[k].min(v),
            None => {
                pts.push(u);
                vals.push(v);
            }
        }
    }
    let own = pts.len() - kept;
    if own < d + 1 || affine_rank_of_rows(&pts[kept..]) < d + 1 {
        return Ok(Err(FillReason::TooFewSuccesses {
            successes: own,
            needed: d + 1,
        }));
    }
    // The best point of the run's own evaluations.
    let best = (kept..vals.len()).fold(kept, |k, i| if vals[i] < vals[k] { i } else { k });
    let best_x = pts[best].clone();
    let centre = match state.options.local_region {
        Some(half) if escape_rank > 0 => {
            basin_centre(&pts[kept..], &vals[kept..], half, escape_rank).to_vec()
        }
        _ => best_x.clone(),
    };
    let second = match state.options.second_region {
        Some(half) if state.options.local_region.is_some() => {
            second_centre(&pts[kept..], &vals[kept..], &centre, half).to_vec()
        }
        _ => centre.clone(),
    };
    state.options.transform.apply(&mut vals);
    if vals.iter().any(|v| !v.is_finite()) {
        return Ok(Err(FillReason::TransformNotFinite));
    }
    Ok(
        match state.fit_cache.fit(&pts, &vals, state.options.kernel) {
            Ok(surrogate) => Ok(Fitted {
                surrogate,
                best: best_x,
                centre,
                second,
            }),
            Err(e) => Err(FillReason::SurrogateFailed {
                message: e.to_string(),
            }),
        },
    )
}

/// The points to keep away from: the earlier runs' successes the surrogate keeps
/// (`earlier`, first, as in its centres), successes of the current run, pending points and
/// the points already proposed, and failures of every run.
fn blockers(
    state: &CorsState,
    plan: &Plan,
    earlier: &[(Vec<f64>, f64)],
    proposed: &[Suggestion],
) -> Result<Blockers> {
    let mut b = Blockers::new(state.space.dim());
    for (u, _) in earlier {
        b.ok.extend_from_slice(u);
    }
    for (k, e) in state.evaluations.iter().enumerate() {
        if e.is_success() {
            if k >= plan.run_start {
                b.ok.extend(state.space.to_unit(&e.x)?);
            }
        } else {
            b.failed.extend(state.space.to_unit(&e.x)?);
        }
    }
    for p in state.pending.iter().chain(proposed) {
        b.ok.extend(state.space.to_unit(&p.x)?);
    }
    Ok(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cycles search whole, first, second, first with both regions; whole and first
    /// alternate without the second; the whole box only without local cycles; and the
    /// local-first option shifts the pattern by one.
    #[test]
    fn the_cycles_follow_the_pattern_of_the_regions() {
        use CycleSearch::{First, Second, Whole};
        let pattern = |options: &CorsOptions| -> Vec<CycleSearch> {
            (0..8).map(|c| cycle_search(c, options)).collect()
        };
        let both = CorsOptions::default();
        assert_eq!(
            pattern(&both),
            [Whole, First, Second, First, Whole, First, Second, First]
        );
        let one = CorsOptions {
            second_region: None,
            ..CorsOptions::default()
        };
        assert_eq!(
            pattern(&one),
            [Whole, First, Whole, First, Whole, First, Whole, First]
        );
        let shifted = CorsOptions {
            local_first: true,
            ..CorsOptions::default()
        };
        assert_eq!(
            pattern(&shifted),
            [First, Second, First, Whole, First, Second, First, Whole]
        );
        let global = CorsOptions {
            local_region: None,
            ..CorsOptions::default()
        };
        assert!(pattern(&global).iter().all(|&c| c == Whole));
    }

    /// The second region's centre is the best point outside the box around the first
    /// centre, whatever the order of the points; the first centre when there is none.
    #[test]
    fn second_centre_is_the_best_point_outside_the_box() {
        let pts = vec![
            vec![0.10, 0.10],
            vec![0.50, 0.45], // inside the box of half-width 0.5 around the centre
            vec![0.90, 0.20], // outside (first coordinate), value 4
            vec![0.20, 0.95], // outside (second coordinate), value 3
        ];
        let vals = [1.0, 0.5, 4.0, 3.0];
        let centre = [0.3, 0.3];
        assert_eq!(second_centre(&pts, &vals, &centre, 0.5), &pts[3][..]);
        assert_eq!(second_centre(&pts, &vals, &centre, 0.7), &centre[..]);
        // Ties go to the earlier point.
        let tied = [1.0, 0.5, 3.0, 3.0];
        assert_eq!(second_centre(&pts, &tied, &centre, 0.5), &pts[2][..]);
    }

    /// Basins: sorted by value, a point opens a basin when it lies outside the box of
    /// half-width `half` around every earlier basin's best point.
    #[test]
    fn basins_are_ranked_by_their_best_point() {
        let pts = vec![
            vec![0.10, 0.10],
            vec![0.15, 0.12], // in the first basin
            vec![0.90, 0.10],
            vec![0.50, 0.90],
            vec![0.85, 0.20], // in the second basin
        ];
        let vals = [1.0, 2.0, 3.0, 5.0, 2.5];
        let centre = |rank| basin_centre(&pts, &vals, 0.2, rank).to_vec();
        assert_eq!(centre(0), pts[0]);
        // 0.85 is within 0.2 of 0.10? No: |0.85 - 0.10| > 0.2, so it opens basin 2 before
        // 0.90 (value 2.5 < 3.0); 0.90 then lies in its box.
        assert_eq!(centre(1), pts[4]);
        assert_eq!(centre(2), pts[3]);
        assert_eq!(centre(3), pts[0]);
    }
}
