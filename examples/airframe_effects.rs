//! Which effects the airframe does not declare would a calibration of its thicknesses see?
//! The measurements behind docs/airframe.md ("Undeclared effects").
//!
//! ```text
//! cargo run --release --example airframe_effects [-- --declared table2|small] [--jitter J] [--end T]
//! ```
//!
//! The coarse airframe over the calibration window of the study (0 to 0.025 s, or `T`), every run
//! filtered with CFC 60, all 1,215 sensor velocities. The declared space is the source
//! paper's Table 2 (six thicknesses), or `small` (`belly_panel.t`, `keel_beam_web.t`).
//!
//! 1. **Simulation noise**: a jitter ensemble of `J` runs (8 by default) with every structural
//!    quantity moved by at most 1e-4 relative ([`SimulationNoise`]); its spread
//!    `sigma_c(t)` is the noise, `||sigma||` its norm over channels and samples.
//! 2. **Declared directions**: one run per declared thickness at +10 % of its range, the
//!    columns of `J = dy/dtheta` (finite differences).
//! 3. **Effects**: one run per undeclared effect at a stated amplitude; its residual
//!    against the nominal run is `r_k`. Printed: `||r_k|| / ||sigma||` (the residual a
//!    calibration of nothing would leave, in noise units), the confounding ratio
//!    `kappa_k = ||P_J r_k|| / ||r_k||` (the share the declared thicknesses can mimic), the
//!    residual left after the declared ones absorb what they can, `||(I - P_J) r_k||`, in
//!    noise units and relative to the signal `||y_0||`, and the mutual coherence
//!    `|<r~_i, r~_j>| / (||r~_i|| ||r~_j||)` of the projected residuals.
//! 4. **Holdout conditions**: one run per condition (another impact speed, a pitch
//!    attitude): whether the airframe takes it, and how far it moves the response.
//!
//! Runs go two at a time (the machine is shared); about 26 runs of 0.025 s.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use impactcal::core::noise::{JitterOptions, SimulationNoise};
use impactcal::core::{Cfc, Histories, Model};
use impactcal::shell::airframe::{
    Airframe, AirframeModel, AirframeOptions, AirframeValues, MeshDensity, Preset, structural_space,
};
use rayon::prelude::*;

/// The undeclared effects, each as (name, value) changes of the nominal airframe, with a
/// label.
const EFFECTS: [(&str, &str, f64); 8] = [
    ("ground friction 0.3 -> 0.5", "ground.friction", 0.5),
    ("damping 0 -> 10 1/s", "damping", 10.0),
    ("damping 0 -> 25 1/s", "damping", 25.0),
    ("occupant mass +20 %", "mass.occupants", 0.84),
    (
        "rotor/transmission mass +20 %",
        "mass.rotor_transmission",
        0.66,
    ),
    ("pitch 0 -> 3 deg", "attitude.pitch", 3.0),
    ("roll 0 -> 3 deg", "attitude.roll", 3.0),
    ("Cowper-Symonds C 6500 -> 65000", "rate.c", 65000.0),
];

/// The holdout conditions.
const HOLDOUTS: [(&str, &str, f64); 3] = [
    ("impact.vertical = 280 in/s", "impact.vertical", 280.0),
    ("impact.vertical = 340 in/s", "impact.vertical", 340.0),
    ("attitude.pitch = 5 deg", "attitude.pitch", 5.0),
];

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn minus(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x - y).collect()
}

/// An orthonormal basis of the columns (modified Gram-Schmidt, twice).
fn orthonormal(columns: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let mut q: Vec<Vec<f64>> = Vec::new();
    for c in columns {
        let mut v = c.clone();
        for _ in 0..2 {
            for e in &q {
                let a = dot(&v, e);
                v.iter_mut().zip(e).for_each(|(x, y)| *x -= a * y);
            }
        }
        let n = norm(&v);
        if n > 1e-12 * norm(c) {
            q.push(v.iter().map(|x| x / n).collect());
        }
    }
    q
}

