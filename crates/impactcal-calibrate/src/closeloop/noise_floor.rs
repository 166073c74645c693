//! The noise floor: the standard deviation of the measurement noise per channel, and the
//! model's own simulation noise, combined in quadrature into the weights
//! `w_sk = 1 / sqrt(sigma_s^2 + spread_sk^2)`.
//!
//! `sigma_s` comes, in this order, from the user (`sigma`, one value for every channel,
//! which wins when given), from the pre-impact window of the test (the samples before the
//! model's response departs from its initial value, moved by the trigger offset; at least
//! [`MIN_PRE_IMPACT`] samples; a straight line is fitted and removed, the residual's
//! standard deviation and lag-one autocorrelation kept), or from the frequencies where the
//! nominal model has no content (its periodogram below 5 % of the test's): an AR(1)
//! density fitted there by the Whittle likelihood gives the noise's variance and lag-one
//! correlation (`impactcal_core::quality::noise_from_band`). Only when the model leaves
//! too few frequencies empty does the band above the model's bandwidth serve: the test
//! minus its CFC-filtered self, whose variance is the part of white noise above the filter,
//! `sigma^2 = var(test - cfc(test)) / f` with `f` the fraction of a white sequence's
//! variance the same filter removes (measured on a seeded white sequence of the same
//! length); it counts whatever the model does above the filter as noise. `spread_sk` is the standard deviation of a jitter ensemble of the model
//! (`impactcal_core::noise`): what the model does on its own under a tiny change of its
//! parameters, which no calibration may call model-form error.

use impactcal_core::quality::noise_from_band;
use impactcal_core::{Cfc, Histories};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::error::{CalibrateError, Result};

/// Fewest pre-impact samples the noise is measured on.
pub const MIN_PRE_IMPACT: usize = 32;

/// Where a channel's noise level came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NoiseSource {
    /// Given by the user.
    User,
    /// The pre-impact window of the test.
    PreImpact,
    /// The band above the model's bandwidth (the residual of a CFC filter): the last
    /// resort, when the model leaves too few frequencies empty.
    HighBand,
    /// The frequencies where the nominal model has no content: an AR(1) fitted there
    /// (`impactcal_core::quality::noise_from_band`).
    ModelFreeBand,
}

/// The noise floor of one channel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelNoise {
    /// The channel.
    pub label: String,
    /// Measurement noise standard deviation (the test's unit).
    pub sigma: f64,
    /// Where it came from.
    pub source: NoiseSource,
    /// Lag-one autocorrelation of the noise (0 when not measurable).
    pub lag1: f64,
    /// RMS over time of the model's simulation noise (jitter spread).
    pub simulation_rms: f64,
}

/// The noise floor of a test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NoiseFloor {
    /// Per channel.
    pub channels: Vec<ChannelNoise>,
    /// Pre-impact samples used (0 when the window was too short).
    pub pre_impact_samples: usize,
}

impl NoiseFloor {
    /// The pooled lag-one autocorrelation of the noise, clamped to `[0, 0.99]`.
    pub fn lag1(&self) -> f64 {
        let n = self.channels.len().max(1) as f64;
        (self.channels.iter().map(|c| c.lag1).sum::<f64>() / n).clamp(0.0, 0.99)
    }

    /// `(1 + rho) / (1 - rho)`: how many samples count as one independent one.
    pub fn inflation(&self) -> f64 {
        let r = self.lag1();
        (1.0 + r) / (1.0 - r)
    }
}

/// The first sample at which any channel of `model` (`S x T`, channel-major) departs from
/// its initial value by more than 2 % of its largest departure.
pub(crate) fn onset(model: &[f64], samples: usize) -> usize {
    model
        .chunks(samples)
        .map(|ch| {
            let peak = ch.iter().map(|v| (v - ch[0]).abs()).fold(0.0, f64::max);
            ch.iter()
                .position(|v| (v - ch[0]).abs() > 0.02 * peak)
                .unwrap_or(samples)
        })
        .min()
        .unwrap_or(0)
}

