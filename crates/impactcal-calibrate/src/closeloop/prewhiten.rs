//! The noise model of every likelihood of the loop: per channel an autoregressive model of
//! the measurement noise, applied as the generalised least-squares whitening of the
//! weighted residual and of every whitened direction.
//!
//! **The form.** After the weights (`closeloop::noise_floor`), the noise of channel `s` in
//! the weighted residual `x = w (test - model)` is taken as a stationary AR(`p`) process of
//! unit variance, `x_k = sum_{i=1..p} phi_i x_{k-i} + u_k` (`phi` the channel's fitted
//! coefficients, `closeloop::noise_floor::ChannelNoise::ar`; `p = 0` for white noise).
//! Its covariance over the channel's `T` samples is the Toeplitz matrix `R` of the
//! process's autocorrelations, and the generalised least-squares problem
//! `min (x - J d)^T R^-1 (x - J d)` is the ordinary one on `L^-1 x` and `L^-1 J`,
//! `R = L L^T` (Cholesky). `L^-1` is the AR filter itself, started exactly: sample `k`
//! is predicted from the `m = min(k, p)` samples before it by the order-`m` predictor
//! `a_m` of the Levinson-Durbin recursion, and
//!
//! `z_k = (x_k - sum_{j=1..m} a_{m,j} x_{k-j}) / sqrt(v_m)`,
//! `v_0 = 1`, `v_m = v_{m-1} (1 - k_m^2)`,
//!
//! with `k_m = a_{m,m}` the reflection coefficients. The `z_k` are the standardised
//! one-step prediction errors (the innovations algorithm; Brockwell and Davis,
//! *Introduction to Time Series and Forecasting*, 2nd ed., §2.5 and §5.1), uncorrelated with
//! unit variance: `z = L^-1 x` exactly, `L^-1` lower triangular with bandwidth `p`. The
//! lower-order predictors come from the fitted coefficients by the step-down recursion
//! `a_{m-1,j} = (a_{m,j} + k_m a_{m,m-j}) / (1 - k_m^2)`; a model with `|k_m| >= 1` is not
//! stationary and is refused.
//!
//! Every likelihood of the loop then sees white residuals: the reduced chi-square counts
//! `n = S T` independent samples, the detection edge is that of unit white noise, the
//! information criteria and every standard error take the noise as independent, and the
//! old lag-one correction (`n_eff = n (1 - rho) / (1 + rho)`) is gone.
//!
//! **Shapes.** The filter acts on each channel's `T` rows alone, so a vector `S x T` stays
//! `S x T`, a direction that is zero outside one channel stays so, and the factored
//! Jacobian's per-channel nuisance columns stay per channel (`closeloop::jacobian`): its
//! memory bound is unchanged. Cost `O(n p)` per vector.
//!
//! **Masked samples** (clipped runs and spikes, weight 0) leave the likelihood: the filter
//! gives 0 there and starts again after them, so each run of unmasked samples is whitened
//! exactly as a record of its own (its correlation with the run before the mask, through
//! the noise across the masked gap, is left out: at most `p` samples after each mask lose a
//! little information, nothing is counted twice).
//!
//! The inverse, `x = L z` ([`Prewhitener::colour`]), draws the noise a repeated test would
//! carry and maps a whitened change of the fit back to the weighted space (M1's predictive
//! ensemble, `closeloop::agreement`).

use crate::error::{CalibrateError, Result};

/// One channel's exact AR filter (see the module docs).
#[derive(Debug, Clone)]
struct ChannelFilter {
    /// `a_m` for `m = 0..=p` (row `m` holds `m` coefficients).
    predictors: Vec<Vec<f64>>,
    /// `1 / sqrt(v_m)` for `m = 0..=p`.
    scales: Vec<f64>,
    /// Samples out of the likelihood.
    masked: Vec<bool>,
}

impl ChannelFilter {
    fn order(&self) -> usize {
        self.predictors.len() - 1
    }

    fn whiten(&self, x: &[f64]) -> Vec<f64> {
        let p = self.order();
        let mut out = vec![0.0; x.len()];
        let mut run = 0;
        for (k, o) in out.iter_mut().enumerate() {
            if self.masked.get(k).copied().unwrap_or(false) {
                run = 0;
                continue;
            }
            let m = run.min(p);
            let a = &self.predictors[m];
            let pred: f64 = (1..=m).map(|j| a[j - 1] * x[k - j]).sum();
            *o = (x[k] - pred) * self.scales[m];
            run += 1;
        }
        out
    }

    fn colour(&self, z: &[f64]) -> Vec<f64> {
        let p = self.order();
        let mut out = vec![0.0; z.len()];
        let mut run = 0;
        for k in 0..z.len() {
            if self.masked.get(k).copied().unwrap_or(false) {
                out[k] = z[k];
                run = 0;
                continue;
            }
            let m = run.min(p);
            let a = &self.predictors[m];
            let pred: f64 = (1..=m).map(|j| a[j - 1] * out[k - j]).sum();
            out[k] = z[k] / self.scales[m] + pred;
            run += 1;
        }
        out
    }
}

