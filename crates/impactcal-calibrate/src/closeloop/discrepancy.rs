//! The fallback when no candidate explains the residual: a low-rank discrepancy
//! `delta_s(t) = sum_i sigma_i u_is v_i(t) / w_s(t)`, the leading singular components of the
//! whitened residual that stand above the noise edge (at least one, at most three),
//! reported as **unattributed model-form error** with its sensor pattern `u_i` and time
//! pattern `v_i`. It is a description of what is missing, never a physical effect.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::linalg::svd_rows;
use crate::error::Result;

/// One component of the discrepancy.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Component {
    /// Its singular value (whitened units).
    pub sigma: f64,
    /// Sensor pattern `u` (label -> entry).
    pub sensors: BTreeMap<String, f64>,
    /// Time pattern `v` (unit norm).
    pub time: Vec<f64>,
    /// When it happens: the time (s, the record's) of the pattern's largest `|v_k|`.
    #[serde(default)]
    pub peak_time: f64,
    /// The span (s) holding the central half of the pattern's energy: from where its
    /// running sum of `v_k^2` passes 1/4 to where it passes 3/4.
    #[serde(default)]
    pub span: (f64, f64),
    /// In which band: the frequencies (Hz) below which 1/4, 1/2 and 3/4 of the pattern's
    /// energy lie, from its periodogram on at most [`BAND_GRID`] frequencies from 0 to
    /// Nyquist. The pattern is the whitened residual's, so this is the band where the
    /// residual stands out of the measurement noise most.
    #[serde(default)]
    pub band: [f64; 3],
}

/// Most frequencies of the periodogram that places a component's band.
pub const BAND_GRID: usize = 512;

impl Component {
    /// The component of singular value `sigma`, sensor pattern `sensors` and time pattern
    /// `time` sampled from `start` at step `dt`, with where and in which band it lies.
    pub fn new(
        sigma: f64,
        sensors: BTreeMap<String, f64>,
        time: Vec<f64>,
        start: f64,
        dt: f64,
    ) -> Self {
        let peak = time
            .iter()
            .enumerate()
            .fold((0, 0.0_f64), |(i, m), (k, v)| {
                if v.abs() > m { (k, v.abs()) } else { (i, m) }
            })
            .0;
        let energy: Vec<f64> = time.iter().map(|v| v * v).collect();
        let at = |q: f64| quantile_index(&energy, q);
        let span = (start + at(0.25) as f64 * dt, start + at(0.75) as f64 * dt);
        let (freqs, power) = periodogram(&time, dt);
        let band =
            [0.25, 0.5, 0.75].map(|q| freqs.get(quantile_index(&power, q)).copied().unwrap_or(0.0));
        Component {
            sigma,
            sensors,
            peak_time: start + peak as f64 * dt,
            span,
            band,
            time,
        }
    }
}

/// The first index where the running sum of `w` reaches `q` of its total (0 for a zero
/// total).
fn quantile_index(w: &[f64], q: f64) -> usize {
    let total: f64 = w.iter().sum();
    if total <= 0.0 {
        return 0;
    }
    let mut run = 0.0;
    for (k, x) in w.iter().enumerate() {
        run += x;
        if run >= q * total {
            return k;
        }
    }
    w.len().saturating_sub(1)
}

/// `|sum_k x_k e^{-2 pi i f k dt}|^2` at `min(T/2, BAND_GRID) + 1` frequencies `f` evenly
/// from 0 to Nyquist, `1 / (2 dt)` (Goertzel's recursion at each).
fn periodogram(x: &[f64], dt: f64) -> (Vec<f64>, Vec<f64>) {
    let m = (x.len() / 2).clamp(1, BAND_GRID);
    let nyquist = 0.5 / dt;
    (0..=m)
        .map(|j| {
            let f = nyquist * j as f64 / m as f64;
            let w = 2.0 * std::f64::consts::PI * f * dt;
            let c = 2.0 * w.cos();
            let (mut s1, mut s2) = (0.0, 0.0);
            for v in x {
                let s0 = v + c * s1 - s2;
                s2 = s1;
                s1 = s0;
            }
            (f, s1 * s1 + s2 * s2 - c * s1 * s2)
        })
        .unzip()
}

