//! Options of the CORS-RBF optimiser, checked once into [`ValidCorsOptions`].

use impactcal_core::{CoreError, ParamGuard};
use serde::{Deserialize, Serialize};

use crate::error::{CorsError, Result};

/// The radial kernel of the surrogate; both take a linear tail.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SurrogateKernel {
    /// `phi(r) = r^3` (the default, as in pySOT and the later Regis-Shoemaker papers).
    #[default]
    Cubic,
    /// `phi(r) = r^2 ln r`.
    ThinPlate,
}

/// A monotone transform applied to the successful objective values before the surrogate is
/// fitted. The optimiser still reports and compares raw values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Transform {
    /// `g = f`.
    #[default]
    Identity,
    /// `g = ln f`; every value must be positive (a non-positive value is refused by `tell`).
    Log,
    /// `g = ln(1 + f - f_min)` over the current successes: any sign, compresses large values.
    ShiftedLog,
    /// `g = min(f, median f)` (Gutmann's capping): flattens the high part of the surface so
    /// that it does not dominate the fit near the minimum.
    MedianCap,
}

impl Transform {
    /// Transforms `values` (all finite) in place.
    pub fn apply(self, values: &mut [f64]) {
        match self {
            Transform::Identity => {}
            Transform::Log => values.iter_mut().for_each(|v| *v = v.ln()),
            Transform::ShiftedLog => {
                let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
                values.iter_mut().for_each(|v| *v = (*v - lo).ln_1p());
            }
            Transform::MedianCap => {
                if values.is_empty() {
                    return;
                }
                let mut sorted = values.to_vec();
                sorted.sort_by(f64::total_cmp);
                let m = sorted.len();
                let median = if m % 2 == 1 {
                    sorted[m / 2]
                } else {
                    0.5 * (sorted[m / 2 - 1] + sorted[m / 2])
                };
                values.iter_mut().for_each(|v| *v = v.min(median));
            }
        }
    }

    /// Checks that a successful value lies in the transform's domain.
    ///
    /// # Errors
    /// [`CorsError::TransformDomain`] for a non-positive value under [`Transform::Log`].
    pub fn check(self, value: f64) -> Result<()> {
        if self == Transform::Log && value <= 0.0 {
            return Err(CorsError::TransformDomain {
                value,
                message: "the log transform needs positive values; use the shifted-log \
                          transform or transform the objective yourself"
                    .into(),
            });
        }
        Ok(())
    }
}

/// Where the initial set of evaluations comes from (the three variants users ask for).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum InitialDesign {
    /// The evaluations told before the first suggestion are the initial set when they hold
    /// `dim + 1` affinely independent successes; otherwise the symmetric Latin hypercube
    /// design is run as well.
    #[default]
    Auto,
    /// Always run the design, on top of any existing evaluations.
    Design,
    /// The existing evaluations are the whole initial set; the first suggestion fails with
    /// [`CorsError::InsufficientInitialSet`] when they cannot support the surrogate.
    Existing,
}

/// When a study stops besides its evaluation budget.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Stopping {
    /// Stop once the best raw value is at or below this target.
    pub target: Option<f64>,
    /// Stop after this many consecutive evaluations without an improvement of the best
    /// value by more than `min_improvement * max(|best|, 1e-12)`.
    pub patience: Option<usize>,
    /// Relative improvement that resets the patience counter (default 0: any decrease).
    pub min_improvement: f64,
}

/// The restart rule, in the spirit of CORS-RBF-Restart (Regis & Shoemaker, J. Global Optim.
/// 37:113-135, 2007): when the current run stops making substantial progress, the study
/// starts a new run from a fresh symmetric Latin hypercube design.
///
/// A run is the initial set (or a restart design) and the CORS points that follow it. The
/// run *stagnates* once `patience` consecutive evaluations after its initial set have not
/// improved the run's best value by more than `min_improvement * |best|`. The next
/// suggestion then starts a new run: a new design of the same size (drawn from the seed and
/// the restart count), then CORS points whose surrogate, distance constraints, maximin
/// distance and `beta` cycle use the new run's evaluations only. Every evaluation stays in
/// the history, the best over all runs is the study's result, and failed points keep their
/// no-go radius across runs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Restart {
    /// Consecutive evaluations without substantial improvement that end a run; `None` is
    /// [`Restart::default_patience`] of the dimension.
    pub patience: Option<usize>,
    /// Relative improvement of the run's best value that counts as substantial.
    pub min_improvement: f64,
}

