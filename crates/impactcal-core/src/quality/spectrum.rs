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
use crate::error::{CoreError, Result};
use crate::signal::Cfc;
use statrs::distribution::{ChiSquared, ContinuousCDF};

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

/// Samples of one segment of the band estimate's averaged periodogram
/// ([`segment_periodogram`]).
pub const BAND_SEGMENT: usize = 1024;

/// The mean of the Hann periodograms ([`periodogram`]) of `ceil(n / seg)` segments of
/// `seg = min(n, BAND_SEGMENT)` samples spread evenly from the first sample to the last
/// (overlapping where `seg` does not divide `n`), ordinates `j = 0 .. seg/2`; and the
/// number of segments. One segment (the whole record) for `n <= BAND_SEGMENT`.
pub fn segment_periodogram(x: &[f64]) -> (Vec<f64>, usize) {
    let n = x.len();
    let seg = n.min(BAND_SEGMENT);
    if seg < 4 {
        return (Vec::new(), 0);
    }
    let k = n.div_ceil(seg);
    let mut sum = vec![0.0; seg / 2 + 1];
    for i in 0..k {
        let first = if k == 1 { 0 } else { i * (n - seg) / (k - 1) };
        for (s, v) in sum.iter_mut().zip(periodogram(&x[first..first + seg])) {
            *s += v;
        }
    }
    sum.iter_mut().for_each(|v| *v /= k as f64);
    (sum, k)
}

/// The noise of a test measured on the band above a model ensemble's bandwidth.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BandNoise {
    /// Standard deviation of the flat noise before the filter (the record's unit).
    pub level: f64,
    /// The noise as compared (after the filter): an AR model by BIC fitted to white noise
    /// of standard deviation `level` passed through the filter (white itself without one).
    pub model: ArModel,
    /// The highest ordinate at which a member of the ensemble has content.
    pub edge: usize,
    /// The band's first ordinate.
    pub first: usize,
    /// Ordinates in the band.
    pub bins: usize,
    /// Ordinates of the periodogram in all (`seg / 2`).
    pub of: usize,
    /// The flatness statistic `Z` of the band (see [`noise_from_band`]): about standard
    /// normal for flat noise.
    pub flatness: f64,
}

/// Why a record has no band to measure its noise on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "reason", rename_all = "kebab-case")]
pub enum BandRefusal {
    /// Too few samples for a spectrum.
    TooShort {
        /// Samples of the record.
        samples: usize,
    },
    /// The filter passes fewer than twice [`MIN_BAND_BINS`] ordinates: no room for a band
    /// above any content.
    Filtered {
        /// The highest ordinate the filter passes (power response at least `1e-3`).
        top: usize,
        /// Ordinates in all.
        of: usize,
    },
    /// Fewer than [`MIN_BAND_BINS`] ordinates lie between a quarter above the highest
    /// content of a member and the top of the usable spectrum (the filter's stop band).
    NoFreeBand {
        /// The highest ordinate with content of a member.
        edge: usize,
        /// The highest usable ordinate (above it the filter's power response is below
        /// `1e-3`).
        top: usize,
        /// Ordinates in all.
        of: usize,
    },
    /// The test's spectrum over the band is not flat: content the ensemble lacks, or
    /// coloured noise, which the band cannot tell apart.
    NotFlat {
        /// The band's first ordinate.
        first: usize,
        /// The flatness statistic (beyond `+-` [`FLATNESS_LIMIT`]).
        flatness: f64,
    },
    /// A narrow line stands out of the band (a mode the ensemble lacks, or hum).
    Line {
        /// Its ordinate.
        bin: usize,
        /// Its ratio to the flat level.
        ratio: f64,
    },
}

