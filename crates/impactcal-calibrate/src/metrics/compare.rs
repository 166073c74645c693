//! All metrics of a model against a test, channel by channel and over channels.

use std::collections::BTreeSet;

use rayon::prelude::*;
use serde::Serialize;

use impactcal_core::signal::{crop, interpolate_onto};
use impactcal_core::{Cfc, ChannelMap, CoreError, Histories, ParamGuard};

use super::{Grade, Iso18571, Iso18571Rating, PointwiseErrors, Russell, SpragueGeers};
use crate::error::{CalibrateError, Result};

/// Every metric of one computed curve against one measured curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CurveMetrics {
    /// Relative L2, RMS, peak and time-of-peak errors.
    #[serde(flatten)]
    pub pointwise: PointwiseErrors,
    /// Sprague-Geers `M`, `P`, `C`.
    pub sprague_geers: SpragueGeers,
    /// Russell `RM`, `RP`, `RC`.
    pub russell: Russell,
    /// ISO/TS 18571 rating and scores.
    pub iso18571: Iso18571Rating,
}

impl CurveMetrics {
    /// All metrics of `computed` against `measured`, both sampled every `dt` from the same
    /// time, with ISO/TS 18571 configured by `iso`.
    ///
    /// # Errors
    /// As [`PointwiseErrors::between`], [`SpragueGeers::between`] and [`Iso18571::rate`].
    pub fn between(
        measured: &[f64],
        computed: &[f64],
        dt: f64,
        iso: &Iso18571,
    ) -> Result<CurveMetrics> {
        Ok(CurveMetrics {
            pointwise: PointwiseErrors::between(measured, computed, dt)?,
            sprague_geers: SpragueGeers::between(measured, computed)?,
            russell: Russell::between(measured, computed)?,
            iso18571: iso.rate(measured, computed, dt)?,
        })
    }
}

/// A test channel and the model channel it is compared with, scaled by `gain`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelPair {
    /// Label of the test channel.
    pub test_label: String,
    /// Label of the model channel.
    pub model_label: String,
    /// Factor applied to the model channel (unit conversion).
    pub gain: f64,
}

impl ChannelPair {
    /// Pairs the channels that carry the same label on both sides, in the test's order, with
    /// gain 1.
    ///
    /// # Errors
    /// [`CalibrateError::Core`] ([`CoreError::Invalid`]) when no label is common to both.
    pub fn by_label(test: &Histories, model: &Histories) -> Result<Vec<ChannelPair>> {
        let pairs: Vec<ChannelPair> = test
            .labels()
            .iter()
            .filter(|l| model.index_of(l).is_some())
            .map(|l| ChannelPair {
                test_label: l.clone(),
                model_label: l.clone(),
                gain: 1.0,
            })
            .collect();
        if pairs.is_empty() {
            return Err(CoreError::Invalid(format!(
                "test and model share no channel label (test: {}; model: {}); pair them with a channel map",
                short(test.labels()),
                short(model.labels())
            ))
            .into());
        }
        Ok(pairs)
    }

    /// The pairs of a channel map, checked against both sides.
    ///
    /// # Errors
    /// [`CoreError::MapLabel`] naming the map's line of a label either side lacks.
    pub fn from_map(
        map: &ChannelMap,
        test: &Histories,
        model: &Histories,
    ) -> Result<Vec<ChannelPair>> {
        map.check(test.labels(), model.labels())?;
        Ok(map
            .entries
            .iter()
            .map(|e| ChannelPair {
                test_label: e.test_label.clone(),
                model_label: e.model_label.clone(),
                gain: e.gain,
            })
            .collect())
    }
}

fn short(labels: &[String]) -> String {
    let mut s: Vec<&str> = labels.iter().take(4).map(String::as_str).collect();
    if labels.len() > 4 {
        s.push("...");
    }
    s.join(", ")
}

/// How a comparison is made.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CompareOptions {
    /// Channel frequency class applied to both sides, each on its own time base, before the
    /// model is interpolated onto the test's time points. `None` compares unfiltered data.
    pub cfc: Option<Cfc>,
    /// Time window `[t0, t1]` to which the test is cropped; `None` keeps all of it.
    pub window: Option<(f64, f64)>,
    /// The ISO/TS 18571 constants.
    pub iso: Iso18571,
}

impl ParamGuard for CompareOptions {
    type Checked = CompareOptions;

