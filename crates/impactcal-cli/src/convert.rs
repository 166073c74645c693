//! `impactcal convert`: measured data and LS-DYNA results into wide CSV on a uniform time
//! base.

use std::path::PathBuf;

use clap::{Args as ClapArgs, ValueEnum};
use impactcal::core::NodalQuantity;
use impactcal::core::{Histories, IsoMme, TestRecord};
use impactcal::runner::{Binout, read_nodout};

use crate::error::CliError;

/// The nodal quantity read from a `nodout` file.
#[derive(ValueEnum, Clone, Copy, Debug, Default)]
pub enum NodoutQuantity {
    /// Displacement.
    Displacement,
    /// Velocity.
    #[default]
    Velocity,
    /// Acceleration.
    Acceleration,
}

/// Arguments of `impactcal convert`.
#[derive(ClapArgs, Debug)]
#[command(group(clap::ArgGroup::new("source").required(true).args(["isomme", "csv", "binout", "nodout"])))]
pub struct Args {
    /// An ISO-MME data set: its folder, its .mme file or a .zip archive.
    #[arg(long)]
    pub isomme: Option<PathBuf>,
    /// A CSV record `time,<label>,...` whose time steps may vary (resampled linearly onto its
    /// median step).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// LS-DYNA's `binout` (LSDA) file; its continuations `binout%001`, ... and, for a name
    /// ending in four digits (`binout0000`), its per-process siblings are read with it.
    #[arg(long)]
    pub binout: Option<PathBuf>,
    /// The binout branch to convert (`nodout`, `glstat`, `matsum`, `rwforc/forces`, ...).
    #[arg(long, requires = "binout")]
    pub branch: Option<String>,
    /// Print the branches of the binout with their variables (items per output time) and
    /// the number of output times, instead of converting.
    #[arg(long, requires = "binout")]
    pub list: bool,
    /// LS-DYNA's ASCII `nodout` file.
    #[arg(long)]
    pub nodout: Option<PathBuf>,
    /// The quantity taken from the nodout.
    #[arg(long, value_enum, default_value_t, requires = "nodout")]
    pub quantity: NodoutQuantity,
    /// The nodes taken from the nodout, in this order (default: all).
    #[arg(long, value_delimiter = ',', requires = "nodout")]
    pub nodes: Vec<u64>,
    /// Channels to keep, several separated by commas: for ISO-MME the channel codes (`*`
    /// and `?` as wildcards), for binout variable names (`x_velocity`) or labels
    /// (`167.x_velocity`); default: all.
    #[arg(long, value_delimiter = ',')]
    pub channels: Vec<String>,
    /// Output CSV (`time,<label>,...`).
    #[arg(long, required_unless_present = "list")]
    pub out: Option<PathBuf>,
}

/// The branches of a binout, their variables and output times, one branch a line.
fn list(b: &Binout) -> Result<(), CliError> {
    for branch in b.branches() {
        let vars = b.variables(&branch)?;
        let times = b.branch(&branch, &[]).map(|r| r.times.len()).unwrap_or(0);
        let v: Vec<String> = vars.iter().map(|(n, k)| format!("{n} ({k})")).collect();
        println!("{branch}: {times} output times; {}", v.join(", "));
    }
    Ok(())
}

/// The histories of a binout branch or a nodout file, with their notes.
fn lsdyna(args: &Args) -> Result<Option<(Histories, Vec<String>)>, CliError> {
    if let Some(path) = &args.binout {
        let b = Binout::open(path)?;
        if args.list {
            list(&b)?;
            return Ok(None);
        }
        let branch = args.branch.as_deref().ok_or_else(|| {
            CliError::input(format!(
                "--binout needs --branch (or --list); {} has: {}",
                path.display(),
                b.branches().join(", ")
            ))
        })?;
        let (h, note) = b.histories(branch, &args.channels)?;
        return Ok(Some((
            h,
            note.map(|n| format!("{}: {branch}: {n}", path.display()))
                .into_iter()
                .collect(),
        )));
    }
    if let Some(path) = &args.nodout {
        if !args.channels.is_empty() {
            return Err(CliError::input(
                "--channels applies to --isomme and --binout; give --nodes for a nodout",
            ));
        }
        let q = match args.quantity {
            NodoutQuantity::Displacement => NodalQuantity::Displacement,
            NodoutQuantity::Velocity => NodalQuantity::Velocity,
            NodoutQuantity::Acceleration => NodalQuantity::Acceleration,
        };
        let nodes = (!args.nodes.is_empty()).then_some(args.nodes.as_slice());
        let (h, note) = read_nodout(path, q, nodes)?;
        return Ok(Some((
            h,
            note.map(|n| format!("{}: {n}", path.display()))
                .into_iter()
                .collect(),
        )));
    }
    Err(CliError::input(
        "give --isomme, --csv, --binout or --nodout",
    ))
}

/// Runs the subcommand: writes the CSV and lists the channels, their units and every default
/// applied on stderr.
pub fn run(args: Args) -> Result<(), CliError> {
    let (histories, notes) = match (&args.isomme, &args.csv) {
        (None, None) => match lsdyna(&args)? {
            Some(r) => r,
            None => return Ok(()),
        },
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
    };
    for n in &notes {
        eprintln!("note: {n}");
    }
    let out = args
        .out
        .as_ref()
        .ok_or_else(|| CliError::input("--out is needed to convert"))?;
    histories.write_csv(out)?;
    eprintln!(
        "wrote {} channels x {} samples to {}",
        histories.channels(),
        histories.samples(),
        out.display()
    );
    Ok(())
}
