//! Detection of model-form error in the whitened residual `e = L^-1 w (test - model)` of a
//! calibrated model (`S` channels, `T` samples, `n = S T` less the masked samples, which
//! leave every statistic below, `p` fitted quantities: the
//! calibrated parameters and the nuisance terms): `w` the weights of the noise floor and
//! `L^-1` each channel's AR filter of the measurement noise (`closeloop::prewhiten`), so
//! that under the noise model `e` is unit white noise plus what the model lacks.
//!
//! - Reduced chi-square: `chi2_red = RSS / (n - p)` with `RSS = sum e^2`, the mean square
//!   residual per independent sample, corrected for the fitted quantities. With a noise
//!   level known (given) its threshold is the `1 - alpha` quantile of `chi2_nu / nu`,
//!   `nu = max(n - p, 1)`. With a level estimated on the record (a quiet window of a few
//!   dozen samples) `chi2_red` is the ratio of the residual's mean square to the estimate's,
//!   an `F(nu, m)` variable, `m` the estimate's degrees of freedom over the channels
//!   (`NoiseFloor::level_dof`); the threshold is its `1 - alpha` quantile. The chi-square
//!   quantile would take an estimate from 40 samples for the truth and call its error
//!   model-form error.
//! - Whiteness: the Ljung-Box statistic `Q = sum_s T (T + 2) sum_{k=1..h} rho_sk^2 / (T - k)`
//!   over `h` lags per channel, against the `1 - alpha` quantile of `chi2_{S h}`. Reported:
//!   a residual that fails it carries colour the noise model does not explain (a missing
//!   effect, or noise unlike the record's quiet part), but it does not decide.
//! - Structure: the SVD of the `S x T` residual matrix. For unit white noise its largest
//!   singular value is about `sqrt(T) + sqrt(S)`; the edge is that times a margin of 1.2.
//!   Above the edge the residual has a coherent pattern: `u_1` says on which sensors, `v_1`
//!   when (in the prewhitened coordinates: a missing effect's shape after the noise's
//!   filter, which sharpens slow shapes).
//!
//! Model-form error is declared when `chi2_red` exceeds its threshold **and** `sigma_1`
//! exceeds the edge. Inside the loop the threshold is raised by what the model's own noise
//! gives when counted as a whole-trajectory change ([`Detection::with_model_noise`]).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF, FisherSnedecor};

use super::linalg::svd_rows;
use crate::error::{CalibrateError, Result};

/// Lags of the whiteness test.
pub const WHITENESS_LAGS: usize = 10;

/// The detection statistics of one residual.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Detection {
    /// Reduced chi-square.
    pub chi2_red: f64,
    /// Samples in the likelihood, `S T` less the masked ones (independent once
    /// prewhitened).
    pub n: usize,
    /// Fitted quantities (parameters and nuisance terms).
    pub p: usize,
    /// The `1 - alpha` quantile of `chi2_nu / nu`, or of `F(nu, noise_dof)` when the noise
    /// level was estimated.
    pub threshold: f64,
    /// Degrees of freedom of the noise level's estimate (`None`: known).
    #[serde(default)]
    pub noise_dof: Option<f64>,
    /// Pooled lag-one autocorrelation of the prewhitened residual (near 0 when the noise
    /// model holds and nothing is missing).
    pub lag1: f64,
    /// Ljung-Box statistic over [`WHITENESS_LAGS`] lags per channel.
    pub ljung_box: f64,
    /// Its `1 - alpha` quantile.
    pub ljung_box_threshold: f64,
    /// Whether the residual passes the whiteness test.
    pub white: bool,
    /// Largest singular value of the whitened residual matrix.
    pub sigma1: f64,
    /// The noise edge it is compared with.
    pub noise_edge: f64,
    /// Singular values above the edge (the rank of the coherent part).
    pub coherent_rank: usize,
    /// Whether `sigma1` exceeds the edge.
    pub coherent: bool,
    /// The verdict: `chi2_red > threshold + model_noise_chi2` and coherent.
    pub model_form_error: bool,
    /// The largest reduced chi-square the model's own noise gives on its own: each draw
    /// of the jitter ensemble (a whole-trajectory change, `closeloop::model_noise`) taken
    /// as a residual, with what the fit can absorb removed. 0 for a smooth model, and
    /// when not measured (the detection of a response that was not fitted).
    #[serde(default)]
    pub model_noise_chi2: f64,
    /// Sensor pattern `u_1` (label -> entry).
    pub u1: BTreeMap<String, f64>,
    /// Time pattern `v_1` (one entry per sample; unit norm).
    pub v1: Vec<f64>,
}

