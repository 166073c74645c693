//! Repeated tests of one article as one data set: the side-by-side run equals each test's
//! own run, the holdout set runs its own inputs, the held quantities share one scale, the
//! malformed sets are refused naming the test, and the scatter between synthetic repeats
//! of known noise recovers that noise.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use std::f64::consts::PI;

use impactcal_core::synthetic::{Measurement, measured};
use impactcal_core::{Enrichable, Histories, Model};
use impactcal_models::lumped::{LumpedModel, LumpedRepeats, LumpedSystem, REPEAT_SET, scatter};

const DT: f64 = 1e-6;
const G1000: f64 = 9806.65;

fn system() -> LumpedSystem {
    let k = 0.05 * (2.0 * PI * 3000.0_f64).powi(2);
    let text = format!(
        "[base]\nchannel = \"table\"\nunit = {G1000}\n[masses]\nboard = 0.05\n\
         [springs.mount]\nbetween = [\"base\", \"board\"]\nstiffness = {k}\ndamping_ratio = 0.03\n\
         [outputs]\n\"accel_1\" = \"board\"\n"
    );
    LumpedSystem::parse(&text, "board.toml").unwrap()
}

/// A half-sine base pulse of `peak` (record units) and `width` (s), with a board channel.
fn record(samples: usize, peak: f64, width: f64) -> Histories {
    let base: Vec<f64> = (0..samples)
        .map(|k| {
            let t = k as f64 * DT;
            if t <= width {
                peak * (PI * t / width).sin()
            } else {
                0.0
            }
        })
        .collect();
    Histories::from_channels(
        vec!["table".into(), "accel_1".into()],
        vec![base, vec![0.0; samples]],
        DT,
        0.0,
        "kg_n",
    )
    .unwrap()
}

#[test]
fn each_test_runs_its_own_input_side_by_side() {
    let a = record(3000, 20.0, 1e-4);
    let b = record(3000, 26.0, 0.8e-4);
    let c = record(3000, 23.0, 0.9e-4);
    let d = record(3000, 30.0, 0.7e-4);
    let reps =
        LumpedRepeats::new(&system(), &[("a", &a), ("b", &b)], &[("c", &c), ("d", &d)]).unwrap();
    assert_eq!(reps.tests(), [vec!["a", "b"], vec!["c", "d"]]);
    let p = reps.space().nominal();
    let h = reps.simulate(&p).unwrap();
    assert_eq!(h.labels(), ["r1/accel_1", "r2/accel_1"]);
    // The response is linear in the input: each test's own run, at the shared point.
    for (k, r) in [&a, &b].iter().enumerate() {
        let own = LumpedModel::new(system(), r).unwrap().simulate(&p).unwrap();
        assert_eq!(h.channel(k), own.channel(0));
    }
    let held = reps.at_condition(&[(REPEAT_SET.into(), 1.0)]).unwrap();
    let h = held.simulate(&p).unwrap();
    assert_eq!(h.labels(), ["r1/accel_1", "r2/accel_1"]);
    for (k, r) in [&c, &d].iter().enumerate() {
        let own = LumpedModel::new(system(), r).unwrap().simulate(&p).unwrap();
        assert_eq!(h.channel(k), own.channel(0));
    }
    // Back to the calibration set; another value is refused.
    let back = held.at_condition(&[(REPEAT_SET.into(), 0.0)]).unwrap();
    assert_eq!(
        back.simulate(&p).unwrap().channel(0),
        reps.simulate(&p).unwrap().channel(0)
    );
    let e = reps
        .at_condition(&[(REPEAT_SET.into(), 2.0)])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("0 runs the calibration tests, 1 the holdout tests"),
        "{e}"
    );
    // One test keeps its channel's own label.
    let one = LumpedRepeats::new(&system(), &[("a", &a)], &[("c", &c)]).unwrap();
    assert_eq!(one.simulate(&p).unwrap().labels(), ["accel_1"]);
    let one_held = one.at_condition(&[(REPEAT_SET.into(), 1.0)]).unwrap();
    let own = LumpedModel::new(system(), &c)
        .unwrap()
        .simulate(&p)
        .unwrap();
    assert_eq!(one_held.simulate(&p).unwrap().channel(0), own.channel(0));
    let none = LumpedRepeats::new(&system(), &[("a", &a)], &[]).unwrap();
    let e = none
        .at_condition(&[(REPEAT_SET.into(), 1.0)])
        .unwrap_err()
        .to_string();
    assert!(e.contains("none was given"), "{e}");
}

