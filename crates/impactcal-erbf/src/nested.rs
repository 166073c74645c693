//! Nested cross-validation for the choice of a surrogate's options
//! ([`crate::Selection::Nested`]).
//!
//! The minimum of many leave-one-out (LOO) scores is biased low: it rewards the candidate
//! that fitted the noise of these samples best, so the score of the chosen candidate
//! overstates how well it predicts. Nested cross-validation measures that optimism instead
//! of trusting it. The candidates fall into **classes**, the structural choices ([`class_of`]:
//! the kernel, and whether it interpolates or smooths); within a class the continuous
//! parameters (width or radius, amount of smoothing) are chosen by the minimum LOO error.
//! An outer split into [`OUTER_FOLDS`] folds scores each class's whole procedure: for
//! every fold, the class's candidates are scored by LOO on the other folds' samples only,
//! the best one is fitted to those samples, and it predicts the held-out fold. The sum of
//! squared held-out errors over the folds estimates the error of "choose within the class
//! by LOO, then fit" without the selection's optimism, since no held-out sample took part
//! in the choice it scores. The class of the lowest outer error is kept (per output column,
//! like the LOO choice), and its candidate is chosen by LOO on all samples.
//!
//! Only a few classes compete at the outer level (2 for one kernel, 8 for all four classic
//! kernels), so the outer minimum is itself a choice among few, not among about 90 or 400.
//!
//! Folds: sample `k` is in fold `k mod 5`. No random numbers are needed, the answer is the
//! same for every run, and a design listed in some order (sorted by a parameter, or grown
//! in stages) has every part of that order in every fold. Each fold's training set has at
//! least four fifths of the samples, so the procedure scored is the one applied to all of
//! them, on a slightly smaller design (the usual, slightly pessimistic, bias of K-fold
//! cross-validation, the same for every class).
//!
//! Cost: the candidate grid is scored `OUTER_FOLDS + 1` times (on four fifths of the
//! samples in each fold), plus one fit per class, fold and chosen candidate.

use faer::{Mat, MatRef};
use impactcal_core::ParameterSpace;

use crate::components::Fitted;
use crate::error::{ErbfError, Result};
use crate::radial::RadialFunction;
use crate::tuning::{ComponentOptions, Scores, Selection, Tuned, finish};

/// Number of outer folds (5, as Hastie, Tibshirani and Friedman advise for K-fold
/// cross-validation: a fold's training set is 80 % of the samples).
pub const OUTER_FOLDS: usize = 5;

/// The class of a candidate: its family and kernel (the ERBF, cubic, thin-plate, Gaussian or
/// multiquadric) and whether it smooths (`smoothing > 0`) or interpolates. Widths, radii
/// and the amount of smoothing are the continuous parameters tuned within a class.
pub fn class_of(candidate: &ComponentOptions) -> (u8, bool) {
    match candidate {
        ComponentOptions::Erbf(o) => (0, o.smoothing > 0.0),
        ComponentOptions::Rbf(o) => (
            match o.radial {
                RadialFunction::Cubic => 1,
                RadialFunction::ThinPlate => 2,
                RadialFunction::Gaussian { .. } => 3,
                RadialFunction::Multiquadric { .. } => 4,
            },
            o.smoothing > 0.0,
        ),
    }
}

/// The outer estimate of every class ([`estimate`]).
#[derive(Debug, Clone)]
pub struct NestedEstimate {
    /// The classes, as lists of candidate indices, in order of first appearance.
    pub classes: Vec<Vec<usize>>,
    /// Per class and scored column: the mean squared error on the held-out samples of
    /// "choose within the class by the minimum LOO error on the other folds, then fit to
    /// them" (`f64::INFINITY` when in some fold no candidate of the class could be fitted).
    pub outer: Vec<Vec<f64>>,
    /// Per class and scored column: the mean squared LOO error, on all samples, of the
    /// class's candidate of the lowest LOO error (the score the minimum rule reports and
    /// trusts), `f64::INFINITY` when none could be fitted.
    pub inner: Vec<Vec<f64>>,
}

