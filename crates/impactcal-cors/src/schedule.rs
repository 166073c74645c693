//! Where a step stands in the `beta` pattern: one place further per evaluation after the
//! run's initial set, except where a refinement step that improved is taken again
//! ([`RepeatRefinement`]). A function of the run's ordered results only, so that a study
//! rebuilt from its history walks the same schedule as an uninterrupted one.

use crate::options::CorsOptions;
use crate::region::SUCCESS_IMPROVEMENT;
use crate::stall::StallRule;
use crate::state::Evaluation;

/// The position in the pattern (`beta = pattern[p mod k]`, cycle `p div k`) of the run's
/// step number `step` (counted from the run's first row), where `run` holds the run's
/// results known so far and the adaptive steps start at row `cycle_start`.
///
/// Rows at or past `run.len()` (pending, or being proposed) advance the pattern as steps
/// that did not succeed. Without [`CorsOptions::repeat_refinement`] this is
/// `step - cycle_start` (zero before the cycle starts).
pub(crate) fn pattern_position(
    options: &CorsOptions,
    run: &[Evaluation],
    cycle_start: usize,
    step: usize,
) -> usize {
    let plain = step.saturating_sub(cycle_start);
    let Some(rule) = &options.repeat_refinement else {
        return plain;
    };
    let k = options.pattern.len();
    let stall = StallRule {
        min_improvement: SUCCESS_IMPROVEMENT,
        floor: 0.0,
    };
    let mut best = None;
    let (mut position, mut repeats) = (0, 0);
    for (row, e) in run.iter().enumerate().take(step) {
        let improved = stall.improves(e.value, &mut best);
        if row < cycle_start {
            continue;
        }
        let refining = options.pattern[position % k] <= rule.max_beta;
        if refining && improved && repeats < rule.max_repeats {
            repeats += 1;
        } else {
            position += 1;
            repeats = 0;
        }
    }
    // Rows not yet known advance the pattern.
    position + step.saturating_sub(run.len().max(cycle_start))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::options::RepeatRefinement;
    use crate::state::evaluations_with_values as run;

    fn betas(options: &CorsOptions, values: &[Option<f64>], cycle_start: usize) -> Vec<f64> {
        let r = run(values);
        (cycle_start..=values.len())
            .map(|step| {
                let p = pattern_position(options, &r, cycle_start, step);
                options.pattern[p % options.pattern.len()]
            })
            .collect()
    }

    /// A refinement step that improves by more than 0.1 % is taken again, up to the cap;
    /// exploration steps, small improvements, failures and pending rows advance.
    #[test]
    fn repeats_refinement_while_it_improves() {
        let options = CorsOptions {
            repeat_refinement: Some(RepeatRefinement {
                max_beta: 0.05,
                max_repeats: 2,
            }),
            ..CorsOptions::default()
        };
        let v = |x: f64| Some(x);
        // Initial set of two (best 10); steps at 0.9 and 0.75 improve but do not repeat;
        // 0.25 does not improve; 0.05 improves (10 -> 8): repeated; again (8 -> 7):
        // repeated; a third success hits the cap of 2: the pattern moves to 0.03; a failed
        // evaluation there advances to 0; an improvement of 0.05 % at 0 advances to the next
        // cycle's 0.9.
        let values = [
            v(10.0),
            v(12.0),
            v(9.9),
            v(9.8),
            v(9.9),
            v(8.0),
            v(7.0),
            v(6.0),
            None,
            v(5.998),
        ];
        assert_eq!(
            betas(&options, &values, 2),
            [0.9, 0.75, 0.25, 0.05, 0.05, 0.05, 0.03, 0.0, 0.9]
        );
        // Pending rows (past the known results) advance one place each.
        let r = run(&values[..6]);
        let known = pattern_position(&options, &r, 2, 6);
        assert_eq!(pattern_position(&options, &r, 2, 8), known + 2);
        // Without the option the pattern advances once per row from the cycle's start.
        let plain = CorsOptions {
            repeat_refinement: None,
            ..options
        };
        assert_eq!(
            betas(&plain, &values, 2),
            [0.9, 0.75, 0.25, 0.05, 0.03, 0.0, 0.9, 0.75, 0.25]
        );
        assert_eq!(pattern_position(&plain, &run(&values), 2, 1), 0);
    }
}
