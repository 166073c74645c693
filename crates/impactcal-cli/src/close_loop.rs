//! `impactcal close-loop`: the closed loop of a model against a test, from a TOML file.
//!
//! ```toml
//! [model]
//! kind = "drop-tower"            # the built-in fast impact model; or, as in a study file:
//!                                # airframe = "coarse" (+ end_time) or deck = "model.k"
//! set = { v0 = 4.0 }             # held quantities at the calibration test's condition
//!
//! [space]                        # airframe and decks, as in a study file: the declared
//! preset = "table2"              # parameters (or bounds = "bounds.csv"); every other
//!                                # quantity of the model is a candidate effect
//!
//! [test]
//! data = "test.csv"              # wide CSV, or an ISO-MME data set
//! map = "map.csv"                # optional
//! cfc = 1000                     # optional
//! sigma = 0.5                    # optional: measurement noise, every channel
//!
//! [holdout]                      # optional: a test at another condition, never fitted
//! data = "holdout.csv"
//! set = { v0 = 5.5 }
//!
//! [budget]
//! ensemble = 8                   # jitter runs measuring the model's own noise
//! reconcile = 24                 # CORS runs of the first calibration
//! recalibrate = 24               # CORS runs of each recalibration
//! seed = 1
//!
//! [loop]                         # optional: the other loop options
//! candidates = ["damping", "added_mass"]
//! alpha = 0.01
//!
//! [executor]                     # optional, as in a study file
//! kind = "processes"             # "local" (default) | "processes" | "slurm"
//! jobs = 2
//!
//! [batch]                        # optional
//! retries = 2                    # further attempts of a failing run
//! ```
//!
//! With `kind = "processes"` or `"slurm"`, each run is `impactcal loop-point --config <this
//! file>` in its own directory: it rebuilds the model from this file and the run's
//! `params.json` (the declared parameters, the candidates added, the holdout's condition).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use clap::Args as ClapArgs;
use impactcal::calibrate::closeloop::document::report;
use impactcal::calibrate::closeloop::{Holdout, LoopOptions, LoopResult, Verdict, run_loop_on};
use impactcal::calibrate::study::{StudyOptions, TestData, Worker};
use impactcal::core::drop_tower::DropTower;
use impactcal::core::enrich::rebuild;
use impactcal::core::{Cfc, ChannelMap, Enrichable, Histories};
use impactcal::runner::Cancel;
use impactcal::runner::config::{BatchSection, ExecutorSection};
use serde::Deserialize;

use crate::error::CliError;
use crate::output::write_text;
use crate::simulate::thread_pool;
use crate::study::{
    Built, Config as StudyConfig, ModelConfig as StudyModel, PointArgs, Progress, SpaceConfig,
    TestConfig as StudyTest, point_solver, read_record, read_test, resolve, retries_of,
};

/// Arguments of `impactcal close-loop`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// The loop file (TOML: `[model]`, `[test]`, `[holdout]`, `[budget]`, `[loop]`).
    #[arg(long)]
    pub config: PathBuf,
    /// Output folder: the run journal, `loop.json`, `report.html`, `report.md`. Running the
    /// same loop again in the same folder reuses the runs that finished.
    #[arg(long)]
    pub out: PathBuf,
    /// Number of threads (runs go in parallel; results do not depend on it).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Memory the loop may use (`2G`, `512M`, bytes; K/M/G/T are powers of 1024); default:
    /// what the machine has available. A stage whose estimate does not fit stops the loop
    /// before it allocates (exit 2), naming the stage and what to change; the journal keeps
    /// every finished run.
    #[arg(long, value_parser = crate::size::parse_bytes)]
    pub max_memory: Option<u64>,
}

