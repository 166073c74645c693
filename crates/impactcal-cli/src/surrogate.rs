//! `impactcal surrogate fit|predict`: ERBF and RBF surrogates of sampled responses.

use std::path::{Path, PathBuf};

use clap::{Args as ClapArgs, Subcommand, ValueEnum};
use impactcal::core::{Samples, Table, TableOptions, read_samples, read_text};
use impactcal::erbf::{
    ErbfError, FitOptions, LOO_ROUND_OFF, LooMethod, OutputBasis, ResponseSurrogate, Selection,
    SurrogateKind, Tuning,
};

use impactcal::erbf::{ComponentOptions, RadialFunction, SurrogateModel};

use crate::error::CliError;
use crate::output::{write_json, writer};
use crate::samples::SampleFiles;

/// Fit a surrogate to samples, or predict with a saved one.
#[derive(ClapArgs, Debug)]
pub struct Args {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Fit a surrogate: prints the training residual and the leave-one-out error to stderr
    /// and writes the model as JSON.
    Fit(FitArgs),
    /// Predict with a saved model at new parameter values.
    Predict(PredictArgs),
}

/// Surrogate kinds on the command line.
#[derive(ValueEnum, Clone, Copy, Debug)]
enum Kind {
    /// Extended RBF (Mullur and Messac; n_t = 4, gamma = 0.15, r_c = 0.15).
    Erbf,
    /// Gaussian RBF (r_c = 0.15 in scaled inputs), no tail.
    Gaussian,
    /// Cubic RBF with a linear tail.
    Cubic,
    /// Thin-plate spline with a linear tail.
    ThinPlate,
    /// Multiquadric RBF (c = 0.15 in scaled inputs) with a constant tail.
    Multiquadric,
    /// The classic RBF kind, shape parameter and smoothing with the smallest
    /// leave-one-out error, chosen per output (or per shape coordinate).
    Auto,
}

/// Output representations on the command line.
#[derive(ValueEnum, Clone, Copy, Debug, Default)]
enum Basis {
    /// Every output column.
    #[default]
    Full,
    /// Coordinates on the impact shapes of the training histories (one surrogate per
    /// coordinate, histories rebuilt when predicted).
    Shapes,
}

/// How `--auto` and `--kind auto` pick among their candidates.
#[derive(ValueEnum, Clone, Copy, Debug, Default)]
enum Pick {
    /// The lowest leave-one-out error.
    #[default]
    MinLoo,
    /// The smoothest candidate within one standard error of the lowest leave-one-out
    /// error (paired over the samples).
    OneSe,
    /// Nested cross-validation: the kernel and whether to smooth by the held-out error of
    /// five outer folds, the width and smoothing within them by leave-one-out.
    Nested,
}

impl From<Kind> for SurrogateKind {
    fn from(k: Kind) -> Self {
        match k {
            Kind::Auto => SurrogateKind::Cubic,
            Kind::Erbf => SurrogateKind::Erbf,
            Kind::Gaussian => SurrogateKind::Gaussian,
            Kind::Cubic => SurrogateKind::Cubic,
            Kind::ThinPlate => SurrogateKind::ThinPlate,
            Kind::Multiquadric => SurrogateKind::Multiquadric,
        }
    }
}

#[derive(ClapArgs, Debug)]
struct FitArgs {
    /// The training runs: bounds (which scale the inputs), parameter samples and responses
    /// (for example the samples of a time history).
    #[command(flatten)]
    files: SampleFiles,
    /// Surrogate kind.
    #[arg(long, value_enum, default_value = "erbf")]
    kind: Kind,
    /// Fit every output column, or the coordinates of the histories on their impact shapes.
    #[arg(long, value_enum, default_value = "full")]
    basis: Basis,
    /// Impact shapes to keep with `--basis shapes` (default: the fewest whose truncation
    /// error stays below a quarter of the surrogate's leave-one-out error).
    #[arg(long)]
    shapes: Option<usize>,
    /// Choose the shape parameter (Gaussian and multiquadric width, ERBF's r_c) and the
    /// smoothing by leave-one-out, per output (or per shape coordinate).
    #[arg(long)]
    auto: bool,
    /// How `--auto` and `--kind auto` pick a candidate: the lowest leave-one-out error
    /// (default), the smoothest within one standard error of it, or by nested
    /// cross-validation.
    #[arg(long, value_enum, default_value = "min-loo")]
    select: Pick,
    /// Where to write the model (JSON); stdout when absent.
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(ClapArgs, Debug)]
struct PredictArgs {
    /// A model written by `impactcal surrogate fit`.
    #[arg(long)]
    model: PathBuf,
    /// Parameter values: a header of parameter names (exactly the model's), one row per
    /// query.
    #[arg(long)]
    params: PathBuf,
    /// Where to write the predictions (CSV with the model's output names); stdout when
    /// absent.
    #[arg(long)]
    out: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    match args.command {
        Command::Fit(a) => fit(a),
        Command::Predict(a) => predict(a),
    }
}

