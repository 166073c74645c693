//! Placement options.

use serde::{Deserialize, Serialize};

use crate::candidates::CandidateShapes;
use crate::error::{Result, SensorsError};
use impactcal_core::error::invalid_option;
use impactcal_core::{CoreError, ParamGuard};

/// How the sensor set is built.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlacementMethod {
    /// Kammer's backward elimination: start from every usable candidate and remove, one at
    /// a time, the candidate (or node) whose removal loses the smallest fraction of
    /// `det(Phi^T Phi)`, recomputing the scores after every removal.
    #[default]
    Backward,
    /// Forward greedy: start from the `k` rows chosen by QR with column pivoting of
    /// `Phi^T` (plus the DOFs that must stay), then add, one at a time, the candidate (or
    /// node) that raises `det(Phi^T Phi)` the most. Cheaper than backward elimination when
    /// the target is much smaller than the candidate count.
    Forward,
}

/// What one sensor is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Grouping {
    /// A sensor measures one DOF (uniaxial); the target counts DOFs.
    #[default]
    Dof,
    /// A sensor measures every candidate direction of a node (triaxial); the target counts
    /// nodes, labels must read `<node>.<x|y|z>`, and a node is scored by
    /// `1 - det(I - E_bb)` over its block of the projector.
    Node,
}

/// Options of [`place`](crate::place): build with [`PlacementOptions::new`] and the
/// setters, which check their values (argmin style: a setter that can refuse its value
/// returns a `Result`), so that an options value is always valid on its own.
/// [`place`](crate::place) then checks them against the candidates (labels that exist, one
/// noise level per candidate).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "OptionsData")]
pub struct PlacementOptions {
    pub(crate) target: usize,
    pub(crate) grouping: Grouping,
    pub(crate) method: PlacementMethod,
    pub(crate) keep: Vec<String>,
    pub(crate) exclude: Vec<String>,
    pub(crate) noise: Option<Vec<f64>>,
    pub(crate) swap_refinement: bool,
    pub(crate) max_swaps: usize,
    pub(crate) refresh_every: usize,
    pub(crate) rank_tolerance: f64,
    pub(crate) equivalence_tolerance: f64,
}

/// The unchecked serialised form of [`PlacementOptions`].
#[derive(Deserialize)]
struct OptionsData {
    target: usize,
    grouping: Grouping,
    method: PlacementMethod,
    keep: Vec<String>,
    exclude: Vec<String>,
    noise: Option<Vec<f64>>,
    swap_refinement: bool,
    max_swaps: usize,
    refresh_every: usize,
    rank_tolerance: f64,
    #[serde(default = "default_equivalence")]
    equivalence_tolerance: f64,
}

/// The default of [`PlacementOptions::equivalence_tolerance`]: `1 - |cos theta|` of
/// `5e-7`, an angle `theta` of `1e-3` between whitened rows.
pub const DEFAULT_EQUIVALENCE_TOLERANCE: f64 = 5e-7;

fn default_equivalence() -> f64 {
    DEFAULT_EQUIVALENCE_TOLERANCE
}

impl TryFrom<OptionsData> for PlacementOptions {
    type Error = SensorsError;
    fn try_from(d: OptionsData) -> Result<Self> {
        let mut o = PlacementOptions::new(d.target)
            .grouping(d.grouping)
            .method(d.method)
            .keep(d.keep)?
            .exclude(d.exclude)?
            .swap_refinement(d.swap_refinement)
            .max_swaps(d.max_swaps)
            .refresh_every(d.refresh_every)
            .rank_tolerance(d.rank_tolerance)?
            .equivalence_tolerance(d.equivalence_tolerance)?;
        if let Some(sigma) = d.noise {
            o = o.noise(sigma)?;
        }
        Ok(o)
    }
}

impl PlacementOptions {
    /// Options for `target` sensors with the defaults: per DOF, backward elimination, no
    /// constraints, equal noise, no swaps (at most 1000 when turned on), a fresh
    /// recomputation every 100 steps, rank tolerance `1e-10`, candidates repeating the
    /// information of another merged at the [`DEFAULT_EQUIVALENCE_TOLERANCE`].
    pub fn new(target: usize) -> Self {
        PlacementOptions {
            target,
            grouping: Grouping::Dof,
            method: PlacementMethod::Backward,
            keep: Vec::new(),
            exclude: Vec::new(),
            noise: None,
            swap_refinement: false,
            max_swaps: 1000,
            refresh_every: 100,
            rank_tolerance: 1e-10,
            equivalence_tolerance: DEFAULT_EQUIVALENCE_TOLERANCE,
        }
    }

    /// Per DOF or per node.
    #[must_use]
    pub fn grouping(mut self, grouping: Grouping) -> Self {
        self.grouping = grouping;
        self
    }

    /// Backward elimination or forward greedy.
    #[must_use]
    pub fn method(mut self, method: PlacementMethod) -> Self {
        self.method = method;
        self
    }

