//! The CORS-RBF optimiser: state, ask-and-tell, the closed loop, JSON persistence.

use std::path::Path;

use impactcal_core::ParameterSpace;
use serde::{Deserialize, Serialize};

use crate::design::{affine_rank, find_near_duplicate, symmetric_design};
use crate::error::{CorsError, Result};
use crate::geometry::{distance, mix, stream};
use crate::options::{CorsOptions, InitialDesign, Restart};
use crate::subproblem::{Blockers, Region, StepSettings, cors_step, maximin};
use crate::surrogate::Surrogate;

/// Tag of the saved state format.
const FORMAT: &str = "impactcal-cors/1";

/// Two points of the unit box closer than this (times `sqrt(d)`) are the same design point.
const MATCH_TOL: f64 = 1e-6;

/// Existing evaluations closer than this (times `sqrt(d)`) are refused as near-duplicates;
/// successes that close are merged (the lower value kept) when the surrogate is fitted.
const DUPLICATE_TOL: f64 = 1e-8;

/// How a point came to be evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Origin {
    /// Given by the user (a warm start or an evaluation told with [`Cors::tell_point`]).
    Existing,
    /// A point of the symmetric Latin hypercube design.
    Design,
    /// A space-filling (maximin) point, proposed while no surrogate could be fitted (for
    /// example after failures in the design).
    Fill,
    /// A CORS point: the surrogate's minimiser under the distance constraint.
    Cors,
}

/// One evaluated point.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Evaluation {
    /// The parameters (in the units of the parameter space).
    pub x: Vec<f64>,
    /// The objective value; `None` for a failed evaluation (NaN or infinite result).
    pub value: Option<f64>,
    /// Where the point came from.
    pub origin: Origin,
}

impl Evaluation {
    /// Whether the evaluation succeeded.
    pub fn is_success(&self) -> bool {
        self.value.is_some()
    }
}

/// A point to evaluate, with the id to [`tell`](Cors::tell) its result under.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Suggestion {
    /// Identifier, unique within the study.
    pub id: u64,
    /// The parameters (in the units of the parameter space, inside the bounds).
    pub x: Vec<f64>,
    /// Design, fill or CORS point.
    pub origin: Origin,
    /// For a CORS point: `beta_n` of the cycle.
    pub beta: Option<f64>,
    /// For a CORS or fill point: the maximin distance `Delta_n` in the unit box.
    pub delta: Option<f64>,
    /// For a CORS point: the surrogate's (transformed) prediction at the point.
    pub predicted: Option<f64>,
}

/// Whether the initial set is the user's evaluations or includes the design.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Mode {
    /// The existing evaluations form the initial set.
    Existing,
    /// The symmetric Latin hypercube design is (being) evaluated.
    Design,
}

/// The plan of the current run, fixed at the first suggestion and renewed at each restart.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Plan {
    mode: Mode,
    /// Design points of the current run in the unit box (kept even in existing mode, for
    /// the record).
    design: Vec<Vec<f64>>,
    /// Index in the history of the first point of the `beta` cycle: point `n` uses
    /// `pattern[(n - cycle_origin) mod k]`.
    cycle_origin: usize,
    /// Index in the history of the first evaluation of the current run (0 before any
    /// restart).
    #[serde(default)]
    run_start: usize,
    /// Number of restarts so far.
    #[serde(default)]
    restarts: usize,
}

impl Plan {
    /// Whether the current run stagnates after the first `upto` evaluations: `patience`
    /// consecutive evaluations after its initial set without improving the run's best by
    /// more than `min_improvement * |best|`.
    fn stagnates(
        &self,
        evaluations: &[Evaluation],
        upto: usize,
        rule: &Restart,
        dim: usize,
    ) -> bool {
        let patience = rule.patience_for(dim);
        let mut best: Option<f64> = None;
        let mut since = 0;
        for (k, e) in evaluations
            .iter()
            .enumerate()
            .take(upto)
            .skip(self.run_start)
        {
            let improved = match (e.value, best) {
                (Some(_), None) => true,
                (Some(v), Some(b)) => v < b - rule.min_improvement * b.abs(),
                (None, _) => false,
            };
            if let Some(v) = e.value {
                best = Some(best.map_or(v, |b| b.min(v)));
            }
            if improved {
                since = 0;
            } else if k >= self.cycle_origin {
                since += 1;
            }
        }
        since >= patience
    }
}

