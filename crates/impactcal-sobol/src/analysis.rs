//! Sobol' indices of every output column of a Saltelli design, in one pass.

use faer::MatRef;
use rand::Rng;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;

use crate::accumulate::{self, Plan, Weights};
use crate::design::DesignLayout;
use crate::error::{Result, SobolError};
use crate::estimators::{
    FirstOrderEstimator, ParamMoments, SharedMoments, TotalEstimator, first_order,
    needs_full_moments, total,
};
use crate::stats::{percentile_sorted, sample_sd};
use impactcal_core::ParamGuard;
use impactcal_core::error::{dimension_mismatch, invalid_option};

/// How to estimate: estimators, bootstrap, the low-variance threshold and names.
#[derive(Debug, Clone, PartialEq)]
pub struct SobolOptions {
    /// First-order estimator (default Saltelli 2010).
    pub first_order: FirstOrderEstimator,
    /// Total-index estimator (default Jansen 1999).
    pub total: TotalEstimator,
    /// Bootstrap resamples of the base rows; 0 for none (default 0). The same resamples are
    /// used for every parameter, pair and output column.
    pub bootstrap: usize,
    /// Level of the bootstrap percentile intervals, in (0, 1) (default 0.95).
    pub confidence: f64,
    /// Seed of the bootstrap resampling.
    pub seed: u64,
    /// A column whose output variance `V(t)` is at most this fraction of its own mean
    /// square `mean(y(t)^2)` (or is zero) is flagged as low-variance; its indices are NaN
    /// (`null` in JSON) and it is left out of the aggregated indices (default 1e-10).
    ///
    /// The criterion is the column's own: `V / mean(y^2) = cv^2 / (1 + cv^2)` carries no
    /// unit, so columns in different units (a velocity of 1 beside an energy of 1e13) are
    /// judged alike, and a constant column is flagged whatever its size. `1e-10` is a
    /// spread below 1e-5 of the values' size: outputs of crash solvers are written in
    /// single precision (`eps = 1.2e-7`), whose rounding then makes up a few tenths of a
    /// percent of the spread's standard deviation, and smaller spreads are soon mostly
    /// rounding.
    pub low_variance_tolerance: f64,
    /// Parameter names (default `x1, x2, ...`).
    pub parameter_names: Option<Vec<String>>,
    /// Output column names (default `y1, y2, ...`).
    pub output_names: Option<Vec<String>>,
}

impl Default for SobolOptions {
    fn default() -> Self {
        SobolOptions {
            first_order: FirstOrderEstimator::default(),
            total: TotalEstimator::default(),
            bootstrap: 0,
            confidence: 0.95,
            seed: 0,
            low_variance_tolerance: 1e-10,
            parameter_names: None,
            output_names: None,
        }
    }
}

impl ParamGuard for SobolOptions {
    /// The options themselves: the names are checked against the design and the outputs
    /// when the indices are computed.
    type Checked = SobolOptions;

    /// Checks the confidence level in (0, 1), a bootstrap of 0 or at least 2 resamples and
    /// a finite non-negative low-variance tolerance.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) naming the
    /// option.
    fn check_ref(&self) -> impactcal_core::Result<()> {
        if !(self.confidence > 0.0 && self.confidence < 1.0) {
            return Err(invalid_option(
                "confidence",
                self.confidence,
                "the confidence level must lie in (0, 1)",
            ));
        }
        if self.bootstrap == 1 {
            return Err(invalid_option(
                "bootstrap",
                self.bootstrap,
                "a bootstrap needs at least 2 resamples (or 0 for none)",
            ));
        }
        if !(self.low_variance_tolerance >= 0.0 && self.low_variance_tolerance.is_finite()) {
            return Err(invalid_option(
                "low_variance_tolerance",
                self.low_variance_tolerance,
                "the low-variance tolerance must be finite and non-negative",
            ));
        }
        Ok(())
    }

    fn check(self) -> impactcal_core::Result<SobolOptions> {
        self.check_ref()?;
        Ok(self)
    }
}

/// Bootstrap settings as reported.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BootstrapInfo {
    /// Number of resamples.
    pub resamples: usize,
    /// Interval level.
    pub confidence: f64,
    /// Seed.
    pub seed: u64,
}

