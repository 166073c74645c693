//! `impactcal close-loop`: an experiment file's closed loop (the schema, the model and the
//! loop live in the library: `impactcal::experiment`; docs/closed-loop.md).

use impactcal::calibrate::closeloop::{LoopResult, Verdict};

use crate::error::CliError;
use crate::progress::Progress;
use crate::simulate::thread_pool;
use crate::study::Args;

/// Runs `impactcal close-loop`.
pub fn run(args: Args) -> Result<(), CliError> {
    let experiment = args.experiment()?;
    crate::output::check_out_folder(&args.out)?;
    let progress = Progress::new();
    let done =
        thread_pool(args.threads)?.install(|| experiment.close_loop_with(&args.out, &progress));
    progress.done();
    let done = done?;
    crate::output::print_finished(&done, &format!("verdict: {}; ", verdict(&done.result)));
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
