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
        let s = scatter(&named, &["accel_1".into()], &[0.0; 5]).unwrap();
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
    let s = scatter(
        &[("a", &truth), ("b", &truth)],
        &["accel_1".into()],
        &[0.0; 2],
    )
    .unwrap();
    assert_eq!(s[0].rms, 0.0);
    // Fewer than two tests, a missing channel: refused.
    let e = scatter(&[("a", &truth)], &["accel_1".into()], &[0.0])
        .unwrap_err()
        .to_string();
    assert!(e.contains("at least two tests"), "{e}");
    let e = scatter(
        &[("a", &truth), ("b", &truth)],
        &["accel_9".into()],
        &[0.0; 2],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("accel_9"), "{e}");
}

/// Repeats that trigger at known offsets (whole and fractional samples, either way) with
/// known noise: the alignment on the input recovers each offset to a fifth of a sample (the
/// noise alone makes the estimate scatter by about `sqrt 2 sigma / sqrt(sum x'^2)`, 0.06 of
/// a sample for this pulse and noise, so the bound is about three of those), and the aligned
/// scatter is the noise's, where the unaligned one is many times it.
#[test]
fn alignment_recovers_known_shifts_and_the_aligned_scatter_the_noise() {
    use impactcal_models::lumped::{alignment, input_shift};
    let n = 3000;
    // A smooth pulse of 200 us from 0.8 ms, and the board's ringing answer to it.
    let input = |t: f64| {
        let u = (t - 0.8e-3) / 0.2e-3;
        if (0.0..=1.0).contains(&u) {
            30.0 * (PI * u).sin().powi(2)
        } else {
            0.0
        }
    };
    let board = |t: f64| {
        let u = t - 0.9e-3;
        60.0 * (-(u / 0.4e-3).powi(2)).exp() * (2.0 * PI * 3000.0 * u).sin()
    };
    let shifts = [0.0, 19.37, -7.6, 3.25, 0.5];
    let snr = 30.0;
    let repeats: Vec<Histories> = shifts
        .iter()
        .enumerate()
        .map(|(seed, s)| {
            let t = |k: usize| (k as f64 - s) * DT;
            let clean = Histories::from_channels(
                vec!["table".into(), "accel_1".into()],
                vec![
                    (0..n).map(|k| input(t(k))).collect(),
                    (0..n).map(|k| board(t(k))).collect(),
                ],
                DT,
                0.0,
                "kg_n",
            )
            .unwrap();
            measured(
                &clean,
                &Measurement {
                    snr_db: Some(snr),
                    seed: seed as u64,
                    ..Measurement::default()
                },
            )
            .unwrap()
        })
        .collect();
    let named: Vec<(&str, &Histories)> = repeats.iter().map(|h| ("t", h)).collect();
    let found = alignment(&named, "table").unwrap();
    for (f, s) in found.iter().zip(shifts) {
        assert!((f / DT - s).abs() < 0.2, "{found:?} vs {shifts:?}");
    }
    let rms_y = ((0..n).map(|k| board(k as f64 * DT).powi(2)).sum::<f64>() / n as f64).sqrt();
    let sigma = rms_y * 10f64.powf(-snr / 20.0);
    let aligned = scatter(&named, &["accel_1".into()], &found).unwrap();
    assert!(
        (aligned[0].rms / sigma - 1.0).abs() < 0.1,
        "{} {sigma}",
        aligned[0].rms
    );
    let raw = scatter(&named, &["accel_1".into()], &[0.0; 5]).unwrap();
    assert!(raw[0].rms > 5.0 * sigma, "{} {sigma}", raw[0].rms);
    // The fractional delay moves the smooth pulse to its exact delayed values, a whole
    // sample to the sample, and keeps white noise's variance at half a sample.
    use impactcal_models::lumped::delay_exact;
    let x: Vec<f64> = (0..n).map(|k| input(k as f64 * DT)).collect();
    for s in [0.5, 3.0, -7.25] {
        let moved = delay_exact(&x, s);
        let worst = moved.iter().enumerate().fold(0.0_f64, |w, (k, v)| {
            w.max((v - input((k as f64 - s) * DT)).abs())
        });
        assert!(worst < 1e-4 * 30.0, "{s}: {worst}");
    }
    // The first 700 samples of a repeat's input are its white noise alone.
    let quiet = &repeats[0].channel(0)[..700];
    let var = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64;
    let moved = delay_exact(quiet, 0.5);
    let ratio = var(&moved[50..650]) / var(&quiet[50..650]);
    assert!((ratio - 1.0).abs() < 0.1, "{ratio}");
    // The refusals: inputs of different lengths, no positive peak, too few tests.
    let e = input_shift(&[1.0, 2.0, 1.0], &[1.0, 2.0], 1).unwrap_err();
    assert!(e.to_string().contains("3 and 2 samples"), "{e}");
    let e = input_shift(&[0.0; 10], &[1.0; 10], 2).unwrap_err();
    assert!(e.to_string().contains("no positive peak"), "{e}");
    let e = alignment(&named[..1], "table").unwrap_err();
    assert!(e.to_string().contains("at least two tests"), "{e}");
    let e = alignment(&named, "nope").unwrap_err();
    assert!(e.to_string().contains("nope"), "{e}");
    let e = scatter(&named, &["accel_1".into()], &[0.0; 2]).unwrap_err();
    assert!(e.to_string().contains("as many finite shifts"), "{e}");
}