impl Default for Restart {
    fn default() -> Self {
        Restart {
            patience: None,
            min_improvement: 1e-3,
        }
    }
}

/// The decay of the DYCORS schedules (Regis & Shoemaker, INFORMS J. Comput. 25:32-47,
/// 2013): `phi(m) = 1 - ln(m + 1) / ln(horizon)` for the `m`-th evaluation after the run's
/// initial set (`m = 0, 1, ...`), clamped to `[0, 1]`: 1 at the first adaptive point, 0 at
/// and after `m = horizon - 1`. DYCORS takes `horizon` = budget minus the initial set.
pub fn dycors_decay(m: usize, horizon: usize) -> f64 {
    if horizon < 2 {
        return 0.0;
    }
    (1.0 - ((m + 1) as f64).ln() / (horizon as f64).ln()).clamp(0.0, 1.0)
}

/// The horizon of the perturbation schedule when neither it nor the study's budget is
/// given: 300 evaluations after the run's initial set.
pub const DEFAULT_HORIZON: usize = 300;

/// DYCORS-style coordinate perturbation of the candidates around the best point in the
/// local cycles (Regis & Shoemaker 2013): each coordinate of such a candidate is perturbed
/// with probability `p(m) = min(20 / d, 1) phi(m)` ([`dycors_decay`]), and one coordinate
/// drawn uniformly when none is; the other coordinates keep the best point's values. Early
/// in a run every coordinate moves; later, in many dimensions, a few at a time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Perturbation {
    /// Evaluations after the run's initial set over which `p` falls to its floor; at least
    /// 2. `None` (the default): DYCORS's own rule, the study's
    /// [`budget`](CorsOptions::budget) less the evaluations before the run's first adaptive
    /// point, or [`DEFAULT_HORIZON`] when the budget is not known
    /// ([`horizon_for`](Self::horizon_for)).
    pub horizon: Option<usize>,
}

impl Perturbation {
    /// The horizon of a run whose first adaptive point is evaluation `cycle_origin` (the
    /// evaluations before it, warm start and design included) in a study of `budget`
    /// evaluations in all: `horizon` when set, else `budget - cycle_origin` (0 when the
    /// budget is spent, which makes `phi` 0), else [`DEFAULT_HORIZON`].
    pub fn horizon_for(&self, budget: Option<usize>, cycle_origin: usize) -> usize {
        match (self.horizon, budget) {
            (Some(h), _) => h,
            (None, Some(b)) => b.saturating_sub(cycle_origin),
            (None, None) => DEFAULT_HORIZON,
        }
    }

    /// The probability of perturbing a coordinate at the `m`-th evaluation after the run's
    /// initial set in `dim` dimensions, the schedule's horizon being `horizon`
    /// ([`horizon_for`](Self::horizon_for)).
    pub fn probability(&self, m: usize, dim: usize, horizon: usize) -> f64 {
        (20.0 / dim.max(1) as f64).min(1.0) * dycors_decay(m, horizon)
    }
}

/// A number of quasi-random candidates that falls as the run proceeds:
/// `max(min_per_dim, round(candidates_per_dim phi(m))) d` at the `m`-th evaluation after the
/// run's initial set ([`dycors_decay`]). Late steps, whose surrogate is dense and whose
/// search is mostly local, screen fewer candidates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct CandidateDecay {
    /// The floor, per dimension; at least 1 and at most `candidates_per_dim`.
    pub min_per_dim: usize,
    /// Evaluations after the run's initial set over which the count falls to its floor; at
    /// least 2.
    pub horizon: usize,
}

impl CandidateDecay {
    /// Quasi-random candidates per dimension at the `m`-th evaluation after the run's
    /// initial set, from `per_dim` at `m = 0`.
    pub fn per_dim(&self, per_dim: usize, m: usize) -> usize {
        let scaled = (per_dim as f64 * dycors_decay(m, self.horizon)).round() as usize;
        scaled
            .max(self.min_per_dim)
            .min(per_dim.max(self.min_per_dim))
    }
}

