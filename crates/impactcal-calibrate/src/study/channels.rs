//! The test on the model's channels and time base, and the norm history `Q(t)`.

use impactcal_core::signal::interpolate_onto;
use impactcal_core::{Cfc, ChannelMap, Histories};

use crate::error::{CalibrateError, Result};

/// The test as the study sees it: converted by the map's conversions (bridges,
/// accelerometers, units), the channels it shares with the model (by label, or
/// through a channel map, the model channel scaled by the map's gain standing for the test
/// channel), relabelled with the model's labels, filtered with the study's CFC class on its
/// own time base, then interpolated onto the model's time points.
///
/// # Errors
/// [`CalibrateError::Study`] when the test shares no channel with the model; the map's
/// and the filter's errors; `CoreError::OutsideModelTime` (read: the test does not cover
/// the model's window) when the model's window reaches past the test's record.
pub fn test_on_model(
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
    let on_labels =
        Histories::from_channels(labels, channels, test.dt(), test.start(), test.unit())?;
    let what = "the test against the model's window (the test must cover it)";
    Ok(interpolate_onto(
        &on_labels,
        model.start(),
        model.dt(),
        model.samples(),
        what,
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
