//! `impactcal simulate`: run a keyword deck, or the built-in parametric airframe, with the
//! built-in shell solver.

use std::io::IsTerminal;
use std::path::PathBuf;

use clap::{Args as ClapArgs, ValueEnum};
use impactcal::core::NodalQuantity;
use impactcal::shell::airframe::{Airframe, AirframeOptions, AirframeValues, MeshDensity};
use impactcal::shell::keyword::{Deck, read_deck};
use impactcal::shell::{Energies, ShellError, ShellModel, Simulation};

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

/// A built-in model.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum BuiltIn {
    /// The parametric light-helicopter airframe (`impactcal airframe --list`).
    Airframe,
}

/// Mesh density of the built-in airframe.
#[derive(ValueEnum, Clone, Copy, Debug, Default)]
pub enum MeshArg {
    /// About 2,000 shells.
    #[default]
    Coarse,
    /// About 6,000 shells.
    Medium,
    /// At least 20,000 shells.
    Fine,
}

impl From<MeshArg> for MeshDensity {
    fn from(m: MeshArg) -> Self {
        match m {
            MeshArg::Coarse => MeshDensity::Coarse,
            MeshArg::Medium => MeshDensity::Medium,
            MeshArg::Fine => MeshDensity::Fine,
        }
    }
}

/// The model a command runs: a keyword deck, or the built-in airframe with its settings.
#[derive(ClapArgs, Debug)]
#[command(group(clap::ArgGroup::new("source").required(true).args(["deck", "model"])))]
pub struct Source {
    /// The keyword deck (`.k`).
    #[arg(long)]
    pub deck: Option<PathBuf>,
    /// A built-in model instead of a deck.
    #[arg(long, value_enum)]
    pub model: Option<BuiltIn>,
    /// Mesh density of the built-in airframe.
    #[arg(long, value_enum, default_value_t, requires = "model")]
    pub mesh: MeshArg,
    /// Set a quantity of the built-in airframe, `<part>.<field>=<value>` or
    /// `<global>=<value>` (repeatable; `impactcal airframe --list` shows the names).
    #[arg(long = "set", value_name = "NAME=VALUE", requires = "model")]
    pub set: Vec<String>,
    /// Simulated time of the built-in airframe in seconds (0.08 by default).
    #[arg(long, requires = "model")]
    pub end_time: Option<f64>,
}

impl Source {
    /// The built-in airframe with the `--mesh` and `--end-time` options, and the values
    /// with the `--set` assignments.
    pub fn airframe(&self) -> Result<(Airframe, AirframeValues), CliError> {
        let mut options = AirframeOptions::new(self.mesh.into());
        if let Some(t) = self.end_time {
            options.end_time = t;
            options.output_interval = options.output_interval.min(t);
        }
        let airframe = Airframe::new(options)?;
        let mut values = AirframeValues::nominal();
        for a in &self.set {
            values.assign_in_range(a)?;
        }
        Ok((airframe, values))
    }

    /// The deck, with its warnings printed on stderr.
    pub fn deck(&self, path: &std::path::Path) -> Result<Deck, CliError> {
        let deck = read_deck(path)?;
        for w in &deck.warnings {
            eprintln!("impactcal: warning: {w}");
        }
        Ok(deck)
    }

    /// The deck's model, with its warnings printed on stderr.
    pub fn deck_model(&self, path: &std::path::Path) -> Result<ShellModel, CliError> {
        Ok(self.deck(path)?.model)
    }
}

/// Arguments of `impactcal simulate`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// The model to run.
    #[command(flatten)]
    pub source: Source,
    /// Write the nodal histories of *DATABASE_HISTORY_NODE (for the airframe: its sensor
    /// nodes) here (wide CSV, labels `<node>.<x|y|z>`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write the global energies (LS-DYNA's glstat quantities) and the walls' total force
    /// here (wide CSV).
    #[arg(long)]
    pub energies: Option<PathBuf>,
    /// Write the force of each rigid wall on the structure here, sampled at the output
    /// interval as the mean over each interval (wide CSV, columns `<wall id>.fx|fy|fz|f`,
    /// `f` the normal force).
    #[arg(long)]
    pub wall_forces: Option<PathBuf>,
    /// Write the energies of each part here (wide CSV, columns
    /// `<part>.internal|kinetic|hourglass|damping`).
    #[arg(long)]
    pub part_energies: Option<PathBuf>,
    /// Write the velocity of each part's centre of mass here (LS-DYNA's matsum rigid-body
    /// velocities; wide CSV, columns `<part>.vx|vy|vz`).
    #[arg(long)]
    pub part_velocities: Option<PathBuf>,
    /// Write the energy of each contact interface here (wide CSV, columns
    /// `<interface id>.energy|friction`).
    #[arg(long)]
    pub contact_energies: Option<PathBuf>,
    /// Write the force of each contact interface here, sampled at the output interval as
    /// the mean over each interval (wide CSV, columns `<interface id>.fx|fy|fz|fn`: the
    /// resultant on the slave side, zero for a single-surface contact, and the sum of the
    /// normal force over its contacts).
    #[arg(long)]
    pub contact_forces: Option<PathBuf>,
    /// The nodal quantity written to `--out`.
    #[arg(long, value_enum, default_value_t)]
    pub quantity: QuantityArg,
    /// Stop after this many cycles (a quick check that a model runs; the outputs end
    /// there).
    #[arg(long)]
    pub end_cycles: Option<u64>,
    /// Number of threads of the element loop (results do not depend on it).
    #[arg(long)]
    pub threads: Option<usize>,
}