/// Scores every class of `candidates` (raw `points` `N x m` in the order of `space`,
/// `values` `N x T`; one scored column per output column when `per_column`, else one for all
/// of them, summing their squared errors) by the outer split described in the module
/// documentation.
///
/// # Errors
/// [`ErbfError::InvalidModel`] when there are fewer than `2 OUTER_FOLDS` samples (a fold's
/// training set would be too small to say anything); the first candidate's error when no
/// candidate can be fitted to all samples.
pub fn estimate(
    space: &ParameterSpace,
    points: MatRef<'_, f64>,
    values: MatRef<'_, f64>,
    candidates: &[ComponentOptions],
    per_column: bool,
) -> Result<NestedEstimate> {
    check_samples(values.nrows())?;
    let all = Scores::new(space, points, values, candidates, per_column)?;
    Ok(estimate_from(
        space, points, values, candidates, per_column, &all,
    ))
}

/// [`estimate`] with the LOO scores of all samples already formed (`n >= 2 OUTER_FOLDS`).
fn estimate_from(
    space: &ParameterSpace,
    points: MatRef<'_, f64>,
    values: MatRef<'_, f64>,
    candidates: &[ComponentOptions],
    per_column: bool,
    all: &Scores,
) -> NestedEstimate {
    let (n, t) = values.shape();
    let mut classes: Vec<((u8, bool), Vec<usize>)> = Vec::new();
    for (i, c) in candidates.iter().enumerate() {
        let key = class_of(c);
        match classes.iter_mut().find(|(k, _)| *k == key) {
            Some((_, members)) => members.push(i),
            None => classes.push((key, vec![i])),
        }
    }
    let classes: Vec<Vec<usize>> = classes.into_iter().map(|(_, m)| m).collect();
    let scored = if per_column { t } else { 1 };
    let inner = classes
        .iter()
        .map(|members| {
            let among = entries_of(all, members);
            (0..scored)
                .map(|c| {
                    all.pick(&among, c, Selection::MinimumLoo)
                        .map_or(f64::INFINITY, |e| finite_or_inf(all.mean(e, c)))
                })
                .collect()
        })
        .collect();
    let mut outer = vec![vec![0.0; scored]; classes.len()];
    for fold in 0..OUTER_FOLDS {
        let train: Vec<usize> = (0..n).filter(|k| k % OUTER_FOLDS != fold).collect();
        let test: Vec<usize> = (0..n).filter(|k| k % OUTER_FOLDS == fold).collect();
        let rows = |m: MatRef<'_, f64>, idx: &[usize]| {
            Mat::from_fn(idx.len(), m.ncols(), |i, j| m[(idx[i], j)])
        };
        let (p_train, v_train) = (rows(points, &train), rows(values, &train));
        let (p_test, v_test) = (rows(points, &test), rows(values, &test));
        let scores = Scores::new(
            space,
            p_train.as_ref(),
            v_train.as_ref(),
            candidates,
            per_column,
        )
        .ok();
        for (class, members) in classes.iter().enumerate() {
            let held_out = scores.as_ref().and_then(|s| {
                held_out_errors(
                    space,
                    (p_train.as_ref(), v_train.as_ref()),
                    (p_test.as_ref(), v_test.as_ref()),
                    candidates,
                    s,
                    members,
                )
            });
            for c in 0..scored {
                outer[class][c] += match &held_out {
                    Some(sq) if per_column => sq[c],
                    Some(sq) => sq.iter().sum(),
                    None => f64::INFINITY,
                };
            }
        }
    }
    for row in &mut outer {
        for v in row.iter_mut() {
            *v = finite_or_inf(*v / n as f64);
        }
    }
    NestedEstimate {
        classes,
        outer,
        inner,
    }
}

