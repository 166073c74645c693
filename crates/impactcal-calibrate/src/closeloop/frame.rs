//! The loop's comparison set up: the model's own noise from a jitter ensemble, the test's
//! noise floor, the whitened frame with its noise model (masks and AR whitening) and the
//! nuisance terms profiled on it; used for the calibration test and again for a holdout.

use impactcal_core::noise::{JitterOptions, SimulationNoise, jitter_points};
use impactcal_core::{Cfc, Histories, Model};

use super::fit::{Ctx, Journaled};
use super::model_noise::ModelNoise;
use super::noise_floor::{self, NoiseFloor};
use super::nuisance::{self, Frame};
use super::options::LoopOptions;
use super::prewhiten;
use super::setup::Nominal;
use crate::error::{CalibrateError, Result};

/// What every later stage compares through: the fits' context (frame, filter, journal,
/// the model's noise), the noise floor and the nominal response on the frame.
pub(super) struct Setting<'a> {
    /// The frame, the journal and the model's noise the fits share.
    pub ctx: Ctx<'a>,
    /// The calibration test's noise floor.
    pub floor: NoiseFloor,
    /// The nominal run on the frame's channels (filtered), `S x T`.
    pub y_nominal: Vec<f64>,
    /// The sample where the nominal response departs from rest.
    pub onset: usize,
    /// Nuisance quantities fitted: the trigger offset, a bias per channel and, when gains
    /// are fitted, a gain per channel.
    pub n_nuisance: usize,
    /// The CFC class of the high band that measures the noise when the pre-impact window
    /// is too short.
    pub band: Cfc,
}

/// The nuisance stage: the model's noise about the nominal point (journal stage `noise`),
/// the noise floor, the whitened frame of the test and its noise model, with the nuisance
/// terms profiled on it. The largest trigger offset is `options.max_time_shift`, else a
/// tenth of the record.
///
/// # Errors
/// Run and journal errors; fewer than 2 successful jitter runs; a noise floor that cannot
/// be measured; a noise model that is not stationary; an unknown CFC class.
pub(super) fn nuisance<'a, M: Model>(
    runner: Journaled<'a>,
    model: &M,
    nominal: &Nominal,
    cfc: Option<Cfc>,
    options: &LoopOptions,
) -> Result<Setting<'a>> {
    let labels = &nominal.labels;
    let (samples, dt) = (nominal.test.samples(), nominal.test.dt());
    let max_shift = options
        .max_time_shift
        .unwrap_or(0.1 * dt * (samples - 1) as f64);
    let band = Cfc::from_class(options.noise_band_cfc)?;
    let unit_gains = (!options.fit_gains).then(|| vec![1.0; labels.len()]);
    let (spread, model_noise) = model_spread(
        runner,
        model,
        &nominal.point,
        &nominal.raw,
        options,
        labels,
        cfc,
        "noise",
    )?;
    let y_nominal = compared(&nominal.raw, cfc, labels)?;
    let (mut frame, floor) = frame_of(
        FrameInputs {
            labels,
            test: nominal.test.data(),
            samples,
            dt,
            y_nominal: &y_nominal,
            model_noise: &model_noise,
            spread: &spread,
            max_shift,
            filters: (cfc, band),
            fixed_gains: unit_gains.as_deref(),
            lead: nominal.preparation.pre_trigger.as_ref(),
        },
        options,
    )?;
    noise_model(&mut frame, &nominal.masks, &floor, cfc)?;
    let onset = noise_floor::onset(&y_nominal, samples);
    let n_nuisance = 1 + if options.fit_gains { 2 } else { 1 } * labels.len();
    Ok(Setting {
        ctx: Ctx {
            frame,
            cfc,
            max_shift,
            fixed_gains: unit_gains,
            runner,
            seed: options.seed,
            batch: options.batch,
            model_noise,
        },
        floor,
        y_nominal,
        onset,
        n_nuisance,
        band,
    })
}

