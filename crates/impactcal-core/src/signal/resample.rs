//! Linear interpolation between time bases.

use crate::error::{CoreError, Result};
use crate::histories::Histories;

/// Fraction of a time step by which time stamps may stray outside a range and still count as
/// inside it (time stamps written to text are rounded).
const TIME_SLACK: f64 = 1e-6;

/// How a record on a non-uniform time base was put on a uniform one (see
/// [`resample_uniform`]), so that readers can say so.
#[derive(Debug, Clone, PartialEq)]
pub struct Resampling {
    /// Samples in the source.
    pub source_samples: usize,
    /// Smallest and largest time step of the source.
    pub source_steps: (f64, f64),
    /// Samples on the uniform base.
    pub samples: usize,
    /// The uniform step: the median step of the source.
    pub dt: f64,
}

impl std::fmt::Display for Resampling {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "non-uniform time steps ({:e} to {:e}): {} samples resampled linearly onto {} samples at the median step {:e}",
            self.source_steps.0, self.source_steps.1, self.source_samples, self.samples, self.dt
        )
    }
}

/// Puts channels sampled at the strictly increasing times `times` on a uniform base by linear
/// interpolation. The uniform step is the median step of `times`; the base starts at
/// `times[0]` and holds every point `times[0] + k dt` up to the last time (within a millionth
/// of a step).
///
/// Returns the resampled channels and the uniform step.
///
/// # Errors
/// [`CoreError::Invalid`] for fewer than two times, times that do not strictly increase, or a
/// channel whose length differs from `times`.
pub fn resample_uniform(
    times: &[f64],
    channels: &[Vec<f64>],
) -> Result<(Vec<Vec<f64>>, Resampling)> {
    if times.len() < 2 {
        return Err(CoreError::Invalid(
            "resampling needs at least two time points".into(),
        ));
    }
    let mut steps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    if let Some(k) = steps
        .iter()
        .position(|s| s.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater))
    {
        return Err(CoreError::Invalid(format!(
            "time {} at point {} does not increase (previous {})",
            times[k + 1],
            k + 1,
            times[k]
        )));
    }
    if let Some(c) = channels.iter().position(|ch| ch.len() != times.len()) {
        return Err(CoreError::DimensionMismatch {
            what: format!("samples of channel {c}"),
            expected: times.len(),
            found: channels[c].len(),
        });
    }
    steps.sort_by(f64::total_cmp);
    let dt = steps[steps.len() / 2];
    let span = times[times.len() - 1] - times[0];
    let samples = (span / dt + TIME_SLACK).floor() as usize + 1;
    let out = channels
        .iter()
        .map(|ch| {
            let mut j = 0;
            (0..samples)
                .map(|k| {
                    let t = (times[0] + k as f64 * dt).min(times[times.len() - 1]);
                    while j + 2 < times.len() && times[j + 1] < t {
                        j += 1;
                    }
                    lerp(times[j], times[j + 1], ch[j], ch[j + 1], t)
                })
                .collect()
        })
        .collect();
    let resampling = Resampling {
        source_samples: times.len(),
        source_steps: (steps[0], steps[steps.len() - 1]),
        samples,
        dt,
    };
    Ok((out, resampling))
}

fn lerp(t0: f64, t1: f64, y0: f64, y1: f64, t: f64) -> f64 {
    let w = (t - t0) / (t1 - t0);
    y0 + w * (y1 - y0)
}

/// The model `model` linearly interpolated onto the uniform time points
/// `start + k dt, k = 0..samples` (the test's), keeping its labels and unit. The model is
/// never extrapolated: every time point must lie inside the model's range (to a millionth of
/// the smaller step).
///
/// `what` names the comparison in errors.
///
/// # Errors
/// [`CoreError::NoTimeOverlap`] when the two ranges do not overlap at all;
/// [`CoreError::OutsideModelTime`] when they overlap but some time points fall outside the
/// model's range; [`CoreError::Invalid`] for `samples == 0` or a `dt` that is not finite and
/// positive.
pub fn interpolate_onto(
    model: &Histories,
    start: f64,
    dt: f64,
    samples: usize,
    what: &str,
) -> Result<Histories> {
    if samples == 0 || !(dt.is_finite() && dt > 0.0) || !start.is_finite() {
        return Err(CoreError::Invalid(format!(
            "{what}: cannot interpolate onto {samples} samples of step {dt} from {start}"
        )));
    }
    let end = start + (samples - 1) as f64 * dt;
    let model_end = model.start() + (model.samples() - 1) as f64 * model.dt();
    let slack = TIME_SLACK * dt.min(model.dt());
    let (test_start, test_end, model_start) = (start, end, model.start());
    if end < model_start - slack || start > model_end + slack {
        return Err(CoreError::NoTimeOverlap {
            what: what.to_string(),
            test_start,
            test_end,
            model_start,
            model_end,
        });
    }
    if start < model_start - slack || end > model_end + slack {
        return Err(CoreError::OutsideModelTime {
            what: what.to_string(),
            test_start,
            test_end,
            model_start,
            model_end,
        });
    }
    let last = model.samples() - 1;
    let mut data = Vec::with_capacity(model.channels() * samples);
    for c in 0..model.channels() {
        let y = model.channel(c);
        data.extend((0..samples).map(|k| {
            let t = start + k as f64 * dt;
            let s = ((t - model_start) / model.dt()).clamp(0.0, last as f64);
            let j = (s.floor() as usize).min(last.saturating_sub(1));
            if last == 0 {
                return y[0];
            }
            let w = s - j as f64;
            y[j] + w * (y[j + 1] - y[j])
        }));
    }
    Histories::new(
        model.labels().to_vec(),
        samples,
        dt,
        start,
        model.unit(),
        data,
    )
}