    /// Checks the options on their own (the window against the data is checked by
    /// [`compare`]; the ISO/TS 18571 constants by their own setters).
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for a `window` whose ends are not finite or not
    /// increasing.
    fn check_ref(&self) -> impactcal_core::Result<()> {
        if let Some((t0, t1)) = self.window
            && !(t0.is_finite() && t1.is_finite() && t0 < t1)
        {
            return Err(CoreError::invalid_option(
                "window",
                format!("[{t0}, {t1}]"),
                "must be finite and increasing (s)",
            ));
        }
        Ok(())
    }

    fn check(self) -> impactcal_core::Result<CompareOptions> {
        self.check_ref()?;
        Ok(self)
    }
}

/// The metrics of one channel pair.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelMetrics {
    /// Label of the test channel.
    pub test_label: String,
    /// Label of the model channel.
    pub model_label: String,
    /// Gain applied to the model channel.
    pub gain: f64,
    /// The metrics.
    #[serde(flatten)]
    pub metrics: CurveMetrics,
}

/// Mean of each ISO/TS 18571 score over channels, and the grade of the mean rating.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MeanIso {
    /// Mean `R`.
    pub r: f64,
    /// Mean corridor score.
    pub corridor: f64,
    /// Mean phase score.
    pub phase: f64,
    /// Mean magnitude score.
    pub magnitude: f64,
    /// Mean slope score.
    pub slope: f64,
    /// Grade of the mean `R`.
    pub grade: Grade,
}

/// A Sprague-Geers or Russell triple averaged over channels.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MeanTriple {
    /// Mean magnitude error.
    pub m: f64,
    /// Mean phase error.
    pub p: f64,
    /// Mean comprehensive error.
    pub c: f64,
}

/// Metrics aggregated over channels: the arithmetic mean of each, and the channel with the
/// lowest ISO/TS 18571 rating.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Overall {
    /// Mean relative L2 error.
    pub rel_l2: f64,
    /// Mean RMS error.
    pub rms: f64,
    /// Mean peak value error.
    pub peak_error: f64,
    /// Mean time-of-peak error.
    pub time_of_peak_error: f64,
    /// Mean Sprague-Geers errors.
    pub sprague_geers: MeanTriple,
    /// Mean Russell errors.
    pub russell: MeanTriple,
    /// Mean ISO/TS 18571 scores.
    pub iso18571: MeanIso,
    /// Test label of the channel with the lowest ISO/TS 18571 rating.
    pub worst_channel: String,
    /// That channel's rating.
    pub worst_r: f64,
}

impl Overall {
    fn of(channels: &[ChannelMetrics]) -> Overall {
        let n = channels.len() as f64;
        let mean = |f: &dyn Fn(&CurveMetrics) -> f64| {
            channels.iter().map(|c| f(&c.metrics)).sum::<f64>() / n
        };
        let worst = channels
            .iter()
            .min_by(|a, b| a.metrics.iso18571.r.total_cmp(&b.metrics.iso18571.r));
        let r = mean(&|m| m.iso18571.r);
        Overall {
            rel_l2: mean(&|m| m.pointwise.rel_l2),
            rms: mean(&|m| m.pointwise.rms),
            peak_error: mean(&|m| m.pointwise.peak_error),
            time_of_peak_error: mean(&|m| m.pointwise.time_of_peak_error),
            sprague_geers: MeanTriple {
                m: mean(&|m| m.sprague_geers.magnitude),
                p: mean(&|m| m.sprague_geers.phase),
                c: mean(&|m| m.sprague_geers.comprehensive),
            },
            russell: MeanTriple {
                m: mean(&|m| m.russell.magnitude),
                p: mean(&|m| m.russell.phase),
                c: mean(&|m| m.russell.comprehensive),
            },
            iso18571: MeanIso {
                r,
                corridor: mean(&|m| m.iso18571.corridor),
                phase: mean(&|m| m.iso18571.phase),
                magnitude: mean(&|m| m.iso18571.magnitude),
                slope: mean(&|m| m.iso18571.slope),
                grade: Grade::of(r),
            },
            worst_channel: worst.map(|w| w.test_label.clone()).unwrap_or_default(),
            worst_r: worst.map_or(f64::NAN, |w| w.metrics.iso18571.r),
        }
    }
}

