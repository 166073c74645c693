//! `impactcal compare`: calibration metric M2 between test and analysis impact shapes.

use std::path::PathBuf;

use clap::Args as ClapArgs;
use impactcal::core::Histories;
use impactcal::shapes::Orthogonality;
use serde::Serialize;

use crate::error::CliError;
use crate::output::write_json;
use crate::shapes::{decompose, options};

/// Arguments of `impactcal compare`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Test (measured) histories in wide CSV.
    #[arg(long)]
    pub test: PathBuf,
    /// Analysis (model) histories on the same channels, in wide CSV.
    #[arg(long)]
    pub analysis: PathBuf,
    /// Number of shapes of each side to compare (default: all up to the rank).
    #[arg(long)]
    pub shapes: Option<usize>,
    /// Write the JSON here instead of stdout.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

#[derive(Serialize)]
struct Report {
    orthogonality: Vec<Vec<f64>>,
    pairs: Vec<(usize, usize, f64)>,
    matched_above_0_9: usize,
    principal_cosines: Vec<f64>,
    test_contributions: Vec<f64>,
    analysis_contributions: Vec<f64>,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    let test = Histories::read_csv(&args.test)?;
    let analysis = Histories::read_csv(&args.analysis)?;
    let opts = options(args.shapes, None);
    let t = decompose(&test, &opts, &args.test.display().to_string())?;
    let a = decompose(&analysis, &opts, &args.analysis.display().to_string())?;
    let m2 = Orthogonality::between(&a, &t).map_err(|e| {
        CliError::from(e).context(format!(
            "{} vs {}",
            args.analysis.display(),
            args.test.display()
        ))
    })?;
    let m = m2.matrix();
    let report = Report {
        orthogonality: (0..m.nrows())
            .map(|i| (0..m.ncols()).map(|j| m[(i, j)]).collect())
            .collect(),
        pairs: m2
            .pairs()
            .iter()
            .map(|p| (p.analysis, p.test, p.value))
            .collect(),
        matched_above_0_9: m2.matched_above(0.9),
        principal_cosines: m2.principal_cosines().to_vec(),
        test_contributions: t.contributions(),
        analysis_contributions: a.contributions(),
    };
    write_json(&report, args.out.as_deref())
}