/// `(I - P) v` for the orthonormal basis `q`.
fn residual(q: &[Vec<f64>], v: &[f64]) -> Vec<f64> {
    let mut r = v.to_vec();
    for e in q {
        let a = dot(&r, e);
        r.iter_mut().zip(e).for_each(|(x, y)| *x -= a * y);
    }
    r
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let opt = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let declared: Vec<&str> = match opt("--declared").as_deref() {
        Some("small") => vec!["belly_panel.t", "keel_beam_web.t"],
        _ => Preset::Table2.names().to_vec(),
    };
    let jitter: usize = opt("--jitter").map_or(8, |j| j.parse().unwrap());
    let end: f64 = opt("--end").map_or(0.025, |t| t.parse().unwrap());
    rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build_global()
        .unwrap();

    let mut o = AirframeOptions::new(MeshDensity::Coarse);
    o.end_time = end;
    let airframe = Airframe::new(o).unwrap();
    let cfc = Cfc::from_class(60).unwrap();
    let started = Instant::now();

    // 1. The noise: the nominal run and a jitter ensemble about it.
    let structure = AirframeModel::new(airframe.clone(), structural_space().unwrap()).unwrap();
    let noise = SimulationNoise::measure(
        &structure,
        &structure.space().nominal(),
        &JitterOptions::new(jitter, 1e-4, 1).with_cfc(cfc),
    )
    .unwrap();
    let y0: Vec<f64> = noise.nominal.concat();
    let sigma = norm(&noise.spread.concat());
    let signal = norm(&y0);

    // 2-4. Every other run, two at a time.
    let table2 = Preset::Table2.space().unwrap();
    let mut changes: Vec<(String, String, f64)> = Vec::new();
    let mut steps = Vec::new();
    for name in &declared {
        let p = &table2.parameters()[table2.index_of(name).unwrap()];
        let h = 0.1 * p.width();
        steps.push(h);
        changes.push((format!("{name} +{h}"), name.to_string(), p.nominal + h));
    }
    for (label, name, v) in EFFECTS.iter().chain(&HOLDOUTS) {
        changes.push((label.to_string(), name.to_string(), *v));
    }
    let runs: Vec<Result<Vec<f64>, String>> = changes
        .par_iter()
        .map(|(_, name, v)| {
            let mut values = AirframeValues::nominal();
            values.set(name, *v).map_err(|e| e.to_string())?;
            let r = airframe.run(&values).map_err(|e| e.to_string())?;
            let h: Histories = r.velocity.ok_or("no histories")?;
            let f = h.filtered(cfc).map_err(|e| e.to_string())?;
            Ok(f.data().to_vec())
        })
        .collect();
    let elapsed = started.elapsed().as_secs_f64();

    let n_decl = declared.len();
    let jcols: Vec<Vec<f64>> = runs[..n_decl]
        .iter()
        .zip(&steps)
        .map(|(r, h)| {
            minus(r.as_ref().unwrap(), &y0)
                .iter()
                .map(|x| x / h)
                .collect()
        })
        .collect();
    let q = orthonormal(&jcols);

    println!(
        "coarse airframe, 0-{end} s, CFC 60, {} channels x {} samples; declared: {}",
        noise.channels(),
        noise.samples(),
        declared.join(", ")
    );
    println!(
        "simulation noise: {jitter}-run jitter ensemble (eps 1e-4), ||sigma|| / ||y0|| = {:.2e}",
        sigma / signal
    );
    let rms = |c: usize| norm(&noise.nominal[c]) / (noise.samples() as f64).sqrt();
    let loudest = (0..noise.channels())
        .filter(|&c| noise.labels[c].ends_with(".z"))
        .max_by(|&a, &b| rms(a).total_cmp(&rms(b)))
        .unwrap();
    println!(
        "largest vertical channel: {} (RMS {:.1} in/s)",
        noise.labels[loudest],
        rms(loudest)
    );
    println!(
        "runs: {} ({} jitter + nominal, {n_decl} declared directions, {} effects, {} holdouts) in {elapsed:.0} s",
        jitter + 1 + changes.len(),
        jitter,
        EFFECTS.len(),
        HOLDOUTS.len()
    );
    println!();
    println!(
        "| effect | ||r|| / ||sigma|| | kappa | ||(I-P)r|| / ||sigma|| | ||(I-P)r|| / ||y0|| |"
    );
    println!("|---|---|---|---|---|");
    let mut projected = Vec::new();
    for (k, (label, _, _)) in EFFECTS.iter().enumerate() {
        match &runs[n_decl + k] {
            Ok(y) => {
                let r = minus(y, &y0);
                let rt = residual(&q, &r);
                let (nr, nt) = (norm(&r), norm(&rt));
                let kappa = (1.0 - (nt / nr).powi(2)).max(0.0).sqrt();
                println!(
                    "| {label} | {:.1} | {kappa:.3} | {:.1} | {:.2e} |",
                    nr / sigma,
                    nt / sigma,
                    nt / signal
                );
                projected.push((label, rt));
            }
            Err(e) => println!("| {label} | failed: {e} | | | |"),
        }
    }
    println!();
    println!("mutual coherence of the projected residuals (pairs above 0.5):");
    let mut any = false;
    for i in 0..projected.len() {
        for j in i + 1..projected.len() {
            let (a, b) = (&projected[i].1, &projected[j].1);
            let mu = dot(a, b).abs() / (norm(a) * norm(b));
            if mu > 0.5 {
                any = true;
                println!("  {:.3}  {} / {}", mu, projected[i].0, projected[j].0);
            }
        }
    }
    if !any {
        println!("  none");
    }
    println!();
    println!("| holdout | runs | ||y - y0|| / ||y0|| |");
    println!("|---|---|---|");
    let base = n_decl + EFFECTS.len();
    for (k, (label, _, _)) in HOLDOUTS.iter().enumerate() {
        match &runs[base + k] {
            Ok(y) => println!("| {label} | yes | {:.3} |", norm(&minus(y, &y0)) / signal),
            Err(e) => println!("| {label} | no: {e} | |"),
        }
    }
}