impl std::fmt::Display for BandRefusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BandRefusal::TooShort { samples } => {
                write!(f, "{samples} samples are too few for a spectrum")
            }
            BandRefusal::Filtered { top, of } => write!(
                f,
                "the filter passes only ordinates up to {top} of {of}: too few for a band"
            ),
            BandRefusal::NoFreeBand { edge, top, of } => write!(
                f,
                "the model ensemble has content above the noise up to ordinate {edge} of {of}, \
                 and the filter passes up to ordinate {top}: no band between"
            ),
            BandRefusal::NotFlat { first, flatness } => write!(
                f,
                "the test's spectrum above ordinate {first} is not flat (statistic {flatness:.1}): \
                 content the ensemble lacks or coloured noise"
            ),
            BandRefusal::Line { bin, ratio } => write!(
                f,
                "a line at ordinate {bin} stands {ratio:.0} times above the band's level"
            ),
        }
    }
}

/// Fewest periodogram ordinates a band estimate is made from.
pub const MIN_BAND_BINS: usize = 8;

/// A member of the ensemble has content at an ordinate where its periodogram reaches this
/// fraction of the noise's density there.
pub const MODEL_FREE_RATIO: f64 = 0.05;

/// The band starts this factor above the ensemble's edge.
pub const BAND_GUARD: f64 = 1.25;

/// Two-sided 1 % limit of the flatness statistic (standard normal).
pub const FLATNESS_LIMIT: f64 = 2.576;

/// Variance of the mean of `m` Hann periodogram ordinates of white noise, times `m`:
/// neighbouring ordinates correlate by `|sum w_k^2 e^{2 pi i k / n}|^2 / (sum w_k^2)^2`,
/// `(2/3)^2` at one ordinate and `(1/6)^2` at two, so `1 + 2 (4/9 + 1/36)`.
pub const HANN_VARIANCE_FACTOR: f64 = 1.0 + 2.0 * (4.0 / 9.0 + 1.0 / 36.0);

/// Ordinates where the filter's power response is below this are not used (the filter's
/// stop band, where leakage of the passband's content dominates).
const STOP_BAND: f64 = 1e-3;

/// The noise of `test` measured on the band above the bandwidth of a model ensemble, for a
/// test whose noise is flat (white) before the filter `cfc` that both the test and the
/// members went through (`None`: no filter); `members` are the same channel of every run
/// of the ensemble on the test's samples, `dt` the step.
///
/// Model-form error lives where the model's physics acts: a missing effect reshapes the
/// response within the bandwidth the model's parameters reach, so the band must lie above
/// the content of *every* member (not the nominal run alone), where no parameter set of
/// the model puts anything, and measurement noise is then all that remains. With `T_j` the
/// test's periodogram ([`segment_periodogram`]), `P_ij` the members', `G_j` the filter's
/// power response ([`crate::Cfc::power_response`], 1 without one) and the flat level
/// `s^2`:
///
/// 1. starting from the top quarter of the usable ordinates (`G_j >= 1e-3`), `s^2 =
///    mean_band T_j / G_j` (the Whittle estimate of a known shape); the ensemble's edge
///    `e` is the highest ordinate where some member reaches `max_i P_ij >=`
///    [`MODEL_FREE_RATIO`] `s^2 G_j` (a member below it biases `s^2` by less than 5 %);
///    the band is `ceil(BAND_GUARD e) + 1 ..` the top (a quarter above the edge: content
///    moved that far beyond every member's would take a structure 1.56 times stiffer than
///    the stiffest the parameters allow); repeated until the band stays put;
/// 2. the band must be flat: the normalised ordinates `u_j = T_j / (s^2 G_j)` (mean 1,
///    variance 1 for flat noise) must not trend with `c_j = cos omega_j`, the score
///    statistic of an AR(1) colour `phi` at `phi = 0` (`ln S = -ln(1 - 2 phi cos omega +
///    phi^2)` has slope `2 cos omega` there):
///    `Z = sum (c_j - c) u_j / sqrt(HANN_VARIANCE_FACTOR sum (c_j - c)^2 / K)` (`c` the mean
///    of the `c_j`, `K` segments) within `+-` [`FLATNESS_LIMIT`]. Coloured noise, and
///    content the ensemble lacks just above its edge, raise the band's low end;
/// 3. and hold no line: no `u_j` above the `1 - 0.01 / m` quantile of `chi^2_{2K} / 2K`
///    (the mean of `K` exponential ordinates; `ln(m / 0.01)` for one segment), which the
///    largest of `m` ordinates of flat noise exceeds with probability about 1 %.
///
/// The noise as compared is then white noise of standard deviation `s` through the filter;
/// its AR model (order by BIC, at most 10) is fitted on 16 384 seeded samples of that.
///
/// # Errors
/// The outer error: [`CoreError::DimensionMismatch`] when a member's length differs from
/// the test's; the filter's errors for a step it cannot serve. The inner one: why there is
/// no band ([`BandRefusal`]).
pub fn noise_from_band(
    test: &[f64],
    members: &[&[f64]],
    dt: f64,
    cfc: Option<Cfc>,
) -> Result<std::result::Result<BandNoise, BandRefusal>> {
    let mut envelope = MemberEnvelope::new(test.len());
    for m in members {
        envelope.add(m)?;
    }
    noise_above_envelope(test, &envelope, dt, cfc)
}

