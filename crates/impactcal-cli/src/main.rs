//! The `impactcal` command: calibration of impact models on CSV files.
//!
//! Each subcommand lives in its own module with an `Args` struct (clap) and a `run`
//! function; this file only registers them. Numerical work happens in the library.

mod airframe;
mod batch;
mod check;
mod close_loop;
mod compare;
mod convert;
mod demo;
mod demo_car_pole;
mod demo_loop;
mod error;
mod expand;
mod filter;
mod metrics;
mod noise;
mod optimize;
mod output;
mod place;
mod progress;
mod sample;
mod samples;
mod shapes;
mod simulate;
mod size;
mod sobol;
mod study;
mod surrogate;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::error::CliError;

/// Multi-dimensional calibration of impact dynamics models.
#[derive(Parser, Debug)]
#[command(name = "impactcal", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// ERBF and RBF surrogates of sampled responses (whole time histories).
    Surrogate(surrogate::Args),
    /// Impact shapes (SVD) of a histories file: singular values, contributions, shapes and
    /// time functions as JSON.
    Shapes(shapes::Args),
    /// Calibration metric M2: orthogonality and pairing of test and analysis impact shapes.
    Compare(compare::Args),
    /// Expand measured channels to the unmeasured channels of a model through its shapes.
    Expand(expand::Args),
    /// CORS-RBF optimisation of an expensive model driven from the shell.
    Optimize(optimize::Args),
    /// Sensor placement by effective independence (Kammer) on impact shapes or a shape
    /// matrix.
    Place(place::Args),
    /// Run an LS-DYNA keyword deck with the built-in explicit shell solver; write nodal
    /// histories and energies as CSV.
    Simulate(simulate::Args),
    /// The noise a model produces on its own: a jitter ensemble at one point gives the
    /// spread per channel and time and each channel's predictability horizon (JSON).
    Noise(noise::Args),
    /// Space-filling samples (Halton, Sobol', Latin hypercubes) and Saltelli designs.
    Sample(sample::Args),
    /// Sobol' sensitivity indices of every output column.
    Sobol(sobol::Args),
    /// Measured data (an ISO-MME data set, or CSV on a non-uniform time base) into wide CSV.
    Convert(convert::Args),
    /// The quality of a measured record: offsets, noise (level, colour, AR model, lines),
    /// clipped runs, spikes, drift of accelerations, gaps; JSON, one line per finding on
    /// stderr.
    Check(check::Args),
    /// SAE J211 / ISO 6487 channel frequency class filter (CFC 60, 180, 600, 1000).
    Filter(filter::Args),
    /// Curve metrics of a model against a test: relative L2, RMS, peak, Sprague-Geers,
    /// Russell and ISO/TS 18571, per channel, overall and on the norm history Q(t).
    Metrics(metrics::Args),
    /// The built-in parametric helicopter airframe: write it as a keyword deck, list its
    /// adjustable quantities and presets, draw its parts.
    Airframe(airframe::Args),
    /// The calibration study of a model against a test (M1, sensors, M2, surrogates,
    /// sensitivity, CORS-RBF reconciliation) from a TOML study file; runs are journaled.
    Study(study::Args),
    /// Runs the built-in model of an experiment file at a run's `params.json` (declared
    /// parameters, candidates a loop added, condition) and writes its histories: what the
    /// processes and slurm executors run for each of a study's or a loop's runs.
    #[command(alias = "study-point", alias = "loop-point")]
    Point(study::PointArgs),
    /// The source paper's study on the coarse airframe against a test with hidden changes:
    /// Table 1 screened by M1, Table 2 studied and reconciled, the changes revealed; with
    /// `--close-loop`, the closed loop against a test with hidden damping.
    Demo(demo::Args),
    /// Run a batch of parameter points through a solver (in process, a local process pool
    /// or Slurm) from a TOML configuration; journaled, and resumed by running it again.
    Batch(batch::Args),
    /// The closed loop from a TOML file: nuisance terms, noise floor, detection of
    /// model-form error, attribution to the model's candidate effects, enrichment and
    /// recalibration, errors before and after on the test and a holdout; runs are journaled.
    CloseLoop(study::Args),
}

fn run(command: Command) -> Result<(), CliError> {
    match command {
        Command::Surrogate(args) => surrogate::run(args),
        Command::Shapes(a) => shapes::run(a),
        Command::Compare(a) => compare::run(a),
        Command::Expand(a) => expand::run(a),
        Command::Optimize(a) => optimize::run(a),
        Command::Place(a) => place::run(a),
        Command::Simulate(a) => simulate::run(a),
        Command::Noise(a) => noise::run(a),
        Command::Sample(a) => sample::run(a),
        Command::Sobol(a) => sobol::run(a),
        Command::Airframe(a) => airframe::run(a),
        Command::Convert(a) => convert::run(a),
        Command::Check(a) => check::run(a),
        Command::Filter(a) => filter::run(a),
        Command::Metrics(a) => metrics::run(a),
        Command::Study(a) => study::run(a),
        Command::Point(a) => study::run_point(a),
        Command::Demo(a) => demo::run(a),
        Command::Batch(a) => batch::run(a),
        Command::CloseLoop(a) => close_loop::run(a),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("impactcal: error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