/// The channels `labels` of a run as the loop compares them (filtered with `cfc`), `S x T`.
///
/// # Errors
/// A label the run does not have; filter errors.
pub(super) fn compared(h: &Histories, cfc: Option<Cfc>, labels: &[String]) -> Result<Vec<f64>> {
    let h = match cfc {
        Some(c) => h.filtered(c)?,
        None => h.clone(),
    };
    Ok(h.select(labels)?.data().to_vec())
}

/// The jitter spread of `model` about `point` on `labels`, `S x T` (filtered like the test),
/// and the ensemble's draws of the model's noise (each run minus the nominal run, with the
/// jitter it was given), from journal stage `name`.
///
/// # Errors
/// Run and journal errors; [`CalibrateError::Study`] when fewer than 2 jitter runs succeed.
#[allow(clippy::too_many_arguments)]
pub(super) fn model_spread<M: Model>(
    runner: Journaled<'_>,
    model: &M,
    point: &[f64],
    nominal: &Histories,
    options: &LoopOptions,
    labels: &[String],
    cfc: Option<Cfc>,
    name: &str,
) -> Result<(Vec<f64>, ModelNoise)> {
    let jitter = JitterOptions::new(options.ensemble, options.jitter, options.seed);
    let pts = jitter_points(model.space(), point, &jitter)?;
    let runs = runner.stage(model, name, &pts)?;
    let used: Vec<usize> = (0..runs.len()).filter(|&i| runs.succeeded(i)).collect();
    if used.len() < 2 {
        return Err(CalibrateError::study(
            name,
            "fewer than 2 jitter runs succeeded; the model's noise cannot be measured",
        ));
    }
    let shifts = used
        .iter()
        .map(|&i| pts[i].iter().zip(point).map(|(a, b)| a - b).collect())
        .collect();
    let nominal = nominal.select(labels)?;
    let nominal = match cfc {
        Some(c) => nominal.filtered(c)?,
        None => nominal,
    };
    let draws = ModelNoise {
        runs,
        used,
        shifts,
        nominal: nominal.clone(),
        labels: labels.to_vec(),
        cfc,
    };
    let noise = SimulationNoise::from_run_reader(&nominal, draws.len(), &mut |j| draws.run(j))?;
    Ok((noise.spread.concat(), draws))
}

/// What a whitened frame is made from.
pub(super) struct FrameInputs<'a> {
    /// The channels compared.
    pub labels: &'a [String],
    /// The test on those channels, `S x T`.
    pub test: &'a [f64],
    /// `T`.
    pub samples: usize,
    /// The time step.
    pub dt: f64,
    /// The nominal run on the channels, `S x T`.
    pub y_nominal: &'a [f64],
    /// The jitter runs, read one at a time only when a channel's noise comes from the band.
    pub model_noise: &'a ModelNoise,
    /// The jitter spread, `S x T`.
    pub spread: &'a [f64],
    /// The largest trigger offset.
    pub max_shift: f64,
    /// The test's CFC (the one the test and the runs went through) and the class of the
    /// high band.
    pub filters: (Option<Cfc>, Cfc),
    /// Gains held (not fitted), per channel.
    pub fixed_gains: Option<&'a [f64]>,
    /// The test's record before the model's start (`study::channels::pre_trigger`),
    /// measured with the window's quiet start.
    pub lead: Option<&'a Histories>,
}

