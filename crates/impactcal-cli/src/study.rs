//! `impactcal study`: the calibration study of a model against a test, from a TOML file.
//!
//! ```toml
//! [model]
//! airframe = "coarse"            # or: deck = "model.k"
//! end_time = 0.025               # airframe only
//! set = { "ground.friction" = 0.3 }
//!
//! [parameters]                   # deck only: study names -> deck quantities
//! belly = "section.3.t"
//!
//! [space]
//! preset = "table2"              # or: bounds = "bounds.csv"
//!
//! [test]
//! data = "test.csv"              # wide CSV, or an ISO-MME data set
//! map = "map.csv"                # optional
//! cfc = 60                       # optional
//! sigma = 0.5                    # optional: measurement noise (else measured)
//!
//! [study]
//! ensemble = 50
//! sensors = 41
//! sensitivity_samples = 1024
//! reconcile_runs = 60
//! seed = 1
//!
//! [executor]                     # optional; the tables `impactcal batch` reads
//! kind = "processes"             # "local" (default) | "processes" | "slurm"
//! jobs = 2
//!
//! [batch]                        # optional
//! retries = 2                    # further attempts of a failing run
//! ```
//!
//! Instead of `[model]`, a `[solver]` table (as in a batch configuration: a deck template
//! and a command) runs an external solver; `[space] bounds` then names its parameters.
//! With `kind = "processes"` or `"slurm"`, a built-in model runs as `impactcal study-point
//! --config <this file>` in each run's directory.

use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use clap::Args as ClapArgs;
use impactcal::calibrate::report::{Report, ReportFiles};
use impactcal::calibrate::study::document::{Geometry, report};
use impactcal::calibrate::study::{
    Executor, InProcess, Observer, Runner, StudyOptions, StudyResult, Subspace, TestData,
    ValidStudyOptions,
};
use impactcal::core::{
    Cfc, ChannelMap, Histories, IsoMme, Model, ParamGuard, Parameter, ParameterSpace, TestRecord,
};
use impactcal::runner::config::{BatchSection, ExecutorSection, SolverSection};
use impactcal::runner::workdir::RunRecord;
use impactcal::runner::{Cancel, OutputSpec, Solver, SolverCommand, fingerprint};
use impactcal::shell::DeckModel;
use impactcal::shell::airframe::{
    Airframe, AirframeModel, AirframeOptions, AirframeValues, MeshDensity, Preset, catalogue,
    space_of,
};
use impactcal::shell::keyword::read_deck;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Deserialize;

use crate::error::CliError;
use crate::output::write_text;
use crate::simulate::thread_pool;

/// Arguments of `impactcal study`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// The study file (TOML: `[model]`, `[space]`, `[test]`, `[study]`).
    #[arg(long)]
    pub config: PathBuf,
    /// Output folder: the run journal, `study.json`. Running the same study again in the
    /// same folder reuses the runs that finished.
    #[arg(long)]
    pub out: PathBuf,
    /// Number of threads (runs go in parallel; results do not depend on it).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Memory the study may use (`2G`, `512M`, bytes; K/M/G/T are powers of 1024);
    /// default: what the machine has available. A stage whose estimate does not fit stops
    /// the study before it allocates (exit 2), naming the stage and what to change.
    #[arg(long, value_parser = crate::size::parse_bytes)]
    pub max_memory: Option<u64>,
}

/// The study file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// The built-in model (or `solver`).
    pub model: Option<ModelConfig>,
    /// An external solver (or `model`), as in a batch configuration.
    pub solver: Option<SolverSection>,
    /// Where the runs happen (default: in this process).
    pub executor: Option<ExecutorSection>,
    /// Retries (the `[batch]` table of a batch configuration; its `study` does not apply).
    pub batch: Option<BatchSection>,
    /// Deck quantities under study names.
    #[serde(default)]
    pub parameters: BTreeMap<String, String>,
    /// The parameter space.
    #[serde(default)]
    pub space: SpaceConfig,
    /// The test.
    pub test: TestConfig,
    /// The study's options.
    #[serde(default)]
    pub study: StudyOptions,
}

