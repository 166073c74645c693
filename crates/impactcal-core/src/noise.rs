//! Simulation noise: the spread a model produces on its own when its parameters move by
//! amounts far below any engineering tolerance, measured with a jitter ensemble.
//!
//! An explicit crash model is not a smooth function of its parameters: buckling and folding
//! are bifurcations, and a thin-walled structure that rings after an impact amplifies small
//! differences. Repeated runs of a model at (almost) the same point therefore spread, and the
//! spread grows with time. A calibration must neither fit that spread nor mistake it for
//! model-form error, so it is measured here as a quantity of its own:
//!
//! 1. **Jitter ensemble.** `J` runs at `x_j = x + eps s u_j` with `u_j` uniform in
//!    `[-1, 1]^d` (seeded), `s_i = |x_i|`, or the width of the parameter's range where
//!    `x_i = 0`: every parameter moves by a relative amount of at most `eps`.
//! 2. **Spread.** Per channel `c` and sample `k`, the sample standard deviation over the
//!    ensemble, `sigma_c(t_k) = sqrt(sum_j (y_jc(t_k) - mean_c(t_k))^2 / (J - 1))`.
//! 3. **Scale.** Per channel, the root mean square of the nominal run over the record,
//!    `S_c = sqrt(mean_k y_c(t_k)^2)`.
//! 4. **Predictability horizon.** For a fraction `f`, the first sample time at which
//!    `sigma_c(t) > f S_c`; `None` when the spread stays within `f S_c` over the whole
//!    record. Channels that carry no signal (a lateral velocity in a symmetric impact) have a
//!    horizon at their first sample: they cannot be predicted and should be dropped.
//!
//! Optionally every run is passed through a CFC filter ([`Cfc::filter`])
//! before the spread is formed, as test data would be.
//!
//! ```
//! use impactcal_core::noise::{JitterOptions, SimulationNoise};
//! use impactcal_core::{Histories, Model, Parameter, ParameterSpace};
//!
//! /// y(t) = a sin(w t), and a channel in which the deviation of a from 1 grows as exp(40 t).
//! struct Toy(ParameterSpace);
//! impl Model for Toy {
//!     fn space(&self) -> &ParameterSpace { &self.0 }
//!     fn simulate(&self, p: &[f64]) -> impactcal_core::Result<Histories> {
//!         let t: Vec<f64> = (0..200).map(|k| k as f64 * 1e-3).collect();
//!         let smooth = t.iter().map(|t| p[0] * (p[1] * t).sin()).collect();
//!         let chaotic = t.iter().map(|t| 1.0 + (p[0] - 1.0) * (40.0 * t).exp()).collect();
//!         Histories::from_channels(vec!["a".into(), "b".into()], vec![smooth, chaotic], 1e-3, 0.0, "")
//!     }
//! }
//! let model = Toy(ParameterSpace::new(vec![
//!     Parameter::new("a", 0.5, 2.0, 1.0)?,
//!     Parameter::new("w", 10.0, 50.0, 30.0)?,
//! ])?);
//! let noise = SimulationNoise::measure(&model, &[1.0, 30.0], &JitterOptions::new(8, 1e-4, 1))?;
//! // The smooth channel stays within 1 % of its signal; the growing one does not.
//! assert_eq!(noise.horizon(0, 0.01), None);
//! let h = noise.horizon(1, 0.01).expect("the growing channel is unpredictable");
//! assert!(h > 0.1 && h < 0.17, "{h}");
//! assert_eq!(noise.predictable_channels(0.199, 0.01), vec![0]);
//! # Ok::<(), impactcal_core::CoreError>(())
//! ```

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::error::{CoreError, ParamGuard, Result};
use crate::histories::Histories;
use crate::model::Model;
use crate::signal::Cfc;
use crate::space::ParameterSpace;

/// Settings of a jitter ensemble.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct JitterOptions {
    /// Number of jittered runs `J`, at least 2.
    pub runs: usize,
    /// Largest relative perturbation `eps` of each parameter, in `(0, 0.1]`.
    pub eps: f64,
    /// Seed of the perturbations.
    pub seed: u64,
    /// CFC class applied to every run before the spread is formed (`None`: raw).
    pub cfc: Option<Cfc>,
}

impl JitterOptions {
    /// `runs` runs with relative perturbations of at most `eps`, seeded, unfiltered.
    pub fn new(runs: usize, eps: f64, seed: u64) -> Self {
        JitterOptions {
            runs,
            eps,
            seed,
            cfc: None,
        }
    }