/// Aggregated indices over all output columns (Gamboa, Janon, Klein & Lagnoux 2014): for
/// each parameter `sum_t V_i(t) / sum_t V(t)`, the sum of the partial variances over the sum
/// of the variances (each estimator's numerator over its denominator), columns flagged as
/// low-variance left out. Columns with large variance weigh more; standardise the columns
/// first if every time step should count equally.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AggregatedIndices {
    /// Aggregated first-order index per parameter.
    pub first_order: Vec<f64>,
    /// Aggregated total index per parameter.
    pub total: Vec<f64>,
    /// Bootstrap percentile intervals `[lo, hi]` of the above, when bootstrapped.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_order_ci: Option<Vec<[f64; 2]>>,
    /// As `first_order_ci`, for the total index.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub total_ci: Option<Vec<[f64; 2]>>,
}

/// The estimated indices. Arrays over outputs hold one entry per output column; inside,
/// one entry per parameter (or a `d x d` matrix for second order). NaN (written `null` in
/// JSON) marks the columns listed in `low_variance_outputs` and the diagonal of the
/// second-order matrices.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SobolIndices {
    /// Parameter names.
    pub parameters: Vec<String>,
    /// Output column names.
    pub outputs: Vec<String>,
    /// Base rows `N`.
    pub n: usize,
    /// Estimators used.
    pub first_order_estimator: FirstOrderEstimator,
    /// Estimator of the total index.
    pub total_estimator: TotalEstimator,
    /// `first_order[t][i]`: first-order index of parameter `i` on output `t`.
    pub first_order: Vec<Vec<f64>>,
    /// `total[t][i]`: total index.
    pub total: Vec<Vec<f64>>,
    /// `first_order_ci[t][i] = [lo, hi]`: bootstrap percentile interval.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_order_ci: Option<Vec<Vec<[f64; 2]>>>,
    /// Bootstrap intervals of the total index.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub total_ci: Option<Vec<Vec<[f64; 2]>>>,
    /// Bootstrap standard errors of the first-order index (SALib's `S1_conf` is
    /// `z_(1+c)/2` times this).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_order_se: Option<Vec<Vec<f64>>>,
    /// Bootstrap standard errors of the total index.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub total_se: Option<Vec<Vec<f64>>>,
    /// `second_order[t][i][k]`: closed second-order index `S_ik` (Saltelli 2002, as SALib:
    /// `mean(f(BA_i) f(AB_k) - f(A) f(B)) / V - S_i - S_k`), symmetric, NaN on the diagonal.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub second_order: Option<Vec<Vec<Vec<f64>>>>,
    /// Bootstrap intervals of the second-order indices (`[NaN, NaN]` on the diagonal).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub second_order_ci: Option<Vec<Vec<Vec<[f64; 2]>>>>,
    /// `variance[t]`: the output variance `V(t)` (pooled `A` and `B` rows, divisor `2N`).
    pub variance: Vec<f64>,
    /// `normalised_first_order_share[t][i] = max(S_i, 0) / sum_j max(S_j, 0)`: each
    /// parameter's share of the sum of first-order effects, which sums to 1 by construction
    /// (the quantity the source paper plots). It equals `S_i` only for additive outputs; NaN
    /// where no parameter has a positive first-order index.
    pub normalised_first_order_share: Vec<Vec<f64>>,
    /// `interaction_share[t] = 1 - sum_i S_i(t)`: the variance share of interactions.
    pub interaction_share: Vec<f64>,
    /// Aggregated indices over the columns.
    pub aggregated: AggregatedIndices,
    /// Names of the columns whose output variance is at most the low-variance tolerance times
    /// their own mean square (see [`SobolOptions::low_variance_tolerance`]).
    pub low_variance_outputs: Vec<String>,
    /// Bootstrap settings, when bootstrapped.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bootstrap: Option<BootstrapInfo>,
}

/// Per-resample estimates, `[g][t][i]` flattened.
struct Estimates {
    t: usize,
    d: usize,
    pairs: usize,
    first_num: Vec<f64>,
    first_den: Vec<f64>,
    total_num: Vec<f64>,
    total_den: Vec<f64>,
    second: Vec<f64>,
    variance: Vec<f64>,
    /// `mean(y^2)` of the pooled `A` and `B` rows (the outputs as given, not centred), per
    /// column (the full sample only).
    mean_square: Vec<f64>,
}

