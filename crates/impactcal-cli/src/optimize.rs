//! `impactcal optimize suggest`: the next points of a CORS-RBF study, stateless over a
//! history file, so that a shell loop of suggest, run, append drives a study with any
//! simulator; `impactcal optimize answer`: the best sample and the smoothed surrogate's
//! answer of such a history.

use std::io::Write;
use std::path::PathBuf;

use clap::{Args as ClapArgs, Subcommand, ValueEnum};
use faer::Mat;
use impactcal::core::ParamGuard;
use impactcal::core::{CoreError, ParameterSpace, Samples, Table, TableOptions};
use impactcal::cors::{
    AdaptiveRegion, CandidateDecay, Converged, Cors, CorsOptions, InitialDesign, Perturbation,
    RepeatRefinement, Restart, SurrogateKernel, Transform,
};

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
    Suggest(Box<SuggestArgs>),
    /// Print the answers of a study from its history (JSON): the best sample (lowest
    /// objective seen) and the evaluated point of lowest smoothed-surrogate value, the
    /// better answer under a noisy objective.
    Answer(AnswerArgs),
}

/// Arguments of `impactcal optimize answer`.
#[derive(ClapArgs, Debug)]
struct AnswerArgs {
    /// Bounds file (`name,lower,upper,nominal[,unit]`).
    #[arg(long)]
    bounds: PathBuf,
    /// History file: the parameter columns and `objective` (empty for a failed run).
    #[arg(long)]
    history: PathBuf,
    /// The surrogate's kernel (linear tail).
    #[arg(long, value_enum, default_value_t = KernelArg::Cubic)]
    kernel: KernelArg,
    /// Output file (default: standard output).
    #[arg(long)]
    out: Option<PathBuf>,
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

/// What a converged adaptive local region does, on the command line.
#[derive(ValueEnum, Clone, Copy, Debug)]
enum ConvergedArg {
    Restore,
    Escape,
    Restart,
    RestartOutside,
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
    /// failed run), one row per evaluation in the order they were run. A file that does not
    /// exist (in a directory that does) means no evaluation yet; a header without rows too.
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
    /// Start each run with a local cycle (around the best point) instead of a whole-box one.
    #[arg(long, conflicts_with = "global_only")]
    local_first: bool,
    /// Move the local cycles to the next basin after this many evaluations without
    /// improvement (default 60).
    #[arg(long, conflicts_with_all = ["global_only", "no_local_escape"])]
    local_escape: Option<usize>,
    /// Keep the local cycles around the best point (no basin escape).
    #[arg(long)]
    no_local_escape: bool,
    /// Every second whole-box cycle searches instead around the best point outside the box
    /// of this half-width around the first local centre (default 0.5).
    #[arg(long, conflicts_with_all = ["global_only", "no_second_region"])]
    second_region: Option<f64>,
    /// No second region: the cycles alternate between the whole box and the first centre's.
    #[arg(long)]
    no_second_region: bool,
    /// DYCORS-style coordinate perturbation in the local cycles: each coordinate of a
    /// candidate around the best point moves with a probability that falls over this many
    /// evaluations after the initial set (default: the `--budget` less the initial set, or
    /// 300 without a budget).
    #[arg(long, conflicts_with = "no_perturbation")]
    perturb_horizon: Option<usize>,
    /// The study's budget: the rows the history will hold in all (existing runs and design
    /// included). The perturbation's probability then falls to its floor at the budget,
    /// as DYCORS's does; it stops nothing. Keep it fixed for the whole study.
    #[arg(long)]
    budget: Option<usize>,
    /// Move every coordinate of the candidates around the best point.
    #[arg(long)]
    no_perturbation: bool,
    /// Take a refinement step (beta <= 0.05) again while it lowers the best value by more
    /// than 0.1 %, at most this many times in a row (default 6).
    #[arg(long, conflicts_with = "no_repeat_refinement")]
    repeat_refinement: Option<usize>,
    /// Advance the search pattern by one step at every evaluation (no repeated refinement).
    #[arg(long)]
    no_repeat_refinement: bool,
    /// Let the number of quasi-random candidates fall from 300 d to this many per dimension
    /// over `--candidate-horizon` evaluations after the initial set (off by default).
    #[arg(long)]
    candidate_floor: Option<usize>,
    /// The horizon of `--candidate-floor` (default 300).
    #[arg(long, requires = "candidate_floor", default_value_t = 300)]
    candidate_horizon: usize,
    /// SRBF's weight cycle (comma-separated weights in [0, 1], e.g. 0.3,0.5,0.8,0.95) in
    /// place of the distance constraint (off by default).
    #[arg(long, value_delimiter = ',')]
    merit_weights: Option<Vec<f64>>,
    /// DYCORS's adaptive step on the local region's half-width (doubled after 3
    /// improvements, halved after max(5, d) evaluations without, converged below 2^-6 of
    /// its start), and what its convergence does: restore the width, move to the next basin,
    /// restart the run, or restart keeping the earlier points outside the converged basins
    /// (off by default).
    #[arg(long, value_enum, conflicts_with = "global_only")]
    adaptive_region: Option<ConvergedArg>,
    /// Evaluations without improvement that halve the adaptive width (default max(5, d)).
    #[arg(long, requires = "adaptive_region")]
    adaptive_shrink_after: Option<usize>,
    /// Halvings after which the adaptive width has converged (default 6).
    #[arg(long, requires = "adaptive_region", default_value_t = 6)]
    adaptive_halvings: u32,
    /// Keep the local box at its half-width and adapt only the Gaussian candidates' widths.
    #[arg(long, requires = "adaptive_region")]
    adaptive_sigma_only: bool,
    /// Write the points here instead of stdout.
    #[arg(long)]
    out: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    match args.command {
        OptimizeCommand::Suggest(a) => suggest(*a),
        OptimizeCommand::Answer(a) => answer(a),
    }
}

fn kernel(arg: KernelArg) -> SurrogateKernel {
    match arg {
        KernelArg::Cubic => SurrogateKernel::Cubic,
        KernelArg::ThinPlate => SurrogateKernel::ThinPlate,
    }
}

/// `impactcal optimize answer`: both answers as JSON, rows counted from 1 after the header.
fn answer(args: AnswerArgs) -> Result<(), CliError> {
    let space = ParameterSpace::read_csv(&args.bounds)?;
    let (points, values) = read_history(&space, &args.history)?;
    let history = args.history.display().to_string();
    let options = CorsOptions {
        kernel: kernel(args.kernel),
        ..CorsOptions::default()
    };
    let study = Cors::from_history(space.clone(), options, points.as_ref(), &values, None)
        .map_err(|e| CliError::from(e).context(&history))?;
    let best = study.best().ok_or_else(|| {
        CliError::input(format!(
            "{history}: no successful evaluation to answer from"
        ))
    })?;
    let sample_row = study
        .evaluations()
        .iter()
        .position(|e| std::ptr::eq(e, best))
        .unwrap_or(0);
    let surrogate = study
        .surrogate_answer()
        .map_err(|e| CliError::from(e).context(&history))?
        .ok_or_else(|| {
            CliError::input(format!(
                "{history}: the successful evaluations hold fewer than {} distinct points \
                 spanning the space, too few for the smoothed surrogate",
                space.dim() + 2
            ))
        })?;
    let named = |x: &[f64]| {
        space
            .names()
            .iter()
            .zip(x)
            .map(|(n, v)| (n.to_string(), serde_json::json!(v)))
            .collect::<serde_json::Map<_, _>>()
    };
    let doc = serde_json::json!({
        "best_sample": {
            "row": sample_row + 1,
            "parameters": named(&best.x),
            "objective": best.value,
        },
        "surrogate": {
            "row": surrogate.index + 1,
            "parameters": named(&surrogate.x),
            "objective": surrogate.observed,
            "predicted": surrogate.predicted,
            "smoothing": surrogate.smoothing,
            "loo_rmse": surrogate.loo_rmse,
        },
    });
    let (mut out, name) = writer(args.out.as_deref())?;
    let text =
        serde_json::to_string_pretty(&doc).map_err(|e| CliError::io(format!("{name}: {e}")))?;
    writeln!(out, "{text}").map_err(|e| CliError::io(format!("{name}: {e}")))?;
    Ok(())
}

/// Reads the history: the parameters (by name, any column order) and the objectives. Only
/// a file that does not exist, in a directory that does, is a study without evaluations;
/// any other failure to read it (a missing directory, a directory in its place, an empty
/// or malformed file) is reported.
fn read_history(
    space: &ParameterSpace,
    path: &std::path::Path,
) -> Result<(Mat<f64>, Vec<f64>), CliError> {
    match std::fs::metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound && parent_exists(path) => {
            return Ok((Mat::zeros(0, space.dim()), Vec::new()));
        }
        Err(source) => {
            return Err(CoreError::Io {
                path: path.display().to_string(),
                source,
            }
            .into());
        }
        Ok(_) => {}
    }
    let options = TableOptions {
        allow_missing: true,
        allow_no_rows: true,
    };
    let table = Table::read(path, options)?;
    let mut samples = table.samples(space, &["objective"])?;
    check_inside(space, &table, &samples)?;
    let values = samples.also.pop().unwrap_or_default();
    Ok((samples.points, values))
}