    /// The same options with every run filtered at channel frequency class `cfc`.
    #[must_use]
    pub fn with_cfc(mut self, cfc: Cfc) -> Self {
        self.cfc = Some(cfc);
        self
    }
}

impl ParamGuard for JitterOptions {
    /// The options themselves.
    type Checked = JitterOptions;

    /// Checks the options.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for fewer than 2 runs or `eps` outside `(0, 0.1]`.
    fn check_ref(&self) -> Result<()> {
        if self.runs < 2 {
            return Err(CoreError::invalid_option(
                "jitter runs",
                self.runs,
                "a jitter ensemble needs at least 2 runs",
            ));
        }
        if !(self.eps > 0.0 && self.eps <= 0.1) {
            return Err(CoreError::invalid_option(
                "jitter eps",
                self.eps,
                "must lie in (0, 0.1]",
            ));
        }
        Ok(())
    }

    fn check(self) -> Result<JitterOptions> {
        self.check_ref()?;
        Ok(self)
    }
}

impl Default for JitterOptions {
    /// 8 runs, `eps` 1e-4, seed 0, unfiltered.
    fn default() -> Self {
        JitterOptions::new(8, 1e-4, 0)
    }
}

/// The jittered points of an ensemble about `point` (see the module docs): `options.runs`
/// points, each coordinate moved by `eps s_i u` with `u` uniform in `[-1, 1]`.
///
/// # Errors
/// [`CoreError::Invalid`] for invalid options; the space's errors for a point of the wrong
/// length or with a non-finite coordinate.
pub fn jitter_points(
    space: &ParameterSpace,
    point: &[f64],
    options: &JitterOptions,
) -> Result<Vec<Vec<f64>>> {
    options.check_ref()?;
    space.to_unit(point)?;
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let scales: Vec<f64> = space
        .parameters()
        .iter()
        .zip(point)
        .map(|(p, &x)| if x != 0.0 { x.abs() } else { p.width() })
        .collect();
    Ok((0..options.runs)
        .map(|_| {
            point
                .iter()
                .zip(&scales)
                .map(|(&x, &s)| x + options.eps * s * rng.random_range(-1.0..=1.0))
                .collect()
        })
        .collect())
}

/// The noise a model produces on its own at one point: per channel and per sample the
/// spread of a jitter ensemble, with the nominal run it is compared with.
///
/// `spread[c][k]` and `nominal[c][k]` are channel `c` at time `start + k dt`. Serialises to
/// JSON with serde (every field below).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SimulationNoise {
    /// Parameter names, in the order of `point` (empty when built from runs).
    pub parameters: Vec<String>,
    /// The point the ensemble was run about (empty when built from runs).
    pub point: Vec<f64>,
    /// The ensemble settings (`runs` is the number of runs used).
    pub options: JitterOptions,
    /// Channel labels.
    pub labels: Vec<String>,
    /// Unit of the channels.
    pub unit: String,
    /// Sampling step.
    pub dt: f64,
    /// Time of the first sample.
    pub start: f64,
    /// The nominal run (filtered when `options.cfc` is set), channels x samples.
    pub nominal: Vec<Vec<f64>>,
    /// The ensemble standard deviation, channels x samples.
    pub spread: Vec<Vec<f64>>,
    /// Root mean square of each nominal channel over the record.
    pub scale: Vec<f64>,
}

impl SimulationNoise {
    /// Runs the nominal point and a jitter ensemble about it (in parallel, through
    /// [`Model::simulate_batch`]) and measures the spread.
    ///
    /// # Errors
    /// As [`jitter_points`]; the first failed run (index 0 is the nominal point, `j` the
    /// `j`-th jittered one) as [`CoreError::Simulation`] wrapping its
    /// [`crate::RunFailure`]; as
    /// [`from_runs`](Self::from_runs) (and the CFC filter) for histories that do not match.
    pub fn measure<M: Model>(model: &M, point: &[f64], options: &JitterOptions) -> Result<Self> {
        let mut points = vec![point.to_vec()];
        points.extend(jitter_points(model.space(), point, options)?);
        let mut runs = model
            .simulate_batch(&points)
            .into_all()
            .map_err(CoreError::simulation)?;
        let nominal = runs.remove(0);
        let mut noise = Self::from_runs_filtered(&nominal, &runs, options.cfc)?;
        noise.parameters = model
            .space()
            .parameters()
            .iter()
            .map(|p| p.name.clone())
            .collect();
        noise.point = point.to_vec();
        noise.options = JitterOptions {
            runs: runs.len(),
            ..*options
        };
        Ok(noise)
    }

