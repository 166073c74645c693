//! `impactcal study` and `impactcal point`: an experiment file's calibration study, and one
//! run of an experiment's model in a run directory (what the process-pool and Slurm
//! executors run for a study's and a loop's runs alike). The file's schema, the model
//! assembly and the study live in the library (`impactcal::experiment`; docs/study.md).

use std::path::PathBuf;

use clap::Args as ClapArgs;
use impactcal::experiment::{Experiment, POINT_OUTPUT, read_record};
use impactcal::runner::Cancel;

use crate::error::CliError;
use crate::progress::Progress;
use crate::simulate::thread_pool;

/// Arguments of `impactcal study` and `impactcal close-loop`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// The experiment file (TOML: `[model]`, `[space]`, `[test]`, `[study]`, ...).
    #[arg(long)]
    pub config: PathBuf,
    /// Output folder: the run journal, `study.json` (or `loop.json`), the report. Running
    /// the same file again in the same folder reuses the runs that finished.
    #[arg(long)]
    pub out: PathBuf,
    /// Number of threads (runs go in parallel; results do not depend on it).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Memory the run may use (`2G`, `512M`, bytes; K/M/G/T are powers of 1024);
    /// default: what the machine has available. A stage whose estimate does not fit stops
    /// before it allocates (exit 2), naming the stage and what to change; the journal keeps
    /// every finished run.
    #[arg(long, value_parser = crate::size::parse_bytes)]
    pub max_memory: Option<u64>,
}

impl Args {
    /// The experiment of `--config` with `--max-memory`, its runs stopped by Ctrl-C.
    pub fn experiment(&self) -> Result<Experiment, CliError> {
        let e = Experiment::from_file(&self.config)?.with_max_memory(self.max_memory);
        stop_on_ctrl_c(e.cancel());
        Ok(e)
    }
}

/// Sets `cancel` on Ctrl-C. A second handler cannot be installed (tests run more than one
/// command in a process): Ctrl-C then keeps its default action, which loses nothing either.
pub fn stop_on_ctrl_c(cancel: Cancel) {
    let _ = ctrlc::set_handler(move || cancel.cancel());
}

/// Runs `impactcal study`.
pub fn run(args: Args) -> Result<(), CliError> {
    let experiment = args.experiment()?;
    crate::output::check_out_folder(&args.out)?;
    let progress = Progress::new();
    let done = thread_pool(args.threads)?.install(|| experiment.study_with(&args.out, &progress));
    progress.done();
    crate::output::print_finished(&done?, "");
    Ok(())
}

/// Arguments of `impactcal point`.
#[derive(ClapArgs, Debug)]
pub struct PointArgs {
    /// The experiment file whose built-in model is run.
    #[arg(long)]
    pub config: PathBuf,
    /// The run's parameters: the `params.json` the runner writes in each run's directory.
    #[arg(long, default_value = "params.json")]
    pub params: PathBuf,
    /// Where the histories go (our wide CSV).
    #[arg(long, default_value = POINT_OUTPUT)]
    pub out: PathBuf,
    /// Number of threads of the solver.
    #[arg(long)]
    pub threads: Option<usize>,
}

/// Runs the model of an experiment file at a run's `params.json` (its parameters, the
/// candidates a loop added, its condition) and writes its histories.
pub fn run_point(args: PointArgs) -> Result<(), CliError> {
    let experiment = Experiment::from_file(&args.config)?;
    let record = read_record(&args.params)?;
    let h = thread_pool(args.threads)?
        .install(|| experiment.point_at(&record))
        .map_err(|e| CliError::from(e).context(args.params.display()))?;
    h.write_csv(&args.out)?;
    Ok(())
}
