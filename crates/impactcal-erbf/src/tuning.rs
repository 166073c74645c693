//! Shape parameters and smoothing chosen by leave-one-out cross-validation.
//!
//! Real crash responses carry numerical noise (a tiny parameter change moves them), and an
//! interpolating surrogate fits that noise; a Gaussian or multiquadric whose width does not
//! suit the spacing of the samples fails outright in many dimensions. Given candidate
//! options, [`tune`] fits each one, scores it **for every output column separately** by its
//! leave-one-out (LOO) errors `e_k = F_kt - s^{(-k)}_t(x_k)`, and keeps the candidate of
//! the lowest score ([`Selection::MinimumLoo`], the default) or the smoothest within one
//! standard error of it ([`Selection::OneStandardError`]). Candidates that cannot be
//! fitted (a singular system) are skipped.
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
//! `smoothing.rs`). Under [`Selection::MinimumLoo`] smaller smoothing wins ties, so data
//! without noise stays interpolated.

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
                for s in smoothing_grid(smoothing_unit(radial, dmax)) {
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

/// How [`tune`] picks among the candidates' leave-one-out scores.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
#[non_exhaustive]
pub enum Selection {
    /// The candidate of the smallest sum of squared LOO errors (the first on ties): the
    /// default.
    #[default]
    MinimumLoo,
    /// The one-standard-error rule toward the smoother candidate: among the
    /// candidates whose squared LOO errors are not worse than the lowest-scoring
    /// candidate's by more than one standard error of their paired difference, the one
    /// with the most relative smoothing ([`relative_smoothing`]); ties to the lower score.
    ///
    /// With `s_k` the squared LOO error of sample `k` under a candidate and `s*_k` under
    /// the candidate of the lowest mean, `d_k = s_k - s*_k` (`k = 1..N`), a candidate is
    /// eligible when `mean(d) <= sd(d) / sqrt(N)`. The lowest of many noisy scores is
    /// biased low (the minimum rewards the candidate that fitted the noise of these
    /// samples best); a candidate the samples cannot tell from it within one standard
    /// error is as good on the evidence, and the smoother one varies less. The paired
    /// difference is the right scale: the candidates are scored on the same samples, so
    /// their errors are strongly correlated, and on data without noise every sample
    /// tells the interpolant from a smoothed fit (which then stays out).
    ///
    /// Not the default: on data it was not designed on (five random splits of a crash
    /// study, synthetic families at three noise levels) it was more often worse than the
    /// minimum than better (docs/validation.md, "Surrogate choice without selection bias").
    OneStandardError,
    /// Nested cross-validation ([`crate::nested`]): the candidates fall into a few classes
    /// (a kernel, interpolating or smoothed); within a class the minimum LOO error chooses,
    /// and the class is the one whose "choose by LOO, then fit" has the lowest error on
    /// held-out samples of an outer split, where the samples that score a choice took no
    /// part in making it.
    ///
    /// Not the default: its check on data it was not designed on is incomplete
    /// (docs/validation.md, "Surrogate choice by nested cross-validation").
    Nested,
}

/// The smoothing of a candidate relative to the scale its grid is built on
/// ([`candidates`]): for a classic RBF `lambda / phi_max` (`phi_max` the largest `|phi|` over
/// the distances `0..=diameter` of the samples `unit`), for ERBF its `smoothing` (already
/// relative to the mean diagonal of its kernel matrix). 0 is interpolation; large values
/// leave only the least-squares tail (a linear regression for the cubic and thin-plate
/// kernels).
pub fn relative_smoothing(candidate: ComponentOptions, diameter: f64) -> f64 {
    match candidate {
        ComponentOptions::Erbf(o) => o.smoothing,
        ComponentOptions::Rbf(o) => o.smoothing / smoothing_unit(o.radial, diameter),
    }
}

/// `phi_max`: the largest `|phi(r)|` for `r` in `0..=diameter` (at one end or the other for
/// every kernel here), at least the smallest positive number.
fn smoothing_unit(radial: RadialFunction, diameter: f64) -> f64 {
    radial
        .value(0.0)
        .abs()
        .max(radial.value(diameter).abs())
        .max(f64::MIN_POSITIVE)
}

/// Fits every candidate to `points` (raw, `N x m`, in the order of `space`) and `values`
/// (`N x T`) and keeps, per output column (or, unless `per_column`, for all columns
/// together), the candidate that `selection` picks from their leave-one-out errors
/// ([`Selection`]; [`Selection::MinimumLoo`] keeps the first on ties, so order candidates
/// from least to most smoothing). The scores are kept per sample (`N` values per scored
/// column and candidate); the LOO errors of the chosen candidates are formed again at the
/// end. [`Selection::Nested`] chooses the class of candidates by nested cross-validation
/// first ([`crate::nested`], classes by [`crate::nested::class_of`]).
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
    selection: Selection,
) -> Result<Tuned> {
    if selection == Selection::Nested {
        return crate::nested::tune_nested(space, points, values, candidates, per_column);
    }
    let scores = Scores::new(space, points, values, candidates, per_column)?;
    let all: Vec<usize> = (0..scores.entries.len()).collect();
    let chosen: Vec<usize> = (0..scores.scored)
        .map(|c| scores.pick(&all, c, selection).unwrap_or(0))
        .map(|e| scores.entries[e].0)
        .collect();
    finish(space, points, values, candidates, per_column, &chosen)
}