/// The whitened frame of a test and its noise floor. The nominal run and the jitter runs
/// are the model ensemble whose bandwidth bounds the noise's band.
///
/// # Errors
/// A noise floor that cannot be measured (`noise_floor::estimate`).
pub(super) fn frame_of(
    inputs: FrameInputs<'_>,
    options: &LoopOptions,
) -> Result<(Frame, NoiseFloor)> {
    let FrameInputs {
        labels,
        test,
        samples,
        dt,
        y_nominal,
        model_noise,
        spread,
        max_shift,
        filters,
        fixed_gains,
        lead,
    } = inputs;
    let mut frame = Frame {
        labels: labels.to_vec(),
        samples,
        dt,
        test: test.to_vec(),
        weights: vec![1.0; test.len()],
        whitener: prewhiten::Prewhitener::default(),
    };
    let (terms, _) = nuisance::profile(y_nominal, &frame, max_shift, fixed_gains);
    let onset = noise_floor::onset(y_nominal, samples) as f64 + terms.tau / dt;
    let pre = (onset - 3.0).floor().max(0.0) as usize;
    // A test that departs before the model's start leaves its record's last samples out.
    let lead: Vec<f64> = lead.map_or_else(Vec::new, |h| {
        let late = (3.0 - onset).ceil().max(0.0) as usize;
        let keep = h.samples().saturating_sub(late);
        (0..h.channels())
            .flat_map(|c| h.channel(c)[..keep].iter().copied())
            .collect()
    });
    let members = || {
        let runs = (0..model_noise.len()).map(|j| Ok(model_noise.run(j)?.data().to_vec()));
        noise_floor::envelopes_of(
            std::iter::once(Ok(y_nominal.to_vec())).chain(runs),
            labels.len(),
            samples,
        )
    };
    let floor = noise_floor::estimate(
        labels,
        test,
        &members,
        samples,
        dt,
        &lead,
        pre.min(samples),
        spread,
        options.sigma,
        filters,
    )?;
    frame.weights = noise_floor::weights(&floor, spread, samples);
    Ok((frame, floor))
}

/// How far (relative) a filtered sample's noise level may depart from the stationary level
/// the noise model holds before the sample leaves the likelihood: 10 % in standard
/// deviation is 21 % in a whitened square, beyond the spread of the noise floor's own
/// estimate.
const FILTER_END_TOLERANCE: f64 = 0.1;