/// The largest periodogram ordinate ([`segment_periodogram`]) of an ensemble's members
/// at every frequency, `max_i P_ij`, built one member at a time so that an ensemble read
/// run by run is never held whole: `floor(min(n, BAND_SEGMENT) / 2) + 1` numbers for members of `n`
/// samples, whatever the number of members.
#[derive(Debug, Clone, PartialEq)]
pub struct MemberEnvelope {
    samples: usize,
    max: Vec<f64>,
}

impl MemberEnvelope {
    /// An envelope of no member yet, for members of `samples` samples (all ordinates 0).
    pub fn new(samples: usize) -> Self {
        let seg = samples.min(BAND_SEGMENT);
        MemberEnvelope {
            samples,
            max: vec![0.0; seg / 2 + 1],
        }
    }

    /// Takes in one member.
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`] when the member's length is not the envelope's.
    pub fn add(&mut self, member: &[f64]) -> Result<()> {
        if member.len() != self.samples {
            return Err(CoreError::DimensionMismatch {
                what: "samples of a member of the ensemble against the test's".into(),
                expected: self.samples,
                found: member.len(),
            });
        }
        for (a, b) in self.max.iter_mut().zip(segment_periodogram(member).0) {
            *a = a.max(b);
        }
        Ok(())
    }
}

/// [`noise_from_band`] with the members given by their [`MemberEnvelope`] (all it uses of
/// them).
///
/// # Errors
/// As [`noise_from_band`]: [`CoreError::DimensionMismatch`] when the envelope's members
/// are not of the test's length; the filter's errors.
pub fn noise_above_envelope(
    test: &[f64],
    envelope: &MemberEnvelope,
    dt: f64,
    cfc: Option<Cfc>,
) -> Result<std::result::Result<BandNoise, BandRefusal>> {
    if envelope.samples != test.len() {
        return Err(CoreError::DimensionMismatch {
            what: "samples of a member of the ensemble against the test's".into(),
            expected: test.len(),
            found: envelope.samples,
        });
    }
    let (pt, k) = segment_periodogram(test);
    if pt.len() < 2 * MIN_BAND_BINS {
        return Ok(Err(BandRefusal::TooShort {
            samples: test.len(),
        }));
    }
    let seg = test.len().min(BAND_SEGMENT);
    let of = pt.len() - 1;
    let omega = |j: usize| 2.0 * std::f64::consts::PI * j as f64 / seg as f64;
    let gain: Vec<f64> = match cfc {
        Some(c) => (0..=of)
            .map(|j| c.power_response(omega(j), dt))
            .collect::<Result<_>>()?,
        None => vec![1.0; of + 1],
    };
    // Usable: ordinates 1 .. the last above the stop band.
    let top = (1..=of).rev().find(|&j| gain[j] >= STOP_BAND).unwrap_or(0);
    if top < 2 * MIN_BAND_BINS {
        return Ok(Err(BandRefusal::Filtered { top, of }));
    }
    let pm = &envelope.max;
    let level = |first: usize| {
        (first..=top).map(|j| pt[j] / gain[j]).sum::<f64>() / (top + 1 - first) as f64
    };
    let mut first = top + 1 - (top / 4).max(MIN_BAND_BINS);
    let mut edge = 0;
    for _ in 0..20 {
        let s2 = level(first);
        edge = (1..=top)
            .rev()
            .find(|&j| pm[j] >= MODEL_FREE_RATIO * s2 * gain[j])
            .unwrap_or(0);
        let next = ((BAND_GUARD * edge as f64).ceil() as usize + 1).max(1);
        if next + MIN_BAND_BINS > top + 1 {
            return Ok(Err(BandRefusal::NoFreeBand { edge, top, of }));
        }
        if next == first {
            break;
        }
        first = next;
    }
    let s2 = level(first);
    if s2 <= 0.0 {
        return Ok(Err(BandRefusal::NoFreeBand { edge, top, of }));
    }
    let u: Vec<f64> = (first..=top).map(|j| pt[j] / (s2 * gain[j])).collect();
    let m = u.len();
    let c: Vec<f64> = (first..=top).map(|j| omega(j).cos()).collect();
    let cm = c.iter().sum::<f64>() / m as f64;
    let scc: f64 = c.iter().map(|v| (v - cm).powi(2)).sum();
    let flatness = c.iter().zip(&u).map(|(a, b)| (a - cm) * b).sum::<f64>()
        / (HANN_VARIANCE_FACTOR * scc / k as f64).sqrt();
    if flatness.is_nan() || flatness.abs() > FLATNESS_LIMIT {
        return Ok(Err(BandRefusal::NotFlat { first, flatness }));
    }
    // The mean of K exponential ordinates is chi^2_{2K} / 2K: its 1 - 0.01 / m quantile.
    let line_limit = ChiSquared::new(2.0 * k as f64)
        .map(|d| d.inverse_cdf(1.0 - 0.01 / m as f64) / (2.0 * k as f64))
        .unwrap_or(f64::INFINITY);
    if let Some((i, &r)) = u
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .filter(|(_, r)| **r > line_limit)
    {
        return Ok(Err(BandRefusal::Line {
            bin: first + i,
            ratio: r,
        }));
    }
    let model = match cfc {
        None => ArModel::white(s2.sqrt()),
        Some(c) => filtered_white(s2.sqrt(), dt, c)?,
    };
    Ok(Ok(BandNoise {
        level: s2.sqrt(),
        model,
        edge,
        first,
        bins: m,
        of,
        flatness,
    }))
}

/// White noise of standard deviation `sigma` through `cfc` at step `dt`, as an AR model by
/// BIC (order at most [`super::ar::DEFAULT_MAX_ORDER`]) fitted on 16 384 seeded samples.
///
/// # Errors
/// The filter's errors for a step it cannot serve.
pub fn filtered_white(sigma: f64, dt: f64, cfc: Cfc) -> Result<ArModel> {
    use rand::SeedableRng;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x0b5e_55ed);
    let x = ArModel::white(1.0).generate(16_384, &mut rng);
    let y = cfc.filter(&x, dt, "white reference sequence")?;
    let mut m = ArModel::fit(&y, super::ar::DEFAULT_MAX_ORDER)?;
    let scale = sigma * sigma;
    m.innovation_variance *= scale;
    m.variance *= scale;
    Ok(m)
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

    /// A low-pass "model" of three modes below 250 Hz at 10 kHz, at stiffness `k`.
    fn member(k: f64, n: usize) -> Vec<f64> {
        (0..n)
            .map(|i| {
                let t = i as f64 * 1e-4;
                [(60.0, 300.0), (140.0, 80.0), (230.0, 30.0)]
                    .iter()
                    .map(|(f, a)| {
                        let w = 2.0 * std::f64::consts::PI * f * k.sqrt();
                        a * (-0.05 * w * t).exp() * (w * t).sin()
                    })
                    .sum::<f64>()
            })
            .collect()
    }

    #[test]
    fn the_band_measures_flat_noise_and_refuses_colour_and_what_the_ensemble_lacks() {
        let n = 1000;
        let members: Vec<Vec<f64>> = (0..9).map(|i| member(0.8 + 0.05 * i as f64, n)).collect();
        let refs: Vec<&[f64]> = members.iter().map(Vec::as_slice).collect();
        let truth = member(1.03, n);
        let with = |noise: &[f64], extra: &dyn Fn(usize) -> f64| -> Vec<f64> {
            (0..n).map(|i| truth[i] + noise[i] + extra(i)).collect()
        };
        let cfc = Cfc::Cfc1000;
        for seed in 0..10 {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let e = ArModel::white(2.0).generate(n, &mut rng);
            // Raw: the flat level is the noise's.
            let b = noise_from_band(&with(&e, &|_| 0.0), &refs, 1e-4, None)
                .unwrap()
                .unwrap();
            assert!((b.model.sigma() / 2.0 - 1.0).abs() < 0.1, "{b:?}");
            assert!(b.edge < b.first && b.first < b.of / 2, "{b:?}");
            // Through CFC 1000 (test and members alike): the noise as compared is the
            // filtered white noise, its standard deviation and lag-one correlation.
            let f = |x: &[f64]| cfc.filter(x, 1e-4, "x").unwrap();
            let fe = f(&e);
            let fm: Vec<Vec<f64>> = members.iter().map(|m| f(m)).collect();
            let frefs: Vec<&[f64]> = fm.iter().map(Vec::as_slice).collect();
            let b = noise_from_band(&f(&with(&e, &|_| 0.0)), &frefs, 1e-4, Some(cfc))
                .unwrap()
                .unwrap();
            let sd = (fe.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
            assert!((b.model.sigma() / sd - 1.0).abs() < 0.15, "{b:?} {sd}");
            assert!((b.model.lag1() - super::super::ar::lag1(&fe)).abs() < 0.1);
            // A mode the ensemble lacks inside its bandwidth (at 180 Hz) changes nothing.
            let inside =
                |i: usize| 60.0 * (2.0 * std::f64::consts::PI * 180.0 * i as f64 * 1e-4).sin();
            let c = noise_from_band(&with(&e, &inside), &refs, 1e-4, None)
                .unwrap()
                .unwrap();
            assert!((c.model.sigma() / 2.0 - 1.0).abs() < 0.1, "{c:?}");
            // One just above the ensemble's edge (a decaying 1.2 kHz ring the ensemble lacks)
            // is not noise: refused.
            let above = |i: usize| {
                let t = i as f64 * 1e-4;
                20.0 * (-t / 0.02).exp() * (2.0 * std::f64::consts::PI * 1200.0 * t).sin()
            };
            let r = noise_from_band(&with(&e, &above), &refs, 1e-4, None).unwrap();
            assert!(
                matches!(
                    r,
                    Err(BandRefusal::NotFlat { .. } | BandRefusal::Line { .. })
                ),
                "{r:?}"
            );
            // AR(1) noise of lag-one correlation 0.8 is not flat: refused.
            let red = ArModel::ar1(0.8, 2.0).generate(n, &mut rng);
            let r = noise_from_band(&with(&red, &|_| 0.0), &refs, 1e-4, None).unwrap();
            assert!(matches!(r, Err(BandRefusal::NotFlat { .. })), "{r:?}");
        }
        // A noiseless test from the model: no band (the ensemble has content wherever the
        // test has).
        let r = noise_from_band(&truth, &refs, 1e-4, None).unwrap();
        assert!(matches!(r, Err(BandRefusal::NoFreeBand { .. })), "{r:?}");
        // Members of another length are an error of the caller.
        assert!(noise_from_band(&truth, &[&truth[..10]], 1e-4, None).is_err());
        assert!(matches!(
            noise_from_band(&truth[..20], &[&truth[..20]], 1e-4, None).unwrap(),
            Err(BandRefusal::TooShort { .. })
        ));
    }
}