/// The leave-one-out scores of candidates on one set of samples: per fitted candidate its
/// index and, per scored column (one per output column, or one for all), the squared LOO
/// error of every sample.
pub(crate) struct Scores {
    /// `(candidate index, squared errors per scored column per sample)`.
    pub(crate) entries: Vec<(usize, Vec<Vec<f64>>)>,
    /// Relative smoothing of each entry ([`relative_smoothing`]).
    smoothing: Vec<f64>,
    /// Scored columns.
    pub(crate) scored: usize,
}

impl Scores {
    /// Scores every candidate that can be fitted.
    ///
    /// # Errors
    /// The first candidate's error when none can be fitted.
    pub(crate) fn new(
        space: &ParameterSpace,
        points: MatRef<'_, f64>,
        values: MatRef<'_, f64>,
        candidates: &[ComponentOptions],
        per_column: bool,
    ) -> Result<Self> {
        let unit = space.to_unit_matrix(points)?;
        let (n, t) = values.shape();
        let scored = if per_column { t } else { 1 };
        let diameter = diameter(unit.as_ref());
        let mut entries: Vec<(usize, Vec<Vec<f64>>)> = Vec::new();
        let mut first_error = None;
        let mut loo_of = LooOf::new(space, points, unit.as_ref(), values);
        for (index, &candidate) in candidates.iter().enumerate() {
            let loo = match loo_of.loo(candidate) {
                Ok(e) => e,
                Err(e) => {
                    first_error.get_or_insert(e);
                    continue;
                }
            };
            let squared: Vec<Vec<f64>> = (0..scored)
                .map(|c| {
                    (0..n)
                        .map(|k| {
                            if per_column {
                                loo[(k, c)] * loo[(k, c)]
                            } else {
                                (0..t).map(|j| loo[(k, j)] * loo[(k, j)]).sum()
                            }
                        })
                        .collect()
                })
                .collect();
            entries.push((index, squared));
        }
        if entries.is_empty() {
            return Err(first_error.unwrap_or_else(|| {
                crate::error::ErbfError::InvalidModel("no candidate options to choose from".into())
            }));
        }
        let smoothing = entries
            .iter()
            .map(|(i, _)| relative_smoothing(candidates[*i], diameter))
            .collect();
        Ok(Scores {
            entries,
            smoothing,
            scored,
        })
    }

    /// The entry (a position in `entries`) that `selection` picks for scored column `c`
    /// among the entries `among` (`None` when `among` is empty).
    pub(crate) fn pick(&self, among: &[usize], c: usize, selection: Selection) -> Option<usize> {
        let column: Vec<(f64, &[f64])> = among
            .iter()
            .map(|&e| (self.smoothing[e], self.entries[e].1[c].as_slice()))
            .collect();
        (!column.is_empty()).then(|| among[pick(&column, selection)])
    }

