#![allow(clippy::unwrap_used, clippy::float_cmp)]

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::*;

const DT: f64 = 1e-6;
const N: usize = 3000;
const ONSET: usize = 600;

/// A shock record: `offset` plus AR(1) noise (`phi`, `sigma`) throughout, a decaying
/// 5 kHz oscillation of amplitude `amp` from sample 600 (time constant 400 us).
fn shock(seed: u64, phi: f64, sigma: f64, amp: f64, offset: f64) -> Vec<f64> {
    shock_decaying(seed, phi, sigma, amp, offset, 4e-4)
}

fn shock_decaying(seed: u64, phi: f64, sigma: f64, amp: f64, offset: f64, tau: f64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let e = ArModel::ar1(phi, sigma).generate(N, &mut rng);
    (0..N)
        .map(|k| {
            let s = if k >= ONSET {
                let t = (k - ONSET) as f64 * DT;
                amp * (-t / tau).exp() * (2.0 * std::f64::consts::PI * 5e3 * t).sin()
            } else {
                0.0
            };
            offset + s + e[k]
        })
        .collect()
}

fn record(label: &str, x: Vec<f64>) -> Histories {
    Histories::from_channels(vec![label.into()], vec![x], DT, 0.0, "").unwrap()
}

fn quantised(x: &[f64], q: f64) -> Vec<f64> {
    x.iter().map(|v| (v / q).round() * q).collect()
}

