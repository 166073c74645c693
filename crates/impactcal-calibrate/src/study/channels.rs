//! The test on the model's channels and time base, and the norm history `Q(t)`.

use std::collections::BTreeMap;

use impactcal_core::quality::{QualityOptions, bridged, check};
use impactcal_core::signal::interpolate_onto;
use impactcal_core::{Cfc, ChannelMap, Histories};
use serde::{Deserialize, Serialize};

use crate::error::{CalibrateError, Result};

/// The test as the study sees it: converted by the map's conversions (bridges,
/// accelerometers, units), the channels it shares with the model (by label, or
/// through a channel map, the model channel scaled by the map's gain standing for the test
/// channel), relabelled with the model's labels, filtered with the study's CFC class on its
/// own time base, then interpolated onto the model's time points.
///
/// # Errors
/// [`CalibrateError::Study`] when the test shares no channel with the model; the map's
/// and the filter's errors; [`CalibrateError::TestShorterThanModel`] when the model's window
/// reaches past the test's record.
pub fn test_on_model(
    test: &Histories,
    map: Option<&ChannelMap>,
    cfc: Option<Cfc>,
    model: &Histories,
) -> Result<Histories> {
    window_of(&on_model_labels(test, map, cfc, model)?, model)
}

/// A test already on the model's labels (`on_model_labels`) on the model's time points.
///
/// # Errors
/// [`CalibrateError::TestShorterThanModel`] when the test's record does not cover the
/// model's window (within a millionth of a step).
fn window_of(on_labels: &Histories, model: &Histories) -> Result<Histories> {
    let last = |h: &Histories| h.start() + (h.samples().saturating_sub(1)) as f64 * h.dt();
    let (test_start, test_end) = (on_labels.start(), last(on_labels));
    let (model_start, model_end) = (model.start(), last(model));
    let slack = 1e-6 * model.dt().min(on_labels.dt());
    if test_start > model_start + slack || test_end < model_end - slack {
        return Err(CalibrateError::TestShorterThanModel {
            test_start,
            test_end,
            model_start,
            model_end,
            advice: if test_end < model_end - slack {
                format!(
                    "end the model's window by {} s, or give a longer record",
                    crate::error::to_ns(test_end)
                )
            } else {
                format!(
                    "start the model's window at {} s or later, or give a record that starts \
                     earlier",
                    crate::error::to_ns(test_start)
                )
            },
        });
    }
    let what = "the test against the model's window (the test must cover it)";
    Ok(interpolate_onto(
        on_labels,
        model.start(),
        model.dt(),
        model.samples(),
        what,
    )?)
}

/// Most samples of the test's record before the model's start that the closed loop
/// measures the noise on: the level's relative standard error is then about
/// `sqrt((1 + phi^2) / (2 m (1 - phi^2)))`, under 5 % for AR(1) noise of lag-one
/// correlation 0.8, and the AR fit's cost stays bounded on records with long pre-triggers.
pub const MAX_PRE_TRIGGER: usize = 1024;

/// The test's record before the model's start, as [`test_on_model`] prepares the rest
/// (converted, filtered on its own time base, relabelled, in the model's channel order):
/// the last `min(most, n)` samples on the model's step before `model.start()`, `n` those
/// the record holds. `None` when the record starts at or after the model (within a
/// millionth of a step), or `most == 0`.
///
/// # Errors
/// As [`test_on_model`].
pub fn pre_trigger(
    test: &Histories,
    map: Option<&ChannelMap>,
    cfc: Option<Cfc>,
    model: &Histories,
    most: usize,
) -> Result<Option<Histories>> {
    if lead_samples(test, model, most) == 0 {
        return Ok(None);
    }
    lead_of(&on_model_labels(test, map, cfc, model)?, model, most)
}

/// How many samples of `test`'s record before `model.start()` [`pre_trigger`] keeps.
fn lead_samples(test: &Histories, model: &Histories, most: usize) -> usize {
    let room = (model.start() - test.start()) / model.dt();
    ((room + 1e-6).floor().max(0.0) as usize).min(most)
}