/// Why a study stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum StopReason {
    /// The evaluation budget is spent.
    Budget,
    /// The best value reached the target.
    Target,
    /// No improvement within the patience.
    NoImprovement,
}

/// The result of [`Cors::minimize`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    /// The best successful evaluation of the whole study (`None` if all failed).
    pub best: Option<Evaluation>,
    /// Evaluations made by this call.
    pub evaluations: usize,
    /// Why it stopped.
    pub stop: StopReason,
}

/// The CORS-RBF optimiser of Regis & Shoemaker (2005) over a [`ParameterSpace`].
///
/// Works in the unit box of the space. The initial set is a symmetric Latin hypercube of
/// `2 (d + 1)` points, the user's evaluations, or both ([`InitialDesign`]). Every later
/// point minimises a cubic (or thin-plate) RBF surrogate with a linear tail, fitted to all
/// successful evaluations, subject to `|x - x_j| >= beta_n Delta_n` for every evaluated or
/// pending point, `Delta_n` the maximin distance and `beta_n` cycling through the pattern
/// once per evaluation. Failed evaluations stay in the history, out of the surrogate, with
/// a no-go radius around them.
///
/// The state (space, options, history, pending suggestions) is everything: a study saved
/// with [`save`](Self::save) and [`load`](Self::load)ed proposes exactly the points an
/// uninterrupted one would, and [`from_history`](Self::from_history) rebuilds a study from
/// a table of evaluations alone.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "CorsData")]
pub struct Cors {
    format: String,
    space: ParameterSpace,
    options: CorsOptions,
    evaluations: Vec<Evaluation>,
    pending: Vec<Suggestion>,
    next_id: u64,
    plan: Option<Plan>,
}

/// The unchecked serialised form of [`Cors`].
#[derive(Deserialize)]
struct CorsData {
    format: String,
    space: ParameterSpace,
    options: CorsOptions,
    evaluations: Vec<Evaluation>,
    pending: Vec<Suggestion>,
    next_id: u64,
    plan: Option<Plan>,
}

impl TryFrom<CorsData> for Cors {
    type Error = CorsError;

    fn try_from(d: CorsData) -> Result<Self> {
        let state_err = |message: String| CorsError::State {
            source_name: "state".into(),
            message,
        };
        if d.format != FORMAT {
            return Err(state_err(format!(
                "format `{}` is not `{FORMAT}`",
                d.format
            )));
        }
        let dim = d.space.dim();
        d.options.validate(dim)?;
        for (i, e) in d.evaluations.iter().enumerate() {
            if e.x.len() != dim || e.x.iter().any(|v| !v.is_finite()) {
                return Err(state_err(format!(
                    "evaluation {i} has not {dim} finite coordinates"
                )));
            }
            if e.value.is_some_and(|v| !v.is_finite()) {
                return Err(state_err(format!("evaluation {i} has a non-finite value")));
            }
        }
        for p in &d.pending {
            if p.x.len() != dim || p.id >= d.next_id {
                return Err(state_err(format!(
                    "pending suggestion {} is malformed",
                    p.id
                )));
            }
        }
        if let Some(plan) = &d.plan
            && plan.design.iter().any(|u| u.len() != dim)
        {
            return Err(state_err("a design point has the wrong dimension".into()));
        }
        Ok(Cors {
            format: d.format,
            space: d.space,
            options: d.options,
            evaluations: d.evaluations,
            pending: d.pending,
            next_id: d.next_id,
            plan: d.plan,
        })
    }
}

impl Cors {
    /// A new study over `space`.
    ///
    /// # Errors
    /// [`CorsError::InvalidOption`] for options that [`CorsOptions::validate`] refuses.
    pub fn new(space: ParameterSpace, options: CorsOptions) -> Result<Self> {
        options.validate(space.dim())?;
        Ok(Cors {
            format: FORMAT.into(),
            space,
            options,
            evaluations: Vec::new(),
            pending: Vec::new(),
            next_id: 0,
            plan: None,
        })
    }

