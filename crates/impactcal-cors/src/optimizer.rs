//! The CORS-RBF driver: ask and tell, the closed loop, history replay and persistence, over
//! the state of [`crate::state`] and the pure step (the private `step` module).

use std::path::Path;

use faer::MatRef;
use impactcal_core::points::{from_rows, to_rows};
use impactcal_core::{CoreError, ParamGuard, ParameterSpace};
use serde::{Deserialize, Serialize};

use crate::answer::SurrogateAnswer;
use crate::design::find_near_duplicate;
use crate::error::{CorsError, Result};
use crate::geometry::distance;
use crate::options::{CorsOptions, InitialDesign, ValidCorsOptions};
use crate::stall::StallRule;
use crate::state::{
    CorsState, DUPLICATE_TOL, Evaluation, FillReason, MATCH_TOL, Mode, Origin, Plan, Suggestion,
};
use crate::step::{advance_plan, propose};

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
    /// For every point of this call that had to be a fill point because the surrogate
    /// could not be fitted ([`FillReason::is_failure`]), the reason (empty when every step
    /// could use the surrogate).
    #[serde(default)]
    pub failed_fits: Vec<FillReason>,
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
/// The study is split as argmin splits a solver: the serialisable [`CorsState`] is
/// everything (space, options, history, pending suggestions, the plan of the run), the step
/// is a pure function of it, and this driver asks, tells, loops and saves. A study saved
/// with [`save`](Self::save) and [`load`](Self::load)ed proposes exactly the points an
/// uninterrupted one would, and [`from_history`](Self::from_history) rebuilds a study from
/// a table of evaluations alone.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Cors {
    state: CorsState,
}