/// `[model]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelConfig {
    /// The built-in airframe's mesh density (`coarse`, `medium`, `fine`).
    pub airframe: Option<String>,
    /// A keyword deck.
    pub deck: Option<PathBuf>,
    /// Simulated time of the airframe (s).
    pub end_time: Option<f64>,
    /// Base values of airframe quantities.
    #[serde(default)]
    pub set: BTreeMap<String, f64>,
}

/// `[space]`.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpaceConfig {
    /// `table1` or `table2` (airframe).
    pub preset: Option<String>,
    /// A bounds file `name,lower,upper,nominal[,unit]`.
    pub bounds: Option<PathBuf>,
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
    /// Measurement noise standard deviation of every channel (after the filter); default:
    /// measured on the test.
    pub sigma: Option<f64>,
}

/// A model built from a study file, ready to run.
pub enum Built {
    /// The airframe restricted to the study's quantities, and where its sensors are.
    Airframe(Box<Subspace<AirframeModel>>, Geometry),
    /// A deck restricted to the study's quantities.
    Deck(Box<Subspace<DeckModel>>),
    /// An external solver (no model in this process).
    Solver,
}

/// Everything a study needs besides its options.
pub struct Setup {
    /// The model.
    pub model: Built,
    /// Its description (enters the fingerprint).
    pub description: String,
    /// The test's histories.
    pub test: Histories,
    /// The channel map.
    pub map: Option<ChannelMap>,
    /// The CFC class.
    pub cfc: Option<Cfc>,
    /// Runs through a solver command on an executor (an external solver, or a built-in
    /// model on a process pool or Slurm); `None`: the built-in model in this process.
    pub runner: Option<Runner>,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    let (config, name) = read_config(&args.config)?;
    let base = args.config.parent().unwrap_or(Path::new("."));
    let mut study = config.study.clone();
    if config.test.sigma.is_some() {
        study.sigma = config.test.sigma;
    }
    let options = StudyOptions {
        max_memory: args.max_memory,
        ..study
    }
    .check()
    .map_err(|e| CliError::from(e).context(&name))?;
    let mut setup = setup(&config, base).map_err(|e| e.context(&name))?;
    setup.runner = runner(&config, &args.config, base, &setup).map_err(|e| e.context(&name))?;
    if let Some(r) = &setup.runner {
        let handler = r.cancel.clone();
        // A second handler cannot be installed (tests call `run` more than once): Ctrl-C
        // then keeps its default action, which loses nothing either.
        let _ = ctrlc::set_handler(move || handler.cancel());
    }
    let pool = thread_pool(args.threads)?;
    let result = pool.install(|| execute(&setup, &options, &args.out))?;
    finish(&result, &setup, &args.out)
}

/// Reads a study file; returns it with its name for messages.
fn read_config(path: &Path) -> Result<(Config, String), CliError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| CliError::io(format!("{}: {e}", path.display())))?;
    let name = path.display().to_string();
    let config: Config = toml::from_str(&text)
        .map_err(|e| CliError::input(format!("{name}: {}", one_line(&e.to_string()))))?;
    Ok((config, name))
}

/// Writes `study.json`, the report (`report.html`, `report.md` and its SVG figures) and
/// prints the verdicts.
pub fn finish(result: &StudyResult, setup: &Setup, out: &Path) -> Result<(), CliError> {
    let json = serde_json::to_string_pretty(result)
        .map_err(|e| CliError::failure(format!("cannot encode the study: {e}")))?;
    write_text(&(json + "\n"), Some(&out.join("study.json")))?;
    let doc = study_report(result, setup);
    let files = write_report(&doc, out)?;
    for line in &doc.lead {
        eprintln!("{line}");
    }
    eprintln!(
        "wrote {} and {}",
        out.join("study.json").display(),
        files.html.display()
    );
    Ok(())
}

/// Renders `doc` into `out` (`report.html`, `report.md`, one SVG file per figure).
pub fn write_report(doc: &Report, out: &Path) -> Result<ReportFiles, CliError> {
    Ok(impactcal::calibrate::report::write(doc, out)?)
}

/// The report document of a study (rendered to `report.html` and `report.md`).
pub fn study_report(result: &StudyResult, setup: &Setup) -> Report {
    let geometry = match &setup.model {
        Built::Airframe(_, g) => Some(g),
        Built::Deck(_) | Built::Solver => None,
    };
    report(result, geometry)
}

