//! `impactcal shapes`: impact shapes of a histories file.

use std::path::PathBuf;

use clap::Args as ClapArgs;
use impactcal::core::Histories;
use impactcal::shapes::{ImpactShapes, ShapeOptions, SvdMethod, Truncation};
use serde::Serialize;

use crate::error::CliError;
use crate::output::write_json;

/// Arguments of `impactcal shapes`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Histories in wide CSV (`time,<label>,...`).
    #[arg(long)]
    pub input: PathBuf,
    /// Keep exactly this many shapes.
    #[arg(long, conflicts_with = "contribution")]
    pub shapes: Option<usize>,
    /// Keep the fewest shapes whose cumulative contribution reaches this fraction (0, 1].
    #[arg(long)]
    pub contribution: Option<f64>,
    /// Write the JSON here instead of stdout.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

#[derive(Serialize)]
struct Report<'a> {
    channels: &'a [String],
    singular_values: &'a [f64],
    contributions: Vec<f64>,
    energy_fractions: Vec<f64>,
    contribution_basis: impactcal::shapes::ContributionBasis,
    rank: usize,
    shapes: Vec<Vec<f64>>,
    time: Vec<f64>,
    time_functions: Vec<Vec<f64>>,
}

/// Shape options from the `--shapes` / `--contribution` pair shared by several subcommands.
pub fn options(shapes: Option<usize>, contribution: Option<f64>) -> ShapeOptions {
    let truncation = match (shapes, contribution) {
        (Some(k), _) => Truncation::Count(k),
        (None, Some(f)) => Truncation::Contribution(f),
        (None, None) => Truncation::All,
    };
    ShapeOptions {
        truncation,
        method: SvdMethod::Auto,
    }
}

/// Decomposes histories, turning a library error into a command error that names `file`.
pub fn decompose(
    h: &Histories,
    options: &ShapeOptions,
    file: &str,
) -> Result<ImpactShapes, CliError> {
    ImpactShapes::from_histories(h, options).map_err(|e| CliError::from(e).context(file))
}

/// Columns of a matrix as vectors (one per shape).
pub fn columns(m: faer::MatRef<'_, f64>) -> Vec<Vec<f64>> {
    (0..m.ncols())
        .map(|j| m.col(j).iter().copied().collect())
        .collect()
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    let h = Histories::read_csv(&args.input)?;
    let s = decompose(
        &h,
        &options(args.shapes, args.contribution),
        &args.input.display().to_string(),
    )?;
    let report = Report {
        channels: s.labels(),
        singular_values: s.singular_values(),
        contributions: s.contributions(),
        energy_fractions: s.energy_fractions(),
        contribution_basis: s.contribution_basis(),
        rank: s.rank(),
        shapes: columns(s.shapes()),
        time: h.time(),
        time_functions: columns(s.time_functions()),
    };
    write_json(&report, args.out.as_deref())
}
