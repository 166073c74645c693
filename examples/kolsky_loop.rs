//! The closed loop on the copper Kolsky bar test (examples/kolsky/): the figures of
//! docs/validation.md, "The Kolsky bar: the closed loop".
//!
//! `cargo run --release --example kolsky_loop [-- OUT]` (default `target/kolsky-loop/`)
//!
//! Runs `loop.toml` (both waves), `holdout.toml` (the reflected wave alone, the transmitted
//! one predicted), `loop-gain500.toml` (the planted gain fault) and `pmma13-loop.toml` (a
//! PMMA test on another bar, unseen), each into its folder
//! under OUT with its report, and prints per wave the relative L2 error at the nominal,
//! calibrated and enriched points (each under its own trigger offset and biases), the fitted
//! timing, what was added and why the loop stopped; for a residual left unattributed, where
//! in time and in which frequency bands its first components sit. The holdout's transmitted wave is
//! predicted at the reflected-only calibration with the loop's trigger offset; its own
//! trigger offset (`delay_transmitted`, a nuisance term the reflected wave says nothing
//! about) is the only thing fitted to it, on a 0.05 us grid over its range.

use std::path::{Path, PathBuf};

use impactcal::calibrate::closeloop::{Evidence, LoopResult};
use impactcal::core::enrich::rebuild;
use impactcal::core::{Histories, Model};
use impactcal::experiment::{Experiment, ExperimentModel};

type R<T> = std::result::Result<T, Box<dyn std::error::Error>>;

fn rel_l2(model: &[f64], test: &[f64]) -> f64 {
    let num: f64 = model.iter().zip(test).map(|(m, t)| (m - t).powi(2)).sum();
    let den: f64 = test.iter().map(|t| t * t).sum();
    (num / den).sqrt()
}

/// Channel `c` of `h` moved later by `tau` seconds (linear interpolation, zero outside).
fn shifted(h: &Histories, c: usize, tau: f64) -> Vec<f64> {
    let x = h.channel(c);
    let s = tau / h.dt();
    (0..x.len())
        .map(|k| {
            let at = k as f64 - s;
            let i = at.floor();
            let f = at - i;
            let get = |j: f64| {
                if j >= 0.0 && (j as usize) < x.len() {
                    x[j as usize]
                } else {
                    0.0
                }
            };
            get(i) * (1.0 - f) + get(i + 1.0) * f
        })
        .collect()
}

/// The loop's model rebuilt with what it added, and the point of `values` in its order.
fn point_of(
    model: &ExperimentModel,
    added: &[String],
    values: &std::collections::BTreeMap<String, f64>,
) -> R<(ExperimentModel, Vec<f64>)> {
    let mut names: Vec<String> = model
        .space()
        .names()
        .iter()
        .map(|s| s.to_string())
        .collect();
    names.extend(added.iter().cloned());
    let m = rebuild(model, &names, &[])?;
    let p = m
        .space()
        .names()
        .iter()
        .map(|n| values.get(*n).copied().unwrap_or(0.0))
        .collect();
    Ok((m, p))
}

/// Where a residual's time pattern `v` (first sample at `start`, interval `dt`) holds its
/// energy (the interval from 10 % to 90 % of it) and how its energy splits over frequency
/// bands (a plain DFT of the pattern, up to 2 MHz).
fn where_and_band(v: &[f64], start: f64, dt: f64) -> String {
    let total: f64 = v.iter().map(|x| x * x).sum();
    let mut cum = 0.0;
    let (mut lo, mut hi) = (None, None);
    for (k, x) in v.iter().enumerate() {
        cum += x * x;
        if lo.is_none() && cum > 0.1 * total {
            lo = Some(k);
        }
        if hi.is_none() && cum > 0.9 * total {
            hi = Some(k);
        }
    }
    let at = |k: Option<usize>| (start + k.unwrap_or(0) as f64 * dt) * 1e6;
    let edges = [0.0, 20e3, 50e3, 100e3, 200e3, 500e3, 1e6, 2e6];
    let mut power = vec![0.0; edges.len() - 1];
    let n = v.len();
    for m in 1..n / 2 {
        let f = m as f64 / (n as f64 * dt);
        if f >= 2e6 {
            break;
        }
        let (mut re, mut im) = (0.0, 0.0);
        for (k, x) in v.iter().enumerate() {
            let w = -2.0 * std::f64::consts::PI * (m * k % n) as f64 / n as f64;
            re += x * w.cos();
            im += x * w.sin();
        }
        if let Some(b) = edges.windows(2).position(|e| e[0] <= f && f < e[1]) {
            power[b] += re * re + im * im;
        }
    }
    let all: f64 = power.iter().sum();
    let bands: Vec<String> = power
        .iter()
        .enumerate()
        .map(|(b, p)| {
            format!(
                "{:.0}-{:.0} kHz {:.0} %",
                edges[b] / 1e3,
                edges[b + 1] / 1e3,
                100.0 * p / all
            )
        })
        .collect();
    format!(
        "80 % of its energy from {:.1} to {:.1} us; by band: {}",
        at(lo),
        at(hi),
        bands.join(", ")
    )
}

