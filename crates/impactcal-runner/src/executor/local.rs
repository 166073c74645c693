//! The in-process executor: rayon's pool runs the batch.

use rayon::prelude::*;

use crate::batch::Driver;
use crate::error::Result;
use crate::solver::SolverCommand;

/// Runs `pending` in parallel: the built-in solver and an in-process model in process, an
/// external command as a child process per run (no time limit).
pub(crate) fn run(driver: &Driver<'_>, pending: &[usize]) -> Result<()> {
    pending.par_iter().try_for_each(|&index| {
        driver.drive(index, |d, index, attempt, dir| {
            match &d.batch.solver().command {
                SolverCommand::BuiltIn { quantity } => d
                    .batch
                    .solver()
                    .run_builtin(index, dir, *quantity)
                    .map(|s| (s, None)),
                SolverCommand::InProcess { .. } => match d.hooks.model {
                    Some(model) => {
                        d.batch
                            .solver()
                            .run_model(index, dir, model, d.batch.point(index))
                    }
                    None => Err(super::config("no model was given to run in process")),
                },
                SolverCommand::Argv(argv) => {
                    super::processes::run_process(d, index, attempt, dir, argv, None)
                        .map(|s| (s, None))
                }
            }
        })
    })
}