    /// The mean squared LOO error of entry `e` in scored column `c`.
    pub(crate) fn mean(&self, e: usize, c: usize) -> f64 {
        let sq = &self.entries[e].1[c];
        sq.iter().sum::<f64>() / sq.len() as f64
    }
}

/// The outcome for the candidates chosen, per scored column, by their index: options per
/// output column and their LOO errors on the samples.
///
/// # Errors
/// As [`Erbf::fit`] or [`RbfInterpolant::fit`] (a chosen candidate was fitted before, so
/// only what failed then).
pub(crate) fn finish(
    space: &ParameterSpace,
    points: MatRef<'_, f64>,
    values: MatRef<'_, f64>,
    candidates: &[ComponentOptions],
    per_column: bool,
    chosen: &[usize],
) -> Result<Tuned> {
    let unit = space.to_unit_matrix(points)?;
    let (n, t) = values.shape();
    let mut loo_of = LooOf::new(space, points, unit.as_ref(), values);
    let mut options = vec![candidates[chosen[0]]; t];
    let mut loo = Mat::zeros(n, t);
    let mut done: Vec<(usize, Mat<f64>)> = Vec::new();
    for c in 0..t {
        let index = chosen[if per_column { c } else { 0 }];
        options[c] = candidates[index];
        if !done.iter().any(|(i, _)| *i == index) {
            done.push((index, loo_of.loo(candidates[index])?));
        }
        if let Some((_, e)) = done.iter().find(|(i, _)| *i == index) {
            loo.col_mut(c).copy_from(e.col(c));
        }
    }
    Ok(Tuned { options, loo })
}

/// Closed-form LOO errors of candidates on one set of samples, ERBF's reusing one
/// factorisation per radius.
struct LooOf<'a> {
    space: &'a ParameterSpace,
    points: MatRef<'a, f64>,
    unit: MatRef<'a, f64>,
    values: MatRef<'a, f64>,
    erbf: ErbfCache,
}

impl<'a> LooOf<'a> {
    fn new(
        space: &'a ParameterSpace,
        points: MatRef<'a, f64>,
        unit: MatRef<'a, f64>,
        values: MatRef<'a, f64>,
    ) -> Self {
        LooOf {
            space,
            points,
            unit,
            values,
            erbf: ErbfCache::default(),
        }
    }

    fn loo(&mut self, candidate: ComponentOptions) -> Result<Mat<f64>> {
        match candidate {
            ComponentOptions::Erbf(o) => self.erbf.loo(self.space, self.points, self.values, o),
            ComponentOptions::Rbf(_) => {
                candidate_loo(self.space, self.points, self.unit, self.values, candidate)
            }
        }
    }
}

/// The position in `column` (per candidate: its relative smoothing and the squared LOO
/// error of every sample, finite or not) that `selection` picks: the lowest sum (the first
/// on ties, within a relative `1e-9`), or under the one-standard-error rule the smoothest
/// candidate not worse than it by more than one standard error of the paired difference.
fn pick(column: &[(f64, &[f64])], selection: Selection) -> usize {
    let sum = |sq: &[f64]| -> f64 {
        let s: f64 = sq.iter().sum();
        if s.is_finite() { s } else { f64::INFINITY }
    };
    let mut best = 0;
    for (i, (_, sq)) in column.iter().enumerate() {
        if sum(sq) < sum(column[best].1) * (1.0 - 1e-9) {
            best = i;
        }
    }
    if selection != Selection::OneStandardError || !sum(column[best].1).is_finite() {
        return best;
    }
    let reference = column[best].1;
    let n = reference.len() as f64;
    let eligible = |sq: &[f64]| -> bool {
        if !sum(sq).is_finite() || n < 2.0 {
            return false;
        }
        let d: Vec<f64> = sq.iter().zip(reference).map(|(a, b)| a - b).collect();
        let mean = d.iter().sum::<f64>() / n;
        let var = d.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0);
        mean <= (var / n).sqrt()
    };
    let mut chosen = best;
    for (i, (smoothing, sq)) in column.iter().enumerate() {
        let (chosen_smoothing, chosen_sq) = column[chosen];
        let smoother = match smoothing.total_cmp(&chosen_smoothing) {
            std::cmp::Ordering::Greater => true,
            std::cmp::Ordering::Equal => sum(sq) < sum(chosen_sq),
            std::cmp::Ordering::Less => false,
        };
        if smoother && eligible(sq) {
            chosen = i;
        }
    }
    chosen
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