/// Runs the study of `setup` in `out`.
pub fn execute(
    setup: &Setup,
    options: &ValidStudyOptions,
    out: &Path,
) -> Result<StudyResult, CliError> {
    std::fs::create_dir_all(out).map_err(|e| CliError::io(format!("{}: {e}", out.display())))?;
    let test = TestData {
        histories: &setup.test,
        map: setup.map.as_ref(),
        cfc: setup.cfc,
    };
    let progress = Progress::new();
    let run = |executor: &dyn Executor| {
        impactcal::calibrate::study::run(
            executor,
            &setup.description,
            test,
            options,
            out,
            &progress,
        )
    };
    let result = match (&setup.runner, &setup.model) {
        (Some(r), _) => run(r),
        (None, Built::Airframe(m, _)) => run(&InProcess(m.as_ref())),
        (None, Built::Deck(m)) => run(&InProcess(m.as_ref())),
        (None, Built::Solver) => Err(impactcal::calibrate::CalibrateError::study(
            "[solver]",
            "an external solver needs an executor",
        )),
    };
    progress.done();
    Ok(result?)
}

/// The runner of a study file whose runs go through a solver command: an external
/// `[solver]` on any executor, or the built-in model on a process pool or Slurm (each run
/// `impactcal study-point --config <file>` in its directory). `None` for the built-in model
/// in this process.
fn runner(
    config: &Config,
    path: &Path,
    base: &Path,
    setup: &Setup,
) -> Result<Option<Runner>, CliError> {
    let section = config.executor.clone().unwrap_or(ExecutorSection::Local);
    let retries = retries_of(config.batch.as_ref())?;
    let exe = current_exe()?;
    let solver = match (&config.solver, &section) {
        (Some(s), _) => s.solver(base, path, &section, Some(&exe))?,
        (None, ExecutorSection::Local) => return Ok(None),
        (None, _) => point_solver("study-point", path, Some("velocity"))?,
    };
    let space = match &setup.model {
        Built::Airframe(m, _) => m.space().clone(),
        Built::Deck(m) => m.space().clone(),
        Built::Solver => study_space(config, base)?.ok_or_else(|| {
            CliError::input("[space]: an external solver needs `bounds = \"bounds.csv\"`")
        })?,
    };
    let executor = section.executor();
    executor.check()?;
    Ok(Some(Runner {
        space,
        solver,
        executor,
        retries,
        cancel: Cancel::new(),
    }))
}

/// The further attempts of a failing run from a `[batch]` table (whose `study` does not
/// apply to a study or loop file: its runs go to `<out>/runs/<stage>/`).
///
/// # Errors
/// [`CliError::input`] when `[batch] study` is given.
pub(crate) fn retries_of(batch: Option<&BatchSection>) -> Result<u32, CliError> {
    match batch {
        Some(b) if b.study != BatchSection::default().study => Err(CliError::input(
            "[batch] study does not apply here: the runs go to <out>/runs/<stage>/",
        )),
        Some(b) => Ok(b.retries),
        None => Ok(BatchSection::default().retries),
    }
}

/// This `impactcal` program, which the process-pool and Slurm executors start.
pub(crate) fn current_exe() -> Result<PathBuf, CliError> {
    std::env::current_exe()
        .map_err(|e| CliError::failure(format!("cannot find the impactcal program: {e}")))
}

/// The solver that runs `impactcal <subcommand> --config <file>` in each run's directory
/// (reading the run's `params.json`, writing `out.csv`): how a built-in model of a study
/// or loop file runs on a process pool or Slurm. `unit` is the histories' unit (our CSV
/// does not carry it).
pub(crate) fn point_solver(
    subcommand: &str,
    config: &Path,
    unit: Option<&str>,
) -> Result<Solver, CliError> {
    let exe = current_exe()?;
    let config = std::fs::canonicalize(config)
        .map_err(|e| CliError::io(format!("{}: {e}", config.display())))?;
    let mut output = OutputSpec::csv("out.csv");
    output.unit = unit.map(str::to_string);
    Ok(Solver {
        inputs: Vec::new(),
        command: SolverCommand::Argv(vec![
            exe.display().to_string(),
            subcommand.into(),
            "--config".into(),
            config.display().to_string(),
        ]),
        output,
    })
}

