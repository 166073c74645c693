//! The closed loop on a model with simulation noise: the drop tower plus a smooth pattern
//! that any change of the parameters, however small, redraws (as a crash model's response
//! beyond its predictability horizon). The pattern grows after the impact and is several
//! times the measurement noise, so once the real effect is added, what remains is mostly
//! the difference between the truth's pattern and the model's: the model's own noise, which
//! the loop must not attribute to a further effect (docs/closed-loop.md, "The model's own
//! noise").

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use impactcal_calibrate::closeloop::{LoopOptions, LoopResult, run_loop};
use impactcal_calibrate::study::{Silent, TestData};
use impactcal_core::drop_tower::DropTower;
use impactcal_core::synthetic::{Measurement, measured};
use impactcal_core::{
    Candidate, CoreError, Enrichable, Histories, Model, Parameter, ParameterSpace,
};

/// The drop tower with simulation noise of `level` times each channel's RMS (once grown).
#[derive(Debug, Clone)]
struct NoisyTower {
    inner: DropTower,
    level: f64,
}

/// FNV-1a over the bits of the point: a different pattern for any change of it.
fn seed_of(p: &[f64]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in p.iter().flat_map(|v| v.to_bits().to_le_bytes()) {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// A uniform draw in [0, 1) from a 64-bit state (splitmix64).
fn next(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    (z ^ (z >> 31)) as f64 / u64::MAX as f64
}

impl Model for NoisyTower {
    fn space(&self) -> &ParameterSpace {
        self.inner.space()
    }

    fn simulate(&self, p: &[f64]) -> Result<Histories, CoreError> {
        let h = self.inner.simulate(p)?;
        let mut state = seed_of(p);
        let channels: Vec<Vec<f64>> = (0..h.channels())
            .map(|c| {
                let y = h.channel(c);
                let rms = (y.iter().map(|v| v * v).sum::<f64>() / y.len() as f64).sqrt();
                let waves: Vec<(f64, f64)> = (0..5)
                    .map(|_| (30.0 + 270.0 * next(&mut state), 6.3 * next(&mut state)))
                    .collect();
                y.iter()
                    .enumerate()
                    .map(|(k, v)| {
                        let t = h.start() + k as f64 * h.dt();
                        let grown = ((t - 0.025) / 0.01).clamp(0.0, 1.0);
                        let pattern: f64 = waves
                            .iter()
                            .map(|(f, phi)| (2.0 * std::f64::consts::PI * f * t + phi).sin())
                            .sum::<f64>()
                            / 5f64.sqrt();
                        v + self.level * rms * grown * pattern
                    })
                    .collect()
            })
            .collect();
        Histories::from_channels(h.labels().to_vec(), channels, h.dt(), h.start(), h.unit())
    }
}

impl Enrichable for NoisyTower {
    fn candidates(&self) -> Vec<Candidate> {
        self.inner.candidates()
    }

    fn enrich(&self, added: &[Parameter]) -> Result<Self, CoreError> {
        Ok(NoisyTower {
            inner: self.inner.enrich(added)?,
            level: self.level,
        })
    }

    fn at_condition(&self, set: &[(String, f64)]) -> Result<Self, CoreError> {
        Ok(NoisyTower {
            inner: self.inner.at_condition(set)?,
            level: self.level,
        })
    }
}

const TRUE_POINT: [f64; 2] = [75.0, 9e5];
/// The model's own noise, as a fraction of each channel's RMS: twice the measurement
/// noise (40 dB).
const LEVEL: f64 = 0.02;

fn run(hidden: &[(&str, f64)], seed: u64) -> LoopResult {
    let model = NoisyTower {
        inner: DropTower::new(),
        level: LEVEL,
    };
    let set: Vec<(String, f64)> = hidden.iter().map(|(n, v)| (n.to_string(), *v)).collect();
    let truth = model.at_condition(&set).unwrap();
    let y = truth.simulate(&TRUE_POINT).unwrap();
    let test = measured(
        &y,
        &Measurement {
            time_shift: 3e-4,
            snr_db: Some(40.0),
            seed,
            ..Measurement::default()
        },
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let data = TestData {
        histories: &test,
        map: None,
        cfc: None,
    };
    let options = LoopOptions {
        seed,
        ..LoopOptions::default()
    };
    run_loop(
        &model,
        "noisy drop tower",
        data,
        None,
        &options,
        dir.path(),
        &Silent,
    )
    .unwrap()
}

/// The truth has damping 0.03 the model holds at zero. Over six seeds the loop adds the
/// damping and nothing else. Without the model-noise rules and the control recalibration,
/// seed 6 also added `stiffness_scale` at 0.99845 (truth 1: the held value), which
/// realised most of a residual made of the two noise patterns; now at least one second
/// addition is tried and refused.
#[test]
fn a_real_effect_is_added_and_the_models_own_noise_adds_nothing_after_it() {
    let mut bad = Vec::new();
    let mut refused = 0;
    for seed in 1..=6 {
        let r = run(&[("damping", 0.03)], seed);
        let names: Vec<&str> = r.added.iter().map(|a| a.name.as_str()).collect();
        let e = &r.errors.calibration;
        if names != ["damping"] || e.enriched >= 0.5 * e.calibrated {
            bad.push(format!("seed {seed}: {names:?} {e:?} ({})", r.stopped));
        }
        refused += usize::from(r.models.iter().any(|m| !m.kept));
    }
    assert!(bad.is_empty(), "{bad:#?}");
    assert!(refused >= 1, "no second addition was tried and refused");
}

/// No hidden effect: whatever the verdict (the calibration of a model this noisy does not
/// always reach the floor), nothing is added.
#[test]
fn without_a_hidden_effect_the_models_own_noise_adds_nothing() {
    for seed in 1..=3 {
        let r = run(&[], seed);
        assert!(
            r.added.is_empty(),
            "seed {seed}: {:?} ({})",
            r.added,
            r.stopped
        );
    }
}
