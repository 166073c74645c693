//! Nuisance terms, estimated before any physics: one trigger offset `tau` for the whole
//! test, and a gain `g_s` and a bias `b_s` per channel, with
//! `test_s(t) = g_s y_s(t - tau) + b_s` (a test triggered late has `tau > 0`).
//!
//! For a given model run they are found by weighted least squares: for each trial `tau`
//! the model is shifted (linear interpolation, held at its first value before its start)
//! and each channel's `(g_s, b_s)` is the weighted linear fit of the test on
//! `[y_s(t - tau), 1]`; `tau` minimises the total weighted residual, first on a grid of one
//! sample over `[-max_shift, max_shift]`, then by golden-section search within a sample of
//! the best grid point. A gain within a relative tolerance of 9.81, 1/9.81, 25.4, 1000 or
//! 0.001 is flagged as a likely units error (g vs m/s^2, inch vs mm, m vs mm, s vs ms).
//! Nuisance terms are reported and never offered as physics.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::prewhiten::Prewhitener;

/// The likely units factors and what each suggests.
const UNITS: [(f64, &str); 5] = [
    (9.81, "g vs m/s^2"),
    (1.0 / 9.81, "m/s^2 vs g"),
    (25.4, "inch vs mm"),
    (1000.0, "a factor of 1000 (m vs mm, kN vs N, s vs ms)"),
    (0.001, "a factor of 1/1000 (mm vs m, N vs kN, ms vs s)"),
];

/// The channels of one comparison on a common time base: `S` channels of `T` samples,
/// channel-major (`[s * T + k]`).
#[derive(Debug, Clone)]
pub(crate) struct Frame {
    pub labels: Vec<String>,
    pub samples: usize,
    pub dt: f64,
    /// The test, `S x T`.
    pub test: Vec<f64>,
    /// Whitening weights `1 / sigma_sk`, `S x T`.
    pub weights: Vec<f64>,
    /// The noise model after the weights: each channel's AR whitening, and the masked
    /// samples (`closeloop::prewhiten`).
    pub whitener: Prewhitener,
}

impl Frame {
    /// Whether each sample (`S x T`) is out of the likelihood: weight 0, a sample masked by
    /// the noise model (`closeloop::frame::noise_model`).
    pub fn masked(&self) -> Vec<bool> {
        self.weights.iter().map(|w| *w == 0.0).collect()
    }

    /// The number of samples in the likelihood (weight above 0).
    pub fn compared(&self) -> usize {
        self.weights.iter().filter(|w| **w > 0.0).count()
    }
}

/// The estimated nuisance terms.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Nuisance {
    /// Trigger offset `tau` (s).
    pub time_shift: f64,
    /// Gain per channel.
    pub gains: BTreeMap<String, f64>,
    /// Bias per channel (the test's unit).
    pub biases: BTreeMap<String, f64>,
    /// Channels whose gain looks like a units error, with the factor it is near.
    pub units_flags: Vec<UnitsFlag>,
}

/// A gain near a units factor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UnitsFlag {
    /// The channel.
    pub channel: String,
    /// Its gain.
    pub gain: f64,
    /// The factor it is near.
    pub factor: f64,
    /// What that factor usually means.
    pub meaning: String,
}

/// Nuisance values in frame order, as the fits use them.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Terms {
    pub tau: f64,
    pub gains: Vec<f64>,
    pub biases: Vec<f64>,
}

impl Terms {
    /// The report form, with the units flags at relative tolerance `tol`.
    pub fn report(&self, labels: &[String], tol: f64) -> Nuisance {
        let mut units_flags = Vec::new();
        for (l, &g) in labels.iter().zip(&self.gains) {
            for (f, meaning) in UNITS {
                if ((g - f) / f).abs() <= tol {
                    units_flags.push(UnitsFlag {
                        channel: l.clone(),
                        gain: g,
                        factor: f,
                        meaning: meaning.into(),
                    });
                }
            }
        }
        Nuisance {
            time_shift: self.tau,
            gains: labels
                .iter()
                .cloned()
                .zip(self.gains.iter().copied())
                .collect(),
            biases: labels
                .iter()
                .cloned()
                .zip(self.biases.iter().copied())
                .collect(),
            units_flags,
        }
    }
}

/// Channel `ch` at time index `x` (fractional), linear, held at its ends.
pub(crate) fn at(ch: &[f64], x: f64) -> f64 {
    let last = ch.len() - 1;
    if x <= 0.0 {
        ch[0]
    } else if x >= last as f64 {
        ch[last]
    } else {
        let i = x.floor() as usize;
        let w = x - i as f64;
        ch[i] + w * (ch[i + 1] - ch[i])
    }
}

