//! `impactcal simulate`: run a keyword deck with the built-in shell solver.

use std::io::IsTerminal;
use std::path::PathBuf;

use clap::{Args as ClapArgs, ValueEnum};
use impactcal::shell::keyword::read_deck;
use impactcal::shell::{Quantity, ShellError, Simulation};

use crate::error::CliError;

/// The nodal quantity written to `--out`.
#[derive(ValueEnum, Clone, Copy, Debug, Default)]
pub enum QuantityArg {
    /// Velocity.
    #[default]
    Velocity,
    /// Displacement from the initial position.
    Displacement,
    /// Acceleration.
    Acceleration,
}

/// Arguments of `impactcal simulate`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// The keyword deck (`.k`).
    #[arg(long)]
    pub deck: PathBuf,
    /// Write the nodal histories of *DATABASE_HISTORY_NODE here (wide CSV, labels
    /// `<node>.<x|y|z>`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write the energies and the wall force here (wide CSV).
    #[arg(long)]
    pub energies: Option<PathBuf>,
    /// The nodal quantity written to `--out`.
    #[arg(long, value_enum, default_value_t)]
    pub quantity: QuantityArg,
    /// Number of threads of the element loop (results do not depend on it).
    #[arg(long)]
    pub threads: Option<usize>,
}

fn shell_error(e: ShellError) -> CliError {
    match e {
        ShellError::Unstable { .. } | ShellError::Io { .. } => CliError::Failure(e.to_string()),
        _ => CliError::Input(e.to_string()),
    }
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    let deck = read_deck(&args.deck).map_err(shell_error)?;
    for w in &deck.warnings {
        eprintln!("impactcal: warning: {w}");
    }
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = args.threads {
        if n == 0 {
            return Err(CliError::Input("--threads must be at least 1".into()));
        }
        builder = builder.num_threads(n);
    }
    let pool = builder
        .build()
        .map_err(|e| CliError::Failure(format!("cannot start the thread pool: {e}")))?;
    let result = pool.install(|| -> Result<_, ShellError> {
        let mut sim = Simulation::new(&deck.model)?;
        if std::io::stderr().is_terminal() {
            let bar = indicatif::ProgressBar::new(1000);
            bar.set_style(
                indicatif::ProgressStyle::with_template(
                    "{bar:40} {percent:>3}% t = {msg} ({elapsed} elapsed, {eta} left)",
                )
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            let r = sim.run_with_progress(|p| {
                bar.set_position((1000.0 * p.time / p.end_time).min(1000.0) as u64);
                bar.set_message(format!("{:.4e}, cycle {}", p.time, p.cycle));
            });
            bar.finish_and_clear();
            r
        } else {
            sim.run()
        }
    });
    let result = result.map_err(shell_error)?;
    let q = match args.quantity {
        QuantityArg::Velocity => Quantity::Velocity,
        QuantityArg::Displacement => Quantity::Displacement,
        QuantityArg::Acceleration => Quantity::Acceleration,
    };
    if let Some(path) = &args.out {
        let h = result.histories(q).ok_or_else(|| {
            CliError::Input(format!(
                "{}: --out needs history nodes (*DATABASE_HISTORY_NODE)",
                args.deck.display()
            ))
        })?;
        h.write_csv(path)?;
    }
    if let Some(path) = &args.energies {
        result.energies.write_csv(path)?;
    }
    let s = &result.summary;
    eprintln!(
        "impactcal: {} shells, {} cycles to t = {:.4e}; time step {:.3e} (first {:.3e}, max {:.3e}); \
         energy ratio {:.4}; hourglass/internal {:.2}%; peak wall force {:.4e}",
        s.elements,
        s.cycles,
        s.end_time,
        s.dt_min,
        s.dt_first,
        s.dt_max,
        s.energy_ratio,
        100.0 * s.hourglass_share,
        s.peak_wall_force
    );
    Ok(())
}