    /// The spread of `runs` (at least 2) about a `nominal` run, all with the same labels,
    /// samples, step and start (filter them first if wanted).
    ///
    /// # Errors
    /// [`CoreError::Invalid`] for fewer than 2 runs or runs that do not match the nominal.
    pub fn from_runs(nominal: &Histories, runs: &[Histories]) -> Result<Self> {
        Self::from_runs_filtered(nominal, runs, None)
    }

    /// [`from_runs`](Self::from_runs) over `count` runs read one at a time: `read(j)` gives
    /// run `j` (and may fail with the caller's error). Each run is read twice, once for the
    /// mean and once for the spread about it, so that only the nominal run, two
    /// channels x samples accumulators and one run are held whatever `count` is. The result
    /// is the same, bit for bit, as `from_runs` on the same runs.
    ///
    /// # Errors
    /// [`CoreError::Invalid`] (converted) for `count < 2` or a run that does not match the
    /// nominal; whatever `read` returns.
    pub fn from_run_reader<E: From<CoreError>>(
        nominal: &Histories,
        count: usize,
        read: &mut dyn FnMut(usize) -> std::result::Result<Histories, E>,
    ) -> std::result::Result<Self, E> {
        Self::accumulate(nominal, count, None, read)
    }

    fn from_runs_filtered(
        nominal: &Histories,
        runs: &[Histories],
        cfc: Option<Cfc>,
    ) -> Result<Self> {
        Self::accumulate(nominal, runs.len(), cfc, &mut |j| Ok(runs[j].clone()))
    }

