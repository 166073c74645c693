//! `impactcal demo --close-loop`: the closed loop on the coarse airframe. The "test" is the
//! airframe with structural damping the model holds at zero, measured on the vertical
//! sensor channels that move most with white noise, a late trigger and one sensor with a wrong
//! gain; the holdout is the same airframe dropped at another sink speed. The loop (Table 2
//! declared, every other catalogue quantity a candidate unless `--candidates` narrows them)
//! reports what it found, and the report ends with what was hidden.

use std::path::Path;
use std::time::Instant;

use impactcal::calibrate::closeloop::document::report_with;
use impactcal::calibrate::closeloop::{
    Holdout, LoopOptions, LoopResult, check_inputs, run_loop_on,
};
use impactcal::calibrate::report::{Block, Provenance, Section, Table};
use impactcal::calibrate::study::TestData;
use impactcal::core::synthetic::{Measurement, measured};
use impactcal::core::{Cfc, Enrichable, Histories, Model};
use impactcal::experiment::model::geometry_of;
use impactcal::shell::airframe::{Airframe, AirframeModel, AirframeOptions, MeshDensity, Preset};
use serde::Serialize;

use crate::demo::Args;
use crate::error::CliError;
use crate::output::write_text;
use crate::progress::Progress;
use crate::simulate::thread_pool;

/// The loop demo's window (s): the window of the coarse-airframe loop test. Over 25 ms
/// the declared thicknesses, calibrated first, take up more of the damping's signature
/// (docs/validation.md, "The closed-loop demo").
pub const END_TIME: f64 = 0.015;
/// What the test hides: structural damping (1/s) the model holds at zero.
pub const HIDDEN_DAMPING: f64 = 10.0;
/// The test's trigger offset (s): two samples late.
pub const TRIGGER_OFFSET: f64 = 2e-4;
/// Measurement noise: signal-to-noise ratio of every channel (dB; 1 % of its RMS).
pub const SNR_DB: f64 = 40.0;
/// The holdout's condition: sink speed (in/s).
pub const HOLDOUT_SPEED: f64 = 280.0;
/// The CFC class of test and runs. (CFC 60, 100 Hz, spans two and a half periods of the
/// 25 ms window: its start-up transient, which a trigger offset moves, would dominate the
/// residual.)
pub const CFC: u32 = 1000;

/// What was hidden and what the loop found, side by side.
#[derive(Debug, Serialize)]
struct Reveal {
    quantity: String,
    hidden: String,
    found: String,
}

#[derive(Serialize)]
struct Summary<'a> {
    wall_time_s: f64,
    end_time: f64,
    channels: &'a [String],
    verdict: &'a str,
    added: Vec<String>,
    relative_l2_calibration: [f64; 3],
    relative_l2_holdout: Option<[f64; 3]>,
    runs: usize,
    reveal: &'a [Reveal],
    noise: NoiseReveal,
}

/// The loop's noise floor against the noise the test hid.
#[derive(Debug, Serialize)]
struct NoiseReveal {
    /// Per channel: the label, the hidden noise's standard deviation after the filter,
    /// the loop's estimate, its source.
    channels: Vec<(String, f64, f64, String)>,
    /// Estimate over hidden: least, median, largest.
    ratio: [f64; 3],
    /// The final reduced chi-square of the loop.
    chi2_red_final: f64,
}

fn noise_reveal(r: &LoopResult, channels: &[String], hidden: &[f64]) -> NoiseReveal {
    let per: Vec<(String, f64, f64, String)> = channels
        .iter()
        .zip(hidden)
        .filter_map(|(l, h)| {
            r.noise_floor
                .channels
                .iter()
                .find(|c| &c.label == l)
                .map(|c| (l.clone(), *h, c.sigma, format!("{:?}", c.source)))
        })
        .collect();
    let mut q: Vec<f64> = per.iter().map(|(_, h, e, _)| e / h).collect();
    q.sort_by(f64::total_cmp);
    let ratio = if q.is_empty() {
        [f64::NAN; 3]
    } else {
        [q[0], q[q.len() / 2], q[q.len() - 1]]
    };
    let chi2_red_final = r.detection_final.chi2_red;
    NoiseReveal {
        channels: per,
        ratio,
        chi2_red_final,
    }
}