/// The names the loop added, in order.
fn added(r: &LoopResult) -> Vec<String> {
    r.added.iter().map(|a| a.name.clone()).collect()
}

/// Per-wave relative L2 errors of one stage's evidence (the test under that stage's own
/// trigger offset and biases, and the model's response, as the report draws them).
fn errors(r: &LoopResult, e: Option<&Evidence>) -> Vec<(String, f64)> {
    let Some(e) = e else { return Vec::new() };
    let t = e.test.len() / r.channels.len().max(1);
    r.channels
        .iter()
        .enumerate()
        .map(|(s, label)| {
            let w = s * t..(s + 1) * t;
            (label.clone(), rel_l2(&e.model[w.clone()], &e.test[w]))
        })
        .collect()
}

fn report(name: &str, file: &Path, out: &Path) -> R<(LoopResult, Experiment)> {
    let e = Experiment::from_file(file)?;
    let done = e.close_loop(out.join(name))?;
    let r = done.result;
    println!("== {name}: {}", done.report.lead.join(" "));
    let m = &r.metrics_calibration;
    let stages = [
        ("nominal", errors(&r, m.nominal.evidence.as_deref())),
        ("calibrated", errors(&r, m.calibrated.evidence.as_deref())),
        ("enriched", errors(&r, m.enriched.evidence.as_deref())),
    ];
    for (stage, e) in &stages {
        let list: Vec<String> = e
            .iter()
            .map(|(l, v)| format!("{l} {:.1} %", 100.0 * v))
            .collect();
        println!("{stage}: {}", list.join(", "));
    }
    println!(
        "combined: nominal {:.1} %, calibrated {:.1} %, enriched {:.1} %",
        100.0 * r.errors.calibration.nominal,
        100.0 * r.errors.calibration.calibrated,
        100.0 * r.errors.calibration.enriched
    );
    println!(
        "timing: loop trigger offset {:.2} us, wave speed {:.1} m/s; delays {:.2} / {:.2} us; \
         calibrated {:?}",
        r.nuisance.time_shift * 1e6,
        r.calibrated.get("wave_speed").copied().unwrap_or(f64::NAN),
        r.calibrated
            .get("delay_reflected")
            .copied()
            .unwrap_or(f64::NAN),
        r.calibrated
            .get("delay_transmitted")
            .copied()
            .unwrap_or(f64::NAN),
        r.calibrated
    );
    let ranked: Vec<String> = r
        .candidates
        .iter()
        .map(|c| {
            format!(
                "{} ({}, share {:.3}, LM {:.0})",
                c.name, c.status, c.explained_fraction, c.score
            )
        })
        .collect();
    println!("ranked: {}", ranked.join("; "));
    for a in &r.added {
        println!(
            "added: {} = {:.4} [{:.4}, {:.4}]",
            a.name, a.value, a.lower, a.upper
        );
    }
    println!("stopped: {}", r.stopped);
    if let Some(u) = &r.unattributed {
        for (i, c) in u.components.iter().take(2).enumerate() {
            println!(
                "unattributed component {}: sigma {:.1}, waves {:?}; {}",
                i + 1,
                c.sigma,
                c.sensors,
                where_and_band(&c.time, r.start, r.time_step)
            );
        }
    }
    Ok((r, e))
}

fn main() -> R<()> {
    let out: PathBuf = std::env::args()
        .nth(1)
        .map_or_else(|| PathBuf::from("target/kolsky-loop"), PathBuf::from);
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/kolsky");
    let (_, full) = report("copper", &dir.join("loop.toml"), &out)?;
    let (held, e) = report("holdout", &dir.join("holdout.toml"), &out)?;
    // The transmitted wave predicted from the reflected-only calibration.
    let measured = full.measured()?.test;
    let t = measured
        .index_of("transmitted")
        .ok_or("no transmitted wave")?;
    let model = e.build()?.model.ok_or("no model")?;
    let (m, mut p) = point_of(&model, &added(&held), &held.calibrated)?;
    let d = m
        .space()
        .index_of("delay_transmitted")
        .ok_or("no delay_transmitted")?;
    let tau = held.nuisance.time_shift;
    let at = |p: &[f64]| -> R<f64> {
        let h = m.simulate(p)?;
        let i = h.index_of("transmitted").ok_or("no transmitted output")?;
        Ok(rel_l2(&shifted(&h, i, tau), measured.channel(t)))
    };
    let as_fitted = at(&p)?;
    let range = &m.space().parameters()[d];
    let (mut best, mut best_delay) = (f64::INFINITY, p[d]);
    let steps = ((range.upper - range.lower) / 0.05).round() as usize;
    for k in 0..=steps {
        p[d] = range.lower + k as f64 * 0.05;
        let e = at(&p)?;
        if e < best {
            (best, best_delay) = (e, p[d]);
        }
    }
    println!(
        "holdout: transmitted predicted from the reflected-only calibration: {:.1} % with its \
         trigger offset fitted ({best_delay:.2} us), {:.1} % at the offset's nominal 0",
        100.0 * best,
        100.0 * as_fitted
    );
    let _ = report("gain500", &dir.join("loop-gain500.toml"), &out)?;
    let _ = report("pmma13", &dir.join("pmma13-loop.toml"), &out)?;
    Ok(())
}
