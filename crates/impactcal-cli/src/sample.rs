//! `impactcal sample`: space-filling and Saltelli designs over a bounds file.

use std::path::PathBuf;

use clap::{Args as ClapArgs, ValueEnum};
use impactcal::core::sampling::{self, Method};
use impactcal::core::{ParameterSpace, Table};
use impactcal::sobol::SaltelliDesign;

use crate::error::CliError;
use crate::output::writer;

/// Arguments of `impactcal sample`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Bounds file: `name,lower,upper,nominal[,unit]`.
    #[arg(long)]
    bounds: PathBuf,
    /// Sampling method. `saltelli` writes the pick-freeze design of `impactcal sobol`
    /// (SALib's row order) built on `--base`.
    #[arg(long, value_enum)]
    method: SampleMethod,
    /// Number of points (for `saltelli`: base rows N; the file has N (d + 2) rows, or
    /// N (2d + 2) with `--second-order`). Use a power of two with Sobol'.
    #[arg(long, default_value_t = 1024)]
    n: usize,
    /// Seed of the scrambling or of the random methods.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Plain Halton or Sobol' instead of the scrambled sequence (Halton as in the source
    /// paper).
    #[arg(long)]
    no_scramble: bool,
    /// Sequence under a `saltelli` design.
    #[arg(long, value_enum, default_value_t = BaseMethod::Sobol)]
    base: BaseMethod,
    /// Add the BA blocks for second-order indices (`saltelli` only).
    #[arg(long)]
    second_order: bool,
    /// Output CSV (header of parameter names); stdout when absent.
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum SampleMethod {
    Halton,
    Sobol,
    Lhs,
    Slhd,
    Random,
    Saltelli,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum BaseMethod {
    Sobol,
    Halton,
    Lhs,
    Random,
}

fn core_method(base: BaseMethod, plain: bool) -> Method {
    match (base, plain) {
        (BaseMethod::Sobol, false) => Method::ScrambledSobol,
        (BaseMethod::Sobol, true) => Method::Sobol,
        (BaseMethod::Halton, false) => Method::ScrambledHalton,
        (BaseMethod::Halton, true) => Method::Halton,
        (BaseMethod::Lhs, _) => Method::LatinHypercube,
        (BaseMethod::Random, _) => Method::Random,
    }
}

/// Runs `impactcal sample`.
pub fn run(args: Args) -> Result<(), CliError> {
    let space = ParameterSpace::read_csv(&args.bounds)?;
    if args.second_order && args.method != SampleMethod::Saltelli {
        return Err(CliError::input(
            "--second-order applies to --method saltelli only",
        ));
    }
    let (points, warnings) = match args.method {
        SampleMethod::Saltelli => {
            let method = core_method(args.base, args.no_scramble);
            let d = SaltelliDesign::generate(&space, args.n, method, args.second_order, args.seed)?;
            (d.points, d.warnings)
        }
        other => {
            let method = match other {
                SampleMethod::Halton => core_method(BaseMethod::Halton, args.no_scramble),
                SampleMethod::Sobol => core_method(BaseMethod::Sobol, args.no_scramble),
                SampleMethod::Lhs => Method::LatinHypercube,
                SampleMethod::Slhd => Method::SymmetricLatinHypercube,
                _ => Method::Random,
            };
            let s = sampling::sample(&space, method, args.n, args.seed)?;
            (s.points, s.warnings)
        }
    };
    for w in &warnings {
        eprintln!("impactcal: warning: {w}");
    }
    let names = space.names().into_iter().map(str::to_string).collect();
    let table = Table::from_matrix(names, points.as_ref())?;
    let (out, name) = writer(args.out.as_deref())?;
    table.write(out, &name)?;
    Ok(())
}
