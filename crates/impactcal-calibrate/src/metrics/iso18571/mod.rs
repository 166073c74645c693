//! ISO/TS 18571 objective rating of a computed curve against a reference curve.

mod dtw;
mod phase;
mod slope;

use serde::Serialize;

use super::check_pair;
use impactcal_core::error::invalid_option;

use crate::error::{CalibrateError, Result};

/// The verbal grade of an ISO/TS 18571 rating `R`: excellent above 0.94, good above 0.8, fair
/// above 0.58, poor otherwise.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Grade {
    /// `R <= 0.58`.
    Poor,
    /// `0.58 < R <= 0.8`.
    Fair,
    /// `0.8 < R <= 0.94`.
    Good,
    /// `R > 0.94`.
    Excellent,
}

impl Grade {
    /// The grade of rating `r`.
    pub fn of(r: f64) -> Grade {
        if r > 0.94 {
            Grade::Excellent
        } else if r > 0.8 {
            Grade::Good
        } else if r > 0.58 {
            Grade::Fair
        } else {
            Grade::Poor
        }
    }
}

impl std::fmt::Display for Grade {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Grade::Poor => "poor",
            Grade::Fair => "fair",
            Grade::Good => "good",
            Grade::Excellent => "excellent",
        })
    }
}

/// The result of [`Iso18571::rate`]: the overall rating `R` and its four scores, each in
/// `[0, 1]` with 1 for a perfect match.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Iso18571Rating {
    /// Overall rating `R = w_Z Z + w_P E_P + w_M E_M + w_S E_S`.
    pub r: f64,
    /// Corridor score `Z`.
    pub corridor: f64,
    /// Phase score `E_P`.
    pub phase: f64,
    /// Magnitude score `E_M`.
    pub magnitude: f64,
    /// Slope score `E_S`.
    pub slope: f64,
    /// The grade of `r`.
    pub grade: Grade,
    /// The phase shift found, in samples of the rated (10 kHz) grid: positive when the
    /// computed curve lags the reference.
    pub shift_samples: isize,
    /// The same shift in time units.
    pub time_shift: f64,
    /// The magnitude error `epsilon_mag` after phase shift and time warping.
    pub magnitude_error: f64,
    /// The slope error `epsilon_slope` of the phase-shifted derivatives.
    pub slope_error: f64,
}

/// The ISO/TS 18571 objective rating metric for non-ambiguous signals, with its constants.
///
/// For a reference `T` (the test) and a computed curve `C` on the same times:
///
/// - **Corridor** `Z`: around `T` an inner corridor of half-width `a_0 max|T|` and an outer one
///   of half-width `b_0 max|T|`; a point inside the inner scores 1, outside the outer 0, in
///   between `((delta_o - |C - T|) / (delta_o - delta_i))^k_z`; `Z` is the mean score.
/// - **Phase** `E_P`: `C` is shifted against `T` by up to `(1 - init_min) N` samples (the two
///   keep at least `init_min` of their length in common) to the shift `n_eps` that maximises
///   the Pearson correlation of the overlapping parts (smallest shift on ties, left before
///   right); `E_P = ((eps_P N - |n_eps|) / (eps_P N))^k_p` with `eps_P = 1 - init_min`, 1 without
///   shift and 0 at or beyond the limit.
/// - **Magnitude** `E_M`: the shifted curves are aligned by dynamic time warping (squared
///   differences, Sakoe-Chiba band of `ceil(0.1 n) - 1` samples) and
///   `eps_mag = ||C_w - T_w||_1 / ||T_w||_1`; `E_M = ((eps_M - eps_mag) / eps_M)^k_m`, 0 above
///   `eps_M`.
/// - **Slope** `E_S`: the derivatives of the shifted curves (central differences, 9-point moving
///   average) give `eps_slope = ||C' - T'||_1 / ||T'||_1`; `E_S = (e_S - eps_slope) / e_S`,
///   0 above `e_S`.
/// - `R = 0.4 Z + 0.2 E_P + 0.2 E_M + 0.2 E_S` with the default weights.
///
/// The standard asks for curves sampled at 10 kHz (its shifts, band and derivatives count
/// samples); curves on another step are first interpolated linearly onto a 10 kHz grid over
/// the same time span. The defaults are the standard's: `k_z = 2`, `k_p = k_m = 1`,
/// `eps_M = 0.5`, `e_S = 2`, `init_min = 0.8`, `a_0 = 0.05`, `b_0 = 0.5`, weights
/// `0.4, 0.2, 0.2, 0.2`. The computation follows objective-rating-metrics 1.3 (the
/// implementation pyisomme calls) step for step and agrees with it to 1e-12 on the validation
/// set (`docs/validation.md`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Iso18571 {
    a0: f64,
    b0: f64,
    kz: i32,
    kp: i32,
    km: i32,
    eps_m: f64,
    e_s: f64,
    init_min: f64,
    weights: [f64; 4],
    rate_dt: Option<f64>,
}