    /// DOFs that must stay (with [`Grouping::Node`], their nodes stay).
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) for an empty
    /// label; [`SensorsError::KeepExcludeConflict`] for a label that is also excluded.
    pub fn keep<S: Into<String>>(mut self, labels: impl IntoIterator<Item = S>) -> Result<Self> {
        self.keep = labels.into_iter().map(Into::into).collect();
        self.check_ref()?;
        self.check_conflict()?;
        Ok(self)
    }

    /// DOFs that may not be used.
    ///
    /// # Errors
    /// As [`keep`](Self::keep).
    pub fn exclude<S: Into<String>>(mut self, labels: impl IntoIterator<Item = S>) -> Result<Self> {
        self.exclude = labels.into_iter().map(Into::into).collect();
        self.check_ref()?;
        self.check_conflict()?;
        Ok(self)
    }

    /// Noise standard deviation per candidate DOF (same order as the candidates); row `i`
    /// of the shape matrix is divided by `sigma[i]` before placement (prewhitening), so
    /// quieter DOFs count more.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) for a level
    /// that is not finite and positive, naming its position.
    pub fn noise(mut self, sigma: Vec<f64>) -> Result<Self> {
        self.noise = Some(sigma);
        self.check_ref()?;
        Ok(self)
    }

    /// Noise standard deviations given by label, as read from a `label,sigma` table (see
    /// [`CandidateShapes::read_csv`]), put in the order of the candidates `labels`.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) when the
    /// table has not exactly one value column, names a label that is not a candidate (a
    /// typo would otherwise go unnoticed), lacks a level for a candidate, or holds a level
    /// that is not finite and positive; the message names the label.
    pub fn noise_by_label(self, labels: &[String], table: &CandidateShapes) -> Result<Self> {
        if table.shapes_count() != 1 {
            return Err(invalid_option(
                "noise table",
                format!("{} value columns", table.shapes_count()),
                "a noise table has one value column (label,sigma)",
            ));
        }
        if let Some(unknown) = table
            .labels()
            .iter()
            .find(|l| !labels.iter().any(|c| c == *l))
        {
            return Err(invalid_option(
                "noise table",
                format!("`{unknown}`"),
                format!("noise level for `{unknown}`, which is not a candidate"),
            ));
        }
        let sigma = labels
            .iter()
            .map(|l| {
                let level = table
                    .index_of(l)
                    .map(|i| table.shapes()[(i, 0)])
                    .ok_or_else(|| -> SensorsError {
                        invalid_option(
                            "noise table",
                            format!("`{l}`"),
                            format!("no noise level for candidate `{l}`"),
                        )
                    })?;
                if level.is_finite() && level > 0.0 {
                    Ok(level)
                } else {
                    Err(invalid_option(
                        format!("noise level of `{l}`"),
                        level,
                        "must be finite and positive",
                    ))
                }
            })
            .collect::<Result<Vec<f64>>>()?;
        self.noise(sigma)
    }

    /// Turns the swap refinement on or off: after the greedy pass, exchange a chosen
    /// candidate for an unchosen one while that raises `det(Phi^T Phi)` (Fedorov-type
    /// swaps, best swap first).
    #[must_use]
    pub fn swap_refinement(mut self, on: bool) -> Self {
        self.swap_refinement = on;
        self
    }

    /// Most swaps made by the refinement.
    #[must_use]
    pub fn max_swaps(mut self, swaps: usize) -> Self {
        self.max_swaps = swaps;
        self
    }

    /// Steps between fresh recomputations (QR) of the scores (0: never).
    #[must_use]
    pub fn refresh_every(mut self, steps: usize) -> Self {
        self.refresh_every = steps;
        self
    }

    /// Relative singular-value threshold below which the shape matrix counts as rank
    /// deficient.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) for a value
    /// that is negative or not finite.
    pub fn rank_tolerance(mut self, tolerance: f64) -> Result<Self> {
        self.rank_tolerance = tolerance;
        self.check_ref()?;
        Ok(self)
    }

    /// When two candidates count as one: a candidate (or node) whose whitened row (rows)
    /// lies within `1 - |cos theta| <= tolerance` of another's direction (span) repeats that
    /// candidate's information, and the placement keeps one of each such set (the one of
    /// largest noise-weighted signal, else the first), listing the others as equivalents
    /// (see [`Placement::equivalents`](crate::Placement::equivalents)). On a symmetric
    /// structure this is what keeps a sensor's mirror image out: the two rows are equal and
    /// effective independence would otherwise pay for both. The default
    /// [`DEFAULT_EQUIVALENCE_TOLERANCE`] (`5e-7`) is an angle of `1e-3`: two channels whose
    /// responses differ by less than 0.1 % of their signal (60 dB), below what impact
    /// instrumentation resolves, are one. `0` merges nothing (plain effective
    /// independence, which counts a repeat as a second measurement of the same quantity).
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) for a value
    /// that is negative, not finite, or 1 or more (every row would be one).
    pub fn equivalence_tolerance(mut self, tolerance: f64) -> Result<Self> {
        self.equivalence_tolerance = tolerance;
        self.check_ref()?;
        Ok(self)
    }

    /// Number of sensors to keep: DOFs, or nodes with [`Grouping::Node`].
    pub fn target(&self) -> usize {
        self.target
    }

    /// Per DOF or per node.
    pub fn grouping_kind(&self) -> Grouping {
        self.grouping
    }

    /// Backward elimination or forward greedy.
    pub fn placement_method(&self) -> PlacementMethod {
        self.method
    }

    /// Labels of the DOFs that must stay.
    pub fn kept(&self) -> &[String] {
        &self.keep
    }

    /// Labels of the DOFs that may not be used.
    pub fn excluded(&self) -> &[String] {
        &self.exclude
    }

    /// Noise standard deviation per candidate DOF, if given.
    pub fn noise_levels(&self) -> Option<&[f64]> {
        self.noise.as_deref()
    }

    /// Fails when a label is both kept and excluded.
    fn check_conflict(&self) -> Result<()> {
        match self.keep.iter().find(|l| self.exclude.contains(l)) {
            Some(label) => Err(SensorsError::KeepExcludeConflict {
                label: label.clone(),
            }),
            None => Ok(()),
        }
    }
}

