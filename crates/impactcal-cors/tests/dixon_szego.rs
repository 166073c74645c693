//! The seven Dixon-Szego functions reach 1% relative error within the budgets recorded in
//! docs/validation.md (from the 30-seed study of `benches/peers/cors_pysot.sh`; here a
//! few seeds each, so that the suite stays fast).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use impactcal_core::test_functions;
use impactcal_cors::{Cors, CorsOptions, Stopping, Transform};

/// Evaluations until the best value is within 1% of the minimum, or `None` within `budget`.
fn evaluations_to_1pct(
    name: &str,
    seed: u64,
    transform: Transform,
    budget: usize,
) -> Option<usize> {
    evaluations_with(name, transform, budget, CorsOptions::with_seed(seed))
}

/// As [`evaluations_to_1pct`], with `base` options (the seed among them).
fn evaluations_with(
    name: &str,
    transform: Transform,
    budget: usize,
    base: CorsOptions,
) -> Option<usize> {
    let f = test_functions::by_name(name).unwrap();
    let options = CorsOptions {
        transform,
        stopping: Stopping {
            // Relative error below 1%: f < f* + 0.01 |f*| (the target is inclusive).
            target: Some(f.minimum + 0.01 * f.minimum.abs() * (1.0 - 1e-12)),
            ..Stopping::default()
        },
        ..base
    };
    let mut study = Cors::new(f.space().unwrap(), options).unwrap();
    let out = study.minimize(|x| f.eval(x), budget).unwrap();
    let best = out.best.unwrap().value.unwrap();
    (f.relative_error(best) < 0.01).then_some(study.evaluations().len())
}

fn check(name: &str, transform: Transform, cases: &[(u64, usize)]) {
    for &(seed, budget) in cases {
        let n = evaluations_to_1pct(name, seed, transform, budget);
        assert!(
            n.is_some_and(|n| n <= budget),
            "{name}, seed {seed}: not within 1% after {budget} evaluations"
        );
    }
}

#[test]
fn branin() {
    check("branin", Transform::Identity, &[(0, 20), (2, 20), (4, 20)]);
}

#[test]
fn goldstein_price() {
    check("goldstein-price", Transform::Identity, &[(2, 120)]);
    check("goldstein-price", Transform::Log, &[(0, 80)]);
}

#[test]
fn hartmann3() {
    check("hartmann3", Transform::Identity, &[(0, 30), (3, 30)]);
}

#[test]
fn hartmann6() {
    check("hartmann6", Transform::Identity, &[(0, 65), (7, 65)]);
}

/// Seed 1 of Hartmann-6 starts from a design whose best point lies in the basin of the
/// local minimum -3.2032. With one local region the run stays there (best -3.135 after 300
/// evaluations); the second region, around the best point outside the first one's reach,
/// finds the global basin (1 % after 194 evaluations in the record of 2026-11-27).
#[test]
fn the_second_region_leaves_the_basin_of_the_design() {
    let single = CorsOptions {
        second_region: None,
        ..CorsOptions::with_seed(1)
    };
    assert_eq!(
        evaluations_with("hartmann6", Transform::Identity, 300, single),
        None
    );
    assert!(evaluations_to_1pct("hartmann6", 1, Transform::Identity, 210).is_some());
}

#[test]
fn shekel5() {
    // Seeds 0 and 4 need 100 and 126 in the record of 2026-11-27 (bordered factorisation,
    // perturbation, basin escape, second region and repeated refinement on); the Shekel
    // runs are sensitive to the last bits of the fit.
    check("shekel5", Transform::Identity, &[(0, 120), (4, 150)]);
}

#[test]
fn shekel7() {
    check("shekel7", Transform::Identity, &[(3, 70), (5, 70)]);
}

#[test]
fn shekel10() {
    check("shekel10", Transform::Identity, &[(2, 70), (4, 70)]);
}

#[test]
fn a_hard_budget_is_not_met_by_chance() {
    // The check can fail: Hartmann6 is not solved in its own design plus 6 steps.
    assert_eq!(
        evaluations_to_1pct("hartmann6", 0, Transform::Identity, 20),
        None
    );
}
