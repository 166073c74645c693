//! `impactcal sobol`: Sobol' indices of every output column from a Saltelli design, or
//! first-order indices from any sample with `--given-data`.

use std::path::PathBuf;

use clap::{Args as ClapArgs, ValueEnum};
use faer::MatRef;
use impactcal::sobol::{
    DesignLayout, FirstOrderEstimator, GivenDataOptions, SobolOptions, TotalEstimator, analyze,
    given_data_first_order,
};

use crate::error::CliError;
use crate::output::write_json;
use crate::samples::SampleFiles;

/// Arguments of `impactcal sobol`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// The runs: bounds, parameter values (as written by `impactcal sample --method
    /// saltelli`, or SALib's design with that header) and model outputs.
    #[command(flatten)]
    files: SampleFiles,
    /// Bootstrap resamples for the intervals (0: none).
    #[arg(long, default_value_t = 0)]
    bootstrap: usize,
    /// Level of the bootstrap intervals.
    #[arg(long, default_value_t = 0.95)]
    confidence: f64,
    /// Seed of the bootstrap.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// The design has the BA blocks (`sample --second-order`); also estimate S_ij.
    #[arg(long)]
    second_order: bool,
    /// First-order estimator.
    #[arg(long, value_enum, default_value_t = FirstChoice::Saltelli2010)]
    first_estimator: FirstChoice,
    /// Total-index estimator.
    #[arg(long, value_enum, default_value_t = TotalChoice::Jansen1999)]
    total_estimator: TotalChoice,
    /// The runs are any sample (not a Saltelli design): estimate first-order indices by
    /// binning (correlation ratio).
    #[arg(long)]
    given_data: bool,
    /// Bins per parameter with `--given-data` (default round(n^(1/3))).
    #[arg(long)]
    bins: Option<usize>,
    /// Output JSON; stdout when absent.
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum FirstChoice {
    Saltelli2010,
    Jansen1999,
    Janon2014,
    Martinez2011,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum TotalChoice {
    Jansen1999,
    Sobol2007,
    Janon2014,
    Martinez2011,
}

/// Runs `impactcal sobol`.
pub fn run(args: Args) -> Result<(), CliError> {
    let (space, samples, y) = args.files.read()?;
    let x = samples.points;
    let params_name = args.files.params.display().to_string();
    let cols = y.header().len();
    let flat: Vec<f64> = y.rows().iter().flatten().copied().collect();
    let view = MatRef::from_row_major_slice(&flat, x.nrows(), cols);
    let parameter_names: Vec<String> = space.names().into_iter().map(str::to_string).collect();
    if args.given_data {
        let options = GivenDataOptions {
            bins: args.bins,
            parameter_names: Some(parameter_names),
            output_names: Some(y.header().to_vec()),
            ..GivenDataOptions::default()
        };
        return write_json(
            &given_data_first_order(x.as_ref(), view, &options)?,
            args.out.as_deref(),
        );
    }
    let layout = DesignLayout::from_rows(x.nrows(), space.dim(), args.second_order)?;
    layout.check_points(x.as_ref()).map_err(|e| {
        CliError::from(e)
            .context(&params_name)
            .hint("use --given-data for any other sample")
    })?;
    let options = SobolOptions {
        first_order: match args.first_estimator {
            FirstChoice::Saltelli2010 => FirstOrderEstimator::Saltelli2010,
            FirstChoice::Jansen1999 => FirstOrderEstimator::Jansen1999,
            FirstChoice::Janon2014 => FirstOrderEstimator::Janon2014,
            FirstChoice::Martinez2011 => FirstOrderEstimator::Martinez2011,
        },
        total: match args.total_estimator {
            TotalChoice::Jansen1999 => TotalEstimator::Jansen1999,
            TotalChoice::Sobol2007 => TotalEstimator::Sobol2007,
            TotalChoice::Janon2014 => TotalEstimator::Janon2014,
            TotalChoice::Martinez2011 => TotalEstimator::Martinez2011,
        },
        bootstrap: args.bootstrap,
        confidence: args.confidence,
        seed: args.seed,
        parameter_names: Some(parameter_names),
        output_names: Some(y.header().to_vec()),
        ..SobolOptions::default()
    };
    let indices = analyze(&layout, view, &options)?;
    if !indices.low_variance_outputs.is_empty() {
        eprintln!(
            "impactcal: warning: {} output column(s) have a variance at most 1e-10 of their own mean square (constant to float resolution); their indices are null: {}",
            indices.low_variance_outputs.len(),
            indices.low_variance_outputs.join(", ")
        );
    }
    write_json(&indices, args.out.as_deref())
}
