//! CORS-RBF on the Dixon-Szego functions: evaluations to 1% relative error and the time
//! spent choosing each point, one JSON line per (function, seed).
//!
//! `cargo run --release --example cors_dixon_szego -- [--seeds 30] [--budget 300]
//! [--functions branin,hartmann3] [--transform identity|log|shifted-log|median-cap]
//! [--kernel cubic|thin-plate] [--candidates 300] [--local-candidates 100] [--pattern 0.9,0.75,0.25,0.05,0.03,0]
//! [--restart-patience N | --no-restart] [--points]`
//!
//! `--points` adds every chosen point to each line (`"points":[[x1, x2, ...], ...]`, shortest
//! round-trip decimals), so that two builds can be checked to choose the same points bit for
//! bit.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use impactcal::core::test_functions;
use impactcal::cors::{Cors, CorsOptions, Restart, SurrogateKernel, Transform};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let get = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let seeds: u64 = get("--seeds").map_or(30, |s| s.parse().unwrap());
    let first_seed: u64 = get("--first-seed").map_or(0, |s| s.parse().unwrap());
    let budget: usize = get("--budget").map_or(300, |s| s.parse().unwrap());
    let transform = match get("--transform").as_deref() {
        None | Some("identity") => Transform::Identity,
        Some("log") => Transform::Log,
        Some("shifted-log") => Transform::ShiftedLog,
        Some("median-cap") => Transform::MedianCap,
        Some(t) => panic!("unknown transform {t}"),
    };
    let kernel = match get("--kernel").as_deref() {
        None | Some("cubic") => SurrogateKernel::Cubic,
        Some("thin-plate") => SurrogateKernel::ThinPlate,
        Some(k) => panic!("unknown kernel {k}"),
    };
    let pattern: Option<Vec<f64>> =
        get("--pattern").map(|s| s.split(',').map(|b| b.parse().unwrap()).collect());
    let names: Vec<String> = get("--functions").map_or_else(
        || {
            test_functions::dixon_szego()
                .iter()
                .map(|f| f.name.to_string())
                .collect()
        },
        |s| s.split(',').map(str::to_string).collect(),
    );
    for name in &names {
        let f = test_functions::by_name(name).expect("a Dixon-Szego function");
        for seed in first_seed..first_seed + seeds {
            let mut options = CorsOptions {
                transform,
                kernel,
                ..CorsOptions::with_seed(seed)
            };
            if let Some(c) = get("--candidates") {
                options.candidates_per_dim = c.parse().unwrap();
            }
            if let Some(c) = get("--local-candidates") {
                options.local_candidates_per_dim = c.parse().unwrap();
            }
            if let Some(p) = &pattern {
                options.pattern.clone_from(p);
            }
            if let Some(h) = get("--local-region") {
                options.local_region = Some(h.parse().unwrap());
            }
            if args.iter().any(|a| a == "--no-restart") {
                options.restart = None;
            } else if let Some(p) = get("--restart-patience") {
                options.restart = Some(Restart {
                    patience: Some(p.parse().unwrap()),
                    ..Restart::default()
                });
            }
            let mut study = Cors::new(f.space().unwrap(), options).unwrap();
            let mut hit: Option<usize> = None;
            let mut best = f64::INFINITY;
            let mut suggest_s = Vec::new();
            let mut chosen: Vec<String> = Vec::new();
            for k in 0..budget {
                let t = Instant::now();
                let s = study.suggest(1).unwrap().pop().unwrap();
                suggest_s.push(t.elapsed().as_secs_f64());
                let v = f.eval(&s.x);
                let coordinates: Vec<String> = s.x.iter().map(|c| format!("{c:?}")).collect();
                chosen.push(format!("[{}]", coordinates.join(",")));
                study.tell(s.id, v).unwrap();
                best = best.min(v);
                if hit.is_none() && f.relative_error(best) < 0.01 {
                    hit = Some(k + 1);
                    break;
                }
            }
            // Overhead of the adaptive steps only (the design points cost nothing).
            let n0 = 2 * (f.dim + 1);
            let adaptive: Vec<f64> = suggest_s.iter().skip(n0).copied().collect();
            let mean = if adaptive.is_empty() {
                0.0
            } else {
                adaptive.iter().sum::<f64>() / adaptive.len() as f64
            };
            println!(
                "{{\"tool\":\"impactcal-cors\",\"function\":\"{name}\",\"seed\":{seed},\"evals_to_1pct\":{},\"best\":{best},\"evaluations\":{},\"overhead_s\":{mean},\"restarts\":{}{}}}",
                hit.map_or("null".to_string(), |h| h.to_string()),
                study.evaluations().len(),
                study.restarts(),
                if args.iter().any(|a| a == "--points") {
                    format!(",\"points\":[{}]", chosen.join(","))
                } else {
                    String::new()
                }
            );
        }
    }
}