/// The `count` vertical channels of `h` with the largest standard deviation after filtering,
/// largest first: where the crash shows (a velocity that barely changes is a constant whose
/// gain and bias cannot be told apart).
///
/// # Errors
/// Filter errors.
pub fn moving_channels(h: &Histories, count: usize) -> Result<Vec<String>, CliError> {
    let f = h.filtered(Cfc::from_class(CFC)?)?;
    let vertical: Vec<&String> = f.labels().iter().filter(|l| l.ends_with(".z")).collect();
    Ok(f.select(&vertical)?.most_varying(count))
}

/// Runs `impactcal demo --close-loop`.
///
/// # Errors
/// Bad options (exit 2), run and I/O failures.
pub fn run(args: &Args) -> Result<(), CliError> {
    let started = Instant::now();
    if args.channels == 0 {
        return Err(CliError::input("--channels: at least one sensor channel"));
    }
    let pool = thread_pool(args.threads)?;
    crate::output::out_folder(&args.out)?;
    let mut o = AirframeOptions::new(MeshDensity::Coarse);
    o.end_time = args.end_time;
    let airframe = Airframe::new(o)?;
    let vertical = airframe
        .sensor_labels()
        .iter()
        .filter(|l| l.ends_with(".z"))
        .count();
    if args.channels > vertical {
        return Err(CliError::input(format!(
            "--channels {}: the coarse airframe has {vertical} vertical sensor channels; give \
             at most {vertical}",
            args.channels
        )));
    }
    let geometry = geometry_of(&airframe);
    let model = AirframeModel::preset(airframe, Preset::Table2)?;
    // Every option the loop checks, before the test's runs.
    let options = LoopOptions {
        ensemble: args.loop_ensemble,
        reconcile: args.loop_reconcile,
        recalibrate: args.loop_recalibrate,
        max_added: args.max_added,
        min_explained: args.loop_min_explained,
        polish: args.loop_polish,
        candidates: args.candidates.clone(),
        seed: 1,
        keep_all_channels: args.keep_all_channels,
        ..LoopOptions::default()
    };
    check_inputs(&model, &options).map_err(|e| CliError::from(e).context("demo --close-loop"))?;
    let truth = model.at_condition(&[("damping".into(), HIDDEN_DAMPING)])?;
    let speed = [("impact.vertical".to_string(), HOLDOUT_SPEED)];
    let x = model.space().nominal();
    eprintln!("impactcal: the test and the holdout (the airframe with hidden damping)");
    let (y, yh) = pool.install(|| -> Result<_, CliError> {
        let (a, b) = rayon::join(
            || truth.simulate(&x),
            || truth.at_condition(&speed).and_then(|m| m.simulate(&x)),
        );
        Ok((a?, b?))
    })?;
    let channels = moving_channels(&y, args.channels)?;
    let wrong = channels[0].clone();
    let measure = |h: &Histories, seed: u64| -> Result<Histories, CliError> {
        let m = Measurement {
            time_shift: TRIGGER_OFFSET,
            gains: vec![(wrong.clone(), args.gain)],
            snr_db: Some(SNR_DB),
            seed,
            ..Measurement::default()
        };
        Ok(measured(&h.select(&channels)?, &m)?)
    };
    let (test, holdout) = (measure(&y, 1)?, measure(&yh, 2)?);
    // The noise as the loop compares it: the test less its noiseless self, through the
    // loop's filter; its standard deviation per channel.
    let noiseless = measured(
        &y.select(&channels)?,
        &Measurement {
            time_shift: TRIGGER_OFFSET,
            gains: vec![(wrong.clone(), args.gain)],
            ..Measurement::default()
        },
    )?;
    let hidden = Histories::from_channels(
        channels.clone(),
        (0..channels.len())
            .map(|c| {
                test.channel(c)
                    .iter()
                    .zip(noiseless.channel(c))
                    .map(|(a, b)| a - b)
                    .collect()
            })
            .collect(),
        test.dt(),
        test.start(),
        test.unit(),
    )?
    .filtered(Cfc::from_class(CFC)?)?;
    let hidden_sd: Vec<f64> = (0..channels.len())
        .map(|c| {
            let e = hidden.channel(c);
            (e.iter().map(|v| v * v).sum::<f64>() / e.len() as f64).sqrt()
        })
        .collect();
    test.write_csv(args.out.join("test.csv"))?;
    holdout.write_csv(args.out.join("holdout.csv"))?;

    let description = format!(
        "built-in airframe, coarse mesh, 0-{} s, Table2 declared",
        args.end_time
    );
    eprintln!(
        "impactcal: the closed loop ({} channels, CFC {CFC}, holdout at impact.vertical = \
         {HOLDOUT_SPEED})",
        channels.len()
    );
    let progress = Progress::new();
    let result = pool.install(|| {
        let test = TestData {
            histories: &test,
            map: None,
            cfc: Some(Cfc::from_class(CFC)?),
        };
        let holdout = Holdout {
            histories: &holdout,
            set: &speed,
        };
        let (out, observer) = (&args.out, &progress);
        let r = run_loop_on(
            &model,
            &description,
            test,
            Some(holdout),
            &options,
            out,
            observer,
            None,
        );
        Ok::<_, CliError>(r?)
    });
    progress.done();
    let result = result.map_err(|e| e.context("demo --close-loop"))?;

    let noise = noise_reveal(&result, &channels, &hidden_sd);
    let reveal = reveal(&result, &wrong, args.gain, &noise);
    let provenance = Provenance::now(
        std::env::args().collect::<Vec<_>>().join(" "),
        result.digest.clone(),
        result.seed,
        started.elapsed().as_secs_f64(),
    );
    let mut doc = report_with(&result, Some(&geometry), Some(&provenance));
    doc.title = "Closed loop on the coarse airframe: a test with hidden damping".into();
    // The reveal before the appendix and the provenance, which stay last.
    let at = doc
        .sections
        .iter()
        .position(|s| s.heading.starts_with("Appendix") || s.heading == "Provenance")
        .unwrap_or(doc.sections.len());
    doc.sections.insert(at, reveal_section(&reveal));
    let json = serde_json::to_string_pretty(&result)
        .map_err(|e| CliError::failure(format!("cannot encode the loop's result: {e}")))?;
    write_text(&(json + "\n"), Some(&args.out.join("loop.json")))?;
    let files = impactcal::calibrate::report::write(&doc, &args.out)?;
    let e = &result.errors;
    let summary = Summary {
        wall_time_s: started.elapsed().as_secs_f64(),
        end_time: args.end_time,
        channels: &channels,
        verdict: verdict(&result),
        added: result.added.iter().map(|a| a.name.clone()).collect(),
        relative_l2_calibration: [
            e.calibration.nominal,
            e.calibration.calibrated,
            e.calibration.enriched,
        ],
        relative_l2_holdout: e
            .holdout
            .as_ref()
            .map(|h| [h.nominal, h.calibrated, h.enriched]),
        runs: result.runs,
        reveal: &reveal,
        noise,
    };
    let json = serde_json::to_string_pretty(&summary)
        .map_err(|e| CliError::failure(format!("cannot encode the summary: {e}")))?;
    write_text(&(json + "\n"), Some(&args.out.join("demo.json")))?;
    print_summary(&summary, &args.out, &files.html);
    Ok(())
}

