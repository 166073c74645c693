//! `impactcal batch`: run a batch of parameter points through a solver on an executor,
//! from a TOML configuration (see `impactcal_runner::config`).

use std::path::PathBuf;

use clap::Args as ClapArgs;
use impactcal::ErrorKind;
use impactcal::core::{Table, TableOptions};
use impactcal::experiment::BuiltInSolver;
use impactcal::runner::{Batch, BatchConfig, Cancel, Hooks, run_batch_with};
use serde::Serialize;

use crate::error::CliError;

/// Arguments of `impactcal batch`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// The batch configuration (TOML: [batch], [solver], [executor] with its retries).
    #[arg(long)]
    pub config: PathBuf,
    /// The points: a CSV whose header names the parameters, one run per row.
    #[arg(long)]
    pub points: PathBuf,
    /// The output directory: runs in `<out>/runs/<study>/<index>/`, the journal beside
    /// them, `summary.json` at the top.
    #[arg(long)]
    pub out: PathBuf,
}

/// One run in `summary.json`.
#[derive(Serialize)]
struct RunSummary {
    index: usize,
    ok: bool,
    reused: bool,
    attempts: u32,
    /// The histories (our CSV), relative to the output directory.
    result: Option<String>,
    error: Option<String>,
    kind: Option<String>,
}

#[derive(Serialize)]
struct Summary {
    study: String,
    runs: usize,
    succeeded: usize,
    failed: usize,
    reused: usize,
    journal: String,
    results: Vec<RunSummary>,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    let config = BatchConfig::read(&args.config)?;
    let table = Table::read(&args.points, TableOptions::default())?;
    let names = table.header().to_vec();
    let exe = std::env::current_exe()
        .map_err(|e| CliError::failure(format!("cannot find the impactcal program: {e}")))?;
    let solver = config.solver(Some(&exe))?;
    let batch = Batch::new(&args.out, &config.batch.study, solver, names, table.rows())
        .map_err(|e| CliError::from(e).context(args.config.display()))?
        .with_retries(config.executor.retries);
    let cancel = Cancel::new();
    let handler = cancel.clone();
    // A second handler cannot be installed (tests call `run` more than once): then Ctrl-C
    // keeps its default action, which loses nothing either (the journal is on disk).
    let _ = ctrlc::set_handler(move || handler.cancel());
    // Without a command on the local executor, the built-in solver runs in this process.
    let builtin = BuiltInSolver::new(config.solver.quantity);
    let hooks = Hooks {
        in_process: Some(&builtin),
        ..Hooks::default()
    };
    let report = run_batch_with(&batch, &config.executor(), &cancel, hooks)?;
    let root = batch.root().strip_prefix(&args.out).unwrap_or(batch.root());
    let results: Vec<RunSummary> = report
        .runs
        .iter()
        .enumerate()
        .map(|(i, r)| RunSummary {
            index: i,
            ok: r.is_ok(),
            reused: report.reused[i],
            attempts: report.attempts[i],
            result: r.as_ref().ok().map(|_| {
                root.join(i.to_string())
                    .join("result.csv")
                    .display()
                    .to_string()
            }),
            error: r.as_ref().err().map(ToString::to_string),
            kind: r.as_ref().err().map(|e| e.kind().to_string()),
        })
        .collect();
    let failed = results.iter().filter(|r| !r.ok).count();
    let summary = Summary {
        study: batch.study().to_string(),
        runs: results.len(),
        succeeded: results.len() - failed,
        failed,
        reused: report.reused.iter().filter(|&&r| r).count(),
        journal: root.join("journal.jsonl").display().to_string(),
        results,
    };
    let path = args.out.join("summary.json");
    let text = serde_json::to_string_pretty(&summary)
        .map_err(|e| CliError::failure(format!("summary: {e}")))?;
    std::fs::write(&path, text + "\n")
        .map_err(|e| CliError::io(format!("{}: {e}", path.display())))?;
    eprintln!(
        "impactcal: {} runs: {} succeeded ({} reused from the journal), {} failed; summary in {}",
        summary.runs,
        summary.succeeded,
        summary.reused,
        summary.failed,
        path.display()
    );
    let mut failures = report.failures();
    if let Some((_, first)) = failures.next() {
        let all_input = report
            .failures()
            .all(|(_, e)| e.kind() == ErrorKind::BadInput);
        let message = format!(
            "{failed} of {} runs failed; the first: {first}",
            summary.runs
        );
        return Err(if all_input {
            CliError::input(message)
        } else {
            CliError::failure(message)
        });
    }
    Ok(())
}
