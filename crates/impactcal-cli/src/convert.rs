//! `impactcal convert`: measured data into wide CSV on a uniform time base.

use std::path::PathBuf;

use clap::Args as ClapArgs;
use impactcal::core::{IsoMme, TestRecord};

use crate::error::CliError;

/// Arguments of `impactcal convert`.
#[derive(ClapArgs, Debug)]
#[command(group(clap::ArgGroup::new("source").required(true).args(["isomme", "csv"])))]
pub struct Args {
    /// An ISO-MME data set: its folder, its .mme file or a .zip archive.
    #[arg(long)]
    pub isomme: Option<PathBuf>,
    /// A CSV record `time,<label>,...` whose time steps may vary (resampled linearly onto its
    /// median step).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Channel codes to keep, `*` and `?` as wildcards, several separated by commas
    /// (ISO-MME only; default: all).
    #[arg(long, value_delimiter = ',')]
    pub channels: Vec<String>,
    /// Output CSV (`time,<code>,...`).
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs the subcommand: writes the CSV and lists the channels, their units and every default
/// applied on stderr.
pub fn run(args: Args) -> Result<(), CliError> {
    let (histories, notes) = match (&args.isomme, &args.csv) {
        (Some(path), _) => {
            let set = IsoMme::read(path, &args.channels)?;
            for c in &set.channels {
                eprintln!(
                    "{}  [{}]  {} samples every {:e} s from {} s  ({}, {})",
                    c.code,
                    c.unit,
                    c.values.len(),
                    c.dt,
                    c.start,
                    c.name.as_deref().unwrap_or("no name"),
                    c.encoding
                );
            }
            let (h, mut notes) = set.to_histories()?;
            notes.splice(0..0, set.notes());
            (h, notes)
        }
        (None, Some(path)) => {
            if !args.channels.is_empty() {
                return Err(CliError::input("--channels applies to --isomme only"));
            }
            let record = TestRecord::read(path)?;
            let notes = record
                .resampling
                .iter()
                .map(|r| format!("{}: {r}", path.display()))
                .collect();
            (record.histories, notes)
        }
        (None, None) => return Err(CliError::input("give --isomme or --csv")),
    };
    for n in &notes {
        eprintln!("note: {n}");
    }
    histories.write_csv(&args.out)?;
    eprintln!(
        "wrote {} channels x {} samples to {}",
        histories.channels(),
        histories.samples(),
        args.out.display()
    );
    Ok(())
}
