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
//! Runs go two at a time (the machine is shared); about 26 runs of 0.025 s. Every run goes
//! through the model's `Enrichable` interface: an effect is the model enriched with that
//! candidate and run at the amplitude, a holdout is `at_condition`.
//!
//! With `--deck FILE` the same on a keyword deck (`DeckModel`): the declared quantities are
//! `--declared a,b,...` (the first section's thickness by default), the effects every
//! candidate of the deck moved from its held value by a quarter of its admissible range
//! (upward where there is room), no filter unless `--cfc N`, and no holdouts.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use impactcal::core::enrich::Enrichable;
use impactcal::core::noise::{JitterOptions, SimulationNoise};
use impactcal::core::{Cfc, Model, Parameter, ParameterSpace};
use impactcal::shell::DeckModel;
use impactcal::shell::airframe::{
    Airframe, AirframeModel, AirframeOptions, MeshDensity, Preset, space_of, structural_space,
};
use impactcal::shell::keyword::read_deck;
use rayon::prelude::*;

/// The undeclared effects of the airframe: label, candidate, value.
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

/// The holdout conditions of the airframe: label, held quantity, value.
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

/// What to measure: the model declaring its space, a model over its structure for the
/// jitter ensemble, the effects and the holdouts (label, name, value), the filter.
struct Case<M, N> {
    model: M,
    structure: N,
    effects: Vec<(String, String, f64)>,
    holdouts: Vec<(String, String, f64)>,
    cfc: Option<Cfc>,
    jitter: usize,
}

/// The airframe case: coarse mesh, `declared` thicknesses, 0 to `end` s, CFC 60.
fn airframe_case(declared: &[&str], end: f64, jitter: usize) -> Case<AirframeModel, AirframeModel> {
    let mut o = AirframeOptions::new(MeshDensity::Coarse);
    o.end_time = end;
    let airframe = Airframe::new(o).unwrap();
    let own = |v: &[(&str, &str, f64)]| {
        v.iter()
            .map(|(l, n, x)| (l.to_string(), n.to_string(), *x))
            .collect()
    };
    Case {
        model: AirframeModel::new(airframe.clone(), space_of(declared).unwrap()).unwrap(),
        structure: AirframeModel::new(airframe, structural_space().unwrap()).unwrap(),
        effects: own(&EFFECTS),
        holdouts: own(&HOLDOUTS),
        cfc: Some(Cfc::from_class(60).unwrap()),
        jitter,
    }
}

/// The deck case: `declared` quantities (the first one by default) and every candidate a
/// quarter of its admissible range away from its held value.
fn deck_case(
    path: &str,
    declared: Option<&str>,
    cfc: Option<Cfc>,
    jitter: usize,
) -> Case<DeckModel, DeckModel> {
    let full = DeckModel::new(read_deck(path).unwrap().model).unwrap();
    let names: Vec<String> = match declared {
        Some(d) => d.split(',').map(str::to_string).collect(),
        None => vec![full.space().names()[0].to_string()],
    };
    let params = names
        .iter()
        .map(|n| {
            let i = full
                .space()
                .index_of(n)
                .unwrap_or_else(|| panic!("no quantity {n}"));
            full.space().parameters()[i].clone()
        })
        .collect();
    let model = full.declare(&ParameterSpace::new(params).unwrap()).unwrap();
    let effects = model
        .candidates()
        .iter()
        .map(|c| {
            let p = &c.parameter;
            let v = if p.upper > p.nominal {
                p.nominal + 0.25 * (p.upper - p.nominal)
            } else {
                p.nominal - 0.25 * (p.nominal - p.lower)
            };
            (
                format!("{} {} -> {v:.4e}", c.name(), p.nominal),
                c.name().to_string(),
                v,
            )
        })
        .collect();
    Case {
        model,
        structure: full,
        effects,
        holdouts: Vec::new(),
        cfc,
        jitter,
    }
}

/// One run's filtered histories, flattened (channels x samples).
fn run<M: Model>(m: &M, x: &[f64], cfc: Option<Cfc>) -> Result<Vec<f64>, String> {
    let h = m.simulate(x).map_err(|e| e.to_string())?;
    let h = match cfc {
        Some(c) => h.filtered(c).map_err(|e| e.to_string())?,
        None => h,
    };
    Ok(h.data().to_vec())
}

/// A run of `model` enriched with the candidate `name` at `value`.
fn effect_run<M: Enrichable>(
    model: &M,
    name: &str,
    value: f64,
    cfc: Option<Cfc>,
) -> Result<Vec<f64>, String> {
    let c = model
        .candidates()
        .into_iter()
        .find(|c| c.name() == name)
        .ok_or(format!("{name} is not a candidate"))?;
    let e = model
        .enrich(std::slice::from_ref(&c.parameter))
        .map_err(|e| e.to_string())?;
    let mut x = model.space().nominal();
    x.push(value);
    run(&e, &x, cfc)
}