/// The first history value outside its bounds, as a positioned error (line and column of
/// the file); the optimiser would otherwise name only the point's index. The rule is the
/// optimiser's own ([`Parameter::admits`](impactcal::core::Parameter::admits)).
fn check_inside(space: &ParameterSpace, table: &Table, samples: &Samples) -> Result<(), CliError> {
    for (i, &line) in samples.lines.iter().enumerate() {
        for (j, p) in space.parameters().iter().enumerate() {
            let v = samples.points[(i, j)];
            if !p.admits(v) {
                return Err(CoreError::Csv {
                    file: table.source().to_string(),
                    row: line,
                    column: table.column_index(&p.name).map_or(0, |c| c + 1),
                    message: format!(
                        "parameter `{}` = {v} lies outside its bounds [{}, {}]",
                        p.name, p.lower, p.upper
                    ),
                }
                .into());
            }
        }
    }
    Ok(())
}

/// Whether the directory that would hold `path` exists (the current directory for a bare
/// file name).
fn parent_exists(path: &std::path::Path) -> bool {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.is_dir(),
        _ => true,
    }
}

fn suggest(args: SuggestArgs) -> Result<(), CliError> {
    let space = ParameterSpace::read_csv(&args.bounds)?;
    if args.batch == 0 {
        return Err(CliError::input("--batch must be at least 1"));
    }
    let (points, values) = read_history(&space, &args.history)?;
    let options = CorsOptions {
        kernel: kernel(args.kernel),
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
        local_first: args.local_first,
        local_escape: if args.no_local_escape {
            None
        } else {
            args.local_escape.or(options.local_escape)
        },
        second_region: if args.no_second_region {
            None
        } else {
            args.second_region.or(options.second_region)
        },
        perturbation: if args.no_perturbation {
            None
        } else {
            args.perturb_horizon
                .map(|horizon| Perturbation {
                    horizon: Some(horizon),
                })
                .or(options.perturbation)
        },
        repeat_refinement: if args.no_repeat_refinement {
            None
        } else {
            args.repeat_refinement
                .map(|max_repeats| RepeatRefinement {
                    max_repeats,
                    ..RepeatRefinement::default()
                })
                .or(options.repeat_refinement)
        },
        candidate_decay: args.candidate_floor.map(|min_per_dim| CandidateDecay {
            min_per_dim,
            horizon: args.candidate_horizon,
        }),
        merit_weights: args.merit_weights,
        budget: args.budget,
        adaptive_region: args.adaptive_region.map(|on| AdaptiveRegion {
            shrink_after: args.adaptive_shrink_after,
            halvings: args.adaptive_halvings,
            on_converged: match on {
                ConvergedArg::Restore => Converged::Restore,
                ConvergedArg::Escape => Converged::Escape,
                ConvergedArg::Restart => Converged::Restart,
                ConvergedArg::RestartOutside => Converged::RestartOutside,
            },
            shrink_box: !args.adaptive_sigma_only,
            ..AdaptiveRegion::default()
        }),
        ..options
    };
    let options = options
        .check()
        .map_err(|e| CliError::from(e).context("option"))?;
    let history = args.history.display().to_string();
    let mut study = Cors::from_history(
        space.clone(),
        options,
        points.as_ref(),
        &values,
        args.initial_rows,
    )
    .map_err(|e| CliError::from(e).context(&history))?;
    let next = study
        .suggest(args.batch)
        .map_err(|e| CliError::from(e).context(&history))?;
    for (k, s) in next.iter().enumerate() {
        if let Some(reason) = s.fill_reason.as_ref().filter(|r| r.is_failure()) {
            eprintln!(
                "impactcal: warning: point {} is space-filling, not a CORS point: {reason}",
                k + 1
            );
        }
    }
    let table = Table::new(
        space.names().iter().map(|s| s.to_string()).collect(),
        next.iter().map(|s| s.x.clone()).collect(),
    )?;
    let (out, name) = writer(args.out.as_deref())?;
    table.write(out, &name)?;
    Ok(())
}
