//! Periodograms, spectral lines in noise, and the noise level from a band where a model has
//! no content.
//!
//! The periodogram of `n` samples under a Hann taper `w` is
//! `I(f_j) = |sum_k w_k x_k e^{-2 pi i j k / n}|^2 / sum_k w_k^2` at `f_j = j / (n dt)`,
//! `j = 0 .. n/2`; white noise of variance `sigma^2` has `E I = sigma^2` at every
//! frequency, and a stationary process of density `S` (two-sided, in the same units) has
//! `E I(f) ~ S(f)` away from its sharp features. Ordinates of noise are close to
//! exponentially distributed about `S`, so `I / S > ln(m / alpha)` at one of `m` frequencies
//! happens with probability about `alpha` (the threshold of a line).

use serde::{Deserialize, Serialize};

use super::ar::ArModel;

/// Most samples a periodogram is taken on (the direct transform costs `n^2 / 2`).
pub const MAX_SPECTRUM_SAMPLES: usize = 8192;

/// The Hann-tapered periodogram of `x` (mean and straight line through the least-squares
/// fit removed), ordinates `j = 0 .. n/2`.
pub fn periodogram(x: &[f64]) -> Vec<f64> {
    let x = &x[..x.len().min(MAX_SPECTRUM_SAMPLES)];
    let n = x.len();
    if n < 4 {
        return Vec::new();
    }
    let d = detrended(x);
    let w: Vec<f64> = (0..n)
        .map(|k| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * k as f64 / n as f64).cos())
        .collect();
    let norm: f64 = w.iter().map(|v| v * v).sum();
    let y: Vec<f64> = d.iter().zip(&w).map(|(a, b)| a * b).collect();
    (0..=n / 2)
        .map(|j| {
            let a = 2.0 * std::f64::consts::PI * j as f64 / n as f64;
            let (c, s) = (a.cos(), a.sin());
            // Rotate a phasor sample by sample.
            let (mut re, mut im, mut pr, mut pi) = (0.0, 0.0, 1.0, 0.0);
            for v in &y {
                re += v * pr;
                im -= v * pi;
                let t = pr * c - pi * s;
                pi = pr * s + pi * c;
                pr = t;
            }
            (re * re + im * im) / norm
        })
        .collect()
}

/// `x` minus its least-squares straight line.
pub fn detrended(x: &[f64]) -> Vec<f64> {
    let n = x.len() as f64;
    let tm = (n - 1.0) / 2.0;
    let xm = x.iter().sum::<f64>() / n;
    let (mut stx, mut stt) = (0.0, 0.0);
    for (k, v) in x.iter().enumerate() {
        let t = k as f64 - tm;
        stx += t * (v - xm);
        stt += t * t;
    }
    let slope = if stt > 0.0 { stx / stt } else { 0.0 };
    x.iter()
        .enumerate()
        .map(|(k, v)| v - xm - slope * (k as f64 - tm))
        .collect()
}

/// A narrow-band line in noise (mains hum, a ground loop, an oscillating amplifier).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Line {
    /// Frequency (Hz).
    pub frequency: f64,
    /// Amplitude of the sinusoid that would give the peak (the record's unit).
    pub amplitude: f64,
    /// Peak over the local background of the periodogram.
    pub ratio: f64,
    /// Whether it lies within a frequency bin of a multiple of 50 or 60 Hz.
    pub mains: bool,
}

