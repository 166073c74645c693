//! A runner: a solver on an executor, with its retries, its cancel token and, for a solver
//! that runs in this process, what runs it.

use std::sync::Arc;

use crate::batch::{Batch, BatchReport, Cancel, Hooks};
use crate::error::Result;
use crate::executor::{Executor, run_batch_with};
use crate::solver::{InProcessSolver, Solver};

/// What a run is ([`Solver`]: its templated inputs, command and output), where runs happen
/// ([`Executor`]), how often a failing run is tried again and the token that stops them:
/// everything a caller that submits batches of its own points needs, in one value.
#[derive(Clone)]
pub struct Runner {
    /// The solver that runs one point.
    pub solver: Solver,
    /// Where the runs happen.
    pub executor: Executor,
    /// What a [`SolverCommand::InProcess`](crate::SolverCommand::InProcess) solver runs
    /// (handed in by the layer that knows it, such as the built-in shell solver); `None`
    /// for a solver command run as a process.
    pub in_process: Option<Arc<dyn InProcessSolver + Send>>,
    /// Further attempts of a run that fails in a way another attempt may cure.
    pub retries: u32,
    /// Stops the runs when set (a Ctrl-C handler sets it).
    pub cancel: Cancel,
}

impl std::fmt::Debug for Runner {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Runner")
            .field("solver", &self.solver)
            .field("executor", &self.executor)
            .field("in_process", &self.in_process.is_some())
            .field("retries", &self.retries)
            .field("cancel", &self.cancel)
            .finish()
    }
}

impl Runner {
    /// A runner of `solver` on `executor`, with 2 retries, a fresh cancel token and no
    /// in-process solver.
    pub fn new(solver: Solver, executor: Executor) -> Self {
        Runner {
            solver,
            executor,
            in_process: None,
            retries: 2,
            cancel: Cancel::new(),
        }
    }

    /// The in-process solver, when one was handed in.
    pub fn in_process(&self) -> Option<&dyn InProcessSolver> {
        self.in_process
            .as_deref()
            .map(|s| s as &dyn InProcessSolver)
    }

    /// Runs `batch` (its own solver and retries) on this runner's executor with its cancel
    /// token, its in-process solver unless `hooks` names another.
    ///
    /// # Errors
    /// As [`run_batch_with`].
    pub fn run(&self, batch: &Batch, hooks: Hooks<'_>) -> Result<BatchReport> {
        let mut hooks = hooks;
        if hooks.in_process.is_none() {
            hooks.in_process = self.in_process();
        }
        run_batch_with(batch, &self.executor, &self.cancel, hooks)
    }
}
