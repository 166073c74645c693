//! How the study's true-model runs are executed: one small seam ([`Executor`]) between the
//! study and whatever runs the model, and the journaled stage runner built on it.

use std::sync::Mutex;

use impactcal_core::{CoreError, Histories, Model, ParameterSpace};
use rayon::prelude::*;

use super::journal::{Journal, RunOutcome};
use crate::error::{CalibrateError, Result};

/// Runs batches of points of a model. [`InProcess`] runs a [`Model`] on rayon's pool;
/// other executors (a process pool, a cluster) implement the same two methods.
pub trait Executor: Sync {
    /// The parameters every point has, in order.
    fn space(&self) -> &ParameterSpace;

    /// Runs every point of `points` and calls `done(i, outcome)` as each run finishes (in
    /// any order, from any thread); returns when all have finished.
    fn run(&self, points: &[Vec<f64>], done: &(dyn Fn(usize, RunOutcome) + Sync));
}

/// A [`Model`] run in this process, points in parallel with rayon.
#[derive(Debug)]
pub struct InProcess<'m, M>(pub &'m M);

impl<M: Model> Executor for InProcess<'_, M> {
    fn space(&self) -> &ParameterSpace {
        self.0.space()
    }

    fn run(&self, points: &[Vec<f64>], done: &(dyn Fn(usize, RunOutcome) + Sync)) {
        points.par_iter().enumerate().for_each(|(i, p)| {
            let outcome = match self.0.space().to_unit(p) {
                Ok(_) => self.0.simulate(p).map_err(|e| e.to_string()),
                Err(e) => Err(e.to_string()),
            };
            done(i, outcome);
        });
    }
}

/// What a study tells the person waiting for it. All methods default to nothing.
pub trait Observer: Sync {
    /// A stage of `total` runs starts; `reused` of them come from the journal.
    fn stage(&self, _name: &str, _total: usize, _reused: usize) {}
    /// One more run of the current stage finished.
    fn run_finished(&self) {}
    /// A stage without model runs (a fit, an analysis) starts.
    fn step(&self, _name: &str) {}
}

/// An observer that says nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Observer for Silent {}

/// The executor, journal and observer of one study.
pub(crate) struct Runs<'a> {
    pub executor: &'a dyn Executor,
    pub journal: &'a Journal,
    pub observer: &'a dyn Observer,
}

impl Runs<'_> {
    /// The outcomes of `points` as stage `stage`: journaled runs are read back, the others
    /// run through the executor, each journaled as it finishes. Outcomes in input order.
    ///
    /// # Errors
    /// [`CalibrateError::Journal`] when a run cannot be read or recorded.
    pub fn stage(&self, stage: &str, points: &[Vec<f64>]) -> Result<Vec<RunOutcome>> {
        self.stage_from(stage, 0, points, true)
    }

    /// [`stage`](Self::stage) for runs `first..first + points.len()` of a stage run in
    /// parts; `announce` tells the observer a stage starts.
    ///
    /// # Errors
    /// As [`stage`](Self::stage).
    pub fn stage_from(
        &self,
        stage: &str,
        first: usize,
        points: &[Vec<f64>],
        announce: bool,
    ) -> Result<Vec<RunOutcome>> {
        let mut outcomes: Vec<Option<RunOutcome>> = Vec::with_capacity(points.len());
        for (i, p) in points.iter().enumerate() {
            outcomes.push(self.journal.read(stage, first + i, p)?);
        }
        let missing: Vec<usize> = (0..points.len())
            .filter(|&i| outcomes[i].is_none())
            .collect();
        if announce {
            self.observer
                .stage(stage, points.len(), points.len() - missing.len());
        } else {
            (missing.len()..points.len()).for_each(|_| self.observer.run_finished());
        }
        if !missing.is_empty() {
            let todo: Vec<Vec<f64>> = missing.iter().map(|&i| points[i].clone()).collect();
            let results: Mutex<Vec<(usize, Result<RunOutcome>)>> = Mutex::new(Vec::new());
            self.executor.run(&todo, &|k, outcome| {
                let i = missing[k];
                let stored = self.journal.write(stage, first + i, &points[i], &outcome);
                self.observer.run_finished();
                if let Ok(mut r) = results.lock() {
                    r.push((i, stored));
                }
            });
            let results = results
                .into_inner()
                .map_err(|_| CalibrateError::study(stage, "a run panicked"))?;
            for (i, r) in results {
                outcomes[i] = Some(r?);
            }
        }
        outcomes
            .into_iter()
            .enumerate()
            .map(|(i, o)| {
                o.ok_or_else(|| CalibrateError::study(stage, format!("run {i} never finished")))
            })
            .collect()
    }
}

/// The histories of a successful outcome, or the simulation error.
pub(crate) fn histories_of(outcome: &RunOutcome, what: &str) -> Result<Histories> {
    outcome
        .clone()
        .map_err(|m| CalibrateError::Core(CoreError::Simulation(format!("{what}: {m}").into())))
}