/// The loop file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// The model.
    pub model: ModelConfig,
    /// Deck quantities under the loop's names (decks only, as in a study file).
    #[serde(default)]
    pub parameters: BTreeMap<String, String>,
    /// The declared parameters (airframe and decks, as in a study file).
    #[serde(default)]
    pub space: SpaceConfig,
    /// The calibration test.
    pub test: TestConfig,
    /// The holdout test.
    pub holdout: Option<HoldoutConfig>,
    /// Run budgets and seed.
    #[serde(default)]
    pub budget: Budget,
    /// The other options of the loop.
    #[serde(default, rename = "loop")]
    pub options: LoopOptions,
    /// Where the runs happen (default: in this process), as in a study file.
    pub executor: Option<ExecutorSection>,
    /// Retries, as in a study file.
    pub batch: Option<BatchSection>,
}

/// `[model]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelConfig {
    /// The built-in model: `drop-tower`.
    pub kind: Option<String>,
    /// The built-in airframe's mesh density (`coarse`, `medium`, `fine`).
    pub airframe: Option<String>,
    /// A keyword deck.
    pub deck: Option<PathBuf>,
    /// Simulated time of the airframe (s).
    pub end_time: Option<f64>,
    /// Held quantities at the calibration test's condition.
    #[serde(default)]
    pub set: BTreeMap<String, f64>,
}

/// `[test]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TestConfig {
    /// Wide CSV or an ISO-MME data set.
    pub data: PathBuf,
    /// Channel map `test_label,model_label[,gain]`.
    pub map: Option<PathBuf>,
    /// CFC class applied to test and runs.
    pub cfc: Option<u32>,
    /// Measurement noise standard deviation of every channel.
    pub sigma: Option<f64>,
}

/// `[holdout]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HoldoutConfig {
    /// The holdout test's data.
    pub data: PathBuf,
    /// Its condition, as held quantities of the model.
    pub set: BTreeMap<String, f64>,
}

/// `[budget]`.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Budget {
    /// Jitter runs.
    pub ensemble: Option<usize>,
    /// CORS runs of the first calibration.
    pub reconcile: Option<usize>,
    /// CORS runs of each recalibration.
    pub recalibrate: Option<usize>,
    /// Seed.
    pub seed: Option<u64>,
}

/// Reads a loop file; returns it with its name for messages.
fn read_config(path: &Path) -> Result<(Config, String), CliError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| CliError::io(format!("{}: {e}", path.display())))?;
    let name = path.display().to_string();
    let config: Config = toml::from_str(&text).map_err(|e| {
        CliError::input(format!(
            "{name}: {}",
            e.to_string()
                .split_whitespace()
                .collect::<Vec<_>>()
                .join(" ")
        ))
    })?;
    Ok((config, name))
}

/// The worker of a loop file whose `[executor]` runs processes: `impactcal loop-point` on
/// this file in each run's directory. `None` in process.
fn worker(config: &Config, path: &Path) -> Result<Option<Worker>, CliError> {
    let retries = retries_of(config.batch.as_ref())?;
    let executor = match &config.executor {
        None | Some(ExecutorSection::Local) => return Ok(None),
        Some(e) => e.executor(),
    };
    executor.check()?;
    Ok(Some(Worker {
        solver: point_solver("loop-point", path, None)?,
        executor,
        retries,
        cancel: Cancel::new(),
    }))
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    let (config, name) = read_config(&args.config)?;
    let base = args.config.parent().unwrap_or(Path::new("."));
    let mut options = config.options.clone();
    let b = &config.budget;
    options.ensemble = b.ensemble.unwrap_or(options.ensemble);
    options.reconcile = b.reconcile.unwrap_or(options.reconcile);
    options.recalibrate = b.recalibrate.unwrap_or(options.recalibrate);
    options.seed = b.seed.unwrap_or(options.seed);
    options.sigma = config.test.sigma.or(options.sigma);
    options.max_memory = args.max_memory;
    let model = build_model(&config, base, &name)?;
    let test = read_test(&resolve(base, &config.test.data))?;
    let map = config
        .test
        .map
        .as_ref()
        .map(|m| ChannelMap::read(resolve(base, m)))
        .transpose()?;
    let cfc = config.test.cfc.map(Cfc::from_class).transpose()?;
    let holdout = match &config.holdout {
        Some(h) => Some((
            read_test(&resolve(base, &h.data))?,
            h.set.clone().into_iter().collect::<Vec<_>>(),
        )),
        None => None,
    };
    let worker = worker(&config, &args.config).map_err(|e| e.context(&name))?;
    if let Some(w) = &worker {
        let handler = w.cancel.clone();
        // A second handler cannot be installed (tests call `run` more than once): Ctrl-C
        // then keeps its default action, which loses nothing either.
        let _ = ctrlc::set_handler(move || handler.cancel());
    }
    let pool = thread_pool(args.threads)?;
    let result = pool
        .install(|| {
            let (h, out) = (holdout.as_ref(), &args.out);
            let w = worker.as_ref();
            match &model {
                LoopModel::DropTower(m, d) => {
                    close(m, d, &test, map.as_ref(), cfc, h, &options, out, w)
                }
                LoopModel::Study(Built::Airframe(m, _), d) => {
                    close(&**m, d, &test, map.as_ref(), cfc, h, &options, out, w)
                }
                LoopModel::Study(Built::Deck(m), d) => {
                    close(&**m, d, &test, map.as_ref(), cfc, h, &options, out, w)
                }
                LoopModel::Study(Built::Solver, _) => Err(CliError::input(
                    "[solver]: the closed loop needs a model that lists its candidate effects",
                )),
            }
        })
        .map_err(|e| e.context(&name))?;
    finish(&result, &args.out)
}

