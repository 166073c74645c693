//! Autoregressive noise models: `e_k = sum_{i=1..p} phi_i e_{k-i} + w_k`, `w` white of
//! variance `sigma_w^2`, fitted on a record by the Yule-Walker equations (solved by the
//! Levinson-Durbin recursion) at every order `0..=max_order`, the order chosen by the
//! Bayesian information criterion `BIC(p) = n ln sigma_w^2(p) + p ln n` (Schwarz 1978;
//! Brockwell and Davis, *Introduction to Time Series and Forecasting*, 2nd ed., §5.1 and
//! §5.5). The prewhitening filter `w_k = e_k - sum phi_i e_{k-i}` turns the noise into white
//! noise; whiteness is judged by the Ljung-Box statistic
//! `Q = n (n + 2) sum_{k=1..h} r_k^2 / (n - k)` against `chi^2_{h - p}` (Ljung and Box 1978).

use rand::Rng;
use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF};

use crate::error::{CoreError, Result};

/// Largest AR order searched by default.
pub const DEFAULT_MAX_ORDER: usize = 10;

/// A fitted autoregressive model of zero-mean noise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ArModel {
    /// `phi_1 .. phi_p` (empty for white noise).
    pub coefficients: Vec<f64>,
    /// Variance of the white innovation `w`.
    pub innovation_variance: f64,
    /// Variance of the process `e` (the noise's variance).
    pub variance: f64,
    /// Samples the model was fitted on.
    pub samples: usize,
    /// BIC of the chosen order.
    pub bic: f64,
}

impl ArModel {
    /// White noise of standard deviation `sigma` (order 0).
    pub fn white(sigma: f64) -> ArModel {
        ArModel {
            coefficients: Vec::new(),
            innovation_variance: sigma * sigma,
            variance: sigma * sigma,
            samples: 0,
            bic: 0.0,
        }
    }

    /// AR(1) of lag-one correlation `phi` and process standard deviation `sigma`.
    pub fn ar1(phi: f64, sigma: f64) -> ArModel {
        ArModel {
            coefficients: vec![phi],
            innovation_variance: sigma * sigma * (1.0 - phi * phi),
            variance: sigma * sigma,
            samples: 0,
            bic: 0.0,
        }
    }

    /// The order `p`.
    pub fn order(&self) -> usize {
        self.coefficients.len()
    }

    /// Standard deviation of the process.
    pub fn sigma(&self) -> f64 {
        self.variance.sqrt()
    }

    /// Lag-one autocorrelation of the process (from the Yule-Walker relations).
    pub fn lag1(&self) -> f64 {
        autocorrelations_of(&self.coefficients, 1)[1]
    }

    /// Fits the model of order chosen by BIC among `0..=max_order` on `x` (its mean removed
    /// first). Orders above `n / 10` are not tried.
    ///
    /// # Errors
    /// [`CoreError::Empty`] for fewer than 8 samples; [`CoreError::NonFinite`] for a NaN or
    /// infinite sample; [`CoreError::InvalidOption`] for a constant record (no noise to
    /// model).
    pub fn fit(x: &[f64], max_order: usize) -> Result<ArModel> {
        crate::error::check_finite("noise record", x)?;
        let n = x.len();
        if n < 8 {
            return Err(CoreError::Empty {
                what: "noise record (an AR model needs at least 8 samples)".into(),
            });
        }
        let r = autocovariances(x, max_order.min(n / 10));
        if r[0] <= 0.0 {
            return Err(CoreError::invalid_option(
                "noise record",
                "constant",
                "a constant record has no noise to model",
            ));
        }
        let nf = n as f64;
        let mut best = ArModel {
            coefficients: Vec::new(),
            innovation_variance: r[0],
            variance: r[0],
            samples: n,
            bic: nf * r[0].ln(),
        };
        // Levinson-Durbin on the autocovariances.
        let mut phi: Vec<f64> = Vec::new();
        let mut v = r[0];
        for p in 1..r.len() {
            let acc: f64 = (1..p).map(|i| phi[i - 1] * r[p - i]).sum();
            let k = (r[p] - acc) / v;
            if !k.is_finite() || k.abs() >= 1.0 {
                break;
            }
            let mut next = vec![0.0; p];
            for i in 1..p {
                next[i - 1] = phi[i - 1] - k * phi[p - i - 1];
            }
            next[p - 1] = k;
            phi = next;
            v *= 1.0 - k * k;
            if v <= 0.0 {
                break;
            }
            let bic = nf * v.ln() + p as f64 * nf.ln();
            if bic < best.bic {
                best = ArModel {
                    coefficients: phi.clone(),
                    innovation_variance: v,
                    variance: r[0],
                    samples: n,
                    bic,
                };
            }
        }
        Ok(best)
    }