impl Estimates {
    fn at(&self, g: usize, t: usize, i: usize) -> usize {
        (g * self.t + t) * self.d + i
    }
    fn first(&self, g: usize, t: usize, i: usize) -> f64 {
        let k = self.at(g, t, i);
        self.first_num[k] / self.first_den[k]
    }
    fn total(&self, g: usize, t: usize, i: usize) -> f64 {
        let k = self.at(g, t, i);
        self.total_num[k] / self.total_den[k]
    }
    fn second(&self, g: usize, t: usize, p: usize) -> f64 {
        self.second[(g * self.t + t) * self.pairs + p]
    }
}

fn validate(layout: &DesignLayout, outputs: MatRef<'_, f64>, o: &SobolOptions) -> Result<()> {
    if outputs.nrows() != layout.rows() {
        return Err(SobolError::RowCount {
            rows: outputs.nrows(),
            d: layout.d(),
            detail: format!(
                "the design has {} rows ({} base rows x {}); the outputs have {}",
                layout.rows(),
                layout.n(),
                layout.stride(),
                outputs.nrows()
            ),
        });
    }
    if outputs.ncols() == 0 {
        return Err(dimension_mismatch("output columns, at least", 1, 0));
    }
    o.check_ref()?;
    if let Some(names) = &o.parameter_names
        && names.len() != layout.d()
    {
        return Err(dimension_mismatch(
            "number of parameter names",
            layout.d(),
            names.len(),
        ));
    }
    if let Some(names) = &o.output_names
        && names.len() != outputs.ncols()
    {
        return Err(dimension_mismatch(
            "number of output names",
            outputs.ncols(),
            names.len(),
        ));
    }
    Ok(())
}

/// Column means over all rows (the centring of SALib), checking that every value is finite.
/// Rows are summed in order within chunks of [`CHUNK`] rows, and the chunk sums in order, so
/// the result does not depend on the number of threads.
fn column_means(outputs: MatRef<'_, f64>) -> Result<Vec<f64>> {
    const CHUNK: usize = 2048;
    let cols = outputs.ncols();
    let rows = outputs.nrows();
    let partial: Vec<std::result::Result<Vec<f64>, SobolError>> = (0..rows.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut sums = vec![0.0; cols];
            for r in c * CHUNK..rows.min((c + 1) * CHUNK) {
                let row = outputs.row(r);
                for (t, (s, &v)) in sums.iter_mut().zip(row.iter()).enumerate() {
                    if !v.is_finite() {
                        return Err(non_finite_output(r, t, v));
                    }
                    *s += v;
                }
            }
            Ok(sums)
        })
        .collect();
    let mut means = vec![0.0; cols];
    for p in partial {
        for (m, s) in means.iter_mut().zip(p?) {
            *m += s;
        }
    }
    let rows = rows as f64;
    means.iter_mut().for_each(|m| *m /= rows);
    Ok(means)
}

/// The error of a NaN or infinite model output at `row`, `column` (0-based).
pub(crate) fn non_finite_output(row: usize, column: usize, value: f64) -> SobolError {
    impactcal_core::CoreError::NonFinite {
        what: "model outputs".into(),
        location: format!("row {row}, column {column} (0-based)"),
        value,
    }
    .into()
}

/// Multinomial resampling counts of the base rows, resample `g` from its own ChaCha8
/// stream, so each resample is fixed by the seed alone.
fn resample_weights(n: usize, resamples: usize, seed: u64) -> Weights {
    let groups = resamples + 1;
    let counts: Vec<Vec<u16>> = (0..resamples)
        .into_par_iter()
        .map(|g| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            rng.set_stream(g as u64 + 1);
            let mut c = vec![0u16; n];
            for _ in 0..n {
                let k = rng.random_range(0..n);
                c[k] = c[k].saturating_add(1);
            }
            c
        })
        .collect();
    let mut data = vec![0u16; n * groups];
    for j in 0..n {
        data[j * groups] = 1;
        for (g, c) in counts.iter().enumerate() {
            data[j * groups + g + 1] = c[j];
        }
    }
    Weights { groups, data }
}

