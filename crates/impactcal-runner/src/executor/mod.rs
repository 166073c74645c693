//! Executors: where the runs of a batch happen.
//!
//! - [`Executor::Local`]: in this process, runs in parallel on rayon's thread pool (an
//!   in-process solver in process; an external command as a child process per run);
//! - [`Executor::Processes`]: a pool of at most `jobs` concurrent solver processes, each
//!   with a time limit after which it is killed;
//! - [`Executor::Slurm`]: one Slurm job array per batch, each task in its own work
//!   directory, polled with `squeue`.
//!
//! All three share the journal, the work directories and the retry rule of [`Batch`]: a run
//! is recorded before it starts and its result after it is read, so [`run_batch`] on a
//! batch whose driver was killed reuses finished runs, re-attaches to Slurm tasks still
//! queued or running and runs the rest again, ending with the same results.

mod local;
mod processes;
pub mod slurm;

use std::time::Duration;

use impactcal_core::{CoreError, ParamGuard};
use serde::{Deserialize, Serialize};

use crate::batch::{Batch, BatchReport, Cancel, Driver, Hooks};
use crate::error::{Result, RunnerError};
pub use slurm::SlurmOptions;

/// Options of the local process pool.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProcessOptions {
    /// Concurrent solver processes (at least 1; default: the cores this process may use,
    /// `std::thread::available_parallelism`).
    #[serde(default = "machine_cores")]
    pub jobs: usize,
    /// Time limit per run in seconds; a run still going is killed and counts as failed
    /// (and is retried within the batch's limit). None: no limit.
    #[serde(default)]
    pub timeout: Option<f64>,
}

/// The cores this process may use (1 when the system cannot say).
pub fn machine_cores() -> usize {
    std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
}

impl ParamGuard for ProcessOptions {
    /// The options themselves: nothing downstream needs a separate checked form.
    type Checked = ProcessOptions;

    /// Checks `jobs >= 1` and a finite positive timeout.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] naming the key (`executor.jobs`, `executor.timeout`).
    fn check_ref(&self) -> impactcal_core::Result<()> {
        if self.jobs == 0 {
            return Err(CoreError::invalid_option(
                "executor.jobs",
                self.jobs,
                "must be at least 1",
            ));
        }
        if let Some(t) = self.timeout {
            if !(t.is_finite() && t > 0.0) {
                return Err(CoreError::invalid_option(
                    "executor.timeout",
                    t,
                    "must be finite and positive (seconds)",
                ));
            }
        }
        Ok(())
    }

    fn check(self) -> impactcal_core::Result<ProcessOptions> {
        self.check_ref()?;
        Ok(self)
    }
}

impl ProcessOptions {
    fn timeout(&self) -> Option<Duration> {
        self.timeout.map(Duration::from_secs_f64)
    }
}

/// The solver command of an executor that runs processes (an in-process solver runs in
/// process only).
fn argv<'d>(driver: &'d Driver<'_>) -> Result<&'d [String]> {
    match &driver.batch.solver().command {
        crate::solver::SolverCommand::Argv(argv) => Ok(argv),
        crate::solver::SolverCommand::InProcess { .. } => Err(config(
            "the processes and slurm executors run a solver command; an in-process solver \
             runs in process only (executor kind = \"local\")",
        )),
    }
}

fn config(message: impl Into<String>) -> RunnerError {
    RunnerError::Config {
        file: "configuration".into(),
        message: message.into(),
    }
}

/// Where the runs of a batch happen. In a configuration file it is the `[executor]` table,
/// chosen by `kind` (`"local"`, `"processes"`, `"slurm"`) with the variant's options beside
/// it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
#[non_exhaustive]
pub enum Executor {
    /// In this process, in parallel on rayon's pool.
    Local,
    /// A local pool of solver processes.
    Processes(ProcessOptions),
    /// A Slurm cluster.
    Slurm(SlurmOptions),
}

impl Executor {
    /// The executor's name in the journal and the configuration.
    pub fn name(&self) -> &'static str {
        match self {
            Executor::Local => "local",
            Executor::Processes(_) => "processes",
            Executor::Slurm(_) => "slurm",
        }
    }

    /// Checks the executor's options (as [`run_batch`] does before any run), so that a
    /// caller with many batches can refuse bad options before the first: the options'
    /// [`ParamGuard::check_ref`].
    ///
    /// # Errors
    /// [`RunnerError::Core`] with the [`CoreError::InvalidOption`] naming the option.
    pub fn check(&self) -> Result<()> {
        match self {
            Executor::Local => Ok(()),
            Executor::Processes(o) => Ok(o.check_ref()?),
            Executor::Slurm(o) => Ok(o.check_ref()?),
        }
    }
}