    /// The prewhitened record `w_k = (x_k - m) - sum_i phi_i (x_{k-i} - m)` for
    /// `k = p .. n` (`m` the mean of `x`): `n - p` values, white when the model is right.
    pub fn prewhiten(&self, x: &[f64]) -> Vec<f64> {
        let p = self.order();
        if x.len() <= p {
            return Vec::new();
        }
        let m = x.iter().sum::<f64>() / x.len() as f64;
        (p..x.len())
            .map(|k| {
                let pred: f64 = (1..=p)
                    .map(|i| self.coefficients[i - 1] * (x[k - i] - m))
                    .sum();
                x[k] - m - pred
            })
            .collect()
    }

    /// `n` samples of the stationary process (started from a stationary state by a burn-in
    /// of `50 p + 100` samples), drawn with `rng`.
    pub fn generate(&self, n: usize, rng: &mut impl Rng) -> Vec<f64> {
        let p = self.order();
        let s = self.innovation_variance.max(0.0).sqrt();
        let burn = 50 * p + 100;
        let mut e = vec![0.0; n + burn];
        for k in 0..e.len() {
            let pred: f64 = (1..=p.min(k))
                .map(|i| self.coefficients[i - 1] * e[k - i])
                .sum();
            e[k] = pred + s * standard_normal(rng);
        }
        e.split_off(burn)
    }

    /// The noise's power spectral density at normalised angular frequency `omega`
    /// (radians per sample), two-sided, in the units where white noise of variance
    /// `sigma^2` has density `sigma^2`: `sigma_w^2 / |1 - sum phi_i e^{-i omega i}|^2`.
    pub fn density(&self, omega: f64) -> f64 {
        let (mut re, mut im) = (1.0, 0.0);
        for (i, phi) in self.coefficients.iter().enumerate() {
            let a = omega * (i + 1) as f64;
            re -= phi * a.cos();
            im += phi * a.sin();
        }
        self.innovation_variance / (re * re + im * im)
    }
}

/// A standard normal draw (Box-Muller).
pub fn standard_normal(rng: &mut impl Rng) -> f64 {
    let u1: f64 = rng.random_range(f64::MIN_POSITIVE..1.0);
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// Biased sample autocovariances `r_0 .. r_h` of `x` about its mean (the form whose
/// Toeplitz matrix is positive definite).
pub fn autocovariances(x: &[f64], h: usize) -> Vec<f64> {
    let n = x.len();
    if n == 0 {
        return vec![0.0; h + 1];
    }
    let m = x.iter().sum::<f64>() / n as f64;
    (0..=h.min(n.saturating_sub(1)))
        .map(|k| (k..n).map(|i| (x[i] - m) * (x[i - k] - m)).sum::<f64>() / n as f64)
        .collect()
}

/// Sample autocorrelation at lag one (0 for a constant record).
pub fn lag1(x: &[f64]) -> f64 {
    let r = autocovariances(x, 1);
    if r.len() > 1 && r[0] > 0.0 {
        r[1] / r[0]
    } else {
        0.0
    }
}

/// Autocorrelations `rho_0 .. rho_h` of the AR process with coefficients `phi`.
fn autocorrelations_of(phi: &[f64], h: usize) -> Vec<f64> {
    // From the impulse response psi of the causal filter, truncated where it has decayed
    // (2000 samples, 200 per order at least: |psi| falls as the largest root's modulus to
    // that power).
    let p = phi.len();
    if p == 0 {
        let mut r = vec![0.0; h + 1];
        r[0] = 1.0;
        return r;
    }
    // rho_k = sum psi_j psi_{j+k} / sum psi_j^2.
    let len = 2000.max(200 * p);
    let mut psi = vec![0.0; len];
    psi[0] = 1.0;
    for j in 1..len {
        psi[j] = (1..=p.min(j)).map(|i| phi[i - 1] * psi[j - i]).sum();
    }
    let c0: f64 = psi.iter().map(|v| v * v).sum();
    (0..=h)
        .map(|k| (0..len - k).map(|j| psi[j] * psi[j + k]).sum::<f64>() / c0)
        .collect()
}

/// The Ljung-Box test of whiteness of `x` over `lags` lags.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LjungBox {
    /// `Q = n (n + 2) sum_{k=1..h} r_k^2 / (n - k)`.
    pub statistic: f64,
    /// Lags `h`.
    pub lags: usize,
    /// Degrees of freedom `h - fitted` of the reference chi-square.
    pub dof: usize,
    /// `P(chi^2_dof >= Q)`.
    pub p_value: f64,
}