    /// The parameter space.
    pub fn space(&self) -> &ParameterSpace {
        &self.space
    }

    /// The options.
    pub fn options(&self) -> &CorsOptions {
        &self.options
    }

    /// Every evaluation told so far, in order.
    pub fn evaluations(&self) -> &[Evaluation] {
        &self.evaluations
    }

    /// Suggestions not yet told.
    pub fn pending(&self) -> &[Suggestion] {
        &self.pending
    }

    /// The mode fixed at the first suggestion (`None` before it).
    pub fn mode(&self) -> Option<Mode> {
        self.plan.as_ref().map(|p| p.mode)
    }

    /// The best successful evaluation (lowest value; the earliest on ties).
    pub fn best(&self) -> Option<&Evaluation> {
        let mut best: Option<&Evaluation> = None;
        for e in &self.evaluations {
            if let Some(v) = e.value
                && best.and_then(|b| b.value).is_none_or(|b| v < b)
            {
                best = Some(e);
            }
        }
        best
    }

    /// The design points of this study's seed, in the parameter space (the design is
    /// generated the same way whether or not it is used).
    ///
    /// # Errors
    /// Those of the sampler (not expected for a validated study).
    pub fn design_points(&self) -> Result<Vec<Vec<f64>>> {
        let design = match &self.plan {
            Some(p) => p.design.clone(),
            None => self.make_design()?,
        };
        design.iter().map(|u| self.unit_to_space(u)).collect()
    }

    fn make_design(&self) -> Result<Vec<Vec<f64>>> {
        self.make_run_design(0)
    }

    /// The design of run `run` (0 the initial one, `r` the one of the `r`-th restart).
    fn make_run_design(&self, run: usize) -> Result<Vec<Vec<f64>>> {
        let d = self.space.dim();
        let mut seed = mix(self.options.seed ^ 0xDE51_6E00_0000_0001);
        if run > 0 {
            seed = mix(seed ^ mix(run as u64 ^ 0x4E57_2A11_0000_0000));
        }
        symmetric_design(self.options.design_size_for(d), d, seed)
    }

    /// Starts a new run at history index `at`: a new design, a new cycle after it.
    fn restart_plan(&self, plan: &mut Plan, at: usize) -> Result<()> {
        plan.restarts += 1;
        plan.design = self.make_run_design(plan.restarts)?;
        plan.mode = Mode::Design;
        plan.run_start = at;
        plan.cycle_origin = at + plan.design.len();
        Ok(())
    }

    /// Whether the restart rule fires for the next suggestion, given the first `upto`
    /// evaluations.
    fn should_restart(&self, plan: &Plan, upto: usize) -> bool {
        self.options
            .restart
            .as_ref()
            .is_some_and(|rule| plan.stagnates(&self.evaluations, upto, rule, self.space.dim()))
    }

    /// Number of restarts so far.
    pub fn restarts(&self) -> usize {
        self.plan.as_ref().map_or(0, |p| p.restarts)
    }

    /// Index in [`evaluations`](Self::evaluations) of the first evaluation of the current
    /// run (0 before any restart).
    pub fn run_start(&self) -> usize {
        self.plan.as_ref().map_or(0, |p| p.run_start)
    }

    fn unit_to_space(&self, u: &[f64]) -> Result<Vec<f64>> {
        let mut x = self.space.from_unit(u)?;
        for (v, p) in x.iter_mut().zip(self.space.parameters()) {
            *v = v.clamp(p.lower, p.upper);
        }
        Ok(x)
    }

    /// Checks a point given by the user: length, finite, inside the bounds.
    fn check_point(&self, what: &str, x: &[f64]) -> Result<()> {
        if x.len() != self.space.dim() {
            return Err(CorsError::DimensionMismatch {
                what: format!("{what}: number of parameters"),
                expected: self.space.dim(),
                found: x.len(),
            });
        }
        for (v, p) in x.iter().zip(self.space.parameters()) {
            if !v.is_finite() {
                return Err(CorsError::NonFinitePoint {
                    what: what.into(),
                    parameter: p.name.clone(),
                    value: *v,
                });
            }
            let slack = 1e-12 * p.width();
            if *v < p.lower - slack || *v > p.upper + slack {
                return Err(CorsError::OutOfBounds {
                    what: what.into(),
                    parameter: p.name.clone(),
                    value: *v,
                    lower: p.lower,
                    upper: p.upper,
                });
            }
        }
        Ok(())
    }

