//! `impactcal check`: the quality of a measured record before anything uses it.

use std::path::PathBuf;

use clap::Args as ClapArgs;
use impactcal::core::quality::{Accelerations, QualityOptions, check, read_record};
use impactcal::core::testdata::LanlBarRecord;

use crate::error::CliError;
use crate::output::write_json;

/// Arguments of `impactcal check`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// The record: wide CSV (`time,<label>,...`), or a Kolsky-bar record in the Los Alamos
    /// layout (`.raw`: set-up header beside two volt columns).
    #[arg(long)]
    pub test: PathBuf,
    /// The samples before this time (s) are the quiet part (default: found per channel).
    #[arg(long)]
    pub pre_trigger: Option<f64>,
    /// Which channels are accelerations, for the drift check: `all`, `none`, or labels
    /// separated by commas (default: labels containing `acc`, ISO-MME codes of dimension
    /// AC).
    #[arg(long)]
    pub acceleration: Option<String>,
    /// Write the JSON (`channels`: `offset`, `noise_std`, `lag1`, `white`, `clipped`,
    /// `spikes`, `drift`, ...) here instead of stdout.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    let name = args.test.display().to_string();
    let (h, faults) = if args.test.extension().is_some_and(|e| e == "raw") {
        (LanlBarRecord::read(&args.test)?.histories, Vec::new())
    } else {
        read_record(&args.test)?
    };
    let accelerations = match args.acceleration.as_deref() {
        None => Accelerations::ByLabel,
        Some("all") => Accelerations::All,
        Some("none") => Accelerations::None,
        Some(list) => {
            let labels: Vec<String> = list.split(',').map(|s| s.trim().to_string()).collect();
            if let Some(l) = labels.iter().find(|l| h.index_of(l).is_none()) {
                return Err(CliError::input(format!(
                    "--acceleration: `{l}` is not a channel of {name} ({})",
                    h.labels().join(", ")
                )));
            }
            Accelerations::Labels(labels)
        }
    };
    let options = QualityOptions {
        pre_trigger: args.pre_trigger,
        accelerations,
    };
    let mut quality = check(&h, &options).map_err(|e| CliError::from(e).context(&name))?;
    quality.time_faults = faults;
    for line in quality.findings() {
        eprintln!("{name}: {line}");
    }
    write_json(&quality, args.out.as_deref())
}
