//! Quality checks of measured data, before any comparison uses it.
//!
//! Per channel of a record ([`check`]):
//!
//! - **offset and noise** on the quiet part before the trigger (given as a time, or found
//!   from the record: [`faults::quiet_end`]): the mean (`offset`), the standard deviation
//!   about it (`noise_std`), the lag-one autocorrelation (`lag1`), an AR noise model with
//!   its order chosen by BIC ([`ArModel`]), whether the noise is white (Ljung-Box at the
//!   1 % level over `min(20, n / 5)` lags), and narrow-band lines such as mains hum
//!   ([`spectrum::lines`]). A record without a quiet part gets its noise from second
//!   differences (`1.4826 median |x_{k+1} - 2 x_k + x_{k-1}| / sqrt 6`, the standard
//!   deviation of white noise; low for coloured noise) and no offset.
//! - **clipped runs** at the channel's own extremes, found without the rails
//!   ([`faults::clipped_runs`]);
//! - **spikes**, isolated outliers against a robust local scale ([`faults::spikes`]);
//! - **drift** of accelerations: the velocity change the record implies after the event,
//!   against what the pre-trigger noise allows ([`faults::drift`]);
//! - and for the file, **gaps or repeated time stamps** ([`faults::time_faults`]).
//!
//! The masks ([`RecordQuality::mask_on`]) take clipped samples and spikes out of every
//! residual, and [`RecordQuality::repaired`] removes the offsets and bridges masked samples
//! linearly (so that a filter does not spread a spike over its neighbours).
//!
//! ```
//! use impactcal_core::Histories;
//! use impactcal_core::quality::{QualityOptions, check};
//!
//! // A quiet start, then a pulse; sample 300 carries a spike.
//! let mut x: Vec<f64> = (0..400)
//!     .map(|k| 0.01 * ((k * 7919 % 13) as f64 - 6.0) + if k >= 200 { ((k - 200) as f64 * 0.05).sin() } else { 0.0 })
//!     .collect();
//! x[300] += 5.0;
//! let h = Histories::from_channels(vec!["a".into()], vec![x], 1e-4, 0.0, "")?;
//! let q = check(&h, &QualityOptions { pre_trigger: Some(0.015), ..Default::default() })?;
//! assert_eq!(q.channels[0].spike_spans, vec![[300, 300]]);
//! assert!(q.channels[0].clipped.is_empty());
//! # Ok::<(), impactcal_core::CoreError>(())
//! ```

pub mod ar;
pub mod faults;
pub mod spectrum;

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{CoreError, ParamGuard, Result};
use crate::histories::Histories;
use crate::table::{Table, TableOptions};

pub use ar::{ArModel, LjungBox, ljung_box};
pub use faults::{ClipRun, Drift, TimeFault};
pub use spectrum::{
    BandNoise, BandRefusal, Line, MemberEnvelope, filtered_white, noise_above_envelope,
    noise_from_band,
};

/// Level of the whiteness test and of the line search.
pub const ALPHA: f64 = 0.01;

/// Which channels hold accelerations (their drift is checked).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Accelerations {
    /// Channels whose label says so: it contains `acc` (any case), or is an ISO-MME code
    /// with the physical dimension `AC` (characters 13-14).
    #[default]
    ByLabel,
    /// Every channel.
    All,
    /// None.
    None,
    /// These labels.
    Labels(Vec<String>),
}

impl Accelerations {
    /// Whether the channel `label` holds an acceleration.
    pub fn holds(&self, label: &str) -> bool {
        match self {
            Accelerations::ByLabel => {
                label.to_ascii_lowercase().contains("acc")
                    || (label.len() >= 16 && label.get(12..14) == Some("AC"))
            }
            Accelerations::All => true,
            Accelerations::None => false,
            Accelerations::Labels(l) => l.iter().any(|x| x == label),
        }
    }
}

/// Options of [`check`].
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct QualityOptions {
    /// The samples before this time are the quiet part; `None`: found from each channel.
    pub pre_trigger: Option<f64>,
    /// Which channels are accelerations.
    pub accelerations: Accelerations,
}