impl ParamGuard for PlacementOptions {
    type Checked = PlacementOptions;

    /// Checks every option on its own; each setter that can refuse its value calls it (the
    /// options against the candidates are checked by [`place`](crate::place)). A label
    /// both kept and excluded is a [`SensorsError::KeepExcludeConflict`] of the setters.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] naming the option: an empty label in `keep` or
    /// `exclude`, a noise level that is not finite and positive (`noise level <i>
    /// (0-based)`), a `rank tolerance` that is negative or not finite, an `equivalence
    /// tolerance` outside `[0, 1)`.
    fn check_ref(&self) -> impactcal_core::Result<()> {
        for (option, labels) in [("keep", &self.keep), ("exclude", &self.exclude)] {
            if labels.iter().any(|l| l.trim().is_empty()) {
                return Err(CoreError::invalid_option(
                    option,
                    "\"\"",
                    "labels must not be empty",
                ));
            }
        }
        if let Some(sigma) = &self.noise
            && let Some(i) = sigma.iter().position(|v| !(v.is_finite() && *v > 0.0))
        {
            return Err(CoreError::invalid_option(
                format!("noise level {i} (0-based)"),
                sigma[i],
                "must be finite and positive",
            ));
        }
        if !(self.rank_tolerance.is_finite() && self.rank_tolerance >= 0.0) {
            return Err(CoreError::invalid_option(
                "rank tolerance",
                self.rank_tolerance,
                "must be finite and non-negative",
            ));
        }
        if !(self.equivalence_tolerance.is_finite()
            && (0.0..1.0).contains(&self.equivalence_tolerance))
        {
            return Err(CoreError::invalid_option(
                "equivalence tolerance",
                self.equivalence_tolerance,
                "must be finite, at least 0 (0: merge nothing) and below 1",
            ));
        }
        Ok(())
    }

    fn check(self) -> impactcal_core::Result<PlacementOptions> {
        self.check_ref()?;
        Ok(self)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// Each setter that can refuse its value refuses a bad one with
    /// `CoreError::InvalidOption` naming the option, through `ParamGuard::check_ref`.
    #[test]
    fn a_bad_value_is_refused_naming_its_key() {
        let key = |r: Result<PlacementOptions>| match r {
            Err(SensorsError::Core(CoreError::InvalidOption { name, .. })) => name,
            other => panic!("{other:?}"),
        };
        let o = || PlacementOptions::new(3);
        assert_eq!(key(o().keep(["a", " "])), "keep");
        assert_eq!(key(o().exclude([""])), "exclude");
        assert_eq!(key(o().noise(vec![1.0, 0.0])), "noise level 1 (0-based)");
        assert_eq!(key(o().rank_tolerance(f64::NAN)), "rank tolerance");
        assert_eq!(
            key(o().equivalence_tolerance(-1e-3)),
            "equivalence tolerance"
        );
        assert_eq!(key(o().equivalence_tolerance(1.0)), "equivalence tolerance");
        assert_eq!(
            key(o().equivalence_tolerance(f64::INFINITY)),
            "equivalence tolerance"
        );
        assert!(o().equivalence_tolerance(0.0).is_ok());
        let bad = PlacementOptions {
            rank_tolerance: -1.0,
            ..o()
        };
        match bad.check_ref() {
            Err(CoreError::InvalidOption { name, .. }) => assert_eq!(name, "rank tolerance"),
            other => panic!("{other:?}"),
        }
        let fine = o().keep(["a"]).unwrap().noise(vec![1.0, 2.0]).unwrap();
        assert!(fine.check_ref().is_ok());
        assert!(matches!(
            fine.exclude(["a"]),
            Err(SensorsError::KeepExcludeConflict { .. })
        ));
    }
}
