//! The adaptive half-width of the local region ([`AdaptiveRegion`]): a function of the
//! run's ordered evaluations only, so that a study rebuilt from its history searches the
//! same boxes as an uninterrupted one.

use crate::options::{AdaptiveRegion, Converged};
use crate::stall::StallRule;
use crate::state::Evaluation;

/// Relative improvement that counts as a success of the step-size rule and ends a stall of
/// the basin escape (pySOT's success threshold).
pub(crate) const SUCCESS_IMPROVEMENT: f64 = 1e-3;

/// The local region after a run's evaluations: its half-width and, under
/// [`Converged::Escape`], the rank of the basin its centre lies in (0: the best point's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LocalWidth {
    /// The adapted half-width `h`: the Gaussian candidates' scale is `h / local_region`.
    pub(crate) half: f64,
    /// Half-width of the box around the centre (`h`, or `local_region` when the box does
    /// not shrink).
    pub(crate) boxed: f64,
    /// Convergences since the run's last improvement (only counted under
    /// [`Converged::Escape`]).
    pub(crate) rank: usize,
    /// Convergences in the run.
    pub(crate) converged: usize,
}

/// Applies `rule` to the run's `evaluations`, counting successes and failures from index
/// `count_from` (the end of the run's initial set), from the half-width `initial`.
pub(crate) fn adaptive_width(
    rule: &AdaptiveRegion,
    initial: f64,
    evaluations: &[Evaluation],
    count_from: usize,
    dim: usize,
) -> LocalWidth {
    let stall = StallRule {
        min_improvement: SUCCESS_IMPROVEMENT,
        floor: 0.0,
    };
    let shrink_after = rule.shrink_after_for(dim);
    let floor = initial * 0.5f64.powi(rule.halvings as i32);
    let mut best = None;
    let (mut successes, mut failures) = (0, 0);
    let mut width = LocalWidth {
        half: initial,
        boxed: initial,
        rank: 0,
        converged: 0,
    };
    for (k, e) in evaluations.iter().enumerate() {
        let improved = stall.improves(e.value, &mut best);
        if k < count_from {
            continue;
        }
        if improved {
            successes += 1;
            failures = 0;
            width.rank = 0;
        } else {
            failures += 1;
            successes = 0;
        }
        if successes >= rule.grow_after {
            width.half = (2.0 * width.half).min(initial);
            successes = 0;
        }
        if failures >= shrink_after {
            width.half *= 0.5;
            failures = 0;
            if width.half < floor {
                width.half = initial;
                width.converged += 1;
                if rule.on_converged == Converged::Escape {
                    width.rank += 1;
                }
            }
        }
    }
    if rule.shrink_box {
        width.boxed = width.half;
    }
    width
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::evaluations_with_values;

    fn evals(values: &[f64]) -> Vec<Evaluation> {
        evaluations_with_values(&values.iter().map(|&v| Some(v)).collect::<Vec<_>>())
    }

    /// Halves after `shrink_after` failures, doubles (capped) after `grow_after`
    /// successes, and restores the width (escaping under `Escape`) past the floor.
    #[test]
    #[allow(clippy::float_cmp)] // powers of two, exact by construction
    fn follows_dycors_rule() {
        let rule = AdaptiveRegion {
            grow_after: 2,
            shrink_after: Some(3),
            halvings: 2,
            on_converged: Converged::Escape,
            shrink_box: true,
        };
        // Initial set [10]; then 3 failures: 0.4 -> 0.2.
        let mut v = vec![10.0, 10.0, 10.0, 10.0];
        assert_eq!(adaptive_width(&rule, 0.4, &evals(&v), 1, 1).half, 0.2);
        // Three more: 0.1 (= 0.4 / 4, the floor, not below it).
        v.extend([10.0; 3]);
        let w = adaptive_width(&rule, 0.4, &evals(&v), 1, 1);
        assert_eq!((w.half, w.boxed, w.rank), (0.1, 0.1, 0));
        let fixed = AdaptiveRegion {
            shrink_box: false,
            ..rule
        };
        let w = adaptive_width(&fixed, 0.4, &evals(&v), 1, 1);
        assert_eq!((w.half, w.boxed), (0.1, 0.4));
        // Two successes: doubled to 0.2.
        v.extend([9.0, 8.0]);
        assert_eq!(adaptive_width(&rule, 0.4, &evals(&v), 1, 1).half, 0.2);
        // Two more successes: 0.4, capped there by two further ones.
        v.extend([7.0, 6.0, 5.0, 4.0]);
        assert_eq!(adaptive_width(&rule, 0.4, &evals(&v), 1, 1).half, 0.4);
        // Nine failures: 0.2, 0.1, then below the floor: restored and escaped once.
        v.extend([4.0; 9]);
        let w = adaptive_width(&rule, 0.4, &evals(&v), 1, 1);
        assert_eq!((w.half, w.rank, w.converged), (0.4, 1, 1));
        // An improvement of less than 0.1 % is a failure; a larger one resets the rank.
        v.push(3.999);
        assert_eq!(adaptive_width(&rule, 0.4, &evals(&v), 1, 1).rank, 1);
        v.push(3.0);
        assert_eq!(adaptive_width(&rule, 0.4, &evals(&v), 1, 1).rank, 0);
        // Under Restore the rank stays 0; the default shrink count is max(5, d).
        let restore = AdaptiveRegion {
            on_converged: Converged::Restore,
            ..rule
        };
        let w = adaptive_width(&restore, 0.4, &evals(&v[..22]), 1, 1);
        assert_eq!((w.half, w.rank), (0.4, 0));
        assert_eq!(AdaptiveRegion::default().shrink_after_for(3), 5);
        assert_eq!(AdaptiveRegion::default().shrink_after_for(6), 6);
        // Evaluations of the initial set are not counted.
        assert_eq!(adaptive_width(&rule, 0.4, &evals(&v[..7]), 7, 1).half, 0.4);
    }
}