impl Detection {
    /// The same detection with the model's own noise counted coherently: `model_noise_chi2`
    /// (the largest reduced chi-square of the jitter ensemble's draws taken as residuals)
    /// is added to the threshold. The whitening holds the model's noise as if it were
    /// independent from sample to sample, where a jitter moves the whole trajectory: a
    /// residual made of such a change has few degrees of freedom and its chi-square is not
    /// the sum of independent squares the threshold assumes. Reduced chi-squares of
    /// independent parts add (their sums of squares do), so a residual whose chi-square
    /// stays below the threshold plus the largest the ensemble produced is at the floor of
    /// measurement noise plus model noise.
    pub fn with_model_noise(mut self, model_noise_chi2: f64) -> Self {
        self.model_noise_chi2 = model_noise_chi2;
        self.model_form_error = self.coherent && self.chi2_red > self.threshold + model_noise_chi2;
        self
    }
}

/// The `1 - alpha` quantile of `chi2_nu`.
///
/// # Errors
/// [`CalibrateError::Study`] for `nu <= 0` or `alpha` outside `(0, 1)`.
pub fn chi2_quantile(nu: f64, alpha: f64) -> Result<f64> {
    let d = ChiSquared::new(nu)
        .map_err(|e| CalibrateError::study("chi-square quantile", e.to_string()))?;
    upper_quantile(&d, alpha, "chi-square quantile")
}

/// The `1 - alpha` quantile of `F(nu, m)`, the ratio of independent `chi2_nu / nu` and
/// `chi2_m / m`.
///
/// # Errors
/// [`CalibrateError::Study`] for `nu <= 0`, `m <= 0` or `alpha` outside `(0, 1)`.
pub fn f_quantile(nu: f64, m: f64, alpha: f64) -> Result<f64> {
    let d = FisherSnedecor::new(nu, m)
        .map_err(|e| CalibrateError::study("F quantile", e.to_string()))?;
    upper_quantile(&d, alpha, "F quantile")
}

/// The `1 - alpha` quantile of `d`, `alpha` checked to lie in `(0, 1)`.
fn upper_quantile(d: &impl ContinuousCDF<f64, f64>, alpha: f64, what: &str) -> Result<f64> {
    if !(alpha > 0.0 && alpha < 1.0) {
        return Err(CalibrateError::study(
            what,
            format!("alpha {alpha} outside (0, 1)"),
        ));
    }
    Ok(d.inverse_cdf(1.0 - alpha))
}

/// Pooled lag-`k` autocorrelation of the channels of `e` (`S x T`, channel-major) over the
/// samples in the likelihood (`inside`, `S x T`): each channel's mean and sums of squares
/// over its samples inside, products over the pairs `(i, i - k)` both inside.
fn autocorrelation(e: &[f64], inside: &[bool], samples: usize, k: usize) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for (ch, ins) in e.chunks(samples).zip(inside.chunks(samples)) {
        let count = ins.iter().filter(|&&i| i).count();
        if count == 0 {
            continue;
        }
        let m = ch
            .iter()
            .zip(ins)
            .filter(|(_, i)| **i)
            .map(|(v, _)| v)
            .sum::<f64>()
            / count as f64;
        den += ch
            .iter()
            .zip(ins)
            .filter(|(_, i)| **i)
            .map(|(v, _)| (v - m).powi(2))
            .sum::<f64>();
        num += (k..samples)
            .filter(|&i| ins[i] && ins[i - k])
            .map(|i| (ch[i] - m) * (ch[i - k] - m))
            .sum::<f64>();
    }
    if den > 0.0 { num / den } else { 0.0 }
}