#[cfg(test)]
#[allow(clippy::float_cmp)] // exact values by construction
mod tests {
    use super::*;

    /// Squared errors `base_k + shift + wobble_k`: a candidate whose mean is above the best
    /// by `shift` while the samples scatter its difference by `wobble`.
    fn scores(base: &[f64], shift: f64, wobble: f64) -> Vec<f64> {
        base.iter()
            .enumerate()
            .map(|(k, b)| b + shift + if k % 2 == 0 { wobble } else { -wobble })
            .collect()
    }

    /// The rule by its definition: a smoother candidate whose paired excess is within one
    /// standard error is taken, one that is worse at every sample (the case of data
    /// without noise) is not, and the minimum rule keeps the lowest score either way.
    #[test]
    fn one_standard_error_rule_picks_the_smoothest_candidate_the_samples_cannot_reject() {
        let base: Vec<f64> = (0..40).map(|k| 1.0 + 0.1 * f64::from(k % 7)).collect();
        // Paired differences 0.01 +- 0.5: a standard error of about 0.5 / sqrt(40) = 0.08,
        // far above the mean excess of 0.01.
        let close = scores(&base, 0.01, 0.5);
        // A mean excess of 0.01 with no scatter: every sample says it is worse.
        let worse = scores(&base, 0.01, 0.0);
        // Within the standard error, but less smoothed than `close`.
        let middle = scores(&base, 0.005, 0.5);
        let column: Vec<(f64, &[f64])> = vec![
            (0.0, &base),
            (1e-6, &middle),
            (1e-3, &close),
            (1e-1, &worse),
        ];
        assert_eq!(pick(&column, Selection::MinimumLoo), 0);
        assert_eq!(pick(&column, Selection::OneStandardError), 2);
        let strict: Vec<(f64, &[f64])> = vec![(0.0, &base), (1e-1, &worse)];
        assert_eq!(pick(&strict, Selection::OneStandardError), 0);
        // A mean excess beyond the standard error: 0.2 against about 0.08.
        let far = scores(&base, 0.2, 0.5);
        let column: Vec<(f64, &[f64])> = vec![(0.0, &base), (1.0, &far)];
        assert_eq!(pick(&column, Selection::OneStandardError), 0);
        // Non-finite scores are never chosen, and the lowest finite one is the reference.
        let bad = vec![f64::NAN; 40];
        let column: Vec<(f64, &[f64])> = vec![(0.0, &bad), (1e-3, &base), (1.0, &bad)];
        assert_eq!(pick(&column, Selection::OneStandardError), 1);
        assert_eq!(pick(&column, Selection::MinimumLoo), 1);
    }

    /// The relative smoothing is the grid's exponent back: `10^p` for the candidates of
    /// every kernel, 0 for interpolation.
    #[test]
    fn relative_smoothing_inverts_the_grid() {
        let unit = Mat::from_fn(12, 2, |i, j| ((i * 7 + j * 3) % 12) as f64 / 11.0);
        let dmax = diameter(unit.as_ref());
        for base in [
            ComponentOptions::Rbf(RbfOptions::new(RadialFunction::Cubic)),
            ComponentOptions::Rbf(RbfOptions::new(RadialFunction::Gaussian { width: 0.3 })),
            ComponentOptions::Erbf(ErbfOptions::default()),
        ] {
            let cands = candidates(base, unit.as_ref());
            let rel: Vec<f64> = cands.iter().map(|&c| relative_smoothing(c, dmax)).collect();
            assert_eq!(rel[0], 0.0);
            for (k, p) in (-9..=2).enumerate() {
                let expected = 10f64.powi(p);
                assert!(
                    (rel[k + 1] / expected - 1.0).abs() < 1e-12,
                    "{base:?}: {rel:?}"
                );
            }
        }
    }
}