impl Default for Iso18571 {
    fn default() -> Self {
        Iso18571 {
            a0: 0.05,
            b0: 0.5,
            kz: 2,
            kp: 1,
            km: 1,
            eps_m: 0.5,
            e_s: 2.0,
            init_min: 0.8,
            weights: [0.4, 0.2, 0.2, 0.2],
            rate_dt: Some(1e-4),
        }
    }
}

/// Sampling interval the standard rates at (10 kHz).
pub const ISO18571_DT: f64 = 1e-4;

/// Fewest samples a rating needs: the shifted curves must keep 9 samples for the slope's
/// moving average.
const MIN_SAMPLES: usize = 12;

impl Iso18571 {
    /// The standard's constants.
    pub fn new() -> Iso18571 {
        Iso18571::default()
    }

    /// Relative half-widths `a_0 < b_0` of the inner and outer corridors.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) unless `0 <= a_0 < b_0`, both finite.
    pub fn corridors(mut self, a0: f64, b0: f64) -> Result<Self> {
        if !(a0.is_finite() && b0.is_finite() && 0.0 <= a0 && a0 < b0) {
            return Err(invalid_option(
                "ISO 18571 corridors (a_0, b_0)",
                format!("({a0}, {b0})"),
                "need 0 <= a_0 < b_0, both finite",
            ));
        }
        self.a0 = a0;
        self.b0 = b0;
        Ok(self)
    }

    /// Exponents `k_z`, `k_p`, `k_m` of the corridor, phase and magnitude scores.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) for an exponent outside 1..=3 (the standard's range).
    pub fn exponents(mut self, kz: i32, kp: i32, km: i32) -> Result<Self> {
        if ![kz, kp, km].iter().all(|k| (1..=3).contains(k)) {
            return Err(invalid_option(
                "ISO 18571 exponents (k_z, k_p, k_m)",
                format!("({kz}, {kp}, {km})"),
                "each must be 1, 2 or 3",
            ));
        }
        (self.kz, self.kp, self.km) = (kz, kp, km);
        Ok(self)
    }

    /// Error limits `eps_M` of the magnitude and `e_S` of the slope score.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) unless both are finite and positive.
    pub fn limits(mut self, eps_m: f64, e_s: f64) -> Result<Self> {
        if !(eps_m.is_finite() && e_s.is_finite() && eps_m > 0.0 && e_s > 0.0) {
            return Err(invalid_option(
                "ISO 18571 limits (eps_M, e_S)",
                format!("({eps_m}, {e_s})"),
                "both must be finite and positive",
            ));
        }
        (self.eps_m, self.e_s) = (eps_m, e_s);
        Ok(self)
    }