    /// A result value: finite and in the transform's domain, or a failure (`None`) for NaN
    /// and infinities.
    fn check_value(&self, value: f64) -> Result<Option<f64>> {
        if value.is_finite() {
            self.options.transform.check(value)?;
            Ok(Some(value))
        } else {
            Ok(None)
        }
    }

    /// Adds existing evaluations (the "50 runs you already have"): `points[k]` has one
    /// coordinate per parameter, `values[k]` is its objective (NaN for a failed run).
    ///
    /// Call before the first [`suggest`](Self::suggest); with [`InitialDesign::Auto`] they
    /// replace the design when they hold `d + 1` affinely independent successes.
    ///
    /// # Errors
    /// [`CorsError::DimensionMismatch`] for lengths that differ or a point of the wrong
    /// length; [`CorsError::NonFinitePoint`] and [`CorsError::OutOfBounds`] for a bad
    /// point; [`CorsError::NearDuplicate`] for two points (among these and earlier ones)
    /// closer than `1e-8 sqrt(d)` in the unit box; [`CorsError::TransformDomain`] for a
    /// value the transform cannot take. On error nothing is added.
    pub fn warm_start(&mut self, points: &[Vec<f64>], values: &[f64]) -> Result<()> {
        if points.len() != values.len() {
            return Err(CorsError::DimensionMismatch {
                what: "existing evaluations: number of values (one per point)".into(),
                expected: points.len(),
                found: values.len(),
            });
        }
        let mut new = Vec::with_capacity(points.len());
        for (k, (x, &v)) in points.iter().zip(values).enumerate() {
            self.check_point(&format!("existing evaluation {k}"), x)?;
            new.push(Evaluation {
                x: x.clone(),
                value: self.check_value(v)?,
                origin: Origin::Existing,
            });
        }
        let mut units = self.units(self.evaluations.iter().map(|e| e.x.as_slice()))?;
        units.extend(self.units(new.iter().map(|e| e.x.as_slice()))?);
        let tol = DUPLICATE_TOL * (self.space.dim() as f64).sqrt();
        if let Some((first, second, distance)) = find_near_duplicate(&units, tol) {
            return Err(CorsError::NearDuplicate {
                first,
                second,
                distance,
                tolerance: tol,
            });
        }
        self.evaluations.extend(new);
        Ok(())
    }

