//! `impactcal noise`: the noise a model produces on its own, from a jitter ensemble at one
//! point (per channel and time spread, predictability horizons), as JSON.

use std::path::PathBuf;

use clap::Args as ClapArgs;
use impactcal::core::noise::{JitterOptions, SimulationNoise};
use impactcal::core::{Cfc, GroupHorizon, Model};
use impactcal::shell::DeckModel;
use impactcal::shell::airframe::{AirframeModel, Preset, structural_space};

use crate::error::CliError;
use crate::output::write_json_compact;
use crate::simulate::{Source, thread_pool};

/// The group of a channel label, for the summary.
type Grouping = Box<dyn Fn(&str) -> String>;

/// Arguments of `impactcal noise`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// The model: a deck (every section thickness, material E, yield stress and tangent
    /// modulus and concentrated mass is jittered; the output is the velocity of the
    /// *DATABASE_HISTORY_NODE nodes) or the airframe (every part's t, E, Et, sigy and the
    /// five masses are jittered; the output is the 1,215 sensor velocities).
    #[command(flatten)]
    pub source: Source,
    /// Jitter only the quantities of a preset of the airframe (`table1` or `table2`).
    #[arg(long, requires = "model")]
    pub preset: Option<String>,
    /// Number of jittered runs.
    #[arg(long, default_value_t = 8)]
    pub runs: usize,
    /// Largest relative change of each parameter.
    #[arg(long, default_value_t = 1e-4)]
    pub eps: f64,
    /// Seed of the perturbations.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Filter every run with this CFC class before the spread is formed (60 for structural
    /// velocities); raw histories when absent.
    #[arg(long)]
    pub cfc: Option<u32>,
    /// Fraction of a channel's RMS signal that its spread may reach before the channel
    /// counts as unpredictable (the horizons printed).
    #[arg(long, default_value_t = 0.1)]
    pub fraction: f64,
    /// Number of threads (runs go in parallel; results do not depend on it).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Write the result (a `SimulationNoise`) here as JSON.
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    if !(args.fraction > 0.0 && args.fraction.is_finite()) {
        return Err(CliError::input(format!(
            "--fraction must be positive, got {}",
            args.fraction
        )));
    }
    let mut options = JitterOptions::new(args.runs, args.eps, args.seed);
    options.cfc = args.cfc.map(Cfc::from_class).transpose()?;
    impactcal::core::ParamGuard::check_ref(&options)?;
    let pool = thread_pool(args.threads)?;
    let started = std::time::Instant::now();
    let (noise, group): (SimulationNoise, Grouping) = match &args.source.deck {
        Some(path) => {
            let model = DeckModel::from_deck(args.source.deck(path)?, None)
                .map_err(|e| CliError::input(format!("{}: {e}", path.display())))?;
            let point = model.space().nominal();
            let noise = measure(&pool, &model, &point, &options)?;
            (noise, Box::new(|l: &str| axis(l).to_string()))
        }
        None => {
            let (airframe, values) = args.source.airframe()?;
            let space = match &args.preset {
                Some(p) => Preset::parse(p).and_then(|p| p.space()),
                None => structural_space(),
            }
            .map_err(CliError::input)?;
            let point = space
                .parameters()
                .iter()
                .map(|p| values.get(&p.name))
                .collect::<Result<Vec<f64>, _>>()
                .map_err(CliError::input)?;
            let model = AirframeModel::new(airframe.clone(), space)
                .map_err(CliError::input)?
                .with_base(values);
            let noise = measure(&pool, &model, &point, &options)?;
            let grouping = move |l: &str| {
                let part = l
                    .split('.')
                    .next()
                    .and_then(|n| n.parse().ok())
                    .and_then(|n| airframe.part_of_node(n))
                    .map_or("unknown", |p| p.name());
                format!("{part}.{}", axis(l))
            };
            (noise, Box::new(grouping))
        }
    };
    write_json_compact(&noise, &args.out)?;
    let end = noise.time(noise.samples().saturating_sub(1));
    let windows: Vec<String> = [0.125, 0.25, 0.5, 1.0]
        .iter()
        .map(|f| {
            let until = noise.start + f * (end - noise.start);
            format!(
                "to {until:.4} s: {:.3} %",
                100.0 * noise.relative_spread(until, &[])
            )
        })
        .collect();
    eprintln!(
        "impactcal: {} channels, {} runs about the point (eps {}, {}), {:.1} s; relative \
         spread {}",
        noise.channels(),
        noise.options.runs,
        args.eps,
        args.cfc.map_or("raw".to_string(), |c| format!("CFC {c}")),
        started.elapsed().as_secs_f64(),
        windows.join(", ")
    );
    eprintln!(
        "impactcal: predictability horizons (spread > {} of a channel's RMS), by group:",
        args.fraction
    );
    eprintln!("  group, channels, predictable to the end, first, lower quartile, median (s)");
    let t = |h: Option<f64>| h.map_or("-".to_string(), |v| format!("{v:.4}"));
    for g in noise.horizons_by(args.fraction, group) {
        let GroupHorizon {
            group,
            channels,
            predictable_to_end,
            first,
            quartile,
            median,
            ..
        } = g;
        eprintln!(
            "  {group}, {channels}, {predictable_to_end}, {}, {}, {}",
            t(first),
            t(quartile),
            t(median)
        );
    }
    Ok(())
}

fn measure<M: Model>(
    pool: &rayon::ThreadPool,
    model: &M,
    point: &[f64],
    options: &JitterOptions,
) -> Result<SimulationNoise, CliError> {
    Ok(pool.install(|| SimulationNoise::measure(model, point, options))?)
}

/// The axis of a nodal label `<node>.<x|y|z>` (the whole label otherwise).
fn axis(label: &str) -> &str {
    label.rsplit_once('.').map_or(label, |(_, a)| a)
}
