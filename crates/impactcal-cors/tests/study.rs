//! Behaviour of a CORS-RBF study: design, warm start, failures, batches, resume, stateless
//! rebuild, stopping, transforms, typed errors.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use impactcal_core::points::{from_rows, to_rows};
use impactcal_core::test_functions::{self, TestFunction};
use impactcal_core::{CoreError, Parameter, ParameterSpace};
use impactcal_cors::design::{affine_rank, symmetric_design};
use impactcal_cors::{
    AdaptiveRegion, CandidateDecay, Converged, Cors, CorsError, CorsOptions, FillReason,
    InitialDesign, Mode, Origin, Perturbation, RepeatRefinement, Restart, StopReason, Stopping,
    Transform,
};

fn unit_distance(space: &ParameterSpace, a: &[f64], b: &[f64]) -> f64 {
    let (ua, ub) = (space.to_unit(a).unwrap(), space.to_unit(b).unwrap());
    ua.iter()
        .zip(&ub)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
}

#[test]
fn design_is_a_spanning_symmetric_latin_hypercube() {
    for d in [1, 2, 3, 6] {
        let n = 2 * (d + 1);
        let design = symmetric_design(n, d, 5).unwrap();
        assert_eq!(affine_rank(design.as_ref()), d + 1);
        let pts = to_rows(design.as_ref());
        assert_eq!(pts.len(), n);
        for j in 0..d {
            // One point per stratum, at the centres, mirrored in pairs.
            let mut col: Vec<f64> = pts.iter().map(|p| p[j]).collect();
            col.sort_by(f64::total_cmp);
            for (k, v) in col.iter().enumerate() {
                assert!((v - (k as f64 + 0.5) / n as f64).abs() < 1e-12);
            }
            for i in 0..n {
                assert!((pts[i][j] + pts[n - 1 - i][j] - 1.0).abs() < 1e-12);
            }
        }
    }
}

#[test]
fn affine_rank_sees_collinear_points() {
    let line: Vec<Vec<f64>> = (0..5)
        .map(|k| vec![0.1 * k as f64, 0.2 * k as f64])
        .collect();
    assert_eq!(affine_rank(from_rows(&line, "line").unwrap().as_ref()), 2);
    let mut tri = line.clone();
    tri.push(vec![0.9, 0.1]);
    assert_eq!(affine_rank(from_rows(&tri, "tri").unwrap().as_ref()), 3);
}

#[test]
fn cors_points_respect_the_distance_constraint_and_cycle() {
    let f = test_functions::by_name("hartmann3").unwrap();
    let space = f.space().unwrap();
    let options = CorsOptions {
        repeat_refinement: None,
        ..CorsOptions::with_seed(3)
    };
    let mut study = Cors::new(space.clone(), options).unwrap();
    let mut betas = Vec::new();
    for _ in 0..26 {
        let s = study.suggest(1).unwrap().pop().unwrap();
        if s.origin == Origin::Cors {
            betas.push(s.beta.unwrap());
            let delta = s.delta.unwrap();
            let radius = (s.beta.unwrap() * delta).max(1e-3 * 3f64.sqrt());
            for e in study.evaluations() {
                let r = unit_distance(&space, &s.x, &e.x);
                assert!(r >= radius * (1.0 - 1e-9), "{r} < {radius}");
                // Delta is the largest empty-ball radius: no point is farther from all.
                assert!(delta <= 3f64.sqrt());
            }
        }
        let v = f.eval(&s.x);
        study.tell(s.id, v).unwrap();
    }
    assert_eq!(study.evaluations().len(), 26);
    assert_eq!(
        study.evaluations()[..8]
            .iter()
            .filter(|e| e.origin == Origin::Design)
            .count(),
        8
    );
    // The pattern, advancing once per evaluation, from its start right after the design.
    let expected: Vec<f64> = (0..18)
        .map(|k| [0.9, 0.75, 0.25, 0.05, 0.03, 0.0][k % 6])
        .collect();
    assert_eq!(betas, expected);
}