    fn units<'a>(&self, xs: impl Iterator<Item = &'a [f64]>) -> Result<Vec<Vec<f64>>> {
        xs.map(|x| Ok(self.space.to_unit(x)?)).collect()
    }

    /// Records the result of a pending suggestion: `value` is the objective, NaN (or an
    /// infinity) for a failed evaluation, which is kept in the history, out of the
    /// surrogate, with a no-go radius around it.
    ///
    /// # Errors
    /// [`CorsError::UnknownSuggestion`] when `id` is not pending;
    /// [`CorsError::TransformDomain`] for a value the transform cannot take. On error the
    /// state is unchanged.
    pub fn tell(&mut self, id: u64, value: f64) -> Result<()> {
        let k = self
            .pending
            .iter()
            .position(|p| p.id == id)
            .ok_or(CorsError::UnknownSuggestion(id))?;
        let value = self.check_value(value)?;
        let p = self.pending.remove(k);
        self.evaluations.push(Evaluation {
            x: p.x,
            value,
            origin: p.origin,
        });
        Ok(())
    }

    /// Records an evaluation at a point that was not suggested (origin
    /// [`Origin::Existing`]).
    ///
    /// # Errors
    /// As [`warm_start`](Self::warm_start) for one point, except that a near-duplicate is
    /// accepted (the surrogate keeps the lower of two coinciding values).
    pub fn tell_point(&mut self, x: &[f64], value: f64) -> Result<()> {
        self.check_point("told point", x)?;
        let value = self.check_value(value)?;
        self.evaluations.push(Evaluation {
            x: x.to_vec(),
            value,
            origin: Origin::Existing,
        });
        Ok(())
    }

    /// Rebuilds a study from a history alone, as a stateless driver (`impactcal optimize
    /// suggest`) does: rows `points[k]` with `values[k]` (NaN for a failed or missing
    /// result), in the order they were evaluated.
    ///
    /// Rows that coincide (within `1e-6 sqrt(d)` in the unit box) with this seed's design
    /// points are recognised as the design, which fixes the mode and the start of the
    /// `beta` cycle right after the design. Without design rows the history is the initial
    /// set (under [`InitialDesign::Auto`], when it spans) and `initial_rows` says how many
    /// of its first rows were the pre-existing runs, which places the start of the cycle
    /// (default 0: the cycle phase is the row count). With the same `initial_rows`, a study
    /// driven by suggest-run-append suggests exactly what the library's loop suggests.
    ///
    /// # Errors
    /// As [`tell_point`](Self::tell_point) for each row (naming it), and
    /// [`CorsError::InsufficientInitialSet`] under [`InitialDesign::Existing`] when the
    /// rows do not span.
    pub fn from_history(
        space: ParameterSpace,
        options: CorsOptions,
        points: &[Vec<f64>],
        values: &[f64],
        initial_rows: Option<usize>,
    ) -> Result<Self> {
        let mut cors = Cors::new(space, options)?;
        if points.len() != values.len() {
            return Err(CorsError::DimensionMismatch {
                what: "history: number of values (one per point)".into(),
                expected: points.len(),
                found: values.len(),
            });
        }
        for (k, (x, &v)) in points.iter().zip(values).enumerate() {
            cors.check_point(&format!("history row {}", k + 1), x)?;
            let value = cors.check_value(v)?;
            cors.evaluations.push(Evaluation {
                x: x.clone(),
                value,
                origin: Origin::Existing,
            });
        }
        let design = cors.make_design()?;
        let units = cors.units(cors.evaluations.iter().map(|e| e.x.as_slice()))?;
        let tol = MATCH_TOL * (cors.space.dim() as f64).sqrt();
        let mut used = vec![false; design.len()];
        let mut first_design_row = None;
        for (k, u) in units.iter().enumerate() {
            if let Some(j) = (0..design.len()).find(|&j| !used[j] && distance(u, &design[j]) <= tol)
            {
                used[j] = true;
                cors.evaluations[k].origin = Origin::Design;
                first_design_row.get_or_insert(k);
            }
        }
        let n = points.len();
        let n0 = design.len();
        let initial = initial_rows.unwrap_or(0).min(n);
        let spans = cors.successes_span()?;
        let (mode, cycle_origin) = match (cors.options.initial, first_design_row) {
            (InitialDesign::Existing, _) => {
                cors.require_span()?;
                (Mode::Existing, initial)
            }
            (_, Some(first)) => (Mode::Design, first + n0),
            (InitialDesign::Design, None) => (Mode::Design, n + n0),
            (InitialDesign::Auto, None) if spans => (Mode::Existing, initial),
            (InitialDesign::Auto, None) => (Mode::Design, n + n0),
        };
        for (k, e) in cors.evaluations.iter_mut().enumerate() {
            if k >= cycle_origin && e.origin == Origin::Existing {
                e.origin = Origin::Cors;
            }
        }
        let mut plan = Plan {
            mode,
            design,
            cycle_origin,
            run_start: 0,
            restarts: 0,
        };
        // Replay the restart rule as the library's loop applied it before each suggestion.
        let mut k = plan.cycle_origin;
        while k < n {
            if cors.should_restart(&plan, k) {
                cors.restart_plan(&mut plan, k)?;
                let mut used = vec![false; plan.design.len()];
                let end = n.min(k + plan.design.len());
                for (u, e) in units[k..end].iter().zip(&mut cors.evaluations[k..end]) {
                    if let Some(j) = (0..plan.design.len())
                        .find(|&j| !used[j] && distance(u, &plan.design[j]) <= tol)
                    {
                        used[j] = true;
                        e.origin = Origin::Design;
                    }
                }
                k = plan.cycle_origin;
            } else {
                k += 1;
            }
        }
        cors.plan = Some(plan);
        Ok(cors)
    }

    fn success_units(&self) -> Result<Vec<Vec<f64>>> {
        self.units(
            self.evaluations
                .iter()
                .filter(|e| e.is_success())
                .map(|e| e.x.as_slice()),
        )
    }

    fn successes_span(&self) -> Result<bool> {
        Ok(affine_rank(&self.success_units()?) == self.space.dim() + 1)
    }

    fn require_span(&self) -> Result<()> {
        let units = self.success_units()?;
        let rank = affine_rank(&units);
        let d = self.space.dim();
        if rank == d + 1 {
            Ok(())
        } else {
            Err(CorsError::InsufficientInitialSet {
                successes: units.len(),
                rank_minus_one: rank.saturating_sub(1),
                dim: d,
                needed: d + 1,
            })
        }
    }

    /// Fixes the plan at the first suggestion.
    fn ensure_plan(&mut self) -> Result<()> {
        if self.plan.is_some() {
            return Ok(());
        }
        let design = self.make_design()?;
        let spans = self.successes_span()?;
        let mode = match self.options.initial {
            InitialDesign::Design => Mode::Design,
            InitialDesign::Existing => {
                self.require_span()?;
                Mode::Existing
            }
            InitialDesign::Auto if spans => Mode::Existing,
            InitialDesign::Auto => Mode::Design,
        };
        let n = self.evaluations.len() + self.pending.len();
        let cycle_origin = match mode {
            Mode::Existing => n,
            Mode::Design => n + design.len(),
        };
        self.plan = Some(Plan {
            mode,
            design,
            cycle_origin,
            run_start: 0,
            restarts: 0,
        });
        Ok(())
    }

    /// The surrogate fitted to the successes (near-duplicates merged, lower value kept,
    /// values transformed) and the best successful point, or `None` when the successes do
    /// not support it.
    fn fit_surrogate(&self) -> Result<Option<(Surrogate, Vec<f64>)>> {
        let d = self.space.dim();
        let tol = DUPLICATE_TOL * (d as f64).sqrt();
        let mut pts: Vec<Vec<f64>> = Vec::new();
        let mut vals: Vec<f64> = Vec::new();
        for e in &self.evaluations[self.run_start()..] {
            let Some(v) = e.value else { continue };
            let u = self.space.to_unit(&e.x)?;
            match pts.iter().position(|p| distance(p, &u) <= tol) {
                Some(k) => vals[k] = vals[k].min(v),
                None => {
                    pts.push(u);
                    vals.push(v);
                }
            }
        }
        if pts.len() < d + 1 || affine_rank(&pts) < d + 1 {
            return Ok(None);
        }
        let best = vals
            .iter()
            .enumerate()
            .fold(0, |k, (i, v)| if *v < vals[k] { i } else { k });
        let best_x = pts[best].clone();
        self.options.transform.apply(&mut vals);
        if vals.iter().any(|v| !v.is_finite()) {
            return Ok(None);
        }
        Ok(Surrogate::fit(&pts, &vals, self.options.kernel)
            .ok()
            .map(|s| (s, best_x)))
    }

    /// The points to keep away from: successes of the current run and pending points, and
    /// failures of every run.
    fn blockers(&self) -> Result<Blockers> {
        let mut b = Blockers::new(self.space.dim());
        let run_start = self.run_start();
        for (k, e) in self.evaluations.iter().enumerate() {
            if e.is_success() {
                if k >= run_start {
                    b.ok.extend(self.space.to_unit(&e.x)?);
                }
            } else {
                b.failed.extend(self.space.to_unit(&e.x)?);
            }
        }
        for p in &self.pending {
            b.ok.extend(self.space.to_unit(&p.x)?);
        }
        Ok(b)
    }

    fn push_pending(&mut self, s: Suggestion) -> Suggestion {
        self.next_id += 1;
        self.pending.push(s.clone());
        s
    }

    /// Suggests `q` distinct points to evaluate next (they become pending until told).
    ///
    /// Design points not yet evaluated or pending come first. Then each CORS point
    /// minimises the surrogate (fitted once to the successes) subject to the distance
    /// constraint with `beta` of its own place in the cycle, keeping away from evaluated,
    /// pending and already chosen points, so a batch holds `q` distinct points. While the
    /// successes cannot support a surrogate, maximin points fill in.
    ///
    /// # Errors
    /// [`CorsError::InsufficientInitialSet`] under [`InitialDesign::Existing`] when the
    /// existing evaluations do not span; mapping errors of the parameter space (not
    /// expected).
    pub fn suggest(&mut self, q: usize) -> Result<Vec<Suggestion>> {
        if q == 0 {
            return Ok(Vec::new());
        }
        self.ensure_plan()?;
        let Some(mut plan) = self.plan.clone() else {
            return Ok(Vec::new());
        };
        let index = self.evaluations.len() + self.pending.len();
        if index >= plan.cycle_origin && self.should_restart(&plan, self.evaluations.len()) {
            self.restart_plan(&mut plan, index)?;
            self.plan = Some(plan.clone());
        }
        let d = self.space.dim();
        let mut out = Vec::with_capacity(q);
        if plan.mode == Mode::Design {
            let tol = MATCH_TOL * (d as f64).sqrt();
            let mut seen = self.units(
                self.evaluations[plan.run_start..]
                    .iter()
                    .map(|e| e.x.as_slice()),
            )?;
            seen.extend(self.units(self.pending.iter().map(|p| p.x.as_slice()))?);
            for u in &plan.design {
                if out.len() == q {
                    break;
                }
                if seen.iter().any(|s| distance(s, u) <= tol) {
                    continue;
                }
                let s = Suggestion {
                    id: self.next_id,
                    x: self.unit_to_space(u)?,
                    origin: Origin::Design,
                    beta: None,
                    delta: None,
                    predicted: None,
                };
                out.push(self.push_pending(s));
            }
        }
        if out.len() == q {
            return Ok(out);
        }
        let fitted = self.fit_surrogate()?;
        let root_d = (d as f64).sqrt();
        while out.len() < q {
            let index = self.evaluations.len() + self.pending.len();
            let mut rng = stream(self.options.seed, index);
            let blockers = self.blockers()?;
            let n_cand = self.options.candidates_per_dim * d;
            let s = match &fitted {
                Some((surrogate, best)) => {
                    let k = self.options.pattern.len();
                    let beta = self.options.pattern[index.saturating_sub(plan.cycle_origin) % k];
                    let settings = StepSettings {
                        beta,
                        floor: self.options.min_distance * root_d,
                        failure_radius: self.options.failure_radius * root_d,
                        candidates: n_cand,
                        local_candidates: self.options.local_candidates_per_dim * d,
                        polish_starts: self.options.polish_starts,
                    };
                    let cycle = index.saturating_sub(plan.cycle_origin) / k;
                    let region = match self.options.local_region {
                        Some(half) if cycle % 2 == 1 => Region::around(best, half),
                        _ => Region::unit(d),
                    };
                    let c = cors_step(surrogate, best, &blockers, &settings, &region, &mut rng);
                    Suggestion {
                        id: self.next_id,
                        x: self.unit_to_space(&c.x)?,
                        origin: Origin::Cors,
                        beta: Some(beta),
                        delta: Some(c.delta),
                        predicted: Some(c.predicted),
                    }
                }
                None => {
                    let (u, delta) = if blockers.is_empty() {
                        (vec![0.5; d], f64::INFINITY)
                    } else {
                        maximin(&blockers, n_cand, &mut rng)
                    };
                    Suggestion {
                        id: self.next_id,
                        x: self.unit_to_space(&u)?,
                        origin: Origin::Fill,
                        beta: None,
                        delta: delta.is_finite().then_some(delta),
                        predicted: None,
                    }
                }
            };
            out.push(self.push_pending(s));
        }
        Ok(out)
    }

    /// Forgets a pending suggestion without recording a result (for example a simulation
    /// that was never started).
    ///
    /// # Errors
    /// [`CorsError::UnknownSuggestion`] when `id` is not pending.
    pub fn cancel(&mut self, id: u64) -> Result<()> {
        let k = self
            .pending
            .iter()
            .position(|p| p.id == id)
            .ok_or(CorsError::UnknownSuggestion(id))?;
        self.pending.remove(k);
        Ok(())
    }

    /// Why the study should stop by the target or patience rules of
    /// [`Stopping`](crate::Stopping), if it should.
    pub fn stop_reason(&self) -> Option<StopReason> {
        let stopping = &self.options.stopping;
        let best = self.best().and_then(|e| e.value);
        if let (Some(t), Some(b)) = (stopping.target, best)
            && b <= t
        {
            return Some(StopReason::Target);
        }
        if let Some(patience) = stopping.patience {
            let mut best: Option<f64> = None;
            let mut last = None;
            for (k, e) in self.evaluations.iter().enumerate() {
                if let Some(v) = e.value {
                    let improves = match best {
                        None => true,
                        Some(b) => v < b - stopping.min_improvement * b.abs().max(1e-12),
                    };
                    if improves {
                        last = Some(k);
                    }
                    best = Some(best.map_or(v, |b: f64| b.min(v)));
                }
            }
            let since = match last {
                Some(k) => self.evaluations.len() - 1 - k,
                None => self.evaluations.len(),
            };
            if since >= patience {
                return Some(StopReason::NoImprovement);
            }
        }
        None
    }

    /// The closed loop: suggests one point at a time, evaluates `objective` there (NaN or
    /// an infinity marks a failed evaluation) and tells the result, until `budget`
    /// evaluations have been made by this call or a stopping rule fires.
    ///
    /// # Errors
    /// As [`suggest`](Self::suggest) and [`tell`](Self::tell).
    pub fn minimize(
        &mut self,
        mut objective: impl FnMut(&[f64]) -> f64,
        budget: usize,
    ) -> Result<Outcome> {
        let mut used = 0;
        let stop = loop {
            if let Some(r) = self.stop_reason() {
                break r;
            }
            if used >= budget {
                break StopReason::Budget;
            }
            let Some(s) = self.suggest(1)?.pop() else {
                break StopReason::Budget;
            };
            let v = objective(&s.x);
            self.tell(s.id, v)?;
            used += 1;
        };
        Ok(Outcome {
            best: self.best().cloned(),
            evaluations: used,
            stop,
        })
    }

    /// The whole state as JSON.
    ///
    /// # Errors
    /// [`CorsError::State`] if encoding fails (not expected).
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string_pretty(self).map_err(|e| CorsError::State {
            source_name: "state".into(),
            message: e.to_string(),
        })
    }

    /// A study from the JSON of [`to_json`](Self::to_json); `source_name` names it in
    /// errors.
    ///
    /// # Errors
    /// [`CorsError::State`] for text that is not a valid state (wrong format tag, options
    /// out of range, points of the wrong dimension...).
    pub fn from_json(text: &str, source_name: &str) -> Result<Self> {
        serde_json::from_str(text).map_err(|e| CorsError::State {
            source_name: source_name.into(),
            message: e.to_string(),
        })
    }

    /// Writes the state to `path` atomically (a temporary file renamed over it), so a crash
    /// while saving leaves the previous state intact.
    ///
    /// # Errors
    /// [`CorsError::Core`] with an I/O error when the file cannot be written.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        let io = |source| {
            CorsError::Core(impactcal_core::CoreError::Io {
                path: path.display().to_string(),
                source,
            })
        };
        let mut tmp = path.as_os_str().to_owned();
        tmp.push(".tmp");
        std::fs::write(&tmp, self.to_json()? + "\n").map_err(io)?;
        std::fs::rename(&tmp, path).map_err(io)
    }

    /// Reads a state written by [`save`](Self::save).
    ///
    /// # Errors
    /// [`CorsError::Core`] with an I/O error when unreadable; otherwise as
    /// [`from_json`](Self::from_json).
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| {
            CorsError::Core(impactcal_core::CoreError::Io {
                path: path.display().to_string(),
                source,
            })
        })?;
        Self::from_json(&text, &path.display().to_string())
    }
}