/// Reads the record of a run (`params.json`).
pub(crate) fn read_record(path: &Path) -> Result<RunRecord, CliError> {
    serde_json::from_str(
        &std::fs::read_to_string(path)
            .map_err(|e| CliError::io(format!("{}: {e}", path.display())))?,
    )
    .map_err(|e| CliError::input(format!("{}: {e}", path.display())))
}

/// Arguments of `impactcal study-point`.
#[derive(ClapArgs, Debug)]
pub struct PointArgs {
    /// The study file whose built-in model is run.
    #[arg(long)]
    pub config: PathBuf,
    /// The run's parameters: the `params.json` the runner writes in each run's directory.
    #[arg(long, default_value = "params.json")]
    pub params: PathBuf,
    /// Where the histories go (our wide CSV).
    #[arg(long, default_value = "out.csv")]
    pub out: PathBuf,
    /// Number of threads of the solver.
    #[arg(long)]
    pub threads: Option<usize>,
}

/// Runs the built-in model of a study file at the point of a run's `params.json` and
/// writes its histories: what a process-pool or Slurm executor runs for each point.
pub fn run_point(args: PointArgs) -> Result<(), CliError> {
    let (config, name) = read_config(&args.config)?;
    let base = args.config.parent().unwrap_or(Path::new("."));
    let (model, _) = build_model(&config, base).map_err(|e| e.context(&name))?;
    let record = read_record(&args.params)?;
    if let Some((name, _)) = record.set.iter().next() {
        return Err(CliError::input(format!(
            "{}: `{name}` is set as a condition; a study's runs set none (a loop's runs go to \
             `impactcal loop-point`)",
            args.params.display()
        )));
    }
    let simulate = |m: &dyn Model| -> Result<Histories, CliError> {
        let names = m.space().names();
        if names != record.names {
            return Err(CliError::input(format!(
                "{}: parameters {:?}, but the study's model takes {:?}",
                args.params.display(),
                record.names,
                names
            )));
        }
        m.space().to_unit(&record.values)?;
        Ok(m.simulate(&record.values)?)
    };
    let pool = thread_pool(args.threads)?;
    let h = pool.install(|| match &model {
        Built::Airframe(m, _) => simulate(m.as_ref()),
        Built::Deck(m) => simulate(m.as_ref()),
        Built::Solver => Err(CliError::input(
            "study-point runs the built-in model of a study file; this one names a [solver]",
        )),
    })?;
    h.write_csv(&args.out)?;
    Ok(())
}

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

pub(crate) fn resolve(base: &Path, p: &Path) -> PathBuf {
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        base.join(p)
    }
}

/// Builds the model, reads the test, the map and the CFC class of a study file whose
/// relative paths start at `base`.
///
/// # Errors
/// Bad input naming what is wrong.
pub fn setup(config: &Config, base: &Path) -> Result<Setup, CliError> {
    let (model, description) = build_model(config, base)?;
    let data = resolve(base, &config.test.data);
    let test = read_test(&data)?;
    let map = config
        .test
        .map
        .as_ref()
        .map(|m| ChannelMap::read(resolve(base, m)))
        .transpose()?;
    let cfc = config.test.cfc.map(Cfc::from_class).transpose()?;
    Ok(Setup {
        model,
        description,
        test,
        map,
        cfc,
        runner: None,
    })
}

/// The model of a study file and its description (which enters the study's fingerprint).
pub(crate) fn build_model(config: &Config, base: &Path) -> Result<(Built, String), CliError> {
    let none = ModelConfig {
        airframe: None,
        deck: None,
        end_time: None,
        set: BTreeMap::new(),
    };
    let model = config.model.as_ref().unwrap_or(&none);
    match (&model.airframe, &model.deck, &config.solver) {
        (Some(mesh), None, None) => airframe(config, model, mesh, base),
        (None, Some(deck), None) => deck_model(config, model, &resolve(base, deck), base),
        (None, None, Some(solver)) if config.model.is_none() => external(config, solver, base),
        _ => Err(CliError::input(
            "[model]: give either `airframe = \"coarse\"` or `deck = \"model.k\"`, or a \
             [solver] table instead of [model]",
        )),
    }
}

