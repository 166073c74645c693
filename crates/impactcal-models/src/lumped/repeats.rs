//! Repeated tests of one article as one data set: one [`LumpedSystem`] driven by the base
//! channel of each test, the calibration tests' outputs side by side as one set of
//! histories, the holdout tests' likewise ([`LumpedRepeats`]); and the scatter between
//! repeats, channel by channel ([`scatter`]).
//!
//! **Labels.** With one test in a set, a channel keeps its test label (`accel_1`). With
//! several, the `k`-th test's (1-based, in the order given) is `r<k>/<label>`
//! ([`repeat_label`]), so the calibration set and the holdout set, which must then name as
//! many tests, carry the same labels: the closed loop judges a holdout channel with the
//! sensor gain it fitted to the calibration channel of the same label.
//!
//! **Scales.** The held quantities' ranges and held values (a rattle's gap, a rail, the
//! cubic term's reach) are scaled by the largest peak base acceleration over every test of
//! both sets, so that a freed quantity means the same physical thing on each test and its
//! range covers the largest drive; and the rattles' probe clearances, fractions of the
//! travel each spring reaches in the nominal run, take that travel from the run under the
//! strongest test's input on every test ([`LumpedModel::with_reference`]).
//!
//! **Which set runs** is a condition: [`REPEAT_SET`] `= 0` the calibration tests (the
//! default), `= 1` the holdout tests; the loop's holdout runs at `repeat_set = 1`.

use impactcal_core::{
    Candidate, CoreError, Enrichable, Histories, Model, Parameter, ParameterSpace,
};

use crate::error::{ModelsError, Result};
use crate::lumped::align::{delay_exact, input_shift};
use crate::lumped::model::LumpedModel;
use crate::lumped::system::LumpedSystem;

/// The condition that selects the set of tests a [`LumpedRepeats`] runs: 0 calibration, 1
/// holdout.
pub const REPEAT_SET: &str = "repeat_set";

/// The label of `channel` of the `k`-th test (0-based) of a set of `n` tests: the channel's
/// own label when `n == 1`, `r<k+1>/<channel>` otherwise.
pub fn repeat_label(channel: &str, k: usize, n: usize) -> String {
    if n == 1 {
        channel.to_string()
    } else {
        format!("r{}/{channel}", k + 1)
    }
}

/// One lumped system driven by each of several tests of the same article (see the module
/// docs): a [`Model`] whose run is every test of the active set, side by side.
#[derive(Debug, Clone, PartialEq)]
pub struct LumpedRepeats {
    /// `[calibration, holdout]`: per test, its name and its model.
    sets: [Vec<(String, LumpedModel)>; 2],
    /// Index into `sets` of the set that runs.
    active: usize,
}

impl LumpedRepeats {
    /// `system` driven by each of the `calibration` tests and each of the `holdout` tests,
    /// `(name, record)` each (the name is for messages: a file name).
    ///
    /// # Errors
    /// [`ModelsError::Record`] naming the test for: no calibration test, a holdout set of
    /// another size than the calibration set (unless empty), a test whose step, sample count
    /// or start differs from the first calibration test's (cut the records to one window),
    /// and what [`LumpedModel::new`] refuses of a record (its base channel missing, not
    /// finite or never moving).
    pub fn new(
        system: &LumpedSystem,
        calibration: &[(&str, &Histories)],
        holdout: &[(&str, &Histories)],
    ) -> Result<LumpedRepeats> {
        if calibration.is_empty() {
            return Err(ModelsError::record(
                "repeated tests",
                "no calibration test: name at least one",
            ));
        }
        if !holdout.is_empty() && holdout.len() != calibration.len() {
            return Err(ModelsError::record(
                "repeated tests",
                format!(
                    "{} holdout tests for {} calibration tests: a holdout set names as many \
                     tests as the calibration set, so that each holdout channel has the \
                     calibration channel of its label",
                    holdout.len(),
                    calibration.len()
                ),
            ));
        }
        let all = || calibration.iter().chain(holdout);
        same_window(&all().copied().collect::<Vec<_>>())?;
        let mut peak = 0.0_f64;
        let mut reference = Vec::new();
        for (name, record) in all() {
            let m = LumpedModel::new(system.clone(), record).map_err(|e| in_test(name, e))?;
            let own = m.input().iter().fold(0.0_f64, |p, a| p.max(a.abs()));
            if own > peak {
                peak = own;
                reference = m.input().to_vec();
            }
        }
        let build = |set: &[(&str, &Histories)]| -> Result<Vec<(String, LumpedModel)>> {
            set.iter()
                .map(|(name, record)| {
                    LumpedModel::with_reference(system.clone(), record, peak, &reference)
                        .map(|m| (name.to_string(), m))
                        .map_err(|e| in_test(name, e))
                })
                .collect()
        };
        Ok(LumpedRepeats {
            sets: [build(calibration)?, build(holdout)?],
            active: 0,
        })
    }

