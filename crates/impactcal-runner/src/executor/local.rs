//! The in-process executor: rayon's pool runs the batch.

use rayon::prelude::*;

use crate::batch::Driver;
use crate::error::Result;
use crate::solver::SolverCommand;

/// Runs `pending` in parallel: the built-in solver in process, an external command as a
/// child process per run (no time limit).
pub(crate) fn run(driver: &Driver<'_>, pending: &[usize]) -> Result<()> {
    pending.par_iter().try_for_each(|&index| {
        driver.drive(index, |d, index, attempt, dir| {
            match &d.batch.solver().command {
                SolverCommand::BuiltIn { quantity } => {
                    d.batch.solver().run_builtin(index, dir, *quantity)
                }
                SolverCommand::Argv(argv) => {
                    super::processes::run_process(d, index, attempt, dir, argv, None)
                }
            }
        })
    })
}
