//! A two-channel toy model with closed-form responses for the stages' unit tests, and a
//! harness that runs the loop's first stages on it.
//!
//! Over `u = j / (T - 1)`, `j = 0..T`: channel `a` is `v k u^2 + c s_c(u) + m s_m(u)` and
//! channel `b` is `v k^2 u^1.5 + c t_c(u) + m t_m(u)`, with `k` declared, the candidates
//! `c` (range `[0, 1]`) and `m` (range `[-1, 1]`) held at 0, and the condition `v` held at
//! 1.

use std::cell::Cell;
use std::path::Path;

use impactcal_core::{
    Candidate, CoreError, Enrichable, Histories, Model, Parameter, ParameterSpace,
};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

use super::fit::Journaled;
use super::frame::{self, Setting};
use super::options::LoopOptions;
use super::setup::{self, Nominal};
use crate::error::Result;
use crate::study::{Silent, TestData};

/// Samples per channel.
pub const T: usize = 100;
/// Time step.
pub const DT: f64 = 1e-3;

/// The toy model (see the module docs).
#[derive(Debug, Clone)]
pub struct Toy {
    space: ParameterSpace,
    c: f64,
    m: f64,
    v: f64,
}

/// The signatures `(s_c, t_c, s_m, t_m)` at `u`.
fn signatures(u: f64) -> (f64, f64, f64, f64) {
    use std::f64::consts::PI;
    (
        u * (4.0 * PI * u).sin(),
        -0.5 * (3.0 * PI * u).sin(),
        u * u * (5.0 * PI * u).cos(),
        u * (6.0 * PI * u).sin(),
    )
}

impl Toy {
    /// The model with `k` in `[0.5, 2]` (nominal 1) and the held values given.
    pub fn new(c: f64, m: f64, v: f64) -> Self {
        let k = Parameter::new("k", 0.5, 2.0, 1.0).unwrap();
        Toy {
            space: ParameterSpace::new(vec![k]).unwrap(),
            c,
            m,
            v,
        }
    }

    /// The response at the point `p` of this model's space, channels `a` then `b`.
    pub fn channels(&self, p: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let get = |n: &str, held: f64| self.space.index_of(n).map_or(held, |i| p[i]);
        let (k, c, m) = (get("k", 1.0), get("c", self.c), get("m", self.m));
        (0..T)
            .map(|j| {
                let u = j as f64 / (T - 1) as f64;
                let (sc, tc, sm, tm) = signatures(u);
                (
                    self.v * k * u * u + c * sc + m * sm,
                    self.v * k * k * u.powf(1.5) + c * tc + m * tm,
                )
            })
            .unzip()
    }
}

impl Model for Toy {
    fn space(&self) -> &ParameterSpace {
        &self.space
    }
    fn simulate(&self, p: &[f64]) -> impactcal_core::Result<Histories> {
        let (a, b) = self.channels(p);
        Histories::from_channels(vec!["a".into(), "b".into()], vec![a, b], DT, 0.0, "")
    }
}

impl Enrichable for Toy {
    fn candidates(&self) -> Vec<Candidate> {
        let mut out = Vec::new();
        for (name, lower, held, group) in
            [("c", 0.0, self.c, "damping"), ("m", -1.0, self.m, "mass")]
        {
            if self.space.index_of(name).is_none() {
                let p = Parameter::new(name, lower, 1.0, held).unwrap();
                out.push(Candidate::new(p, group, name));
            }
        }
        out
    }
    fn enrich(&self, added: &[Parameter]) -> impactcal_core::Result<Self> {
        let mut params = self.space.parameters().to_vec();
        for p in added {
            self.check_candidate(p)?;
            params.push(p.clone());
        }
        Ok(Toy {
            space: ParameterSpace::new(params)?,
            ..self.clone()
        })
    }
    fn at_condition(&self, set: &[(String, f64)]) -> impactcal_core::Result<Self> {
        let mut m = self.clone();
        for (n, v) in set {
            if n != "v" {
                return Err(CoreError::invalid_option("condition", n, "not held"));
            }
            m.v = *v;
        }
        Ok(m)
    }
}