/// Where a channel's noise level came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NoiseSource {
    /// The quiet part before the trigger.
    PreTrigger,
    /// Second differences of the whole record (no quiet part).
    Differences,
}

/// The quality of one channel. Times are the record's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelQuality {
    /// The channel.
    pub label: String,
    /// Mean of the quiet part (`None` without one).
    pub offset: Option<f64>,
    /// Standard deviation of the noise.
    pub noise_std: f64,
    /// Lag-one autocorrelation of the noise.
    pub lag1: f64,
    /// Whether the quiet part passes the Ljung-Box test at [`ALPHA`] (false without one).
    pub white: bool,
    /// The Ljung-Box test of the quiet part.
    pub ljung_box: Option<LjungBox>,
    /// The AR noise model of the quiet part (order by BIC).
    pub noise_model: Option<ArModel>,
    /// Where the noise level came from.
    pub noise_source: NoiseSource,
    /// Samples of the quiet part (0 without one).
    pub quiet_samples: usize,
    /// Lines in the quiet part's spectrum.
    pub lines: Vec<Line>,
    /// Clipped runs, `[t_first, t_last, level]`.
    pub clipped: Vec<[f64; 3]>,
    /// Clipped runs by sample, with how much of the signal each cut.
    pub clipped_runs: Vec<ClipRun>,
    /// Times of the spikes (their largest sample).
    pub spikes: Vec<f64>,
    /// Samples of the spikes, `[first, last]` (one to three samples each).
    pub spike_spans: Vec<[usize; 2]>,
    /// Drift of an acceleration (`None` for other channels or a record too short).
    pub drift: Option<Drift>,
}

/// The quality of a record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecordQuality {
    /// Time of the first sample.
    pub start: f64,
    /// Sample interval.
    pub dt: f64,
    /// Samples per channel.
    pub samples: usize,
    /// The pre-trigger time given (`None`: found per channel).
    pub pre_trigger: Option<f64>,
    /// Faults of the time column (empty for a record made on a uniform base).
    pub time_faults: Vec<TimeFault>,
    /// Per channel.
    pub channels: Vec<ChannelQuality>,
}

impl ParamGuard for QualityOptions {
    type Checked = QualityOptions;

    /// Checks the options on their own (a pre-trigger time is checked against the record
    /// by [`check`]).
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for a `pre-trigger` time that is not finite, or an
    /// empty label among the `accelerations`.
    fn check_ref(&self) -> Result<()> {
        if let Some(t) = self.pre_trigger
            && !t.is_finite()
        {
            return Err(CoreError::invalid_option(
                "pre-trigger",
                t,
                "must be a finite time (s)",
            ));
        }
        if let Accelerations::Labels(labels) = &self.accelerations
            && labels.iter().any(|l| l.trim().is_empty())
        {
            return Err(CoreError::invalid_option(
                "accelerations",
                "\"\"",
                "a channel label is empty",
            ));
        }
        Ok(())
    }

    fn check(self) -> Result<QualityOptions> {
        self.check_ref()?;
        Ok(self)
    }
}

/// Checks every channel of `h` (see the module docs).
///
/// # Errors
/// [`ParamGuard::check_ref`]'s errors for the options; [`CoreError::InvalidOption`] for a
/// pre-trigger time that leaves fewer than [`faults::MIN_QUIET`] samples before it.
pub fn check(h: &Histories, options: &QualityOptions) -> Result<RecordQuality> {
    options.check_ref()?;
    let n = h.samples();
    let quiet_given = match options.pre_trigger {
        None => None,
        Some(t) => {
            let k = ((t - h.start()) / h.dt() - 1e-9).ceil().max(0.0) as usize;
            if k < faults::MIN_QUIET || k > n {
                return Err(CoreError::invalid_option(
                    "pre-trigger",
                    t,
                    format!(
                        "leaves {} samples before it (the record starts at {} s with a step of \
                         {} s); at least {} are needed",
                        k.min(n),
                        h.start(),
                        h.dt(),
                        faults::MIN_QUIET
                    ),
                ));
            }
            Some(k)
        }
    };
    let channels = (0..h.channels())
        .map(|c| channel(h, c, quiet_given, options))
        .collect::<Result<_>>()?;
    Ok(RecordQuality {
        start: h.start(),
        dt: h.dt(),
        samples: n,
        pre_trigger: options.pre_trigger,
        time_faults: Vec::new(),
        channels,
    })
}

