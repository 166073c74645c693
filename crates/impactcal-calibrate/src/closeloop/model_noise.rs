//! The model's own noise counted as what it is: a change of the whole trajectory, not an
//! independent error at every sample.
//!
//! The whitening weights hold the jitter ensemble's spread per sample, as if the model's
//! noise were independent from sample to sample. A crash model's noise is not: a jitter of
//! `1e-4` moves the whole response, coherently over time and sensors, and a candidate's
//! direction can fit part of that pattern as well as it fits physics. The ensemble already
//! holds draws of the pattern: the deviations `d_j = L^-1 w (N(y_j) - N(y_0))` of the `m`
//! jittered runs from the nominal one, whitened under the fit's nuisance terms `N`. (A residual
//! between a test and a model at another point carries the difference of two such draws,
//! the same variance as `y_j - y_0`.)
//!
//! Regressed on the fit's whitened Jacobian `J` (parameters and nuisance terms), each draw
//! moves the fitted parameters by `delta_j = J^+ d_j` minus the jitter `s_j` the run was
//! given (its smooth, first-order response, which is not noise). Their mean square
//! `v_i = sum_j (delta_ji - s_ji)^2 / m` is the variance the model's noise adds to parameter
//! `i`, counted coherently: the sample form of `J^+ Sigma_model J^+T` with the noise
//! covariance `Sigma_model` estimated by `sum_j d_j d_j^T / m`. A parameter's variance is
//! then `se_i^2 + v_i` (`se_i` its linearised standard error under the measurement noise's
//! model, the whitening being `L^-1 w`, `closeloop::prewhiten`).
//!
//! For a candidate direction `g~` (already orthogonal to `J`) the same regression is
//! `a_j = <g~, d_j> / <g~, g~>`, the amplitude the model's noise alone would attribute to
//! it, and its variance `sum_j a_j^2 / m` widens the candidate's interval and its
//! significance test (`closeloop::attribution`).
//!
//! The part of a draw no parameter absorbs, `u_j = (I - P_J) d_j`, does not move the
//! linearised optimum but makes the objective rough: at a nearby point the profiled
//! chi-square is `||e - u_j||^2` instead of `||e||^2` (`e` the whitened residual at the fit),
//! a jump `dS_j = ||u_j||^2 - 2 <e, u_j>` that no smooth trend explains. An optimiser on a
//! function with noise of size `eps_f` locates its minimum only to where the smooth rise,
//! `delta^2 / C_ii` for parameter `i` with the others re-tuned (`C = (J^T J)^+`, so `C_ii =
//! se_i^2`), reaches `eps_f`: `|delta_i| ~ se_i sqrt(eps_f)`. With `eps_f` the draws' RMS
//! jump `R = sqrt(sum_j dS_j^2 / m)` this is one more standard deviation, `se_i sqrt(R)`,
//! in the interval of an added quantity: the spread of the optimiser's end point, which
//! the linearised error does not count (docs/closed-loop.md, "Intervals").
//!
//! With a smooth model (the drop tower) each `d_j` is its first-order response at the
//! nominal point, so `v_i`, `a_j` and `R` hold only the change of that response between
//! the nominal and the fitted point: small, and erring wide; on a crash model they are what keeps the
//! loop from adding a quantity whose change the model's own noise can produce, and its
//! intervals from claiming a precision the optimiser cannot reach.

use impactcal_core::{Cfc, Histories};

use super::detection::chi2_red;
use super::fit::Fit;
use super::linalg::dot;
use super::nuisance::{self, Frame};
use crate::error::Result;
use crate::study::execute::Outcomes;