/// Ljung-Box test of `x` at `lags` lags, `fitted` coefficients already fitted to it (the
/// order of an AR model whose prewhitened record `x` is; 0 for a raw record).
///
/// # Errors
/// [`CoreError::InvalidOption`] when `lags` is 0, not above `fitted`, or not below the
/// record's length.
pub fn ljung_box(x: &[f64], lags: usize, fitted: usize) -> Result<LjungBox> {
    let n = x.len();
    if lags == 0 || lags <= fitted || lags >= n {
        return Err(CoreError::invalid_option(
            "Ljung-Box lags",
            lags,
            format!(
                "must lie in {}..{n} (fitted coefficients {fitted})",
                fitted + 1
            ),
        ));
    }
    let r = autocovariances(x, lags);
    let nf = n as f64;
    let statistic = if r[0] > 0.0 {
        nf * (nf + 2.0)
            * (1..=lags)
                .map(|k| (r[k] / r[0]).powi(2) / (nf - k as f64))
                .sum::<f64>()
    } else {
        0.0
    };
    let dof = lags - fitted;
    let p_value = ChiSquared::new(dof as f64)
        .map(|d| d.sf(statistic))
        .unwrap_or(f64::NAN);
    Ok(LjungBox {
        statistic,
        lags,
        dof,
        p_value,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn an_ar1_of_known_coefficient_is_recovered_and_prewhitens_to_white() {
        let truth = ArModel::ar1(0.8, 2.0);
        let mut white_after = 0;
        for seed in 0..20 {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let x = truth.generate(5000, &mut rng);
            let m = ArModel::fit(&x, DEFAULT_MAX_ORDER).unwrap();
            // BIC picks order 1 and the coefficient within sampling error (sd ~0.0085).
            assert_eq!(m.order(), 1, "seed {seed}: {:?}", m.coefficients);
            assert!((m.coefficients[0] - 0.8).abs() < 0.035, "{m:?}");
            assert!((m.sigma() - 2.0).abs() < 0.15, "{}", m.sigma());
            assert!((m.lag1() - m.coefficients[0]).abs() < 1e-9);
            // The raw noise fails Ljung-Box, the prewhitened passes at the 1 % level.
            assert!(ljung_box(&x, 20, 0).unwrap().p_value < 1e-6);
            let w = m.prewhiten(&x);
            assert_eq!(w.len(), x.len() - 1);
            if ljung_box(&w, 20, 1).unwrap().p_value > 0.01 {
                white_after += 1;
            }
        }
        // At the 1 % level about 0.2 of 20 seeds fail by chance.
        assert!(white_after >= 18, "{white_after}");
    }

    #[test]
    fn an_ar2_is_found_and_white_noise_stays_order_zero() {
        let truth = ArModel {
            coefficients: vec![1.2, -0.5],
            innovation_variance: 1.0,
            variance: 0.0,
            samples: 0,
            bic: 0.0,
        };
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let x = truth.generate(8000, &mut rng);
        let m = ArModel::fit(&x, DEFAULT_MAX_ORDER).unwrap();
        assert_eq!(m.order(), 2, "{m:?}");
        assert!((m.coefficients[0] - 1.2).abs() < 0.03);
        assert!((m.coefficients[1] + 0.5).abs() < 0.03);
        let w = ArModel::white(1.0).generate(8000, &mut rng);
        let m = ArModel::fit(&w, DEFAULT_MAX_ORDER).unwrap();
        assert_eq!(m.order(), 0);
        assert!((m.sigma() - 1.0).abs() < 0.03);
        // The density integrates to the variance: mean over a uniform frequency grid.
        let a = ArModel::ar1(0.6, 1.5);
        let k = 4096;
        let mean = (0..k)
            .map(|j| a.density(2.0 * std::f64::consts::PI * j as f64 / k as f64))
            .sum::<f64>()
            / k as f64;
        assert!((mean - 2.25).abs() < 1e-6, "{mean}");
    }

    #[test]
    fn bad_records_are_typed_errors() {
        assert!(ArModel::fit(&[1.0; 4], 3).is_err());
        assert!(ArModel::fit(&[1.0; 40], 3).is_err());
        let mut x = vec![0.0; 40];
        x[3] = f64::NAN;
        assert!(ArModel::fit(&x, 3).is_err());
        assert!(ljung_box(&[1.0, 2.0, 3.0], 5, 0).is_err());
        assert!(ljung_box(&[1.0, 2.0, 3.0, 1.0, 0.0], 2, 2).is_err());
    }
}