fn channel(
    h: &Histories,
    c: usize,
    quiet_given: Option<usize>,
    options: &QualityOptions,
) -> Result<ChannelQuality> {
    let x = h.channel(c);
    let label = h.labels()[c].clone();
    let time = |k: usize| h.start() + k as f64 * h.dt();
    let quiet = quiet_given.or_else(|| faults::quiet_end(x)).unwrap_or(0);
    let mut q = ChannelQuality {
        label: label.clone(),
        offset: None,
        noise_std: 0.0,
        lag1: 0.0,
        white: false,
        ljung_box: None,
        noise_model: None,
        noise_source: NoiseSource::Differences,
        quiet_samples: 0,
        lines: Vec::new(),
        clipped: Vec::new(),
        clipped_runs: Vec::new(),
        spikes: Vec::new(),
        spike_spans: Vec::new(),
        drift: None,
    };
    if quiet >= faults::MIN_QUIET {
        let part = &x[..quiet];
        let mean = part.iter().sum::<f64>() / quiet as f64;
        let var = part.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (quiet - 1) as f64;
        q.offset = Some(mean);
        q.noise_std = var.sqrt();
        q.lag1 = ar::lag1(part);
        q.quiet_samples = quiet;
        q.noise_source = NoiseSource::PreTrigger;
        if var > 0.0 {
            let lags = 20.min(quiet / 5);
            let lb = ljung_box(part, lags, 0)?;
            q.white = lb.p_value >= ALPHA;
            q.ljung_box = Some(lb);
            let model = ArModel::fit(part, ar::DEFAULT_MAX_ORDER)?;
            q.lines = spectrum::lines(part, h.dt(), ALPHA, Some(&model));
            q.noise_model = Some(model);
        }
    } else if x.len() >= 3 {
        let d2: Vec<f64> = x.windows(3).map(|w| w[2] - 2.0 * w[1] + w[0]).collect();
        q.noise_std = faults::robust_scale(&d2) / 6f64.sqrt();
    }
    q.clipped_runs = faults::clipped_runs(x, q.noise_std);
    q.clipped = q
        .clipped_runs
        .iter()
        .map(|r| [time(r.first), time(r.last), r.level])
        .collect();
    let clipped_at = |k: usize| {
        q.clipped_runs
            .iter()
            .any(|r| (r.first..=r.last).contains(&k))
    };
    q.spike_spans = faults::spikes(x, q.noise_std)
        .into_iter()
        .filter(|&(a, b)| !(a..=b).any(clipped_at))
        .map(|(a, b)| [a, b])
        .collect();
    let base = q.offset.unwrap_or_else(|| faults::median(x));
    q.spikes = q
        .spike_spans
        .iter()
        .map(|&[a, b]| {
            let peak = (a..=b)
                .max_by(|&i, &j| (x[i] - base).abs().total_cmp(&(x[j] - base).abs()))
                .unwrap_or(a);
            time(peak)
        })
        .collect();
    if options.accelerations.holds(&label) && q.offset.is_some() {
        let clean = bridged(x, &q.masked_spans());
        q.drift = faults::drift(
            &clean,
            h.dt(),
            h.start(),
            quiet,
            q.offset.unwrap_or(0.0),
            q.noise_std,
            q.lag1,
        );
    }
    Ok(q)
}

