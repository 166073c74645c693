//! The classic analysis against closed forms: a rigid, perfectly plastic specimen between
//! identical elastic bars, whose waves, stress, strain rate and strain are known exactly;
//! and the Los Alamos copper record's equilibrium under its two transmitted gains.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use impactcal_core::testdata::LanlBarRecord;
use impactcal_models::ModelsError;
use impactcal_models::kolsky::{ClassicAnalysis, GainRow, KolskyTest, LanlOptions, from_lanl};

mod common;

use common::{C, E, LS, X, bar, test_from, trapezoid};

const A_PEAK: f64 = 2e-3;
const SIGMA0: f64 = 300e6;

/// The incident pulse at the gauge: a trapezoid from 80 us, rise 10, plateau 40, fall 10.
fn incident(t: f64) -> f64 {
    trapezoid(t, A_PEAK, 80e-6, 10e-6, 40e-6)
}

/// The transmitted strain at which the specimen flows.
fn flow_strain() -> f64 {
    SIGMA0 * common::specimen().section.area() / (E * bar(9.5e-3, 1.0, "x").area())
}

/// The test of a rigid, perfectly plastic specimen sampled at `dt` over 480 us: the
/// transmitted face strain is `min(eps_I, s)` and the reflected `min(eps_I, s) - eps_I`;
/// the transmitted bar is read with gain `read_gain` (the volts are made with 200).
fn synthetic(dt: f64, read_gain: f64) -> KolskyTest {
    let s = flow_strain();
    let bars = (bar(9.5e-3, 200.0, "inc"), bar(9.5e-3, 200.0, "tra"));
    let mut t = test_from(
        dt,
        480e-6,
        bars,
        incident,
        |t| incident(t).min(s) - incident(t),
        |t| incident(t).min(s),
    );
    t.transmitted.gain = read_gain;
    t
}

#[test]
fn a_rigid_plastic_specimen_gives_its_flow_stress_rate_and_strain() {
    let t = synthetic(0.4e-6, 200.0);
    let a = ClassicAnalysis::of(&t).unwrap();
    assert!(a.resampling.is_none());
    let s = flow_strain();
    let area_ratio = t.transmitted.area() / t.specimen.section.area();
    for k in 0..a.time.len() {
        let ei = incident(a.time[k] - X / C);
        let sigma = E * area_ratio * ei.min(s);
        let rate = 2.0 * C * (ei - s).max(0.0) / LS;
        assert!((a.waves[0][k] - ei).abs() < 1e-12, "{k}");
        assert!((a.stress_one[k] - sigma).abs() < 1e-6 * SIGMA0, "{k}");
        assert!((a.stress_three[k] - sigma).abs() < 1e-6 * SIGMA0, "{k}");
        assert!((a.rate_one[k] - rate).abs() < 1e-6 * 1e4, "{k}");
        assert!((a.rate_three[k] - rate).abs() < 1e-6 * 1e4, "{k}");
    }
    // Plateau stress = sigma0; final strain 2 c / L (a - s)(P + R (1 - s / a)).
    let peak = a.stress_three.iter().fold(0.0_f64, |m, v| m.max(*v));
    assert!((peak / SIGMA0 - 1.0).abs() < 1e-6, "{peak}");
    let want = 2.0 * C / LS * (A_PEAK - s) * (40e-6 + 10e-6 * (1.0 - s / A_PEAK));
    let got = *a.strain_three.last().unwrap();
    // Trapezoidal rule on a piecewise-linear rate: exact but for the two kinks at s.
    assert!((got / want - 1.0).abs() < 2e-3, "{got} {want}");
    assert!((a.strain_one.last().unwrap() / want - 1.0).abs() < 2e-3);
    assert!((a.equilibrium - 1.0).abs() < 1e-6, "{}", a.equilibrium);
    let (et, st) = a.true_curve();
    let k = a.strain_three.len() - 1;
    assert!((et[k] + (1.0 - got).ln()).abs() < 1e-15 && st[k] <= a.stress_three[k]);
}

#[test]
fn a_wrong_transmitted_gain_shows_in_equilibrium() {
    // Read with 2.5 times the gain the volts were made with: the back force is 2.5 times
    // too small (the half bridge's non-linearity aside).
    let a = ClassicAnalysis::of(&synthetic(0.4e-6, 500.0)).unwrap();
    assert!(
        (a.equilibrium / 2.5 - 1.0).abs() < 2e-3,
        "{}",
        a.equilibrium
    );
}

#[test]
fn a_fine_record_is_resampled_to_what_the_bars_carry_and_says_so() {
    // 100 MHz: 48,000 samples; the bars carry D / (4 c) = 0.475 us: decimated by 47.
    let fine = synthetic(0.01e-6, 200.0);
    let a = ClassicAnalysis::of(&fine).unwrap();
    let r = a.resampling.expect("resampled");
    assert_eq!(r.factor, 47);
    assert!((r.to_dt - 0.47e-6).abs() < 1e-15);
    assert!(r.cutoff > 0.8e6 && r.cutoff < 0.9e6);
    // The plateau stress and the final strain survive the low-pass.
    let peak = a.stress_three.iter().fold(0.0_f64, |m, v| m.max(*v));
    assert!((peak / SIGMA0 - 1.0).abs() < 5e-3, "{peak}");
    let coarse = ClassicAnalysis::of(&synthetic(0.4e-6, 200.0)).unwrap();
    let (f, c) = (
        a.strain_three.last().unwrap(),
        coarse.strain_three.last().unwrap(),
    );
    assert!((f / c - 1.0).abs() < 1e-2, "{f} {c}");
}

#[test]
fn a_pulse_longer_than_the_round_trip_is_refused() {
    let mut t = synthetic(0.4e-6, 200.0);
    t.incident.gauge_distance = 0.1; // 40 us round trip, 60 us pulse
    match ClassicAnalysis::of(&t) {
        Err(ModelsError::Record { message, .. }) => assert!(message.contains("overlaps")),
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_copper_record_is_in_equilibrium_with_the_test_gains_only() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/kolsky/20061201_1148HE_CuOFE_273K.raw"
    );
    let record = LanlBarRecord::read(path).unwrap();
    let test = from_lanl(&record, &LanlOptions::default()).unwrap().test;
    let a = ClassicAnalysis::of(&test).unwrap();
    let cal = LanlOptions {
        transmitted_gain: GainRow::Calibrated,
        ..LanlOptions::default()
    };
    let b = ClassicAnalysis::of(&from_lanl(&record, &cal).unwrap().test).unwrap();
    let peak = |v: &[f64]| v.iter().fold(0.0_f64, |m, x| m.max(*x));
    eprintln!(
        "copper: equilibrium {:.3} (gain 200) {:.3} (gain 500); resampled {:?}; peak stress {:.1} MPa; final strain {:.3}; peak rate {:.0}/s",
        a.equilibrium,
        b.equilibrium,
        a.resampling,
        peak(&a.stress_three) / 1e6,
        a.strain_three.last().unwrap(),
        peak(&a.rate_three)
    );
    assert!((a.equilibrium - 1.0).abs() < 0.1, "{}", a.equilibrium);
    assert!((b.equilibrium / a.equilibrium / 2.5 - 1.0).abs() < 0.01);
}
