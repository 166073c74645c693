//! `impactcal metrics`: curve metrics of a model against a test, per channel and overall.

use std::path::PathBuf;

use clap::Args as ClapArgs;
use impactcal::calibrate::metrics::{ChannelPair, CompareOptions, compare};
use impactcal::core::{Cfc, ChannelMap, Histories, TestRecord};

use crate::error::CliError;
use crate::output::write_json;

/// Arguments of `impactcal metrics`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Test (measured) histories in wide CSV; time steps may vary (resampled linearly).
    #[arg(long)]
    pub test: PathBuf,
    /// Analysis (model) histories in wide CSV.
    #[arg(long)]
    pub analysis: PathBuf,
    /// Channel map `test_label,model_label[,gain[,conversion]]` (default: pair equal labels).
    #[arg(long)]
    pub map: Option<PathBuf>,
    /// Channel frequency class applied to both sides before comparing: 60, 180, 600 or 1000.
    #[arg(long)]
    pub cfc: Option<u32>,
    /// Compare only the test's samples within `T0,T1` (seconds).
    #[arg(long, value_name = "T0,T1")]
    pub window: Option<String>,
    /// Write the JSON here instead of stdout.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    let record = TestRecord::read(&args.test)?;
    if let Some(r) = &record.resampling {
        eprintln!("note: {}: {r}", args.test.display());
    }
    let model = Histories::read_csv(&args.analysis)?;
    let map = args.map.as_ref().map(ChannelMap::read).transpose()?;
    // The map's conversions (bridges, accelerometers, units) turn raw channels into SI.
    let test = match &map {
        Some(m) => m.convert(&record.histories)?,
        None => record.histories,
    };
    let pairs = match &map {
        Some(m) => ChannelPair::from_map(m, &test, &model)?,
        None => ChannelPair::by_label(&test, &model)?,
    };
    let window = args.window.as_deref().map(parse_window).transpose()?;
    let options = CompareOptions {
        cfc: args.cfc.map(Cfc::from_class).transpose()?,
        window,
        ..CompareOptions::default()
    };
    let comparison = compare(&test, &model, &pairs, &options)?;
    if let Some(w) = comparison.dropped.warning(pairs.len()) {
        eprintln!("impactcal: warning: {w}");
    }
    if let Some((t0, t1)) = window {
        let [u0, u1] = comparison.window;
        if u0 - t0 > comparison.dt || t1 - u1 > comparison.dt {
            eprintln!(
                "note: the test has samples over [{}, {}] of the window [{t0}, {t1}]; the \
                 metrics cover that range",
                significant(u0),
                significant(u1)
            );
        }
    }
    write_json(&comparison, args.out.as_deref())
}

/// `x` rounded to seven significant digits, for messages (sample times carry the
/// round-off of `start + k dt`).
fn significant(x: f64) -> f64 {
    format!("{x:.6e}").parse().unwrap_or(x)
}

/// Parses `T0,T1`.
fn parse_window(text: &str) -> Result<(f64, f64), CliError> {
    let bad = || CliError::input(format!("--window `{text}`: expected two times T0,T1"));
    let (a, b) = text.split_once(',').ok_or_else(bad)?;
    let t0: f64 = a.trim().parse().map_err(|_| bad())?;
    let t1: f64 = b.trim().parse().map_err(|_| bad())?;
    Ok((t0, t1))
}