/// [`pre_trigger`] of a test already on the model's labels (`on_model_labels`).
fn lead_of(on_labels: &Histories, model: &Histories, most: usize) -> Result<Option<Histories>> {
    let k = lead_samples(on_labels, model, most);
    if k == 0 {
        return Ok(None);
    }
    let dt = model.dt();
    let what = "the test's record before the model's start";
    Ok(Some(interpolate_onto(
        on_labels,
        model.start() - k as f64 * dt,
        dt,
        k,
        what,
    )?))
}

/// The test converted, filtered with `cfc` on its own time base, on the channels it shares
/// with `model` (by label or through `map`, each divided by the map's gain), relabelled
/// with the model's labels, in the model's channel order.
/// The channels the study or loop leaves out of `test` (after the map's conversions) and
/// of `model`: those no pair names (by label, or through the channel map).
///
/// # Errors
/// The map's conversion errors.
pub fn dropped(
    test: &Histories,
    map: Option<&ChannelMap>,
    model: &Histories,
) -> Result<crate::metrics::Dropped> {
    let converted = match map {
        Some(m) => m.convert(test)?,
        None => test.clone(),
    };
    let pairs: Vec<(String, String)> = match map {
        Some(m) => m
            .entries
            .iter()
            .map(|e| (e.test_label.clone(), e.model_label.clone()))
            .collect(),
        None => converted
            .labels()
            .iter()
            .filter(|l| model.index_of(l).is_some())
            .map(|l| (l.clone(), l.clone()))
            .collect(),
    };
    Ok(crate::metrics::Dropped::of(
        converted.labels(),
        model.labels(),
        pairs.iter().map(|(t, m)| (t.as_str(), m.as_str())),
    ))
}

fn on_model_labels(
    test: &Histories,
    map: Option<&ChannelMap>,
    cfc: Option<Cfc>,
    model: &Histories,
) -> Result<Histories> {
    let converted = match map {
        Some(m) => m.convert(test)?,
        None => test.clone(),
    };
    let test = match cfc {
        Some(c) => converted.filtered(c)?,
        None => converted,
    };
    // (test label, model label, gain): model * gain ~ test.
    let pairs: Vec<(String, String, f64)> = match map {
        Some(m) => {
            m.check(test.labels(), model.labels())?;
            m.entries
                .iter()
                .map(|e| (e.test_label.clone(), e.model_label.clone(), e.gain))
                .collect()
        }
        None => test
            .labels()
            .iter()
            .filter(|l| model.index_of(l).is_some())
            .map(|l| (l.clone(), l.clone(), 1.0))
            .collect(),
    };
    if pairs.is_empty() {
        return Err(CalibrateError::study(
            "test",
            format!(
                "no channel in common with the model (test: {}; model: {}); give a channel map",
                few(test.labels()),
                few(model.labels())
            ),
        ));
    }
    // Keep the model's channel order.
    let mut ordered: Vec<&(String, String, f64)> = pairs.iter().collect();
    ordered.sort_by_key(|p| model.index_of(&p.1).unwrap_or(usize::MAX));
    let mut labels = Vec::new();
    let mut channels = Vec::new();
    for (t, m, gain) in ordered {
        labels.push(m.clone());
        channels.push(test.channel_by_label(t)?.iter().map(|v| v / gain).collect());
    }
    Ok(Histories::from_channels(
        labels,
        channels,
        test.dt(),
        test.start(),
        test.unit(),
    )?)
}

fn few(labels: &[String]) -> String {
    let mut s: Vec<&str> = labels.iter().take(4).map(String::as_str).collect();
    if labels.len() > 4 {
        s.push("...");
    }
    s.join(", ")
}

