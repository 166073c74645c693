//! CORS-RBF on the Dixon-Szego functions: evaluations to 1% relative error and the time
//! spent choosing each point, one JSON line per (function, seed).
//!
//! `cargo run --release -p impactcal-cors --example cors_dixon_szego -- [--seeds 30] [--budget 300]
//! [--functions branin,hartmann3] [--transform identity|log|shifted-log|median-cap]
//! [--kernel cubic|thin-plate] [--candidates 300] [--local-candidates 100] [--pattern 0.9,0.75,0.25,0.05,0.03,0]
//! [--restart-patience N | --restart | --no-restart] [--global-only] [--local-first] [--escape N | --no-escape]
//! [--second-region H | --no-second-region]
//! [--perturb-horizon H | --no-perturb] [--repeat-refinement N | --no-repeat-refinement] [--candidate-floor N [--candidate-horizon H] |
//! --no-candidate-decay] [--merit-weights 0.3,0.5,0.8,0.95]
//! [--adaptive-region restore|escape|restart|restart-outside [--grow-after 3] [--shrink-after N] [--halvings 6] [--sigma-only] |
//! --no-adaptive-region] [--unknown-budget] [--points]`
//!
//! The study is told its budget (`CorsOptions::budget`), so that the perturbation schedule
//! falls over it as DYCORS's does; `--unknown-budget` leaves it out (the horizon of 300).
//!
//! `--noise LEVEL --noise-file FILE` runs the whole budget on `f(x) + LEVEL * range * z_k`,
//! with the range of each function and the draws `z_k` of each seed read from the table
//! that `cors_pysot.py --write-noise` writes (the same noise as pySOT's runs), and reports
//! the luckiest sample and [`Cors::surrogate_answer`] with the true value at each.
//!
//! `--points` adds every chosen point to each line (`"points":[[x1, x2, ...], ...]`, shortest
//! round-trip decimals), so that two builds can be checked to choose the same points bit for
//! bit.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use std::collections::HashMap;

use impactcal_core::test_functions::{self, TestFunction};
use impactcal_cors::{
    AdaptiveRegion, CandidateDecay, Converged, Cors, CorsOptions, Perturbation, Restart,
    SurrogateKernel, Transform,
};

/// The noise table of `cors_pysot.py --write-noise`: range per function, draws per seed.
struct Noise {
    level: f64,
    ranges: HashMap<String, f64>,
    draws: HashMap<u64, Vec<f64>>,
}

impl Noise {
    fn read(level: f64, path: &str) -> Self {
        let text = std::fs::read_to_string(path).expect("the noise table");
        let (mut ranges, mut draws) = (HashMap::new(), HashMap::new());
        for line in text.lines() {
            let parts: Vec<&str> = line.split_whitespace().collect();
            match parts.first() {
                Some(&"range") => {
                    ranges.insert(parts[1].to_string(), parts[2].parse().unwrap());
                }
                Some(&"z") => {
                    let z = parts[2..].iter().map(|v| v.parse().unwrap()).collect();
                    draws.insert(parts[1].parse().unwrap(), z);
                }
                _ => {}
            }
        }
        Noise {
            level,
            ranges,
            draws,
        }
    }
}

