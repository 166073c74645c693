//! The source paper's metrics M1 and M2 for each model of the loop (nominal, calibrated,
//! enriched), with no extra run.
//!
//! **M1 exceedance.** M1 asks whether the test's `Q_e(t) = ||v_e(t)||_2` (the norm over the
//! compared channels at each sample) lies inside the envelope `[min_j Q_j(t), max_j Q_j(t)]`
//! of an ensemble of equally probable model responses ([`crate::study::m1`]). In the loop
//! the ensemble is the *predictive* one of each model, linearised about its response `y`
//! (nuisance terms taken out, in the test's units after filtering):
//!
//! `y_j = y + L (U z_j + eta_j) / (w g)`,  `z_j ~ N(0, I_r)`, `eta_j ~ N(0, I)`,
//!
//! where `w` are the loop's whitening weights (`1 / sqrt(sigma_s^2 + spread_s(t)^2)`: the
//! measurement noise and the model's own simulation noise), `L` each channel's AR
//! colouring of the measurement noise (the inverse of the prewhitening,
//! `closeloop::prewhiten`), `g` the channel gains, and `U` (rank `r`) an orthonormal basis
//! of the column space of the whitened Jacobian of a fit (parameters and nuisance terms;
//! the factored form's basis, `closeloop::jacobian`). `J delta` with `delta` drawn from the
//! linearised posterior `N(0, (J^T J)^+)` is exactly `U z`, so the first term is the
//! parameters' uncertainty propagated to first order, the second the noise a repeated test
//! would carry, coloured as the record's. A model with no fit at that point (the nominal model; any
//! model on the holdout, where the loop makes no Jacobian) has the noise term only.
//!
//! If the model is right, the test is one more draw from its predictive distribution and
//! lies outside the envelope of `N` draws at a given sample with probability `2 / (N + 1)`:
//! the exceedance of a correct model is that fraction of the samples on average (1 % for the
//! default 199 members); model-form error drives it towards 1.
//!
//! **M2 count.** The impact shapes (SVD, [`crate::study::m2`]) of the model's response and of
//! the test on the compared channels, up to 10 a side (fewer with fewer channels), and the
//! number of optimally paired shapes with `|M2| > 0.9`. One response per model: M2 compares
//! shapes, not an ensemble.

use impactcal_core::{Histories, norm_history_of};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use super::jacobian::Jacobian;
use super::nuisance::{self, Frame, Terms};
use crate::error::Result;
use crate::study::{m1, m2};

/// Impact shapes compared a side by the loop's M2 (the study's default).
pub const M2_SHAPES: usize = 10;

/// A fit's linearised posterior: its whitened Jacobian (parameters and nuisance terms).
pub(crate) struct Posterior<'a> {
    pub jac: &'a Jacobian,
}

/// M1 of the test (nuisance terms `terms` taken out) against the envelope of `members`
/// predictive draws about the model response `y` (`S x T`); see the module docs: the
/// observed exceedance, the expected one `2 / (N + 1)` (the draws carry the noise), the
/// probability and the verdict as the study judges them ([`m1::m1`]). Deterministic for a
/// given `seed`. A masked sample (weight 0: clipped, a spike) carries no evidence: the draws
/// and the test take the model's value there, so it neither widens the band nor leaves it.
///
/// # Errors
/// [`crate::CalibrateError::Study`] when `members` is zero.
pub(crate) fn m1_exceedance(
    frame: &Frame,
    y: &[f64],
    terms: &Terms,
    posterior: Option<Posterior<'_>>,
    members: usize,
    seed: u64,
) -> Result<m1::M1> {
    let t = frame.samples;
    let lsq = posterior.map(|p| p.jac);
    let scale: Vec<f64> = frame
        .weights
        .iter()
        .enumerate()
        .map(|(i, w)| {
            let g = terms.gains[i / t];
            let g = if g != 0.0 { g.abs() } else { 1.0 };
            if *w > 0.0 { 1.0 / (w * g) } else { 0.0 }
        })
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut normal = || -> f64 { StandardNormal.sample(&mut rng) };
    let runs: Vec<Vec<f64>> = (0..members)
        .map(|_| {
            let spread = lsq.map(|l| {
                let z: Vec<f64> = (0..l.rank()).map(|_| normal()).collect();
                l.span(&z)
            });
            let white: Vec<f64> = (0..y.len())
                .map(|i| spread.as_ref().map_or(0.0, |u| u[i]) + normal())
                .collect();
            let draw: Vec<f64> = y
                .iter()
                .zip(&scale)
                .zip(frame.whitener.colour(&white))
                .map(|((v, s), e)| v + e * s)
                .collect();
            norm_history_of(&draw, t)
        })
        .collect();
    let time: Vec<f64> = (0..t).map(|k| k as f64 * frame.dt).collect();
    let mut test = nuisance::corrected_test(frame, terms);
    for ((v, w), m) in test.iter_mut().zip(&frame.weights).zip(y) {
        if *w <= 0.0 {
            *v = *m;
        }
    }
    m1::m1(&time, &runs, &norm_history_of(&test, t))
}