/// The model of a loop file, with its description (which enters the loop's fingerprint).
enum LoopModel {
    /// The built-in drop tower.
    DropTower(DropTower, String),
    /// The airframe or a deck, built as a study file builds it.
    Study(Built, String),
}

/// Builds the model of a loop file: the drop tower from `kind`, the airframe or a deck as
/// a study file does (`[model]`, `[space]`, `[parameters]`).
fn build_model(config: &Config, base: &Path, name: &str) -> Result<LoopModel, CliError> {
    let m = &config.model;
    match (&m.kind, &m.airframe, &m.deck) {
        (Some(k), None, None) if k == "drop-tower" => {
            if config.space.preset.is_some()
                || config.space.bounds.is_some()
                || !config.parameters.is_empty()
                || m.end_time.is_some()
            {
                return Err(CliError::input(format!(
                    "{name}: [space], [parameters] and end_time apply to the airframe and \
                     decks; the drop tower declares modulus and k_contact"
                )));
            }
            let set: Vec<(String, f64)> = m.set.clone().into_iter().collect();
            let model = DropTower::new()
                .at_condition(&set)
                .map_err(|e| CliError::from(e).context(format!("{name}: [model] set")))?;
            Ok(LoopModel::DropTower(model, format!("drop-tower {set:?}")))
        }
        (Some(k), None, None) => Err(CliError::input(format!(
            "{name}: [model] kind = \"{k}\": unknown (the built-in model is \"drop-tower\")"
        ))),
        (None, Some(_), None) | (None, None, Some(_)) => {
            let study = StudyConfig {
                model: Some(StudyModel {
                    airframe: m.airframe.clone(),
                    deck: m.deck.clone(),
                    end_time: m.end_time,
                    set: m.set.clone(),
                }),
                solver: None,
                executor: None,
                batch: None,
                parameters: config.parameters.clone(),
                space: SpaceConfig {
                    preset: config.space.preset.clone(),
                    bounds: config.space.bounds.clone(),
                },
                test: StudyTest {
                    data: config.test.data.clone(),
                    map: config.test.map.clone(),
                    cfc: config.test.cfc,
                    sigma: config.test.sigma,
                },
                study: StudyOptions::default(),
            };
            let (built, description) =
                crate::study::build_model(&study, base).map_err(|e| e.context(name))?;
            Ok(LoopModel::Study(built, description))
        }
        _ => Err(CliError::input(format!(
            "{name}: [model]: give one of kind = \"drop-tower\", airframe or deck"
        ))),
    }
}