/// With the default repeated refinement, a step repeats the previous `beta` exactly when
/// that was a refinement step (`beta <= 0.05`) whose result lowered the best by more than
/// 0.1 % and the repeats in a row stay within 6; every other step takes the pattern's next
/// value; and on this run the rule fires at least once.
#[test]
fn refinement_steps_repeat_while_they_improve() {
    let pattern = [0.9, 0.75, 0.25, 0.05, 0.03, 0.0];
    for seed in 0..4 {
        let f = test_functions::by_name("hartmann3").unwrap();
        let mut study = Cors::new(f.space().unwrap(), CorsOptions::with_seed(seed)).unwrap();
        let (mut best, mut previous) = (f64::INFINITY, None::<(f64, bool)>);
        let (mut position, mut repeats, mut fired) = (0usize, 0usize, 0usize);
        for _ in 0..60 {
            let s = study.suggest(1).unwrap().pop().unwrap();
            let v = f.eval(&s.x);
            if s.origin == Origin::Cors {
                if let Some((beta, improved)) = previous {
                    if beta <= 0.05 && improved && repeats < 6 {
                        repeats += 1;
                        fired += 1;
                    } else {
                        position += 1;
                        repeats = 0;
                    }
                }
                assert_eq!(s.beta, Some(pattern[position % 6]), "seed {seed}");
                previous = Some((s.beta.unwrap(), v < best - 1e-3 * best.abs()));
            }
            best = best.min(v);
            study.tell(s.id, v).unwrap();
        }
        assert!(fired > 0, "seed {seed}: no refinement step repeated");
    }
}

#[test]
fn every_second_cycle_searches_the_box_around_the_best() {
    let f = test_functions::by_name("hartmann3").unwrap();
    let space = f.space().unwrap();
    // Cycles of six steps each: the pattern without repeated refinement.
    let options = CorsOptions {
        repeat_refinement: None,
        ..CorsOptions::with_seed(3)
    };
    let mut study = Cors::new(space.clone(), options).unwrap();
    let mut outside = [0usize; 3];
    for n in 0..26 {
        let s = study.suggest(1).unwrap().pop().unwrap();
        if s.origin == Origin::Cors {
            let best = space.to_unit(&study.best().unwrap().x).unwrap();
            let u = space.to_unit(&s.x).unwrap();
            let far = u
                .iter()
                .zip(&best)
                .any(|(a, b)| (a - b).abs() > 0.3 + 1e-12);
            if far {
                outside[(n - 8) / 6] += 1;
            }
        }
        study.tell(s.id, f.eval(&s.x)).unwrap();
    }
    // Cycle 1 stays within 0.3 of the best point in every coordinate; the whole-box cycle
    // 0 and the second region's cycle 2 (around a point beyond 0.5 of the best) leave it.
    assert_eq!(outside[1], 0);
    assert!(outside[0] > 0 && outside[2] > 0, "{outside:?}");
}

#[test]
fn restarts_start_a_new_design_and_keep_the_history() {
    let f = test_functions::by_name("shekel5").unwrap();
    let options = CorsOptions {
        restart: Some(Restart {
            patience: Some(6),
            min_improvement: 1e-3,
        }),
        ..CorsOptions::with_seed(4)
    };
    // Long enough for steps of the new run after its design.
    let n = 105;
    let mut whole = Cors::new(f.space().unwrap(), options.clone()).unwrap();
    whole.minimize(|x| f.eval(x), n).unwrap();
    assert_eq!(whole.evaluations().len(), n);
    assert!(whole.restarts() >= 1);
    let start = whole.run_start();
    assert!(
        start >= 16 && start + 12 < n,
        "the last run starts at {start}"
    );
    // The new run opens with its own design of 2 (d + 1) points.
    assert!(
        whole.evaluations()[start..(start + 10).min(n)]
            .iter()
            .all(|e| e.origin == Origin::Design)
    );
    let first_design: Vec<&Vec<f64>> = whole.evaluations()[..10].iter().map(|e| &e.x).collect();
    assert!(!first_design.contains(&&whole.evaluations()[start].x));
    // The best over every run is the study's best.
    let best = whole
        .evaluations()
        .iter()
        .filter_map(|e| e.value)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(whole.best().unwrap().value, Some(best));

    // Resume through JSON and rebuild from the history: the same sequence, restarts included.
    let mut first = Cors::new(f.space().unwrap(), options.clone()).unwrap();
    first.minimize(|x| f.eval(x), start + 3).unwrap();
    let mut resumed = Cors::from_json(&first.to_json().unwrap(), "state").unwrap();
    resumed.minimize(|x| f.eval(x), n - start - 3).unwrap();
    assert_eq!(resumed.evaluations(), whole.evaluations());
    assert_replays(
        &f,
        &options,
        &whole,
        &[start - 1, start, start + 4, start + 12, n - 1],
    );
}