impl ChannelQuality {
    /// The masked samples, as inclusive spans `(first, last)`: clipped runs and spikes.
    pub fn masked_spans(&self) -> Vec<(usize, usize)> {
        let mut s: Vec<(usize, usize)> = self
            .clipped_runs
            .iter()
            .map(|r| (r.first, r.last))
            .chain(self.spike_spans.iter().map(|&[a, b]| (a, b)))
            .collect();
        s.sort_unstable();
        s
    }

    /// Masked samples in all.
    pub fn masked_count(&self) -> usize {
        self.masked_spans().iter().map(|(a, b)| b - a + 1).sum()
    }

    /// One line per finding, for a person.
    pub fn findings(&self) -> Vec<String> {
        let mut out = Vec::new();
        let l = &self.label;
        match self.offset {
            Some(o) => out.push(format!(
                "{l}: offset {o:.6e}, noise std {:.3e} (lag-one correlation {:.2}, {}, AR({}) \
                 by BIC) on {} pre-trigger samples",
                self.noise_std,
                self.lag1,
                if self.white { "white" } else { "coloured" },
                self.noise_model.as_ref().map_or(0, ArModel::order),
                self.quiet_samples
            )),
            None => out.push(format!(
                "{l}: no quiet part before the event (give --pre-trigger); noise std {:.3e} \
                 from second differences (white-noise reading)",
                self.noise_std
            )),
        }
        for line in &self.lines {
            out.push(format!(
                "{l}: line at {:.1} Hz, amplitude {:.3e}{}",
                line.frequency,
                line.amplitude,
                if line.mains { " (mains)" } else { "" }
            ));
        }
        for (r, c) in self.clipped_runs.iter().zip(&self.clipped) {
            out.push(format!(
                "{l}: clipped at {:.6e} from {:.6e} s to {:.6e} s ({} samples; it met the \
                 level at a step of {:.3e})",
                c[2],
                c[0],
                c[1],
                r.last - r.first + 1,
                r.step
            ));
        }
        for (t, [a, b]) in self.spikes.iter().zip(&self.spike_spans) {
            out.push(format!("{l}: spike at {t:.6e} s ({} sample(s))", b - a + 1));
        }
        if let Some(d) = &self.drift {
            out.push(format!(
                "{l}: {} velocity change {:.3e} after {:.6e} s (noise allows {:.3e})",
                if d.significant { "drift:" } else { "no drift:" },
                d.velocity_change,
                d.tail_start,
                d.allowed
            ));
        }
        out
    }
}

impl RecordQuality {
    /// One line per finding over the record.
    pub fn findings(&self) -> Vec<String> {
        let mut out: Vec<String> = self
            .time_faults
            .iter()
            .map(|f| match f {
                TimeFault::Repeated { sample, time } => {
                    format!("time: stamp {time} repeated at sample {sample} (row dropped)")
                }
                TimeFault::Backwards {
                    sample,
                    time,
                    previous,
                } => format!(
                    "time: stamp {time} at sample {sample} goes back from {previous} (row dropped)"
                ),
                TimeFault::Gap {
                    from, to, missing, ..
                } => format!(
                    "time: gap from {from} to {to} ({missing} samples missing; resampled \
                     linearly across it)"
                ),
            })
            .collect();
        for c in &self.channels {
            out.extend(c.findings());
        }
        out
    }

    /// The quality of channel `label`.
    pub fn channel(&self, label: &str) -> Option<&ChannelQuality> {
        self.channels.iter().find(|c| c.label == label)
    }

    /// Masked samples over all channels.
    pub fn masked_count(&self) -> usize {
        self.channels.iter().map(ChannelQuality::masked_count).sum()
    }