/// Refinement steps taken again while they improve: a step of the pattern with
/// `beta <= max_beta` whose result lowers the run's best value by more than 0.1 % of
/// `|best|` (DYCORS's success) is followed by another step with the same `beta` in the same
/// region instead of the pattern's next one, up to `max_repeats` times in a row.
///
/// The pattern's `beta` cycle spends a fixed share of the steps on exploration whatever
/// the refinement achieves; a success at a small `beta` says that the surrogate resolves
/// the basin it refines, where one more such step is the cheapest improvement on offer.
/// Exploration resumes at the first refinement step that does not succeed (or after
/// `max_repeats`), so every exploration step of the pattern still comes, only later, and
/// the cycle never stalls. The schedule is a function of the run's ordered results: a
/// point still pending counts as a step that did not succeed, so a study rebuilt from its
/// history (or resumed) proposes what an uninterrupted one does.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RepeatRefinement {
    /// The largest `beta` of a refinement step, in `[0, 1]` (default 0.05: the last three
    /// values of the default pattern).
    pub max_beta: f64,
    /// The most repeats in a row; at least 1 (default 6, one pattern's length).
    pub max_repeats: usize,
}

impl Default for RepeatRefinement {
    fn default() -> Self {
        RepeatRefinement {
            max_beta: 0.05,
            max_repeats: 6,
        }
    }
}

/// DYCORS's step-size rule (Regis & Shoemaker 2013; pySOT's `DYCORSStrategy`) applied to
/// the half-width of the local region ([`CorsOptions::local_region`]).
///
/// Walking the run's evaluations after its initial set, an evaluation *succeeds* when it
/// lowers the run's best value by more than 0.1 % of `|best|` and *fails* otherwise. The
/// half-width `h` starts at `local_region`; after `grow_after` consecutive successes it
/// doubles (never above `local_region`), after `shrink_after` consecutive failures it
/// halves, and each change restarts both counts. Once `h` falls below
/// `local_region 2^-halvings` the region has *converged*, and [`Converged`] says what
/// follows. In the local cycles the box has half-width `h` (with `shrink_box`) and the
/// Gaussian candidates scale their standard deviations by `h / local_region`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct AdaptiveRegion {
    /// Consecutive successes that double the half-width (DYCORS: 3); at least 1.
    pub grow_after: usize,
    /// Consecutive failures that halve it; `None` is `max(5, d)` (DYCORS's rule).
    pub shrink_after: Option<usize>,
    /// Halvings below which the region has converged (DYCORS: 6, its floor
    /// `0.2 * 0.5^6`); at least 1.
    pub halvings: u32,
    /// What a converged region does.
    pub on_converged: Converged,
    /// Whether the box of the local cycles shrinks with `h` (DYCORS's trust-region
    /// reading); `false` keeps the box at `local_region` and scales only the Gaussian
    /// candidates (DYCORS's own step: the perturbation width).
    pub shrink_box: bool,
}

impl Default for AdaptiveRegion {
    /// DYCORS's constants: grow after 3 successes, shrink after `max(5, d)` failures,
    /// converged after 6 halvings; then restore the width around the best point.
    fn default() -> Self {
        AdaptiveRegion {
            grow_after: 3,
            shrink_after: None,
            halvings: 6,
            on_converged: Converged::Restore,
            shrink_box: true,
        }
    }
}

impl AdaptiveRegion {
    /// The failures that halve the half-width in `dim` dimensions.
    pub fn shrink_after_for(&self, dim: usize) -> usize {
        self.shrink_after.unwrap_or(dim.max(5))
    }
}

/// What the local region does once its half-width has converged ([`AdaptiveRegion`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Converged {
    /// The half-width returns to `local_region` around the same (best) point, as DYCORS's
    /// restart would, but keeping every point in the surrogate.
    #[default]
    Restore,
    /// The half-width returns to `local_region` and the local cycles move on to the next
    /// basin (as [`CorsOptions::local_escape`] does, which this trigger replaces): the basin
    /// escape triggered by convergence rather than by a fixed idle count. An improvement of
    /// the run's best brings them back to the best point.
    Escape,
    /// The run ends and a new one starts, as by the restart rule ([`Restart`]; DYCORS's
    /// own restart): a new design and a surrogate of the new run's points only.
    Restart,
    /// A restart whose surrogate (and distance constraints) keep the successes of the
    /// earlier runs that lie outside the box of half-width `local_region` (0.3 without one)
    /// around each earlier run's best point: the converged basins are left out, the rest of what is
    /// known stays. The new run's best point, from its own evaluations, centres its local
    /// cycles.
    RestartOutside,
}