/// [`Selection::Nested`]: per scored column the class of the lowest outer estimate
/// ([`estimate`]; ties to the class listed first), and within it the candidate of the
/// lowest LOO error on all samples. With a single class this is the minimum rule.
///
/// # Errors
/// As [`estimate`].
pub(crate) fn tune_nested(
    space: &ParameterSpace,
    points: MatRef<'_, f64>,
    values: MatRef<'_, f64>,
    candidates: &[ComponentOptions],
    per_column: bool,
) -> Result<Tuned> {
    let scored = if per_column { values.ncols() } else { 1 };
    check_samples(values.nrows())?;
    let all = Scores::new(space, points, values, candidates, per_column)?;
    let est = estimate_from(space, points, values, candidates, per_column, &all);
    let chosen: Vec<usize> = (0..scored)
        .map(|c| {
            let mut best: Option<usize> = None;
            for (class, row) in est.outer.iter().enumerate() {
                let fitted = !entries_of(&all, &est.classes[class]).is_empty();
                if fitted && best.is_none_or(|b| row[c] < est.outer[b][c]) {
                    best = Some(class);
                }
            }
            let among = match best {
                Some(class) if est.outer[class][c].is_finite() => {
                    entries_of(&all, &est.classes[class])
                }
                // No class could be scored in every fold: the minimum over all.
                _ => (0..all.entries.len()).collect(),
            };
            let e = all.pick(&among, c, Selection::MinimumLoo).unwrap_or(0);
            all.entries[e].0
        })
        .collect();
    finish(space, points, values, candidates, per_column, &chosen)
}

/// Two samples per outer fold at least, or [`ErbfError::InvalidModel`].
fn check_samples(n: usize) -> Result<()> {
    if n < 2 * OUTER_FOLDS {
        return Err(ErbfError::InvalidModel(format!(
            "nested cross-validation needs at least {} samples, got {n}",
            2 * OUTER_FOLDS
        )));
    }
    Ok(())
}

/// Positions in `scores.entries` of the candidates `members` that could be fitted.
fn entries_of(scores: &Scores, members: &[usize]) -> Vec<usize> {
    scores
        .entries
        .iter()
        .enumerate()
        .filter(|(_, (i, _))| members.contains(i))
        .map(|(e, _)| e)
        .collect()
}

/// The sum, per output column, of the squared errors on the held-out samples of the
/// class's candidates chosen (per scored column) by the minimum LOO error on the training
/// samples and fitted to them; `None` when the class has no candidate that fits.
fn held_out_errors(
    space: &ParameterSpace,
    (p_train, v_train): (MatRef<'_, f64>, MatRef<'_, f64>),
    (p_test, v_test): (MatRef<'_, f64>, MatRef<'_, f64>),
    candidates: &[ComponentOptions],
    scores: &Scores,
    members: &[usize],
) -> Option<Vec<f64>> {
    let among = entries_of(scores, members);
    let t = v_train.ncols();
    let chosen: Vec<usize> = (0..scores.scored)
        .map(|c| {
            scores
                .pick(&among, c, Selection::MinimumLoo)
                .map(|e| scores.entries[e].0)
        })
        .collect::<Option<_>>()?;
    let u_train = space.to_unit_matrix(p_train).ok()?;
    let u_test = space.to_unit_matrix(p_test).ok()?;
    let mut sq = vec![0.0; t];
    let mut fitted: Vec<(usize, Mat<f64>)> = Vec::new();
    for (c, total) in sq.iter_mut().enumerate() {
        let index = chosen[if scores.scored == t { c } else { 0 }];
        if !fitted.iter().any(|(i, _)| *i == index) {
            let model =
                Fitted::fit(space, p_train, u_train.as_ref(), v_train, candidates[index]).ok()?;
            fitted.push((index, model.predict(p_test, u_test.as_ref()).ok()?));
        }
        let pred = &fitted.iter().find(|(i, _)| *i == index)?.1;
        *total = (0..v_test.nrows())
            .map(|k| (pred[(k, c)] - v_test[(k, c)]).powi(2))
            .sum();
    }
    Some(sq)
}

fn finite_or_inf(v: f64) -> f64 {
    if v.is_finite() { v } else { f64::INFINITY }
}