/// A study rebuilt from the first `n` rows of `whole`'s history suggests `whole`'s next
/// point, for every `n` in `rows`.
fn assert_replays(f: &TestFunction, options: &CorsOptions, whole: &Cors, rows: &[usize]) {
    let xs: Vec<Vec<f64>> = whole.evaluations().iter().map(|e| e.x.clone()).collect();
    let fs: Vec<f64> = whole
        .evaluations()
        .iter()
        .map(|e| e.value.unwrap())
        .collect();
    for &n in rows {
        let mut rebuilt = Cors::from_history_rows(
            f.space().unwrap(),
            options.clone(),
            &xs[..n],
            &fs[..n],
            None,
        )
        .unwrap();
        let next = rebuilt.suggest(1).unwrap().pop().unwrap();
        assert_eq!(next.x, xs[n], "after {n} rows");
    }
}

#[test]
fn warm_start_replaces_the_design_and_improves() {
    // The source study: 50 existing runs, then 60 more.
    let f = test_functions::by_name("hartmann6").unwrap();
    let space = f.space().unwrap();
    let existing = impactcal_core::sampling::sample(
        &space,
        impactcal_core::SamplingMethod::LatinHypercube,
        50,
        11,
    )
    .unwrap()
    .points;
    let values: Vec<f64> = to_rows(existing.as_ref())
        .iter()
        .map(|x| f.eval(x))
        .collect();
    let best_existing = values.iter().copied().fold(f64::INFINITY, f64::min);
    // The source study's method: the 2005 pattern over the whole box in every cycle.
    let options = CorsOptions {
        local_region: None,
        ..CorsOptions::with_seed(2)
    };
    let mut study = Cors::new(space, options).unwrap();
    study.warm_start(existing.as_ref(), &values).unwrap();
    let out = study.minimize(|x| f.eval(x), 60).unwrap();
    assert_eq!(study.mode(), Some(Mode::Existing));
    assert_eq!(out.evaluations, 60);
    assert_eq!(study.evaluations().len(), 110);
    assert!(
        study.evaluations()[50..]
            .iter()
            .all(|e| e.origin == Origin::Cors)
    );
    let best = out.best.unwrap().value.unwrap();
    // A Latin hypercube of 50 leaves Hartmann6 far from its minimum (more than 25% off);
    // 60 CORS steps get within 10% of it.
    assert!(f.relative_error(best_existing) > 0.25, "{best_existing}");
    assert!(f.relative_error(best) < 0.1, "best {best}");
}

#[test]
fn warm_start_checks_its_input() {
    let space = test_functions::by_name("branin").unwrap().space().unwrap();
    let mut study = Cors::new(space.clone(), CorsOptions::default()).unwrap();
    let dup = study.warm_start_rows(
        &[vec![1.0, 2.0], vec![3.0, 4.0], vec![1.0, 2.0 + 1e-12]],
        &[1.0, 2.0, 3.0],
    );
    assert!(matches!(
        dup,
        Err(CorsError::NearDuplicate {
            first: 0,
            second: 2,
            ..
        })
    ));
    assert!(matches!(
        study.warm_start_rows(&[vec![1.0]], &[1.0]),
        Err(CorsError::Core(CoreError::DimensionMismatch { .. }))
    ));
    assert!(matches!(
        study.warm_start_rows(&[vec![11.0, 2.0]], &[1.0]),
        Err(CorsError::OutOfBounds { .. })
    ));
    assert!(study.evaluations().is_empty());
    // Existing-only on collinear points: the surrogate cannot be fitted.
    let options = CorsOptions {
        initial: InitialDesign::Existing,
        ..CorsOptions::default()
    };
    let mut only = Cors::new(space.clone(), options).unwrap();
    only.warm_start_rows(
        &[
            vec![0.0, 0.0],
            vec![1.0, 1.0],
            vec![2.0, 2.0],
            vec![3.0, 3.0],
        ],
        &[1.0, 2.0, 3.0, 4.0],
    )
    .unwrap();
    assert!(matches!(
        only.suggest(1),
        Err(CorsError::InsufficientInitialSet {
            successes: 4,
            rank_minus_one: 1,
            needed: 3,
            ..
        })
    ));
    // The same set under Auto: the design is run as well.
    let mut auto = Cors::new(space, CorsOptions::default()).unwrap();
    auto.warm_start_rows(
        &[
            vec![0.0, 0.0],
            vec![1.0, 1.0],
            vec![2.0, 2.0],
            vec![3.0, 3.0],
        ],
        &[1.0, 2.0, 3.0, 4.0],
    )
    .unwrap();
    assert_eq!(auto.suggest(1).unwrap()[0].origin, Origin::Design);
    assert_eq!(auto.mode(), Some(Mode::Design));
}