impl Cors {
    /// A new study over `space`, with [`CorsOptions`] (checked here) or
    /// [`ValidCorsOptions`].
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] (as a [`CorsError`]) for options the checks refuse,
    /// including a design smaller than `dim + 1`.
    pub fn new(
        space: ParameterSpace,
        options: impl ParamGuard<Checked = ValidCorsOptions>,
    ) -> Result<Self> {
        Ok(Cors {
            state: CorsState::new(space, options.check()?)?,
        })
    }

    /// A study resuming from a state.
    pub fn from_state(state: CorsState) -> Self {
        Cors { state }
    }

    /// The state.
    pub fn state(&self) -> &CorsState {
        &self.state
    }

    /// The state, by value.
    pub fn into_state(self) -> CorsState {
        self.state
    }

    /// The parameter space.
    pub fn space(&self) -> &ParameterSpace {
        self.state.space()
    }

    /// The options.
    pub fn options(&self) -> &CorsOptions {
        self.state.options()
    }

    /// Every evaluation told so far, in order.
    pub fn evaluations(&self) -> &[Evaluation] {
        self.state.evaluations()
    }

    /// Suggestions not yet told.
    pub fn pending(&self) -> &[Suggestion] {
        self.state.pending()
    }

    /// The mode fixed at the first suggestion (`None` before it).
    pub fn mode(&self) -> Option<Mode> {
        self.state.mode()
    }

    /// The best successful evaluation (lowest value; the earliest on ties).
    pub fn best(&self) -> Option<&Evaluation> {
        self.state.best()
    }

    /// The answer under a noisy objective: the evaluated point where a smoothed RBF of every
    /// successful evaluation is lowest (see [`SurrogateAnswer`] and the module
    /// [`crate::answer`]), rather than the luckiest sample [`best`](Self::best). Without
    /// noise the chosen smoothing is (near) zero and both agree. `None` while the successes
    /// hold fewer than `d + 2` distinct points or do not span the space. Costs about 30 RBF
    /// fits of the whole history; call it once, at the end.
    ///
    /// # Errors
    /// Mapping errors of the parameter space (not expected).
    pub fn surrogate_answer(&self) -> Result<Option<SurrogateAnswer>> {
        crate::answer::surrogate_answer(&self.state)
    }

    /// The design points of this study's seed, one per row, in the parameter space (the
    /// design is generated the same way whether or not it is used).
    ///
    /// # Errors
    /// Those of the sampler (not expected for a valid study).
    pub fn design_points(&self) -> Result<faer::Mat<f64>> {
        self.state.design_points()
    }

    /// Number of restarts so far.
    pub fn restarts(&self) -> usize {
        self.state.restarts()
    }

    /// Index in [`evaluations`](Self::evaluations) of the first evaluation of the current
    /// run (0 before any restart).
    pub fn run_start(&self) -> usize {
        self.state.run_start()
    }

    /// Adds existing evaluations (the "50 runs you already have"): `points` is `n x d`, one
    /// point per row, `values[k]` the objective of row `k` (NaN for a failed run).
    ///
    /// Call before the first [`suggest`](Self::suggest); with [`InitialDesign::Auto`] they
    /// replace the design when they hold `d + 1` affinely independent successes.
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`] for a number of values that differs from the number
    /// of rows or rows of the wrong length; [`CoreError::NonFinite`] and
    /// [`CorsError::OutOfBounds`] for a bad point; [`CorsError::NearDuplicate`] for two
    /// points (among these and earlier ones) closer than `1e-8 sqrt(d)` in the unit box;
    /// [`CorsError::TransformDomain`] for a value the transform cannot take. On error
    /// nothing is added.
    pub fn warm_start(&mut self, points: MatRef<'_, f64>, values: &[f64]) -> Result<()> {
        self.warm_start_rows(&to_rows(points), values)
    }

    /// [`warm_start`](Self::warm_start) with the points as rows.
    ///
    /// # Errors
    /// As [`warm_start`](Self::warm_start).
    pub fn warm_start_rows(&mut self, points: &[Vec<f64>], values: &[f64]) -> Result<()> {
        one_value_per_point("existing evaluations", points.len(), values.len())?;
        let state = &self.state;
        let mut new = Vec::with_capacity(points.len());
        for (k, (x, &v)) in points.iter().zip(values).enumerate() {
            state.check_point(&format!("existing evaluation {k}"), x)?;
            new.push(Evaluation {
                x: x.clone(),
                value: state.check_value(v)?,
                origin: Origin::Existing,
            });
        }
        let mut units = state.units(state.evaluations.iter().map(|e| e.x.as_slice()))?;
        units.extend(state.units(new.iter().map(|e| e.x.as_slice()))?);
        let tol = DUPLICATE_TOL * (state.space.dim() as f64).sqrt();
        if let Some((first, second, distance)) = find_near_duplicate(&units, tol) {
            return Err(CorsError::NearDuplicate {
                first,
                second,
                distance,
                tolerance: tol,
            });
        }
        self.state.evaluations.extend(new);
        Ok(())
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
            .state
            .pending
            .iter()
            .position(|p| p.id == id)
            .ok_or(CorsError::UnknownSuggestion(id))?;
        let value = self.state.check_value(value)?;
        let p = self.state.pending.remove(k);
        self.state.evaluations.push(Evaluation {
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
        self.state.check_point("told point", x)?;
        let value = self.state.check_value(value)?;
        self.state.evaluations.push(Evaluation {
            x: x.to_vec(),
            value,
            origin: Origin::Existing,
        });
        Ok(())
    }

    /// Rebuilds a study from a history alone, as a stateless driver (`impactcal optimize
    /// suggest`) does: `points` (`n x d`, one evaluation per row, in the order they were
    /// evaluated) with `values[k]` the objective of row `k` (NaN for a failed or missing
    /// result).
    ///
    /// Rows that coincide (within `1e-6 sqrt(d)` in the unit box) with this seed's design
    /// points are recognised as the design, which fixes the mode and the start of the
    /// `beta` cycle right after the design. Without design rows the history is the initial
    /// set (under [`InitialDesign::Auto`], when it spans) and `initial_rows` says how many
    /// of its first rows were the pre-existing runs, which places the start of the cycle
    /// (default 0: the cycle phase is the row count). Restarts are found by the restart
    /// decision the step itself makes, taken at every row. With the same `initial_rows`, a
    /// study driven by suggest-run-append suggests exactly what the library's loop
    /// suggests.
    ///
    /// # Errors
    /// As [`tell_point`](Self::tell_point) for each row (naming it),
    /// [`CoreError::DimensionMismatch`] when the number of values differs from the number of
    /// rows, and [`CorsError::InsufficientInitialSet`] under [`InitialDesign::Existing`]
    /// when the rows do not span.
    pub fn from_history(
        space: ParameterSpace,
        options: impl ParamGuard<Checked = ValidCorsOptions>,
        points: MatRef<'_, f64>,
        values: &[f64],
        initial_rows: Option<usize>,
    ) -> Result<Self> {
        let mut cors = Cors::new(space, options)?;
        one_value_per_point("history", points.nrows(), values.len())?;
        let state = &mut cors.state;
        for (k, (x, &v)) in to_rows(points).into_iter().zip(values).enumerate() {
            state.check_point(&format!("history row {}", k + 1), &x)?;
            let value = state.check_value(v)?;
            state.evaluations.push(Evaluation {
                x,
                value,
                origin: Origin::Existing,
            });
        }
        let design = state.run_design(0)?;
        let units = state.units(state.evaluations.iter().map(|e| e.x.as_slice()))?;
        let tol = MATCH_TOL * (state.space.dim() as f64).sqrt();
        let mut used = vec![false; design.len()];
        let mut first_design_row = None;
        for (k, u) in units.iter().enumerate() {
            if let Some(j) = (0..design.len()).find(|&j| !used[j] && distance(u, &design[j]) <= tol)
            {
                used[j] = true;
                state.evaluations[k].origin = Origin::Design;
                first_design_row.get_or_insert(k);
            }
        }
        let n = points.nrows();
        let n0 = design.len();
        let initial = initial_rows.unwrap_or(0).min(n);
        let spans = state.successes_span()?;
        let (mode, cycle_origin) = match (state.options.initial, first_design_row) {
            (InitialDesign::Existing, _) => {
                state.require_span()?;
                (Mode::Existing, initial)
            }
            (_, Some(first)) => (Mode::Design, first + n0),
            (InitialDesign::Design, None) => (Mode::Design, n + n0),
            (InitialDesign::Auto, None) if spans => (Mode::Existing, initial),
            (InitialDesign::Auto, None) => (Mode::Design, n + n0),
        };
        for (k, e) in state.evaluations.iter_mut().enumerate() {
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
            excluded: Vec::new(),
        };
        // The restart decision the step makes before each suggestion, at every row.
        let mut k = plan.cycle_origin;
        while k < n {
            if advance_plan(state, &mut plan, k, k)? {
                let mut used = vec![false; plan.design.len()];
                let end = n.min(k + plan.design.len());
                for (u, e) in units[k..end].iter().zip(&mut state.evaluations[k..end]) {
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
        state.plan = Some(plan);
        Ok(cors)
    }

    /// [`from_history`](Self::from_history) with the points as rows.
    ///
    /// # Errors
    /// As [`from_history`](Self::from_history), and [`CoreError::DimensionMismatch`] for
    /// rows of unequal length.
    pub fn from_history_rows(
        space: ParameterSpace,
        options: impl ParamGuard<Checked = ValidCorsOptions>,
        points: &[Vec<f64>],
        values: &[f64],
        initial_rows: Option<usize>,
    ) -> Result<Self> {
        let dim = space.dim();
        let x = if points.is_empty() {
            faer::Mat::zeros(0, dim)
        } else {
            from_rows(points, "history")?
        };
        Self::from_history(space, options, x.as_ref(), values, initial_rows)
    }

    /// Suggests `q` distinct points to evaluate next (they become pending until told).
    ///
    /// Design points not yet evaluated or pending come first. Then each CORS point
    /// minimises the surrogate (fitted once to the successes) subject to the distance
    /// constraint with `beta` of its own place in the cycle, keeping away from evaluated,
    /// pending and already chosen points, so a batch holds `q` distinct points. While no
    /// surrogate can be fitted, maximin points fill in, each with its
    /// [`FillReason`] (too few successes so far, or a failed fit).
    ///
    /// # Errors
    /// [`CorsError::InsufficientInitialSet`] under [`InitialDesign::Existing`] when the
    /// existing evaluations do not span; mapping errors of the parameter space (not
    /// expected).
    pub fn suggest(&mut self, q: usize) -> Result<Vec<Suggestion>> {
        if q == 0 {
            return Ok(Vec::new());
        }
        let proposal = propose(&self.state, q)?;
        self.state.plan = Some(proposal.plan);
        self.state.next_id += proposal.suggestions.len() as u64;
        self.state
            .pending
            .extend(proposal.suggestions.iter().cloned());
        Ok(proposal.suggestions)
    }

    /// Forgets a pending suggestion without recording a result (for example a simulation
    /// that was never started).
    ///
    /// # Errors
    /// [`CorsError::UnknownSuggestion`] when `id` is not pending.
    pub fn cancel(&mut self, id: u64) -> Result<()> {
        let k = self
            .state
            .pending
            .iter()
            .position(|p| p.id == id)
            .ok_or(CorsError::UnknownSuggestion(id))?;
        self.state.pending.remove(k);
        Ok(())
    }

    /// Why the study should stop by the target or patience rules of
    /// [`Stopping`](crate::Stopping), if it should. The patience rule is the study's one
    /// stall rule over the whole history.
    pub fn stop_reason(&self) -> Option<StopReason> {
        let stopping = &self.state.options.stopping;
        let best = self.best().and_then(|e| e.value);
        if let (Some(t), Some(b)) = (stopping.target, best)
            && b <= t
        {
            return Some(StopReason::Target);
        }
        if let Some(patience) = stopping.patience {
            let rule = StallRule {
                min_improvement: stopping.min_improvement,
                floor: 1e-12,
            };
            if rule.stall_length(&self.state.evaluations, 0) >= patience {
                return Some(StopReason::NoImprovement);
            }
        }
        None
    }

    /// The closed loop: suggests one point at a time, evaluates `objective` there (NaN or
    /// an infinity marks a failed evaluation) and tells the result, until `budget`
    /// evaluations have been made by this call or a stopping rule fires. Fill points made
    /// because the surrogate could not be fitted are listed in the outcome.
    ///
    /// # Errors
    /// As [`suggest`](Self::suggest) and [`tell`](Self::tell).
    pub fn minimize(
        &mut self,
        mut objective: impl FnMut(&[f64]) -> f64,
        budget: usize,
    ) -> Result<Outcome> {
        let mut used = 0;
        let mut failed_fits = Vec::new();
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
            if let Some(reason) = s.fill_reason.as_ref().filter(|r| r.is_failure()) {
                failed_fits.push(reason.clone());
            }
            let v = objective(&s.x);
            self.tell(s.id, v)?;
            used += 1;
        };
        Ok(Outcome {
            best: self.best().cloned(),
            evaluations: used,
            stop,
            failed_fits,
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
    /// [`CoreError::Io`] (as a [`CorsError`]) when the file cannot be written.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        let io = |source| {
            CorsError::Core(CoreError::Io {
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
    /// [`CoreError::Io`] (as a [`CorsError`]) when unreadable; otherwise as
    /// [`from_json`](Self::from_json).
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| {
            CorsError::Core(CoreError::Io {
                path: path.display().to_string(),
                source,
            })
        })?;
        Self::from_json(&text, &path.display().to_string())
    }
}

/// Fails unless there is one value per point.
fn one_value_per_point(what: &str, points: usize, values: usize) -> Result<()> {
    if points == values {
        return Ok(());
    }
    Err(CoreError::DimensionMismatch {
        what: format!("{what}: number of values (one per point)"),
        expected: points,
        found: values,
    }
    .into())
}
