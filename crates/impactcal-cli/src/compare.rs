//! `impactcal compare`: calibration metric M2 between test and analysis impact shapes, on
//! the channels both files hold; the channels of one side only are left out, named in a
//! warning on stderr and in the JSON's `dropped`.

use std::path::PathBuf;

use clap::Args as ClapArgs;
use impactcal::calibrate::metrics::Dropped;
use impactcal::core::Histories;
use impactcal::shapes::Orthogonality;
use serde::Serialize;

use crate::error::CliError;
use crate::output::write_json;
use crate::shapes::{decompose, options};

/// Arguments of `impactcal compare`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Test (measured) histories in wide CSV.
    #[arg(long)]
    pub test: PathBuf,
    /// Analysis (model) histories on the same channels, in wide CSV.
    #[arg(long)]
    pub analysis: PathBuf,
    /// Number of shapes of each side to compare (default: all up to the rank).
    #[arg(long)]
    pub shapes: Option<usize>,
    /// Write the JSON here instead of stdout.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

#[derive(Serialize)]
struct Report {
    orthogonality: Vec<Vec<f64>>,
    pairs: Vec<(usize, usize, f64)>,
    matched_above_0_9: usize,
    principal_cosines: Vec<f64>,
    test_contributions: Vec<f64>,
    analysis_contributions: Vec<f64>,
    /// The shared channels compared, in the test's order.
    channels: Vec<String>,
    /// Channels of the test without an analysis channel, and of the analysis without a
    /// test channel: not compared.
    dropped: Dropped,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    let test = Histories::read_csv(&args.test)?;
    let analysis = Histories::read_csv(&args.analysis)?;
    let shared: Vec<String> = test
        .labels()
        .iter()
        .filter(|l| analysis.labels().contains(l))
        .cloned()
        .collect();
    if shared.is_empty() {
        return Err(CliError::input(format!(
            "{} and {} share no channel label: M2 compares the shapes of the same channels \
             (the test's first channels: {}; the analysis's: {})",
            args.test.display(),
            args.analysis.display(),
            first_labels(&test),
            first_labels(&analysis)
        )));
    }
    let dropped = Dropped::of(
        test.labels(),
        analysis.labels(),
        shared.iter().map(|l| (l.as_str(), l.as_str())),
    );
    if let Some(w) = dropped.warning(shared.len()) {
        eprintln!("impactcal: warning: {w}");
    }
    let test = test.select(&shared)?;
    let analysis = analysis.select(&shared)?;
    let opts = options(args.shapes, None);
    let t = decompose(&test, &opts, &args.test.display().to_string())?;
    let a = decompose(&analysis, &opts, &args.analysis.display().to_string())?;
    let m2 = Orthogonality::between(&a, &t).map_err(|e| {
        CliError::from(e).context(format!(
            "{} vs {}",
            args.analysis.display(),
            args.test.display()
        ))
    })?;
    let m = m2.matrix();
    let report = Report {
        orthogonality: (0..m.nrows())
            .map(|i| (0..m.ncols()).map(|j| m[(i, j)]).collect())
            .collect(),
        pairs: m2
            .pairs()
            .iter()
            .map(|p| (p.analysis, p.test, p.value))
            .collect(),
        matched_above_0_9: m2.matched_above(0.9),
        principal_cosines: m2.principal_cosines().to_vec(),
        test_contributions: t.contributions(),
        analysis_contributions: a.contributions(),
        channels: shared,
        dropped,
    };
    write_json(&report, args.out.as_deref())
}

/// The first five labels of `h`, quoted, for messages.
fn first_labels(h: &Histories) -> String {
    let mut s: Vec<String> = h
        .labels()
        .iter()
        .take(5)
        .map(|l| format!("`{l}`"))
        .collect();
    if h.labels().len() > 5 {
        s.push(format!("and {} more", h.labels().len() - 5));
    }
    s.join(", ")
}