    /// The spread of `count` runs given by `read` about `nominal`, each channel filtered
    /// with `cfc` when given: two passes over the runs (the mean, then the sum of squares
    /// about it), each summing over the runs in order.
    fn accumulate<E: From<CoreError>>(
        nominal: &Histories,
        count: usize,
        cfc: Option<Cfc>,
        read: &mut dyn FnMut(usize) -> std::result::Result<Histories, E>,
    ) -> std::result::Result<Self, E> {
        if count < 2 {
            return Err(CoreError::Invalid(format!(
                "the spread needs at least 2 runs, got {count}"
            ))
            .into());
        }
        let channels = |h: &Histories| -> Result<Vec<Vec<f64>>> {
            (0..h.channels())
                .map(|c| match cfc {
                    Some(f) => f.filter(h.channel(c), h.dt(), &h.labels()[c]),
                    None => Ok(h.channel(c).to_vec()),
                })
                .collect()
        };
        let mut run = |j: usize| -> std::result::Result<Vec<Vec<f64>>, E> {
            let r = read(j)?;
            let same = r.labels() == nominal.labels()
                && r.samples() == nominal.samples()
                && (r.dt() - nominal.dt()).abs() <= 1e-9 * nominal.dt()
                && (r.start() - nominal.start()).abs() <= 1e-9 * nominal.dt();
            if !same {
                return Err(CoreError::Invalid(format!(
                    "run {j} does not match the nominal run (labels, samples, step or start)"
                ))
                .into());
            }
            Ok(channels(&r)?)
        };
        let nom = channels(nominal)?;
        let n = nominal.samples();
        let jf = count as f64;
        let mut mean: Vec<Vec<f64>> = vec![vec![0.0; n]; nom.len()];
        for j in 0..count {
            for (acc, ch) in mean.iter_mut().zip(run(j)?) {
                acc.iter_mut().zip(ch).for_each(|(a, v)| *a += v);
            }
        }
        mean.iter_mut()
            .for_each(|ch| ch.iter_mut().for_each(|a| *a /= jf));
        let mut spread: Vec<Vec<f64>> = vec![vec![0.0; n]; nom.len()];
        for j in 0..count {
            for ((acc, m), ch) in spread.iter_mut().zip(&mean).zip(run(j)?) {
                for ((a, mk), v) in acc.iter_mut().zip(m).zip(ch) {
                    *a += (v - mk).powi(2);
                }
            }
        }
        spread
            .iter_mut()
            .for_each(|ch| ch.iter_mut().for_each(|a| *a = (*a / (jf - 1.0)).sqrt()));
        let scale = nom
            .iter()
            .map(|y| (y.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt())
            .collect();
        Ok(SimulationNoise {
            parameters: Vec::new(),
            point: Vec::new(),
            options: JitterOptions {
                runs: count,
                eps: 0.0,
                seed: 0,
                cfc,
            },
            labels: nominal.labels().to_vec(),
            unit: nominal.unit().to_string(),
            dt: nominal.dt(),
            start: nominal.start(),
            nominal: nom,
            spread,
            scale,
        })
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.labels.len()
    }

    /// Number of samples per channel.
    pub fn samples(&self) -> usize {
        self.spread.first().map_or(0, Vec::len)
    }

    /// Time of sample `k`.
    pub fn time(&self, k: usize) -> f64 {
        self.start + k as f64 * self.dt
    }

    /// The index of the channel labelled `label`.
    pub fn index_of(&self, label: &str) -> Option<usize> {
        self.labels.iter().position(|l| l == label)
    }

    /// The first time at which the spread of channel `c` exceeds `fraction` of its scale,
    /// or `None` when it never does within the record (see the module docs).
    ///
    /// # Panics
    /// When `c` is not a channel index.
    pub fn horizon(&self, c: usize, fraction: f64) -> Option<f64> {
        let bound = fraction * self.scale[c];
        self.spread[c]
            .iter()
            .position(|&s| s > bound)
            .map(|k| self.time(k))
    }

    /// [`horizon`](Self::horizon) of every channel.
    pub fn horizons(&self, fraction: f64) -> Vec<Option<f64>> {
        (0..self.channels())
            .map(|c| self.horizon(c, fraction))
            .collect()
    }

    /// The channels whose spread stays within `fraction` of their scale at every sample up
    /// to time `until` (inclusive): those a calibration can use over the window
    /// `[start, until]`.
    pub fn predictable_channels(&self, until: f64, fraction: f64) -> Vec<usize> {
        (0..self.channels())
            .filter(|&c| self.horizon(c, fraction).is_none_or(|h| h > until))
            .collect()
    }

    /// The relative size of the noise over the window `[start, until]` and the channels
    /// `channels` (all when empty): `sqrt(sum sigma^2) / sqrt(sum y_nominal^2)` over those
    /// channels and samples, the ensemble counterpart of a relative L2 difference between
    /// two runs (which for independent runs is about `sqrt(2)` times larger).
    pub fn relative_spread(&self, until: f64, channels: &[usize]) -> f64 {
        let all: Vec<usize>;
        let chans = if channels.is_empty() {
            all = (0..self.channels()).collect();
            &all
        } else {
            channels
        };
        let last = self.samples_until(until);
        let (mut num, mut den) = (0.0, 0.0);
        for &c in chans {
            for k in 0..last {
                num += self.spread[c][k].powi(2);
                den += self.nominal[c][k].powi(2);
            }
        }
        if den > 0.0 { (num / den).sqrt() } else { 0.0 }
    }

    /// Horizons summarised per group of channels, the group of a channel being
    /// `group(label)` (for example its axis or the part it lies on); groups in order of
    /// first appearance.
    pub fn horizons_by<G: Fn(&str) -> String>(&self, fraction: f64, group: G) -> Vec<GroupHorizon> {
        let mut groups: Vec<(String, Vec<Option<f64>>)> = Vec::new();
        for (c, label) in self.labels.iter().enumerate() {
            let g = group(label);
            let h = self.horizon(c, fraction);
            match groups.iter_mut().find(|(name, _)| *name == g) {
                Some((_, v)) => v.push(h),
                None => groups.push((g, vec![h])),
            }
        }
        let end = self.time(self.samples().saturating_sub(1));
        groups
            .into_iter()
            .map(|(group, hs)| {
                let mut t: Vec<f64> = hs.iter().map(|h| h.unwrap_or(f64::INFINITY)).collect();
                t.sort_by(f64::total_cmp);
                let q = |p: f64| {
                    let v = t[((t.len() - 1) as f64 * p).round() as usize];
                    v.is_finite().then_some(v)
                };
                GroupHorizon {
                    group,
                    channels: hs.len(),
                    predictable_to_end: hs.iter().filter(|h| h.is_none()).count(),
                    first: q(0.0),
                    quartile: q(0.25),
                    median: q(0.5),
                    record_end: end,
                }
            })
            .collect()
    }

    fn samples_until(&self, until: f64) -> usize {
        let n = self.samples();
        if until.is_nan() || until < self.start {
            return 0;
        }
        (((until - self.start) / self.dt * (1.0 + 1e-12)).floor() as usize + 1).min(n)
    }
}

/// The horizons of a group of channels (see [`SimulationNoise::horizons_by`]); `None`
/// means "not within the record".
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GroupHorizon {
    /// Group name.
    pub group: String,
    /// Number of channels in the group.
    pub channels: usize,
    /// Channels predictable over the whole record.
    pub predictable_to_end: usize,
    /// The earliest horizon in the group.
    pub first: Option<f64>,
    /// The lower quartile of the horizons (a quarter of the channels are lost by then).
    pub quartile: Option<f64>,
    /// The median horizon.
    pub median: Option<f64>,
    /// Time of the last sample of the record.
    pub record_end: f64,
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::float_cmp)]
mod tests {
    use super::*;
    use crate::space::Parameter;

