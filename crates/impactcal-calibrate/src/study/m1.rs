//! Calibration metric M1: can the parameter set explain the test at all?
//!
//! `Q(t, p) = ||v(t, p)||_2` over the chosen channels; the envelope
//! `sigma_lo(t) = min_p Q(t, p)`, `sigma_hi(t) = max_p Q(t, p)` over the `N` runs of the
//! ensemble; the test's `Q_e(t)`. The source paper's Eq. 4.1 bounds the probability that
//! the model reproduces a value outside the envelope by `1/N`: where `Q_e` leaves the
//! envelope, the chance of reconciling test and model with this parameter set is below
//! `1/N`, and the verdict is `cannot-explain`.

use serde::{Deserialize, Serialize};

use crate::error::{CalibrateError, Result};

/// Whether the parameter set can explain the test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    /// `Q_e` stays inside the envelope over the whole window.
    CanExplain,
    /// `Q_e` leaves the envelope somewhere: probability of reconciling below `1/N`.
    CannotExplain,
}

impl Verdict {
    /// `can-explain` or `cannot-explain`.
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::CanExplain => "can-explain",
            Verdict::CannotExplain => "cannot-explain",
        }
    }
}

/// The M1 result of one ensemble.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct M1 {
    /// Successful runs `N` the envelope is made of.
    pub n_runs: usize,
    /// Sample times.
    pub time: Vec<f64>,
    /// `min_p Q(t, p)`.
    pub lower: Vec<f64>,
    /// `max_p Q(t, p)`.
    pub upper: Vec<f64>,
    /// The test's `Q_e(t)`.
    pub test: Vec<f64>,
    /// Fraction of the samples at which `Q_e` lies outside `[lower, upper]`.
    pub exceedance_fraction: f64,
    /// Maximal runs of consecutive samples outside, `[first time, last time]`.
    pub intervals: Vec<[f64; 2]>,
    /// Largest distance of `Q_e` outside the envelope, relative to `max Q_e`.
    pub largest_exceedance: f64,
    /// The bound of Eq. 4.1, `1/N`.
    pub probability_bound: f64,
    /// The verdict.
    pub verdict: Verdict,
    /// Eq. 4.1 in words, with the numbers of this ensemble.
    pub statement: String,
}

/// M1 of the test's `q_test` (one value per sample at `time`) against the ensemble's
/// `q_runs` (one `Q(t)` per successful run, each as long as `time`).
///
/// # Errors
/// [`CalibrateError::Study`] for no runs or lengths that do not match.
pub fn m1(time: &[f64], q_runs: &[Vec<f64>], q_test: &[f64]) -> Result<M1> {
    let n = q_runs.len();
    if n == 0 {
        return Err(CalibrateError::study(
            "M1",
            "no successful run to build the envelope from",
        ));
    }
    if q_test.len() != time.len() || q_runs.iter().any(|q| q.len() != time.len()) {
        return Err(CalibrateError::study(
            "M1",
            "the test and every run need one Q value per sample",
        ));
    }
    let lower: Vec<f64> = (0..time.len())
        .map(|k| q_runs.iter().map(|q| q[k]).fold(f64::INFINITY, f64::min))
        .collect();
    let upper: Vec<f64> = (0..time.len())
        .map(|k| {
            q_runs
                .iter()
                .map(|q| q[k])
                .fold(f64::NEG_INFINITY, f64::max)
        })
        .collect();
    let outside: Vec<f64> = (0..time.len())
        .map(|k| (lower[k] - q_test[k]).max(q_test[k] - upper[k]).max(0.0))
        .collect();
    let count = outside.iter().filter(|&&o| o > 0.0).count();
    let mut intervals = Vec::new();
    let mut open: Option<usize> = None;
    for k in 0..=time.len() {
        let out = k < time.len() && outside[k] > 0.0;
        match (out, open) {
            (true, None) => open = Some(k),
            (false, Some(s)) => {
                intervals.push([time[s], time[k - 1]]);
                open = None;
            }
            _ => {}
        }
    }
    let peak = q_test.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let worst = outside.iter().fold(0.0_f64, |m, &v| m.max(v));
    let verdict = if count > 0 {
        Verdict::CannotExplain
    } else {
        Verdict::CanExplain
    };
    let bound = 1.0 / n as f64;
    let statement = match verdict {
        Verdict::CannotExplain => format!(
            "Q_e(t) leaves the envelope of {n} equally probable runs at {count} of {} samples \
             ({:.1} % of the time, in {} interval(s)); by Eq. 4.1 the probability of \
             reconciling test and model with this parameter set there is below 1/{n} = {bound:.4}",
            time.len(),
            100.0 * count as f64 / time.len() as f64,
            intervals.len()
        ),
        Verdict::CanExplain => format!(
            "Q_e(t) stays inside the envelope of {n} equally probable runs at every sample: \
             the parameter set leaves enough freedom to reconcile test and model (a value \
             outside would have probability below 1/{n} = {bound:.4})"
        ),
    };
    Ok(M1 {
        n_runs: n,
        time: time.to_vec(),
        lower,
        upper,
        test: q_test.to_vec(),
        exceedance_fraction: count as f64 / time.len() as f64,
        intervals,
        largest_exceedance: if peak > 0.0 { worst / peak } else { 0.0 },
        probability_bound: bound,
        verdict,
        statement,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn envelope_fraction_intervals_and_verdict_by_hand() {
        let time = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5];
        let runs = vec![
            vec![1.0, 2.0, 3.0, 3.0, 2.0, 1.0],
            vec![2.0, 3.0, 5.0, 4.0, 3.0, 2.0],
            vec![1.5, 2.5, 4.0, 3.5, 2.5, 1.5],
        ];
        let inside = [1.2, 2.9, 3.1, 3.9, 2.1, 1.9];
        let r = m1(&time, &runs, &inside).unwrap();
        assert_eq!(r.lower, vec![1.0, 2.0, 3.0, 3.0, 2.0, 1.0]);
        assert_eq!(r.upper, vec![2.0, 3.0, 5.0, 4.0, 3.0, 2.0]);
        assert_eq!(r.verdict, Verdict::CanExplain);
        assert!(r.exceedance_fraction.abs() < 1e-15);
        assert!(r.intervals.is_empty());
        assert!((r.probability_bound - 1.0 / 3.0).abs() < 1e-15);
        // Below at samples 1-2, above at sample 5.
        let out = [1.2, 1.5, 2.0, 3.9, 2.1, 2.5];
        let r = m1(&time, &runs, &out).unwrap();
        assert_eq!(r.verdict, Verdict::CannotExplain);
        assert!((r.exceedance_fraction - 0.5).abs() < 1e-15);
        assert_eq!(r.intervals, vec![[0.1, 0.2], [0.5, 0.5]]);
        // Largest distance: 1.0 below at sample 2, relative to max Q_e = 3.9.
        assert!((r.largest_exceedance - 1.0 / 3.9).abs() < 1e-12);
        assert!(m1(&time, &[], &out).is_err());
    }
}
