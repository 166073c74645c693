//! The model's own noise counted as what it is: a change of the whole trajectory, not an
//! independent error at every sample.
//!
//! The whitening weights hold the jitter ensemble's spread per sample, as if the model's
//! noise were independent from sample to sample. A crash model's noise is not: a jitter of
//! `1e-4` moves the whole response, coherently over time and sensors, and a candidate's
//! direction can fit part of that pattern as well as it fits physics. The ensemble already
//! holds draws of the pattern: the deviations `d_j = w (N(y_j) - N(y_0))` of the `m` jittered
//! runs from the nominal one, whitened under the fit's nuisance terms `N`. (A residual
//! between a test and a model at another point carries the difference of two such draws,
//! the same variance as `y_j - y_0`.)
//!
//! Regressed on the fit's whitened Jacobian `J` (parameters and nuisance terms), each draw
//! moves the fitted parameters by `delta_j = J^+ d_j` minus the jitter `s_j` the run was
//! given (its smooth, first-order response, which is not noise). Their mean square
//! `v_i = sum_j (delta_ji - s_ji)^2 / m` is the variance the model's noise adds to parameter
//! `i`, counted coherently: the sample form of `J^+ Sigma_model J^+T` with the noise
//! covariance `Sigma_model` estimated by `sum_j d_j d_j^T / m`. A parameter's variance is
//! then `c se_i^2 + v_i` (`c` the measurement noise's inflation, `se_i` its linearised
//! standard error for unit white noise).
//!
//! For a candidate direction `g~` (already orthogonal to `J`) the same regression is
//! `a_j = <g~, d_j> / <g~, g~>`, the amplitude the model's noise alone would attribute to
//! it, and its variance `sum_j a_j^2 / m` widens the candidate's interval and its
//! significance test (`closeloop::attribution`).
//!
//! With a smooth model (the drop tower) each `d_j` is its first-order response `J s_j`, so
//! `v_i` and `a_j` vanish and nothing changes; on a crash model they are what keeps the loop
//! from adding a quantity whose change the model's own noise can produce.

use super::detection::detect;
use super::fit::Fit;
use super::linalg::{Lsq, dot};
use super::nuisance::{self, Frame};
use crate::error::Result;

/// The jitter ensemble's draws of the model's own noise.
#[derive(Debug, Clone, Default)]
pub(crate) struct ModelNoise {
    /// Each jittered run's response minus the nominal run's (the loop's channels, filtered
    /// like the test), `S x T`.
    pub deviations: Vec<Vec<f64>>,
    /// Each jittered run's parameter change from the nominal point (declared space).
    pub shifts: Vec<Vec<f64>>,
}

impl ModelNoise {
    /// The draws whitened under the nuisance terms of `fit`: `w (N(y + d_j) - N(y))`.
    pub fn whitened(&self, fit: &Fit, frame: &Frame) -> Vec<Vec<f64>> {
        let base = nuisance::apply(&fit.y, frame, &fit.terms);
        self.deviations
            .iter()
            .map(|d| {
                let y: Vec<f64> = fit.y.iter().zip(d).map(|(a, b)| a + b).collect();
                nuisance::apply(&y, frame, &fit.terms)
                    .iter()
                    .zip(&base)
                    .zip(&frame.weights)
                    .map(|((a, b), w)| w * (a - b))
                    .collect()
            })
            .collect()
    }

    /// The draws whitened under the nuisance terms of `fit`, with the least-squares solver
    /// of its Jacobian that every statistic of them needs: built once per fit.
    ///
    /// # Errors
    /// When the Jacobian's SVD fails.
    pub fn draws(&self, fit: &Fit, frame: &Frame) -> Result<Draws<'_>> {
        Ok(Draws {
            shifts: &self.shifts,
            lsq: Lsq::new(&fit.jac)?,
            whitened: self.whitened(fit, frame),
        })
    }
}

/// The model's noise draws whitened under one fit ([`ModelNoise::draws`]), and that fit's
/// least-squares solver.
pub(crate) struct Draws<'a> {
    shifts: &'a [Vec<f64>],
    lsq: Lsq,
    whitened: Vec<Vec<f64>>,
}

impl Draws<'_> {
    /// The least-squares solver of the fit's Jacobian.
    pub fn lsq(&self) -> &Lsq {
        &self.lsq
    }

    /// The largest whitened draw outside the span of the fit's Jacobian,
    /// `max_j ||(I - P_J) d_j||`: how far the model's response moves by itself under a
    /// jitter, in a way re-tuning cannot undo; 0 without draws.
    pub fn largest(&self) -> f64 {
        self.whitened
            .iter()
            .map(|d| unfitted(&self.lsq, d).sqrt())
            .fold(0.0, f64::max)
    }

    /// The variance the model's noise adds to each of the first `p` parameters of the fit
    /// (`v_i` of the module docs); zeros without draws.
    pub fn parameter_variances(&self, p: usize) -> Vec<f64> {
        let mut var = vec![0.0; p];
        if self.whitened.is_empty() {
            return var;
        }
        for (d, s) in self.whitened.iter().zip(self.shifts) {
            let x = self.lsq.solve(d);
            for (i, v) in var.iter_mut().enumerate() {
                let given = s.get(i).copied().unwrap_or(0.0);
                *v += (x[i] - given).powi(2);
            }
        }
        let m = self.whitened.len() as f64;
        var.into_iter().map(|v| v / m).collect()
    }

    /// The largest reduced chi-square of the draws taken as residuals of the fit: each
    /// whitened draw with its projection on the fit's Jacobian removed, scored by `detect`
    /// (the frame's labels and samples, fitted quantities `p`, noise correlation `lag1`,
    /// level `alpha`); 0 without draws.
    ///
    /// # Errors
    /// When `detect` fails.
    pub fn largest_chi2(&self, frame: &Frame, p: usize, lag1: f64, alpha: f64) -> Result<f64> {
        let mut worst: f64 = 0.0;
        for d in &self.whitened {
            let fitted = self.lsq.project(d);
            let r: Vec<f64> = d.iter().zip(&fitted).map(|(a, b)| a - b).collect();
            let det = detect(&frame.labels, &r, frame.samples, p, lag1, alpha)?;
            worst = worst.max(det.chi2_red);
        }
        Ok(worst)
    }

    /// The mean of `||(I - P) d_j||^2` over the draws (0 without draws).
    pub fn unfitted_energy(&self) -> f64 {
        if self.whitened.is_empty() {
            return 0.0;
        }
        self.whitened
            .iter()
            .map(|d| unfitted(&self.lsq, d))
            .sum::<f64>()
            / self.whitened.len() as f64
    }

    /// The variance of the amplitude the draws attribute to the direction `gt` (orthogonal
    /// to the fitted Jacobian): `sum_j (<gt, d_j> / <gt, gt>)^2 / m`.
    pub fn amplitude_variance(&self, gt: &[f64]) -> f64 {
        let gg = dot(gt, gt);
        if self.whitened.is_empty() || gg <= 0.0 {
            return 0.0;
        }
        self.whitened
            .iter()
            .map(|d| (dot(gt, d) / gg).powi(2))
            .sum::<f64>()
            / self.whitened.len() as f64
    }
}

/// `||(I - P) d||^2` for the projector `P` of `lsq`.
fn unfitted(lsq: &Lsq, d: &[f64]) -> f64 {
    let fitted = lsq.project(d);
    d.iter().zip(&fitted).map(|(a, b)| (a - b).powi(2)).sum()
}