/// The frame's noise model: zero weight for the masked samples of `core::quality` (clipped
/// runs and spikes, per channel in frame order: they leave every residual) and for the
/// samples at the record's ends where the CFC filter `cfc` does not pass noise as it does
/// inside ([`Cfc::end_samples`]: the reflection through the end value leaves the end
/// sample's own noise unfiltered, which the stationary noise model would read as a spike
/// in the residual's last sample), and each channel's AR whitening of the noise `floor`
/// measured, started afresh after each mask. The ends are kept when masking them would
/// leave no sample.
///
/// # Errors
/// [`CalibrateError::Study`] for a noise model that is not stationary; filter errors.
pub(super) fn noise_model(
    frame: &mut Frame,
    masks: &[Vec<bool>],
    floor: &NoiseFloor,
    cfc: Option<Cfc>,
) -> Result<()> {
    let t = frame.samples;
    for (s, m) in masks.iter().enumerate() {
        for (k, &out) in m.iter().enumerate().take(t) {
            if out {
                frame.weights[s * t + k] = 0.0;
            }
        }
    }
    if let Some(c) = cfc {
        let (head, tail) = c.end_samples(t, frame.dt, FILTER_END_TOLERANCE)?;
        if head + tail < t {
            for ch in frame.weights.chunks_mut(t) {
                ch[..head].iter_mut().for_each(|w| *w = 0.0);
                ch[t - tail..].iter_mut().for_each(|w| *w = 0.0);
            }
        }
    }
    let masked = frame
        .weights
        .chunks(t)
        .map(|w| w.iter().map(|v| *v == 0.0).collect())
        .collect();
    frame.whitener = prewhiten::Prewhitener::new(&frame.labels, &floor.ar_models(), masked, t)?;
    Ok(())
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use crate::closeloop::toy::{self, Toy};
    use impactcal_core::Histories;

    /// A filtered comparison leaves out the samples at each end where the CFC filter's end
    /// treatment passes the noise unfiltered (`Cfc::end_samples`), on every channel, and
    /// keeps the rest.
    #[test]
    fn the_filters_end_samples_leave_the_likelihood() {
        let model = Toy::new(0.0, 0.0, 1.0);
        let (a, b) = model.channels(&[1.0]);
        let test =
            Histories::from_channels(vec!["a".into(), "b".into()], vec![a, b], toy::DT, 0.0, "")
                .unwrap();
        let cfc = impactcal_core::Cfc::from_class(60).unwrap();
        let (head, tail) = cfc.end_samples(toy::T, toy::DT, 0.1).unwrap();
        assert!(
            head >= 1 && tail >= 1 && head + tail < toy::T,
            "{head}, {tail}"
        );
        toy::with_filtered_setting(
            &model,
            &test,
            &toy::options(0.01),
            Some(cfc),
            |setting, _| {
                for ch in setting.ctx.frame.weights.chunks(toy::T) {
                    assert!(ch[..head].iter().all(|w| *w == 0.0), "head kept: {ch:?}");
                    assert!(ch[toy::T - tail..].iter().all(|w| *w == 0.0), "tail kept");
                    assert!(
                        ch[head..toy::T - tail].iter().all(|w| *w > 0.0),
                        "inside masked"
                    );
                }
                let frame = &setting.ctx.frame;
                assert_eq!(frame.compared(), 2 * (toy::T - head - tail));
                assert_eq!(
                    frame.masked().iter().filter(|m| **m).count(),
                    2 * (head + tail)
                );
                Ok(())
            },
        )
        .unwrap();
    }

    /// A test that is the nominal run with a gain and a bias per channel and no noise: the
    /// nuisance stage profiles them back exactly, with the weights `1 / sigma` of the known
    /// noise level; held gains leave only the biases (and the offset) to fit.
    #[test]
    fn the_nuisance_stage_profiles_known_gains_and_biases() {
        let model = Toy::new(0.0, 0.0, 1.0);
        let (a, b) = model.channels(&[1.0]);
        let (gains, biases) = ([2.0, 0.5], [0.2, -0.1]);
        let test = Histories::from_channels(
            vec!["a".into(), "b".into()],
            vec![
                a.iter().map(|y| gains[0] * y + biases[0]).collect(),
                b.iter().map(|y| gains[1] * y + biases[1]).collect(),
            ],
            toy::DT,
            0.0,
            "",
        )
        .unwrap();
        let sigma = 0.01;
        let fitted = crate::closeloop::LoopOptions {
            fit_gains: true,
            ..toy::options(sigma)
        };
        toy::with_setting(&model, &test, &fitted, |setting, _| {
            assert_eq!(setting.n_nuisance, 1 + 2 * 2);
            let (terms, rss) = setting.ctx.profile(&setting.y_nominal);
            assert_eq!(terms.tau.to_bits(), 0f64.to_bits());
            for s in 0..2 {
                assert!((terms.gains[s] - gains[s]).abs() < 1e-9, "{terms:?}");
                assert!((terms.biases[s] - biases[s]).abs() < 1e-9, "{terms:?}");
            }
            assert!(rss < 1e-12, "{rss}");
            for w in &setting.ctx.frame.weights {
                assert!((w * sigma - 1.0).abs() < 1e-9, "{w}");
            }
            Ok(())
        })
        .unwrap();
        toy::with_setting(&model, &test, &toy::options(sigma), |setting, _| {
            assert_eq!(setting.n_nuisance, 1 + 2);
            let (terms, _) = setting.ctx.profile(&setting.y_nominal);
            assert_eq!(terms.gains, [1.0, 1.0]);
            // With the gain held at 1, the bias is the mean difference.
            for (s, y) in [&a, &b].iter().enumerate() {
                let mean = y
                    .iter()
                    .map(|y| (gains[s] - 1.0) * y + biases[s])
                    .sum::<f64>()
                    / toy::T as f64;
                assert!((terms.biases[s] - mean).abs() < 1e-9, "{terms:?}");
            }
            Ok(())
        })
        .unwrap();
    }
}