/// The model to run and a name for messages: the deck, or the built-in airframe with the
/// `--set` values.
fn load(args: &Args) -> Result<(ShellModel, String), CliError> {
    if let Some(path) = &args.source.deck {
        return Ok((args.source.deck_model(path)?, path.display().to_string()));
    }
    let (airframe, values) = args.source.airframe()?;
    let model = airframe.model(&values)?;
    Ok((model, "the airframe".into()))
}

/// A thread pool of `--threads` threads (rayon's default when absent).
pub fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool, CliError> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        if n == 0 {
            return Err(CliError::input("--threads must be at least 1"));
        }
        builder = builder.num_threads(n);
    }
    builder
        .build()
        .map_err(|e| CliError::failure(format!("cannot start the thread pool: {e}")))
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    let (mut model, name) = load(&args)?;
    if let Some(n) = args.end_cycles {
        model.control.end_cycles = n;
    }
    let pool = thread_pool(args.threads)?;
    let started = std::time::Instant::now();
    let result = pool.install(|| -> Result<_, ShellError> {
        let mut sim = Simulation::new(&model)?;
        for (id, n, deepest) in sim.initial_penetrations() {
            if n > 0 {
                eprintln!(
                    "impactcal: warning: contact interface {id}: {n} nodes start inside a segment \
                     (deepest {deepest:.4e}); these penetrations are kept as references that only \
                     further penetration acts against (nodes are not moved)"
                );
            }
        }
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
    let result = result.map_err(|e| CliError::from(e).context(&name))?;
    let wall = started.elapsed().as_secs_f64();
    let q = match args.quantity {
        QuantityArg::Velocity => NodalQuantity::Velocity,
        QuantityArg::Displacement => NodalQuantity::Displacement,
        QuantityArg::Acceleration => NodalQuantity::Acceleration,
    };
    if let Some(path) = &args.out {
        let h = result.histories(q).ok_or_else(|| {
            CliError::input(format!(
                "{name}: --out needs history nodes (*DATABASE_HISTORY_NODE)"
            ))
        })?;
        h.write_csv(path)?;
    }
    if let Some(path) = &args.energies {
        result.energies.write_csv(path)?;
    }
    let optional = [
        (
            &args.wall_forces,
            result.walls.as_ref(),
            "--wall-forces needs a rigid wall",
        ),
        (
            &args.contact_energies,
            result.contacts.as_ref(),
            "--contact-energies needs a contact interface",
        ),
        (
            &args.contact_forces,
            result.contact_forces.as_ref(),
            "--contact-forces needs a contact interface",
        ),
    ];
    for (path, histories, need) in optional {
        if let Some(path) = path {
            let h =
                histories.ok_or_else(|| CliError::input(format!("{name}: {need} in the model")))?;
            h.write_csv(path)?;
        }
    }
    if let Some(path) = &args.part_energies {
        result.part_energies.write_csv(path)?;
    }
    if let Some(path) = &args.part_velocities {
        result.part_velocities.write_csv(path)?;
    }
    let s = &result.summary;
    eprintln!(
        "impactcal: {} shells, {} cycles to t = {:.4e}; time step {:.3e} (first {:.3e}, max {:.3e}); \
         energy ratio {:.4}; {}; peak wall force {:.4e}{}{}; \
         {:.2} s wall time on {} threads ({:.3} us per element-cycle)",
        s.elements,
        s.cycles,
        s.end_time,
        s.dt_min,
        s.dt_first,
        s.dt_max,
        s.energy_ratio,
        hourglass_message(&s.energies, s.hourglass_share),
        s.peak_wall_force,
        wall_peaks(&s.wall_peaks),
        contact_message(result.contacts.as_ref()),
        wall,
        pool.current_num_threads(),
        1e6 * wall / (s.cycles.max(1) as f64 * s.elements.max(1) as f64)
    );
    Ok(())
}

/// Each contact interface's final energy and friction share, when there are interfaces.
fn contact_message(h: Option<&impactcal::core::Histories>) -> String {
    let Some(h) = h else {
        return String::new();
    };
    let last = h.samples().saturating_sub(1);
    let each: Vec<String> = (0..h.channels() / 2)
        .map(|k| {
            let id = h.labels()[2 * k].trim_end_matches(".energy");
            format!(
                "interface {id} {:.4e} (friction {:.4e})",
                h.value(2 * k, last),
                h.value(2 * k + 1, last)
            )
        })
        .collect();
    format!("; contact energy: {}", each.join(", "))
}

/// Each wall's sampled peak, when there are several walls.
fn wall_peaks(peaks: &[(u64, f64)]) -> String {
    if peaks.len() < 2 {
        return String::new();
    }
    let each: Vec<String> = peaks
        .iter()
        .map(|(id, f)| format!("wall {id} {f:.4e}"))
        .collect();
    format!(" ({})", each.join(", "))
}

/// The hourglass share of the internal energy, or a note that the internal energy is
/// negligible (below 1e-6 of the initial energy: a share of it would mean nothing).
fn hourglass_message(e: &Energies, share: f64) -> String {
    let scale = e.initial.abs().max(e.kinetic.abs());
    if e.internal > 1e-6 * scale {
        format!("hourglass/internal {:.2}%", 100.0 * share)
    } else {
        format!(
            "internal energy negligible ({:.3e}, initial {:.3e}): no hourglass share",
            e.internal, e.initial
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hourglass_share_is_printed_only_for_a_real_internal_energy() {
        let mut e = Energies {
            initial: 100.0,
            kinetic: 90.0,
            internal: 10.0,
            ..Energies::default()
        };
        assert_eq!(hourglass_message(&e, 0.0312), "hourglass/internal 3.12%");
        e.internal = 1e-9;
        let m = hourglass_message(&e, 0.5);
        assert!(m.starts_with("internal energy negligible"), "{m}");
    }
}