#[test]
fn failures_are_recorded_avoided_and_the_run_goes_on() {
    let f = test_functions::by_name("branin").unwrap();
    let space = f.space().unwrap();
    // The simulation crashes for x1 > 7 (a third of the box).
    let objective = |x: &[f64]| if x[0] > 7.0 { f64::NAN } else { f.eval(x) };
    let mut study = Cors::new(space.clone(), CorsOptions::with_seed(4)).unwrap();
    let out = study.minimize(objective, 60).unwrap();
    let failed: Vec<_> = study
        .evaluations()
        .iter()
        .filter(|e| !e.is_success())
        .collect();
    assert!(!failed.is_empty());
    assert!(failed.iter().all(|e| e.x[0] > 7.0 && e.value.is_none()));
    // No later point inside the no-go radius of an earlier failure.
    let radius = 0.05 * 2f64.sqrt();
    let evals = study.evaluations();
    for (k, e) in evals.iter().enumerate() {
        for g in evals[..k].iter().filter(|g| !g.is_success()) {
            if e.origin == Origin::Cors {
                assert!(unit_distance(&space, &e.x, &g.x) >= radius * (1.0 - 1e-9));
            }
        }
    }
    // Two of Branin's three minima lie in the working region; one is found.
    let best = out.best.unwrap().value.unwrap();
    assert!(f.relative_error(best) < 0.01, "best {best}");
}

#[test]
fn resume_from_json_gives_the_same_sequence() {
    let f = test_functions::by_name("hartmann3").unwrap();
    let options = CorsOptions::with_seed(9);
    let mut whole = Cors::new(f.space().unwrap(), options.clone()).unwrap();
    whole.minimize(|x| f.eval(x), 30).unwrap();

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("state.json");
    let mut first = Cors::new(f.space().unwrap(), options).unwrap();
    first.minimize(|x| f.eval(x), 14).unwrap();
    // Crash with a suggestion out for evaluation.
    let pending = first.suggest(1).unwrap().pop().unwrap();
    first.save(&path).unwrap();
    drop(first);
    let mut resumed = Cors::load(&path).unwrap();
    assert_eq!(resumed.pending().len(), 1);
    resumed.tell(pending.id, f.eval(&pending.x)).unwrap();
    resumed.minimize(|x| f.eval(x), 15).unwrap();
    assert_eq!(resumed.evaluations(), whole.evaluations());
}

#[test]
fn from_history_matches_the_library_loop() {
    let f = test_functions::by_name("shekel5").unwrap();
    let options = CorsOptions::with_seed(21);
    let mut study = Cors::new(f.space().unwrap(), options.clone()).unwrap();
    study.minimize(|x| f.eval(x), 25).unwrap();
    assert_replays(&f, &options, &study, &[0, 3, 10, 11, 24]);
}

/// A known budget sets the perturbation schedule's horizon by DYCORS's rule, the budget
/// less the evaluations before the run's first adaptive point: a study of budget 40 walks
/// the points of one with the horizon fixed at 40 - 14 (Hartmann-6's design of 14), and
/// after 20 existing evaluations at 40 - 20. Without a budget the horizon stays 300, and a
/// state saved before the budget existed (a fixed horizon of 300, no `budget` field) loads
/// and goes on as it did.
#[test]
fn budget_sets_the_perturbation_horizon() {
    let f = test_functions::by_name("hartmann6").unwrap();
    let space = f.space().unwrap();
    let walk = |options: CorsOptions, existing: Option<(&[Vec<f64>], &[f64])>| {
        let mut s = Cors::new(space.clone(), options).unwrap();
        if let Some((xs, fs)) = existing {
            s.warm_start_rows(xs, fs).unwrap();
        }
        s.minimize(|x| f.eval(x), 26).unwrap();
        s.evaluations().to_vec()
    };
    let fixed = |h: usize| CorsOptions {
        perturbation: Some(Perturbation { horizon: Some(h) }),
        ..CorsOptions::with_seed(3)
    };
    let budget = CorsOptions {
        budget: Some(40),
        ..CorsOptions::with_seed(3)
    };
    let by_budget = walk(budget.clone(), None);
    assert_eq!(by_budget, walk(fixed(26), None));
    let unknown = walk(CorsOptions::with_seed(3), None);
    assert_eq!(unknown, walk(fixed(300), None));
    assert_ne!(by_budget, unknown);
    let xs: Vec<Vec<f64>> = unknown[..20].iter().map(|e| e.x.clone()).collect();
    let fs: Vec<f64> = unknown[..20].iter().map(|e| e.value.unwrap()).collect();
    let warm = walk(budget, Some((&xs, &fs)));
    assert_eq!(warm, walk(fixed(20), Some((&xs, &fs))));
    // A state of the format before the budget: `"horizon": 300` and no `budget`.
    let mut old = Cors::new(space.clone(), CorsOptions::with_seed(3)).unwrap();
    old.minimize(|x| f.eval(x), 20).unwrap();
    let json = old.to_json().unwrap();
    let before = json
        .replace("\"horizon\": null", "\"horizon\": 300")
        .replace("\"budget\": null,", "");
    assert!(!before.contains("budget") && before.contains("\"horizon\": 300"));
    let mut resumed = Cors::from_json(&before, "old.json").unwrap();
    resumed.minimize(|x| f.eval(x), 6).unwrap();
    assert_eq!(resumed.evaluations(), &unknown[..26]);
}