/// An external solver: its description fingerprints the `[solver]` table and the text of
/// its templates, so that a changed deck or command is another study.
fn external(
    config: &Config,
    solver: &SolverSection,
    base: &Path,
) -> Result<(Built, String), CliError> {
    if !config.parameters.is_empty() {
        return Err(CliError::input(
            "[parameters] maps deck quantities of a built-in deck model; an external solver's \
             parameters are its template's",
        ));
    }
    let mut bytes = serde_json::to_vec(solver).unwrap_or_default();
    for p in std::iter::once(&solver.template).chain(&solver.inputs) {
        let p = resolve(base, p);
        bytes.extend(std::fs::read(&p).map_err(|e| CliError::io(format!("{}: {e}", p.display())))?);
    }
    let description = format!(
        "solver {} ({})",
        solver.template.display(),
        fingerprint(&bytes)
    );
    Ok((Built::Solver, description))
}

/// A test file: an ISO-MME data set (a folder, an `.mme` file or a zip) or wide CSV.
pub(crate) fn read_test(path: &Path) -> Result<Histories, CliError> {
    let is_mme = path.is_dir()
        || path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("mme") || e.eq_ignore_ascii_case("zip"));
    if is_mme {
        let set = IsoMme::read(path, &[])?;
        let (h, notes) = set.to_histories()?;
        notes.iter().for_each(|n| eprintln!("note: {n}"));
        Ok(h)
    } else {
        let record = TestRecord::read(path)?;
        if let Some(r) = &record.resampling {
            eprintln!("note: {}: {r}", path.display());
        }
        Ok(record.histories)
    }
}

fn study_space(config: &Config, base: &Path) -> Result<Option<ParameterSpace>, CliError> {
    match (&config.space.preset, &config.space.bounds) {
        (Some(p), None) => Ok(Some(
            Preset::parse(p)
                .and_then(|p| p.space())
                .map_err(CliError::input)?,
        )),
        (None, Some(b)) => Ok(Some(ParameterSpace::read_csv(resolve(base, b))?)),
        (None, None) => Ok(None),
        (Some(_), Some(_)) => Err(CliError::input(
            "[space]: give `preset` or `bounds`, not both",
        )),
    }
}

fn airframe(
    config: &Config,
    model: &ModelConfig,
    mesh: &str,
    base: &Path,
) -> Result<(Built, String), CliError> {
    if !config.parameters.is_empty() {
        return Err(CliError::input(
            "[parameters] maps deck quantities; the airframe's names are its catalogue's",
        ));
    }
    let mut options = AirframeOptions::new(MeshDensity::parse(mesh).map_err(CliError::input)?);
    if let Some(t) = model.end_time {
        options.end_time = t;
        options.output_interval = options.output_interval.min(t);
    }
    let airframe = Airframe::new(options).map_err(CliError::input)?;
    let mut values = AirframeValues::nominal();
    for (k, v) in &model.set {
        values.set(k, *v).map_err(CliError::input)?;
    }
    let Some(space) = study_space(config, base)? else {
        return Err(CliError::input(
            "[space]: give `preset = \"table1\"|\"table2\"` or `bounds = \"bounds.csv\"`",
        ));
    };
    let names: Vec<String> = catalogue().into_iter().map(|a| a.name).collect();
    let full = space_of(&names).map_err(CliError::input)?;
    let base_point: Vec<f64> = names
        .iter()
        .map(|n| values.get(n))
        .collect::<Result<_, _>>()
        .map_err(CliError::input)?;
    let geometry = geometry_of(&airframe);
    let solver = AirframeModel::new(airframe, full).map_err(CliError::input)?;
    let sub = Subspace::new(solver, space)?.with_base(base_point)?;
    let description = format!(
        "built-in airframe, {mesh} mesh, {} s, set {:?}",
        options.end_time, model.set
    );
    Ok((Built::Airframe(Box::new(sub), geometry), description))
}