/// The result of [`compare`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Comparison {
    /// One entry per channel pair, in pair order.
    pub channels: Vec<ChannelMetrics>,
    /// Means over channels and the worst channel.
    pub overall: Overall,
    /// The metrics of the norm histories `Q(t) = ||v(t)||_2` over the paired channels.
    pub q_norm: CurveMetrics,
    /// The channel frequency class applied, if any.
    pub cfc: Option<u32>,
    /// First and last time compared.
    pub window: [f64; 2],
    /// Samples compared per channel.
    pub samples: usize,
    /// Time step of the comparison (the test's).
    pub dt: f64,
    /// The channels of either side that no pair names: not compared.
    pub dropped: Dropped,
}

/// The channels a comparison leaves out: the test's channels no pair names (measured data
/// that is not compared) and the model's channels no pair names (outputs the test does not
/// have), each in its file's order.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct Dropped {
    /// Test channels without a model channel.
    pub test: Vec<String>,
    /// Model channels without a test channel.
    pub model: Vec<String>,
}

impl Dropped {
    /// The channels of `test` and `model` outside the pairs' labels.
    pub fn of<'a>(
        test: &[String],
        model: &[String],
        paired: impl Iterator<Item = (&'a str, &'a str)>,
    ) -> Dropped {
        let (paired_test, paired_model): (BTreeSet<&str>, BTreeSet<&str>) = paired.unzip();
        let outside = |labels: &[String], paired: &BTreeSet<&str>| {
            labels
                .iter()
                .filter(|l| !paired.contains(&l.as_str()))
                .cloned()
                .collect()
        };
        Dropped {
            test: outside(test, &paired_test),
            model: outside(model, &paired_model),
        }
    }

    /// Whether nothing was left out.
    pub fn is_empty(&self) -> bool {
        self.test.is_empty() && self.model.is_empty()
    }

    /// The warning a person reads, `None` when nothing was left out: what was compared of
    /// each side and the first names left out, e.g. "compared 3 of the test's 6 channels:
    /// the test's `b`, `c`, `d` have no model channel (add them to the model's output or
    /// map them with a channel map)".
    pub fn warning(&self, compared: usize) -> Option<String> {
        let names = |v: &[String]| {
            let mut s: Vec<String> = v.iter().take(5).map(|l| format!("`{l}`")).collect();
            if v.len() > 5 {
                s.push(format!("and {} more", v.len() - 5));
            }
            s.join(", ")
        };
        let mut parts = Vec::new();
        if !self.test.is_empty() {
            parts.push(format!(
                "compared {compared} of the test's {} channels: the test's {} have no model \
                 channel (give the model that output, or pair them with a channel map)",
                compared + self.test.len(),
                names(&self.test)
            ));
        }
        if !self.model.is_empty() {
            parts.push(format!(
                "{} of the model's {} channels are not in the test ({}) and are not compared",
                self.model.len(),
                self.model.len() + compared,
                names(&self.model)
            ));
        }
        (!parts.is_empty()).then(|| parts.join("; "))
    }
}

