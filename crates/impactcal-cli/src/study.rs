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
//!
//! [study]
//! ensemble = 50
//! sensors = 41
//! sensitivity_samples = 1024
//! reconcile_runs = 60
//! seed = 1
//! ```

use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use clap::Args as ClapArgs;
use impactcal::calibrate::report::{Report, ReportFiles};
use impactcal::calibrate::study::document::{Geometry, report};
use impactcal::calibrate::study::journal::fingerprint;
use impactcal::calibrate::study::{
    Observer, StudyOptions, StudyResult, Subspace, TestData, ValidStudyOptions, run_model,
};
use impactcal::core::{
    Cfc, ChannelMap, Histories, IsoMme, Model, ParamGuard, Parameter, ParameterSpace, TestRecord,
};
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
}

/// The study file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// The model.
    pub model: ModelConfig,
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
}

/// A model built from a study file, ready to run.
pub enum Built {
    /// The airframe restricted to the study's quantities, and where its sensors are.
    Airframe(Box<Subspace<AirframeModel>>, Geometry),
    /// A deck restricted to the study's quantities.
    Deck(Box<Subspace<DeckModel>>),
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
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    let text = std::fs::read_to_string(&args.config)
        .map_err(|e| CliError::io(format!("{}: {e}", args.config.display())))?;
    let name = args.config.display().to_string();
    let config: Config = toml::from_str(&text)
        .map_err(|e| CliError::input(format!("{name}: {}", one_line(&e.to_string()))))?;
    let base = args.config.parent().unwrap_or(Path::new("."));
    let options = config
        .study
        .clone()
        .check()
        .map_err(|e| CliError::from(e).context(&name))?;
    let setup = setup(&config, base).map_err(|e| e.context(&name))?;
    let pool = thread_pool(args.threads)?;
    let result = pool.install(|| execute(&setup, &options, &args.out))?;
    finish(&result, &setup, &args.out)
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
        Built::Deck(_) => None,
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
    let result = match &setup.model {
        Built::Airframe(m, _) => run_model(
            m.as_ref(),
            &setup.description,
            test,
            options,
            out,
            &progress,
        ),
        Built::Deck(m) => run_model(
            m.as_ref(),
            &setup.description,
            test,
            options,
            out,
            &progress,
        ),
    };
    progress.done();
    Ok(result?)
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
    let (model, description) = match (&config.model.airframe, &config.model.deck) {
        (Some(mesh), None) => airframe(config, mesh, base)?,
        (None, Some(deck)) => deck_model(config, &resolve(base, deck), base)?,
        _ => {
            return Err(CliError::input(
                "[model]: give either `airframe = \"coarse\"` or `deck = \"model.k\"`",
            ));
        }
    };
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
    })
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

fn airframe(config: &Config, mesh: &str, base: &Path) -> Result<(Built, String), CliError> {
    if !config.parameters.is_empty() {
        return Err(CliError::input(
            "[parameters] maps deck quantities; the airframe's names are its catalogue's",
        ));
    }
    let mut options = AirframeOptions::new(MeshDensity::parse(mesh).map_err(CliError::input)?);
    if let Some(t) = config.model.end_time {
        options.end_time = t;
        options.output_interval = options.output_interval.min(t);
    }
    let airframe = Airframe::new(options).map_err(CliError::input)?;
    let mut values = AirframeValues::nominal();
    for (k, v) in &config.model.set {
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
    let model = AirframeModel::new(airframe, full).map_err(CliError::input)?;
    let sub = Subspace::new(model, space)?.with_base(base_point)?;
    let description = format!(
        "built-in airframe, {mesh} mesh, {} s, set {:?}",
        options.end_time, config.model.set
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

fn deck_model(config: &Config, path: &Path, base: &Path) -> Result<(Built, String), CliError> {
    if !config.model.set.is_empty() || config.model.end_time.is_some() {
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
    let model = DeckModel::new(deck.model).map_err(CliError::input)?;
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
