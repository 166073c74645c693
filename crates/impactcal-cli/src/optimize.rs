//! `impactcal optimize suggest`: the next points of a CORS-RBF study, stateless over a
//! history file, so that a shell loop of suggest, run, append drives a study with any
//! simulator.

use std::path::PathBuf;

use clap::{Args as ClapArgs, Subcommand, ValueEnum};
use impactcal::core::{ParameterSpace, Table, TableOptions};
use impactcal::cors::{Cors, CorsOptions, InitialDesign, Restart, SurrogateKernel, Transform};

use crate::error::CliError;
use crate::output::writer;

/// Arguments of `impactcal optimize`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    #[command(subcommand)]
    command: OptimizeCommand,
}

#[derive(Subcommand, Debug)]
enum OptimizeCommand {
    /// Print the next points to evaluate (CSV with the parameter header): missing design
    /// points first, then CORS points.
    Suggest(SuggestArgs),
}

/// Kernel choices on the command line.
#[derive(ValueEnum, Clone, Copy, Debug)]
enum KernelArg {
    Cubic,
    ThinPlate,
}

/// Transform choices on the command line.
#[derive(ValueEnum, Clone, Copy, Debug)]
enum TransformArg {
    Identity,
    Log,
    ShiftedLog,
    MedianCap,
}

/// Initial-set choices on the command line.
#[derive(ValueEnum, Clone, Copy, Debug)]
enum InitialArg {
    Auto,
    Design,
    Existing,
}

/// Arguments of `impactcal optimize suggest`.
#[derive(ClapArgs, Debug)]
struct SuggestArgs {
    /// Bounds file: `name,lower,upper,nominal[,unit]`.
    #[arg(long)]
    bounds: PathBuf,
    /// History: the parameter columns and an `objective` column (empty or `nan` for a
    /// failed run), one row per evaluation in the order they were run. A missing or empty
    /// file means no evaluation yet.
    #[arg(long)]
    history: PathBuf,
    /// Number of distinct points to suggest (to run at once).
    #[arg(long, default_value_t = 1)]
    batch: usize,
    /// Seed of the design and the candidates; keep it fixed for a whole study.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Surrogate kernel (linear tail).
    #[arg(long, value_enum, default_value_t = KernelArg::Cubic)]
    kernel: KernelArg,
    /// Transform of the objective before fitting.
    #[arg(long, value_enum, default_value_t = TransformArg::Identity)]
    transform: TransformArg,
    /// Initial set: the history if it spans (auto), always the design, or the history only.
    #[arg(long, value_enum, default_value_t = InitialArg::Auto)]
    initial: InitialArg,
    /// Size of the symmetric Latin hypercube design (default 2 (d + 1)).
    #[arg(long)]
    design_size: Option<usize>,
    /// Number of leading history rows that are pre-existing runs, when there is no design:
    /// the search-pattern cycle starts after them (default 0).
    #[arg(long)]
    initial_rows: Option<usize>,
    /// Half-width, in the unit box, of the box around the best point that every second
    /// cycle of the search pattern searches (default 0.3).
    #[arg(long, conflicts_with = "global_only")]
    local_half_width: Option<f64>,
    /// Search the whole box in every cycle (the 2005 method, no local cycles).
    #[arg(long)]
    global_only: bool,
    /// Restart with a new design after this many evaluations without substantial
    /// improvement (off by default; `--restart` uses a patience that grows with the
    /// dimension).
    #[arg(long)]
    restart_patience: Option<usize>,
    /// Turn the restart rule on with its default patience.
    #[arg(long)]
    restart: bool,
    /// Write the points here instead of stdout.
    #[arg(long)]
    out: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    match args.command {
        OptimizeCommand::Suggest(a) => suggest(a),
    }
}

/// Reads the history: rows of parameters (by name, any column order) and objectives.
fn read_history(
    space: &ParameterSpace,
    args: &SuggestArgs,
) -> Result<(Vec<Vec<f64>>, Vec<f64>), CliError> {
    let path = &args.history;
    let empty = match std::fs::metadata(path) {
        Err(_) => true,
        Ok(m) => m.len() == 0,
    };
    if empty {
        return Ok((Vec::new(), Vec::new()));
    }
    let table = Table::read(
        path,
        TableOptions {
            allow_missing: true,
            allow_no_rows: true,
        },
    )?;
    let name = path.display();
    let columns = space
        .names()
        .iter()
        .map(|p| {
            table.column_index(p).ok_or_else(|| {
                CliError::input(format!(
                    "{name}: no column `{p}` (a parameter of the bounds)"
                ))
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let objective = table
        .column_index("objective")
        .ok_or_else(|| CliError::input(format!("{name}: no `objective` column")))?;
    let mut points = Vec::with_capacity(table.rows.len());
    for (row, line) in table.rows.iter().zip(&table.lines) {
        let x: Vec<f64> = columns.iter().map(|&j| row[j]).collect();
        if let Some(j) = columns.iter().position(|&j| row[j].is_nan()) {
            return Err(CliError::input(format!(
                "{name}: row {line}: parameter `{}` is empty",
                space.names()[j]
            )));
        }
        points.push(x);
    }
    let values = table.rows.iter().map(|r| r[objective]).collect();
    Ok((points, values))
}

fn suggest(args: SuggestArgs) -> Result<(), CliError> {
    let space = ParameterSpace::read_csv(&args.bounds)?;
    if args.batch == 0 {
        return Err(CliError::input("--batch must be at least 1"));
    }
    let (points, values) = read_history(&space, &args)?;
    let options = CorsOptions {
        kernel: match args.kernel {
            KernelArg::Cubic => SurrogateKernel::Cubic,
            KernelArg::ThinPlate => SurrogateKernel::ThinPlate,
        },
        transform: match args.transform {
            TransformArg::Identity => Transform::Identity,
            TransformArg::Log => Transform::Log,
            TransformArg::ShiftedLog => Transform::ShiftedLog,
            TransformArg::MedianCap => Transform::MedianCap,
        },
        initial: match args.initial {
            InitialArg::Auto => InitialDesign::Auto,
            InitialArg::Design => InitialDesign::Design,
            InitialArg::Existing => InitialDesign::Existing,
        },
        design_size: args.design_size,
        ..CorsOptions::with_seed(args.seed)
    };
    let options = CorsOptions {
        local_region: if args.global_only {
            None
        } else {
            args.local_half_width.or(options.local_region)
        },
        restart: (args.restart || args.restart_patience.is_some()).then(|| Restart {
            patience: args.restart_patience,
            ..Restart::default()
        }),
        ..options
    };
    options
        .validate(space.dim())
        .map_err(|e| CliError::input(format!("option: {e}")))?;
    let history = args.history.display().to_string();
    let mut study = Cors::from_history(space.clone(), options, &points, &values, args.initial_rows)
        .map_err(|e| CliError::input(format!("{history}: {e}")))?;
    let next = study
        .suggest(args.batch)
        .map_err(|e| CliError::input(format!("{history}: {e}")))?;
    let table = Table {
        header: space.names().iter().map(|s| s.to_string()).collect(),
        rows: next.iter().map(|s| s.x.clone()).collect(),
        lines: Vec::new(),
    };
    let (out, name) = writer(args.out.as_deref())?;
    table.write(out, &name)?;
    Ok(())
}
