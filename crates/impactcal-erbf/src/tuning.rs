//! Shape parameters and smoothing chosen by leave-one-out cross-validation.
//!
//! Real crash responses carry numerical noise (a tiny parameter change moves them), and an
//! interpolating surrogate fits that noise; a Gaussian or multiquadric whose width does not
//! suit the spacing of the samples fails outright in many dimensions. Given candidate
//! options, [`tune`] fits each one and keeps, **for every output column separately**, the
//! candidate with the smallest sum of squared leave-one-out (LOO) errors
//! `sum_k (F_kt - s^{(-k)}_t(x_k))^2`. Candidates that cannot be fitted (a singular
//! system) are skipped.
//!
//! The candidates of [`candidates`], in unit-scaled inputs with `h` the median distance from
//! a sample to its nearest neighbour:
//!
//! - widths (Gaussian `w`, multiquadric `c`) `h 2^j`, `j = -2..=5`;
//! - smoothing `lambda` (a ridge `lambda I` on the kernel block) `0` and
//!   `phi_max 10^p`, `p = -9..=2`, with `phi_max` the largest `|phi(r)|` over the sample
//!   distances: from interpolation to the limit where the kernel part vanishes and only
//!   the least-squares polynomial tail is left;
//! - ERBF radii `r_c = h 2^j`, `j = -2..=4`, each with the smoothing `0` and `10^p`,
//!   `p = -9..=2`, relative to the mean diagonal of ERBF's kernel matrix
//!   ([`ErbfOptions::smoothing`]), all with centred outputs (which smoothing implies) so
//!   that the candidates differ only in radius and smoothing.
//!
//! Classic RBF candidates are scored by Rippa's exact closed form (valid with smoothing);
//! ERBF candidates by ERBF's closed-form kernel-view approximation, which is cheap but only
//! approximate (one factorisation and one SVD per radius serve all its smoothings,
//! `smoothing.rs`). Smaller smoothing wins ties, so data without noise stays interpolated.

use faer::{Mat, MatRef};
use impactcal_core::ParameterSpace;

use crate::erbf::Erbf;
use crate::error::Result;
use crate::loo::LooMethod;
use crate::options::ErbfOptions;
use crate::radial::RadialFunction;
use crate::rbf::{RbfInterpolant, RbfOptions};
use crate::smoothing::RSvd;

/// The options of one component surrogate: a family and its parameters.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "family", rename_all = "kebab-case")]
pub enum ComponentOptions {
    /// ERBF with these options (inputs scaled by the space inside the model).
    Erbf(ErbfOptions),
    /// A classic RBF interpolant in unit-scaled inputs.
    Rbf(RbfOptions),
}

/// The outcome of [`tune`]: per output column, the chosen options and their LOO errors.
#[derive(Debug, Clone)]
pub struct Tuned {
    /// Chosen options, one per output column.
    pub options: Vec<ComponentOptions>,
    /// LOO errors of the chosen options, `N x T`.
    pub loo: Mat<f64>,
}