/// Lines in the noise record `x` (sampled at `dt`): periodogram ordinates above
/// `ln(m / alpha)` times the background (`m` ordinates tested), local maxima only, bins 2
/// and above (the lowest frequencies are the taper's and the trend's). The background is the
/// density of the record's AR noise model `noise` where one is given (a coloured spectrum
/// falls steeply and a running median would lag it), and the running median of the 32
/// neighbours otherwise (over `ln 2`, the median of exponential ordinates). A line counts
/// as mains when the frequency resolution `1 / (n dt)` is at most 12.5 Hz and it lies within
/// a bin of a multiple of 50 or 60 Hz. Needs 64 samples; returns none below.
pub fn lines(x: &[f64], dt: f64, alpha: f64, noise: Option<&ArModel>) -> Vec<Line> {
    let p = periodogram(x);
    let n = x.len().min(MAX_SPECTRUM_SAMPLES);
    if n < 64 || p.len() < 16 {
        return Vec::new();
    }
    let m = p.len() - 2;
    let threshold = (m as f64 / alpha).ln();
    let df = 1.0 / (n as f64 * dt);
    let norm_w: f64 = (0..n)
        .map(|k| (0.5 - 0.5 * (2.0 * std::f64::consts::PI * k as f64 / n as f64).cos()).powi(2))
        .sum();
    let sum_w: f64 = n as f64 / 2.0;
    let mut out = Vec::new();
    for j in 2..p.len() - 1 {
        if p[j] < p[j - 1] || p[j] < p[j + 1] {
            continue;
        }
        let background = match noise {
            Some(m) => m.density(2.0 * std::f64::consts::PI * j as f64 / n as f64),
            None => {
                let lo = j.saturating_sub(16);
                let hi = (j + 16).min(p.len() - 1);
                let mut nb: Vec<f64> = (lo..=hi)
                    .filter(|&i| i + 1 < j || i > j + 1)
                    .map(|i| p[i])
                    .collect();
                nb.sort_by(f64::total_cmp);
                // The median of exponential ordinates is ln 2 times their mean.
                nb[nb.len() / 2] / std::f64::consts::LN_2
            }
        };
        if background <= 0.0 {
            continue;
        }
        let ratio = p[j] / background;
        if ratio > threshold {
            let f = j as f64 * df;
            // A sinusoid of amplitude A gives a peak of (A sum w / 2)^2 / sum w^2.
            let amplitude = 2.0 * (p[j] * norm_w).sqrt() / sum_w;
            let mains = df <= 12.5
                && [50.0, 60.0].iter().any(|base| {
                    let h = (f / base).round();
                    h >= 1.0 && (f - h * base).abs() <= df
                });
            out.push(Line {
                frequency: f,
                amplitude,
                ratio,
                mains,
            });
        }
    }
    out
}

/// The noise of a record measured on the frequencies where a model has no content.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BandNoise {
    /// The AR(1) noise model fitted on those frequencies (Whittle likelihood).
    pub model: ArModel,
    /// Frequencies used (periodogram ordinates).
    pub bins: usize,
    /// Ordinates of the periodogram in all.
    pub of: usize,
}

/// Fewest periodogram ordinates a band estimate is made from.
pub const MIN_BAND_BINS: usize = 8;

/// The model has no content at an ordinate where its periodogram is below this fraction of
/// the test's (smoothed over five ordinates).
pub const MODEL_FREE_RATIO: f64 = 0.05;

