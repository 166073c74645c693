//! The test's measurement noise as M1 counts it, per objective channel.

use impactcal_core::quality::{ArModel, MemberEnvelope, RecordNoiseSource, noise_of};
use impactcal_core::{Cfc, Histories};

use super::result::MeasurementNoise;
use crate::error::{CalibrateError, Result};

/// The noise of every channel of `test` (the objective channels as compared: filtered,
/// on the model's samples): the user's `sigma` (white) when given; else from the test's
/// first `quiet` samples, or from the band above the bandwidth of every member of the
/// ensemble (`envelopes`: per channel of `test`, in its order, the envelope of the
/// baseline's and every run's spectrum, [`envelopes`]) through `cfc`
/// ([`impactcal_core::quality::noise_of`]); else none (zero), which is the paper's
/// noiseless reading for that channel. Returns the noise models in channel order and
/// what was measured, with the reason where nothing was.
///
/// # Errors
/// Fewer envelopes than channels; the band's errors (members of another length, a filter
/// that cannot serve the step).
pub fn measured(
    test: &Histories,
    envelopes: &[MemberEnvelope],
    quiet: usize,
    cfc: Option<Cfc>,
    sigma: Option<f64>,
) -> Result<(Vec<ArModel>, Vec<MeasurementNoise>)> {
    let mut models = Vec::new();
    let mut summary = Vec::new();
    if sigma.is_none() && envelopes.len() < test.channels() {
        return Err(CalibrateError::study(
            "measurement noise",
            format!(
                "{} ensemble envelopes for {} test channels",
                envelopes.len(),
                test.channels()
            ),
        ));
    }
    for (c, l) in test.labels().iter().enumerate() {
        let x = test.channel(c);
        let (model, source, note) = match sigma {
            Some(s) => (ArModel::white(s), RecordNoiseSource::Given, None),
            None => {
                let n = noise_of(x, &envelopes[c], quiet, test.dt(), cfc)?;
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

/// Per channel of `baseline` (in its order), the envelope of the spectra of the baseline
/// and of every run `runs` yields (each the same channels, in the same order, on the same
/// samples), each run read once and dropped: `S (min(T, 1024) / 2 + 1)` numbers held.
///
/// # Errors
/// A run that fails to read; a run of other channels or samples.
pub fn envelopes(
    baseline: &Histories,
    runs: impl IntoIterator<Item = Result<Histories>>,
) -> Result<Vec<MemberEnvelope>> {
    let t = baseline.samples();
    let mut out: Vec<MemberEnvelope> = (0..baseline.channels())
        .map(|c| {
            let mut e = MemberEnvelope::new(t);
            e.add(baseline.channel(c)).map(|()| e)
        })
        .collect::<std::result::Result<_, _>>()?;
    for run in runs {
        let run = run?;
        if run.labels() != baseline.labels() {
            return Err(CalibrateError::study(
                "measurement noise",
                "an ensemble run holds other channels than the baseline",
            ));
        }
        for (c, e) in out.iter_mut().enumerate() {
            e.add(run.channel(c))?;
        }
    }
    Ok(out)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use impactcal_core::drop_tower::DropTower;
    use impactcal_core::sampling::{Method, sample};
    use impactcal_core::{Model, Parameter};
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::study::m1::{Verdict, m1_with_noise};

    /// The drop tower's middle and top channels (the bottom one carries the contact's
    /// content up to the top of the spectrum: no band): 50 runs on a Halton design over the
    /// middle fifth of each parameter's range, the nominal run, and a test at an interior
    /// point with white noise of 1 % of each channel's RMS; with `push`, content the model
    /// lacks: a slow shift of [`PUSH`] times each channel's RMS over 20 ms after the impact
    /// (cosine ramps of 6 ms), inside the ensemble's bandwidth. Its noise is measured without the quiet part (the band alone). Returns
    /// the verdict, the measured noise over the noise added per channel, and M1's words.
    fn judged(push: bool, seed: u64) -> (Verdict, Vec<f64>, String) {
        let model = DropTower::new();
        let space = model.space();
        let labels = ["a2".to_string(), "a3".to_string()];
        let pts = sample(space, Method::ScrambledHalton, 50, 7)
            .unwrap()
            .points;
        let runs: Vec<Histories> = (0..50)
            .map(|i| {
                let p: Vec<f64> = space
                    .parameters()
                    .iter()
                    .enumerate()
                    .map(|(j, q)| {
                        let u = (pts[(i, j)] - q.lower) / (q.upper - q.lower);
                        q.lower + (0.35 + 0.2 * u) * (q.upper - q.lower)
                    })
                    .collect();
                model.simulate(&p).unwrap().select(&labels).unwrap()
            })
            .collect();
        let baseline = model
            .simulate(&space.nominal())
            .unwrap()
            .select(&labels)
            .unwrap();
        let x: Vec<f64> = space
            .parameters()
            .iter()
            .map(|p: &Parameter| p.lower + 0.43 * (p.upper - p.lower))
            .collect();
        let y = model.simulate(&x).unwrap().select(&labels).unwrap();
        let t = y.samples();
        // A Tukey window over samples 80 .. 280 with 60-sample cosine ramps.
        let window: Vec<f64> = (0..t)
            .map(|k| {
                if !push || !(80..280).contains(&k) {
                    return 0.0;
                }
                let ramp = (k - 80).min(279 - k).min(60) as f64 / 60.0;
                0.5 - 0.5 * (std::f64::consts::PI * ramp).cos()
            })
            .collect();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut data = y.data().to_vec();
        let mut sigma = Vec::new();
        for c in 0..2 {
            let ch = y.channel(c);
            let rms = (ch.iter().map(|v| v * v).sum::<f64>() / t as f64).sqrt();
            let e = ArModel::white(0.01 * rms).generate(t, &mut rng);
            sigma.push((e.iter().map(|v| v * v).sum::<f64>() / t as f64).sqrt());
            for (k, (v, e)) in data[c * t..(c + 1) * t].iter_mut().zip(e).enumerate() {
                *v += e + PUSH * rms * window[k];
            }
        }
        let test = Histories::new(y.labels().to_vec(), t, y.dt(), y.start(), "", data).unwrap();
        let env = envelopes(&baseline, runs.iter().cloned().map(Ok)).unwrap();
        let (noise, summary) = measured(&test, &env, 0, None, None).unwrap();
        let ratios = summary
            .iter()
            .zip(&sigma)
            .map(|(n, s)| {
                assert_eq!(n.source, RecordNoiseSource::ModelFreeBand, "{n:?}");
                n.sigma / s
            })
            .collect();
        let r = m1_with_noise(
            &runs[0].time(),
            runs.iter().cloned().map(Ok),
            &test,
            &noise,
            seed,
        )
        .unwrap();
        (r.verdict, ratios, r.statement)
    }

    /// A missing effect below the band (a slow shift inside the ensemble's bandwidth) is not taken for noise: the noise is measured within 20 % with
    /// it and without it, and M1 says cannot-explain with it, can-explain without.
    /// The missing effect's size, in each channel's RMS.
    const PUSH: f64 = 2.0;

    #[test]
    fn a_missing_effect_below_the_band_is_not_taken_for_noise() {
        for seed in 0..5 {
            let (v, ratios, s) = judged(false, seed);
            assert_eq!(v, Verdict::CanExplain, "seed {seed}: {s}");
            assert!(ratios.iter().all(|r| (r - 1.0).abs() < 0.2), "{ratios:?}");
            let (v, ratios, s) = judged(true, seed);
            assert_eq!(v, Verdict::CannotExplain, "seed {seed}: {s}");
            assert!(ratios.iter().all(|r| (r - 1.0).abs() < 0.2), "{ratios:?}");
        }
    }
}