/// The search options of the DYCORS and SRBF variants (coordinate perturbation, falling
/// candidate count, weight cycle) and repeated refinement keep a study a function of its history: resuming from
/// JSON and rebuilding from the rows give the library loop's points bit for bit.
#[test]
fn search_variants_resume_and_replay_exactly() {
    let f = test_functions::by_name("hartmann6").unwrap();
    let variants = [
        CorsOptions {
            perturbation: Some(Perturbation { horizon: Some(40) }),
            candidate_decay: Some(CandidateDecay {
                min_per_dim: 50,
                horizon: 40,
            }),
            ..CorsOptions::with_seed(5)
        },
        CorsOptions {
            merit_weights: Some(vec![0.3, 0.5, 0.8, 0.95]),
            ..CorsOptions::with_seed(6)
        },
        CorsOptions {
            repeat_refinement: Some(RepeatRefinement {
                max_beta: 0.25,
                max_repeats: 2,
            }),
            ..CorsOptions::with_seed(12)
        },
        CorsOptions {
            local_escape: Some(3),
            local_first: true,
            ..CorsOptions::with_seed(7)
        },
        CorsOptions {
            budget: Some(40),
            ..CorsOptions::with_seed(13)
        },
        // Short counts, so that the width shrinks, converges and escapes within 40 points.
        CorsOptions {
            adaptive_region: Some(AdaptiveRegion {
                grow_after: 2,
                shrink_after: Some(2),
                halvings: 2,
                on_converged: Converged::Escape,
                shrink_box: true,
            }),
            ..CorsOptions::with_seed(8)
        },
        CorsOptions {
            adaptive_region: Some(AdaptiveRegion {
                shrink_after: Some(3),
                shrink_box: false,
                ..AdaptiveRegion::default()
            }),
            ..CorsOptions::with_seed(11)
        },
        CorsOptions {
            adaptive_region: Some(AdaptiveRegion {
                grow_after: 2,
                shrink_after: Some(2),
                halvings: 1,
                on_converged: Converged::Restart,
                shrink_box: false,
            }),
            ..CorsOptions::with_seed(10)
        },
        CorsOptions {
            adaptive_region: Some(AdaptiveRegion {
                grow_after: 2,
                shrink_after: Some(2),
                halvings: 1,
                on_converged: Converged::RestartOutside,
                shrink_box: false,
            }),
            ..CorsOptions::with_seed(10)
        },
    ];
    for options in variants {
        let mut whole = Cors::new(f.space().unwrap(), options.clone()).unwrap();
        whole.minimize(|x| f.eval(x), 40).unwrap();
        let restarts_on_convergence = options.adaptive_region.is_some_and(|a| {
            matches!(
                a.on_converged,
                Converged::Restart | Converged::RestartOutside
            )
        });
        assert_eq!(whole.restarts() > 0, restarts_on_convergence);
        let default = {
            let o = CorsOptions {
                seed: options.seed,
                ..CorsOptions::default()
            };
            let mut s = Cors::new(f.space().unwrap(), o).unwrap();
            s.minimize(|x| f.eval(x), 40).unwrap();
            s
        };
        // The variant changes the search (after the common design of 14 points).
        assert_eq!(whole.evaluations()[..14], default.evaluations()[..14]);
        assert_ne!(whole.evaluations(), default.evaluations(), "{options:?}");
        let mut first = Cors::new(f.space().unwrap(), options.clone()).unwrap();
        first.minimize(|x| f.eval(x), 23).unwrap();
        let mut resumed = Cors::from_json(&first.to_json().unwrap(), "state").unwrap();
        resumed.minimize(|x| f.eval(x), 17).unwrap();
        assert_eq!(resumed.evaluations(), whole.evaluations());
        assert_replays(&f, &options, &whole, &[14, 21, 39]);
    }
    // Keeping the earlier runs' points outside their basins changes the restarted runs.
    let after_restarts = |on_converged| {
        let options = CorsOptions {
            adaptive_region: Some(AdaptiveRegion {
                grow_after: 2,
                shrink_after: Some(2),
                halvings: 1,
                on_converged,
                shrink_box: false,
            }),
            ..CorsOptions::with_seed(10)
        };
        let mut s = Cors::new(f.space().unwrap(), options).unwrap();
        s.minimize(|x| f.eval(x), 60).unwrap();
        s.evaluations().to_vec()
    };
    assert_ne!(
        after_restarts(Converged::Restart),
        after_restarts(Converged::RestartOutside)
    );
}