fn fit(a: FitArgs) -> Result<(), CliError> {
    let (space, params, outputs) = a.files.read()?;
    let basis = match (a.basis, a.shapes) {
        (Basis::Full, None) => OutputBasis::Full,
        (Basis::Full, Some(_)) => {
            return Err(CliError::input("--shapes needs --basis shapes".to_string()));
        }
        (Basis::Shapes, count) => OutputBasis::Shapes { count },
    };
    let tuning = match (a.kind, a.auto) {
        (Kind::Auto, _) => Tuning::Kinds,
        (_, true) => Tuning::Parameters,
        (_, false) => Tuning::Off,
    };
    let options = FitOptions {
        kind: a.kind.into(),
        basis,
        tuning,
        selection: match a.select {
            Pick::OneSe => Selection::OneStandardError,
            Pick::MinLoo => Selection::MinimumLoo,
            Pick::Nested => Selection::Nested,
        },
    };
    let model = ResponseSurrogate::fit_with(
        &space,
        params.points.as_ref(),
        outputs.to_matrix(),
        outputs.header().to_vec(),
        &options,
    )
    .map_err(|e| fit_error(e, &params, &a.files.params))?;
    eprintln!(
        "surrogate ({:?}{}): {} samples, {} parameters, {} outputs",
        model.kind(),
        describe(&model),
        model.n_samples(),
        space.dim(),
        outputs.header().len()
    );
    eprintln!(
        "training residual max|f(x_k) - F_k| / max|F| = {:.3e}",
        model.training_residual()
    );
    report_loo(&model);
    write_json(&model, a.out.as_deref())
}

/// What a component model chose, for the summary line.
fn describe(model: &ResponseSurrogate) -> String {
    let SurrogateModel::Components(c) = model.model() else {
        return String::new();
    };
    let mut out = String::new();
    if let Some(b) = c.basis() {
        out += &format!(
            ", {} impact shapes, truncation error {:.2e}",
            b.len(),
            b.truncation_error(b.len())
        );
    }
    let options = c.column_options();
    if options.len() <= MAX_LISTED {
        let names: Vec<String> = options.iter().map(describe_options).collect();
        out += &format!(
            "; per {}: {}",
            if c.basis().is_some() {
                "shape"
            } else {
                "output"
            },
            names.join(", ")
        );
    }
    out
}

fn describe_options(o: &ComponentOptions) -> String {
    match o {
        ComponentOptions::Erbf(e) => {
            format!("erbf r_c={:.3} smoothing={:.2e}", e.rc, e.smoothing)
        }
        ComponentOptions::Rbf(r) => {
            let shape = match r.radial {
                RadialFunction::Gaussian { width } => format!(" width={width:.3}"),
                RadialFunction::Multiquadric { c } => format!(" c={c:.3}"),
                _ => String::new(),
            };
            format!(
                "{:?}{shape} smoothing={:.2e}",
                SurrogateKind::of(o),
                r.smoothing
            )
        }
    }
}

/// Outputs listed one per line in the summaries (more are pooled).
const MAX_LISTED: usize = 20;

