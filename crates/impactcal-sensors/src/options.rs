//! Placement options.

use crate::candidates::CandidateShapes;
use crate::error::{Result, SensorsError};
use serde::{Deserialize, Serialize};

/// How the sensor set is built.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
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

/// Options of [`place`](crate::place). Build with [`PlacementOptions::new`] and the
/// setters; [`place`](crate::place) checks them against the candidates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlacementOptions {
    /// Number of sensors to keep: DOFs, or nodes with [`Grouping::Node`].
    pub target: usize,
    /// Per DOF or per node.
    pub grouping: Grouping,
    /// Backward elimination (Kammer) or forward greedy.
    pub method: Method,
    /// Labels of DOFs that must stay in the set (with [`Grouping::Node`], their nodes stay).
    pub keep: Vec<String>,
    /// Labels of DOFs that may not be used.
    pub exclude: Vec<String>,
    /// Noise standard deviation per candidate DOF (same order as the candidates); row `i`
    /// of the shape matrix is divided by `noise[i]` before placement (prewhitening), so
    /// quieter DOFs count more. `None`: equal noise everywhere.
    pub noise: Option<Vec<f64>>,
    /// After the greedy pass, exchange a chosen candidate for an unchosen one while that
    /// raises `det(Phi^T Phi)` (Fedorov-type swaps, best swap first).
    pub swap_refinement: bool,
    /// Most swaps made by the refinement.
    pub max_swaps: usize,
    /// Steps between fresh recomputations (QR) of the scores; 0 never refreshes.
    pub refresh_every: usize,
    /// Relative singular-value threshold below which the shape matrix counts as rank
    /// deficient.
    pub rank_tolerance: f64,
}

impl PlacementOptions {
    /// Options for `target` sensors with the defaults: per DOF, backward elimination, no
    /// constraints, equal noise, no swaps, a fresh recomputation every 100 steps, rank
    /// tolerance `1e-10`.
    pub fn new(target: usize) -> Self {
        PlacementOptions {
            target,
            grouping: Grouping::Dof,
            method: Method::Backward,
            keep: Vec::new(),
            exclude: Vec::new(),
            noise: None,
            swap_refinement: false,
            max_swaps: 1000,
            refresh_every: 100,
            rank_tolerance: 1e-10,
        }
    }

    /// Per DOF or per node.
    pub fn grouping(mut self, grouping: Grouping) -> Self {
        self.grouping = grouping;
        self
    }

    /// Backward elimination or forward greedy.
    pub fn method(mut self, method: Method) -> Self {
        self.method = method;
        self
    }

    /// DOFs that must stay.
    pub fn keep<S: Into<String>>(mut self, labels: impl IntoIterator<Item = S>) -> Self {
        self.keep = labels.into_iter().map(Into::into).collect();
        self
    }

    /// DOFs that may not be used.
    pub fn exclude<S: Into<String>>(mut self, labels: impl IntoIterator<Item = S>) -> Self {
        self.exclude = labels.into_iter().map(Into::into).collect();
        self
    }

    /// Noise standard deviation per candidate DOF.
    pub fn noise(mut self, sigma: Vec<f64>) -> Self {
        self.noise = Some(sigma);
        self
    }

    /// Noise standard deviations given by label, as read from a `label,sigma` table (see
    /// [`CandidateShapes::read_csv`]), put in the order of the candidates `labels`.
    ///
    /// # Errors
    /// [`SensorsError::InvalidOption`] when the table has not exactly one value column,
    /// names a label that is not a candidate (a typo would otherwise go unnoticed), or
    /// lacks a level for a candidate; the message names the label.
    pub fn noise_by_label(self, labels: &[String], table: &CandidateShapes) -> Result<Self> {
        if table.shapes_count() != 1 {
            return Err(SensorsError::InvalidOption(format!(
                "a noise table has one value column (label,sigma); found {}",
                table.shapes_count()
            )));
        }
        if let Some(unknown) = table
            .labels()
            .iter()
            .find(|l| !labels.iter().any(|c| c == *l))
        {
            return Err(SensorsError::InvalidOption(format!(
                "noise level for `{unknown}`, which is not a candidate"
            )));
        }
        let sigma = labels
            .iter()
            .map(|l| {
                table
                    .index_of(l)
                    .map(|i| table.shapes()[(i, 0)])
                    .ok_or_else(|| {
                        SensorsError::InvalidOption(format!("no noise level for candidate `{l}`"))
                    })
            })
            .collect::<Result<Vec<f64>>>()?;
        Ok(self.noise(sigma))
    }

    /// Turns the swap refinement on or off.
    pub fn swap_refinement(mut self, on: bool) -> Self {
        self.swap_refinement = on;
        self
    }

    /// Steps between fresh recomputations of the scores (0: never).
    pub fn refresh_every(mut self, steps: usize) -> Self {
        self.refresh_every = steps;
        self
    }
}
