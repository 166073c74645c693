//! The in-process executor: rayon's pool runs the batch.

use rayon::prelude::*;

use crate::batch::Driver;
use crate::error::Result;
use crate::solver::{InProcessRun, SolverCommand};

/// Runs `pending` in parallel: an in-process solver in process, an external command as a
/// child process per run (no time limit).
pub(crate) fn run(driver: &Driver<'_>, pending: &[usize]) -> Result<()> {
    let solver = driver.batch.solver();
    let inputs: Vec<String> = solver.inputs.iter().map(|(_, n)| n.clone()).collect();
    pending.par_iter().try_for_each(|&index| {
        driver.drive(index, |d, index, attempt, dir| match &solver.command {
            SolverCommand::InProcess { .. } => match d.hooks.in_process {
                Some(in_process) => {
                    let run = InProcessRun {
                        index,
                        dir,
                        inputs: &inputs,
                        names: d.batch.names(),
                        values: d.batch.point(index),
                    };
                    solver.run_in_process(in_process, &run)
                }
                None => Err(super::config("no solver was given to run in process")),
            },
            SolverCommand::Argv(argv) => {
                super::processes::run_process(d, index, attempt, dir, argv, None).map(|s| (s, None))
            }
        })
    })
}