    /// Least overlap `init_min` kept by the phase search (the largest shift is
    /// `1 - init_min` of the length, rounded to two decimals).
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) unless `0.5 <= init_min < 1`.
    pub fn min_overlap(mut self, init_min: f64) -> Result<Self> {
        if !(0.5..1.0).contains(&init_min) {
            return Err(invalid_option(
                "ISO 18571 init_min",
                init_min,
                "must lie in [0.5, 1)",
            ));
        }
        self.init_min = init_min;
        Ok(self)
    }

    /// Weights of corridor, phase, magnitude and slope scores.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) for a negative weight or weights not summing to 1.
    pub fn weights(mut self, weights: [f64; 4]) -> Result<Self> {
        let sum: f64 = weights.iter().sum();
        if weights.iter().any(|w| w.is_nan() || *w < 0.0) || (sum - 1.0).abs() > 1e-12 {
            return Err(invalid_option(
                "ISO 18571 weights",
                format!("{weights:?}"),
                "must be non-negative and sum to 1",
            ));
        }
        self.weights = weights;
        Ok(self)
    }

    /// The step curves are rated on: `Some(1e-4)` (10 kHz, the standard's, default)
    /// resamples other steps onto it; `None` rates curves on their own step.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) for a step that is not finite and positive.
    pub fn rating_step(mut self, dt: Option<f64>) -> Result<Self> {
        if let Some(dt) = dt {
            if !(dt.is_finite() && dt > 0.0) {
                return Err(invalid_option(
                    "ISO 18571 rating step",
                    dt,
                    "must be finite and positive",
                ));
            }
        }
        self.rate_dt = dt;
        Ok(self)
    }

    /// The largest shift as a fraction of the length, `1 - init_min` rounded to two decimals.
    fn max_shift_fraction(&self) -> f64 {
        ((1.0 - self.init_min) * 100.0).round() / 100.0
    }

    /// Rates `computed` against `reference`, both sampled every `dt` from the same time.
    ///
    /// # Errors
    /// [`CalibrateError::Length`] for curves of different lengths or with fewer than 12
    /// samples on the rated grid; [`CalibrateError::Degenerate`] for a reference that is
    /// identically zero or constant over the shifted window (no corridor, magnitude or slope
    /// exists); [`CalibrateError::Core`] for non-finite values.
    pub fn rate(&self, reference: &[f64], computed: &[f64], dt: f64) -> Result<Iso18571Rating> {
        self.rate_with(reference, computed, dt, &mut Vec::new())
    }

    /// [`Iso18571::rate`] reusing `scratch` for the warping table (for many ratings in a row).
    ///
    /// # Errors
    /// As [`Iso18571::rate`].
    pub fn rate_with(
        &self,
        reference: &[f64],
        computed: &[f64],
        dt: f64,
        scratch: &mut Vec<f64>,
    ) -> Result<Iso18571Rating> {
        check_pair(reference, computed, 2, "ISO 18571")?;
        impactcal_core::check_finite("ISO 18571 reference", reference)?;
        impactcal_core::check_finite("ISO 18571 computed curve", computed)?;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(invalid_option(
                "ISO 18571 time step",
                dt,
                "must be finite and positive",
            ));
        }
        let resampled;
        let (t, c, step) = match self.rate_dt {
            Some(target) if (dt - target).abs() > 1e-9 * target => {
                resampled = (
                    resample(reference, dt, target),
                    resample(computed, dt, target),
                );
                (resampled.0.as_slice(), resampled.1.as_slice(), target)
            }
            _ => (reference, computed, dt),
        };
        let n = t.len();
        if n < MIN_SAMPLES {
            return Err(CalibrateError::Length {
                what: "ISO 18571".into(),
                reason: format!(
                    "needs at least {MIN_SAMPLES} samples on the rated grid, found {n}"
                ),
            });
        }
        let degenerate = |reason: &str| CalibrateError::Degenerate {
            what: "ISO 18571".into(),
            reason: reason.into(),
        };
        let corridor = self
            .corridor(t, c)
            .ok_or_else(|| degenerate("the reference is identically zero"))?;
        let eps_p = self.max_shift_fraction();
        let max_shift = (n as f64 * eps_p).floor() as usize;
        let shift = phase::best_shift(t, c, max_shift);
        let d = shift.samples.unsigned_abs();
        let limit = n as f64 * eps_p;
        let phase = if d == 0 {
            1.0
        } else if d as f64 >= limit {
            0.0
        } else {
            ((limit - d as f64) / limit).powi(self.kp)
        };
        let (ts, cs) = if shift.samples >= 0 {
            (&t[..n - d], &c[d..])
        } else {
            (&t[d..], &c[..n - d])
        };
        let m = ts.len();
        let band = ((0.1 * m as f64).ceil() as usize).saturating_sub(1);
        let (diff, norm) = dtw::warped_l1(cs, ts, band, scratch);
        if norm == 0.0 {
            return Err(degenerate(
                "the phase-shifted reference is identically zero",
            ));
        }
        let magnitude_error = diff / norm;
        let magnitude = if magnitude_error == 0.0 {
            1.0
        } else if magnitude_error > self.eps_m {
            0.0
        } else {
            ((self.eps_m - magnitude_error) / self.eps_m).powi(self.km)
        };
        let dts = slope::smoothed_derivative(ts);
        let dcs = slope::smoothed_derivative(cs);
        let norm: f64 = dts.iter().map(|v| v.abs()).sum();
        if norm == 0.0 {
            return Err(degenerate(
                "the phase-shifted reference is constant, so it has no slope",
            ));
        }
        let slope_error = dcs
            .iter()
            .zip(&dts)
            .map(|(a, b)| (a - b).abs())
            .sum::<f64>()
            / norm;
        let slope = if slope_error <= 0.0 {
            1.0
        } else if slope_error >= self.e_s {
            0.0
        } else {
            (self.e_s - slope_error) / self.e_s
        };
        let [wz, wp, wm, ws] = self.weights;
        let r = wz * corridor + wp * phase + wm * magnitude + ws * slope;
        Ok(Iso18571Rating {
            r,
            corridor,
            phase,
            magnitude,
            slope,
            grade: Grade::of(r),
            shift_samples: shift.samples,
            time_shift: shift.samples as f64 * step,
            magnitude_error,
            slope_error,
        })
    }

    /// Rates many `(reference, computed)` pairs sampled every `dt`, in parallel (each
    /// worker reuses one warping table). The ratings come back in pair order and equal those of
    /// [`Iso18571::rate`] bit for bit.
    ///
    /// # Errors
    /// The first failing pair's error, as [`Iso18571::rate`], prefixed with its index.
    pub fn rate_many<R, C>(&self, pairs: &[(R, C)], dt: f64) -> Result<Vec<Iso18571Rating>>
    where
        R: AsRef<[f64]> + Sync,
        C: AsRef<[f64]> + Sync,
    {
        use rayon::prelude::*;
        pairs
            .par_iter()
            .enumerate()
            .map_init(Vec::new, |scratch, (k, (r, c))| {
                self.rate_with(r.as_ref(), c.as_ref(), dt, scratch)
                    .map_err(|e| e.with_subject(|what| format!("{what}, pair {k}")))
            })
            .collect()
    }

    /// The corridor score, `None` for a reference that is identically zero.
    fn corridor(&self, t: &[f64], c: &[f64]) -> Option<f64> {
        let norm = t.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if norm == 0.0 {
            return None;
        }
        let (inner, outer) = (self.a0 * norm, self.b0 * norm);
        let sum: f64 = t
            .iter()
            .zip(c)
            .map(|(a, b)| {
                let d = (a - b).abs();
                if d < inner {
                    1.0
                } else if d > outer {
                    0.0
                } else {
                    ((outer - d) / (outer - inner)).powi(self.kz)
                }
            })
            .sum();
        Some(sum / t.len() as f64)
    }
}

