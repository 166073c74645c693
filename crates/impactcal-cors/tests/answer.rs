//! The answer under a noisy objective: the smoothed surrogate's lowest evaluated point
//! against the luckiest sample, checked against the true function.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use impactcal_core::{Parameter, ParameterSpace};
use impactcal_cors::{Cors, CorsOptions};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

const CENTRE: [f64; 3] = [0.3, 0.6, 0.45];

fn space() -> ParameterSpace {
    ParameterSpace::new(
        (0..3)
            .map(|i| Parameter::new(format!("x{i}"), 0.0, 1.0, 0.5).unwrap())
            .collect(),
    )
    .unwrap()
}

/// `sum (x_i - c_i)^2`: minimum 0 at `CENTRE`; its range over the unit cube is about 1.2.
fn quadratic(x: &[f64]) -> f64 {
    x.iter().zip(CENTRE).map(|(a, c)| (a - c) * (a - c)).sum()
}

/// Runs 80 evaluations of the quadratic plus Gaussian noise of standard deviation `sd`;
/// returns the true values at the luckiest sample and at the surrogate's answer, and the
/// chosen smoothing.
fn run(seed: u64, sd: f64) -> (f64, f64, f64) {
    let mut study = Cors::new(space(), CorsOptions::with_seed(seed)).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(100 + seed);
    let noise = Normal::new(0.0, sd).unwrap();
    study
        .minimize(|x| quadratic(x) + noise.sample(&mut rng), 80)
        .unwrap();
    let sample = study.best().unwrap().clone();
    let answer = study.surrogate_answer().unwrap().unwrap();
    assert_eq!(study.evaluations()[answer.index].x, answer.x);
    (quadratic(&sample.x), quadratic(&answer.x), answer.smoothing)
}

/// With noise of 5 % of the range, the surrogate's answer lies closer to the true minimum
/// than the luckiest sample on most seeds and on average, and the smoothing is switched on.
#[test]
fn noisy_quadratic_surrogate_answer_beats_luckiest_sample() {
    let seeds = 0..8;
    let mut closer = 0;
    let (mut sum_sample, mut sum_answer) = (0.0, 0.0);
    for seed in seeds.clone() {
        let (sample, answer, smoothing) = run(seed, 0.06);
        assert!(smoothing > 0.0, "seed {seed}: no smoothing under noise");
        closer += usize::from(answer < sample);
        sum_sample += sample;
        sum_answer += answer;
    }
    let n = seeds.count();
    assert!(closer * 4 >= n * 3, "closer on only {closer} of {n} seeds");
    assert!(
        sum_answer < 0.5 * sum_sample,
        "mean true value {} at the answer, {} at the luckiest sample",
        sum_answer / n as f64,
        sum_sample / n as f64
    );
}

/// Without noise the surrogate interpolates (or nearly), and its answer is the best sample.
#[test]
fn clean_quadratic_answer_is_the_best_sample() {
    for seed in 0..3 {
        let mut study = Cors::new(space(), CorsOptions::with_seed(seed)).unwrap();
        study.minimize(quadratic, 40).unwrap();
        let answer = study.surrogate_answer().unwrap().unwrap();
        let best = study.best().unwrap();
        assert_eq!(answer.x, best.x, "seed {seed}");
        assert_eq!(answer.observed.to_bits(), best.value.unwrap().to_bits());
        assert!((answer.predicted - answer.observed).abs() < 1e-6);
    }
}

/// Too few distinct successes for a leave-one-out error: no answer rather than a guess.
#[test]
fn no_answer_before_d_plus_two_points() {
    let mut study = Cors::new(space(), CorsOptions::with_seed(1)).unwrap();
    study.minimize(quadratic, 4).unwrap();
    assert!(study.surrogate_answer().unwrap().is_none());
    study.minimize(quadratic, 1).unwrap();
    assert!(study.surrogate_answer().unwrap().is_some());
}