impl Restart {
    /// The default patience in `dim` dimensions: `6 max(5, d)`, i.e. five cycles of the
    /// default pattern in up to 5 dimensions.
    pub fn default_patience(dim: usize) -> usize {
        6 * dim.max(5)
    }

    /// The patience in `dim` dimensions.
    pub fn patience_for(&self, dim: usize) -> usize {
        self.patience.unwrap_or_else(|| Self::default_patience(dim))
    }
}

/// Options of [`Cors`](crate::Cors), checked into [`ValidCorsOptions`] (by
/// [`ParamGuard::check`], or by [`Cors::new`](crate::Cors::new) itself) before a study uses
/// them. Every check but one needs no dimension; the design size is checked against the
/// dimension when the study is made.
///
/// All distances are in the unit box `[0, 1]^d` of the parameter space. The defaults are
/// those of Regis & Shoemaker (2005) where the reference gives one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CorsOptions {
    /// The surrogate's kernel (linear tail in both cases).
    pub kernel: SurrogateKernel,
    /// The search pattern `<beta_1 .. beta_k>`, each in `[0, 1]`; the distance constraint
    /// of the `n`-th new point is `beta_n Delta_n` with `Delta_n` the maximin distance.
    pub pattern: Vec<f64>,
    /// How the initial set is formed.
    pub initial: InitialDesign,
    /// Size of the symmetric Latin hypercube design; `None` is `2 (d + 1)`. At least
    /// `d + 1`.
    pub design_size: Option<usize>,
    /// Transform of the objective values for the surrogate.
    pub transform: Transform,
    /// Quasi-random (randomly shifted Sobol') candidates per dimension for the auxiliary problem
    /// and the maximin distance.
    pub candidates_per_dim: usize,
    /// Candidates per dimension drawn around the best point (Gaussian perturbations of
    /// standard deviation 0.1, 0.02 and 0.004), which let the local stages of the cycle
    /// resolve the surrogate's minimum near the incumbent.
    pub local_candidates_per_dim: usize,
    /// Number of the best feasible candidates polished by the constrained local method.
    pub polish_starts: usize,
    /// Distance floor, times `sqrt(d)`, kept at `beta = 0` so that no point repeats.
    pub min_distance: f64,
    /// Radius, times `sqrt(d)`, around a failed evaluation inside which no point is
    /// proposed.
    pub failure_radius: f64,
    /// Stopping rules besides the budget.
    pub stopping: Stopping,
    /// The restart rule (`None`, the default: a single run, as in the 2005 method).
    pub restart: Option<Restart>,
    /// Half-width (in the unit box) of the box around the run's best point that every
    /// second cycle of the pattern searches: cycles 1, 3, 5... search the box
    /// `[x_best - h, x_best + h]` cut to the unit box, with `Delta` the maximin distance
    /// within it, cycles 0, 2, 4... the whole box (cycles 2, 6, 10... the second region's
    /// box instead, with [`second_region`](Self::second_region)). `None`: every cycle
    /// searches the whole box (the 2005 method). Default 0.3.
    pub local_region: Option<f64>,
    /// Whether the first cycle after a run's initial set is a local one: the pattern of
    /// regions is shifted by one cycle (cycles 0, 2, 4... search the box around the best
    /// point; 1, 3, 5... the whole box, or 1, 5, 9... the second region's box). Default
    /// `false`. No effect without `local_region`.
    pub local_first: bool,
    /// Local-basin escape: once the run has gone this many evaluations after its initial
    /// set without improving its best value by more than 0.1 %, the local cycles search
    /// around the best point of the next basin instead (successes grouped by value into
    /// boxes of half-width `local_region`), moving on to the next basin after every further
    /// `local_escape` evaluations without improvement; an improvement brings them back to
    /// the best point. Unlike a restart, the surrogate keeps every point of the run.
    /// `None`: always around the best point. Default 60.
    pub local_escape: Option<usize>,
    /// A second local region: every second whole-box cycle (cycles 2, 6, 10... of the
    /// pattern, so that cycles run whole, first, second, first) searches instead the box of
    /// half-width `local_region` around the best success lying outside the box of this
    /// half-width around the first region's centre (the best point, or the escape's
    /// basin); around the first region's centre when every success lies inside. Two
    /// regions in two basins are refined side by side, so a run that started in the basin
    /// of a local minimum (the best design point there) still resolves the best other
    /// basin, as the several trust regions of TuRBO (Eriksson et al. 2019) do. `None`: the
    /// cycles alternate between the whole box and the first region. Default 0.5. No effect
    /// without `local_region`.
    pub second_region: Option<f64>,
    /// DYCORS-style perturbation of the candidates around the best point in the local
    /// cycles (`None`: every coordinate of every such candidate moves). Default: the
    /// horizon follows [`budget`](Self::budget) (300 evaluations when it is `None`).
    pub perturbation: Option<Perturbation>,
    /// Refinement steps repeated while they improve the run's best value
    /// ([`RepeatRefinement`]); `None`: the pattern advances by one at every evaluation.
    /// Default: `beta <= 0.05`, at most 6 repeats in a row.
    pub repeat_refinement: Option<RepeatRefinement>,
    /// DYCORS's adaptive step applied to the local region's half-width, with what follows
    /// its convergence (`None`: the half-width stays `local_region`). Without
    /// `local_region` there are no local cycles to adapt and only a convergence restart
    /// ([`Converged::Restart`], [`Converged::RestartOutside`]) acts, the width starting
    /// at 1. Default `None`.
    pub adaptive_region: Option<AdaptiveRegion>,
    /// A quasi-random candidate count that falls as the run proceeds (`None`: always
    /// `candidates_per_dim d`).
    pub candidate_decay: Option<CandidateDecay>,
    /// SRBF's weight cycle (Regis & Shoemaker 2007) in place of the distance constraint:
    /// step `m` after the run's initial set takes the candidate minimising
    /// `w V_S + (1 - w) V_D` with `w` the `m`-th weight (cyclically), each in `[0, 1]`
    /// (pySOT: `[0.3, 0.5, 0.8, 0.95]`); the pattern then only counts the steps of a cycle
    /// for the local cycles. `None`: CORS's constrained step.
    pub merit_weights: Option<Vec<f64>>,
    /// The study's evaluation budget when it is known: every evaluation it will hold, warm
    /// start, design and adaptive points together. A run's perturbation schedule then
    /// falls to its floor at the budget, as DYCORS's does (Regis & Shoemaker 2013:
    /// `phi(n) = 1 - ln(n - n0 + 1) / ln(N - n0)` for a budget `N` and an initial set of
    /// `n0`); it stops nothing (the caller stops asking, or [`Cors::minimize`](crate::Cors::minimize)
    /// at its own budget). `None` (the default): unknown, and the horizon is
    /// [`DEFAULT_HORIZON`]. At least 1.
    pub budget: Option<usize>,
    /// Seed of the design and of every candidate set.
    pub seed: u64,
}