/// Runs the loop of any enrichable `model` in `out` (its runs on `worker`, or in process).
#[allow(clippy::too_many_arguments)]
pub fn close<M: Enrichable>(
    model: &M,
    description: &str,
    test: &Histories,
    map: Option<&ChannelMap>,
    cfc: Option<Cfc>,
    holdout: Option<&(Histories, Vec<(String, f64)>)>,
    options: &LoopOptions,
    out: &Path,
    worker: Option<&Worker>,
) -> Result<LoopResult, CliError> {
    std::fs::create_dir_all(out).map_err(|e| CliError::io(format!("{}: {e}", out.display())))?;
    let data = TestData {
        histories: test,
        map,
        cfc,
    };
    let h = holdout.map(|(histories, set)| Holdout {
        histories,
        set: set.as_slice(),
    });
    let progress = Progress::new();
    let result = run_loop_on(model, description, data, h, options, out, &progress, worker);
    progress.done();
    Ok(result?)
}

/// Writes `loop.json` and the report, and prints the verdict.
pub fn finish(result: &LoopResult, out: &Path) -> Result<(), CliError> {
    let doc = report(result);
    let files = write_result(result, &doc, out)?;
    for line in &doc.lead {
        eprintln!("{line}");
    }
    let verdict = match result.verdict {
        Verdict::NoModelFormError => "no-model-form-error",
        Verdict::Attributed => "attributed",
        Verdict::Unattributed => "unattributed",
    };
    eprintln!(
        "verdict: {verdict}; wrote {} and {}",
        out.join("loop.json").display(),
        files.html.display()
    );
    Ok(())
}

/// Runs the model of a loop file at the point of a run's `params.json` and writes its
/// histories: what a process-pool or Slurm executor runs for each of the loop's runs. The
/// model is rebuilt from the file as the loop builds it, then enriched with the candidates
/// the run names and set to the run's condition ([`rebuild`]); a name the model does not
/// know is refused (exit 2), so a loop file edited under a running loop cannot give runs of
/// another model.
pub fn run_point(args: PointArgs) -> Result<(), CliError> {
    let (config, name) = read_config(&args.config)?;
    let base = args.config.parent().unwrap_or(Path::new("."));
    let model = build_model(&config, base, &name)?;
    let record = read_record(&args.params)?;
    let set: Vec<(String, f64)> = record.set.clone().into_iter().collect();
    let params = args.params.display().to_string();
    let (names, values) = (&record.names, &record.values);
    let pool = thread_pool(args.threads)?;
    let h = pool.install(|| match &model {
        LoopModel::DropTower(m, _) => point(m, names, values, &set, &params),
        LoopModel::Study(Built::Airframe(m, _), _) => point(&**m, names, values, &set, &params),
        LoopModel::Study(Built::Deck(m), _) => point(&**m, names, values, &set, &params),
        LoopModel::Study(Built::Solver, _) => Err(CliError::input(
            "loop-point runs the built-in model of a loop file; this one names a [solver]",
        )),
    })?;
    h.write_csv(&args.out)?;
    Ok(())
}

/// The histories of `model` rebuilt with `names` at the condition `set`, at `values`.
fn point<M: Enrichable>(
    model: &M,
    names: &[String],
    values: &[f64],
    set: &[(String, f64)],
    params: &str,
) -> Result<Histories, CliError> {
    let m = rebuild(model, names, set).map_err(|e| CliError::from(e).context(params))?;
    m.space()
        .to_unit(values)
        .map_err(|e| CliError::from(e).context(params))?;
    Ok(m.simulate(values)?)
}

/// Writes `loop.json` and the report document `doc` of `result` into `out`.
pub fn write_result(
    result: &LoopResult,
    doc: &impactcal::calibrate::report::Report,
    out: &Path,
) -> Result<impactcal::calibrate::report::ReportFiles, CliError> {
    let json = serde_json::to_string_pretty(result)
        .map_err(|e| CliError::failure(format!("cannot encode the loop's result: {e}")))?;
    write_text(&(json + "\n"), Some(&out.join("loop.json")))?;
    Ok(impactcal::calibrate::report::write(doc, out)?)
}