#[test]
fn batches_hold_distinct_points_with_consecutive_betas() {
    let f = test_functions::by_name("hartmann6").unwrap();
    let space = f.space().unwrap();
    let mut study = Cors::new(space.clone(), CorsOptions::with_seed(1)).unwrap();
    // The design (14 points) in two batches, told out of order.
    let mut a = study.suggest(10).unwrap();
    let b = study.suggest(10).unwrap();
    assert_eq!(a.len(), 10);
    assert_eq!(b.len(), 10);
    assert_eq!(b.iter().filter(|s| s.origin == Origin::Design).count(), 4);
    // Fill points while no surrogate exists (the design is still pending).
    assert!(b[4..].iter().all(|s| s.origin == Origin::Fill));
    a.reverse();
    for s in a.iter().chain(&b) {
        study.tell(s.id, f.eval(&s.x)).unwrap();
    }
    let batch = study.suggest(6).unwrap();
    // The six fill points took places 14..19 of the cycle that starts after the design.
    let betas: Vec<f64> = batch.iter().map(|s| s.beta.unwrap()).collect();
    assert_eq!(betas, vec![0.9, 0.75, 0.25, 0.05, 0.03, 0.0]);
    for (i, s) in batch.iter().enumerate() {
        for t in &batch[i + 1..] {
            assert!(unit_distance(&space, &s.x, &t.x) >= 1e-3 * 6f64.sqrt() * (1.0 - 1e-9));
        }
        for e in study.evaluations() {
            assert!(unit_distance(&space, &s.x, &e.x) >= 1e-3 * 6f64.sqrt() * (1.0 - 1e-9));
        }
    }
    assert!(matches!(
        study.tell(12345, 1.0),
        Err(CorsError::UnknownSuggestion(12345))
    ));
}

/// A fill point says why it is one: too few successes while the design is still pending
/// (expected), or a surrogate that cannot be fitted, here because the shifted-log transform
/// of values spanning -1e308 to 1e308 overflows. The failure is reported in the suggestion
/// and in the outcome of the loop, not hidden behind a space-filling point.
#[test]
fn fill_points_say_why() {
    let space = test_functions::by_name("branin").unwrap().space().unwrap();
    let options = CorsOptions {
        transform: Transform::ShiftedLog,
        ..CorsOptions::with_seed(1)
    };
    let mut study = Cors::new(space, options).unwrap();
    let batch = study.suggest(8).unwrap();
    assert_eq!(
        batch[..6]
            .iter()
            .filter(|s| s.origin == Origin::Design)
            .count(),
        6
    );
    for s in &batch[6..] {
        assert_eq!(s.origin, Origin::Fill);
        assert_eq!(
            s.fill_reason,
            Some(FillReason::TooFewSuccesses {
                successes: 0,
                needed: 3
            })
        );
        assert!(!s.fill_reason.as_ref().unwrap().is_failure());
    }
    assert!(batch[..6].iter().all(|s| s.fill_reason.is_none()));
    for (k, s) in batch.iter().enumerate() {
        let v = if k % 2 == 0 { 1e308 } else { -1e308 };
        study.tell(s.id, v).unwrap();
    }
    let out = study.minimize(|_| 1.0, 2).unwrap();
    assert_eq!(
        out.failed_fits,
        vec![
            FillReason::TransformNotFinite,
            FillReason::TransformNotFinite
        ]
    );
    let last = &study.evaluations()[8..];
    assert!(last.iter().all(|e| e.origin == Origin::Fill));
    // The reason travels with a pending suggestion through the saved state.
    let pending = study.suggest(1).unwrap().pop().unwrap();
    assert_eq!(pending.fill_reason, Some(FillReason::TransformNotFinite));
    let again = Cors::from_json(&study.to_json().unwrap(), "state").unwrap();
    assert_eq!(again.pending(), study.pending());
    // A study that can fit reports nothing.
    let f = test_functions::by_name("branin").unwrap();
    let mut plain = Cors::new(f.space().unwrap(), CorsOptions::with_seed(1)).unwrap();
    assert!(
        plain
            .minimize(|x| f.eval(x), 12)
            .unwrap()
            .failed_fits
            .is_empty()
    );
}