/// The search pattern of Regis & Shoemaker (2005).
pub const DEFAULT_PATTERN: [f64; 6] = [0.9, 0.75, 0.25, 0.05, 0.03, 0.0];

impl Default for CorsOptions {
    fn default() -> Self {
        CorsOptions {
            kernel: SurrogateKernel::Cubic,
            pattern: DEFAULT_PATTERN.to_vec(),
            initial: InitialDesign::Auto,
            design_size: None,
            transform: Transform::Identity,
            candidates_per_dim: 300,
            local_candidates_per_dim: 100,
            polish_starts: 5,
            min_distance: 1e-3,
            failure_radius: 0.05,
            stopping: Stopping::default(),
            restart: None,
            local_region: Some(0.3),
            local_first: false,
            local_escape: Some(60),
            second_region: Some(0.5),
            perturbation: Some(Perturbation { horizon: None }),
            repeat_refinement: Some(RepeatRefinement::default()),
            adaptive_region: None,
            candidate_decay: None,
            merit_weights: None,
            budget: None,
            seed: 0,
        }
    }
}

impl CorsOptions {
    /// The default options with `seed`.
    pub fn with_seed(seed: u64) -> Self {
        CorsOptions {
            seed,
            ..Self::default()
        }
    }

    /// The design size for `dim` parameters: `design_size` or `2 (dim + 1)`.
    pub fn design_size_for(&self, dim: usize) -> usize {
        self.design_size.unwrap_or(2 * (dim + 1))
    }
}

impl ParamGuard for CorsOptions {
    type Checked = ValidCorsOptions;

