//! The loop's first stages: its inputs checked (the options, the candidates they name, the
//! holdout's condition), then the nominal run, the test on the model's channels and the
//! memory plan made from the shapes that run gives.

use impactcal_core::{ChannelMap, Enrichable, Histories};

use super::Holdout;
use super::fit::Journaled;
use super::options::LoopOptions;
use super::plan::{LoopShapes, Plan};
use crate::error::{CalibrateError, Result};
use crate::memory::Guard;
use crate::study::TestData;
use crate::study::channels::{TestPreparation, prepared_test};

/// Checks the options against the model's space and candidates, and builds the model at
/// the holdout's condition (returned beside the holdout).
///
/// # Errors
/// [`CalibrateError::Study`] for invalid options or a budget too small to recalibrate, a
/// candidate the model does not list, no candidate left to consider, a holdout condition
/// the model cannot take.
pub(super) fn checked_inputs<'h, M: Enrichable>(
    model: &M,
    options: &LoopOptions,
    holdout: Option<Holdout<'h>>,
) -> Result<Option<(Holdout<'h>, M)>> {
    options.check(model.space().dim())?;
    let listed = model.candidates();
    if let Some(names) = &options.candidates {
        for n in names {
            if !listed.iter().any(|c| c.name() == n) {
                return Err(CalibrateError::study(
                    format!("candidate `{n}`"),
                    format!(
                        "not a candidate of the model (it lists: {})",
                        listed
                            .iter()
                            .map(|c| c.name())
                            .collect::<Vec<_>>()
                            .join(", ")
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
    Ok(Nominal {
        point,
        raw,
        test: test_m,
        masks,
        preparation,
        labels,
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