#[test]
fn offset_noise_and_colour_of_the_quiet_part() {
    let white = check(
        &record("a", shock(1, 0.0, 0.02, 20.0, 0.3)),
        &QualityOptions::default(),
    )
    .unwrap();
    let c = &white.channels[0];
    assert_eq!(c.noise_source, NoiseSource::PreTrigger);
    // The quiet part is found from the record: it ends a little before the onset.
    assert!(
        (540..ONSET).contains(&c.quiet_samples),
        "{}",
        c.quiet_samples
    );
    assert!((c.offset.unwrap() - 0.3).abs() < 0.004);
    assert!((c.noise_std - 0.02).abs() < 0.002, "{}", c.noise_std);
    assert!(c.lag1.abs() < 0.1);
    assert!(c.white);
    let coloured = check(
        &record("a", shock(2, 0.8, 0.02, 20.0, -0.1)),
        &QualityOptions {
            pre_trigger: Some(500.0 * DT),
            ..Default::default()
        },
    )
    .unwrap();
    let c = &coloured.channels[0];
    assert_eq!(c.quiet_samples, 500);
    assert!((c.lag1 - 0.8).abs() < 0.08, "{}", c.lag1);
    assert!(!c.white);
    assert_eq!(c.noise_model.as_ref().unwrap().order(), 1);
    assert!(c.spikes.is_empty() && c.clipped.is_empty());
    // A pre-trigger time leaving too few samples is refused.
    let e = check(
        &record("a", shock(2, 0.8, 0.02, 20.0, -0.1)),
        &QualityOptions {
            pre_trigger: Some(10.0 * DT),
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("pre-trigger"), "{e}");
    let e = check(
        &record("a", shock(2, 0.8, 0.02, 20.0, -0.1)),
        &QualityOptions {
            pre_trigger: Some(f64::NAN),
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("finite time"), "{e}");
}

#[test]
fn planted_clipping_spikes_and_mains_are_found_where_planted() {
    let mut x = shock(3, 0.3, 0.02, 20.0, 0.0);
    // A rail at 12: the first positive half-wave is cut.
    let rail = 12.0;
    let cut: Vec<usize> = (0..N).filter(|&k| x[k] >= rail).collect();
    for &k in &cut {
        x[k] = rail;
    }
    x[2000] += 3.0;
    x[250] -= 1.0;
    // A three-sample glitch.
    for v in &mut x[2500..2503] {
        *v += 2.0;
    }
    let q = check(&record("a", x), &QualityOptions::default()).unwrap();
    let c = &q.channels[0];
    assert_eq!(c.clipped_runs.len(), 1, "{:?}", c.clipped_runs);
    assert_eq!(
        (c.clipped_runs[0].first, c.clipped_runs[0].last),
        (cut[0], *cut.last().unwrap())
    );
    assert_eq!(c.clipped[0][2], rail);
    assert_eq!(c.spike_spans, vec![[250, 250], [2000, 2000], [2500, 2502]]);
    assert!((c.spikes[1] - 2000.0 * DT).abs() < 1e-12);
    // Masks on the record's own base cover the planted samples and one step either side.
    let m = q.mask_on("a", 0.0, DT, N);
    assert!(m[2000] && m[1999] && m[2001] && !m[1997]);
    assert!(cut.iter().all(|&k| m[k]));
    let r = q
        .repaired(&record("a", shock(3, 0.3, 0.02, 20.0, 0.0)))
        .unwrap();
    assert!((r.channel(0)[2000] - 0.5 * (r.channel(0)[1999] + r.channel(0)[2001])).abs() < 1e-12);

    // 50 Hz hum of 0.05 on noise of 0.02, over a 0.2 s pre-trigger at 10 kHz.
    let dt = 1e-4;
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let e = ArModel::white(0.02).generate(4000, &mut rng);
    let y: Vec<f64> = (0..4000)
        .map(|k| e[k] + 0.05 * (2.0 * std::f64::consts::PI * 50.0 * k as f64 * dt).sin())
        .collect();
    let h = Histories::from_channels(vec!["b".into()], vec![y], dt, 0.0, "").unwrap();
    let q = check(
        &h,
        &QualityOptions {
            pre_trigger: Some(0.2),
            ..Default::default()
        },
    )
    .unwrap();
    let l = &q.channels[0].lines;
    assert_eq!(l.len(), 1, "{l:?}");
    assert!(l[0].mains && (l[0].frequency - 50.0).abs() <= 5.0);
}

#[test]
fn no_false_clipping_or_spikes_on_clean_records() {
    // Many seeds, white and coloured noise, raw and quantised to a step below the noise
    // and above it (where smooth peaks repeat samples).
    let mut checked = 0;
    for seed in 0..60 {
        for (phi, q) in [(0.0, 0.0), (0.7, 0.0), (0.0, 0.01), (0.5, 0.05), (0.0, 0.5)] {
            let mut x = shock(100 + seed, phi, 0.02, 10.0 + seed as f64 * 0.37, 0.0);
            if q > 0.0 {
                x = quantised(&x, q);
            }
            let c = &check(&record("a", x), &QualityOptions::default())
                .unwrap()
                .channels[0];
            assert!(
                c.clipped.is_empty(),
                "seed {seed} phi {phi} q {q}: {:?}",
                c.clipped_runs
            );
            assert!(
                c.spikes.is_empty(),
                "seed {seed} phi {phi} q {q}: {:?}",
                c.spikes
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 300);
}

#[test]
fn drift_of_an_acceleration_is_found_and_a_clean_one_passes() {
    // An event that is over (time constant 150 us) before the record ends.
    let clean = shock_decaying(4, 0.5, 0.02, 20.0, 0.1, 1.5e-4);
    let mut shifted = clean.clone();
    // The zero moves by 0.05 (2.5 noise std) after the event.
    for v in shifted.iter_mut().skip(1500) {
        *v += 0.05;
    }
    let opts = QualityOptions::default();
    let d = check(&record("accel_1", clean), &opts).unwrap().channels[0]
        .drift
        .clone()
        .unwrap();
    assert!(!d.significant, "{d:?}");
    let d = check(&record("accel_1", shifted), &opts).unwrap().channels[0]
        .drift
        .clone()
        .unwrap();
    assert!(d.significant, "{d:?}");
    // Velocity change over the tail: 0.05 over its samples.
    let m = (N as f64) - d.tail_start / DT;
    assert!(
        (d.velocity_change - 0.05 * m * DT).abs() < 0.2 * 0.05 * m * DT,
        "{d:?}"
    );
    // Not an acceleration by label: no drift.
    let x = shock(4, 0.5, 0.02, 20.0, 0.1);
    assert!(
        check(&record("force", x), &opts).unwrap().channels[0]
            .drift
            .is_none()
    );
}

#[test]
fn gaps_and_repeated_stamps_are_reported_and_the_rows_dropped() {
    let text = "time,a\n0,1\n0.001,2\n0.001,7\n0.002,3\n0.0015,9\n0.003,4\n0.006,5\n0.007,6\n";
    let (h, faults) = parse_record(text, "t.csv").unwrap();
    assert_eq!(faults.len(), 3, "{faults:?}");
    assert!(matches!(faults[0], TimeFault::Repeated { sample: 2, .. }));
    assert!(matches!(faults[1], TimeFault::Backwards { sample: 4, .. }));
    assert!(matches!(
        faults[2],
        TimeFault::Gap {
            sample: 6,
            missing: 2,
            ..
        }
    ));
    // Resampled at the median step over 0 .. 0.007 s.
    assert_eq!(h.samples(), 8);
    assert!(
        (h.channel(0)[4] - 4.0 - 1.0 / 3.0).abs() < 1e-9,
        "{:?}",
        h.channel(0)
    );
    let e = parse_record("time,a\n0,1\n0,2\n", "t.csv").unwrap_err();
    assert!(e.to_string().contains("t.csv: 1 row(s)"), "{e}");
    // A stray stamp far beyond the rest: refused before anything is allocated for it.
    let mut far = String::from("time,a\n");
    for k in 0..100 {
        far.push_str(&format!("{},{}\n", k as f64 * 1e-6, k % 3));
    }
    far.push_str("1000,1\n");
    let e = parse_record(&far, "far.csv").unwrap_err().to_string();
    assert!(
        e.contains("far.csv") && e.contains("0.000099 s to 1000 s"),
        "{e}"
    );
    let q = check(&h, &QualityOptions::default()).unwrap();
    assert_eq!(q.channels[0].noise_source, NoiseSource::Differences);
}

#[test]
fn the_drop_tower_excerpt_shows_its_clipping_and_noise() {
    // Test 4 of the AFRL drop tower, board accelerometer 4 (docs/validation.md):
    // clipped at -71.56 kg_n for two samples.
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/droptower/test4_excerpt.csv"
    );
    let (h, faults) = read_record(path).unwrap();
    assert!(faults.is_empty());
    let q = check(
        &h,
        &QualityOptions {
            pre_trigger: Some(3.5e-4),
            ..Default::default()
        },
    )
    .unwrap();
    let c = q.channel("accel_4").unwrap();
    assert_eq!(c.clipped.len(), 1, "{:?}", c.clipped);
    assert!((c.clipped[0][2] + 71.5605456679512).abs() < 1e-9);
    assert!(c.lag1 > 0.5 && !c.white, "{}", c.lag1);
    let top = q.channel("accel_top").unwrap();
    assert!(top.clipped.is_empty());
}

/// Each bad option is refused by `ParamGuard::check_ref` with `CoreError::InvalidOption`
/// naming it, and `check` refuses it the same way before reading the record.
#[test]
fn a_bad_option_is_refused_naming_its_key() {
    use crate::error::ParamGuard;
    let cases = [
        (
            QualityOptions {
                pre_trigger: Some(f64::NAN),
                ..QualityOptions::default()
            },
            "pre-trigger",
        ),
        (
            QualityOptions {
                accelerations: Accelerations::Labels(vec!["a1".into(), " ".into()]),
                ..QualityOptions::default()
            },
            "accelerations",
        ),
    ];
    let h = Histories::from_channels(
        vec!["a1".into()],
        vec![(0..200).map(|k| (k as f64 * 0.1).sin()).collect()],
        1e-4,
        0.0,
        "g",
    )
    .unwrap();
    for (o, key) in cases {
        match o.check_ref() {
            Err(CoreError::InvalidOption { name, .. }) => assert_eq!(name, key),
            other => panic!("{key}: {other:?}"),
        }
        match check(&h, &o) {
            Err(CoreError::InvalidOption { name, .. }) => assert_eq!(name, key),
            other => panic!("{key}: {other:?}"),
        }
    }
    assert!(QualityOptions::default().check_ref().is_ok());
}