/// M2 of the model response `y` against the test (nuisance terms taken out): the matrix,
/// the pairing and its count of shapes with `|M2| > 0.9`.
///
/// # Errors
/// Shape errors (a response or test without signal on these channels).
pub(crate) fn m2_result(frame: &Frame, y: &[f64], terms: &Terms) -> Result<m2::M2Result> {
    let t = frame.samples;
    let block = |v: &[f64]| -> Result<Histories> {
        Ok(Histories::from_channels(
            frame.labels.clone(),
            v.chunks(t).map(<[f64]>::to_vec).collect(),
            frame.dt,
            0.0,
            "",
        )?)
    };
    let test = nuisance::corrected_test(frame, terms);
    m2::m2(&block(y)?, &block(&test)?, &frame.labels, M2_SHAPES)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// Two channels of smooth pulses, 200 samples.
    fn pulses() -> Vec<f64> {
        let t = 200;
        (0..2 * t)
            .map(|i| {
                let (s, k) = (i / t, (i % t) as f64 / t as f64);
                (1.0 + s as f64) * (std::f64::consts::PI * k).sin().powi(2)
                    + 0.3 * (7.0 * k + s as f64).sin()
            })
            .collect()
    }

    fn frame(test: Vec<f64>, sigma: f64) -> Frame {
        Frame {
            labels: vec!["a".into(), "b".into()],
            samples: 200,
            dt: 1e-3,
            weights: vec![1.0 / sigma; test.len()],
            test,
            whitener: Default::default(),
        }
    }

    fn unit_terms() -> Terms {
        Terms {
            tau: 0.0,
            gains: vec![1.0, 1.0],
            biases: vec![0.0, 0.0],
        }
    }

    #[test]
    fn a_test_drawn_from_the_model_stays_inside_and_a_scaled_one_leaves() {
        let y = pulses();
        let sigma = 0.01;
        // The test is the model plus noise of the floor's size: a draw of the ensemble.
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let test: Vec<f64> = y
            .iter()
            .map(|v| {
                let e: f64 = StandardNormal.sample(&mut rng);
                v + sigma * e
            })
            .collect();
        let f = frame(test, sigma);
        let inside = m1_exceedance(&f, &y, &unit_terms(), None, 199, 1)
            .unwrap()
            .exceedance_fraction;
        // Expected 2/(N+1) = 1 % of the samples; allow for chance.
        assert!(inside < 0.05, "{inside}");
        // The noiseless model itself: Q_e at the centre, inside wherever the signal is
        // far above the noise (every sample here but where both channels cross zero).
        let own = m1_exceedance(&frame(y.clone(), sigma), &y, &unit_terms(), None, 199, 1);
        assert!(own.unwrap().exceedance_fraction < 0.05);
        // A test 10 % larger than the model leaves the envelope almost everywhere.
        let scaled = frame(y.iter().map(|v| 1.1 * v).collect(), sigma);
        let out = m1_exceedance(&scaled, &y, &unit_terms(), None, 199, 1).unwrap();
        assert!(out.exceedance_fraction > 0.8, "{}", out.statement);
        // Far more often than the 1 % a draw of the ensemble leaves it: cannot-explain.
        assert!((out.expected_exceedance - 0.01).abs() < 1e-12);
        assert!(out.probability < 1.0 / 200.0, "{}", out.statement);
        assert_eq!(out.verdict, m1::Verdict::CannotExplain);
        // With the gain profiled (1.1 on both channels) the same test is back inside.
        let terms = Terms {
            gains: vec![1.1, 1.1],
            ..unit_terms()
        };
        let back = m1_exceedance(&scaled, &y, &terms, None, 199, 1).unwrap();
        assert!(back.exceedance_fraction < 0.05, "{}", back.statement);
        assert_eq!(back.verdict, m1::Verdict::CanExplain);
    }

    #[test]
    fn m2_of_the_model_against_itself_pairs_every_shape() {
        let y = pulses();
        let f = frame(y.clone(), 0.01);
        let r = m2_result(&f, &y, &unit_terms()).unwrap();
        assert_eq!(r.pairs.len(), 2);
        assert_eq!(r.matched_above_0_9, 2);
    }
}
