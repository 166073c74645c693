//! The closed loop on the five drops of a potted electronics unit
//! (`examples/shocktest/loop.toml`): the before/after table of docs/validation.md
//! ("Repeated shock tests"), in the full band and below 10 kHz, on the calibration drops and
//! the holdout drops; what was added or refused and why; and where and in which band the
//! unexplained residual lies.
//!
//! ```text
//! cargo run --release --example shocktest [-- examples/shocktest/loop.toml] [--out DIR]
//! ```
//!
//! Full band: the loop's own relative L2 errors (nuisance terms out, masked samples out).
//! Below 10 kHz: the same compared histories (the loop's evidence: the test with its
//! nuisance terms out and the model on the same samples) low-passed forward and backward by
//! a 4-pole Butterworth at 10 kHz (zero phase, -6 dB at 10 kHz), the error
//! `||lp(test - model)|| / ||lp(test)||` over every channel.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use impactcal::calibrate::closeloop::{Errors, Stages};
use impactcal::experiment::Experiment;

/// The split between the bands (Hz).
const SPLIT: f64 = 1e4;

/// `x` low-passed forward and backward by a 4-pole Butterworth at `fc` (two biquads of
/// quality factors 0.5412 and 1.3066, bilinear with the corner pre-warped).
fn low_pass(x: &[f64], fc: f64, dt: f64) -> Vec<f64> {
    let w0 = 2.0 * std::f64::consts::PI * fc * dt;
    let pass = |x: &[f64], q: f64| -> Vec<f64> {
        let (c, alpha) = (w0.cos(), w0.sin() / (2.0 * q));
        let a0 = 1.0 + alpha;
        let (b0, b1, b2) = ((1.0 - c) / 2.0 / a0, (1.0 - c) / a0, (1.0 - c) / 2.0 / a0);
        let (a1, a2) = (-2.0 * c / a0, (1.0 - alpha) / a0);
        let (mut x1, mut x2, mut y1, mut y2) = (0.0, 0.0, 0.0, 0.0);
        x.iter()
            .map(|&v| {
                let y = b0 * v + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2;
                (x2, x1, y2, y1) = (x1, v, y1, y);
                y
            })
            .collect()
    };
    let forward = pass(&pass(x, 0.5412), 1.3066);
    let back: Vec<f64> = forward.into_iter().rev().collect();
    let mut y = pass(&pass(&back, 0.5412), 1.3066);
    y.reverse();
    y
}

/// The relative L2 below [`SPLIT`] of one comparison's evidence (`channels` rows).
fn below(e: &Errors, channels: usize, dt: f64) -> Option<f64> {
    let ev = e.evidence.as_ref()?;
    let t = ev.test.len() / channels;
    let (mut num, mut den) = (0.0, 0.0);
    for c in 0..channels {
        let test = &ev.test[c * t..(c + 1) * t];
        let diff: Vec<f64> = test
            .iter()
            .zip(&ev.model[c * t..(c + 1) * t])
            .map(|(a, b)| a - b)
            .collect();
        num += low_pass(&diff, SPLIT, dt)
            .iter()
            .map(|v| v * v)
            .sum::<f64>();
        den += low_pass(test, SPLIT, dt).iter().map(|v| v * v).sum::<f64>();
    }
    Some((num / den).sqrt())
}

fn row(what: &str, s: &Stages<Errors>, channels: usize, dt: f64) {
    let b = |e: &Errors| below(e, channels, dt).map_or("-".into(), |v| format!("{v:.3}"));
    println!(
        "| {what} | {:.3} | {:.3} | {:.3} | {} | {} | {} |",
        s.nominal.rel_l2,
        s.calibrated.rel_l2,
        s.enriched.rel_l2,
        b(&s.nominal),
        b(&s.calibrated),
        b(&s.enriched)
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let file = args
        .iter()
        .find(|a| a.ends_with(".toml"))
        .cloned()
        .unwrap_or_else(|| "examples/shocktest/loop.toml".into());
    let out = args
        .iter()
        .position(|a| a == "--out")
        .and_then(|i| args.get(i + 1))
        .cloned()
        .unwrap_or_else(|| "shocktest-out".into());
    let start = Instant::now();
    let e = Experiment::from_file(&file).expect("the loop file");
    for n in e.measured().expect("the drops").notes {
        println!("note: {n}");
    }
    let done = e.close_loop(&out).expect("the loop");
    let r = &done.result;
    let channels = r.channels.len();
    let dt = r.time_step;
    println!(
        "\nloop on {file}: {:.1} s, verdict {:?}, stopped: {}",
        start.elapsed().as_secs_f64(),
        r.verdict,
        r.stopped
    );
    println!(
        "\n| drops | full band: nominal | calibrated | enriched | below 10 kHz: nominal | calibrated | enriched |"
    );
    println!("|---|---|---|---|---|---|---|");
    row("calibration", &r.metrics_calibration, channels, dt);
    if let Some(h) = &r.metrics_holdout {
        row("holdout", h, channels, dt);
    }
    println!("\ncalibrated: {:?}", r.calibrated);
    println!("\nadded:");
    for a in &r.added {
        println!(
            "  {} = {:.4e} in [{:.4e}, {:.4e}]",
            a.name, a.value, a.lower, a.upper
        );
    }
    println!("\ncandidates (first attribution), ranked:");
    for s in &r.candidates {
        println!("  {s:?}");
    }
    for round in &r.rounds {
        println!("\nround {:?}: runs {}", round.added, round.runs);
    }
    if let Some(d) = &r.unattributed {
        println!(
            "\nunattributed: {:.1} % of the whitened residual in {} components; closest {:?}",
            100.0 * d.energy_fraction,
            d.components.len(),
            d.closest
        );
        for c in &d.components {
            println!(
                "  sigma {:.1}: peak at {:.4} ms, central half {:.4}-{:.4} ms, band quartiles {:.1} / {:.1} / {:.1} kHz, sensors {:?}",
                c.sigma,
                c.peak_time * 1e3,
                c.span.0 * 1e3,
                c.span.1 * 1e3,
                c.band[0] / 1e3,
                c.band[1] / 1e3,
                c.band[2] / 1e3,
                c.sensors
            );
        }
    }
}
