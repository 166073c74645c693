//! The test's measurement noise as M1 counts it, per objective channel.

use impactcal_core::quality::{ArModel, RecordNoiseSource, noise_of};
use impactcal_core::{Cfc, Histories};

use super::result::MeasurementNoise;
use crate::error::Result;

/// The noise of every channel of `test` (the objective channels as compared: filtered,
/// on the model's samples): the user's `sigma` (white) when given; else from the test's
/// first `quiet` samples, or from the band above the bandwidth of every member of the
/// ensemble (`baseline` and `runs`, the same channels) through `cfc`
/// ([`impactcal_core::quality::noise_of`]); else none (zero), which is the paper's
/// noiseless reading for that channel. Returns the noise models in channel order and
/// what was measured, with the reason where nothing was.
///
/// # Errors
/// A channel missing from the baseline or a run; the band's errors (a filter that cannot
/// serve the step).
pub fn measured(
    test: &Histories,
    baseline: &Histories,
    runs: &[Histories],
    quiet: usize,
    cfc: Option<Cfc>,
    sigma: Option<f64>,
) -> Result<(Vec<ArModel>, Vec<MeasurementNoise>)> {
    let mut models = Vec::new();
    let mut summary = Vec::new();
    for l in test.labels() {
        let x = test.channel_by_label(l)?;
        let (model, source, note) = match sigma {
            Some(s) => (ArModel::white(s), RecordNoiseSource::Given, None),
            None => {
                let mut members = vec![baseline.channel_by_label(l)?];
                for r in runs {
                    members.push(r.channel_by_label(l)?);
                }
                let n = noise_of(x, &members, quiet, test.dt(), cfc)?;
                (
                    n.model.unwrap_or_else(|| ArModel::white(0.0)),
                    n.source,
                    n.refusal.map(|r| {
                        format!("no quiet part and no band: {r}; no measurement noise counted")
                    }),
                )
            }
        };
        summary.push(MeasurementNoise {
            label: l.clone(),
            source,
            sigma: model.sigma(),
            lag1: model.lag1(),
            order: model.order(),
            note,
        });
        models.push(model);
    }
    Ok((models, summary))
}