/// The truth's run at `k` plus white noise of standard deviation `sigma` (seeded), plus
/// `extra` (`S x T`, channel `a` then `b`) when given.
pub fn measured(truth: &Toy, k: f64, sigma: f64, seed: u64, extra: Option<&[f64]>) -> Histories {
    let (a, b) = truth.channels(&[k]);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let normal = Normal::new(0.0, sigma).unwrap();
    let mut data: Vec<f64> = a.into_iter().chain(b).collect();
    for (i, x) in data.iter_mut().enumerate() {
        *x += normal.sample(&mut rng) + extra.map_or(0.0, |e| e[i]);
    }
    let (a, b) = data.split_at(T);
    Histories::from_channels(
        vec!["a".into(), "b".into()],
        vec![a.to_vec(), b.to_vec()],
        DT,
        0.0,
        "",
    )
    .unwrap()
}

/// Options for the toy: the noise's `sigma` known, no trigger offset, gains held at 1, a
/// jitter small enough that the weights are `1 / sigma` to round-off, small budgets.
pub fn options(sigma: f64) -> LoopOptions {
    LoopOptions {
        sigma: Some(sigma),
        max_time_shift: Some(0.0),
        fit_gains: false,
        jitter: 1e-9,
        reconcile: 8,
        recalibrate: 12,
        max_added: 2,
        ..LoopOptions::default()
    }
}

/// A journaled runner in `dir` in this process, counting its runs in `used`.
pub fn journaled<'a>(dir: &'a Path, used: &'a Cell<usize>) -> Journaled<'a> {
    Journaled {
        dir,
        fingerprint: "toy",
        observer: &Silent,
        used,
        worker: None,
        condition: &[],
        plan: None,
        estimate: None,
        stored: None,
    }
}

/// Runs the loop's first stages (nominal run, plan, nuisance frame) of `model` against
/// `test` in a fresh folder, then `body` on what they give.
pub fn with_setting<M: Enrichable, R>(
    model: &M,
    test: &Histories,
    options: &LoopOptions,
    body: impl FnOnce(&Setting<'_>, &Nominal) -> Result<R>,
) -> Result<R> {
    with_filtered_setting(model, test, options, None, body)
}

/// [`with_setting`] with test and runs filtered with `cfc`.
pub fn with_filtered_setting<M: Enrichable, R>(
    model: &M,
    test: &Histories,
    options: &LoopOptions,
    cfc: Option<impactcal_core::Cfc>,
    body: impl FnOnce(&Setting<'_>, &Nominal) -> Result<R>,
) -> Result<R> {
    let dir = tempfile::tempdir().unwrap();
    let used = Cell::new(0usize);
    let runner = journaled(dir.path(), &used);
    let data = TestData {
        histories: test,
        map: None,
        cfc,
    };
    let nominal = setup::nominal(&runner, model, data)?;
    let plan = setup::plan(model, &nominal, options, 1)?;
    let runner = Journaled {
        plan: Some(&plan),
        ..runner
    };
    let setting = frame::nuisance(runner, model, &nominal, cfc, options)?;
    body(&setting, &nominal)
}

/// The relative L2 error by hand, for held unit gains, no offset and uniform weights: per
/// channel the bias is the mean of `test - y`, and the error is
/// `sqrt(sum (test - b - y)^2 / sum (test - b)^2)` over both channels.
pub fn rel_l2_by_hand(test: &[f64], y: &[f64]) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for s in 0..test.len() / T {
        let (z, y) = (&test[s * T..(s + 1) * T], &y[s * T..(s + 1) * T]);
        let b = z.iter().zip(y).map(|(z, y)| z - y).sum::<f64>() / T as f64;
        num += z
            .iter()
            .zip(y)
            .map(|(z, y)| (z - b - y).powi(2))
            .sum::<f64>();
        den += z.iter().map(|z| (z - b).powi(2)).sum::<f64>();
    }
    (num / den).sqrt()
}

/// The toy's response at `p` as one vector, channel `a` then `b`.
pub fn response(model: &Toy, p: &[f64]) -> Vec<f64> {
    let (a, b) = model.channels(p);
    a.into_iter().chain(b).collect()
}

/// A wave no candidate of the toy makes, `S x T`: `amplitude cos(11 pi u)` on `a` and
/// `amplitude sin(13 pi u)` on `b`.
pub fn foreign_wave(amplitude: f64) -> Vec<f64> {
    use std::f64::consts::PI;
    let u = |j: usize| j as f64 / (T - 1) as f64;
    (0..T)
        .map(|j| amplitude * (11.0 * PI * u(j)).cos())
        .chain((0..T).map(|j| amplitude * (13.0 * PI * u(j)).sin()))
        .collect()
}
