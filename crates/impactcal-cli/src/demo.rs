//! `impactcal demo`: the source paper's study on the coarse airframe. The "test" is the
//! airframe with undisclosed thickness changes in a few sections; Table 1's parameter set is
//! screened with M1 on 150 runs, then Table 2's is studied in full (50 runs, sensors, M2,
//! surrogates, sensitivity, 60 CORS-RBF runs), and the report ends with the reveal.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args as ClapArgs;
use impactcal::calibrate::report::{Block, Plot, Provenance, Report};
use impactcal::calibrate::study::document::{Geometry, Revealed, report, reveal_section};
use impactcal::calibrate::study::{
    StudyOptions, StudyResult, Subspace, TestData, ValidStudyOptions, run_model,
};
use impactcal::core::{Cfc, Model, ParamGuard};
use impactcal::experiment::model::geometry_of;
use impactcal::experiment::{command_line, write_study};
use impactcal::shell::airframe::{
    Airframe, AirframeModel, AirframeOptions, MeshDensity, Preset, catalogue, space_of,
};
use serde::Serialize;

use crate::error::CliError;
use crate::output::write_text;
use crate::progress::Progress;
use crate::simulate::thread_pool;

/// The demo's window (s): the airframe is predictable over it (docs/airframe.md,
/// "Predictability"); later, its own noise grows by e every 4 ms.
pub const END_TIME: f64 = 0.025;

/// The hidden changes of the test: factor on the nominal value of each section thickness.
pub const HIDDEN: [(&str, f64); 3] = [
    ("belly_panel.t", 1.2),
    ("keel_beam_stiffener.t", 1.2),
    ("back_panel.t", 0.8),
];

/// Arguments of `impactcal demo`.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Output folder: `test.csv`, `table1/` and `table2/` (each with its run journal and
    /// `study.json`), `demo.json`.
    #[arg(long)]
    pub out: PathBuf,
    /// Number of threads.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Runs of the Table 1 ensemble (the paper: 150).
    #[arg(long, default_value_t = 150)]
    pub table1_runs: usize,
    /// Runs of the Table 2 ensemble (the paper: 50).
    #[arg(long, default_value_t = 50)]
    pub table2_runs: usize,
    /// New runs of the CORS-RBF reconciliation (the paper: 60).
    #[arg(long, default_value_t = 60)]
    pub reconcile_runs: usize,
    /// Sensors (the paper: 41).
    #[arg(long, default_value_t = 41)]
    pub sensors: usize,
    /// Base rows of the Sobol' design on the surrogate (n (d + 2) evaluations).
    #[arg(long, default_value_t = 1024)]
    pub sensitivity_samples: usize,
    /// The closed loop instead: a test with structural damping the model lacks, noise, a
    /// late trigger and one wrong gain; the loop finds what it can and the report reveals
    /// what was hidden (`test.csv`, `holdout.csv`, the run journal, `loop.json`,
    /// `report.html`, `report.md`, `demo.json`).
    #[arg(long)]
    pub close_loop: bool,
    /// Closed loop: simulated time (s).
    #[arg(long, default_value_t = crate::demo_loop::END_TIME)]
    pub end_time: f64,
    /// Closed loop: sensor channels of the test (the ones that move most).
    #[arg(long, default_value_t = 24)]
    pub channels: usize,
    /// Closed loop: the wrong gain of the first channel (25.4 shows the units flag).
    #[arg(long, default_value_t = 1.2)]
    pub gain: f64,
    /// Closed loop: jitter runs measuring the model's own noise.
    #[arg(long, default_value_t = 8)]
    pub loop_ensemble: usize,
    /// Closed loop: CORS runs of the first calibration.
    #[arg(long, default_value_t = 24)]
    pub loop_reconcile: usize,
    /// Closed loop: CORS runs of each recalibration.
    #[arg(long, default_value_t = 24)]
    pub loop_recalibrate: usize,
    /// Closed loop: Gauss-Newton polish iterations after each CORS search.
    #[arg(long, default_value_t = 8)]
    pub loop_polish: usize,
    /// Closed loop: the least fraction of the residual a candidate must explain to be added
    /// (the library's default).
    #[arg(long, default_value_t = 0.5)]
    pub loop_min_explained: f64,
    /// Closed loop: most candidates added.
    #[arg(long, default_value_t = 2)]
    pub max_added: usize,
    /// Closed loop: the candidates the loop may consider (comma-separated; all the
    /// airframe's undeclared quantities when absent).
    #[arg(long, value_delimiter = ',')]
    pub candidates: Option<Vec<String>>,
    /// The car pole crash instead: our model's nine parameters calibrated to LS-DYNA's four
    /// outputs (dmax, fmax, vfin, IE) at one design of the public LS-OPT car pole study, kept
    /// in DIR (`p9_problem.txt`, `p9_X.csv`, `p9_Y_*.csv`, `decks/`); needs `--runs`. Writes
    /// `car-pole.json`, `report.md` and `calibrated.k` (the deck of the calibrated point).
    #[arg(long, value_name = "DIR")]
    pub car_pole: Option<PathBuf>,
    /// Car pole: our solver's outputs per design, reused (a CSV with a `row` column, `base`
    /// or a row of `p9_X.csv`, and dmax, fmax, vfin, IE; benches/peers/car_pole_crosscode.sh
    /// writes it).
    #[arg(long, value_name = "RESULTS")]
    pub runs: Option<PathBuf>,
    /// Car pole: the design whose LS-DYNA outputs are the test: `base` (the box centre, the
    /// mean of LS-DYNA's five repeats) or a row of `p9_X.csv`.
    #[arg(long, default_value = "base")]
    pub target: String,
    /// Keep every channel of every run in its `result.csv` (by default a run after the
    /// nominal and jitter runs stores only the channels compared).
    #[arg(long)]
    pub keep_all_channels: bool,
}