/// The whole budget on the noisy function; one JSON line with both answers.
fn run_noisy(
    name: &str,
    f: &TestFunction,
    seed: u64,
    options: CorsOptions,
    budget: usize,
    noise: &Noise,
) {
    let sd = noise.level * noise.ranges[name];
    let z = &noise.draws[&seed];
    let mut study = Cors::new(f.space().unwrap(), options).unwrap();
    let mut k = 0;
    study
        .minimize(
            |x| {
                let v = f.eval(x) + sd * z[k];
                k += 1;
                v
            },
            budget,
        )
        .unwrap();
    let sample = study.best().unwrap();
    let answer = study.surrogate_answer().unwrap().unwrap();
    let (t_sample, t_answer) = (f.eval(&sample.x), f.eval(&answer.x));
    println!(
        "{{\"tool\":\"impactcal-cors\",\"function\":\"{name}\",\"seed\":{seed},\"noise\":{},\"evaluations\":{},\"sample_noisy\":{},\"sample_true\":{t_sample},\"sample_error\":{},\"answer_predicted\":{},\"answer_observed\":{},\"answer_true\":{t_answer},\"answer_error\":{},\"smoothing\":{}}}",
        noise.level,
        study.evaluations().len(),
        sample.value.unwrap(),
        f.relative_error(t_sample),
        answer.predicted,
        answer.observed,
        f.relative_error(t_answer),
        answer.smoothing,
    );
}

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
                // The study knows its budget, as pySOT's strategies do (`max_evals`);
                // `--unknown-budget` measures the schedule of a study that does not.
                budget: (!args.iter().any(|a| a == "--unknown-budget")).then_some(budget),
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
            if let Some(p) = get("--escape") {
                options.local_escape = Some(p.parse().unwrap());
            }
            if args.iter().any(|a| a == "--no-escape") {
                options.local_escape = None;
            }
            if let Some(h) = get("--second-region") {
                options.second_region = Some(h.parse().unwrap());
            }
            if args.iter().any(|a| a == "--no-second-region") {
                options.second_region = None;
            }
            if args.iter().any(|a| a == "--local-first") {
                options.local_first = true;
            }
            if args.iter().any(|a| a == "--global-only") {
                options.local_region = None;
            }
            if let Some(h) = get("--perturb-horizon") {
                options.perturbation = Some(Perturbation {
                    horizon: Some(h.parse().unwrap()),
                });
            }
            if args.iter().any(|a| a == "--no-perturb") {
                options.perturbation = None;
            }
            if let Some(c) = get("--candidate-floor") {
                options.candidate_decay = Some(CandidateDecay {
                    min_per_dim: c.parse().unwrap(),
                    horizon: get("--candidate-horizon").map_or(300, |h| h.parse().unwrap()),
                });
            }
            if let Some(n) = get("--repeat-refinement") {
                options.repeat_refinement = Some(impactcal_cors::RepeatRefinement {
                    max_repeats: n.parse().unwrap(),
                    ..Default::default()
                });
            }
            if args.iter().any(|a| a == "--no-repeat-refinement") {
                options.repeat_refinement = None;
            }
            if args.iter().any(|a| a == "--no-candidate-decay") {
                options.candidate_decay = None;
            }
            if let Some(a) = get("--adaptive-region") {
                let on_converged = match a.as_str() {
                    "restore" => Converged::Restore,
                    "escape" => Converged::Escape,
                    "restart" => Converged::Restart,
                    "restart-outside" => Converged::RestartOutside,
                    other => panic!("unknown --adaptive-region {other}"),
                };
                let base = AdaptiveRegion::default();
                options.adaptive_region = Some(AdaptiveRegion {
                    grow_after: get("--grow-after").map_or(base.grow_after, |v| v.parse().unwrap()),
                    shrink_after: get("--shrink-after").map(|v| v.parse().unwrap()),
                    halvings: get("--halvings").map_or(base.halvings, |v| v.parse().unwrap()),
                    on_converged,
                    shrink_box: !args.iter().any(|a| a == "--sigma-only"),
                });
            }
            if args.iter().any(|a| a == "--no-adaptive-region") {
                options.adaptive_region = None;
            }
            if let Some(w) = get("--merit-weights") {
                options.merit_weights = Some(w.split(',').map(|v| v.parse().unwrap()).collect());
            }
            if args.iter().any(|a| a == "--no-restart") {
                options.restart = None;
            } else if let Some(p) = get("--restart-patience") {
                options.restart = Some(Restart {
                    patience: Some(p.parse().unwrap()),
                    ..Restart::default()
                });
            } else if args.iter().any(|a| a == "--restart") {
                options.restart = Some(Restart::default());
            }
            if let Some(level) = get("--noise") {
                let path = get("--noise-file").expect("--noise-file with --noise");
                let noise = Noise::read(level.parse().unwrap(), &path);
                run_noisy(name, &f, seed, options, budget, &noise);
                continue;
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