/// The unattributed model-form error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Discrepancy {
    /// The components kept.
    pub components: Vec<Component>,
    /// Fraction of the residual's weighted sum of squares they carry.
    pub energy_fraction: f64,
    /// The directions that came closest, with their explained fractions.
    pub closest: Vec<(String, f64)>,
}

/// The low-rank discrepancy of the whitened residual `e` (`S x T`, samples from `start` at
/// step `dt`) with `rank` components (clamped to 1..=3).
///
/// # Errors
/// When the SVD fails.
pub(crate) fn fit(
    labels: &[String],
    e: &[f64],
    (samples, start, dt): (usize, f64, f64),
    rank: usize,
    closest: Vec<(String, f64)>,
) -> Result<Discrepancy> {
    let (s, u, v) = svd_rows(e, labels.len(), samples)?;
    let keep = rank.clamp(1, 3).min(s.len());
    let total: f64 = e.iter().map(|x| x * x).sum();
    let kept: f64 = s[..keep].iter().map(|x| x * x).sum();
    Ok(Discrepancy {
        components: (0..keep)
            .map(|i| {
                Component::new(
                    s[i],
                    labels
                        .iter()
                        .enumerate()
                        .map(|(r, l)| (l.clone(), u[(r, i)]))
                        .collect(),
                    (0..samples).map(|k| v[(k, i)]).collect(),
                    start,
                    dt,
                )
            })
            .collect(),
        energy_fraction: if total > 0.0 { kept / total } else { 0.0 },
        closest,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tone burst of known time and frequency (a 20 kHz sine under a Gaussian of
    /// 0.1 ms standard deviation centred at 1.3 ms, from 0.2 ms at 1 MHz): the component
    /// places its peak within half a period of the centre, its central half of energy at
    /// the Gaussian's quartiles of `g^2` (`+- 0.674 sigma / sqrt 2`), and its median
    /// frequency at 20 kHz within one step of the periodogram's grid (500 kHz / 512).
    #[test]
    fn a_tone_burst_is_placed_in_time_and_band() {
        let (start, dt, n) = (2e-4, 1e-6, 2500);
        let (t0, width, f) = (1.3e-3, 1e-4, 2e4);
        let time: Vec<f64> = (0..n)
            .map(|k| {
                let t = start + k as f64 * dt;
                (-0.5 * ((t - t0) / width).powi(2)).exp()
                    * (2.0 * std::f64::consts::PI * f * t).sin()
            })
            .collect();
        let c = Component::new(1.0, BTreeMap::new(), time, start, dt);
        assert!((c.peak_time - t0).abs() <= 0.5 / f, "{}", c.peak_time);
        let q = 0.674 * width / 2f64.sqrt();
        assert!(
            (c.span.0 - (t0 - q)).abs() < 5e-6 && (c.span.1 - (t0 + q)).abs() < 5e-6,
            "{:?}",
            c.span
        );
        let step = 0.5 / dt / BAND_GRID as f64;
        assert!((c.band[1] - f).abs() <= step, "{:?}", c.band);
        // The burst's spectrum is a Gaussian of 1.6 kHz standard deviation about 20 kHz:
        // its quartiles lie within 0.674 of that (and a grid step) of it.
        let spread = 0.674 / (2.0 * std::f64::consts::PI * width) + step;
        assert!(
            c.band[0] <= c.band[1] && c.band[1] <= c.band[2],
            "{:?}",
            c.band
        );
        assert!(
            (c.band[0] - f).abs() <= spread && (c.band[2] - f).abs() <= spread,
            "{:?}",
            c.band
        );
    }

    /// A zero pattern has no place: everything at the start and at zero frequency.
    #[test]
    fn a_zero_pattern_is_not_placed() {
        let c = Component::new(0.0, BTreeMap::new(), vec![0.0; 16], 1.0, 0.5);
        assert_eq!((c.peak_time, c.span, c.band), (1.0, (1.0, 1.0), [0.0; 3]));
    }
}