#[derive(Serialize)]
struct Summary<'a> {
    wall_time_s: f64,
    end_time: f64,
    table1_verdict: &'a str,
    table1_exceedance_fraction: f64,
    table1_intervals: &'a [[f64; 2]],
    table2_verdict: &'a str,
    table2_exceedance_fraction: f64,
    prediction_error_before: Option<f64>,
    prediction_error_after: Option<f64>,
    reduction: Option<f64>,
    m2_above_0_9_before: Option<usize>,
    m2_above_0_9_after: Option<usize>,
    reveal: &'a [Revealed],
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), CliError> {
    if args.close_loop {
        return crate::demo_loop::run(&args);
    }
    if let Some(dir) = &args.car_pole {
        return crate::demo_car_pole::run(dir, args.runs.as_deref(), &args.target, &args.out);
    }
    let started = Instant::now();
    let pool = thread_pool(args.threads)?;
    crate::output::out_folder(&args.out)?;
    let mut options = AirframeOptions::new(MeshDensity::Coarse);
    options.end_time = END_TIME;
    let airframe = Airframe::new(options)?;
    // Every option of both studies, before the test's run and Table 1's runs.
    let table1 = StudyOptions {
        halton_runs: args.table1_runs,
        screen_only: true,
        keep_all_channels: args.keep_all_channels,
        ..StudyOptions::default()
    }
    .check()
    .map_err(|e| CliError::from(e).context("demo, Table 1"))?;
    let table2 = StudyOptions {
        halton_runs: args.table2_runs,
        sensors: args.sensors,
        shapes: 10.min(args.sensors),
        sensitivity_samples: args.sensitivity_samples,
        reconcile_runs: args.reconcile_runs,
        keep_all_channels: args.keep_all_channels,
        ..StudyOptions::default()
    }
    .check()
    .map_err(|e| CliError::from(e).context("demo, Table 2"))?;
    let channels = airframe.sensor_labels().len();
    if args.sensors > channels {
        return Err(CliError::input(format!(
            "--sensors {}: the coarse airframe has {channels} sensor channels, and Table 2 \
             places sensors on those of them its model predicts; give at most {channels} \
             (the source paper: 41)",
            args.sensors
        )));
    }
    let names: Vec<String> = catalogue().into_iter().map(|a| a.name).collect();
    let full = space_of(&names)?;
    let model = AirframeModel::new(airframe.clone(), full.clone())?;
    let mut hidden_point = full.nominal();
    for (name, factor) in HIDDEN {
        if let Some(i) = full.index_of(name) {
            hidden_point[i] *= factor;
        }
    }
    eprintln!("impactcal: the test (the airframe with hidden changes)");
    let test = pool.install(|| model.simulate(&hidden_point))?;
    test.write_csv(args.out.join("test.csv"))?;
    let cfc = Some(Cfc::from_class(60)?);
    let geometry = geometry_of(&airframe);
    let study = |preset: Preset,
                 options: &ValidStudyOptions,
                 dir: &Path|
     -> Result<StudyResult, CliError> {
        let sub = Subspace::new(model.clone(), preset.space()?)?;
        let description = format!("built-in airframe, coarse mesh, {END_TIME} s, {preset:?}");
        std::fs::create_dir_all(dir)
            .map_err(|e| CliError::io(format!("{}: {e}", dir.display())))?;
        let test = TestData {
            histories: &test,
            map: None,
            cfc,
        };
        let progress = Progress::new();
        let started = Instant::now();
        let result = pool.install(|| run_model(&sub, &description, test, options, dir, &progress));
        progress.done();
        let result = result?;
        let provenance = Provenance::now(
            command_line(),
            result.fingerprint.clone(),
            result.options.seed,
            started.elapsed().as_secs_f64(),
        );
        let done = write_study(result, Some(&geometry), Some(&provenance), dir)?;
        crate::output::print_finished(&done, "");
        Ok(done.result)
    };
    eprintln!(
        "impactcal: Table 1 ({} runs): does M1 let this parameter set explain the test?",
        table1.halton_runs
    );
    let dir1 = args.out.join("table1");
    let r1 = study(Preset::Table1, &table1, &dir1)?;
    eprintln!(
        "impactcal: Table 2 ({} runs), sensitivity, reconciliation",
        table2.halton_runs
    );
    let dir2 = args.out.join("table2");
    let r2 = study(Preset::Table2, &table2, &dir2)?;
    let reveal: Vec<Revealed> = r2
        .space
        .parameters()
        .iter()
        .enumerate()
        .map(|(i, p)| Revealed {
            name: p.name.clone(),
            nominal: p.nominal,
            hidden: full
                .index_of(&p.name)
                .map_or(p.nominal, |k| hidden_point[k]),
            calibrated: r2
                .reconcile
                .as_ref()
                .map_or(p.nominal, |c| c.calibrated_point[i]),
        })
        .collect();
    let provenance = Provenance::now(
        command_line(),
        format!(
            "Table 1 study {}; Table 2 study {}",
            r1.fingerprint, r2.fingerprint
        ),
        r2.options.seed,
        started.elapsed().as_secs_f64(),
    );
    let doc = demo_report(&r1, &r2, &reveal, &geometry, &provenance);
    let e = r2.errors.as_ref();
    let m2 = r2.m2.as_ref();
    let summary = Summary {
        wall_time_s: started.elapsed().as_secs_f64(),
        end_time: END_TIME,
        table1_verdict: r1.m1.verdict.as_str(),
        table1_exceedance_fraction: r1.m1.exceedance_fraction,
        table1_intervals: &r1.m1.intervals,
        table2_verdict: r2.m1.verdict.as_str(),
        table2_exceedance_fraction: r2.m1.exceedance_fraction,
        prediction_error_before: e.map(|e| e.baseline.prediction_error),
        prediction_error_after: e.map(|e| e.calibrated.prediction_error),
        reduction: e.map(|e| e.reduction),
        m2_above_0_9_before: m2.map(|m| m.baseline.matched_above_0_9),
        m2_above_0_9_after: m2
            .and_then(|m| m.calibrated.as_ref())
            .map(|c| c.matched_above_0_9),
        reveal: &reveal,
    };
    let json = serde_json::to_string_pretty(&summary)
        .map_err(|e| CliError::failure(format!("cannot encode the summary: {e}")))?;
    write_text(&(json + "\n"), Some(&args.out.join("demo.json")))?;
    let files = impactcal::calibrate::report::write(&doc, &args.out)?;
    for line in &doc.lead {
        eprintln!("{line}");
    }
    eprintln!(
        "impactcal: demo finished in {:.0} s; wrote {} and {}",
        summary.wall_time_s,
        args.out.join("demo.json").display(),
        files.html.display()
    );
    Ok(())
}

