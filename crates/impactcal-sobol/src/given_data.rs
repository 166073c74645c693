//! First-order indices from one existing sample (no pick-freeze design).

use faer::MatRef;
use rayon::prelude::*;
use serde::Serialize;

use crate::analysis::non_finite_output;
use crate::error::{Result, SobolError};
use impactcal_core::ParamGuard;
use impactcal_core::error::{dimension_mismatch, invalid_option};

/// Options of [`given_data_first_order`].
#[derive(Debug, Clone, PartialEq)]
pub struct GivenDataOptions {
    /// Number of equal-count bins per parameter; default `round(n^(1/3))`, at least 2.
    pub bins: Option<usize>,
    /// Low-variance threshold, as in [`SobolOptions`](crate::SobolOptions) (default 1e-10).
    pub low_variance_tolerance: f64,
    /// Parameter names (default `x1, x2, ...`).
    pub parameter_names: Option<Vec<String>>,
    /// Output names (default `y1, y2, ...`).
    pub output_names: Option<Vec<String>>,
}

impl ParamGuard for GivenDataOptions {
    type Checked = GivenDataOptions;

    /// Checks the options on their own (the bins against the sample's runs and the names
    /// against the columns are checked when the indices are computed).
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) naming the
    /// option: fewer than 2 `bins`, a `low_variance_tolerance` that is not finite and
    /// non-negative, an empty name in `parameter_names` or `output_names`.
    fn check_ref(&self) -> impactcal_core::Result<()> {
        if let Some(b) = self.bins
            && b < 2
        {
            return Err(invalid_option("bins", b, "need at least 2 bins"));
        }
        if !(self.low_variance_tolerance >= 0.0 && self.low_variance_tolerance.is_finite()) {
            return Err(invalid_option(
                "low_variance_tolerance",
                self.low_variance_tolerance,
                "the low-variance tolerance must be finite and non-negative",
            ));
        }
        for (key, names) in [
            ("parameter_names", &self.parameter_names),
            ("output_names", &self.output_names),
        ] {
            if let Some(i) = names.iter().flatten().position(|n| n.trim().is_empty()) {
                return Err(invalid_option(key, format!("entry {i}"), "a name is empty"));
            }
        }
        Ok(())
    }

    fn check(self) -> impactcal_core::Result<GivenDataOptions> {
        self.check_ref()?;
        Ok(self)
    }
}

impl Default for GivenDataOptions {
    fn default() -> Self {
        GivenDataOptions {
            bins: None,
            low_variance_tolerance: 1e-10,
            parameter_names: None,
            output_names: None,
        }
    }
}

/// First-order indices estimated from a given sample by the correlation ratio.
///
/// For parameter `i` the `n` runs are split by the rank of `x_i` into `M` bins of (almost)
/// equal count; with bin means `ybar_m`, counts `n_m` and overall mean `ybar`,
/// `SSB = sum_m n_m (ybar_m - ybar)^2`, `SST = sum_k (y_k - ybar)^2`, `SSW = SST - SSB`:
///
/// - `first_order_uncorrected = SSB / SST` (the binned correlation ratio, biased upward by
///   about `(M - 1) / n` for an inactive parameter);
/// - `first_order = (SSB - (M - 1) SSW / (n - M)) / SST`, the bias-corrected value (the
///   epsilon-squared of one-way ANOVA), near zero for an inactive parameter and possibly
///   slightly negative.
///
/// Binning also loses the variation of `E[Y|X_i]` inside a bin (for a linear effect a
/// fraction `1/M^2` of `V_i`). Plischke, Borgonovo & Smith (2013) discuss the method. Only
/// first-order indices can be had this way; totals and interactions need a pick-freeze
/// design.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GivenDataIndices {
    /// Parameter names.
    pub parameters: Vec<String>,
    /// Output names.
    pub outputs: Vec<String>,
    /// Number of runs.
    pub n: usize,
    /// Bins per parameter.
    pub bins: usize,
    /// `first_order[t][i]`: bias-corrected first-order index.
    pub first_order: Vec<Vec<f64>>,
    /// `first_order_uncorrected[t][i]`: the plain binned correlation ratio.
    pub first_order_uncorrected: Vec<Vec<f64>>,
    /// `max(S_i, 0) / sum_j max(S_j, 0)` from `first_order`: shares that sum to 1.
    pub normalised_first_order_share: Vec<Vec<f64>>,
    /// Output variance per column (divisor `n`).
    pub variance: Vec<f64>,
    /// Names of the columns whose variance is at most the low-variance tolerance times their
    /// own mean square; their indices are NaN.
    pub low_variance_outputs: Vec<String>,
}

