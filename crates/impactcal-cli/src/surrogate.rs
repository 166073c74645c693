//! `impactcal surrogate fit|predict`: ERBF and RBF surrogates of sampled responses.

use std::path::{Path, PathBuf};

use clap::{Args as ClapArgs, Subcommand, ValueEnum};
use impactcal::core::{Samples, Table, TableOptions, read_samples, read_text};
use impactcal::erbf::{ErbfError, ErrorSummary, LooMethod, ResponseSurrogate, SurrogateKind};

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
}

impl From<Kind> for SurrogateKind {
    fn from(k: Kind) -> Self {
        match k {
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
    let model = ResponseSurrogate::fit(
        &space,
        a.kind.into(),
        params.points.as_ref(),
        outputs.to_matrix().as_ref(),
        outputs.header().to_vec(),
    )
    .map_err(|e| fit_error(e, &params, &a.files.params))?;
    eprintln!(
        "surrogate ({:?}): {} samples, {} parameters, {} outputs",
        model.kind(),
        model.n_samples(),
        space.dim(),
        outputs.header().len()
    );
    eprintln!(
        "training residual max|f(x_k) - F_k| / max|F| = {:.3e}",
        model.training_residual()
    );
    match model.loo_errors(LooMethod::Auto) {
        Ok(e) => {
            let s = ErrorSummary::new(e.as_ref(), model.values());
            eprintln!(
                "leave-one-out error: rms {:.6e}, max {:.6e}, rms / std(F) {:.4}",
                s.rms, s.max_abs, s.relative_rms
            );
        }
        Err(e) => eprintln!("leave-one-out error: not available ({e})"),
    }
    write_json(&model, a.out.as_deref())
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