/// The noise of `test` from the frequencies where `model` (the same channel, same time base)
/// has no content: the ordinates `j >= 1` where the model's periodogram is below
/// [`MODEL_FREE_RATIO`] times the test's (smoothed over five ordinates, so that a chance
/// high ordinate of the test does not pick itself), and on those an AR(1) density
/// `S(omega) = sigma_w^2 / (1 - 2 phi cos omega + phi^2)` fitted by the Whittle likelihood
/// `sum_j ln S(omega_j) + I_j / S(omega_j)` (`phi` on a grid of 0.005 in `[-0.95, 0.95]`,
/// `sigma_w^2` in closed form); the noise's variance is `sigma_w^2 / (1 - phi^2)`. With
/// fewer than [`MIN_BAND_BINS`] such ordinates the record has no usable band: `None`.
///
/// The AR(1) shape is what the band can support: a few high frequencies fix a level and a
/// slope, not a higher-order spectrum. `test` and `model` must have equal lengths.
pub fn noise_from_band(test: &[f64], model: &[f64]) -> Option<BandNoise> {
    if test.len() != model.len() || test.len() < 16 {
        return None;
    }
    let pt = periodogram(test);
    let pm = periodogram(model);
    let n = test.len().min(MAX_SPECTRUM_SAMPLES);
    let smooth: Vec<f64> = (0..pt.len())
        .map(|j| {
            let lo = j.saturating_sub(2);
            let hi = (j + 2).min(pt.len() - 1);
            pt[lo..=hi].iter().sum::<f64>() / (hi - lo + 1) as f64
        })
        .collect();
    let bins: Vec<usize> = (1..pt.len())
        .filter(|&j| pm[j] < MODEL_FREE_RATIO * smooth[j])
        .collect();
    if bins.len() < MIN_BAND_BINS {
        return None;
    }
    let omega = |j: usize| 2.0 * std::f64::consts::PI * j as f64 / n as f64;
    let mut best: Option<(f64, f64, f64)> = None;
    for step in -190..=190 {
        let phi = step as f64 * 0.005;
        let g = |j: usize| 1.0 / (1.0 - 2.0 * phi * omega(j).cos() + phi * phi);
        let s2 = bins.iter().map(|&j| pt[j] / g(j)).sum::<f64>() / bins.len() as f64;
        if s2 <= 0.0 {
            return None;
        }
        let nll = bins.len() as f64 * s2.ln() + bins.iter().map(|&j| g(j).ln()).sum::<f64>();
        if best.is_none_or(|b| nll < b.0) {
            best = Some((nll, phi, s2));
        }
    }
    let (_, phi, s2) = best?;
    let mut model = ArModel::ar1(phi, (s2 / (1.0 - phi * phi)).sqrt());
    model.samples = test.len();
    Some(BandNoise {
        model,
        bins: bins.len(),
        of: pt.len() - 1,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn white_noise_periodogram_has_its_variance_and_a_planted_line_is_found() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let dt = 1e-4;
        let mut x = ArModel::white(0.5).generate(4000, &mut rng);
        let p = periodogram(&x);
        let mean = p[5..].iter().sum::<f64>() / (p.len() - 5) as f64;
        assert!((mean - 0.25).abs() < 0.02, "{mean}");
        assert!(
            lines(&x, dt, 0.01, None).is_empty(),
            "{:?}",
            lines(&x, dt, 0.01, None)
        );
        // 0.3 amplitude of 50 Hz hum on 0.5 noise: one line, at 50 Hz, amplitude ~0.3.
        for (k, v) in x.iter_mut().enumerate() {
            *v += 0.3 * (2.0 * std::f64::consts::PI * 50.0 * k as f64 * dt).sin();
        }
        let l = lines(&x, dt, 0.01, None);
        assert_eq!(l.len(), 1, "{l:?}");
        assert!((l[0].frequency - 50.0).abs() <= 2.5, "{l:?}");
        assert!((l[0].amplitude - 0.3).abs() < 0.06, "{l:?}");
        assert!(l[0].mains);
    }

    #[test]
    fn the_band_fit_recovers_white_and_coloured_noise_above_a_low_pass_signal() {
        let n = 1000;
        let signal: Vec<f64> = (0..n)
            .map(|k| {
                let t = k as f64 / n as f64;
                300.0 - 400.0 * t + 50.0 * (2.0 * std::f64::consts::PI * 3.0 * t).sin()
            })
            .collect();
        for (phi, seed) in [(0.0, 1), (0.8, 2), (0.5, 3)] {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let noise = ArModel::ar1(phi, 2.0).generate(n, &mut rng);
            let test: Vec<f64> = signal.iter().zip(&noise).map(|(a, b)| a + b).collect();
            let b = noise_from_band(&test, &signal).unwrap();
            assert!((b.model.sigma() - 2.0).abs() < 0.2, "phi {phi}: {b:?}");
            assert!(
                (b.model.coefficients[0] - phi).abs() < 0.1,
                "phi {phi}: {b:?}"
            );
        }
    }
}