/// Estimates first-order, total and (when the layout has them) second-order Sobol' indices
/// of every output column, with bootstrap intervals when `options.bootstrap > 0`.
///
/// `outputs` is `layout.rows() x T`: one row per model run, in the design's row order, one
/// column per output (a time step, a channel, a scalar metric). Any faer view is accepted;
/// a row-major one (for example `MatRef::from_row_major_slice` over a CSV's rows) is read in
/// place, and so is a single column (`ColRef::from_slice(&y).as_mat()`).
///
/// The outputs are centred by their column means over all rows first (as SALib does; the
/// estimators that multiply outputs are otherwise sensitive to large offsets). One pass over
/// the data accumulates, per column and parameter, the sums that every estimator needs; the
/// bootstrap resamples reuse the same pass with multinomial row weights, the same resample
/// for every parameter, pair and column, so intervals are coherent across time. The cost is
/// `O(N T (d + P) (B + 1))` for `P` parameter pairs, and the memory beyond the outputs is
/// `O((B + 1) T (d + P))`; the outputs are never copied.
///
/// # Errors
/// [`SobolError::RowCount`] when the outputs do not have `layout.rows()` rows; and, under
/// [`SobolError::Core`]: [`CoreError::NonFinite`](impactcal_core::CoreError::NonFinite) for
/// NaN or infinite outputs (the first in row order, naming row and column),
/// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) for a confidence
/// outside (0, 1), one bootstrap resample, or a negative tolerance,
/// [`CoreError::DimensionMismatch`](impactcal_core::CoreError::DimensionMismatch) for no
/// output column or name lists of the wrong length.
pub fn analyze(
    layout: &DesignLayout,
    outputs: MatRef<'_, f64>,
    options: &SobolOptions,
) -> Result<SobolIndices> {
    validate(layout, outputs, options)?;
    let (d, n, cols) = (layout.d(), layout.n(), outputs.ncols());
    let centre = column_means(outputs)?;
    let pairs: Vec<(usize, usize)> = if layout.second_order() {
        (0..d)
            .flat_map(|i| (i + 1..d).map(move |k| (i, k)))
            .collect()
    } else {
        Vec::new()
    };
    let plan = Plan {
        layout: *layout,
        full: needs_full_moments(options.first_order, options.total),
        pairs,
    };
    let weights = resample_weights(n, options.bootstrap, options.seed);
    let items = accumulate::accumulate(&plan, outputs, &centre, &weights);
    let est = estimates_from_sums(&plan, options, &items, weights.groups, cols, &centre);
    Ok(assemble(&plan, options, &est, cols))
}