#[test]
fn stopping_rules() {
    let f = test_functions::by_name("branin").unwrap();
    let options = CorsOptions {
        stopping: Stopping {
            target: Some(0.45),
            ..Stopping::default()
        },
        ..CorsOptions::with_seed(0)
    };
    let mut study = Cors::new(f.space().unwrap(), options).unwrap();
    let out = study.minimize(|x| f.eval(x), 200).unwrap();
    assert_eq!(out.stop, StopReason::Target);
    assert!(out.best.unwrap().value.unwrap() <= 0.45);
    assert!(out.evaluations < 200);
    // A constant objective never improves after its first value.
    let options = CorsOptions {
        stopping: Stopping {
            patience: Some(10),
            ..Stopping::default()
        },
        ..CorsOptions::with_seed(0)
    };
    let mut flat = Cors::new(f.space().unwrap(), options).unwrap();
    let out = flat.minimize(|_| 1.0, 200).unwrap();
    assert_eq!(out.stop, StopReason::NoImprovement);
    assert_eq!(out.evaluations, 11);
}

#[test]
fn transforms() {
    let mut v = vec![5.0, 1.0, 100.0, 3.0, 2.0];
    Transform::MedianCap.apply(&mut v);
    assert_eq!(v, vec![3.0, 1.0, 3.0, 3.0, 2.0]);
    let mut v = vec![2.0, 1.0, 1.0 + std::f64::consts::E - 1.0];
    Transform::ShiftedLog.apply(&mut v);
    assert!((v[0] - 2f64.ln()).abs() < 1e-15 && v[1] == 0.0 && (v[2] - 1.0).abs() < 1e-15);
    // Goldstein-Price spans 3 to 1e6: under a log transform CORS reaches 1% quickly.
    let f = test_functions::by_name("goldstein-price").unwrap();
    let options = CorsOptions {
        transform: Transform::Log,
        ..CorsOptions::with_seed(0)
    };
    let mut study = Cors::new(f.space().unwrap(), options).unwrap();
    let out = study.minimize(|x| f.eval(x), 100).unwrap();
    assert!(f.relative_error(out.best.unwrap().value.unwrap()) < 0.01);
    // The log transform refuses non-positive values instead of recording them.
    let s = study.suggest(1).unwrap().pop().unwrap();
    assert!(matches!(
        study.tell(s.id, -1.0),
        Err(CorsError::TransformDomain { .. })
    ));
    assert_eq!(study.pending().len(), 1);
}

#[test]
fn thin_plate_kernel_works() {
    let f = test_functions::by_name("branin").unwrap();
    let options = CorsOptions {
        kernel: impactcal_cors::SurrogateKernel::ThinPlate,
        ..CorsOptions::with_seed(2)
    };
    let mut study = Cors::new(f.space().unwrap(), options).unwrap();
    let out = study.minimize(|x| f.eval(x), 60).unwrap();
    assert!(f.relative_error(out.best.unwrap().value.unwrap()) < 0.01);
}