    /// The names of the calibration tests and of the holdout tests.
    pub fn tests(&self) -> [Vec<&str>; 2] {
        self.sets
            .each_ref()
            .map(|s| s.iter().map(|(n, _)| n.as_str()).collect())
    }

    /// The model of each test of the active set.
    pub fn models(&self) -> impl Iterator<Item = &LumpedModel> {
        self.sets[self.active].iter().map(|(_, m)| m)
    }

    /// The first calibration test's model: its space and candidates are every test's.
    fn lead(&self) -> &LumpedModel {
        &self.sets[0][0].1
    }

    /// Each model of both sets mapped by `f`.
    fn map(
        &self,
        f: impl Fn(&LumpedModel) -> impactcal_core::Result<LumpedModel>,
    ) -> impactcal_core::Result<LumpedRepeats> {
        let mut out = self.clone();
        for set in &mut out.sets {
            for (_, m) in set.iter_mut() {
                *m = f(m)?;
            }
        }
        Ok(out)
    }
}

/// Refuses tests whose step, sample count or start differs from the first's, naming the
/// test.
fn same_window(tests: &[(&str, &Histories)]) -> Result<()> {
    let Some((first_name, first)) = tests.first() else {
        return Ok(());
    };
    for (name, record) in tests {
        let same_dt = (record.dt() - first.dt()).abs() <= 1e-9 * first.dt();
        let same_start = (record.start() - first.start()).abs() <= 1e-6 * first.dt();
        if !same_dt || record.samples() != first.samples() || !same_start {
            return Err(ModelsError::record(
                format!("test `{name}`"),
                format!(
                    "{} samples from {} s every {} s, but `{first_name}` has {} from {} s \
                     every {} s: repeated tests share one window (cut each record to it)",
                    record.samples(),
                    record.start(),
                    record.dt(),
                    first.samples(),
                    first.start(),
                    first.dt()
                ),
            ));
        }
    }
    Ok(())
}

/// The channels `channels` (test labels) of each of `tests` side by side, labelled as a
/// [`LumpedRepeats`] labels its run ([`repeat_label`]): the measured side of a set of
/// repeated tests.
///
/// # Errors
/// [`ModelsError::Record`] for no test, tests of different windows, or a test without one
/// of the channels (naming the test and the channel).
pub fn side_by_side(tests: &[(&str, &Histories)], channels: &[String]) -> Result<Histories> {
    let Some((_, first)) = tests.first() else {
        return Err(ModelsError::record("repeated tests", "no test"));
    };
    same_window(tests)?;
    let n = tests.len();
    let mut labels = Vec::with_capacity(n * channels.len());
    let mut data = Vec::with_capacity(n * channels.len());
    for (k, (name, h)) in tests.iter().enumerate() {
        for c in channels {
            let y = h.channel_by_label(c).map_err(|e| {
                ModelsError::record(format!("test `{name}`"), format!("channel `{c}`: {e}"))
            })?;
            labels.push(repeat_label(c, k, n));
            data.push(y.to_vec());
        }
    }
    Ok(Histories::from_channels(
        labels,
        data,
        first.dt(),
        first.start(),
        first.unit(),
    )?)
}

/// `e` of the test `name`.
fn in_test(name: &str, e: ModelsError) -> ModelsError {
    ModelsError::record(format!("test `{name}`"), e.to_string())
}