/// The held quantities are scaled by the largest peak over both sets: `d_s = a_pk m / k`
/// with `a_pk` the largest drive (test `d`, 30,000 g), and the rattles are probed at the
/// clearances of the nominal run under that test's input on every test.
#[test]
fn held_quantities_share_the_largest_drives_scale() {
    let a = record(2000, 20.0, 1e-4);
    let d = record(2000, 30.0, 0.7e-4);
    let reps = LumpedRepeats::new(&system(), &[("a", &a)], &[("d", &d)]).unwrap();
    let k = system().springs[0].stiffness;
    let reach = 30.0 * G1000 * 0.05 / k;
    let on_d = LumpedModel::new(system(), &d).unwrap();
    let travel = on_d.travel(&on_d.space().nominal()).unwrap()[0];
    for set in [0.0, 1.0] {
        let run = reps.at_condition(&[(REPEAT_SET.into(), set)]).unwrap();
        for m in run.models() {
            assert!(
                (m.reach()[0] / reach - 1.0).abs() <= 1e-12,
                "{:?}",
                m.reach()
            );
            let gap = m
                .candidates()
                .into_iter()
                .find(|c| c.name() == "rattle_mount_c1_gap")
                .unwrap();
            assert_eq!(gap.parameter.nominal, 0.5 * travel);
            assert!((gap.parameter.upper / (2.0 * reach) - 1.0).abs() <= 1e-12);
        }
    }
    let gap = reps
        .candidates()
        .into_iter()
        .find(|c| c.name() == "rattle_mount_c1_gap")
        .unwrap();
    // Freed on both sets: the holdout run takes the freed rattle too.
    let enriched = reps.enrich(std::slice::from_ref(&gap.parameter)).unwrap();
    let held = enriched.at_condition(&[(REPEAT_SET.into(), 1.0)]).unwrap();
    assert_eq!(held.space().dim(), 3);
    assert!(held.simulate(&held.space().nominal()).is_ok());
}

#[test]
fn malformed_sets_are_refused_naming_the_test() {
    let a = record(2000, 20.0, 1e-4);
    let b = record(2000, 25.0, 1e-4);
    let short = record(1500, 20.0, 1e-4);
    let e = LumpedRepeats::new(&system(), &[], &[])
        .unwrap_err()
        .to_string();
    assert!(e.contains("no calibration test"), "{e}");
    let e = LumpedRepeats::new(&system(), &[("a", &a), ("b", &b)], &[("c", &a)])
        .unwrap_err()
        .to_string();
    assert!(e.contains("1 holdout tests for 2 calibration tests"), "{e}");
    let e = LumpedRepeats::new(&system(), &[("a", &a), ("short", &short)], &[])
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("test `short`: 1500 samples"), "{e}");
    let other = Histories::from_channels(
        vec!["fixture".into()],
        vec![vec![1.0; 2000]],
        DT,
        0.0,
        "kg_n",
    )
    .unwrap();
    let e = LumpedRepeats::new(&system(), &[("a", &a), ("other", &other)], &[])
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("test `other`:") && e.contains("table"), "{e}");
}

/// Five repeats of one response, each with noise of known standard deviation `sigma`
/// (white, then AR(1) with phi = 0.6): the scatter's RMS is `sigma` within its sampling
/// error (4 x 5,000 degrees of freedom: 1 %; coloured, fewer), and the envelope holds every
/// repeat.
#[test]
fn scatter_of_synthetic_repeats_recovers_the_known_noise() {
    let n = 5000;
    let y: Vec<f64> = (0..n)
        .map(|k| {
            let t = k as f64 * DT;
            (2.0 * PI * 3000.0 * t).sin() * (-t / 2e-3).exp()
        })
        .collect();
    let truth =
        Histories::from_channels(vec!["accel_1".into()], vec![y.clone()], DT, 0.0, "g").unwrap();
    let rms = (y.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
    for (ar1, tol) in [(0.0, 0.04), (0.6, 0.08)] {
        let snr = 20.0;
        let sigma = rms * 10f64.powf(-snr / 20.0);
        let repeats: Vec<Histories> = (0..5)
            .map(|seed| {
                measured(
                    &truth,
                    &Measurement {
                        snr_db: Some(snr),
                        ar1,
                        seed,
                        ..Measurement::default()
                    },
                )
                .unwrap()
            })
            .collect();
        let named: Vec<(&str, &Histories)> = repeats.iter().map(|h| ("t", h)).collect();
        let s = scatter(&named, &["accel_1".into()]).unwrap();
        assert_eq!(s[0].repeats, 5);
        assert!(
            (s[0].rms / sigma - 1.0).abs() < tol,
            "ar1 {ar1}: {} vs {sigma}",
            s[0].rms
        );
        let size = (rms * rms + sigma * sigma).sqrt();
        assert!(
            (s[0].relative - sigma / size).abs() < tol * sigma / size,
            "{:?}",
            s[0].relative
        );
        for h in &repeats {
            for (t, v) in h.channel(0).iter().enumerate() {
                assert!(s[0].lower[t] <= *v && *v <= s[0].upper[t]);
            }
        }
    }
    // Identical repeats scatter by nothing.
    let s = scatter(&[("a", &truth), ("b", &truth)], &["accel_1".into()]).unwrap();
    assert_eq!(s[0].rms, 0.0);
    // Fewer than two tests, a missing channel: refused.
    let e = scatter(&[("a", &truth)], &["accel_1".into()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("at least two tests"), "{e}");
    let e = scatter(&[("a", &truth), ("b", &truth)], &["accel_9".into()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("accel_9"), "{e}");
}