/// The samples of `h` whose times lie in `[t0, t1]` (to a millionth of a step).
///
/// # Errors
/// [`CoreError::Invalid`] for `t0 > t1` or non-finite bounds, and when fewer than two samples
/// fall inside the window.
pub fn crop(h: &Histories, t0: f64, t1: f64) -> Result<Histories> {
    if !(t0.is_finite() && t1.is_finite() && t0 <= t1) {
        return Err(CoreError::Invalid(format!(
            "time window [{t0}, {t1}] must be finite and increasing"
        )));
    }
    let slack = TIME_SLACK;
    let first = ((t0 - h.start()) / h.dt() - slack).ceil().max(0.0) as usize;
    let last_f = ((t1 - h.start()) / h.dt() + slack).floor();
    if last_f < 0.0 || first >= h.samples() {
        return Err(CoreError::Invalid(format!(
            "time window [{t0}, {t1}] holds no samples of data covering [{}, {}]",
            h.start(),
            h.start() + (h.samples() - 1) as f64 * h.dt()
        )));
    }
    let last = (last_f as usize).min(h.samples() - 1);
    if last < first + 1 {
        return Err(CoreError::Invalid(format!(
            "time window [{t0}, {t1}] holds fewer than two samples"
        )));
    }
    let n = last - first + 1;
    let mut data = Vec::with_capacity(h.channels() * n);
    for c in 0..h.channels() {
        data.extend_from_slice(&h.channel(c)[first..=last]);
    }
    Histories::new(
        h.labels().to_vec(),
        n,
        h.dt(),
        h.start() + first as f64 * h.dt(),
        h.unit(),
        data,
    )
}

#[cfg(test)]
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn ramp(start: f64, dt: f64, n: usize) -> Histories {
        let t: Vec<f64> = (0..n).map(|k| start + k as f64 * dt).collect();
        Histories::from_channels(
            vec!["a".into(), "b".into()],
            vec![
                t.iter().map(|t| 2.0 * t + 1.0).collect(),
                t.iter().map(|t| -t).collect(),
            ],
            dt,
            start,
            "g",
        )
        .unwrap()
    }

    #[test]
    fn interpolation_is_exact_on_lines() {
        let model = ramp(0.0, 1e-3, 101);
        let out = interpolate_onto(&model, 0.0105, 7e-4, 50, "m").unwrap();
        for k in 0..50 {
            let t = 0.0105 + k as f64 * 7e-4;
            assert_relative_eq!(out.value(0, k), 2.0 * t + 1.0, epsilon = 1e-12);
            assert_relative_eq!(out.value(1, k), -t, epsilon = 1e-12);
        }
        assert_eq!(out.unit(), "g");
        // The whole model range, end points included.
        let out = interpolate_onto(&model, 0.0, 1e-3, 101, "m").unwrap();
        assert_eq!(out.data(), model.data());
    }

    #[test]
    fn never_extrapolates() {
        let model = ramp(0.0, 1e-3, 101);
        assert!(matches!(
            interpolate_onto(&model, 0.05, 1e-3, 60, "m").unwrap_err(),
            CoreError::OutsideModelTime { .. }
        ));
        assert!(matches!(
            interpolate_onto(&model, -0.01, 1e-3, 20, "m").unwrap_err(),
            CoreError::OutsideModelTime { .. }
        ));
        assert!(matches!(
            interpolate_onto(&model, 0.2, 1e-3, 20, "m").unwrap_err(),
            CoreError::NoTimeOverlap { .. }
        ));
        assert!(matches!(
            interpolate_onto(&model, -0.2, 1e-3, 20, "m").unwrap_err(),
            CoreError::NoTimeOverlap { .. }
        ));
    }

    #[test]
    fn resampling_uses_the_median_step_and_is_exact_on_lines() {
        let times = [0.0, 0.001, 0.002, 0.0035, 0.004, 0.005, 0.0062];
        let ch: Vec<f64> = times.iter().map(|t| 3.0 * t - 1.0).collect();
        let (out, r) = resample_uniform(&times, &[ch]).unwrap();
        assert_relative_eq!(r.dt, 0.001, max_relative = 1e-12);
        assert_eq!(r.samples, 7);
        assert_eq!(r.source_samples, 7);
        for (k, v) in out[0].iter().enumerate() {
            assert_relative_eq!(*v, 3.0 * (k as f64 * 0.001) - 1.0, epsilon = 1e-12);
        }
        assert!(resample_uniform(&[0.0, 1.0, 1.0], &[vec![0.0; 3]]).is_err());
        assert!(resample_uniform(&[0.0, 1.0, 0.5], &[vec![0.0; 3]]).is_err());
    }

    #[test]
    fn crop_keeps_the_samples_inside() {
        let h = ramp(-0.01, 1e-3, 101);
        let c = crop(&h, 0.0, 0.05).unwrap();
        assert_eq!(c.samples(), 51);
        assert_relative_eq!(c.start(), 0.0, epsilon = 1e-15);
        assert_relative_eq!(c.value(0, 0), 1.0, epsilon = 1e-12);
        assert!(crop(&h, 0.2, 0.3).is_err());
        assert!(crop(&h, 0.05, 0.0).is_err());
    }
}