/// The exact AR whitening `L^-1` of every channel of a comparison (see the module docs).
/// The default is the identity (white noise, nothing masked).
#[derive(Debug, Clone, Default)]
pub(crate) struct Prewhitener {
    samples: usize,
    channels: Vec<ChannelFilter>,
}

/// The order-`m` predictors `a_m` (`m = 0..=p`) and `1 / sqrt(v_m)` of the stationary AR
/// model with coefficients `phi` (step-down recursion, module docs).
fn predictors(phi: &[f64], what: &str) -> Result<(Vec<Vec<f64>>, Vec<f64>)> {
    let p = phi.len();
    let mut rows = vec![Vec::new(); p + 1];
    rows[p] = phi.to_vec();
    let mut reflection = vec![0.0; p + 1];
    for m in (1..=p).rev() {
        let a = &rows[m];
        let k = a[m - 1];
        if !(k.is_finite() && k.abs() < 1.0) || a.iter().any(|v| !v.is_finite()) {
            return Err(CalibrateError::study(
                what,
                format!(
                    "the noise's AR coefficients {phi:?} are not those of a stationary \
                     process (reflection coefficient {k} at order {m})"
                ),
            ));
        }
        reflection[m] = k;
        let d = 1.0 - k * k;
        rows[m - 1] = (1..m).map(|j| (a[j - 1] + k * a[m - j - 1]) / d).collect();
    }
    let mut v = 1.0;
    let mut scales = vec![1.0; p + 1];
    for m in 1..=p {
        v *= 1.0 - reflection[m] * reflection[m];
        scales[m] = 1.0 / v.sqrt();
    }
    Ok((rows, scales))
}

impl Prewhitener {
    /// The filters of channels with AR coefficients `models[s]` (empty: white) and masked
    /// samples `masks[s]` (length `samples`; `true` leaves the likelihood), `S` channels of
    /// `samples` samples; `labels` name the channels in errors.
    ///
    /// # Errors
    /// [`CalibrateError::Study`] for a non-stationary or non-finite model (naming the
    /// channel), or counts that do not match.
    pub fn new(
        labels: &[String],
        models: &[Vec<f64>],
        masks: Vec<Vec<bool>>,
        samples: usize,
    ) -> Result<Self> {
        if models.len() != labels.len() || masks.len() != labels.len() {
            return Err(CalibrateError::study(
                "noise model",
                format!(
                    "{} AR models and {} masks for {} channels",
                    models.len(),
                    masks.len(),
                    labels.len()
                ),
            ));
        }
        let mut channels = Vec::with_capacity(labels.len());
        for ((label, phi), masked) in labels.iter().zip(models).zip(masks) {
            if masked.len() != samples {
                return Err(CalibrateError::study(
                    format!("noise model of `{label}`"),
                    format!("a mask of {} samples for {samples}", masked.len()),
                ));
            }
            let (predictors, scales) = predictors(phi, &format!("noise model of `{label}`"))?;
            channels.push(ChannelFilter {
                predictors,
                scales,
                masked,
            });
        }
        Ok(Prewhitener { samples, channels })
    }

    /// `op` of each channel's filter on that channel's `T` values of `v` (`S x T`); `v`
    /// itself for the identity.
    fn per_channel(&self, v: &[f64], op: fn(&ChannelFilter, &[f64]) -> Vec<f64>) -> Vec<f64> {
        if self.channels.is_empty() {
            return v.to_vec();
        }
        v.chunks(self.samples)
            .zip(&self.channels)
            .flat_map(|(ch, f)| op(f, ch))
            .collect()
    }

    /// `L^-1 v` of a vector `S x T` (channel-major), channel by channel.
    pub fn whiten(&self, v: &[f64]) -> Vec<f64> {
        self.per_channel(v, ChannelFilter::whiten)
    }

    /// `L_s^-1 v` of channel `s`'s `T` values alone (a direction zero on every other
    /// channel).
    pub fn whiten_channel(&self, s: usize, v: &[f64]) -> Vec<f64> {
        match self.channels.get(s) {
            Some(f) => f.whiten(v),
            None => v.to_vec(),
        }
    }