/// The jitter ensemble's draws of the model's own noise, read from the ensemble's runs one
/// at a time whenever a statistic of them is asked for (nothing of the `m` runs is held).
#[derive(Debug, Clone)]
pub(crate) struct ModelNoise {
    /// The ensemble's runs.
    pub runs: Outcomes,
    /// The runs that succeeded, in order: draw `j` is run `used[j]`.
    pub used: Vec<usize>,
    /// Each draw's parameter change from the nominal point (declared space).
    pub shifts: Vec<Vec<f64>>,
    /// The nominal run on the loop's channels, filtered like the test, `S x T`.
    pub nominal: Histories,
    /// The loop's channels.
    pub labels: Vec<String>,
    /// The loop's filter.
    pub cfc: Option<Cfc>,
}

impl ModelNoise {
    /// Number of draws.
    pub fn len(&self) -> usize {
        self.used.len()
    }

    /// Run `j` of the draws on the loop's channels, filtered like the test.
    ///
    /// # Errors
    /// A result file that no longer reads; filter errors.
    pub fn run(&self, j: usize) -> Result<Histories> {
        let h = self
            .runs
            .histories(self.used[j], "a jitter run")?
            .select(&self.labels)?;
        Ok(match self.cfc {
            Some(c) => h.filtered(c)?,
            None => h,
        })
    }

    /// Draw `j` as a response change, `y_j - y_0`, `S x T`.
    fn deviation(&self, j: usize) -> Result<Vec<f64>> {
        let r = self.run(j)?;
        Ok(r.data()
            .iter()
            .zip(self.nominal.data())
            .map(|(a, b)| a - b)
            .collect())
    }

    /// One pass over the draws, each whitened under the nuisance terms of `fit`,
    /// `L^-1 w (N(y + d_j) - N(y))`, regressed on its Jacobian: per draw, the energy outside the
    /// fitted span, the dense coefficients `J^+ d_j`, with `chi2 = Some(p)` the reduced
    /// chi-square of the unfitted part taken as a residual with `p` fitted quantities, and
    /// with `products` the inner products it returns for the whitened draw and its
    /// coefficients on the Jacobian's dense basis (`U_a^T d_j`).
    ///
    /// # Errors
    /// [`ModelNoise::run`]'s errors.
    pub fn stats(
        &self,
        fit: &Fit,
        frame: &Frame,
        chi2: Option<usize>,
        products: Option<&Products<'_>>,
    ) -> Result<DrawStats> {
        let base = nuisance::apply(&fit.y, frame, &fit.terms);
        let mut out = DrawStats {
            shifts: self.shifts.clone(),
            ..DrawStats::default()
        };
        let compared = frame.compared();
        for j in 0..self.len() {
            let d = self.deviation(j)?;
            let y: Vec<f64> = fit.y.iter().zip(&d).map(|(a, b)| a + b).collect();
            drop(d);
            let dw = nuisance::direction(&y, &base, frame, &fit.terms, 1.0);
            let u = fit.jac.unfitted(&dw);
            let uu: f64 = u.iter().map(|v| v * v).sum();
            out.jumps.push(uu - 2.0 * dot(&fit.residual, &u));
            out.unfitted.push(uu);
            out.solved.push(fit.jac.solve(&dw));
            if let Some(p) = chi2 {
                out.chi2.push(chi2_red(&u, compared, p).0);
            }
            if let Some(f) = products {
                out.products.push(f(&dw, &fit.jac.coefficients(&dw)));
            }
        }
        Ok(out)
    }
}

/// The inner products a pass over the draws takes of each whitened draw, given the draw and
/// its coefficients on the Jacobian's dense basis.
pub(crate) type Products<'a> = dyn Fn(&[f64], &[f64]) -> Vec<f64> + 'a;

/// What one pass over the draws gives ([`ModelNoise::stats`]); every statistic is 0 without
/// draws.
#[derive(Debug, Clone, Default)]
pub(crate) struct DrawStats {
    shifts: Vec<Vec<f64>>,
    /// `||(I - P_J) d_j||^2` per draw.
    unfitted: Vec<f64>,
    /// The objective's jump per draw, `||u_j||^2 - 2 <e, u_j>`.
    jumps: Vec<f64>,
    /// `J^+ d_j` per draw (the dense coefficients).
    solved: Vec<Vec<f64>>,
    /// The reduced chi-square of each draw's unfitted part (when asked).
    chi2: Vec<f64>,
    /// The inner products asked for, per draw.
    products: Vec<Vec<f64>>,
}

