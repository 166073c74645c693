//! Synthetic "measured" data: model histories as a test rig would record them.
//!
//! Channel `s` of the result is
//! `test_s(t) = g_s y_s(t - tau) + b_s + e_s(t)`:
//! a trigger offset `tau` (a test triggered late has `tau > 0`; `y` is interpolated
//! linearly and held at its first value before its start), a gain `g_s` and a bias `b_s`
//! per channel (1 and 0 unless given), and noise `e_s` of standard deviation
//! `sigma_s = rms(y_s) 10^(-snr_db / 20)`, white or AR(1)-coloured
//! (`e_k = phi e_{k-1} + sqrt(1 - phi^2) sigma w_k`, stationary, `w` standard normal), from
//! a seeded generator: the same options give the same data.
//!
//! ```
//! use impactcal_core::synthetic::{Measurement, measured};
//! use impactcal_core::Histories;
//!
//! let y = Histories::from_channels(vec!["a".into()], vec![vec![0.0, 1.0, 2.0, 3.0]], 1.0, 0.0, "")?;
//! let m = Measurement { time_shift: 1.0, gains: vec![("a".into(), 2.0)], ..Measurement::default() };
//! let t = measured(&y, &m)?;
//! assert_eq!(t.channel(0), &[0.0, 0.0, 2.0, 4.0]);
//! # Ok::<(), impactcal_core::CoreError>(())
//! ```

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::error::{CoreError, Result};
use crate::histories::Histories;

/// How the synthetic test departs from the model (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Measurement {
    /// Trigger offset `tau` (s).
    pub time_shift: f64,
    /// `(label, g_s)`: channels with a gain other than 1.
    pub gains: Vec<(String, f64)>,
    /// `(label, b_s)`: channels with a bias.
    pub biases: Vec<(String, f64)>,
    /// Signal-to-noise ratio in dB (RMS of the channel over the noise's standard
    /// deviation); `None`: no noise.
    pub snr_db: Option<f64>,
    /// Lag-one correlation `phi` of AR(1) noise, in `[0, 1)`; 0 for white noise.
    pub ar1: f64,
    /// Seed of the noise.
    pub seed: u64,
}

impl Default for Measurement {
    fn default() -> Self {
        Measurement {
            time_shift: 0.0,
            gains: Vec::new(),
            biases: Vec::new(),
            snr_db: None,
            ar1: 0.0,
            seed: 0,
        }
    }
}

/// The histories `y` as measured with `m` (same labels, time base and unit).
///
/// # Errors
/// [`CoreError::InvalidOption`] for a label not in `y`, a non-finite shift, gain, bias or
/// SNR, or `ar1` outside `[0, 1)`.
pub fn measured(y: &Histories, m: &Measurement) -> Result<Histories> {
    if !m.time_shift.is_finite() {
        return Err(CoreError::invalid_option(
            "time_shift",
            m.time_shift,
            "must be finite",
        ));
    }
    if !(0.0..1.0).contains(&m.ar1) {
        return Err(CoreError::invalid_option(
            "ar1",
            m.ar1,
            "must lie in [0, 1)",
        ));
    }
    if let Some(s) = m.snr_db
        && !s.is_finite()
    {
        return Err(CoreError::invalid_option("snr_db", s, "must be finite"));
    }
    let lookup = |list: &[(String, f64)], what: &str, default: f64| -> Result<Vec<f64>> {
        let mut out = vec![default; y.channels()];
        for (label, v) in list {
            let c = y.index_of(label).ok_or_else(|| {
                CoreError::invalid_option(what, label, "not a channel of the histories")
            })?;
            if !v.is_finite() {
                return Err(CoreError::invalid_option(
                    format!("{what} of `{label}`"),
                    v,
                    "must be finite",
                ));
            }
            out[c] = *v;
        }
        Ok(out)
    };
    let gains = lookup(&m.gains, "gain", 1.0)?;
    let biases = lookup(&m.biases, "bias", 0.0)?;
    let mut rng = ChaCha8Rng::seed_from_u64(m.seed);
    let n = y.samples();
    let shift = m.time_shift / y.dt();
    let mut channels = Vec::with_capacity(y.channels());
    for c in 0..y.channels() {
        let ch = y.channel(c);
        let sigma = m.snr_db.map_or(0.0, |snr| {
            let rms = (ch.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
            rms * 10f64.powf(-snr / 20.0)
        });
        let innovation = (1.0 - m.ar1 * m.ar1).sqrt();
        let mut e = sigma * normal(&mut rng);
        let out: Vec<f64> = (0..n)
            .map(|k| {
                if k > 0 {
                    e = m.ar1 * e + innovation * sigma * normal(&mut rng);
                }
                gains[c] * shifted(ch, k as f64 - shift) + biases[c] + e
            })
            .collect();
        channels.push(out);
    }
    Histories::from_channels(y.labels().to_vec(), channels, y.dt(), y.start(), y.unit())
}

/// `ch` at fractional sample `x`, linear, held at its ends.
fn shifted(ch: &[f64], x: f64) -> f64 {
    let last = ch.len() - 1;
    if x <= 0.0 {
        return ch[0];
    }
    if x >= last as f64 {
        return ch[last];
    }
    let i = x.floor() as usize;
    let w = x - i as f64;
    ch[i] + w * (ch[i + 1] - ch[i])
}

/// A standard normal draw (Box-Muller).
fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = rng.random_range(f64::MIN_POSITIVE..1.0);
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_level_and_colour_match_the_options() {
        let n = 20000;
        let y = Histories::from_channels(
            vec!["a".into(), "b".into()],
            vec![vec![1.0; n], vec![2.0; n]],
            1e-4,
            0.0,
            "",
        )
        .unwrap();
        let m = Measurement {
            snr_db: Some(20.0),
            ar1: 0.8,
            seed: 3,
            biases: vec![("b".into(), 0.5)],
            ..Measurement::default()
        };
        let t = measured(&y, &m).unwrap();
        let e: Vec<f64> = t.channel(1).iter().map(|v| v - 2.5).collect();
        let var = e.iter().map(|v| v * v).sum::<f64>() / n as f64;
        let lag1 = e.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / (n - 1) as f64 / var;
        // sigma = 2 * 0.1.
        assert!((var.sqrt() - 0.2).abs() < 0.02, "{}", var.sqrt());
        assert!((lag1 - 0.8).abs() < 0.03, "{lag1}");
        assert_eq!(measured(&y, &m).unwrap(), t);
        let bad = Measurement {
            gains: vec![("c".into(), 2.0)],
            ..Measurement::default()
        };
        assert!(measured(&y, &bad).is_err());
    }
}
