//! The `impactcal` command: calibration of impact models on CSV files.
//!
//! Each subcommand lives in its own module with an `Args` struct (clap) and a `run`
//! function; this file only registers them. Numerical work happens in the library.

mod error;
mod output;
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
}

fn run(command: Command) -> Result<(), CliError> {
    match command {
        Command::Surrogate(args) => surrogate::run(args),
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