    /// Checks every option that does not depend on the dimension.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for an empty pattern or a `beta` outside `[0, 1]`, a
    /// design of fewer than 2 points, no candidates, no polishing start, a distance that is
    /// negative or not finite, a zero patience (stopping or restart) or a negative or
    /// non-finite improvement threshold, a decay horizon below 2, a budget of 0, a candidate floor of 0
    /// or above `candidates_per_dim`, a repeated refinement with `max_beta` outside
    /// `[0, 1]` or no repeat, or an adaptive region with a zero count or halvings outside
    /// `[1, 30]`.
    fn check_ref(&self) -> impactcal_core::Result<()> {
        let bad = |name: &'static str, value: String, message: &str| {
            Err(CoreError::invalid_option(name, value, message))
        };
        if self.pattern.is_empty() {
            return bad("pattern", "[]".into(), "needs at least one beta");
        }
        if let Some(b) = self.pattern.iter().find(|b| !(**b >= 0.0 && **b <= 1.0)) {
            return bad("pattern", b.to_string(), "every beta must lie in [0, 1]");
        }
        if let Some(n0) = self.design_size
            && n0 < 2
        {
            return bad(
                "design_size",
                n0.to_string(),
                "must be at least d + 1, and so at least 2",
            );
        }
        if self.candidates_per_dim == 0 {
            return bad("candidates_per_dim", "0".into(), "must be positive");
        }
        if self.polish_starts == 0 {
            return bad("polish_starts", "0".into(), "must be positive");
        }
        for (name, v) in [
            ("min_distance", self.min_distance),
            ("failure_radius", self.failure_radius),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(name, v.to_string(), "must be finite and non-negative");
            }
        }
        if self.min_distance <= 0.0 {
            return bad(
                "min_distance",
                self.min_distance.to_string(),
                "must be positive, or points could repeat",
            );
        }
        let s = &self.stopping;
        if !(s.min_improvement.is_finite() && s.min_improvement >= 0.0) {
            return bad(
                "stopping.min_improvement",
                s.min_improvement.to_string(),
                "must be finite and non-negative",
            );
        }
        if let Some(t) = s.target
            && !t.is_finite()
        {
            return bad("stopping.target", t.to_string(), "must be finite");
        }
        if s.patience == Some(0) {
            return bad("stopping.patience", "0".into(), "must be positive");
        }
        if let Some(h) = self.local_region
            && !(h.is_finite() && h > 0.0)
        {
            return bad("local_region", h.to_string(), "must be finite and positive");
        }
        if self.local_escape == Some(0) {
            return bad("local_escape", "0".into(), "must be positive");
        }
        if let Some(h) = self.second_region
            && !(h.is_finite() && h > 0.0)
        {
            return bad(
                "second_region",
                h.to_string(),
                "must be finite and positive",
            );
        }
        if let Some(h) = self.perturbation.and_then(|p| p.horizon)
            && h < 2
        {
            return bad("perturbation.horizon", h.to_string(), "must be at least 2");
        }
        if self.budget == Some(0) {
            return bad("budget", "0".into(), "must be at least 1");
        }
        if let Some(r) = &self.repeat_refinement {
            if !(r.max_beta >= 0.0 && r.max_beta <= 1.0) {
                return bad(
                    "repeat_refinement.max_beta",
                    r.max_beta.to_string(),
                    "must lie in [0, 1]",
                );
            }
            if r.max_repeats == 0 {
                return bad(
                    "repeat_refinement.max_repeats",
                    "0".into(),
                    "must be positive",
                );
            }
        }
        if let Some(a) = &self.adaptive_region {
            if a.grow_after == 0 {
                return bad("adaptive_region.grow_after", "0".into(), "must be positive");
            }
            if a.shrink_after == Some(0) {
                return bad(
                    "adaptive_region.shrink_after",
                    "0".into(),
                    "must be positive",
                );
            }
            if !(1..=30).contains(&a.halvings) {
                return bad(
                    "adaptive_region.halvings",
                    a.halvings.to_string(),
                    "must lie in [1, 30]",
                );
            }
        }
        if let Some(c) = &self.candidate_decay {
            if c.horizon < 2 {
                return bad(
                    "candidate_decay.horizon",
                    c.horizon.to_string(),
                    "must be at least 2",
                );
            }
            if c.min_per_dim == 0 || c.min_per_dim > self.candidates_per_dim {
                return bad(
                    "candidate_decay.min_per_dim",
                    c.min_per_dim.to_string(),
                    "must lie in [1, candidates_per_dim]",
                );
            }
        }
        if let Some(w) = &self.merit_weights {
            if w.is_empty() {
                return bad("merit_weights", "[]".into(), "needs at least one weight");
            }
            if let Some(v) = w.iter().find(|v| !(**v >= 0.0 && **v <= 1.0)) {
                return bad(
                    "merit_weights",
                    v.to_string(),
                    "every weight must lie in [0, 1]",
                );
            }
        }
        if let Some(r) = &self.restart {
            if r.patience == Some(0) {
                return bad("restart.patience", "0".into(), "must be positive");
            }
            if !(r.min_improvement.is_finite() && r.min_improvement >= 0.0) {
                return bad(
                    "restart.min_improvement",
                    r.min_improvement.to_string(),
                    "must be finite and non-negative",
                );
            }
        }
        Ok(())
    }

    fn check(self) -> impactcal_core::Result<ValidCorsOptions> {
        ValidCorsOptions::checked(self)
    }
}

