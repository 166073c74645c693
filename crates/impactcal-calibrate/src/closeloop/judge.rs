//! The metrics stage: the errors of a model's response against a test (relative L2, reduced
//! chi-square, Sprague-Geers, ISO 18571, M1 and M2), and of the nominal, calibrated and
//! enriched models on the calibration test.

use super::agreement::{self, Posterior};
use super::detection;
use super::fit::Fit;
use super::frame::Setting;
use super::nuisance::{self, Frame, Terms};
use super::options::LoopOptions;
use super::result::{Errors, Evidence, Stages};
use crate::error::Result;
use crate::metrics::{CurveMetrics, Iso18571};

/// The errors of the nominal model, the declared model calibrated (`fit0`) and the model
/// enriched and recalibrated (`fit`) on the calibration test of `setting`, the calibrated
/// two with the M1 ensemble widened by their parameters' linearised uncertainty (streams
/// 0, 1, 2 of the M1 seeds). `d0` is the number of declared parameters.
///
/// # Errors
/// As [`Judge::errors`].
pub(super) fn calibration_errors(
    setting: &Setting<'_>,
    fit0: &Fit,
    fit: &Fit,
    d0: usize,
    options: &LoopOptions,
) -> Result<Stages<Errors>> {
    let ctx = &setting.ctx;
    let p_of = |d: usize| d + setting.n_nuisance;
    let (terms_nominal, _) = ctx.profile(&setting.y_nominal);
    let judge = Judge {
        options,
        noise_dof: setting.floor.level_dof(),
    };
    Ok(Stages {
        nominal: judge.errors(
            &ctx.frame,
            &setting.y_nominal,
            &terms_nominal,
            p_of(d0),
            None,
            0,
        )?,
        calibrated: judge.errors(
            &ctx.frame,
            &fit0.y,
            &fit0.terms,
            p_of(d0),
            Some(Posterior {
                jac: fit0.jac.as_ref(),
            }),
            1,
        )?,
        enriched: judge.errors(
            &ctx.frame,
            &fit.y,
            &fit.terms,
            p_of(fit.point.len()),
            Some(Posterior {
                jac: fit.jac.as_ref(),
            }),
            2,
        )?,
    })
}

/// What judges a model's response against a test: the loop's options and the degrees of
/// freedom of the noise level's estimate (`NoiseFloor::level_dof`).
pub(super) struct Judge<'a> {
    pub options: &'a LoopOptions,
    pub noise_dof: Option<f64>,
}

impl Judge<'_> {
    /// The errors of model response `y` under nuisance `terms` against the frame's test,
    /// with `p` fitted quantities; `posterior` widens the M1 ensemble by the parameters'
    /// linearised uncertainty; `stream` separates the seeds of the M1 ensembles.
    ///
    /// # Errors
    /// Detection's and M1's numerical errors.
    pub fn errors(
        &self,
        frame: &Frame,
        y: &[f64],
        terms: &Terms,
        p: usize,
        posterior: Option<Posterior<'_>>,
        stream: u64,
    ) -> Result<Errors> {
        let corrected = nuisance::corrected_test(frame, terms);
        let num: f64 = corrected.iter().zip(y).map(|(a, b)| (a - b).powi(2)).sum();
        let den: f64 = corrected.iter().map(|a| a * a).sum();
        let residual = nuisance::residual(y, frame, terms);
        let det = detection::detect(
            &frame.labels,
            &residual,
            Some(&frame.masked()),
            frame.samples,
            p,
            self.options.alpha,
            self.noise_dof,
        )?;
        let iso = Iso18571::new();
        let t = frame.samples;
        let (mut sg, mut r, mut k) = (0.0, 0.0, 0.0);
        for s in 0..frame.labels.len() {
            if let Ok(m) = CurveMetrics::between(
                &corrected[s * t..(s + 1) * t],
                &y[s * t..(s + 1) * t],
                frame.dt,
                &iso,
            ) {
                sg += m.sprague_geers.comprehensive;
                r += m.iso18571.r;
                k += 1.0;
            }
        }
        let m1 = agreement::m1_exceedance(
            frame,
            y,
            terms,
            posterior,
            self.options.m1_members,
            self.options
                .seed
                .wrapping_add(stream.wrapping_mul(0x9E37_79B9_7F4A_7C15)),
        )?;
        let m2 = agreement::m2_result(frame, y, terms).ok();
        Ok(Errors {
            rel_l2: if den > 0.0 {
                (num / den).sqrt()
            } else {
                f64::NAN
            },
            chi2_red: det.chi2_red,
            sprague_geers_c: if k > 0.0 { sg / k } else { f64::NAN },
            iso18571_r: if k > 0.0 { r / k } else { f64::NAN },
            m1_exceedance: m1.exceedance_fraction,
            m1_expected: m1.expected_exceedance,
            m1_probability: m1.probability,
            m2_above_0_9: m2.as_ref().map(|m| m.matched_above_0_9),
            m2_shapes: m2.as_ref().map_or(0, |m| m.pairs.len()),
            evidence: Some(Box::new(Evidence {
                test: corrected,
                model: y.to_vec(),
                m1,
                m2,
            })),
        })
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::closeloop::recalibration;
    use crate::closeloop::toy::{self, Toy};
    use impactcal_core::Enrichable;

    /// The metrics stage on the two-channel toy: the relative L2 error of the nominal,
    /// calibrated and enriched models equals the hand computation (bias the mean
    /// difference, gains held at 1), and falls from stage to stage on a test carrying the
    /// held `c = 0.3`.
    #[test]
    fn calibration_errors_equal_the_hand_computed_l2() {
        let model = Toy::new(0.0, 0.0, 1.0);
        let truth = Toy::new(0.3, 0.0, 1.0);
        let options = toy::options(0.01);
        let test = toy::measured(&truth, 1.3, 0.01, 5, None);
        toy::with_setting(&model, &test, &options, |setting, nominal| {
            let (fit0, outcome) = recalibration(setting, &model, &nominal.point, &options)?;
            let e = calibration_errors(setting, &fit0, &outcome.fit, 1, &options)?;
            let enriched = model.enrich(&outcome.added)?;
            let by_hand = [
                toy::rel_l2_by_hand(test.data(), &toy::response(&model, &nominal.point)),
                toy::rel_l2_by_hand(test.data(), &toy::response(&model, &fit0.point)),
                toy::rel_l2_by_hand(test.data(), &toy::response(&enriched, &outcome.fit.point)),
            ];
            let got = [e.nominal.rel_l2, e.calibrated.rel_l2, e.enriched.rel_l2];
            for (g, h) in got.iter().zip(&by_hand) {
                assert!((g - h).abs() <= 1e-9 * h, "{got:?} vs {by_hand:?}");
            }
            assert!(
                by_hand[0] > by_hand[1] && by_hand[1] > by_hand[2],
                "{by_hand:?}"
            );
            // The enriched model leaves white noise: chi-square near 1.
            assert!((e.enriched.chi2_red - 1.0).abs() < 0.3, "{:?}", e.enriched);
            Ok(())
        })
        .unwrap();
    }
}