    /// Two channels: `a t` (smooth in a) and `exp(g t)` scaled by the deviation of `a`
    /// from 1 (a perturbation that grows), plus a constant.
    struct Growth(ParameterSpace);

    impl Model for Growth {
        fn space(&self) -> &ParameterSpace {
            &self.0
        }
        fn simulate(&self, p: &[f64]) -> Result<Histories> {
            let t: Vec<f64> = (0..1001).map(|k| k as f64 * 0.001).collect();
            let smooth = t.iter().map(|t| p[0] * t).collect();
            let grow = t
                .iter()
                .map(|t| 1.0 + (p[0] - 1.0) * (p[1] * t).exp())
                .collect();
            Histories::from_channels(
                vec!["s".into(), "g".into()],
                vec![smooth, grow],
                0.001,
                0.0,
                "m/s",
            )
        }
    }

    fn model() -> Growth {
        Growth(
            ParameterSpace::new(vec![
                Parameter::new("a", 0.5, 2.0, 1.0).unwrap(),
                Parameter::new("g", 0.0, 20.0, 10.0).unwrap(),
            ])
            .unwrap(),
        )
    }

    #[test]
    fn jitter_points_are_seeded_relative_and_bounded() {
        let space = model().0;
        let o = JitterOptions::new(50, 1e-3, 7);
        let a = jitter_points(&space, &[1.0, 0.0], &o).unwrap();
        assert_eq!(a, jitter_points(&space, &[1.0, 0.0], &o).unwrap());
        assert_ne!(
            a,
            jitter_points(&space, &[1.0, 0.0], &JitterOptions { seed: 8, ..o }).unwrap()
        );
        for p in &a {
            assert!((p[0] - 1.0).abs() <= 1e-3);
            // A zero coordinate moves by eps times the range width (20).
            assert!(p[1].abs() <= 20.0 * 1e-3);
        }
        assert!(a.iter().any(|p| p[1].abs() > 5e-3));
        assert!(jitter_points(&space, &[1.0], &o).is_err());
        assert!(jitter_points(&space, &[1.0, 0.0], &JitterOptions::new(1, 1e-3, 0)).is_err());
        assert!(jitter_points(&space, &[1.0, 0.0], &JitterOptions::new(4, 0.0, 0)).is_err());
    }

    /// The spread of `a t` is `t` times the standard deviation of `a`; the growing channel
    /// crosses 10 % of its scale where `std(a) exp(g t) = 0.1 S`.
    #[test]
    fn spread_and_horizon_match_the_closed_form() {
        let m = model();
        let o = JitterOptions::new(16, 1e-3, 3);
        let noise = SimulationNoise::measure(&m, &[1.0, 10.0], &o).unwrap();
        let pts = jitter_points(m.space(), &[1.0, 10.0], &o).unwrap();
        let a: Vec<f64> = pts.iter().map(|p| p[0]).collect();
        let mean = a.iter().sum::<f64>() / 16.0;
        let sd = (a.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 15.0).sqrt();
        // Samples every 1 ms: sample k is t = k / 1000.
        for k in [0usize, 100, 500, 1000] {
            let t = k as f64 * 0.001;
            assert!((noise.spread[0][k] - sd * t).abs() <= 1e-12, "k = {k}");
        }
        // The growing channel: spread of (a - 1) exp(g t) with g jittered too; within 2 %.
        let k = 800;
        let vals: Vec<f64> = pts
            .iter()
            .map(|p| 1.0 + (p[0] - 1.0) * (p[1] * 0.8).exp())
            .collect();
        let mv = vals.iter().sum::<f64>() / 16.0;
        let sv = (vals.iter().map(|x| (x - mv).powi(2)).sum::<f64>() / 15.0).sqrt();
        assert!((noise.spread[1][k] - sv).abs() <= 1e-12);
        assert_eq!(noise.scale[1], 1.0);
        let h = noise.horizon(1, 0.1).unwrap();
        let expect = (0.1 / sd).ln() / 10.0;
        assert!((h - expect).abs() <= 0.03, "{h} vs {expect}");
        assert_eq!(noise.horizon(0, 0.1), None);
        assert_eq!(noise.predictable_channels(1.0, 0.1), vec![0]);
        assert_eq!(noise.predictable_channels(h - 0.01, 0.1), vec![0, 1]);
        assert_eq!(noise.parameters, vec!["a", "g"]);
        assert_eq!(noise.options.runs, 16);
        // The smooth channel's relative spread is small, the growing one's over the whole
        // record is not.
        assert!(noise.relative_spread(1.0, &[0]) < 1e-3);
        assert!(noise.relative_spread(1.0, &[1]) > 0.1);
    }

