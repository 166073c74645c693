//! The loop's first stages: its inputs checked (the options, the candidates they name, the
//! holdout's condition), then the nominal run, the test on the model's channels and the
//! memory plan made from the shapes that run gives.

use impactcal_core::{ChannelMap, Enrichable, Histories};

use crate::study::subspace::near;

use super::Holdout;
use super::fit::Journaled;
use super::options::LoopOptions;
use super::plan::{LoopShapes, Plan};
use crate::error::{CalibrateError, Result};
use crate::memory::Guard;
use crate::study::TestData;
use crate::study::channels::{TestPreparation, prepared_test};

/// Checks a loop's options against `model` before any run: the options and run budgets
/// ([`LoopOptions::check_budgets`] against the model's dimension), every candidate `options` names
/// (one the model does not list is refused with the closest names it does list), and that
/// at least one candidate is left to consider; and that a stage of each run count the
/// options give can hold its points and run records in memory.
///
/// # Errors
/// [`LoopOptions::check_budgets`]'s errors; [`CalibrateError::Memory`] for a run count whose
/// stage cannot be held; [`CalibrateError::Study`] for a candidate the model
/// does not list or an empty candidate list.
pub fn check_inputs<M: Enrichable>(model: &M, options: &LoopOptions) -> Result<()> {
    options.check_budgets(model.space().dim())?;
    crate::memory::check_run_counts(
        Guard::new(options.max_memory),
        &[
            ("loop.jitter_runs", options.ensemble),
            ("loop.reconcile_runs", options.reconcile),
            ("loop.recalibrate_runs", options.recalibrate),
        ],
        model.space().dim() + options.max_added,
    )?;
    let listed = model.candidates();
    let names: Vec<&str> = listed.iter().map(|c| c.name()).collect();
    if let Some(asked) = &options.candidates {
        for n in asked {
            if !names.contains(&n.as_str()) {
                return Err(CalibrateError::study(
                    format!("candidate `{n}`"),
                    format!(
                        "not a candidate of the model; the closest it lists: {} (of {})",
                        near(n, &names),
                        names.len()
                    ),
                ));
            }
        }
    }
    if !listed.iter().any(|c| options.allows(c.name())) {
        return Err(CalibrateError::study(
            "candidate list",
            "empty: the loop has no candidate effect to attribute a residual to",
        ));
    }
    Ok(())
}

/// Checks the options against the model's space and candidates, and builds the model at
/// the holdout's condition (returned beside the holdout).
///
/// # Errors
/// As [`check_inputs`]; [`CalibrateError::Study`] for a holdout condition the model cannot
/// take.
pub(super) fn checked_inputs<'h, M: Enrichable>(
    model: &M,
    options: &LoopOptions,
    holdout: Option<Holdout<'h>>,
) -> Result<Option<(Holdout<'h>, M)>> {
    check_inputs(model, options)?;
    holdout
        .map(|h| {
            let at = model.at_condition(h.set).map_err(|e| {
                CalibrateError::study("[holdout] set", format!("the model cannot take it: {e}"))
            })?;
            Ok((h, at))
        })
        .transpose()
}

/// The nominal run and the test on the model's channels.
pub(super) struct Nominal {
    /// The nominal point of the model's space.
    pub point: Vec<f64>,
    /// The nominal run, as the model wrote it.
    pub raw: Histories,
    /// The test on the model's time base and channels (offsets kept: the nuisance terms
    /// fit a bias per channel on every sample).
    pub test: Histories,
    /// The samples `core::quality` masks, per channel in the test's order.
    pub masks: Vec<Vec<bool>>,
    /// How the test was prepared.
    pub preparation: TestPreparation,
    /// The channels compared.
    pub labels: Vec<String>,
    /// The channels of either side left out of the comparison.
    pub dropped: crate::metrics::Dropped,
}

/// Runs the model at its nominal point (journal stage `nominal`) and prepares the test on
/// its channels (`study::channels::prepared_test`).
///
/// # Errors
/// Run and journal errors; test channels the map (or the model's labels) do not cover;
/// the test preparation's errors.
pub(super) fn nominal<M: Enrichable>(
    runner: &Journaled<'_>,
    model: &M,
    test: TestData<'_>,
) -> Result<Nominal> {
    let point = model.space().nominal();
    let raw = runner
        .stage(model, "nominal", std::slice::from_ref(&point))?
        .histories(0, "the nominal run")?;
    check_covered(test.histories, test.map, &raw, "test")?;
    let (test_m, masks, preparation) =
        prepared_test(test.histories, test.map, test.cfc, &raw, None)?;
    let labels = test_m.labels().to_vec();
    let dropped = crate::study::channels::dropped(test.histories, test.map, &raw)?;
    if let Some(w) = dropped.warning(labels.len()) {
        runner.observer.warning(&w);
    }
    Ok(Nominal {
        point,
        raw,
        test: test_m,
        masks,
        preparation,
        labels,
        dropped,
    })
}