/// `Q(t_k) = sqrt(sum_c y_c(t_k)^2)` over the channels at `indices`.
pub fn q_of(h: &Histories, indices: &[usize]) -> Vec<f64> {
    (0..h.samples())
        .map(|k| {
            indices
                .iter()
                .map(|&c| h.value(c, k).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .collect()
}

/// The indices of `labels` in `h`.
///
/// # Errors
/// [`CalibrateError::Study`] for a label `h` lacks.
pub fn indices_of(h: &Histories, labels: &[String]) -> Result<Vec<usize>> {
    labels
        .iter()
        .map(|l| {
            h.index_of(l).ok_or_else(|| {
                CalibrateError::study(format!("channel `{l}`"), "not in the histories")
            })
        })
        .collect()
}

/// `||a - b||_F / ||b||_F` over the channels `labels` of two histories on one time base.
///
/// # Errors
/// As [`indices_of`].
pub fn relative_error(model: &Histories, test: &Histories, labels: &[String]) -> Result<f64> {
    let (im, it) = (indices_of(model, labels)?, indices_of(test, labels)?);
    let (mut num, mut den) = (0.0, 0.0);
    for (&a, &b) in im.iter().zip(&it) {
        for (x, y) in model.channel(a).iter().zip(test.channel(b)) {
            num += (x - y) * (x - y);
            den += y * y;
        }
    }
    Ok(if den > 0.0 {
        (num / den).sqrt()
    } else {
        f64::NAN
    })
}

/// `||a - b|| / ||b||` of two vectors.
pub fn relative_l2(a: &[f64], b: &[f64]) -> f64 {
    let num: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
    let den: f64 = b.iter().map(|y| y * y).sum();
    if den > 0.0 {
        (num / den).sqrt()
    } else {
        f64::NAN
    }
}

/// What was done to the test before any comparison: the masks of `core::quality` (clipped
/// runs and spikes found on the raw record, bridged linearly before filtering and, in the
/// closed loop, given zero weight) and the offsets: removed (each channel's pre-impact mean
/// less the model's over the same samples) in the study, fitted with the other nuisance
/// terms (a bias per channel) in the closed loop.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TestPreparation {
    /// Clipped runs found on the raw test.
    pub clipped_runs: usize,
    /// Spikes found on the raw test.
    pub spikes: usize,
    /// Raw samples masked (clipped or spiked).
    pub masked_samples: usize,
    /// Offsets removed, per model channel (empty when the window has no pre-impact part).
    pub offsets: BTreeMap<String, f64>,
    /// Pre-impact samples the offsets (and the noise) were measured on.
    pub pre_impact_samples: usize,
    /// The offsets were left in the test because the comparison fits a bias per channel
    /// (the closed loop's nuisance terms), which takes them out with every sample.
    #[serde(default)]
    pub bias_fitted: bool,
    /// Samples of the record before the model's start kept in [`Self::pre_trigger`].
    #[serde(default)]
    pub pre_trigger_samples: usize,
    /// The test's record before the model's start ([`pre_trigger`], at most
    /// [`MAX_PRE_TRIGGER`] samples, clipped runs and spikes bridged like the rest): the
    /// closed loop measures the noise on it. Not written to files.
    #[serde(skip)]
    pub pre_trigger: Option<Histories>,
}

impl TestPreparation {
    /// One line for a report.
    pub fn describe(&self) -> String {
        format!(
            "Test data as used: {} clipped run(s) and {} spike(s) found by the quality check \
             ({} raw samples) masked out of every comparison; {}",
            self.clipped_runs,
            self.spikes,
            self.masked_samples,
            if self.bias_fitted {
                let lead = match self.pre_trigger_samples {
                    0 => String::new(),
                    n => format!(
                        "; the noise measured on {n} samples of the record before the model's start \
                         with the quiet start of the window"
                    ),
                };
                format!("offsets fitted as a bias per channel with the nuisance terms{lead}")
            } else if self.offsets.is_empty() {
                "no offset removed (no pre-impact samples in the window)".to_string()
            } else {
                format!(
                    "offsets removed on {} channel(s), measured on {} pre-impact samples",
                    self.offsets.len(),
                    self.pre_impact_samples
                )
            }
        )
    }
}

/// The test prepared for comparison with `model` (a run on the model's channels and time
/// base, unfiltered): the raw test checked ([`impactcal_core::quality::check`]) and its
/// clipped and spiked samples bridged, then as [`test_on_model`]; with `pre = Some(p)` the
/// offsets removed over the first `p` samples (when `p >= 8`; the test's mean there less
/// the filtered model's), with `None` left in (the caller fits a bias per channel); and,
/// per model channel of the result, the mask of the samples that lie within a raw step of
/// a masked sample.
///
/// # Errors
/// As [`test_on_model`].
pub fn prepared_test(
    test: &Histories,
    map: Option<&ChannelMap>,
    cfc: Option<Cfc>,
    model: &Histories,
    pre: Option<usize>,
) -> Result<(Histories, Vec<Vec<bool>>, TestPreparation)> {
    let converted = match map {
        Some(m) => m.convert(test)?,
        None => test.clone(),
    };
    let quality = check(&converted, &QualityOptions::default())?;
    let channels: Vec<Vec<f64>> = quality
        .channels
        .iter()
        .enumerate()
        .map(|(c, q)| bridged(converted.channel(c), &q.masked_spans()))
        .collect();
    let repaired = Histories::from_channels(
        converted.labels().to_vec(),
        channels,
        converted.dt(),
        converted.start(),
        converted.unit(),
    )?;
    // The map's conversions are applied: map the labels and gains only.
    let plain = map.map(|m| {
        let mut m = m.clone();
        m.entries.iter_mut().for_each(|e| e.conversion = None);
        m
    });
    // Converted and filtered once; the window and the pre-trigger are both read from it.
    let on_labels = on_model_labels(&repaired, plain.as_ref(), cfc, model)?;
    let on_model = window_of(&on_labels, model)?;
    let lead = lead_of(&on_labels, model, MAX_PRE_TRIGGER)?;
    let test_label = |model_label: &str| -> String {
        map.and_then(|m| {
            m.entries
                .iter()
                .find(|e| e.model_label == model_label)
                .map(|e| e.test_label.clone())
        })
        .unwrap_or_else(|| model_label.to_string())
    };
    let masks: Vec<Vec<bool>> = on_model
        .labels()
        .iter()
        .map(|l| {
            quality.mask_on(
                &test_label(l),
                on_model.start(),
                on_model.dt(),
                on_model.samples(),
            )
        })
        .collect();
    let model_f = match cfc {
        Some(c) => model.filtered(c)?,
        None => model.clone(),
    };
    let mut offsets = BTreeMap::new();
    let t = on_model.samples();
    let mut data = on_model.data().to_vec();
    let removed = pre.filter(|&p| p >= 8).unwrap_or(0);
    if removed > 0 {
        for (c, l) in on_model.labels().iter().enumerate() {
            let m = model_f.channel_by_label(l)?;
            let o = (0..removed).map(|k| data[c * t + k] - m[k]).sum::<f64>() / removed as f64;
            data[c * t..(c + 1) * t].iter_mut().for_each(|v| *v -= o);
            offsets.insert(l.clone(), o);
        }
    }
    let prepared = Histories::new(
        on_model.labels().to_vec(),
        t,
        on_model.dt(),
        on_model.start(),
        on_model.unit(),
        data,
    )?;
    let summary = TestPreparation {
        clipped_runs: quality.channels.iter().map(|c| c.clipped_runs.len()).sum(),
        spikes: quality.channels.iter().map(|c| c.spike_spans.len()).sum(),
        masked_samples: quality.masked_count(),
        offsets,
        pre_impact_samples: removed,
        bias_fitted: pre.is_none(),
        pre_trigger_samples: lead.as_ref().map_or(0, Histories::samples),
        pre_trigger: lead,
    };
    Ok((prepared, masks, summary))
}
