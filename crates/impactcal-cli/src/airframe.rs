//! `impactcal airframe`: the built-in parametric airframe as a keyword deck, its catalogue
//! of adjustable quantities, and a picture of its parts.

use std::fmt::Write;
use std::path::PathBuf;

use clap::Args as ClapArgs;
use impactcal::shell::airframe::{Airframe, AirframeOptions, AirframeValues, Preset, catalogue};
use impactcal::shell::keyword::write_deck_file;

use crate::error::CliError;
use crate::output::write_text;
use crate::simulate::MeshArg;

/// Arguments of `impactcal airframe`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Mesh density.
    #[arg(long, value_enum, default_value_t)]
    pub mesh: MeshArg,
    /// Write the airframe as an LS-DYNA keyword deck here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print the catalogue of adjustable quantities (name, group, nominal, lower, upper,
    /// unit, presets, meaning) as CSV; `lower..upper` is the study range, which is also the
    /// admissible range of the quantity as a candidate effect of the closed loop.
    #[arg(long)]
    pub list: bool,
    /// Print the names of a preset's parameters (`table1` or `table2`) as a bounds file
    /// (`name,lower,upper,nominal,unit`).
    #[arg(long, value_name = "PRESET")]
    pub preset: Option<String>,
    /// Set a quantity, `<name>=<value>` (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Simulated time written to the deck, in seconds (0.08 by default).
    #[arg(long)]
    pub end_time: Option<f64>,
    /// Write a labelled SVG picture of the parts here.
    #[arg(long)]
    pub svg: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    if args.list {
        write_text(&catalogue_csv(), None)?;
    }
    if let Some(name) = &args.preset {
        let preset = Preset::parse(name)?;
        let space = preset.space()?;
        write_text(&space.to_csv_string(), None)?;
    }
    if args.out.is_none() && args.svg.is_none() {
        if !args.list && args.preset.is_none() {
            return Err(CliError::input(
                "nothing to do: give --out, --svg, --list or --preset",
            ));
        }
        return Ok(());
    }
    let mut options = AirframeOptions::new(args.mesh.into());
    if let Some(t) = args.end_time {
        options.end_time = t;
        options.output_interval = options.output_interval.min(t);
    }
    let airframe = Airframe::new(options)?;
    let mut values = AirframeValues::nominal();
    for a in &args.set {
        values.assign_in_range(a)?;
    }
    if let Some(path) = &args.out {
        let model = airframe.model(&values)?;
        write_deck_file(&model, path)?;
        eprintln!(
            "impactcal: wrote {} ({} shells, {} nodes, {} sensor nodes, total mass {:.4} lbf s^2/in)",
            path.display(),
            airframe.shell_count(),
            airframe.node_count(),
            airframe.sensor_nodes().len(),
            model.total_mass()
        );
    }
    if let Some(path) = &args.svg {
        write_text(&airframe.parts_svg(), Some(path))?;
    }
    Ok(())
}

fn catalogue_csv() -> String {
    let mut s = String::from("name,group,nominal,lower,upper,unit,preset,description\n");
    for a in catalogue() {
        let preset = [Preset::Table1, Preset::Table2]
            .iter()
            .filter(|p| p.names().contains(&a.name.as_str()))
            .map(|p| format!("{p:?}").to_lowercase())
            .collect::<Vec<_>>()
            .join(" ");
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},\"{}\"",
            a.name, a.group, a.nominal, a.lower, a.upper, a.unit, preset, a.description
        );
    }
    s
}