/// The airframe's nodes and the position of each sensor channel.
pub fn geometry_of(airframe: &Airframe) -> Geometry {
    let nodes = airframe.node_positions();
    let mut channels = BTreeMap::new();
    for &n in airframe.sensor_nodes() {
        if let Some(at) = usize::try_from(n)
            .ok()
            .and_then(|i| nodes.get(i.wrapping_sub(1)))
        {
            for a in ["x", "y", "z"] {
                channels.insert(format!("{n}.{a}"), *at);
            }
        }
    }
    Geometry {
        points: nodes.to_vec(),
        unit: "in".into(),
        channels,
    }
}

fn deck_model(
    config: &Config,
    model_config: &ModelConfig,
    path: &Path,
    base: &Path,
) -> Result<(Built, String), CliError> {
    if !model_config.set.is_empty() || model_config.end_time.is_some() {
        return Err(CliError::input(
            "[model]: `set` and `end_time` apply to the airframe; edit the deck instead",
        ));
    }
    let bytes =
        std::fs::read(path).map_err(|e| CliError::io(format!("{}: {e}", path.display())))?;
    let deck = read_deck(path)?;
    deck.warnings
        .iter()
        .for_each(|w| eprintln!("impactcal: warning: {w}"));
    let model = DeckModel::new(deck.model)
        .map_err(|e| CliError::input(format!("{}: {e}", path.display())))?;
    let fields_of = |name: &str| {
        config
            .parameters
            .get(name)
            .cloned()
            .unwrap_or_else(|| name.to_string())
    };
    let space = match study_space(config, base)? {
        Some(s) => s,
        None if !config.parameters.is_empty() => {
            let full = model.space();
            let params = config
                .parameters
                .iter()
                .map(|(name, field)| {
                    let q = full.index_of(field).map(|i| full.parameters()[i].clone()).ok_or_else(|| {
                        CliError::input(format!(
                            "[parameters] `{name}` = `{field}`: the deck has no such quantity; closest: {}",
                            impactcal::calibrate::study::subspace::near(field, &full.names())
                        ))
                    })?;
                    Ok(Parameter::new(name.clone(), q.lower, q.upper, q.nominal)?)
                })
                .collect::<Result<Vec<_>, CliError>>()?;
            ParameterSpace::new(params)?
        }
        None => {
            return Err(CliError::input(
                "[space]: give `bounds = \"bounds.csv\"` or a [parameters] table",
            ));
        }
    };
    let fields: Vec<String> = space.names().iter().map(|n| fields_of(n)).collect();
    let sub = Subspace::aliased(model, space, &fields)?;
    let description = format!("deck {} ({})", path.display(), fingerprint(&bytes));
    Ok((Built::Deck(Box::new(sub)), description))
}

/// Progress on stderr: a bar per stage of runs on a terminal, a line per stage otherwise.
pub struct Progress {
    bar: Mutex<Option<ProgressBar>>,
    terminal: bool,
}

impl Progress {
    /// A progress display for this process's stderr.
    pub fn new() -> Progress {
        Progress {
            bar: Mutex::new(None),
            terminal: std::io::stderr().is_terminal(),
        }
    }

    /// Finishes the current bar.
    pub fn done(&self) {
        if let Ok(mut b) = self.bar.lock()
            && let Some(bar) = b.take()
        {
            bar.finish();
        }
    }
}

impl Observer for Progress {
    fn stage(&self, name: &str, total: usize, reused: usize) {
        self.done();
        let reuse = if reused > 0 {
            format!(" ({reused} from the journal)")
        } else {
            String::new()
        };
        if !self.terminal {
            eprintln!("impactcal: {name}: {total} runs{reuse}");
            return;
        }
        let bar = ProgressBar::new(total as u64);
        if let Ok(style) =
            ProgressStyle::with_template("{msg:>10} [{bar:40}] {pos}/{len} runs {elapsed}")
        {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.set_message(name.to_string());
        bar.set_position(reused as u64);
        if let Ok(mut b) = self.bar.lock() {
            *b = Some(bar);
        }
    }

    fn run_finished(&self) {
        if let Ok(b) = self.bar.lock()
            && let Some(bar) = b.as_ref()
        {
            bar.inc(1);
        }
    }

    fn step(&self, name: &str) {
        self.done();
        if !self.terminal {
            eprintln!("impactcal: {name}");
        }
    }
}
