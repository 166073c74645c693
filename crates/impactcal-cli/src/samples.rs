//! The files of sampled runs that `surrogate fit` and `sobol` read, and the one way they are
//! read: the parameters by name through the library's sample reader, the outputs as a table
//! with one row per run.

use std::path::PathBuf;

use clap::Args as ClapArgs;
use impactcal::core::{ParameterSpace, Samples, Table, TableOptions, read_samples};

use crate::error::CliError;

/// Bounds, parameter values and outputs of a set of runs.
#[derive(ClapArgs, Debug)]
pub struct SampleFiles {
    /// Bounds file: `name,lower,upper,nominal[,unit]`.
    #[arg(long)]
    pub bounds: PathBuf,
    /// Parameter values of the runs: a header of parameter names (exactly the names of the
    /// bounds file, in any order), one row per run.
    #[arg(long)]
    pub params: PathBuf,
    /// Outputs of the runs: a header of output names, one row per run in the order of
    /// --params, any number of columns (for example one per time step).
    #[arg(long)]
    pub outputs: PathBuf,
}

impl SampleFiles {
    /// The parameter space, the samples (by name, in the space's order) and the outputs.
    ///
    /// # Errors
    /// Those of the readers, and bad input when the outputs have not one row per sample.
    pub fn read(&self) -> Result<(ParameterSpace, Samples, Table), CliError> {
        let space = ParameterSpace::read_csv(&self.bounds)?;
        let samples = read_samples(&self.params, &space, &[], TableOptions::default())?;
        let outputs = Table::read(&self.outputs, TableOptions::default())?;
        if outputs.len() != samples.points.nrows() {
            return Err(CliError::input(format!(
                "{}: {} rows, but {} has {} samples; one response row per sample is required",
                self.outputs.display(),
                outputs.len(),
                self.params.display(),
                samples.points.nrows()
            )));
        }
        Ok((space, samples, outputs))
    }
}