/// Linear interpolation of `x` (step `dt`) onto the points `k target` that fit in its span.
fn resample(x: &[f64], dt: f64, target: f64) -> Vec<f64> {
    let span = (x.len() - 1) as f64 * dt;
    let m = (span / target + 1e-9).floor() as usize + 1;
    let last = x.len() - 1;
    (0..m)
        .map(|k| {
            let s = (k as f64 * target / dt).min(last as f64);
            let j = (s.floor() as usize).min(last.saturating_sub(1));
            let w = s - j as f64;
            x[j] + w * (x[(j + 1).min(last)] - x[j])
        })
        .collect()
}

#[cfg(test)]
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn pulse(n: usize, at: f64, width: f64, amp: f64) -> Vec<f64> {
        (0..n)
            .map(|k| amp * (-((k as f64 - at) / width).powi(2)).exp())
            .collect()
    }

    #[test]
    fn a_curve_against_itself_is_perfect() {
        let t = pulse(801, 300.0, 60.0, 40.0);
        let r = Iso18571::new().rate(&t, &t, 1e-4).unwrap();
        assert_eq!(
            (r.r, r.corridor, r.phase, r.magnitude, r.slope),
            (1.0, 1.0, 1.0, 1.0, 1.0)
        );
        assert_eq!(r.grade, Grade::Excellent);
    }

    #[test]
    fn a_pure_shift_costs_phase_only_in_proportion() {
        let t = pulse(801, 300.0, 60.0, 40.0);
        let c = pulse(801, 340.0, 60.0, 40.0);
        let r = Iso18571::new().rate(&t, &c, 1e-4).unwrap();
        assert_eq!(r.shift_samples, 40);
        // eps_P N = 160.2 samples; 40 of them used.
        assert_relative_eq!(r.phase, (160.2 - 40.0) / 160.2, epsilon = 1e-12);
        assert!(r.magnitude > 0.99 && r.slope > 0.95, "{r:?}");
        assert!(r.corridor < 0.9);
    }

    #[test]
    fn a_scaling_costs_magnitude_and_corridor() {
        let t = pulse(801, 300.0, 60.0, 40.0);
        let c: Vec<f64> = t.iter().map(|v| 1.2 * v).collect();
        let r = Iso18571::new().rate(&t, &c, 1e-4).unwrap();
        assert_eq!(r.shift_samples, 0);
        assert_eq!(r.phase, 1.0);
        // The warped curves differ by 20 % of the reference's L1 norm at most (warping can
        // only lower it) and the slopes by exactly 20 %.
        assert!(r.magnitude_error <= 0.2 + 1e-12 && r.magnitude >= 0.6 - 1e-12);
        assert_relative_eq!(r.slope_error, 0.2, epsilon = 1e-12);
        assert_relative_eq!(r.slope, 0.9, epsilon = 1e-12);
    }

    #[test]
    fn grades() {
        assert_eq!(Grade::of(0.95), Grade::Excellent);
        assert_eq!(Grade::of(0.94), Grade::Good);
        assert_eq!(Grade::of(0.8), Grade::Fair);
        assert_eq!(Grade::of(0.58), Grade::Poor);
    }

    #[test]
    fn other_steps_are_rated_on_10_khz() {
        let t = pulse(401, 150.0, 30.0, 40.0);
        let c = pulse(401, 170.0, 30.0, 36.0);
        // The same curves at 20 kHz (every other point is a midpoint of a 10 kHz sample
        // would not be exact for a Gaussian; compare the 10 kHz rating with the 20 kHz one
        // built from the 10 kHz samples by linear interpolation, which resamples back
        // exactly).
        let up = |x: &[f64]| -> Vec<f64> {
            let mut out = Vec::new();
            for w in x.windows(2) {
                out.push(w[0]);
                out.push(0.5 * (w[0] + w[1]));
            }
            out.push(x[x.len() - 1]);
            out
        };
        let a = Iso18571::new().rate(&t, &c, 1e-4).unwrap();
        let b = Iso18571::new().rate(&up(&t), &up(&c), 5e-5).unwrap();
        assert_relative_eq!(a.r, b.r, epsilon = 1e-12);
        assert_eq!(a.shift_samples, b.shift_samples);
    }

    #[test]
    fn bad_input() {
        let t = pulse(100, 50.0, 10.0, 1.0);
        assert!(Iso18571::new().rate(&[0.0; 100], &t, 1e-4).is_err());
        assert!(Iso18571::new().rate(&[2.0; 100], &t, 1e-4).is_err());
        assert!(Iso18571::new().rate(&t[..10], &t[..10], 1e-4).is_err());
        assert!(Iso18571::new().rate(&t, &t[..99], 1e-4).is_err());
        let mut nan = t.clone();
        nan[3] = f64::NAN;
        assert!(Iso18571::new().rate(&t, &nan, 1e-4).is_err());
        assert!(Iso18571::new().exponents(0, 1, 1).is_err());
        assert!(Iso18571::new().weights([0.5, 0.5, 0.5, -0.5]).is_err());
        assert!(Iso18571::new().corridors(0.5, 0.05).is_err());
    }
}
