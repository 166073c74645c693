//! Point-by-point error measures: relative L2, RMS, peak value and time of peak.

use serde::Serialize;

use super::check_pair;
use crate::error::{CalibrateError, Result};

/// Error measures that compare the curves sample by sample, with `m` measured and `c`
/// computed on the same uniform times `t_k = start + k dt`:
///
/// - relative L2 error `||c - m||_2 / ||m||_2`;
/// - RMS error `sqrt(mean((c - m)^2))`, in the curves' unit;
/// - peak value error `(max|c| - max|m|) / max|m|`, signed (negative when the model peaks
///   lower);
/// - time-of-peak error `t(argmax|c|) - t(argmax|m|)`, signed (positive when the model peaks
///   later); the first sample reaching the maximum counts.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PointwiseErrors {
    /// `||c - m|| / ||m||`.
    pub rel_l2: f64,
    /// Root mean square of `c - m`.
    pub rms: f64,
    /// Relative error of the largest absolute value.
    pub peak_error: f64,
    /// Difference of the times of the largest absolute values.
    pub time_of_peak_error: f64,
}

impl PointwiseErrors {
    /// The measures of `computed` against `measured`, both sampled every `dt`.
    ///
    /// # Errors
    /// [`CalibrateError::Length`] for curves of different lengths or fewer than two samples;
    /// [`CalibrateError::Degenerate`] for a measured curve that is identically zero.
    pub fn between(measured: &[f64], computed: &[f64], dt: f64) -> Result<PointwiseErrors> {
        check_pair(measured, computed, 2, "pointwise errors")?;
        let (mut diff, mut norm) = (0.0, 0.0);
        for (m, c) in measured.iter().zip(computed) {
            diff += (c - m) * (c - m);
            norm += m * m;
        }
        if norm == 0.0 {
            return Err(CalibrateError::Degenerate {
                what: "pointwise errors".into(),
                reason: "the measured curve is identically zero".into(),
            });
        }
        let (km, pm) = peak(measured);
        let (kc, pc) = peak(computed);
        Ok(PointwiseErrors {
            rel_l2: (diff / norm).sqrt(),
            rms: (diff / measured.len() as f64).sqrt(),
            peak_error: (pc - pm) / pm,
            time_of_peak_error: (kc as f64 - km as f64) * dt,
        })
    }
}

/// Index and value of the first largest absolute value.
fn peak(v: &[f64]) -> (usize, f64) {
    v.iter().enumerate().fold(
        (0, 0.0),
        |(k, p), (i, x)| if x.abs() > p { (i, x.abs()) } else { (k, p) },
    )
}

#[cfg(test)]
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn values_on_a_small_case() {
        let m = [0.0, 1.0, -4.0, 2.0];
        let c = [0.0, 2.0, -3.0, 5.0];
        let e = PointwiseErrors::between(&m, &c, 0.5).unwrap();
        assert_relative_eq!(e.rel_l2, (11.0f64 / 21.0).sqrt());
        assert_relative_eq!(e.rms, (11.0f64 / 4.0).sqrt());
        assert_relative_eq!(e.peak_error, 0.25);
        assert_relative_eq!(e.time_of_peak_error, 0.5);
        assert!(PointwiseErrors::between(&[0.0; 4], &c, 0.5).is_err());
    }
}
