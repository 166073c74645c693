//! The one "no improvement" rule of a study, shared by the restart rule
//! ([`Restart`](crate::Restart)) and the stopping rule ([`Stopping`](crate::Stopping)).
//!
//! Walking the evaluations in order with the best successful value `b` so far, an
//! evaluation *improves* when it is the first success, or a success of value
//! `v < b - min_improvement * max(|b|, floor)`; failures never improve. The stall length is
//! the number of evaluations since the last improvement, counting only those at or after
//! `count_from`. The restart rule counts within the current run from the start of its
//! cycle (`floor` 0); the stopping rule counts over the whole study (`floor` `1e-12`).

use crate::state::Evaluation;

/// The parameters of the rule.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct StallRule {
    /// Relative improvement that counts.
    pub min_improvement: f64,
    /// Lower bound on `|b|` in the threshold (keeps a best value of 0 improvable).
    pub floor: f64,
}

impl StallRule {
    /// Whether a result `value` (`None`: failed) improves on the best value so far, which
    /// it then updates.
    pub(crate) fn improves(&self, value: Option<f64>, best: &mut Option<f64>) -> bool {
        let improved = match (value, *best) {
            (Some(_), None) => true,
            (Some(v), Some(b)) => v < b - self.min_improvement * b.abs().max(self.floor),
            (None, _) => false,
        };
        if let Some(v) = value {
            *best = Some(best.map_or(v, |b| b.min(v)));
        }
        improved
    }

    /// The stall length of `evaluations` (see the module documentation): evaluations since
    /// the last improvement, counting those at index `count_from` or later.
    pub(crate) fn stall_length(&self, evaluations: &[Evaluation], count_from: usize) -> usize {
        let mut best: Option<f64> = None;
        let mut since = 0;
        for (k, e) in evaluations.iter().enumerate() {
            let improved = self.improves(e.value, &mut best);
            if improved {
                since = 0;
            } else if k >= count_from {
                since += 1;
            }
        }
        since
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::evaluations_with_values as evals;

    #[test]
    fn counts_since_the_last_substantial_improvement() {
        let rule = StallRule {
            min_improvement: 0.1,
            floor: 0.0,
        };
        // 10 improves (first success), 9.5 is not 10 % better, 8 is; then a failure and 7.9.
        let e = evals(&[None, Some(10.0), Some(9.5), Some(8.0), None, Some(7.9)]);
        assert_eq!(rule.stall_length(&e, 0), 2);
        // Counting only from index 5: the failure at 4 is not counted.
        assert_eq!(rule.stall_length(&e, 5), 1);
        // No success: every counted evaluation stalls.
        assert_eq!(rule.stall_length(&evals(&[None, None, None]), 1), 2);
        assert_eq!(rule.stall_length(&[], 0), 0);
        // The floor keeps a best of 0 improvable by a tiny decrease only above it.
        let at_zero = evals(&[Some(0.0), Some(-1e-14)]);
        let floored = StallRule {
            min_improvement: 0.5,
            floor: 1e-12,
        };
        assert_eq!(floored.stall_length(&at_zero, 0), 1);
        assert_eq!(rule.stall_length(&at_zero, 0), 0);
    }
}
