//! The state of a CORS-RBF study: everything a study is, serialisable, and nothing that
//! acts on it (the step is a pure function of it; the driver is [`Cors`](crate::Cors)).

use faer::Mat;
use impactcal_core::{CoreError, ParamGuard, ParameterSpace};
use serde::{Deserialize, Serialize};

use crate::design::{affine_rank_of_rows, symmetric_design};
use crate::error::{CorsError, Result};
use crate::geometry::mix;
use crate::options::{CorsOptions, Restart, ValidCorsOptions};
use crate::stall::StallRule;
use crate::surrogate::FitCache;

/// Tag of the saved state format.
pub(crate) const FORMAT: &str = "impactcal-cors/1";

/// Two points of the unit box closer than this (times `sqrt(d)`) are the same design point.
pub(crate) const MATCH_TOL: f64 = 1e-6;

/// Existing evaluations closer than this (times `sqrt(d)`) are refused as near-duplicates;
/// successes that close are merged (the lower value kept) when the surrogate is fitted.
pub(crate) const DUPLICATE_TOL: f64 = 1e-8;

/// How a point came to be evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Origin {
    /// Given by the user (a warm start or an evaluation told with
    /// [`Cors::tell_point`](crate::Cors::tell_point)).
    Existing,
    /// A point of the symmetric Latin hypercube design.
    Design,
    /// A space-filling (maximin) point, proposed while no surrogate could be fitted; the
    /// suggestion's [`FillReason`] says why.
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

/// Why a space-filling point was proposed instead of a CORS point.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "reason", rename_all = "kebab-case")]
#[non_exhaustive]
pub enum FillReason {
    /// The successes of the current run do not (yet) hold `d + 1` affinely independent
    /// points, for example while the design is pending or after failures in it: expected,
    /// not a fault.
    TooFewSuccesses {
        /// Distinct successful points of the run.
        successes: usize,
        /// Affinely independent points needed, `d + 1`.
        needed: usize,
    },
    /// The objective transform gave a non-finite value for some success.
    TransformNotFinite,
    /// Fitting the surrogate failed (even with a small smoothing); the error says why.
    SurrogateFailed {
        /// The error of the fit.
        message: String,
    },
}

impl FillReason {
    /// Whether the fill point stands for a failure of the surrogate (rather than too few
    /// successes so far).
    pub fn is_failure(&self) -> bool {
        !matches!(self, FillReason::TooFewSuccesses { .. })
    }
}

impl std::fmt::Display for FillReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FillReason::TooFewSuccesses { successes, needed } => write!(
                f,
                "the run's {successes} distinct successes do not hold the {needed} affinely \
                 independent points a surrogate needs"
            ),
            FillReason::TransformNotFinite => {
                f.write_str("the objective transform gave a non-finite value")
            }
            FillReason::SurrogateFailed { message } => {
                write!(f, "the surrogate could not be fitted: {message}")
            }
        }
    }
}

/// A point to evaluate, with the id to [`tell`](crate::Cors::tell) its result under.
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
    /// For a fill point: why no CORS point could be proposed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fill_reason: Option<FillReason>,
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
pub(crate) struct Plan {
    pub(crate) mode: Mode,
    /// Design points of the current run in the unit box (kept even in existing mode, for
    /// the record).
    pub(crate) design: Vec<Vec<f64>>,
    /// Index in the history of the first point of the `beta` cycle: point `n` uses
    /// `pattern[(n - cycle_origin) mod k]`.
    pub(crate) cycle_origin: usize,
    /// Index in the history of the first evaluation of the current run (0 before any
    /// restart).
    #[serde(default)]
    pub(crate) run_start: usize,
    /// Number of restarts so far.
    #[serde(default)]
    pub(crate) restarts: usize,
    /// The best points (unit box) of the earlier runs whose basins the surrogate leaves out
    /// ([`Converged::RestartOutside`](crate::Converged::RestartOutside)); empty otherwise.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(crate) excluded: Vec<Vec<f64>>,
}

impl Plan {
    /// Whether the current run stagnates after the first `upto` evaluations: `patience`
    /// consecutive evaluations after its initial set without improving the run's best by
    /// more than `min_improvement * |best|` (the [`StallRule`] within the run, counted
    /// from the start of its cycle).
    pub(crate) fn stagnates(
        &self,
        evaluations: &[Evaluation],
        upto: usize,
        rule: &Restart,
        dim: usize,
    ) -> bool {
        let end = upto.min(evaluations.len());
        let start = self.run_start.min(end);
        let stall = StallRule {
            min_improvement: rule.min_improvement,
            floor: 0.0,
        };
        let count_from = self.cycle_origin.saturating_sub(start);
        stall.stall_length(&evaluations[start..end], count_from) >= rule.patience_for(dim)
    }
}

/// Everything a CORS-RBF study is: its space, checked options, history, pending
/// suggestions and the plan of its current run. Serialises as the saved state
/// (`impactcal-cors/1`); reading one checks it.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "StateData")]
pub struct CorsState {
    pub(crate) format: String,
    pub(crate) space: ParameterSpace,
    pub(crate) options: ValidCorsOptions,
    pub(crate) evaluations: Vec<Evaluation>,
    pub(crate) pending: Vec<Suggestion>,
    pub(crate) next_id: u64,
    pub(crate) plan: Option<Plan>,
    /// The factorisation of the last surrogate (not saved: rebuilt on the first fit).
    #[serde(skip)]
    pub(crate) fit_cache: FitCache,
}