impl Model for LumpedRepeats {
    fn space(&self) -> &ParameterSpace {
        self.lead().space()
    }

    /// Every test of the active set run at `params`, its channels labelled by
    /// [`repeat_label`], the tests in their order.
    fn simulate(&self, params: &[f64]) -> impactcal_core::Result<Histories> {
        let set = &self.sets[self.active];
        let n = set.len();
        let mut labels = Vec::new();
        let mut channels = Vec::new();
        let mut first: Option<Histories> = None;
        for (k, (_, m)) in set.iter().enumerate() {
            let h = m.simulate(params)?;
            for (c, label) in h.labels().iter().enumerate() {
                labels.push(repeat_label(label, k, n));
                channels.push(h.channel(c).to_vec());
            }
            first.get_or_insert(h);
        }
        let Some(first) = first else {
            return Err(CoreError::invalid_option(
                REPEAT_SET,
                self.active,
                "this set names no test",
            ));
        };
        Histories::from_channels(labels, channels, first.dt(), first.start(), first.unit())
    }
}

impl Enrichable for LumpedRepeats {
    fn candidates(&self) -> Vec<Candidate> {
        self.lead().candidates()
    }

    fn enrich(&self, added: &[Parameter]) -> impactcal_core::Result<Self> {
        self.map(|m| m.enrich(added))
    }

    /// [`REPEAT_SET`] selects the set (0 calibration, 1 holdout); every other name is a
    /// held quantity set on each test's model ([`LumpedModel`]'s `at_condition`).
    fn at_condition(&self, set: &[(String, f64)]) -> impactcal_core::Result<Self> {
        let mut active = self.active;
        let mut rest = Vec::with_capacity(set.len());
        for (name, value) in set {
            if name != REPEAT_SET {
                rest.push((name.clone(), *value));
                continue;
            }
            let rounded = value.round();
            let set = ((value - rounded).abs() <= 1e-9 && (0.0..=1.0).contains(&rounded))
                .then_some(rounded as usize);
            active = match set {
                Some(0) => 0,
                Some(_) if !self.sets[1].is_empty() => 1,
                Some(_) => {
                    return Err(CoreError::invalid_option(
                        "condition",
                        REPEAT_SET,
                        "1 runs the holdout tests, and none was given",
                    ));
                }
                None => {
                    return Err(CoreError::invalid_option(
                        "condition",
                        format!("{REPEAT_SET} = {value}"),
                        "0 runs the calibration tests, 1 the holdout tests",
                    ));
                }
            };
        }
        let mut out = if rest.is_empty() {
            self.clone()
        } else {
            self.map(|m| m.at_condition(&rest))?
        };
        out.active = active;
        Ok(out)
    }

    fn describe(&self, name: &str) -> Option<(String, String)> {
        self.lead().describe(name)
    }
}

/// The scatter between repeats of one channel: `y_i(t)` the `n` repeats, `m(t)` their
/// mean, `s(t) = sqrt(sum_i (y_i(t) - m(t))^2 / (n - 1))` their sample standard deviation
/// at each sample.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelScatter {
    /// The channel's test label.
    pub channel: String,
    /// `n`.
    pub repeats: usize,
    /// `sqrt(mean_t s(t)^2)`, the channel's unit: the standard deviation between repeats,
    /// averaged over the window.
    pub rms: f64,
    /// `rms / sqrt(mean_i mean_t y_i(t)^2)`: the scatter as a fraction of the repeats' own
    /// size.
    pub relative: f64,
    /// `min_i y_i(t)` at each sample: the lower edge of the repeats' envelope.
    pub lower: Vec<f64>,
    /// `max_i y_i(t)` at each sample: its upper edge.
    pub upper: Vec<f64>,
}

