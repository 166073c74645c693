//! Leave-one-out cross-validation: methods and summaries.

use faer::MatRef;
use serde::{Deserialize, Serialize};

/// How leave-one-out (LOO) errors are computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum LooMethod {
    /// The model's closed form: exact for classic RBF interpolants (Rippa's identity);
    /// for ERBF the kernel-view approximation, which keeps the removed sample's basis
    /// functions in the model.
    Closed,
    /// Exact: refit without each sample in turn (parallel over samples).
    Refit,
    /// The exact method that is affordable: `Closed` for classic RBF, `Refit` for ERBF up
    /// to 200 samples and `Closed` above.
    #[default]
    Auto,
}

/// Summary of an `N x T` matrix of errors against the training values `F` (`N x T`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ErrorSummary {
    /// Root mean square of all errors.
    pub rms: f64,
    /// Largest error magnitude.
    pub max_abs: f64,
    /// `rms` divided by the standard deviation of all entries of `F` (pooled over samples
    /// and outputs); `NaN` when that deviation is 0.
    pub relative_rms: f64,
}

impl ErrorSummary {
    /// Summarises `errors` against `values` of the same shape.
    pub fn new(errors: MatRef<'_, f64>, values: MatRef<'_, f64>) -> Self {
        let mut sum2 = 0.0;
        let mut max_abs = 0.0_f64;
        let mut count = 0usize;
        for j in 0..errors.ncols() {
            for i in 0..errors.nrows() {
                let e = errors[(i, j)];
                sum2 += e * e;
                max_abs = max_abs.max(e.abs());
                count += 1;
            }
        }
        let rms = if count > 0 {
            (sum2 / count as f64).sqrt()
        } else {
            0.0
        };
        let std = crate::metrics::pooled_std(values);
        ErrorSummary {
            rms,
            max_abs,
            relative_rms: if std > 0.0 { rms / std } else { f64::NAN },
        }
    }
}