/// The memory plan from the shapes the nominal run gives, checked for every stage before
/// any of them runs. `threads` is 0 when a worker runs the model.
///
/// # Errors
/// [`CalibrateError::Memory`] for a stage whose estimate does not fit.
pub(super) fn plan<M: Enrichable>(
    model: &M,
    nominal: &Nominal,
    options: &LoopOptions,
    threads: usize,
) -> Result<Plan> {
    let plan = Plan {
        shapes: LoopShapes {
            channels: nominal.labels.len(),
            samples: nominal.test.samples(),
            run_values: nominal.raw.channels() * nominal.raw.samples(),
            dense: model.space().dim() + options.max_added + 1,
            candidates: model
                .candidates()
                .iter()
                .filter(|c| options.allows(c.name()))
                .count(),
            threads,
            m1_members: options.m1_members,
        },
        guard: Guard::new(options.max_memory),
    };
    plan.check_all()?;
    Ok(plan)
}

/// Every test channel must pair with a model channel (through the map, or by label).
///
/// # Errors
/// [`CalibrateError::Study`] naming the channels not covered and the model's channels.
pub(super) fn check_covered(
    test: &Histories,
    map: Option<&ChannelMap>,
    model: &Histories,
    what: &str,
) -> Result<()> {
    let missing: Vec<&str> = test
        .labels()
        .iter()
        .filter(|l| match map {
            Some(m) => !m.entries.iter().any(|e| &&e.test_label == l),
            None => model.index_of(l).is_none(),
        })
        .map(String::as_str)
        .collect();
    if missing.is_empty() {
        Ok(())
    } else {
        Err(CalibrateError::study(
            format!("{what} channels"),
            format!(
                "{} not covered by {} (model channels: {}); map them or drop them from the test",
                missing.join(", "),
                if map.is_some() {
                    "the channel map"
                } else {
                    "the model's labels"
                },
                model.labels().join(", ")
            ),
        ))
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::closeloop::toy::{self, Toy};
    use impactcal_core::Model;
    use std::cell::Cell;

    /// Each bad input is refused before any run, naming what is wrong.
    #[test]
    fn bad_inputs_are_refused_naming_them() {
        let model = Toy::new(0.0, 0.0, 1.0);
        let options = toy::options(0.01);
        let message = |o: &LoopOptions, h: Option<Holdout<'_>>| {
            checked_inputs(&model, o, h).err().unwrap().to_string()
        };
        let e = message(
            &LoopOptions {
                candidates: Some(vec!["z".into()]),
                ..options.clone()
            },
            None,
        );
        assert!(
            e.contains("candidate `z`") && e.contains("the closest it lists: `c`, `m` (of 2)"),
            "{e}"
        );
        let e = message(
            &LoopOptions {
                alpha: 0.7,
                ..options.clone()
            },
            None,
        );
        assert!(e.contains("alpha"), "{e}");
        let h = toy::measured(&model, 1.0, 0.01, 1, None);
        let set = vec![("w".to_string(), 2.0)];
        let e = message(
            &options,
            Some(Holdout {
                histories: &h,
                set: &set,
            }),
        );
        assert!(e.contains("[holdout] set"), "{e}");
        // A holdout the model can take comes back with the model at its condition.
        let set = vec![("v".to_string(), 2.0)];
        let (_, at) = checked_inputs(
            &model,
            &options,
            Some(Holdout {
                histories: &h,
                set: &set,
            }),
        )
        .unwrap()
        .unwrap();
        let (a, _) = at.channels(&[1.0]);
        let (a1, _) = model.channels(&[1.0]);
        assert!((a[T_LAST] - 2.0 * a1[T_LAST]).abs() < 1e-12);
    }

    const T_LAST: usize = toy::T - 1;

    /// The nominal stage runs the model at its nominal point and gives the test on its
    /// channels unchanged (same time base); a test channel the model lacks is refused.
    #[test]
    fn the_nominal_stage_pairs_the_test_with_the_model() {
        let model = Toy::new(0.0, 0.0, 1.0);
        let dir = tempfile::tempdir().unwrap();
        let used = Cell::new(0);
        let runner = toy::journaled(dir.path(), &used);
        let test = toy::measured(&model, 1.2, 0.01, 2, None);
        let data = |h| TestData {
            histories: h,
            map: None,
            cfc: None,
        };
        let n = nominal(&runner, &model, data(&test)).unwrap();
        assert_eq!(n.point, vec![1.0]);
        assert_eq!(n.raw, model.simulate(&[1.0]).unwrap());
        assert_eq!(n.labels, ["a", "b"]);
        assert_eq!(n.test.data(), test.data());
        assert_eq!(used.get(), 1);
        let plan = plan(&model, &n, &toy::options(0.01), 1).unwrap();
        assert_eq!(plan.shapes.channels, 2);
        assert_eq!(plan.shapes.samples, toy::T);
        assert_eq!(plan.shapes.candidates, 2);
        assert_eq!(plan.shapes.dense, 1 + 2 + 1);
        let extra = Histories::from_channels(
            vec!["a".into(), "q".into()],
            vec![test.channel(0).to_vec(), test.channel(1).to_vec()],
            toy::DT,
            0.0,
            "",
        )
        .unwrap();
        let e = nominal(&runner, &model, data(&extra))
            .err()
            .unwrap()
            .to_string();
        assert!(
            e.contains("test channels") && e.contains("q not covered"),
            "{e}"
        );
    }
}