fn estimates_from_sums(
    plan: &Plan,
    options: &SobolOptions,
    items: &[accumulate::ItemSums],
    groups: usize,
    cols: usize,
    centre: &[f64],
) -> Estimates {
    let d = plan.layout.d();
    let np = plan.pairs.len();
    let inv_n = 1.0 / plan.layout.n() as f64;
    let size = groups * cols * d;
    let mut e = Estimates {
        t: cols,
        d,
        pairs: np,
        first_num: vec![0.0; size],
        first_den: vec![0.0; size],
        total_num: vec![0.0; size],
        total_den: vec![0.0; size],
        second: vec![0.0; groups * cols * np],
        variance: vec![0.0; groups * cols],
        mean_square: vec![0.0; cols],
    };
    let k_terms = plan.terms();
    let mut s_first = vec![0.0; d];
    for item in items {
        let w = item.width;
        for (gl, g) in item.groups.clone().enumerate() {
            let acc = &item.acc[gl * k_terms * w..(gl + 1) * k_terms * w];
            for tl in 0..w {
                let t = item.tile_start + tl;
                let m = |k: usize| acc[k * w + tl] * inv_n;
                let shared = SharedMoments {
                    ma: m(0),
                    mb: m(1),
                    qa: m(2),
                    qb: m(3),
                    pab: m(4),
                };
                let v = shared.variance();
                e.variance[g * cols + t] = v;
                if g == 0 {
                    // The moments are of the centred outputs `y - c`: mean(y^2) is
                    // mean((y - c)^2) + 2 c mean(y - c) + c^2.
                    let c = centre[t];
                    e.mean_square[t] =
                        0.5 * (shared.qa + shared.qb) + c * (shared.ma + shared.mb) + c * c;
                }
                for (i, s) in s_first.iter_mut().enumerate() {
                    let o = plan.param_offset(i);
                    let p = if plan.full {
                        ParamMoments {
                            e1: m(o),
                            e2: m(o + 1),
                            e3: m(o + 2),
                            mx: m(o + 3),
                            qx: m(o + 4),
                        }
                    } else {
                        ParamMoments {
                            e1: m(o),
                            e2: m(o + 1),
                            e3: f64::NAN,
                            mx: f64::NAN,
                            qx: f64::NAN,
                        }
                    };
                    let k = e.at(g, t, i);
                    let (fnum, fden) = first_order(options.first_order, &shared, &p);
                    let (tnum, tden) = total(options.total, &shared, &p);
                    e.first_num[k] = fnum;
                    e.first_den[k] = fden;
                    e.total_num[k] = tnum;
                    e.total_den[k] = tden;
                    *s = fnum / fden;
                }
                for (p, &(i, k)) in plan.pairs.iter().enumerate() {
                    let closed = (m(plan.pair_offset(p)) - shared.pab) / v;
                    e.second[(g * cols + t) * np + p] = closed - s_first[i] - s_first[k];
                }
            }
        }
    }
    e
}

/// Percentile interval and standard error of `values` (NaNs dropped).
fn interval(values: &mut Vec<f64>, confidence: f64) -> ([f64; 2], f64) {
    values.retain(|v| v.is_finite());
    if values.len() < 2 {
        return ([f64::NAN, f64::NAN], f64::NAN);
    }
    let se = sample_sd(values);
    values.sort_by(f64::total_cmp);
    let alpha = 0.5 * (1.0 - confidence);
    (
        [
            percentile_sorted(values, alpha),
            percentile_sorted(values, 1.0 - alpha),
        ],
        se,
    )
}

fn names(given: &Option<Vec<String>>, prefix: &str, count: usize) -> Vec<String> {
    given
        .clone()
        .unwrap_or_else(|| (1..=count).map(|k| format!("{prefix}{k}")).collect())
}