fn verdict(r: &LoopResult) -> &'static str {
    use impactcal::calibrate::closeloop::Verdict;
    match r.verdict {
        Verdict::NoModelFormError => "no-model-form-error",
        Verdict::Attributed => "attributed",
        Verdict::Unattributed => "unattributed",
    }
}

/// `least to largest (median m)` of `values`, to three significant digits.
fn spread(values: impl Iterator<Item = f64>) -> String {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => "-".into(),
        n => format!("{:.3} to {:.3} (median {:.3})", v[0], v[n - 1], v[n / 2]),
    }
}

/// What was hidden beside what the loop found.
fn reveal(r: &LoopResult, wrong: &str, gain: f64, noise: &NoiseReveal) -> Vec<Reveal> {
    let unit = if r.unit.is_empty() {
        "(test units)"
    } else {
        &r.unit
    };
    let damping = r.added.iter().find(|a| a.name == "damping").map_or_else(
        || match r.candidates.iter().position(|c| c.name == "damping") {
            Some(k) => format!(
                "not added (ranked {} of {}: {})",
                k + 1,
                r.candidates.len(),
                r.candidates[k].status
            ),
            None => "not a candidate".into(),
        },
        |a| format!("{:.4} [{:.4}, {:.4}]", a.value, a.lower, a.upper),
    );
    let mut rows = vec![
        Reveal {
            quantity: "damping (1/s), the model holds 0".into(),
            hidden: format!("{HIDDEN_DAMPING}"),
            found: damping,
        },
        Reveal {
            quantity: "trigger offset (s)".into(),
            hidden: format!("{TRIGGER_OFFSET:e}"),
            found: format!("{:.3e}", r.nuisance.time_shift),
        },
        Reveal {
            quantity: format!("gain of {wrong}"),
            hidden: format!("{gain}"),
            found: r
                .nuisance
                .gains
                .get(wrong)
                .map_or_else(|| "-".into(), |g| format!("{g:.4}")),
        },
        Reveal {
            quantity: "units flags".into(),
            hidden: if is_units_factor(gain) {
                format!("{wrong} (gain {gain})")
            } else {
                "none".into()
            },
            found: if r.nuisance.units_flags.is_empty() {
                "none".into()
            } else {
                r.nuisance
                    .units_flags
                    .iter()
                    .map(|f| format!("{} ({})", f.channel, f.meaning))
                    .collect::<Vec<_>>()
                    .join(", ")
            },
        },
        Reveal {
            quantity: "measurement noise".into(),
            hidden: format!(
                "white, {SNR_DB} dB (1 % of each channel's RMS); after CFC {CFC}: sigma {} \
                 {unit} over the channels",
                spread(noise.channels.iter().map(|c| c.1))
            ),
            found: format!(
                "sigma {} {unit} over the channels, {:.2} to {:.2} times the hidden (median \
                 {:.2}); sources {}; final reduced chi-square {:.3}",
                spread(noise.channels.iter().map(|c| c.2)),
                noise.ratio[0],
                noise.ratio[2],
                noise.ratio[1],
                sources(r),
                noise.chi2_red_final
            ),
        },
    ];
    for (name, v) in &r.calibrated {
        if name != "damping" {
            rows.push(Reveal {
                quantity: name.clone(),
                hidden: "nominal".into(),
                found: format!("{v:.5}"),
            });
        }
    }
    rows
}