/// The model `y` (`S x T`, channel-major) shifted by `tau`: `y_s(t_k - tau)`.
pub(crate) fn shifted(y: &[f64], frame: &Frame, tau: f64) -> Vec<f64> {
    let t = frame.samples;
    let d = tau / frame.dt;
    let mut out = Vec::with_capacity(y.len());
    for ch in y.chunks(t) {
        out.extend((0..t).map(|k| at(ch, k as f64 - d)));
    }
    out
}

/// `g_s y_s(t - tau) + b_s`.
pub(crate) fn apply(y: &[f64], frame: &Frame, terms: &Terms) -> Vec<f64> {
    let t = frame.samples;
    let mut out = shifted(y, frame, terms.tau);
    for (s, ch) in out.chunks_mut(t).enumerate() {
        ch.iter_mut()
            .for_each(|v| *v = terms.gains[s] * *v + terms.biases[s]);
    }
    out
}

/// The test with the nuisance terms taken out, on the model's time base:
/// `(test_s(t + tau) - b_s) / g_s` (for the before/after metrics).
pub(crate) fn corrected_test(frame: &Frame, terms: &Terms) -> Vec<f64> {
    let t = frame.samples;
    let d = terms.tau / frame.dt;
    let mut out = Vec::with_capacity(frame.test.len());
    for (s, ch) in frame.test.chunks(t).enumerate() {
        let g = if terms.gains[s] != 0.0 {
            terms.gains[s]
        } else {
            1.0
        };
        out.extend((0..t).map(|k| (at(ch, k as f64 + d) - terms.biases[s]) / g));
    }
    out
}

/// Per channel, the generalised least-squares fit of the test on `[ys, 1]` at the given
/// shifted model under the frame's noise model: the ordinary fit of `L^-1 w z` on
/// `[L^-1 w ys, L^-1 w]` (`closeloop::prewhiten`), `(g, b, rss)`. `fixed_gains` keeps the
/// gains and fits only the biases.
fn channel_fits(
    ys: &[f64],
    frame: &Frame,
    fixed_gains: Option<&[f64]>,
) -> (Vec<f64>, Vec<f64>, f64) {
    let t = frame.samples;
    let (mut gains, mut biases, mut rss) = (Vec::new(), Vec::new(), 0.0);
    for s in 0..frame.labels.len() {
        let r = s * t..(s + 1) * t;
        let (y, z, w) = (&ys[r.clone()], &frame.test[r.clone()], &frame.weights[r]);
        let white = |v: &dyn Fn(usize) -> f64| -> Vec<f64> {
            frame
                .whitener
                .whiten_channel(s, &(0..t).map(|k| w[k] * v(k)).collect::<Vec<f64>>())
        };
        let (c, a, u) = (white(&|_| 1.0), white(&|k| y[k]), white(&|k| z[k]));
        let (mut sw, mut sy, mut sz, mut syy, mut syz) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for k in 0..t {
            sw += c[k] * c[k];
            sy += c[k] * a[k];
            sz += c[k] * u[k];
            syy += a[k] * a[k];
            syz += a[k] * u[k];
        }
        let (g, b) = match fixed_gains {
            Some(g) => (g[s], (sz - g[s] * sy) / sw),
            None => {
                let det = sw * syy - sy * sy;
                if det.abs() <= 1e-300 * (sw * syy).abs().max(1e-300) || det <= 0.0 {
                    (1.0, (sz - sy) / sw)
                } else {
                    ((sw * syz - sy * sz) / det, (syy * sz - sy * syz) / det)
                }
            }
        };
        rss += (0..t)
            .map(|k| (u[k] - g * a[k] - b * c[k]).powi(2))
            .sum::<f64>();
        gains.push(g);
        biases.push(b);
    }
    (gains, biases, rss)
}

/// The nuisance terms that best map the model `y` onto the frame's test (see the module
/// docs), with the weighted residual sum of squares they leave. `fixed_gains` keeps the
/// gains (a holdout test measured with the calibration test's sensors).
pub(crate) fn profile(
    y: &[f64],
    frame: &Frame,
    max_shift: f64,
    fixed_gains: Option<&[f64]>,
) -> (Terms, f64) {
    let eval = |tau: f64| {
        let ys = shifted(y, frame, tau);
        let (g, b, rss) = channel_fits(&ys, frame, fixed_gains);
        (
            Terms {
                tau,
                gains: g,
                biases: b,
            },
            rss,
        )
    };
    let steps = (max_shift / frame.dt).floor() as i64;
    let mut best = eval(0.0);
    for i in -steps..=steps {
        if i == 0 {
            continue;
        }
        let c = eval(i as f64 * frame.dt);
        if c.1 < best.1 {
            best = c;
        }
    }
    if steps > 0 {
        // Golden-section search within one sample of the best grid point.
        let phi = 0.5 * (5f64.sqrt() - 1.0);
        let (mut a, mut b) = (best.0.tau - frame.dt, best.0.tau + frame.dt);
        let mut c = b - phi * (b - a);
        let mut d = a + phi * (b - a);
        let (mut fc, mut fd) = (eval(c).1, eval(d).1);
        for _ in 0..40 {
            if fc < fd {
                b = d;
                d = c;
                fd = fc;
                c = b - phi * (b - a);
                fc = eval(c).1;
            } else {
                a = c;
                c = d;
                fc = fd;
                d = a + phi * (b - a);
                fd = eval(d).1;
            }
        }
        let refined = eval(0.5 * (a + b));
        if refined.1 < best.1 {
            best = refined;
        }
    }
    best
}