impactcal_core::valid_options! {
    /// [`CorsOptions`] that passed their checks: the only form a study works with. Read the
    /// options through `Deref`; serialises as the plain options and is checked again when
    /// read.
    #[derive(Debug, Clone, PartialEq)]
    pub struct ValidCorsOptions(CorsOptions);
}

impl ValidCorsOptions {
    /// Checks the one option bound to the dimension: a design of at least `dim + 1` points.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] (as a [`CorsError`]) for a smaller design.
    pub fn check_dim(&self, dim: usize) -> Result<()> {
        let n0 = self.design_size_for(dim);
        if n0 < dim + 1 {
            return Err(CoreError::invalid_option(
                "design_size",
                n0,
                format!("must be at least d + 1 = {}", dim + 1),
            )
            .into());
        }
        Ok(())
    }
}

impl Default for ValidCorsOptions {
    /// The defaults of [`CorsOptions::default`], which are valid.
    fn default() -> Self {
        ValidCorsOptions(CorsOptions::default())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The DYCORS schedule: 1 at the first adaptive point, `1 - ln 2 / ln H` at the second,
    /// 0 from `m = H - 1` on; the probability is capped by `20 / d` above 20 dimensions.
    #[test]
    #[allow(clippy::float_cmp)] // exact values by construction
    fn dycors_schedules() {
        assert_eq!(dycors_decay(0, 300), 1.0);
        let second = 1.0 - 2f64.ln() / 300f64.ln();
        assert!((dycors_decay(1, 300) - second).abs() < 1e-15);
        assert_eq!(dycors_decay(299, 300), 0.0);
        assert_eq!(dycors_decay(1000, 300), 0.0);
        assert_eq!(dycors_decay(0, 1), 0.0);
        let p = Perturbation { horizon: None };
        assert_eq!(p.probability(0, 6, 300), 1.0);
        assert!((p.probability(0, 40, 300) - 0.5).abs() < 1e-15);
        assert!((p.probability(1, 40, 300) - 0.5 * second).abs() < 1e-15);
        let c = CandidateDecay {
            min_per_dim: 100,
            horizon: 300,
        };
        assert_eq!(c.per_dim(400, 0), 400);
        // 400 (1 - ln 11 / ln 300) = 231.9...
        assert_eq!(c.per_dim(400, 10), 232);
        assert_eq!(c.per_dim(400, 200), 100);
    }

    /// The horizon: a fixed one wins; else DYCORS's budget less the evaluations before the
    /// run's first adaptive point (0 once the budget is spent); else the default 300.
    #[test]
    #[allow(clippy::float_cmp)] // exact values by construction
    fn horizon_follows_the_budget() {
        let follow = Perturbation { horizon: None };
        assert_eq!(follow.horizon_for(None, 14), DEFAULT_HORIZON);
        assert_eq!(follow.horizon_for(Some(60), 14), 46);
        assert_eq!(follow.horizon_for(Some(150), 50), 100);
        assert_eq!(follow.horizon_for(Some(10), 14), 0);
        let fixed = Perturbation { horizon: Some(40) };
        assert_eq!(fixed.horizon_for(Some(60), 14), 40);
        assert_eq!(fixed.horizon_for(None, 14), 40);
        // At a budget of 60 after 14 design points the probability is 0 at the last point.
        assert_eq!(follow.probability(45, 6, 46), 0.0);
        assert!(follow.probability(44, 6, 46) > 0.0);
    }
}