/// Runs every point of `batch` that the journal does not hold a result for, on
/// `executor`, and returns every run's outcome in input order.
///
/// A failed run is reported in its slot and does not stop the others. A rerun after an
/// interruption (Ctrl-C, or the driver killed at any moment) resumes: see the module docs.
///
/// # Errors
/// Faults of the batch as a whole: the journal cannot be written or belongs to another
/// batch; an in-process solver asked of an executor that runs processes; a scheduler that
/// cannot be queried; [`RunnerError::Cancelled`] when `cancel` was set (runs in flight are
/// killed or cancelled; the journal holds the rest).
pub fn run_batch(batch: &Batch, executor: &Executor, cancel: &Cancel) -> Result<BatchReport> {
    run_batch_with(batch, executor, cancel, Hooks::default())
}

/// [`run_batch`] with [`Hooks`]: the solver an in-process command runs, and callbacks that
/// receive each run's histories as it finishes (so that nothing holds every run's
/// histories unless the caller keeps them).
///
/// # Errors
/// As [`run_batch`]; [`RunnerError::Config`] when the solver runs in process and
/// `hooks.in_process` is `None`.
pub fn run_batch_with(
    batch: &Batch,
    executor: &Executor,
    cancel: &Cancel,
    hooks: Hooks<'_>,
) -> Result<BatchReport> {
    if matches!(
        batch.solver().command,
        crate::solver::SolverCommand::InProcess { .. }
    ) && hooks.in_process.is_none()
    {
        return Err(config(
            "the solver runs in process, but no in-process solver was given",
        ));
    }
    let (driver, pending, in_flight) = Driver::open(batch, cancel, executor.name(), hooks)?;
    match executor {
        Executor::Local => {
            let mut pending = pending;
            pending.extend(in_flight.keys());
            pending.sort_unstable();
            local::run(&driver, &pending)?;
        }
        Executor::Processes(options) => {
            options.check_ref()?;
            let mut pending = pending;
            pending.extend(in_flight.keys());
            pending.sort_unstable();
            processes::run(&driver, &pending, options.jobs, options.timeout())?;
        }
        Executor::Slurm(options) => slurm::run(&driver, pending, in_flight, options)?,
    }
    Ok(driver.finish())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The option named by the first fault of `e`'s options, through the executor's check.
    fn fault(e: Executor) -> String {
        match e.check() {
            Err(RunnerError::Core(CoreError::InvalidOption { name, .. })) => name,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn executor_options_are_checked_as_every_option_type_is() {
        let processes = |jobs, timeout| Executor::Processes(ProcessOptions { jobs, timeout });
        assert_eq!(fault(processes(0, None)), "executor.jobs");
        assert_eq!(fault(processes(2, Some(0.0))), "executor.timeout");
        assert_eq!(fault(processes(2, Some(f64::NAN))), "executor.timeout");
        assert!(processes(2, Some(600.0)).check().is_ok());
        let slurm = |f: fn(&mut SlurmOptions)| {
            let mut o = SlurmOptions::default();
            f(&mut o);
            Executor::Slurm(o)
        };
        assert_eq!(
            fault(slurm(|o| o.partition = Some("de bug".into()))),
            "executor.partition"
        );
        assert_eq!(fault(slurm(|o| o.max_array = 0)), "executor.max_array");
        assert_eq!(
            fault(slurm(|o| o.max_running = Some(0))),
            "executor.max_running"
        );
        assert_eq!(fault(slurm(|o| o.poll = -1.0)), "executor.poll");
        assert!(slurm(|o| o.max_running = Some(4)).check().is_ok());
        // The consuming check hands the options back unchanged.
        let o = ProcessOptions {
            jobs: 3,
            timeout: None,
        };
        assert_eq!(o.clone().check().unwrap(), o);
        let e = RunnerError::from(
            ProcessOptions {
                jobs: 0,
                timeout: None,
            }
            .check()
            .unwrap_err(),
        );
        assert_eq!(e.kind(), impactcal_core::ErrorKind::BadInput);
    }
}