/// The whitened residual `L^-1 w (test - N(y))` of a model run under nuisance `terms`
/// (`L^-1` the frame's noise model, `closeloop::prewhiten`).
pub(crate) fn residual(y: &[f64], frame: &Frame, terms: &Terms) -> Vec<f64> {
    let weighted: Vec<f64> = apply(y, frame, terms)
        .iter()
        .zip(&frame.test)
        .zip(&frame.weights)
        .map(|((m, z), w)| w * (z - m))
        .collect();
    frame.whitener.whiten(&weighted)
}

/// The whitened change `L^-1 w (N(y_1) - N(y_0)) / h` between two model runs under the
/// same nuisance terms, given `base = N(y_0)`: a finite-difference direction of the fit.
pub(crate) fn direction(
    y1: &[f64],
    base: &[f64],
    frame: &Frame,
    terms: &Terms,
    h: f64,
) -> Vec<f64> {
    let weighted: Vec<f64> = apply(y1, frame, terms)
        .iter()
        .zip(base)
        .zip(&frame.weights)
        .map(|((a, b), w)| w * (a - b) / h)
        .collect();
    frame.whitener.whiten(&weighted)
}

/// The whitened derivative columns of the nuisance terms at `y`, in the form
/// [`Jacobian::new`](super::jacobian::Jacobian::new) takes them: the dense `tau` column
/// (`-g_s y'_s(t - tau)`), and the per-channel columns, each channel's bias (1 on that
/// channel) and gain (`y_s(t - tau)` on that channel; left out when `gains` is false, the
/// gains being known), weighted and prewhitened (`L^-1 w`, channel by channel, so that a
/// per-channel column stays on its channel); every vector `S x T`.
pub(crate) fn columns(
    y: &[f64],
    frame: &Frame,
    terms: &Terms,
    gains: bool,
) -> (Vec<f64>, Vec<Vec<f64>>) {
    let t = frame.samples;
    let n = y.len();
    let ys = shifted(y, frame, terms.tau);
    let mut tau_col = vec![0.0; n];
    for s in 0..frame.labels.len() {
        let ch = &ys[s * t..(s + 1) * t];
        for k in 0..t {
            let (lo, hi) = (k.saturating_sub(1), (k + 1).min(t - 1));
            let dy = (ch[hi] - ch[lo]) / ((hi - lo).max(1) as f64 * frame.dt);
            tau_col[s * t + k] = -terms.gains[s] * dy * frame.weights[s * t + k];
        }
    }
    let mut local = vec![frame.whitener.whiten(&frame.weights)];
    if gains {
        let g: Vec<f64> = ys.iter().zip(&frame.weights).map(|(v, w)| v * w).collect();
        local.push(frame.whitener.whiten(&g));
    }
    (frame.whitener.whiten(&tau_col), local)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_shift_gain_and_bias_exactly_without_noise() {
        let t = 400;
        let dt = 1e-4;
        let y: Vec<f64> = (0..2 * t)
            .map(|i| {
                let (s, k) = (i / t, i % t);
                let x = k as f64 * dt;
                (1.0 + s as f64) * (-((x - 0.02) / 0.004).powi(2)).exp()
            })
            .collect();
        let truth = Terms {
            tau: 3.4e-4,
            gains: vec![9.81, 0.9],
            biases: vec![0.5, -0.2],
        };
        let mut frame = Frame {
            labels: vec!["a".into(), "b".into()],
            samples: t,
            dt,
            test: vec![],
            weights: vec![1.0; 2 * t],
            whitener: Prewhitener::default(),
        };
        frame.test = apply(&y, &frame, &truth);
        let (est, rss) = profile(&y, &frame, 2e-3, None);
        assert!((est.tau - truth.tau).abs() < 2e-6, "{}", est.tau);
        for s in 0..2 {
            assert!((est.gains[s] - truth.gains[s]).abs() < 1e-3);
            assert!((est.biases[s] - truth.biases[s]).abs() < 1e-3);
        }
        assert!(rss < 1e-4);
        let report = est.report(&frame.labels, 0.02);
        assert_eq!(report.units_flags.len(), 1);
        assert_eq!(report.units_flags[0].channel, "a");
        // Taking the terms out of the test gives back the model away from the ends.
        let back = corrected_test(&frame, &est);
        for k in 10..t - 10 {
            assert!((back[k] - y[k]).abs() < 1e-3);
        }
    }
}