/// Median distance from a sample to its nearest neighbour (`points` `N x m`, `N >= 2`;
/// 1 for a single sample or coincident samples).
pub fn median_spacing(points: MatRef<'_, f64>) -> f64 {
    let n = points.nrows();
    let mut nearest: Vec<f64> = (0..n)
        .map(|i| {
            (0..n)
                .filter(|&j| j != i)
                .map(|j| {
                    (0..points.ncols())
                        .map(|c| (points[(i, c)] - points[(j, c)]).powi(2))
                        .sum::<f64>()
                        .sqrt()
                })
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    nearest.sort_by(f64::total_cmp);
    match nearest.get(n / 2) {
        Some(&h) if h.is_finite() && h > 0.0 => h,
        _ => 1.0,
    }
}

/// The candidate options around `base` for samples `unit` (unit-scaled, `N x m`), as
/// described in the module documentation: for a classic RBF every width (if it has one)
/// with every smoothing, the tail of `base` kept; for ERBF every radius, the other options
/// of `base` kept.
pub fn candidates(base: ComponentOptions, unit: MatRef<'_, f64>) -> Vec<ComponentOptions> {
    let h = median_spacing(unit);
    match base {
        ComponentOptions::Erbf(o) => (-2..=4)
            .flat_map(|j| {
                smoothing_grid(1.0).map(move |smoothing| {
                    ComponentOptions::Erbf(ErbfOptions {
                        rc: h * 2f64.powi(j),
                        smoothing,
                        center_outputs: true,
                        ..o
                    })
                })
            })
            .collect(),
        ComponentOptions::Rbf(o) => {
            let radials: Vec<RadialFunction> = match o.radial {
                RadialFunction::Gaussian { .. } => (-2..=5)
                    .map(|j| RadialFunction::Gaussian {
                        width: h * 2f64.powi(j),
                    })
                    .collect(),
                RadialFunction::Multiquadric { .. } => (-2..=5)
                    .map(|j| RadialFunction::Multiquadric {
                        c: h * 2f64.powi(j),
                    })
                    .collect(),
                other => vec![other],
            };
            let dmax = diameter(unit);
            let mut out = Vec::new();
            for radial in radials {
                let phi_max = radial
                    .value(0.0)
                    .abs()
                    .max(radial.value(dmax).abs())
                    .max(f64::MIN_POSITIVE);
                for s in smoothing_grid(phi_max) {
                    out.push(ComponentOptions::Rbf(RbfOptions {
                        radial,
                        smoothing: s,
                        ..o
                    }));
                }
            }
            out
        }
    }
}

/// Fits every candidate to `points` (raw, `N x m`, in the order of `space`) and `values`
/// (`N x T`) and keeps, per output column (or, unless `per_column`, for all columns
/// together), the one with the smallest sum of squared LOO errors (the first on ties:
/// order candidates from least to most smoothing).
///
/// # Errors
/// The error of the first candidate when no candidate can be fitted (so bad input reports
/// what [`Erbf::fit`] or [`RbfInterpolant::fit`] say about it).
pub fn tune(
    space: &ParameterSpace,
    points: MatRef<'_, f64>,
    values: MatRef<'_, f64>,
    candidates: &[ComponentOptions],
    per_column: bool,
) -> Result<Tuned> {
    let unit = space.to_unit_matrix(points)?;
    let (n, t) = values.shape();
    let mut best: Option<Tuned> = None;
    let mut best_sse = vec![f64::INFINITY; t];
    let mut first_error = None;
    let mut erbf_cache = ErbfCache::default();
    for &candidate in candidates {
        let loo = match candidate {
            ComponentOptions::Erbf(o) => erbf_cache.loo(space, points, values, o),
            ComponentOptions::Rbf(_) => {
                candidate_loo(space, points, unit.as_ref(), values, candidate)
            }
        };
        let loo = match loo {
            Ok(e) => e,
            Err(e) => {
                first_error.get_or_insert(e);
                continue;
            }
        };
        let tuned = best.get_or_insert_with(|| Tuned {
            options: vec![candidate; t],
            loo: Mat::zeros(n, t),
        });
        let sse: Vec<f64> = (0..t)
            .map(|c| loo.col(c).iter().map(|e| e * e).sum())
            .collect();
        // A relative margin keeps the earlier (less smoothed) candidate on ties.
        let better = |new: f64, old: f64| new.is_finite() && new < old * (1.0 - 1e-9);
        if per_column {
            for c in 0..t {
                if better(sse[c], best_sse[c]) {
                    best_sse[c] = sse[c];
                    tuned.options[c] = candidate;
                    tuned.loo.col_mut(c).copy_from(loo.col(c));
                }
            }
        } else if better(sse.iter().sum(), best_sse.iter().sum()) {
            best_sse.copy_from_slice(&sse);
            tuned.options.iter_mut().for_each(|o| *o = candidate);
            tuned.loo.copy_from(&loo);
        }
    }
    match (best, first_error) {
        (Some(t), _) => Ok(t),
        (None, Some(e)) => Err(e),
        (None, None) => Err(crate::error::ErbfError::InvalidModel(
            "no candidate options to choose from".into(),
        )),
    }
}

/// The last ERBF fit and the SVD of its factor, reused for the candidates that differ from
/// it only in their smoothing (one factorisation per radius).
#[derive(Default)]
struct ErbfCache {
    fitted: Option<(ErbfOptions, Erbf, Option<RSvd>)>,
}

impl ErbfCache {
    /// Closed-form LOO errors of ERBF with options `o`.
    fn loo(
        &mut self,
        space: &ParameterSpace,
        points: MatRef<'_, f64>,
        values: MatRef<'_, f64>,
        o: ErbfOptions,
    ) -> Result<Mat<f64>> {
        let key = ErbfOptions {
            smoothing: 0.0,
            ..o
        };
        match &mut self.fitted {
            Some((k, model, svd)) if *k == key => {
                if model.options().smoothing.to_bits() == o.smoothing.to_bits() {
                    return model.loo_errors(LooMethod::Closed);
                }
                if o.smoothing == 0.0 {
                    return Erbf::fit(space, points, values, o)?.loo_errors(LooMethod::Closed);
                }
                let factor_svd = match svd.take() {
                    Some(s) => s,
                    None => model.r_svd()?,
                };
                let loo = model.loo_smoothed(&factor_svd, o.smoothing);
                *svd = Some(factor_svd);
                loo
            }
            _ => {
                self.fitted = None;
                let model = Erbf::fit(space, points, values, o)?;
                let loo = model.loo_errors(LooMethod::Closed);
                self.fitted = Some((key, model, None));
                loo
            }
        }
    }
}

/// LOO errors of one candidate (`N x T`).
fn candidate_loo(
    space: &ParameterSpace,
    points: MatRef<'_, f64>,
    unit: MatRef<'_, f64>,
    values: MatRef<'_, f64>,
    candidate: ComponentOptions,
) -> Result<Mat<f64>> {
    match candidate {
        ComponentOptions::Erbf(o) => {
            Erbf::fit(space, points, values, o)?.loo_errors(LooMethod::Closed)
        }
        ComponentOptions::Rbf(o) => {
            RbfInterpolant::fit(unit, values, o)?.loo_errors(LooMethod::Closed)
        }
    }
}

/// `0` and `unit 10^p`, `p = -9..=2`, least smoothing first.
fn smoothing_grid(unit: f64) -> impl Iterator<Item = f64> {
    std::iter::once(0.0).chain((-9..=2).map(move |p| unit * 10f64.powi(p)))
}

fn diameter(unit: MatRef<'_, f64>) -> f64 {
    let (lo, hi) = crate::rbf::bounding_box(unit);
    lo.iter()
        .zip(&hi)
        .map(|(l, h)| (h - l) * (h - l))
        .sum::<f64>()
        .sqrt()
}