/// The noise floor's sources with how many channels each, and the band's first refusal.
fn sources(r: &LoopResult) -> String {
    let mut count = std::collections::BTreeMap::new();
    for c in &r.noise_floor.channels {
        *count.entry(format!("{:?}", c.source)).or_insert(0) += 1;
    }
    let mut s = count
        .iter()
        .map(|(k, n)| format!("{k} x {n}"))
        .collect::<Vec<_>>()
        .join(", ");
    if let Some(why) = r
        .noise_floor
        .channels
        .iter()
        .find_map(|c| c.band_refusal.as_ref())
    {
        s.push_str(&format!(" (band refused: {why})"));
    }
    s
}

/// Whether `g` is within 5 % of a factor the loop flags as a units error.
fn is_units_factor(g: f64) -> bool {
    [9.81, 1.0 / 9.81, 25.4, 1000.0, 0.001]
        .iter()
        .any(|f| (g / f - 1.0).abs() < 0.05)
}

fn reveal_section(rows: &[Reveal]) -> Section {
    Section {
        heading: "The reveal: what the test hid".into(),
        blocks: vec![
            Block::Paragraph(
                "The test was the airframe at its nominal thicknesses with structural damping \
                 the model holds at zero, measured late, noisy and with one mis-calibrated \
                 sensor. The loop was told none of this."
                    .into(),
            ),
            Block::Table(Table {
                caption: "Hidden beside found".into(),
                header: vec![
                    "quantity".into(),
                    "hidden".into(),
                    "found by the loop".into(),
                ],
                rows: rows
                    .iter()
                    .map(|r| vec![r.quantity.clone(), r.hidden.clone(), r.found.clone()])
                    .collect(),
            }),
        ],
    }
}

fn print_summary(s: &Summary<'_>, out: &Path, html: &Path) {
    let f = |v: [f64; 3]| format!("{:.4} -> {:.4} -> {:.4}", v[0], v[1], v[2]);
    println!("verdict: {}; added: {}", s.verdict, s.added.join(", "));
    println!(
        "relative L2, calibration test (nominal -> calibrated -> enriched): {}",
        f(s.relative_l2_calibration)
    );
    if let Some(h) = s.relative_l2_holdout {
        println!("relative L2, holdout (never fitted): {}", f(h));
    }
    println!("the reveal:");
    for r in s.reveal {
        println!("  {}: hidden {}, found {}", r.quantity, r.hidden, r.found);
    }
    println!(
        "{} runs, {:.0} s; wrote {} and {}",
        s.runs,
        s.wall_time_s,
        out.join("demo.json").display(),
        html.display()
    );
}