fn assemble(plan: &Plan, options: &SobolOptions, e: &Estimates, cols: usize) -> SobolIndices {
    let d = plan.layout.d();
    let resamples = options.bootstrap;
    let output_names = names(&options.output_names, "y", cols);
    let low: Vec<bool> = (0..cols)
        .map(|t| {
            let v = e.variance[t];
            !(v > 0.0 && v > options.low_variance_tolerance * e.mean_square[t])
        })
        .collect();
    let mask = |t: usize, x: f64| if low[t] { f64::NAN } else { x };
    let per_column = |f: &dyn Fn(usize, usize) -> f64| -> Vec<Vec<f64>> {
        (0..cols)
            .map(|t| (0..d).map(|i| mask(t, f(t, i))).collect())
            .collect()
    };
    let first_order = per_column(&|t, i| e.first(0, t, i));
    let total = per_column(&|t, i| e.total(0, t, i));

    let ci =
        |f: &(dyn Fn(usize, usize, usize) -> f64 + Sync)| -> (Vec<Vec<[f64; 2]>>, Vec<Vec<f64>>) {
            let cells: Vec<([f64; 2], f64)> = (0..cols * d)
                .into_par_iter()
                .map(|c| {
                    let (t, i) = (c / d, c % d);
                    if low[t] {
                        return ([f64::NAN, f64::NAN], f64::NAN);
                    }
                    let mut v: Vec<f64> = (1..=resamples).map(|g| f(g, t, i)).collect();
                    interval(&mut v, options.confidence)
                })
                .collect();
            let lo_hi = cells
                .chunks(d)
                .map(|r| r.iter().map(|c| c.0).collect())
                .collect();
            let se = cells
                .chunks(d)
                .map(|r| r.iter().map(|c| c.1).collect())
                .collect();
            (lo_hi, se)
        };
    let (first_order_ci, first_order_se, total_ci, total_se) = if resamples > 0 {
        let (fc, fs) = ci(&|g, t, i| e.first(g, t, i));
        let (tc, ts) = ci(&|g, t, i| e.total(g, t, i));
        (Some(fc), Some(fs), Some(tc), Some(ts))
    } else {
        (None, None, None, None)
    };

    let (second_order, second_order_ci) = if plan.layout.second_order() {
        let matrix = |value: &dyn Fn(usize, usize) -> f64| -> Vec<Vec<Vec<f64>>> {
            (0..cols)
                .map(|t| {
                    let mut m = vec![vec![f64::NAN; d]; d];
                    for (p, &(i, k)) in plan.pairs.iter().enumerate() {
                        let x = mask(t, value(t, p));
                        m[i][k] = x;
                        m[k][i] = x;
                    }
                    m
                })
                .collect()
        };
        let point = matrix(&|t, p| e.second(0, t, p));
        let intervals = (resamples > 0).then(|| {
            (0..cols)
                .map(|t| {
                    let mut m = vec![vec![[f64::NAN; 2]; d]; d];
                    if !low[t] {
                        for (p, &(i, k)) in plan.pairs.iter().enumerate() {
                            let mut v: Vec<f64> =
                                (1..=resamples).map(|g| e.second(g, t, p)).collect();
                            let (c, _) = interval(&mut v, options.confidence);
                            m[i][k] = c;
                            m[k][i] = c;
                        }
                    }
                    m
                })
                .collect()
        });
        (Some(point), intervals)
    } else {
        (None, None)
    };

    let aggregate = |g: usize| -> (Vec<f64>, Vec<f64>) {
        let mut sums = vec![0.0; 4 * d];
        for t in (0..cols).filter(|&t| !low[t]) {
            for i in 0..d {
                let k = e.at(g, t, i);
                sums[i] += e.first_num[k];
                sums[d + i] += e.first_den[k];
                sums[2 * d + i] += e.total_num[k];
                sums[3 * d + i] += e.total_den[k];
            }
        }
        (
            (0..d).map(|i| sums[i] / sums[d + i]).collect(),
            (0..d).map(|i| sums[2 * d + i] / sums[3 * d + i]).collect(),
        )
    };
    let (agg_first, agg_total) = aggregate(0);
    let (agg_first_ci, agg_total_ci) = if resamples > 0 {
        let reps: Vec<(Vec<f64>, Vec<f64>)> = (1..=resamples).map(aggregate).collect();
        let column = |which: usize| -> Vec<[f64; 2]> {
            (0..d)
                .map(|i| {
                    let mut v: Vec<f64> = reps
                        .iter()
                        .map(|r| if which == 0 { r.0[i] } else { r.1[i] })
                        .collect();
                    interval(&mut v, options.confidence).0
                })
                .collect()
        };
        (Some(column(0)), Some(column(1)))
    } else {
        (None, None)
    };

    let normalised_first_order_share = first_order
        .iter()
        .map(|row| {
            let sum: f64 = row.iter().map(|s| s.max(0.0)).sum();
            row.iter().map(|s| s.max(0.0) / sum).collect()
        })
        .collect();
    let interaction_share = first_order
        .iter()
        .map(|row| 1.0 - row.iter().sum::<f64>())
        .collect();
    SobolIndices {
        parameters: names(&options.parameter_names, "x", d),
        low_variance_outputs: (0..cols)
            .filter(|&t| low[t])
            .map(|t| output_names[t].clone())
            .collect(),
        outputs: output_names,
        n: plan.layout.n(),
        first_order_estimator: options.first_order,
        total_estimator: options.total,
        first_order,
        total,
        first_order_ci,
        total_ci,
        first_order_se,
        total_se,
        second_order,
        second_order_ci,
        variance: e.variance[..cols].to_vec(),
        normalised_first_order_share,
        interaction_share,
        aggregated: AggregatedIndices {
            first_order: agg_first,
            total: agg_total,
            first_order_ci: agg_first_ci,
            total_ci: agg_total_ci,
        },
        bootstrap: (resamples > 0).then_some(BootstrapInfo {
            resamples,
            confidence: options.confidence,
            seed: options.seed,
        }),
    }
}