    #[test]
    fn group_summaries_and_json_round_trip() {
        let noise =
            SimulationNoise::measure(&model(), &[1.0, 10.0], &JitterOptions::new(6, 1e-3, 1))
                .unwrap();
        let groups = noise.horizons_by(0.1, |l| {
            if l == "s" {
                "smooth".into()
            } else {
                "other".into()
            }
        });
        assert_eq!(groups.len(), 2);
        assert_eq!(groups[0].group, "smooth");
        assert_eq!(groups[0].predictable_to_end, 1);
        assert_eq!(groups[0].median, None);
        assert_eq!(groups[1].median, noise.horizon(1, 0.1));
        let json = serde_json::to_string(&noise).unwrap();
        let back: SimulationNoise = serde_json::from_str(&json).unwrap();
        assert_eq!(back, noise);
    }

    #[test]
    fn runs_that_do_not_match_are_refused() {
        let m = model();
        let a = m.simulate(&[1.0, 10.0]).unwrap();
        let b = a.select(&["s"]).unwrap();
        assert!(SimulationNoise::from_runs(&a, std::slice::from_ref(&a)).is_err());
        assert!(SimulationNoise::from_runs(&a, &[a.clone(), b]).is_err());
        let ok = SimulationNoise::from_runs(&a, &[a.clone(), a.clone()]).unwrap();
        assert!(ok.spread.iter().flatten().all(|&s| s == 0.0));
    }

    #[test]
    fn a_cfc_filter_is_applied_to_every_run() {
        let m = model();
        let o = JitterOptions::new(4, 1e-3, 2).with_cfc(Cfc::Cfc60);
        let noise = SimulationNoise::measure(&m, &[1.0, 10.0], &o).unwrap();
        let raw = m.simulate(&[1.0, 10.0]).unwrap();
        let f = Cfc::Cfc60.filter(raw.channel(1), 0.001, "g").unwrap();
        assert_eq!(noise.nominal[1], f);
        // 1 kHz sampling cannot carry CFC 1000: a typed error, not a silent result.
        let o = JitterOptions::new(4, 1e-3, 2).with_cfc(Cfc::Cfc1000);
        assert!(matches!(
            SimulationNoise::measure(&m, &[1.0, 10.0], &o),
            Err(CoreError::FilterClass { .. })
        ));
    }

    /// Runs read one at a time give the spread of the same runs held together, bit for
    /// bit, each run read twice; a failed read is the caller's error.
    #[test]
    fn runs_read_one_at_a_time_give_the_same_spread() {
        let m = model();
        let o = JitterOptions::new(7, 1e-3, 5);
        let pts = jitter_points(m.space(), &[1.0, 10.0], &o).unwrap();
        let runs: Vec<Histories> = pts.iter().map(|p| m.simulate(p).unwrap()).collect();
        let nominal = m.simulate(&[1.0, 10.0]).unwrap();
        let held = SimulationNoise::from_runs(&nominal, &runs).unwrap();
        let mut reads = vec![0; runs.len()];
        let streamed = SimulationNoise::from_run_reader(&nominal, runs.len(), &mut |j| {
            reads[j] += 1;
            Ok::<_, CoreError>(runs[j].clone())
        })
        .unwrap();
        assert_eq!(streamed, held);
        assert!(reads.iter().all(|&r| r == 2), "{reads:?}");
        let failed = SimulationNoise::from_run_reader(&nominal, 3, &mut |j| {
            if j == 2 {
                Err(CoreError::Invalid("run 2 is gone".into()))
            } else {
                Ok(runs[j].clone())
            }
        });
        assert!(failed.unwrap_err().to_string().contains("run 2 is gone"));
    }
}