/// Estimates the noise floor (see the module docs). `test` is `S x T` on the model's time
/// base, `model` the nominal response on the same channels and samples, `pre_impact` the
/// number of leading samples free of the impact, `spread` the jitter spread (`S x T`),
/// `cfc` the filter of the high band.
///
/// # Errors
/// [`CalibrateError::Study`] when no source gives a positive noise level for a channel
/// (say `sigma` then).
#[allow(clippy::too_many_arguments)]
pub(crate) fn estimate(
    labels: &[String],
    test: &[f64],
    model: &[f64],
    samples: usize,
    dt: f64,
    pre_impact: usize,
    spread: &[f64],
    user_sigma: Option<f64>,
    cfc: Cfc,
) -> Result<NoiseFloor> {
    let use_pre = pre_impact >= MIN_PRE_IMPACT;
    let fraction = if use_pre || user_sigma.is_some() {
        1.0
    } else {
        removed_fraction(samples, dt, cfc).unwrap_or(f64::NAN)
    };
    let mut channels = Vec::new();
    for (s, label) in labels.iter().enumerate() {
        let ch = &test[s * samples..(s + 1) * samples];
        let sp = &spread[s * samples..(s + 1) * samples];
        let simulation_rms = (sp.iter().map(|v| v * v).sum::<f64>() / samples as f64).sqrt();
        let (sigma, source, lag1) = if let Some(sigma) = user_sigma {
            (sigma, NoiseSource::User, 0.0)
        } else if use_pre {
            let (sd, r) = detrended(&ch[..pre_impact]);
            (sd, NoiseSource::PreImpact, r)
        } else if let Some(b) = noise_from_band(ch, &model[s * samples..(s + 1) * samples]) {
            (b.model.sigma(), NoiseSource::ModelFreeBand, b.model.lag1())
        } else {
            if !fraction.is_finite() {
                removed_fraction(samples, dt, cfc)?;
            }
            let h = Histories::from_channels(vec![label.clone()], vec![ch.to_vec()], dt, 0.0, "")?;
            let f = h.filtered(cfc)?;
            let e: Vec<f64> = ch.iter().zip(f.channel(0)).map(|(a, b)| a - b).collect();
            let var = e.iter().map(|v| v * v).sum::<f64>() / samples as f64;
            ((var / fraction).sqrt(), NoiseSource::HighBand, 0.0)
        };
        if !(sigma.is_finite() && sigma > 0.0) {
            return Err(CalibrateError::study(
                format!("noise floor of `{label}`"),
                format!("{sigma} from the {source:?} estimate; give [test] sigma"),
            ));
        }
        channels.push(ChannelNoise {
            label: label.clone(),
            sigma,
            source,
            lag1,
            simulation_rms,
        });
    }
    Ok(NoiseFloor {
        channels,
        pre_impact_samples: if use_pre { pre_impact } else { 0 },
    })
}

/// The whitening weights `1 / sqrt(sigma_s^2 + spread_sk^2)`, `S x T`.
pub(crate) fn weights(floor: &NoiseFloor, spread: &[f64], samples: usize) -> Vec<f64> {
    let mut w = Vec::with_capacity(spread.len());
    for (s, c) in floor.channels.iter().enumerate() {
        w.extend(
            spread[s * samples..(s + 1) * samples]
                .iter()
                .map(|sp| 1.0 / (c.sigma * c.sigma + sp * sp).sqrt()),
        );
    }
    w
}