/// The reduced chi-square of the whitened residual `e` (`S x T`) over its `n` samples in the
/// likelihood (a masked sample is 0 in `e` and not counted in `n`) with `p` fitted
/// quantities (see the module docs), with the degrees of freedom `nu = max(n - p, 1)` it
/// used: `(chi2_red, nu)`.
pub(crate) fn chi2_red(e: &[f64], n: usize, p: usize) -> (f64, f64) {
    let rss: f64 = e.iter().map(|v| v * v).sum();
    let nu = (n as f64 - p as f64).max(1.0);
    (rss / nu, nu)
}

/// The detection statistics (see the module docs) of the whitened residual `e` (`S x T`),
/// with `p` fitted quantities, level `alpha` and `noise_dof` the degrees of freedom of the
/// noise level's estimate (`None`: known). `masked` (`S x T`, `true`: out of the
/// likelihood, the residual 0 there; `None`: every sample in) takes samples out of every
/// statistic: `n` counts the samples in, the whiteness test's means, sums and record
/// lengths are each channel's samples in, and the noise edge is that of `S` channels of
/// `n / S` samples. The statistics of a residual with masked samples are those of the
/// record without them.
///
/// # Errors
/// [`CalibrateError::Study`] when the SVD fails, the residual is empty or mis-shaped, or
/// every sample is masked.
pub fn detect(
    labels: &[String],
    e: &[f64],
    masked: Option<&[bool]>,
    samples: usize,
    p: usize,
    alpha: f64,
    noise_dof: Option<f64>,
) -> Result<Detection> {
    let s = labels.len();
    if e.is_empty() || s * samples != e.len() || masked.is_some_and(|m| m.len() != e.len()) {
        return Err(CalibrateError::study(
            "detection",
            "empty or mis-shaped residual",
        ));
    }
    let inside: Vec<bool> = match masked {
        Some(m) => m.iter().map(|out| !out).collect(),
        None => vec![true; e.len()],
    };
    let n = inside.iter().filter(|&&i| i).count();
    if n == 0 {
        return Err(CalibrateError::study(
            "detection",
            "every sample of the residual is masked",
        ));
    }
    let (chi2_red, nu) = chi2_red(e, n, p);
    let lag1 = autocorrelation(e, &inside, samples, 1);
    let threshold = match noise_dof {
        Some(m) => f_quantile(nu, m, alpha)?,
        None => chi2_quantile(nu, alpha)? / nu,
    };
    let mut q = 0.0;
    let h = WHITENESS_LAGS.min(samples.saturating_sub(2)).max(1);
    for (ch, ins) in e.chunks(samples).zip(inside.chunks(samples)) {
        let tt = ins.iter().filter(|&&i| i).count() as f64;
        if tt <= h as f64 {
            continue;
        }
        for k in 1..=h {
            let r = autocorrelation(ch, ins, samples, k);
            q += tt * (tt + 2.0) * r * r / (tt - k as f64);
        }
    }
    let ljung_box_threshold = chi2_quantile((s * h) as f64, alpha)?;
    let (sv, u, v) = svd_rows(e, s, samples)?;
    let noise_edge = 1.2 * ((n as f64 / s as f64).sqrt() + (s as f64).sqrt());
    let sigma1 = sv.first().copied().unwrap_or(0.0);
    let coherent_rank = sv.iter().filter(|&&x| x > noise_edge).count();
    let coherent = sigma1 > noise_edge;
    Ok(Detection {
        chi2_red,
        n,
        p,
        threshold,
        noise_dof,
        lag1,
        ljung_box: q,
        ljung_box_threshold,
        white: q <= ljung_box_threshold,
        sigma1,
        noise_edge,
        coherent_rank,
        coherent,
        model_form_error: chi2_red > threshold && coherent,
        model_noise_chi2: 0.0,
        u1: labels
            .iter()
            .enumerate()
            .map(|(i, l)| (l.clone(), u[(i, 0)]))
            .collect(),
        v1: (0..samples).map(|k| v[(k, 0)]).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn white(n: usize, seed: u64) -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                let u1: f64 = rng.random_range(1e-12..1.0);
                let u2: f64 = rng.random();
                (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
            })
            .collect()
    }

    #[test]
    fn quantile_matches_tables() {
        // chi2_{10}, 0.95 quantile 18.307; chi2_1, 0.99 quantile 6.635 (standard tables).
        assert!((chi2_quantile(10.0, 0.05).unwrap() - 18.307).abs() < 1e-3);
        assert!((chi2_quantile(1.0, 0.01).unwrap() - 6.635).abs() < 1e-3);
        // F_{10, 20}, 0.95 quantile 2.348; F_{1, 10}, 0.99 quantile 10.044 (standard tables);
        // F(nu, m) tends to chi2_nu / nu as m grows.
        assert!((f_quantile(10.0, 20.0, 0.05).unwrap() - 2.348).abs() < 2e-3);
        assert!((f_quantile(1.0, 10.0, 0.01).unwrap() - 10.044).abs() < 2e-3);
        let (nu, big) = (1000.0, 1e7);
        let chi = chi2_quantile(nu, 0.01).unwrap() / nu;
        assert!((f_quantile(nu, big, 0.01).unwrap() - chi).abs() < 1e-3);
    }

    #[test]
    fn white_noise_is_quiet_and_a_pattern_is_found() {
        let labels: Vec<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
        let t = 400;
        let mut alarms = 0;
        for seed in 0..20 {
            let d = detect(&labels, &white(3 * t, seed), None, t, 5, 0.01, None).unwrap();
            assert!(d.lag1.abs() < 0.1);
            alarms += usize::from(d.model_form_error);
        }
        assert!(alarms <= 1, "{alarms} false alarms in 20");
        // A pulse on channel b, 3 sigma at its peak, about 100 samples wide.
        let mut e = white(3 * t, 99);
        for k in 0..t {
            e[t + k] += 3.0 * (-((k as f64 - 200.0) / 50.0).powi(2)).exp();
        }
        let d = detect(&labels, &e, None, t, 5, 0.01, None).unwrap();
        assert!(d.model_form_error, "{d:?}");
        assert!(d.u1["b"].abs() > 0.9);
        let peak = (0..t)
            .max_by(|&i, &j| d.v1[i].abs().total_cmp(&d.v1[j].abs()))
            .unwrap();
        assert!((peak as i64 - 200).abs() < 40, "{peak}");
    }

    /// Masked samples leave every statistic: a residual of white noise with a pulse on one
    /// channel, its first two and last two samples of each channel masked (0 there, as the
    /// noise model leaves them), has the detection of the same record without those
    /// samples: the same count, chi-square, threshold, whiteness, singular values, noise
    /// edge and verdict.
    #[test]
    fn masked_samples_leave_every_statistic() {
        let labels: Vec<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
        let (t, head, tail) = (150, 2, 2);
        let inner = t - head - tail;
        for pulse in [0.0, 3.0] {
            let mut e = white(3 * inner, 11);
            for k in 0..inner {
                e[inner + k] += pulse * (-((k as f64 - 70.0) / 30.0).powi(2)).exp();
            }
            let mut padded = vec![0.0; 3 * t];
            let mut masked = vec![true; 3 * t];
            for s in 0..3 {
                for k in head..t - tail {
                    padded[s * t + k] = e[s * inner + k - head];
                    masked[s * t + k] = false;
                }
            }
            let a = detect(&labels, &padded, Some(&masked), t, 5, 0.01, None).unwrap();
            let b = detect(&labels, &e, None, inner, 5, 0.01, None).unwrap();
            assert_eq!((a.n, b.n), (3 * inner, 3 * inner));
            let pairs = [
                (a.chi2_red, b.chi2_red),
                (a.threshold, b.threshold),
                (a.lag1, b.lag1),
                (a.ljung_box, b.ljung_box),
                (a.sigma1, b.sigma1),
                (a.noise_edge, b.noise_edge),
            ];
            for (x, y) in pairs {
                assert!((x - y).abs() <= 1e-9 * y.abs().max(1.0), "{a:?}\n{b:?}");
            }
            assert_eq!(a.coherent_rank, b.coherent_rank);
            assert_eq!(a.model_form_error, b.model_form_error);
            assert_eq!(a.model_form_error, pulse > 0.0, "{a:?}");
        }
        // A residual masked throughout is refused, not judged.
        let all = vec![true; 3 * t];
        assert!(detect(&labels, &vec![0.0; 3 * t], Some(&all), t, 5, 0.01, None).is_err());
    }
}
