//! `impactcal filter`: SAE J211 / ISO 6487 channel frequency class filtering of a CSV file.

use std::path::PathBuf;

use clap::Args as ClapArgs;
use impactcal::core::{Cfc, TestRecord};

use crate::error::CliError;

/// Arguments of `impactcal filter`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Histories in wide CSV (`time,<label>,...`; non-uniform time steps are resampled).
    #[arg(long)]
    pub input: PathBuf,
    /// Channel frequency class: 60, 180, 600 or 1000.
    #[arg(long)]
    pub cfc: u32,
    /// Output CSV with the same labels and times.
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    let cfc = Cfc::from_class(args.cfc)?;
    let record = TestRecord::read(&args.input)?;
    if let Some(r) = &record.resampling {
        eprintln!("note: {}: {r}", args.input.display());
    }
    let filtered = record
        .histories
        .filtered(cfc)
        .map_err(|e| CliError::input(format!("{}: {e}", args.input.display())))?;
    filtered.write_csv(&args.out)?;
    Ok(())
}
