//! `[model] kind = "kolsky-bar"`: a split-Hopkinson bar test in the neutral form
//! (`test = "copper.toml"`, docs/kolsky.md) as the experiment's model and its measured test.
//!
//! The model is [`KolskyModel`] on the test; the measured test is the same record's
//! reflected and transmitted waves on the model's time base
//! ([`KolskyModel::measured`]), so a file of this kind gives no `[test] data`. `[test]`
//! may still give `map` (the waves it names are the measured test: `reflected` alone
//! calibrates on the reflected wave), `cfc` and `sigma`.

use std::path::Path;

use impactcal_core::{ChannelMap, Histories, Model};
use impactcal_models::kolsky::{KolskyModel, KolskyTest};
use impactcal_runner::fingerprint;

use crate::error::{ExperimentError, Result, io};
use crate::model::{Built, ExperimentModel, ModelSpec};
use crate::schema::{ExperimentFile, ModelSection};

/// The spec of a `kind = "kolsky-bar"` model section.
///
/// # Errors
/// [`ExperimentError::File`] for a missing `test`, and for keys that do not apply to a bar
/// test: `[model] set` and `end_time`, `[space]`, `[parameters]`, `[candidates]`, `[held]`
/// (the bar model declares its own), `[test] data` (the bar test holds the signals) and
/// `[holdout]` and `[solver]`.
pub(crate) fn spec(m: &ModelSection, file: &ExperimentFile, name: &str) -> Result<ModelSpec> {
    let fault = |message: &str| ExperimentError::File {
        file: name.to_string(),
        message: message.to_string(),
    };
    let Some(test) = &m.test else {
        return Err(fault(
            "[model] kind = \"kolsky-bar\" needs `test = \"<bar test>.toml\"`: the bar test in \
             the neutral form (docs/kolsky.md)",
        ));
    };
    let mut stray = Vec::new();
    if !m.set.is_empty() {
        stray.push("[model] set");
    }
    if m.end_time.is_some() {
        stray.push("[model] end_time");
    }
    if m.file.is_some() {
        stray.push("[model] file");
    }
    if !file.test.repeats.is_empty() {
        stray.push("[test] repeats");
    }
    if file.space.preset.is_some() || file.space.bounds.is_some() {
        stray.push("[space]");
    }
    if !file.parameters.is_empty() {
        stray.push("[parameters]");
    }
    if !file.candidates.is_empty() {
        stray.push("[candidates]");
    }
    if !file.held.is_empty() {
        stray.push("[held]");
    }
    if file.test.data.is_some() {
        stray.push("[test] data");
    }
    if file.holdout.is_some() {
        stray.push("[holdout]");
    }
    if file.solver.is_some() {
        stray.push("[solver]");
    }
    if !stray.is_empty() {
        return Err(fault(&format!(
            "{} {} not apply to kind = \"kolsky-bar\": the bar model declares A, B, n, \
             modulus and its nuisance terms and lists its own candidates; the measured \
             signals are the bar test's (`[model] test`), and `[test]` takes only `map`, \
             `cfc` and `sigma` (a map naming `reflected` alone calibrates on the reflected \
             wave)",
            stray.join(", "),
            if stray.len() == 1 { "does" } else { "do" }
        )));
    }
    Ok(ModelSpec::KolskyBar { test: test.clone() })
}

/// The bar model of the test at `path`, with a description that fingerprints the test file
/// and its signals (a changed test is another experiment) and a note of the resampling.
///
/// # Errors
/// [`ExperimentError::Io`] when the test or its signals file cannot be read; the test
/// reader's and the model's errors ([`ExperimentError::Models`]) with the test's path.
pub(crate) fn build(path: &Path) -> Result<Built> {
    let test = KolskyTest::read(path)?;
    let model = KolskyModel::new(&test)?;
    let mut bytes = std::fs::read(path).map_err(io(path))?;
    bytes.extend(test.signals.data().iter().flat_map(|v| v.to_le_bytes()));
    let notes = model
        .separated()
        .resampling
        .map(|r| {
            format!(
                "{}: resampled from {:.3} us to {:.3} us (factor {}, low-pass at {:.0} kHz): \
                 what the bars carry",
                path.display(),
                r.from_dt * 1e6,
                r.to_dt * 1e6,
                r.factor,
                r.cutoff / 1e3
            )
        })
        .into_iter()
        .collect();
    Ok(Built {
        space: model.space().clone(),
        description: format!("kolsky-bar {} ({})", path.display(), fingerprint(&bytes)),
        model: Some(ExperimentModel::KolskyBar(Box::new(model))),
        geometry: None,
        notes,
    })
}

/// The measured reflected and transmitted waves of the bar test at `path`, on the model's
/// time base, and the gauges' noise level: the larger of the two gauges' standard
/// deviations over the record's quiet start (`Separated::noise`; white after the resampling's
/// low-pass up to 0.8 of the Nyquist frequency), with a note saying so; `None` for a record
/// with too few samples before its pulse.
///
/// # Errors
/// As [`build`].
pub(crate) fn measured(path: &Path) -> Result<(Histories, Option<f64>, Vec<String>)> {
    let test = KolskyTest::read(path)?;
    let model = KolskyModel::new(&test)?;
    let w = model.separated();
    let sigma = w.noise.map(|[i, t]| i.max(t));
    let notes = match w.noise {
        Some([i, t]) => vec![format!(
            "{}: gauge noise before the incident pulse ({} quiet samples): {i:.3e} (incident), \
             {t:.3e} (transmitted); the larger is the measurement noise of both waves",
            path.display(),
            w.quiet
        )],
        None => vec![format!(
            "{}: fewer than {} samples before the incident pulse: the noise is measured by \
             the loop on the waves",
            path.display(),
            impactcal_models::kolsky::waves::MIN_QUIET
        )],
    };
    Ok((model.measured()?, sigma, notes))
}

/// The bar test's waves that `map` names (a map naming `reflected` alone calibrates on the
/// reflected wave, leaving the transmitted one to predict), in the map's order.
///
/// # Errors
/// [`ExperimentError::File`] naming the map's line whose test label is not a wave of the
/// bar test (`reflected`, `transmitted`).
pub(crate) fn mapped(test: Histories, map: &ChannelMap) -> Result<Histories> {
    let mut labels = Vec::new();
    let mut channels = Vec::new();
    for e in &map.entries {
        let Some(i) = test.index_of(&e.test_label) else {
            return Err(ExperimentError::File {
                file: map.file.clone(),
                message: format!(
                    "line {}: `{}` is not a wave of the bar test (reflected, transmitted)",
                    e.line, e.test_label
                ),
            });
        };
        labels.push(e.test_label.clone());
        channels.push(test.channel(i).to_vec());
    }
    Ok(Histories::from_channels(
        labels,
        channels,
        test.dt(),
        test.start(),
        test.unit(),
    )?)
}