/// Estimates first-order indices of every output column from runs `x` (`n x d`, one run per
/// row, in any design: Halton, Latin hypercube, an existing ensemble) and their `outputs`
/// (`n x T`, same rows). See [`GivenDataIndices`] for the estimator.
///
/// # Errors
/// Under [`SobolError::Core`](crate::SobolError::Core):
/// [`CoreError::DimensionMismatch`](impactcal_core::CoreError::DimensionMismatch) when the
/// row counts differ, there is no output column, or a name list has the wrong length;
/// [`ParamGuard::check_ref`]'s errors for the options;
/// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) when there are
/// fewer than 2 runs per bin;
/// [`CoreError::NonFinite`](impactcal_core::CoreError::NonFinite) for NaN or infinite
/// outputs or parameter values, naming row and column.
pub fn given_data_first_order(
    x: MatRef<'_, f64>,
    outputs: MatRef<'_, f64>,
    options: &GivenDataOptions,
) -> Result<GivenDataIndices> {
    options.check_ref()?;
    let (n, d, cols) = (x.nrows(), x.ncols(), outputs.ncols());
    if outputs.nrows() != n {
        return Err(dimension_mismatch(
            "output rows (one per run of the sample)",
            n,
            outputs.nrows(),
        ));
    }
    if cols == 0 {
        return Err(dimension_mismatch("output columns, at least", 1, 0));
    }
    let bins = options
        .bins
        .unwrap_or_else(|| ((n as f64).cbrt().round() as usize).max(2));
    if bins < 2 || n < 2 * bins {
        return Err(invalid_option(
            "bins",
            bins,
            format!("need at least 2 bins and 2 runs per bin; the sample has {n} runs"),
        ));
    }
    for r in 0..n {
        if let Some(t) = outputs.row(r).iter().position(|v| !v.is_finite()) {
            return Err(non_finite_output(r, t, outputs[(r, t)]));
        }
    }
    impactcal_core::check_finite_mat("parameter values", x)?;
    let names = |given: &Option<Vec<String>>, prefix: &str, count: usize, what: &str| match given {
        Some(v) if v.len() != count => Err(dimension_mismatch::<SobolError>(
            format!("number of {what} names"),
            count,
            v.len(),
        )),
        Some(v) => Ok(v.clone()),
        None => Ok((1..=count).map(|k| format!("{prefix}{k}")).collect()),
    };
    let parameters = names(&options.parameter_names, "x", d, "parameter")?;
    let output_names = names(&options.output_names, "y", cols, "output")?;

    let mut mean = vec![0.0; cols];
    for row in outputs.row_iter() {
        mean.iter_mut().zip(row.iter()).for_each(|(m, v)| *m += v);
    }
    mean.iter_mut().for_each(|m| *m /= n as f64);
    let mut sst = vec![0.0; cols];
    for row in outputs.row_iter() {
        for ((s, v), m) in sst.iter_mut().zip(row.iter()).zip(&mean) {
            *s += (v - m) * (v - m);
        }
    }
    // The column's own scale: its sum of squares about zero (see `SobolOptions`).
    let mut ssq = vec![0.0; cols];
    for row in outputs.row_iter() {
        ssq.iter_mut()
            .zip(row.iter())
            .for_each(|(q, v)| *q += v * v);
    }
    let low: Vec<bool> = sst
        .iter()
        .zip(&ssq)
        .map(|(&s, &q)| !(s > 0.0 && s > options.low_variance_tolerance * q))
        .collect();

    // ssb[i][t] for every parameter.
    let ssb: Vec<Vec<f64>> = (0..d)
        .into_par_iter()
        .map(|i| {
            let mut order: Vec<usize> = (0..n).collect();
            order.sort_by(|&p, &q| x[(p, i)].total_cmp(&x[(q, i)]).then(p.cmp(&q)));
            let mut sums = vec![0.0; bins * cols];
            let mut counts = vec![0usize; bins];
            for (rank, &r) in order.iter().enumerate() {
                let m = rank * bins / n;
                counts[m] += 1;
                let s = &mut sums[m * cols..(m + 1) * cols];
                s.iter_mut()
                    .zip(outputs.row(r).iter())
                    .for_each(|(a, v)| *a += v);
            }
            let mut out = vec![0.0; cols];
            for (m, &c) in counts.iter().enumerate() {
                let s = &sums[m * cols..(m + 1) * cols];
                for t in 0..cols {
                    let dev = s[t] / c as f64 - mean[t];
                    out[t] += c as f64 * dev * dev;
                }
            }
            out
        })
        .collect();

    let factor = (bins - 1) as f64 / (n - bins) as f64;
    let mut first_order = vec![vec![f64::NAN; d]; cols];
    let mut uncorrected = vec![vec![f64::NAN; d]; cols];
    for t in (0..cols).filter(|&t| !low[t]) {
        for i in 0..d {
            let b = ssb[i][t];
            let within = sst[t] - b;
            uncorrected[t][i] = b / sst[t];
            first_order[t][i] = (b - factor * within) / sst[t];
        }
    }
    let normalised_first_order_share = first_order
        .iter()
        .map(|row| {
            let sum: f64 = row.iter().map(|s| s.max(0.0)).sum();
            row.iter().map(|s| s.max(0.0) / sum).collect()
        })
        .collect();
    Ok(GivenDataIndices {
        parameters,
        low_variance_outputs: (0..cols)
            .filter(|&t| low[t])
            .map(|t| output_names[t].clone())
            .collect(),
        outputs: output_names,
        n,
        bins,
        first_order,
        first_order_uncorrected: uncorrected,
        normalised_first_order_share,
        variance: sst.iter().map(|s| s / n as f64).collect(),
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use impactcal_core::CoreError;

    /// Each bad option is refused by `ParamGuard::check_ref` with
    /// `CoreError::InvalidOption` naming it, and the analysis refuses it the same way.
    #[test]
    fn a_bad_value_is_refused_naming_its_key() {
        let base = GivenDataOptions::default();
        let cases = [
            (
                GivenDataOptions {
                    bins: Some(1),
                    ..base.clone()
                },
                "bins",
            ),
            (
                GivenDataOptions {
                    low_variance_tolerance: -1.0,
                    ..base.clone()
                },
                "low_variance_tolerance",
            ),
            (
                GivenDataOptions {
                    parameter_names: Some(vec!["a".into(), String::new()]),
                    ..base.clone()
                },
                "parameter_names",
            ),
            (
                GivenDataOptions {
                    output_names: Some(vec![" ".into()]),
                    ..base.clone()
                },
                "output_names",
            ),
        ];
        let x = faer::Mat::from_fn(64, 2, |i, j| ((i * 7 + j * 3) % 64) as f64 / 64.0);
        let y = faer::Mat::from_fn(64, 1, |i, _| x[(i, 0)] + 0.5 * x[(i, 1)]);
        for (o, key) in cases {
            match o.check_ref() {
                Err(CoreError::InvalidOption { name, .. }) => assert_eq!(name, key),
                other => panic!("{key}: {other:?}"),
            }
            match given_data_first_order(x.as_ref(), y.as_ref(), &o) {
                Err(SobolError::Core(CoreError::InvalidOption { name, .. })) => {
                    assert_eq!(name, key);
                }
                other => panic!("{key}: {other:?}"),
            }
        }
        assert!(given_data_first_order(x.as_ref(), y.as_ref(), &base).is_ok());
    }
}