#[test]
fn options_are_validated() {
    let space = ParameterSpace::new(vec![
        Parameter::new("a", 0.0, 1.0, 0.5).unwrap(),
        Parameter::new("b", 0.0, 1.0, 0.5).unwrap(),
    ])
    .unwrap();
    let bad = [
        CorsOptions {
            pattern: vec![],
            ..CorsOptions::default()
        },
        CorsOptions {
            pattern: vec![0.5, 1.5],
            ..CorsOptions::default()
        },
        CorsOptions {
            design_size: Some(2),
            ..CorsOptions::default()
        },
        CorsOptions {
            min_distance: 0.0,
            ..CorsOptions::default()
        },
        CorsOptions {
            polish_starts: 0,
            ..CorsOptions::default()
        },
        CorsOptions {
            local_region: Some(0.0),
            ..CorsOptions::default()
        },
        CorsOptions {
            restart: Some(Restart {
                patience: Some(0),
                ..Restart::default()
            }),
            ..CorsOptions::default()
        },
        CorsOptions {
            restart: Some(Restart {
                min_improvement: f64::NAN,
                ..Restart::default()
            }),
            ..CorsOptions::default()
        },
        CorsOptions {
            local_escape: Some(0),
            ..CorsOptions::default()
        },
        CorsOptions {
            perturbation: Some(Perturbation { horizon: Some(1) }),
            ..CorsOptions::default()
        },
        CorsOptions {
            repeat_refinement: Some(RepeatRefinement {
                max_beta: f64::NAN,
                max_repeats: 6,
            }),
            ..CorsOptions::default()
        },
        CorsOptions {
            repeat_refinement: Some(RepeatRefinement {
                max_beta: 0.05,
                max_repeats: 0,
            }),
            ..CorsOptions::default()
        },
        CorsOptions {
            candidate_decay: Some(CandidateDecay {
                min_per_dim: 0,
                horizon: 300,
            }),
            ..CorsOptions::default()
        },
        CorsOptions {
            candidate_decay: Some(CandidateDecay {
                min_per_dim: 301,
                horizon: 300,
            }),
            ..CorsOptions::default()
        },
        CorsOptions {
            candidate_decay: Some(CandidateDecay {
                min_per_dim: 100,
                horizon: 0,
            }),
            ..CorsOptions::default()
        },
        CorsOptions {
            adaptive_region: Some(AdaptiveRegion {
                grow_after: 0,
                ..AdaptiveRegion::default()
            }),
            ..CorsOptions::default()
        },
        CorsOptions {
            adaptive_region: Some(AdaptiveRegion {
                shrink_after: Some(0),
                ..AdaptiveRegion::default()
            }),
            ..CorsOptions::default()
        },
        CorsOptions {
            adaptive_region: Some(AdaptiveRegion {
                halvings: 0,
                ..AdaptiveRegion::default()
            }),
            ..CorsOptions::default()
        },
        CorsOptions {
            merit_weights: Some(vec![]),
            ..CorsOptions::default()
        },
        CorsOptions {
            budget: Some(0),
            ..CorsOptions::default()
        },
        CorsOptions {
            merit_weights: Some(vec![0.5, f64::NAN]),
            ..CorsOptions::default()
        },
    ];
    for o in bad {
        assert!(matches!(
            Cors::new(space.clone(), o),
            Err(CorsError::Core(CoreError::InvalidOption { .. }))
        ));
    }
    let text = Cors::new(space, CorsOptions::default())
        .unwrap()
        .to_json()
        .unwrap()
        .replace("impactcal-cors/1", "other/9");
    assert!(matches!(
        Cors::from_json(&text, "x.json"),
        Err(CorsError::State { .. })
    ));
}

/// The second region acts from the second whole-box cycle: with a pattern of two steps per
/// cycle, that is pattern cycle 2 (steps 4 and 5 after the design), so the first 4 steps
/// equal those of a single region and later ones differ; a study resumed from JSON or
/// rebuilt from its rows gives the same points bit for bit.
#[test]
fn the_second_region_acts_and_replays_exactly() {
    let f = test_functions::by_name("hartmann6").unwrap();
    let with = CorsOptions {
        pattern: vec![0.5, 0.0],
        repeat_refinement: None,
        ..CorsOptions::with_seed(12)
    };
    let without = CorsOptions {
        second_region: None,
        ..with.clone()
    };
    let run = |options: &CorsOptions| {
        let mut s = Cors::new(f.space().unwrap(), options.clone()).unwrap();
        s.minimize(|x| f.eval(x), 40).unwrap();
        s
    };
    let (a, b) = (run(&with), run(&without));
    let design = 14;
    assert_eq!(a.evaluations()[..design + 4], b.evaluations()[..design + 4]);
    assert_ne!(a.evaluations()[design + 4], b.evaluations()[design + 4]);
    let mut first = Cors::new(f.space().unwrap(), with.clone()).unwrap();
    first.minimize(|x| f.eval(x), 21).unwrap();
    let mut resumed = Cors::from_json(&first.to_json().unwrap(), "state").unwrap();
    resumed.minimize(|x| f.eval(x), 19).unwrap();
    assert_eq!(resumed.evaluations(), a.evaluations());
    assert_replays(&f, &with, &a, &[design + 4, design + 5, 39]);
}
