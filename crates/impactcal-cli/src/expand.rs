//! `impactcal expand`: unmeasured histories from measured ones through model shapes.

use std::path::PathBuf;

use clap::Args as ClapArgs;
use impactcal::core::Histories;
use impactcal::shapes::Expansion;

use crate::error::CliError;
use crate::output::writer;
use crate::shapes::{decompose, options};

/// Arguments of `impactcal expand`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Measured histories (a subset of the model's channels, by label), wide CSV.
    #[arg(long)]
    pub measured: PathBuf,
    /// Model histories at every channel, wide CSV; its impact shapes do the expansion.
    #[arg(long)]
    pub model: PathBuf,
    /// Number of model shapes to use (default: all up to the rank).
    #[arg(long)]
    pub shapes: Option<usize>,
    /// Write the expanded histories here instead of stdout.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    let measured = Histories::read_csv(&args.measured)?;
    let model = Histories::read_csv(&args.model)?;
    let shapes = decompose(
        &model,
        &options(args.shapes, None),
        &args.model.display().to_string(),
    )?;
    let e = Expansion::compute(&shapes, &measured, None).map_err(|e| {
        CliError::from(e).context(format!(
            "{} with {}",
            args.measured.display(),
            args.model.display()
        ))
    })?;
    eprintln!(
        "cond(Phi) = {:.6e} ({} shapes at {} measured channels; noise gain <= sigma_max(K) / {:.6e})",
        e.condition(),
        shapes.len(),
        measured.channels(),
        e.sigma_min()
    );
    let (out, name) = writer(args.out.as_deref())?;
    e.histories().write_csv_to(out, &name)?;
    Ok(())
}