    /// `L z` of a vector `S x T`: the inverse of [`whiten`](Self::whiten) on unmasked
    /// samples (a masked sample passes `z` through: independent of the rest). For `z` unit
    /// white noise it is the AR noise of unit variance the model describes.
    pub fn colour(&self, z: &[f64]) -> Vec<f64> {
        self.per_channel(z, ChannelFilter::colour)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// `W R W^T` for the whitening `W` of one channel and a covariance `R` (`T x T`).
    fn sandwich(w: &Prewhitener, r: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let t = r.len();
        // W R: whiten every column of R.
        let cols: Vec<Vec<f64>> = (0..t)
            .map(|j| w.whiten(&(0..t).map(|i| r[i][j]).collect::<Vec<_>>()))
            .collect();
        // (W R) W^T = W (W R)^T: whiten every row of W R.
        (0..t)
            .map(|i| w.whiten(&(0..t).map(|j| cols[j][i]).collect::<Vec<_>>()))
            .collect()
    }

    fn toeplitz(rho: &[f64]) -> Vec<Vec<f64>> {
        let t = rho.len();
        (0..t)
            .map(|i| (0..t).map(|j| rho[i.abs_diff(j)]).collect())
            .collect()
    }

    fn one(phi: &[f64], mask: Vec<bool>) -> Prewhitener {
        let t = mask.len();
        Prewhitener::new(&["a".into()], &[phi.to_vec()], vec![mask], t).unwrap()
    }

    /// AR(2) autocorrelations from the Yule-Walker equations:
    /// `rho_1 = phi_1 / (1 - phi_2)`, `rho_k = phi_1 rho_{k-1} + phi_2 rho_{k-2}`.
    fn ar2_rho(phi: [f64; 2], t: usize) -> Vec<f64> {
        let mut rho = vec![1.0, phi[0] / (1.0 - phi[1])];
        while rho.len() < t {
            let k = rho.len();
            rho.push(phi[0] * rho[k - 1] + phi[1] * rho[k - 2]);
        }
        rho
    }

    #[test]
    fn the_filter_whitens_the_ar_covariance_exactly() {
        let t = 12;
        // AR(1): rho_k = phi^k.
        let rho1: Vec<f64> = (0..t).map(|k| 0.8f64.powi(k as i32)).collect();
        // AR(2) with complex roots (a damped oscillation) and with real ones.
        for (phi, rho) in [
            (vec![0.8], rho1),
            (vec![1.2, -0.6], ar2_rho([1.2, -0.6], t)),
            (vec![0.5, 0.3], ar2_rho([0.5, 0.3], t)),
        ] {
            let w = one(&phi, vec![false; t]);
            let s = sandwich(&w, &toeplitz(&rho));
            for (i, row) in s.iter().enumerate() {
                for (j, v) in row.iter().enumerate() {
                    let truth = if i == j { 1.0 } else { 0.0 };
                    assert!((v - truth).abs() < 1e-12, "phi {phi:?} ({i}, {j}): {v}");
                }
            }
        }
    }

    #[test]
    fn colour_inverts_whiten_and_white_noise_passes_unchanged() {
        let t = 40;
        let x: Vec<f64> = (0..2 * t).map(|i| (i as f64 * 0.37).sin() + 0.1).collect();
        let w = Prewhitener::new(
            &["a".into(), "b".into()],
            &[vec![1.2, -0.6], vec![]],
            vec![vec![false; t], vec![false; t]],
            t,
        )
        .unwrap();
        let z = w.whiten(&x);
        for (a, b) in w.colour(&z).iter().zip(&x) {
            assert!((a - b).abs() < 1e-12);
        }
        assert_eq!(&z[t..], &x[t..]);
        assert_eq!(w.whiten_channel(0, &x[..t]), z[..t].to_vec());
        assert_eq!(Prewhitener::default().whiten(&x), x);
    }

    #[test]
    fn a_mask_leaves_zeros_and_each_run_is_whitened_on_its_own() {
        let t = 14;
        let mut mask = vec![false; t];
        mask[5] = true;
        mask[6] = true;
        let w = one(&[0.8], mask.clone());
        let rho: Vec<f64> = (0..t).map(|k| 0.8f64.powi(k as i32)).collect();
        let s = sandwich(&w, &toeplitz(&rho));
        for i in 0..t {
            if mask[i] {
                assert!(s[i].iter().all(|v| *v == 0.0));
                continue;
            }
            // Within a run: unit variance, uncorrelated. Across the mask: only what the AR
            // process carries over the gap (the run starts afresh).
            assert!((s[i][i] - 1.0).abs() < 1e-12, "{i}: {}", s[i][i]);
            for j in 0..t {
                let same_run = (i < 5) == (j < 5);
                if i != j && !mask[j] && same_run {
                    assert!(s[i][j].abs() < 1e-12, "({i}, {j}): {}", s[i][j]);
                }
            }
        }
    }

    #[test]
    fn a_non_stationary_model_is_a_typed_error() {
        let e = Prewhitener::new(&["a".into()], &[vec![1.0]], vec![vec![false; 5]], 5)
            .unwrap_err()
            .to_string();
        assert!(e.contains("`a`") && e.contains("stationary"), "{e}");
        assert!(
            Prewhitener::new(&["a".into()], &[vec![0.5, 0.6]], vec![vec![false; 5]], 5).is_err()
        );
        assert!(Prewhitener::new(&["a".into()], &[vec![]], vec![vec![false; 4]], 5).is_err());
        assert!(Prewhitener::new(&["a".into()], &[], vec![], 5).is_err());
    }
}