impl DrawStats {
    /// The largest whitened draw outside the span of the fit's Jacobian,
    /// `max_j ||(I - P_J) d_j||`: how far the model's response moves by itself under a
    /// jitter, in a way re-tuning cannot undo.
    pub fn largest(&self) -> f64 {
        self.unfitted.iter().map(|e| e.sqrt()).fold(0.0, f64::max)
    }

    /// The variance the model's noise adds to each of the first `p` parameters of the fit
    /// (`v_i` of the module docs).
    pub fn parameter_variances(&self, p: usize) -> Vec<f64> {
        let mut var = vec![0.0; p];
        if self.solved.is_empty() {
            return var;
        }
        for (x, s) in self.solved.iter().zip(&self.shifts) {
            for (i, v) in var.iter_mut().enumerate() {
                let given = s.get(i).copied().unwrap_or(0.0);
                *v += (x[i] - given).powi(2);
            }
        }
        let m = self.solved.len() as f64;
        var.into_iter().map(|v| v / m).collect()
    }

    /// The largest reduced chi-square of the draws taken as residuals of the fit (each
    /// with its projection on the fit's Jacobian removed; `chi2` asked in the pass).
    pub fn largest_chi2(&self) -> f64 {
        self.chi2.iter().copied().fold(0.0, f64::max)
    }

    /// The objective's roughness `R = sqrt(sum_j dS_j^2 / m)`, `dS_j = ||u_j||^2 - 2 <e,
    /// u_j>` (module docs), in units of the whitened chi-square; 0 without draws.
    pub fn objective_noise(&self) -> f64 {
        if self.jumps.is_empty() {
            return 0.0;
        }
        (self.jumps.iter().map(|j| j * j).sum::<f64>() / self.jumps.len() as f64).sqrt()
    }

    /// The mean of `||(I - P) d_j||^2` over the draws.
    pub fn unfitted_energy(&self) -> f64 {
        if self.unfitted.is_empty() {
            return 0.0;
        }
        self.unfitted.iter().sum::<f64>() / self.unfitted.len() as f64
    }

    /// The variance of the amplitude the draws attribute to direction `k` of the products
    /// asked in the pass, `g~` (orthogonal to the fitted Jacobian, `<g~, g~> = gg`):
    /// `sum_j (<g~, d_j> / gg)^2 / m`.
    pub fn amplitude_variance(&self, k: usize, gg: f64) -> f64 {
        if self.products.is_empty() || gg <= 0.0 {
            return 0.0;
        }
        self.products
            .iter()
            .map(|p| (p[k] / gg).powi(2))
            .sum::<f64>()
            / self.products.len() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The roughness is the RMS of the jumps, and the jump is the change of the profiled
    /// chi-square when the residual loses a draw's unabsorbed part: `||e - u||^2 - ||e||^2`.
    #[test]
    fn roughness_is_the_rms_jump_of_the_objective() {
        let e = [1.0, -2.0, 0.5];
        let draws = [[0.3, 0.1, -0.2], [-0.4, 0.0, 0.6]];
        let jumps: Vec<f64> = draws.iter().map(|u| dot(u, u) - 2.0 * dot(&e, u)).collect();
        for (u, j) in draws.iter().zip(&jumps) {
            let after: f64 = e.iter().zip(u).map(|(a, b)| (a - b).powi(2)).sum();
            assert!((after - dot(&e, &e) - j).abs() < 1e-12);
        }
        let stats = DrawStats {
            jumps: jumps.clone(),
            ..DrawStats::default()
        };
        let rms = ((jumps[0].powi(2) + jumps[1].powi(2)) / 2.0).sqrt();
        assert!((stats.objective_noise() - rms).abs() < 1e-12);
        assert!(DrawStats::default().objective_noise().abs() < f64::MIN_POSITIVE);
    }
}