/// Compares the model with the test on every channel pair: filters both sides with the same
/// class (if any), crops the test to the window (if any), interpolates the model linearly
/// onto the test's time points, multiplies each model channel by its pair's gain, and
/// computes [`CurveMetrics`] per pair (in parallel), their means, and the metrics of the
/// norm histories `Q(t)` of the paired test and model channels.
///
/// # Errors
/// - [`CoreError::UnknownLabel`] for a pair naming a channel that is absent;
/// - [`CoreError::FilterClass`] when a side's sampling rate cannot carry the class;
/// - [`CoreError::NoTimeOverlap`] / [`CoreError::OutsideModelTime`] when the test's (cropped)
///   time range does not lie within the model's;
/// - the metrics' errors, naming the channel (for example a test channel that is identically
///   zero).
pub fn compare(
    test: &Histories,
    model: &Histories,
    pairs: &[ChannelPair],
    options: &CompareOptions,
) -> Result<Comparison> {
    options.check_ref()?;
    if pairs.is_empty() {
        return Err(CoreError::Invalid("no channel pairs to compare".into()).into());
    }
    let test_labels: Vec<&str> = pairs.iter().map(|p| p.test_label.as_str()).collect();
    let mut model_labels: Vec<&str> = Vec::new();
    for p in pairs {
        if !model_labels.contains(&p.model_label.as_str()) {
            model_labels.push(&p.model_label);
        }
    }
    let mut t = test.select(&test_labels)?;
    let mut m = model.select(&model_labels)?;
    if let Some(cfc) = options.cfc {
        t = t.filtered(cfc).map_err(|e| side("test", e))?;
        m = m.filtered(cfc).map_err(|e| side("model", e))?;
    }
    if let Some((t0, t1)) = options.window {
        t = crop(&t, t0, t1)?;
    }
    let m = interpolate_onto(&m, t.start(), t.dt(), t.samples(), "test vs model")?;
    let computed: Vec<Vec<f64>> = pairs
        .iter()
        .map(|p| {
            m.channel_by_label(&p.model_label)
                .map(|ch| ch.iter().map(|v| v * p.gain).collect())
        })
        .collect::<impactcal_core::Result<_>>()?;
    let dt = t.dt();
    let channels = pairs
        .par_iter()
        .enumerate()
        .map(|(k, p)| {
            CurveMetrics::between(t.channel(k), &computed[k], dt, &options.iso)
                .map(|metrics| ChannelMetrics {
                    test_label: p.test_label.clone(),
                    model_label: p.model_label.clone(),
                    gain: p.gain,
                    metrics,
                })
                .map_err(|e| name_channel(e, &p.test_label))
        })
        .collect::<Result<Vec<_>>>()?;
    let q_test = t.norm_history();
    let mut q_model = vec![0.0; t.samples()];
    for ch in &computed {
        for (q, v) in q_model.iter_mut().zip(ch) {
            *q += v * v;
        }
    }
    q_model.iter_mut().for_each(|q| *q = q.sqrt());
    let q_norm = CurveMetrics::between(&q_test, &q_model, dt, &options.iso)
        .map_err(|e| name_channel(e, "Q(t)"))?;
    Ok(Comparison {
        overall: Overall::of(&channels),
        channels,
        q_norm,
        cfc: options.cfc.map(Cfc::class),
        window: [t.start(), t.start() + (t.samples() - 1) as f64 * dt],
        samples: t.samples(),
        dt,
        dropped: Dropped::of(
            test.labels(),
            model.labels(),
            pairs
                .iter()
                .map(|p| (p.test_label.as_str(), p.model_label.as_str())),
        ),
    })
}

/// Prefixes a core error's subject with the side it concerns.
fn side(which: &str, e: CoreError) -> CalibrateError {
    match e {
        CoreError::FilterClass {
            what,
            cfc,
            rate_hz,
            min_rate_hz,
        } => CoreError::FilterClass {
            what: format!("{which} {what}"),
            cfc,
            rate_hz,
            min_rate_hz,
        }
        .into(),
        other => other.into(),
    }
}

/// Names the channel in a metric's error.
fn name_channel(e: CalibrateError, label: &str) -> CalibrateError {
    e.with_subject(|what| format!("channel `{label}` ({what})"))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// A window that is not finite or not increasing is refused by
    /// `ParamGuard::check_ref` naming `window`, and `compare` refuses it the same way.
    #[test]
    fn a_bad_window_is_refused_naming_its_key() {
        let h = Histories::from_channels(
            vec!["x".into()],
            vec![(0..50).map(|k| (k as f64 * 0.2).sin()).collect()],
            1e-3,
            0.0,
            "",
        )
        .unwrap();
        let pairs = [ChannelPair {
            test_label: "x".into(),
            model_label: "x".into(),
            gain: 1.0,
        }];
        for window in [(0.02, 0.01), (f64::NAN, 0.01), (0.0, f64::INFINITY)] {
            let o = CompareOptions {
                window: Some(window),
                ..CompareOptions::default()
            };
            match o.check_ref() {
                Err(CoreError::InvalidOption { name, .. }) => assert_eq!(name, "window"),
                other => panic!("{window:?}: {other:?}"),
            }
            match compare(&h, &h, &pairs, &o) {
                Err(CalibrateError::Core(CoreError::InvalidOption { name, .. })) => {
                    assert_eq!(name, "window");
                }
                other => panic!("{window:?}: {other:?}"),
            }
        }
        let fine = CompareOptions {
            window: Some((0.0, 0.02)),
            ..CompareOptions::default()
        };
        assert!(compare(&h, &h, &pairs, &fine).is_ok());
    }
}