/// The demo's report: Table 1's M1 screening, Table 2's whole study, the reveal (the hidden
/// change drawn on the airframe beside the calibrated change of Table 2's report), and the
/// provenance of the whole run.
pub fn demo_report(
    t1: &StudyResult,
    t2: &StudyResult,
    reveal: &[Revealed],
    geometry: &Geometry,
    provenance: &Provenance,
) -> Report {
    let first = report(t1, None);
    let second = report(t2, Some(geometry));
    let mut screening: Vec<_> = first
        .sections
        .into_iter()
        .filter(|s| s.heading.starts_with("M1"))
        .collect();
    for s in &mut screening {
        s.heading = format!("Table 1 screening. {}", s.heading);
        for b in &mut s.blocks {
            if let Block::Figure(f) = b {
                f.name = format!("{}-table1", f.name);
                if let Plot::Envelope(e) = &mut f.plot {
                    e.series.truncate(1);
                }
            }
        }
    }
    let mut lead = vec![format!(
        "Table 1 (moduli): {}. Table 2 (thicknesses): {}.",
        t1.m1.verdict.as_str(),
        t2.m1.verdict.as_str()
    )];
    lead.extend(second.lead.iter().skip(1).cloned());
    let mut sections = screening;
    sections.extend(second.sections);
    sections.push(reveal_section(reveal, 0.05, Some((geometry, &t2.space))));
    sections.push(provenance.section());
    Report {
        title: "The source paper's calibration study on the coarse airframe".into(),
        lead,
        sections,
    }
}