/// Prints the leave-one-out error, beside the linear trend's, and warns where the model
/// is worse than the trend (beyond round-off, [`LOO_ROUND_OFF`]).
fn report_loo(model: &ResponseSurrogate) {
    let cmp = match model.loo_against_trend(LooMethod::Auto) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("leave-one-out error: not available ({e})");
            return;
        }
    };
    let s = cmp.summary;
    let pooled = if s.relative_rms.is_nan() {
        "undefined (every output is constant over the samples)".to_string()
    } else {
        relative(s.relative_rms)
    };
    eprintln!(
        "leave-one-out error: rms {:.6e}, max {:.6e}, rms / std(F) {pooled}",
        s.rms, s.max_abs
    );
    let names = model.output_names();
    if names.len() <= MAX_LISTED {
        for (c, name) in names.iter().enumerate() {
            if cmp.model[c].is_nan() {
                eprintln!("  {name}: constant over the samples; the surrogate reproduces it");
            } else {
                eprintln!(
                    "  {name}: leave-one-out rms / std {}, linear trend {}",
                    relative(cmp.model[c]),
                    relative(cmp.trend[c])
                );
            }
        }
    } else {
        eprintln!(
            "linear trend leave-one-out rms / std(F) {} (pooled over {} outputs)",
            relative(cmp.pooled_trend),
            names.len()
        );
    }
    let worse = cmp.worse_than_trend();
    if names.len() <= MAX_LISTED {
        for c in worse {
            if cmp.trend[c] < LOO_ROUND_OFF {
                eprintln!(
                    "warning: {}: a linear trend reproduces this output to round-off \
                     ({:.1e} of std) where the surrogate's leave-one-out error is {} of std: \
                     the output is linear in the parameters; a linear model, or --kind cubic \
                     or thin-plate (their linear tail reproduces it), fits it exactly",
                    names[c],
                    cmp.trend[c],
                    relative(cmp.model[c])
                );
            } else {
                eprintln!(
                    "warning: {}: the leave-one-out error ({} of std) is {:.2}x that of a \
                     linear trend ({}): the surrogate fits noise or its width does not suit \
                     the samples; try --auto, --kind auto, or a linear model",
                    names[c],
                    relative(cmp.model[c]),
                    cmp.model[c] / cmp.trend[c],
                    relative(cmp.trend[c])
                );
            }
        }
    } else if !worse.is_empty() || cmp.pooled_worse_than_trend() {
        eprintln!(
            "warning: the leave-one-out error is worse than a linear trend's on {} of {} \
             outputs (pooled {} against {} of std); try --auto or --kind auto",
            worse.len(),
            names.len(),
            relative(cmp.pooled_model),
            relative(cmp.pooled_trend)
        );
    }
}

/// A relative error for the summaries: four decimals, small values in exponent form so that
/// round-off does not print as `0.0000`, `undefined` for `NaN` (too few samples for the
/// linear trend).
fn relative(x: f64) -> String {
    if x.is_nan() {
        "undefined".into()
    } else if x > 0.0 && x < 1e-3 {
        format!("{x:.2e}")
    } else {
        format!("{x:.4}")
    }
}

fn predict(a: PredictArgs) -> Result<(), CliError> {
    let (text, name) = read_text(&a.model)?;
    let model: ResponseSurrogate = serde_json::from_str(&text).map_err(|e| {
        CliError::input(format!(
            "{name}: not a surrogate model written by `impactcal surrogate fit`: {e}"
        ))
    })?;
    let params = read_samples(&a.params, model.space(), &[], TableOptions::default())?;
    let x = &params.points;
    let outside: Vec<usize> = (0..x.nrows())
        .filter(|&i| {
            let row: Vec<f64> = x.row(i).iter().copied().collect();
            model.is_outside(&row)
        })
        .collect();
    if let Some(&first) = outside.first() {
        eprintln!(
            "warning: {} of {} query rows lie outside the bounds (first at line {} of {}); \
             the surrogate extrapolates there",
            outside.len(),
            x.nrows(),
            params.lines.get(first).copied().unwrap_or(0),
            a.params.display()
        );
    }
    let y = model
        .predict_batch(x.as_ref())
        .map_err(|e| CliError::from(e).context(a.params.display()))?;
    let table = Table::from_matrix(model.output_names().to_vec(), y.as_ref())?;
    let (out, name) = writer(a.out.as_deref())?;
    Ok(table.write(out, &name)?)
}

/// Maps sample indices in a fit error to lines of the samples file.
fn fit_error(e: ErbfError, params: &Samples, path: &Path) -> CliError {
    let line = |k: usize| params.lines.get(k).copied().unwrap_or(k + 2);
    match e {
        ErbfError::DuplicateSamples {
            first,
            second,
            distance,
            ..
        } => CliError::input(format!(
            "{}: the samples on lines {} and {} are duplicates (scaled distance {distance:.3e}); \
             remove or merge one of them",
            path.display(),
            line(first),
            line(second)
        )),
        other => other.into(),
    }
}
