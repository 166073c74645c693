//! `impactcal place`: sensor placement by effective independence.

use std::path::PathBuf;

use clap::{Args as ClapArgs, ValueEnum};
use impactcal::core::Histories;
use impactcal::sensors::{
    CandidateShapes, Grouping, Placement, PlacementMethod, PlacementOptions, SensorsError, place,
    place_from_histories,
};
use serde::Serialize;

use crate::error::CliError;
use crate::output::write_json;
use crate::shapes::options;

/// Arguments of `impactcal place`.
#[derive(ClapArgs, Debug)]
#[command(group(clap::ArgGroup::new("input").required(true).args(["histories", "shape_matrix"])))]
pub struct Args {
    /// Simulated histories at every candidate DOF (wide CSV); repeat for an ensemble of
    /// runs, which are concatenated in time before the impact-shape SVD.
    #[arg(long, num_args = 1..)]
    pub histories: Vec<PathBuf>,
    /// Number of impact shapes to keep from the histories (default: all up to the rank).
    #[arg(long, requires = "histories", conflicts_with = "contribution")]
    pub shapes: Option<usize>,
    /// Keep the fewest impact shapes whose cumulative contribution reaches this fraction.
    #[arg(long, requires = "histories")]
    pub contribution: Option<f64>,
    /// A candidate shape matrix instead: CSV with header `label,shape1,shape2,...`.
    #[arg(long)]
    pub shape_matrix: Option<PathBuf>,
    /// Number of sensors to keep (of nodes with --nodes).
    #[arg(long)]
    pub sensors: usize,
    /// Place triaxial sensors: select whole nodes (labels `<node>.<x|y|z>`).
    #[arg(long)]
    pub nodes: bool,
    /// DOF labels that must stay, comma separated.
    #[arg(long, value_delimiter = ',')]
    pub keep: Vec<String>,
    /// DOF labels that may not be used, comma separated.
    #[arg(long, value_delimiter = ',')]
    pub exclude: Vec<String>,
    /// Backward elimination (Kammer) or forward greedy from a pivoted-QR start.
    #[arg(long, value_enum, default_value_t = MethodArg::Backward)]
    pub method: MethodArg,
    /// Refine the greedy result by determinant-raising swaps.
    #[arg(long)]
    pub swaps: bool,
    /// Noise standard deviation per candidate DOF: CSV with header `label,sigma`, one row
    /// per candidate label; quieter DOFs then count more (each shape row is divided by its
    /// sigma).
    #[arg(long)]
    pub noise: Option<PathBuf>,
    /// Write the JSON here instead of stdout.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// The `--method` values.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum MethodArg {
    /// Kammer's backward elimination.
    Backward,
    /// Forward greedy addition.
    Forward,
}

#[derive(Serialize)]
struct Report<'a> {
    #[serde(flatten)]
    placement: &'a Placement,
    candidates: usize,
    shapes: usize,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    let opts = PlacementOptions::new(args.sensors)
        .grouping(if args.nodes {
            Grouping::Node
        } else {
            Grouping::Dof
        })
        .method(match args.method {
            MethodArg::Backward => PlacementMethod::Backward,
            MethodArg::Forward => PlacementMethod::Forward,
        })
        .swap_refinement(args.swaps)
        .keep(args.keep.iter().map(|s| s.trim().to_string()))?
        .exclude(args.exclude.iter().map(|s| s.trim().to_string()))?;
    let noise = args
        .noise
        .as_ref()
        .map(|path| CandidateShapes::read_csv(path).map(|t| (path, t)))
        .transpose()?;
    let with_noise = |opts: PlacementOptions, labels: &[String]| match &noise {
        Some((path, table)) => opts
            .noise_by_label(labels, table)
            .map_err(|e| in_file(path, e)),
        None => Ok(opts),
    };
    let (placement, candidates, shapes) = if let Some(path) = &args.shape_matrix {
        let c = CandidateShapes::read_csv(path)?;
        let opts = with_noise(opts, c.labels())?;
        let p = place(&c, &opts).map_err(|e| in_file(path, e))?;
        (p, c.candidates(), c.shapes_count())
    } else {
        let runs = args
            .histories
            .iter()
            .map(Histories::read_csv)
            .collect::<Result<Vec<_>, _>>()?;
        let labels = runs
            .first()
            .map(|r| r.labels().to_vec())
            .unwrap_or_default();
        let opts = with_noise(opts, &labels)?;
        let r = place_from_histories(&runs, &options(args.shapes, args.contribution), &opts)
            .map_err(|e| in_file(&args.histories[0], e))?;
        (r.placement, r.shapes.channels(), r.shapes.len())
    };
    for w in &placement.warnings {
        eprintln!("impactcal: warning: {w}");
    }
    write_json(
        &Report {
            placement: &placement,
            candidates,
            shapes,
        },
        args.out.as_deref(),
    )
}

/// A placement error as a command error naming the input file it concerns.
fn in_file(path: &std::path::Path, e: SensorsError) -> CliError {
    CliError::from(e).context(path.display())
}