/// The unchecked serialised form of [`CorsState`].
#[derive(Deserialize)]
struct StateData {
    format: String,
    space: ParameterSpace,
    options: CorsOptions,
    evaluations: Vec<Evaluation>,
    pending: Vec<Suggestion>,
    next_id: u64,
    plan: Option<Plan>,
}

impl TryFrom<StateData> for CorsState {
    type Error = CorsError;

    fn try_from(d: StateData) -> Result<Self> {
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
        let options = d.options.check()?;
        options.check_dim(dim)?;
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
        Ok(CorsState {
            format: d.format,
            space: d.space,
            options,
            evaluations: d.evaluations,
            pending: d.pending,
            next_id: d.next_id,
            plan: d.plan,
            fit_cache: FitCache::default(),
        })
    }
}

impl CorsState {
    /// The state of a new study over `space`, before any evaluation.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] (as a [`CorsError`]) for a design smaller than
    /// `dim + 1`.
    pub fn new(space: ParameterSpace, options: ValidCorsOptions) -> Result<Self> {
        options.check_dim(space.dim())?;
        Ok(CorsState {
            format: FORMAT.into(),
            space,
            options,
            evaluations: Vec::new(),
            pending: Vec::new(),
            next_id: 0,
            plan: None,
            fit_cache: FitCache::default(),
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
        best_of(&self.evaluations)
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

    /// The design points of the current run (of run 0 before the first suggestion), one
    /// per row, in the parameter space.
    ///
    /// # Errors
    /// Those of the sampler (not expected for a checked state).
    pub fn design_points(&self) -> Result<Mat<f64>> {
        let design = match &self.plan {
            Some(p) => p.design.clone(),
            None => self.run_design(0)?,
        };
        let rows = design
            .iter()
            .map(|u| self.unit_to_space(u))
            .collect::<Result<Vec<_>>>()?;
        let d = self.space.dim();
        Ok(Mat::from_fn(rows.len(), d, |i, j| rows[i][j]))
    }

    /// The design of run `run` (0 the initial one, `r` the one of the `r`-th restart), in
    /// the unit box: a pure function of the seed and `run`.
    pub(crate) fn run_design(&self, run: usize) -> Result<Vec<Vec<f64>>> {
        let d = self.space.dim();
        let mut seed = mix(self.options.seed ^ 0xDE51_6E00_0000_0001);
        if run > 0 {
            seed = mix(seed ^ mix(run as u64 ^ 0x4E57_2A11_0000_0000));
        }
        let design = symmetric_design(self.options.design_size_for(d), d, seed)?;
        Ok(impactcal_core::points::to_rows(design.as_ref()))
    }

    /// A point of the unit box in the parameter space, clamped to the bounds.
    pub(crate) fn unit_to_space(&self, u: &[f64]) -> Result<Vec<f64>> {
        let mut x = self.space.from_unit(u)?;
        for (v, p) in x.iter_mut().zip(self.space.parameters()) {
            *v = v.clamp(p.lower, p.upper);
        }
        Ok(x)
    }

    /// Points of the parameter space in the unit box.
    pub(crate) fn units<'a>(&self, xs: impl Iterator<Item = &'a [f64]>) -> Result<Vec<Vec<f64>>> {
        xs.map(|x| Ok(self.space.to_unit(x)?)).collect()
    }

    /// Checks a point given by the user: length, finite, inside the bounds.
    pub(crate) fn check_point(&self, what: &str, x: &[f64]) -> Result<()> {
        if x.len() != self.space.dim() {
            return Err(CoreError::DimensionMismatch {
                what: format!("{what}: number of parameters"),
                expected: self.space.dim(),
                found: x.len(),
            }
            .into());
        }
        for (v, p) in x.iter().zip(self.space.parameters()) {
            if !v.is_finite() {
                return Err(CoreError::NonFinite {
                    what: what.into(),
                    location: format!("parameter `{}`", p.name),
                    value: *v,
                }
                .into());
            }
            if !p.admits(*v) {
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
    pub(crate) fn check_value(&self, value: f64) -> Result<Option<f64>> {
        if value.is_finite() {
            self.options.transform.check(value)?;
            Ok(Some(value))
        } else {
            Ok(None)
        }
    }

    /// The successful points in the unit box.
    pub(crate) fn success_units(&self) -> Result<Vec<Vec<f64>>> {
        self.units(
            self.evaluations
                .iter()
                .filter(|e| e.is_success())
                .map(|e| e.x.as_slice()),
        )
    }

    /// Whether the successes hold `d + 1` affinely independent points.
    pub(crate) fn successes_span(&self) -> Result<bool> {
        Ok(affine_rank_of_rows(&self.success_units()?) == self.space.dim() + 1)
    }

    /// Errors unless the successes hold `d + 1` affinely independent points.
    pub(crate) fn require_span(&self) -> Result<()> {
        let units = self.success_units()?;
        let rank = affine_rank_of_rows(&units);
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
}

/// The best successful evaluation of `evaluations` (lowest value; the earliest on ties).
pub(crate) fn best_of(evaluations: &[Evaluation]) -> Option<&Evaluation> {
    let mut best: Option<&Evaluation> = None;
    for e in evaluations {
        if let Some(v) = e.value
            && best.and_then(|b| b.value).is_none_or(|b| v < b)
        {
            best = Some(e);
        }
    }
    best
}

/// Evaluations at the origin of a one-dimensional box with the given values (`None`:
/// failed), for the tests of the rules that walk a run's results.
#[cfg(test)]
pub(crate) fn evaluations_with_values(values: &[Option<f64>]) -> Vec<Evaluation> {
    values
        .iter()
        .map(|&value| Evaluation {
            x: vec![0.0],
            value,
            origin: Origin::Cors,
        })
        .collect()
}
