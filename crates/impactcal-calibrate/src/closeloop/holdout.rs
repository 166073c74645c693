//! The holdout stage: the nominal, calibrated and enriched models run at the holdout's
//! condition and judged against the holdout test, which the loop never fits (its trigger
//! offset and biases are profiled, its gains are the calibration test's sensors').

use impactcal_core::{Enrichable, Parameter};

use super::Holdout;
use super::fit::Fit;
use super::frame::{FrameInputs, Setting, compared, frame_of, model_spread, noise_model};
use super::judge::Judge;
use super::nuisance;
use super::options::LoopOptions;
use super::result::{Errors, Stages};
use super::setup::{Nominal, check_covered};
use crate::error::Result;
use crate::study::TestData;
use crate::study::channels::prepared_test;

/// The holdout's errors: `declared_at` is the declared model at the holdout's condition,
/// `added` the candidates forward selection kept, `fit0` the declared model's calibration
/// and `fit` the enriched model's; `test` gives the channel map and filter the holdout
/// shares with the calibration test. Journal stages `holdout-nominal`,
/// `holdout-calibrated`, `holdout-enriched` and `holdout-noise`; streams 3, 4, 5 of the M1
/// seeds.
///
/// # Errors
/// A holdout the enriched model cannot take; holdout channels the map does not cover; run,
/// journal, noise-floor and numerical errors.
#[allow(clippy::too_many_arguments)]
pub(super) fn holdout_errors<M: Enrichable>(
    setting: &Setting<'_>,
    model: &M,
    (h, declared_at): (Holdout<'_>, &M),
    added: &[Parameter],
    nominal: &Nominal,
    (fit0, fit): (&Fit, &Fit),
    test: TestData<'_>,
    options: &LoopOptions,
) -> Result<Stages<Errors>> {
    let ctx = &setting.ctx;
    let runner = ctx.runner.at(h.set);
    let labels = &nominal.labels;
    let enriched_at = model.enrich(added)?.at_condition(h.set)?;
    let run = |m: &M, stage: &str, point: &Vec<f64>, what: &str| {
        runner
            .stage(m, stage, std::slice::from_ref(point))?
            .histories(0, what)
    };
    // The holdout's nominal run keeps every channel, as the test's does: the holdout's
    // test is prepared against it.
    let nominal_h = runner
        .keeping_all()
        .stage(
            declared_at,
            "holdout-nominal",
            std::slice::from_ref(&nominal.point),
        )?
        .histories(0, "the holdout's nominal run")?;
    check_covered(h.histories, test.map, &nominal_h, "holdout")?;
    let (test_h, masks_h, preparation_h) =
        prepared_test(h.histories, test.map, test.cfc, &nominal_h, None)?;
    let calibrated_h = run(
        declared_at,
        "holdout-calibrated",
        &fit0.point,
        "the holdout's calibrated run",
    )?;
    let enriched_h = run(
        &enriched_at,
        "holdout-enriched",
        &fit.point,
        "the holdout's enriched run",
    )?;
    let (spread_h, model_noise_h) = model_spread(
        runner,
        declared_at,
        &nominal.point,
        &nominal_h,
        options,
        labels,
        test.cfc,
        "holdout-noise",
    )?;
    let y_nom_h = compared(&nominal_h, test.cfc, labels)?;
    let gains = &fit.terms.gains;
    let (mut frame_h, floor_h) = frame_of(
        FrameInputs {
            labels,
            test: test_h.data(),
            samples: test_h.samples(),
            dt: ctx.frame.dt,
            y_nominal: &y_nom_h,
            model_noise: &model_noise_h,
            spread: &spread_h,
            max_shift: ctx.max_shift,
            filters: (test.cfc, setting.band),
            fixed_gains: Some(gains),
            lead: preparation_h.pre_trigger.as_ref(),
        },
        options,
    )?;
    noise_model(&mut frame_h, &masks_h, &floor_h, test.cfc)?;
    let ys = [
        y_nom_h,
        compared(&calibrated_h, test.cfc, labels)?,
        compared(&enriched_h, test.cfc, labels)?,
    ];
    let judge = Judge {
        options,
        noise_dof: floor_h.level_dof(),
    };
    let at = |k: usize| {
        let terms = nuisance::profile(&ys[k], &frame_h, ctx.max_shift, Some(gains)).0;
        judge.errors(
            &frame_h,
            &ys[k],
            &terms,
            setting.n_nuisance,
            None,
            3 + k as u64,
        )
    };
    Ok(Stages {
        nominal: at(0)?,
        calibrated: at(1)?,
        enriched: at(2)?,
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::closeloop::recalibration;
    use crate::closeloop::toy::{self, Toy};

    /// The holdout stage on the two-channel toy at the condition `v = 1.5`: each stage's
    /// relative L2 error equals the hand computation with the models at that condition,
    /// and the enriched model (which found the hidden `c`) predicts the holdout best.
    #[test]
    fn holdout_errors_equal_the_hand_computed_l2() {
        let model = Toy::new(0.0, 0.0, 1.0);
        let truth = Toy::new(0.3, 0.0, 1.0);
        let options = toy::options(0.01);
        let test = toy::measured(&truth, 1.3, 0.01, 5, None);
        let set = vec![("v".to_string(), 1.5)];
        let held_out = toy::measured(&truth.at_condition(&set).unwrap(), 1.3, 0.01, 6, None);
        let declared_at = model.at_condition(&set).unwrap();
        let h = Holdout {
            histories: &held_out,
            set: &set,
        };
        let data = TestData {
            histories: &test,
            map: None,
            cfc: None,
        };
        toy::with_setting(&model, &test, &options, |setting, nominal| {
            let (fit0, outcome) = recalibration(setting, &model, &nominal.point, &options)?;
            let e = holdout_errors(
                setting,
                &model,
                (h, &declared_at),
                &outcome.added,
                nominal,
                (&fit0, &outcome.fit),
                data,
                &options,
            )?;
            let enriched_at = model.enrich(&outcome.added)?.at_condition(&set)?;
            let z = held_out.data();
            let by_hand = [
                toy::rel_l2_by_hand(z, &toy::response(&declared_at, &nominal.point)),
                toy::rel_l2_by_hand(z, &toy::response(&declared_at, &fit0.point)),
                toy::rel_l2_by_hand(z, &toy::response(&enriched_at, &outcome.fit.point)),
            ];
            let got = [e.nominal.rel_l2, e.calibrated.rel_l2, e.enriched.rel_l2];
            for (g, h) in got.iter().zip(&by_hand) {
                assert!((g - h).abs() <= 1e-9 * h, "{got:?} vs {by_hand:?}");
            }
            assert!(
                by_hand[2] < by_hand[1] && by_hand[2] < by_hand[0],
                "{by_hand:?}"
            );
            Ok(())
        })
        .unwrap();
    }
}