/// The time (s) by which each of `tests` triggered later than the first, read from the
/// channel `input` (the base acceleration, the same event in every test) by
/// cross-correlation to a fraction of a sample ([`input_shift`], lags up to a quarter of
/// the window): `y_k(t + shift_k)` matches `y_1(t)`. The first test's shift is 0.
///
/// # Errors
/// [`ModelsError::Record`] for fewer than two tests or tests of different windows (naming
/// the test), a test without the channel (naming it), or what [`input_shift`] refuses
/// (naming the test).
pub fn alignment(tests: &[(&str, &Histories)], input: &str) -> Result<Vec<f64>> {
    if tests.len() < 2 {
        return Err(ModelsError::record(
            "alignment of repeated tests",
            "needs at least two tests",
        ));
    }
    same_window(tests)?;
    fn read<'h>(name: &str, h: &'h Histories, input: &str) -> Result<&'h [f64]> {
        h.channel_by_label(input).map_err(|e| {
            ModelsError::record(format!("test `{name}`"), format!("input `{input}`: {e}"))
        })
    }
    let first = read(tests[0].0, tests[0].1, input)?;
    let max_lag = first.len() / 4;
    let dt = tests[0].1.dt();
    tests
        .iter()
        .map(|t| {
            let y = read(t.0, t.1, input)?;
            input_shift(first, y, max_lag)
                .map(|s| s * dt)
                .map_err(|e| in_test(t.0, e))
        })
        .collect()
}

/// The scatter between the repeats `tests` of each of `channels` (test labels), the tests
/// sharing one window, each read `shifts[k]` seconds later than its own time base (the
/// [`alignment`] on the input; zeros compare the samples as recorded). It measures what a
/// test of this article could be (the spread a repeat shows, with the measurement noise in
/// it), beside what the model could be.
///
/// # Errors
/// [`ModelsError::Record`] for fewer than two tests, tests of different windows (naming the
/// test), or a shift per test missing or not finite; a channel a test lacks (the core
/// error, naming it); a non-finite sample (naming the test, the channel and the sample).
pub fn scatter(
    tests: &[(&str, &Histories)],
    channels: &[String],
    shifts: &[f64],
) -> Result<Vec<ChannelScatter>> {
    let [(_, first), ..] = tests else {
        return Err(ModelsError::record(
            "scatter between repeats",
            "needs at least two tests",
        ));
    };
    if tests.len() < 2 {
        return Err(ModelsError::record(
            "scatter between repeats",
            "needs at least two tests",
        ));
    }
    if shifts.len() != tests.len() || shifts.iter().any(|s| !s.is_finite()) {
        return Err(ModelsError::record(
            "scatter between repeats",
            format!(
                "{} tests need as many finite shifts, got {:?}",
                tests.len(),
                shifts
            ),
        ));
    }
    same_window(tests)?;
    let n = tests.len();
    let len = first.samples();
    let dt = first.dt();
    channels
        .iter()
        .map(|channel| {
            let ys = tests
                .iter()
                .zip(shifts)
                .map(|((name, h), shift)| {
                    let y = h.channel_by_label(channel)?;
                    if let Some(k) = y.iter().position(|v| !v.is_finite()) {
                        return Err(ModelsError::record(
                            format!("test `{name}`, channel `{channel}`"),
                            format!("sample {k} is {}", y[k]),
                        ));
                    }
                    Ok(if *shift == 0.0 {
                        y.to_vec()
                    } else {
                        delay_exact(y, -shift / dt)
                    })
                })
                .collect::<Result<Vec<Vec<f64>>>>()?;
            let (mut var, mut power) = (0.0, 0.0);
            let mut lower = vec![f64::INFINITY; len];
            let mut upper = vec![f64::NEG_INFINITY; len];
            for t in 0..len {
                let mean = ys.iter().map(|y| y[t]).sum::<f64>() / n as f64;
                for y in &ys {
                    var += (y[t] - mean).powi(2);
                    power += y[t] * y[t];
                    lower[t] = lower[t].min(y[t]);
                    upper[t] = upper[t].max(y[t]);
                }
            }
            let rms = (var / ((n - 1) * len) as f64).sqrt();
            let size = (power / (n * len) as f64).sqrt();
            Ok(ChannelScatter {
                channel: channel.clone(),
                repeats: n,
                rms,
                relative: if size > 0.0 { rms / size } else { 0.0 },
                lower,
                upper,
            })
        })
        .collect()
}