/// A run of `model` at the condition `name = value`.
fn holdout_run<M: Enrichable>(
    model: &M,
    name: &str,
    value: f64,
    cfc: Option<Cfc>,
) -> Result<Vec<f64>, String> {
    let m = model
        .at_condition(&[(name.to_string(), value)])
        .map_err(|e| e.to_string())?;
    run(&m, &model.space().nominal(), cfc)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let opt = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let jitter: usize = opt("--jitter").map_or(8, |j| j.parse().unwrap());
    rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build_global()
        .unwrap();
    match opt("--deck") {
        Some(path) => {
            let cfc = opt("--cfc").map(|c| Cfc::from_class(c.parse().unwrap()).unwrap());
            measure(
                &deck_case(&path, opt("--declared").as_deref(), cfc, jitter),
                &path,
            );
        }
        None => {
            let declared: Vec<&str> = match opt("--declared").as_deref() {
                Some("small") => vec!["belly_panel.t", "keel_beam_web.t"],
                _ => Preset::Table2.names().to_vec(),
            };
            let end: f64 = opt("--end").map_or(0.025, |t| t.parse().unwrap());
            let what = format!("coarse airframe, 0-{end} s");
            measure(&airframe_case(&declared, end, jitter), &what);
        }
    }
}

/// Runs a case and prints its tables.
fn measure<M, N>(case: &Case<M, N>, what: &str)
where
    M: Enrichable + Sync,
    N: Model + Sync,
{
    let started = Instant::now();
    let model = &case.model;
    let cfc = case.cfc;
    // 1. The noise: the nominal run and a jitter ensemble about it.
    let mut options = JitterOptions::new(case.jitter, 1e-4, 1);
    options.cfc = cfc;
    let noise =
        SimulationNoise::measure(&case.structure, &case.structure.space().nominal(), &options)
            .unwrap();
    let y0: Vec<f64> = noise.nominal.concat();
    let sigma = norm(&noise.spread.concat());
    let signal = norm(&y0);

    // 2-4. Every other run, two at a time.
    let declared: Vec<&Parameter> = model.space().parameters().iter().collect();
    let steps: Vec<f64> = declared.iter().map(|p| 0.1 * p.width()).collect();
    let nd = declared.len();
    let ne = case.effects.len();
    let jobs: Vec<usize> = (0..nd + ne + case.holdouts.len()).collect();
    let runs: Vec<Result<Vec<f64>, String>> = jobs
        .par_iter()
        .map(|&k| {
            if k < nd {
                let mut x = model.space().nominal();
                x[k] += steps[k];
                run(model, &x, cfc)
            } else if k < nd + ne {
                let (_, name, v) = &case.effects[k - nd];
                effect_run(model, name, *v, cfc)
            } else {
                let (_, name, v) = &case.holdouts[k - nd - ne];
                holdout_run(model, name, *v, cfc)
            }
        })
        .collect();
    let elapsed = started.elapsed().as_secs_f64();

    let jcols: Vec<Vec<f64>> = runs[..nd]
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

    let filter = cfc.map_or("unfiltered".to_string(), |c| c.to_string());
    println!(
        "{what}, {filter}, {} channels x {} samples; declared: {}",
        noise.channels(),
        noise.samples(),
        model.space().names().join(", ")
    );
    println!(
        "simulation noise: {}-run jitter ensemble (eps 1e-4), ||sigma|| / ||y0|| = {:.2e}",
        case.jitter,
        sigma / signal
    );
    let rms = |c: usize| norm(&noise.nominal[c]) / (noise.samples() as f64).sqrt();
    if let Some(loudest) = (0..noise.channels())
        .filter(|&c| noise.labels[c].ends_with(".z"))
        .max_by(|&a, &b| rms(a).total_cmp(&rms(b)))
    {
        println!(
            "largest vertical channel: {} (RMS {:.4})",
            noise.labels[loudest],
            rms(loudest)
        );
    }
    println!(
        "runs: {} ({} jitter + nominal, {nd} declared directions, {ne} effects, {} holdouts) in {elapsed:.0} s",
        case.jitter + 1 + jobs.len(),
        case.jitter,
        case.holdouts.len()
    );
    println!();
    println!(
        "| effect | ||r|| / ||sigma|| | kappa | ||(I-P)r|| / ||sigma|| | ||(I-P)r|| / ||y0|| |"
    );
    println!("|---|---|---|---|---|");
    let mut projected = Vec::new();
    for (k, (label, _, _)) in case.effects.iter().enumerate() {
        match &runs[nd + k] {
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
    if case.holdouts.is_empty() {
        return;
    }
    println!();
    println!("| holdout | runs | ||y - y0|| / ||y0|| |");
    println!("|---|---|---|");
    for (k, (label, _, _)) in case.holdouts.iter().enumerate() {
        match &runs[nd + ne + k] {
            Ok(y) => println!("| {label} | yes | {:.3} |", norm(&minus(y, &y0)) / signal),
            Err(e) => println!("| {label} | no: {e} | |"),
        }
    }
}
