//! `impactcal close-loop`: an experiment file's closed loop (the schema, the model and the
//! loop live in the library: `impactcal::experiment`; docs/closed-loop.md).

use impactcal::calibrate::closeloop::{LoopResult, Verdict};

use crate::error::CliError;
use crate::simulate::thread_pool;
use crate::study::{Args, Progress};

/// Runs `impactcal close-loop`.
pub fn run(args: Args) -> Result<(), CliError> {
    let experiment = args.experiment()?;
    let progress = Progress::new();
    let done =
        thread_pool(args.threads)?.install(|| experiment.close_loop_with(&args.out, &progress));
    progress.done();
    let done = done?;
    for line in &done.report.lead {
        eprintln!("{line}");
    }
    eprintln!(
        "verdict: {}; wrote {} and {}",
        verdict(&done.result),
        done.json.display(),
        done.files.html.display()
    );
    Ok(())
}

/// The verdict's name as printed.
pub fn verdict(result: &LoopResult) -> &'static str {
    match result.verdict {
        Verdict::NoModelFormError => "no-model-form-error",
        Verdict::Attributed => "attributed",
        Verdict::Unattributed => "unattributed",
    }
}