    /// `h` (the record checked) with each channel's offset removed and its masked samples
    /// bridged linearly between their unmasked neighbours.
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`] when `h` is not the record checked (other labels or
    /// length).
    pub fn repaired(&self, h: &Histories) -> Result<Histories> {
        if h.samples() != self.samples
            || h.labels().len() != self.channels.len()
            || h.labels()
                .iter()
                .zip(&self.channels)
                .any(|(a, b)| *a != b.label)
        {
            return Err(CoreError::DimensionMismatch {
                what: "the record repaired and the record checked".into(),
                expected: self.samples,
                found: h.samples(),
            });
        }
        let channels = self
            .channels
            .iter()
            .enumerate()
            .map(|(c, q)| {
                let o = q.offset.unwrap_or(0.0);
                bridged(h.channel(c), &q.masked_spans())
                    .into_iter()
                    .map(|v| v - o)
                    .collect()
            })
            .collect();
        Histories::from_channels(h.labels().to_vec(), channels, h.dt(), h.start(), h.unit())
    }

    /// The mask of channel `label` on another time base (`samples` points from `start` at
    /// step `dt`): `true` where a point lies within one record step of a masked sample.
    /// All `false` for a label the record lacks.
    pub fn mask_on(&self, label: &str, start: f64, dt: f64, samples: usize) -> Vec<bool> {
        let mut m = vec![false; samples];
        let Some(q) = self.channel(label) else {
            return m;
        };
        for (a, b) in q.masked_spans() {
            let t0 = self.start + (a as f64 - 1.0) * self.dt;
            let t1 = self.start + (b as f64 + 1.0) * self.dt;
            let k0 = ((t0 - start) / dt - 1e-9).ceil().max(0.0) as usize;
            let k1 = ((t1 - start) / dt + 1e-9).floor();
            if k1 < 0.0 {
                continue;
            }
            for v in m.iter_mut().take((k1 as usize + 1).min(samples)).skip(k0) {
                *v = true;
            }
        }
        m
    }
}

/// Where the noise model of [`noise_of`] came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RecordNoiseSource {
    /// The quiet part before the event (AR model by BIC).
    Quiet,
    /// The band above the model ensemble's bandwidth ([`noise_from_band`]).
    ModelFreeBand,
    /// Given by the user.
    Given,
    /// Nowhere: the record has no quiet part and no band (the note says why).
    None,
}

/// The noise of one channel of a test as compared with a model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecordNoise {
    /// The noise model (`None` when no source shows the noise).
    pub model: Option<ArModel>,
    /// Where it came from.
    pub source: RecordNoiseSource,
    /// Why the band was not used, when it was tried and refused.
    pub refusal: Option<BandRefusal>,
}

/// The noise of test channel `test` (as compared: after the filter `cfc`, on the step
/// `dt`), in this order: from its quiet part `test[..quiet]` when that holds at least
/// [`faults::MIN_QUIET`] samples and is not constant (a straight line removed, an AR model
/// of order by BIC); else from the band above the bandwidth of `members` (the envelope of
/// the same channel of every run of the model ensemble on the same samples,
/// [`noise_above_envelope`]); else none,
/// with the band's refusal. Nothing here reads second differences: on a smooth record they
/// measure its curvature as much as its noise.
///
/// # Errors
/// As [`noise_from_band`] (a member of another length, a step the filter cannot serve).
pub fn noise_of(
    test: &[f64],
    members: &MemberEnvelope,
    quiet: usize,
    dt: f64,
    cfc: Option<crate::signal::Cfc>,
) -> Result<RecordNoise> {
    if quiet >= faults::MIN_QUIET && quiet <= test.len() {
        let part = spectrum::detrended(&test[..quiet]);
        if let Ok(m) = ArModel::fit(&part, ar::DEFAULT_MAX_ORDER) {
            return Ok(RecordNoise {
                model: Some(m),
                source: RecordNoiseSource::Quiet,
                refusal: None,
            });
        }
    }
    Ok(match noise_above_envelope(test, members, dt, cfc)? {
        Ok(b) => RecordNoise {
            model: Some(b.model),
            source: RecordNoiseSource::ModelFreeBand,
            refusal: None,
        },
        Err(r) => RecordNoise {
            model: None,
            source: RecordNoiseSource::None,
            refusal: Some(r),
        },
    })
}

/// `x` with the samples of `spans` replaced by the straight line between the unmasked
/// samples either side (held flat at the record's ends).
pub fn bridged(x: &[f64], spans: &[(usize, usize)]) -> Vec<f64> {
    let mut y = x.to_vec();
    let n = x.len();
    for &(a, b) in spans {
        if a >= n {
            continue;
        }
        let b = b.min(n - 1);
        let left = a.checked_sub(1).map(|i| (i, x[i]));
        let right = (b + 1 < n).then(|| (b + 1, x[b + 1]));
        for (k, v) in y.iter_mut().enumerate().take(b + 1).skip(a) {
            *v = match (left, right) {
                (Some((i, u)), Some((j, w))) => u + (w - u) * (k - i) as f64 / (j - i) as f64,
                (Some((_, u)), None) => u,
                (None, Some((_, w))) => w,
                (None, None) => *v,
            };
        }
    }
    y
}

/// Reads a wide CSV record for checking: rows whose time repeats or goes back are dropped
/// (and reported), a non-uniform time base (gaps) is resampled linearly at its median step;
/// returns the record and its time faults.
///
/// # Errors
/// [`CoreError::Io`] when unreadable; the table's errors (a cell that does not parse, a
/// short row, a duplicate label); [`CoreError::File`] for fewer than two rows left, or
/// gaps that miss more samples than the record holds.
pub fn read_record(path: impl AsRef<Path>) -> Result<(Histories, Vec<TimeFault>)> {
    let (text, name) = crate::table::read_text(path.as_ref())?;
    parse_record(&text, &name)
}

/// [`read_record`] on text.
///
/// # Errors
/// As [`read_record`].
pub fn parse_record(text: &str, source_name: &str) -> Result<(Histories, Vec<TimeFault>)> {
    let table = Table::parse(text, source_name, TableOptions::default())?;
    let times: Vec<f64> = table.rows().iter().map(|r| r[0]).collect();
    let faults = faults::time_faults(&times);
    let mut keep: Vec<usize> = Vec::with_capacity(times.len());
    for k in 0..times.len() {
        if keep.last().is_none_or(|&j| times[k] > times[j]) {
            keep.push(k);
        }
    }
    if keep.len() < 2 {
        return Err(CoreError::File {
            file: source_name.to_string(),
            message: format!(
                "{} row(s) with increasing time stamps: a record needs at least two",
                keep.len()
            ),
        });
    }
    let t: Vec<f64> = keep.iter().map(|&k| times[k]).collect();
    let cols: Vec<Vec<f64>> = (1..table.header().len())
        .map(|c| keep.iter().map(|&k| table.rows()[k][c]).collect())
        .collect();
    let labels = table.header()[1..].to_vec();
    let n = t.len();
    let mean = (t[n - 1] - t[0]) / (n - 1) as f64;
    let uniform = t
        .windows(2)
        .all(|w| ((w[1] - w[0]) - mean).abs() <= crate::histories::TIME_STEP_TOLERANCE * mean);
    let h = if uniform {
        Histories::from_channels(labels, cols, mean, t[0], "")?
    } else {
        // More samples made up across gaps than measured is no longer the record (and a
        // stray stamp far beyond the rest would allocate without bound).
        let missing: usize = faults
            .iter()
            .map(|f| match f {
                TimeFault::Gap { missing, .. } => *missing,
                _ => 0,
            })
            .sum();
        if missing > n {
            let (from, to) = faults
                .iter()
                .find_map(|f| match f {
                    TimeFault::Gap { from, to, .. } => Some((*from, *to)),
                    _ => None,
                })
                .unwrap_or((t[0], t[n - 1]));
            return Err(CoreError::File {
                file: source_name.to_string(),
                message: format!(
                    "the time column's gaps (the first from {from} s to {to} s) leave \
                     {missing} samples missing at the median step against {n} present: \
                     resampling would make up most of the record; split it at the gap"
                ),
            });
        }
        let (resampled, r) = crate::signal::resample_uniform(&t, &cols)?;
        Histories::from_channels(labels, resampled, r.dt, t[0], "")?
    };
    Ok((h, faults))
}

#[cfg(test)]
mod tests;
