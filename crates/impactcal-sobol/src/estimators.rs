//! Pick-freeze estimators of first-order and total indices, written on the sample moments
//! that one pass over the design accumulates.
//!
//! Notation (all means over the `N` base rows, outputs already centred): `a = f(A)`,
//! `b = f(B)`, `x = f(AB_i)`; `V = var([a; b])` (pooled, divisor `2N`, as SALib).

use serde::Serialize;

/// Estimator of the first-order index `S_i = Var(E[Y|X_i]) / Var(Y)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum FirstOrderEstimator {
    /// Saltelli et al. (2010): `mean(b (x - a)) / V`. Unbiased; SALib's and scipy's choice;
    /// the default.
    #[default]
    Saltelli2010,
    /// Jansen (1999): `(V - mean((b - x)^2) / 2) / V`.
    Jansen1999,
    /// Janon et al. (2014), asymptotically efficient: with `m = mean((b + x) / 2)`,
    /// `(mean(b x) - m^2) / (mean((b^2 + x^2) / 2) - m^2)`; uses its own variance.
    Janon2014,
    /// Martinez (2011): the correlation of `b` and `x`.
    Martinez2011,
}

/// Estimator of the total index `ST_i = E[Var(Y|X_~i)] / Var(Y)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum TotalEstimator {
    /// Jansen (1999): `mean((a - x)^2) / 2 / V`, never negative; SALib's choice; the
    /// default.
    #[default]
    Jansen1999,
    /// Sobol' et al. (2007): `mean(a (a - x)) / V`; good for small indices when outputs are
    /// centred (they are).
    Sobol2007,
    /// Janon et al. (2014): `1 - ` the Janon first-order estimator on the pair `(a, x)`.
    Janon2014,
    /// Martinez (2011): `1 - corr(a, x)`.
    Martinez2011,
}

/// Whether an estimator pair needs the full set of moments (beyond
/// `mean(b (x - a))` and `mean((a - x)^2)`).
pub(crate) fn needs_full_moments(first: FirstOrderEstimator, total: TotalEstimator) -> bool {
    !(first == FirstOrderEstimator::Saltelli2010 && total == TotalEstimator::Jansen1999)
}

/// Means of the shared terms of one output column: `a, b, a^2, b^2, a b`.
pub(crate) const SHARED: usize = 5;

/// The moments of one output column and one parameter.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ParamMoments {
    /// `mean(b (x - a))`.
    pub e1: f64,
    /// `mean((a - x)^2)`.
    pub e2: f64,
    /// `mean((b - x)^2)`, `mean(x)`, `mean(x^2)` when full moments were accumulated.
    pub e3: f64,
    pub mx: f64,
    pub qx: f64,
}

/// The shared moments of one column.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SharedMoments {
    pub ma: f64,
    pub mb: f64,
    pub qa: f64,
    pub qb: f64,
    pub pab: f64,
}

impl SharedMoments {
    /// Pooled variance of `[a; b]` with divisor `2N`.
    pub fn variance(&self) -> f64 {
        let m = 0.5 * (self.ma + self.mb);
        0.5 * (self.qa + self.qb) - m * m
    }
}

/// `(numerator, denominator)` of the first-order index: the index is their ratio and the
/// aggregated index sums both over output columns.
pub(crate) fn first_order(
    est: FirstOrderEstimator,
    s: &SharedMoments,
    p: &ParamMoments,
) -> (f64, f64) {
    let v = s.variance();
    match est {
        FirstOrderEstimator::Saltelli2010 => (p.e1, v),
        FirstOrderEstimator::Jansen1999 => (v - 0.5 * p.e3, v),
        FirstOrderEstimator::Janon2014 => {
            let cross = 0.5 * (s.qb + p.qx - p.e3);
            let m = 0.5 * (s.mb + p.mx);
            (cross - m * m, 0.5 * (s.qb + p.qx) - m * m)
        }
        FirstOrderEstimator::Martinez2011 => {
            let cov = 0.5 * (s.qb + p.qx - p.e3) - s.mb * p.mx;
            let sd = ((s.qb - s.mb * s.mb) * (p.qx - p.mx * p.mx))
                .max(0.0)
                .sqrt();
            (cov, sd)
        }
    }
}

/// `(numerator, denominator)` of the total index.
pub(crate) fn total(est: TotalEstimator, s: &SharedMoments, p: &ParamMoments) -> (f64, f64) {
    let v = s.variance();
    match est {
        TotalEstimator::Jansen1999 => (0.5 * p.e2, v),
        TotalEstimator::Sobol2007 => (0.5 * (s.qa - p.qx + p.e2), v),
        TotalEstimator::Janon2014 => {
            let m = 0.5 * (s.ma + p.mx);
            (0.5 * p.e2, 0.5 * (s.qa + p.qx) - m * m)
        }
        TotalEstimator::Martinez2011 => {
            let cov = 0.5 * (s.qa + p.qx - p.e2) - s.ma * p.mx;
            let sd = ((s.qa - s.ma * s.ma) * (p.qx - p.mx * p.mx))
                .max(0.0)
                .sqrt();
            (sd - cov, sd)
        }
    }
}