/// Standard deviation and lag-one autocorrelation of `x` after removing a fitted line.
fn detrended(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let tm = (n - 1.0) / 2.0;
    let xm = x.iter().sum::<f64>() / n;
    let (mut stx, mut stt) = (0.0, 0.0);
    for (k, v) in x.iter().enumerate() {
        let t = k as f64 - tm;
        stx += t * (v - xm);
        stt += t * t;
    }
    let slope = if stt > 0.0 { stx / stt } else { 0.0 };
    let e: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(k, v)| v - xm - slope * (k as f64 - tm))
        .collect();
    let var = e.iter().map(|v| v * v).sum::<f64>() / (n - 2.0).max(1.0);
    let c1 = e.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / (n - 1.0).max(1.0);
    let r = if var > 0.0 { c1 / var } else { 0.0 };
    (var.sqrt(), r)
}

/// The fraction of a white sequence's variance that the CFC filter removes.
fn removed_fraction(samples: usize, dt: f64, cfc: Cfc) -> Result<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed);
    let n = samples.max(512);
    let x: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
    let f = cfc.filter(&x, dt, "white reference sequence")?;
    let total: f64 = x.iter().map(|v| v * v).sum();
    let removed: f64 = x.iter().zip(&f).map(|(a, b)| (a - b).powi(2)).sum();
    let frac = removed / total;
    if frac < 0.05 {
        return Err(CalibrateError::study(
            "noise floor",
            format!(
                "CFC {} keeps almost the whole band at this sampling rate; the high band \
                 cannot measure the noise: give [test] sigma",
                cfc.class()
            ),
        ));
    }
    Ok(frac)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_sources_recover_white_noise_level() {
        let t = 4000;
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        // Box-Muller normal draws of sigma 0.3 on a slow signal.
        let test: Vec<f64> = (0..t)
            .map(|k| {
                let u1: f64 = rng.random_range(1e-12..1.0);
                let u2: f64 = rng.random();
                let e = (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos();
                let quiet = if k < 1000 { 0.0 } else { 1.0 };
                quiet * (k as f64 * 1e-4 * 20.0).sin() + 0.3 * e
            })
            .collect();
        let zeros = vec![0.0; t];
        let cfc = Cfc::from_class(180).unwrap();
        let labels = vec!["a".to_string()];
        let pre = estimate(&labels, &test, &zeros, t, 1e-4, 1000, &zeros, None, cfc).unwrap();
        assert_eq!(pre.channels[0].source, NoiseSource::PreImpact);
        assert!(
            (pre.channels[0].sigma - 0.3).abs() < 0.02,
            "{}",
            pre.channels[0].sigma
        );
        assert!(pre.channels[0].lag1.abs() < 0.1);
        let signal: Vec<f64> = (0..t)
            .map(|k| {
                if k < 1000 {
                    0.0
                } else {
                    (k as f64 * 1e-4 * 20.0).sin()
                }
            })
            .collect();
        let free = estimate(&labels, &test, &signal, t, 1e-4, 5, &zeros, None, cfc).unwrap();
        assert_eq!(free.channels[0].source, NoiseSource::ModelFreeBand);
        assert!(
            (free.channels[0].sigma - 0.3).abs() < 0.03,
            "{}",
            free.channels[0].sigma
        );
        assert!(free.channels[0].lag1.abs() < 0.1);
        // A model with content at every frequency (ten times the test) leaves no band.
        let loud: Vec<f64> = test.iter().map(|v| 10.0 * v).collect();
        let band = estimate(&labels, &test, &loud, t, 1e-4, 5, &zeros, None, cfc).unwrap();
        assert_eq!(band.channels[0].source, NoiseSource::HighBand);
        assert!(
            (band.channels[0].sigma - 0.3).abs() < 0.03,
            "{}",
            band.channels[0].sigma
        );
        let user = estimate(&labels, &test, &zeros, t, 1e-4, 5, &zeros, Some(0.5), cfc).unwrap();
        assert!((user.channels[0].sigma - 0.5).abs() < 1e-15);
        assert!(estimate(&labels, &zeros, &zeros, t, 1e-4, 1000, &zeros, None, cfc).is_err());
    }
}
