//! The driven lumped model as a `Model` and an `Enrichable`: the contract (freed at its held
//! value, a candidate changes nothing), and each held quantity against a closed form or an
//! invariant: the backbone of a Duffing oscillator, a stiffness change's frequency ratio,
//! the resonances of an added mode, a closed rattle as a parallel spring, an exact delay,
//! a clip at the rail.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use std::f64::consts::PI;

use impactcal_core::{Enrichable, Histories, Model, Parameter};
use impactcal_models::lumped::{LumpedModel, LumpedSystem};

const M: f64 = 0.05;
const F0: f64 = 3000.0;
const DT: f64 = 1e-6;
/// The base pulse: a half-sine of this width and peak (record units, 1,000 g).
const WIDTH: f64 = 1e-4;
const PEAK: f64 = 20.0;
const G1000: f64 = 9806.65;

fn k0() -> f64 {
    M * (2.0 * PI * F0).powi(2)
}

fn system(zeta: f64, extra: &str) -> LumpedSystem {
    let text = format!(
        "[base]\nchannel = \"table\"\nunit = {G1000}\n[masses]\nboard = {M}\n\
         [springs.mount]\nbetween = [\"base\", \"board\"]\nstiffness = {}\ndamping_ratio = {zeta}\n\
         {extra}\n[outputs]\n\"accel 1\" = \"board\"\n",
        k0()
    );
    LumpedSystem::parse(&text, "board.toml").unwrap()
}

fn record(samples: usize) -> Histories {
    pulse(samples, WIDTH)
}

fn pulse(samples: usize, width: f64) -> Histories {
    let base: Vec<f64> = (0..samples)
        .map(|k| {
            let t = k as f64 * DT;
            if t <= width {
                PEAK * (PI * t / width).sin()
            } else {
                0.0
            }
        })
        .collect();
    Histories::from_channels(vec!["table".into()], vec![base], DT, 0.0, "kg_n").unwrap()
}

fn model(zeta: f64, samples: usize) -> LumpedModel {
    LumpedModel::new(system(zeta, ""), &record(samples)).unwrap()
}

/// The model with the named candidates freed, and the point with their values.
fn freed(m: &LumpedModel, set: &[(&str, f64)]) -> (LumpedModel, Vec<f64>) {
    let cands = m.candidates();
    let added: Vec<Parameter> = set
        .iter()
        .map(|(n, _)| {
            cands
                .iter()
                .find(|c| c.name() == *n)
                .unwrap()
                .parameter
                .clone()
        })
        .collect();
    let e = m.enrich(&added).unwrap();
    let mut p = m.space().nominal();
    p.extend(set.iter().map(|s| s.1));
    (e, p)
}

/// The frequency (Hz) of a free vibration from its zero crossings after `from` seconds.
fn frequency(y: &[f64], from: f64) -> f64 {
    let first = (from / DT) as usize;
    let mut crossings = vec![];
    for k in first..y.len() - 1 {
        if (y[k] < 0.0) != (y[k + 1] < 0.0) {
            crossings.push((k as f64 + y[k] / (y[k] - y[k + 1])) * DT);
        }
    }
    let n = crossings.len();
    assert!(n > 20, "{n} crossings");
    (n - 1) as f64 / 2.0 / (crossings[n - 1] - crossings[0])
}

/// `|sum y_k w_k e^{-i w t_k}|` after `from` (`w_k` a Hann window, so that a strong mode
/// leaks little into another's band), maximised over `[lo, hi]` Hz (grid, then golden
/// section).
fn spectral_peak(y: &[f64], from: f64, lo: f64, hi: f64) -> f64 {
    let first = (from / DT) as usize;
    let mag = |f: f64| {
        let (mut re, mut im) = (0.0, 0.0);
        let len = (y.len() - first) as f64;
        for (k, v) in y.iter().enumerate().skip(first) {
            let ph = 2.0 * PI * f * k as f64 * DT;
            let hann = 0.5 - 0.5 * (2.0 * PI * (k - first) as f64 / len).cos();
            re += hann * v * ph.cos();
            im -= hann * v * ph.sin();
        }
        (re * re + im * im).sqrt()
    };
    let grid = 200;
    let step = (hi - lo) / grid as f64;
    let best = (0..=grid)
        .map(|i| lo + i as f64 * step)
        .fold((lo, 0.0), |b, f| {
            let m = mag(f);
            if m > b.1 { (f, m) } else { b }
        })
        .0;
    let (mut a, mut b) = (best - step, best + step);
    let r = 0.5 * (5.0_f64.sqrt() - 1.0);
    for _ in 0..60 {
        let (c, d) = (b - r * (b - a), a + r * (b - a));
        if mag(c) > mag(d) { b = d } else { a = c }
    }
    0.5 * (a + b)
}

#[test]
fn declared_parameters_and_candidates_follow_the_file() {
    let m = model(0.02, 5000);
    assert_eq!(m.space().names(), ["k_mount", "zeta_mount"]);
    let names: Vec<String> = m
        .candidates()
        .iter()
        .map(|c| c.name().to_string())
        .collect();
    assert_eq!(
        names,
        [
            "mode_board_ratio",
            "mode_board_frequency",
            "cubic_mount",
            "stiffness_change",
            "rattle_mount_c1_stiffness",
            "rattle_mount_c1_gap",
            "rattle_mount_c2_stiffness",
            "rattle_mount_c2_gap",
            "rattle_mount_c3_stiffness",
            "rattle_mount_c3_gap",
            "delay",
            "saturation_accel_1"
        ]
    );
    let h = m.simulate(&m.space().nominal()).unwrap();
    assert_eq!(h.labels(), ["accel 1"]);
    assert_eq!(h.unit(), "kg_n");
    assert_eq!(h.samples(), 5000);
    // A base channel the record does not hold is named.
    let mut s = system(0.0, "");
    s.base_channel = "tabel".into();
    let e = LumpedModel::new(s, &record(100)).unwrap_err();
    assert!(e.to_string().contains("tabel"), "{e}");
    // A base channel that never moves drives nothing.
    let still =
        Histories::from_channels(vec!["table".into()], vec![vec![0.0; 100]], DT, 0.0, "kg_n")
            .unwrap();
    let e = LumpedModel::new(system(0.0, ""), &still).unwrap_err();
    assert!(e.to_string().contains("zero throughout"), "{e}");
}

#[test]
fn every_candidate_freed_at_its_held_value_changes_nothing() {
    let m = model(0.02, 5000);
    let all: Vec<Parameter> = m.candidates().into_iter().map(|c| c.parameter).collect();
    let e = m.enrich(&all).unwrap();
    assert!(e.candidates().is_empty());
    let mut p = m.space().nominal();
    p.extend(all.iter().map(|c| c.nominal));
    let a = m.simulate(&m.space().nominal()).unwrap();
    let b = e.simulate(&p).unwrap();
    assert_eq!(a.data(), b.data());
    // A condition sets a held value; declared names and unknown names are refused, as are
    // values outside the admissible range and candidates added twice.
    let c = m.at_condition(&[("stiffness_change".into(), 0.1)]).unwrap();
    let (f, q) = freed(&m, &[("stiffness_change", 0.1)]);
    assert_eq!(
        c.simulate(&m.space().nominal()).unwrap().data(),
        f.simulate(&q).unwrap().data()
    );
    assert!(m.at_condition(&[("k_mount".into(), 1.0)]).is_err());
    assert!(m.at_condition(&[("stifness_change".into(), 0.1)]).is_err());
    assert!(m.at_condition(&[("stiffness_change".into(), 0.9)]).is_err());
    assert!(m.enrich(&[all[0].clone(), all[0].clone()]).is_err());
    let mut wide = all[3].clone();
    wide.upper = 2.0;
    assert!(m.enrich(&[wide]).is_err());
    assert_eq!(
        m.describe("k_mount").unwrap().0,
        "stiffness",
        "{:?}",
        m.describe("k_mount")
    );
}

/// Undamped, a change `s` of every stiffness moves the free vibration to `f0 sqrt(1 + s)`.
#[test]
fn a_stiffness_change_moves_the_frequency_by_its_square_root() {
    let m = model(0.0, 20_000);
    let f_lin = frequency(
        m.simulate(&m.space().nominal()).unwrap().channel(0),
        2.0 * WIDTH,
    );
    assert!((f_lin / F0 - 1.0).abs() < 1e-5, "{f_lin}");
    let (e, p) = freed(&m, &[("stiffness_change", -0.19)]);
    let f = frequency(e.simulate(&p).unwrap().channel(0), 2.0 * WIDTH);
    assert!((f / F0 - 0.9).abs() < 1e-5, "{f}");
}

/// Duffing's backbone: `x'' + w0^2 (x + beta x^3) = 0` vibrates at
/// `w0 (1 + 3/8 beta A^2 + O(beta^2 A^4))` at amplitude `A`. The model's `cubic_mount` is
/// `beta d_s^2` with `d_s = a_pk M / k`.
#[test]
fn cubic_stiffness_shifts_the_frequency_along_the_duffing_backbone() {
    let m = model(0.0, 20_000);
    let d_s = PEAK * G1000 * M / k0();
    let w0 = 2.0 * PI * F0;
    for gamma in [0.02, -0.03] {
        let (e, p) = freed(&m, &[("cubic_mount", gamma)]);
        let y = e.simulate(&p).unwrap();
        let y = y.channel(0);
        let f = frequency(y, 2.0 * WIDTH);
        // The amplitude from the peak acceleration after the pulse: a = w0^2 (A + beta A^3).
        let beta = gamma / (d_s * d_s);
        let a_max = y[(2.0 * WIDTH / DT) as usize..]
            .iter()
            .fold(0.0_f64, |x, v| x.max(v.abs()))
            * G1000;
        let mut amp = a_max / (w0 * w0);
        for _ in 0..50 {
            amp = a_max / (w0 * w0) / (1.0 + beta * amp * amp);
        }
        let predicted = 3.0 / 8.0 * beta * amp * amp;
        let measured = f / F0 - 1.0;
        assert!(predicted.abs() > 5e-3, "{predicted}");
        assert!(
            (measured - predicted).abs() < 0.03 * predicted.abs(),
            "gamma {gamma}: measured {measured}, predicted {predicted}"
        );
    }
}

/// A further mode of mass ratio `mu` and fixed-base frequency `f2` on the board: the pair
/// resonates where `m mu m w^4 - ((k1 + k2) mu m + k2 m) w^2 + k1 k2 = 0`, `k2 = mu m w2^2`.
#[test]
fn the_added_mode_resonates_where_the_two_mass_system_does() {
    // A 10 us pulse excites both modes; the high one (2 % damped) is read over the 2 ms
    // after it, the low one (undamped but for the coupling) over 50 ms.
    let m = LumpedModel::new(system(0.0, ""), &pulse(50_000, 1e-5)).unwrap();
    let (mu, f2) = (0.3, 20_000.0);
    let (e, p) = freed(
        &m,
        &[("mode_board_ratio", mu), ("mode_board_frequency", f2)],
    );
    let y = e.simulate(&p).unwrap();
    let (k1, m2) = (k0(), mu * M);
    let k2 = m2 * (2.0 * PI * f2).powi(2);
    let (a, b, c) = (M * m2, (k1 + k2) * m2 + k2 * M, k1 * k2);
    let disc = (b * b - 4.0 * a * c).sqrt();
    let high = ((b + disc) / (2.0 * a)).sqrt() / (2.0 * PI);
    let low = ((b - disc) / (2.0 * a)).sqrt() / (2.0 * PI);
    let f_high = spectral_peak(&y.channel(0)[..2020], 2e-5, 0.9 * high, 1.1 * high);
    let f_low = spectral_peak(y.channel(0), 2e-5, 0.9 * low, 1.1 * low);
    assert!((f_high / high - 1.0).abs() < 2e-3, "{f_high} vs {high}");
    assert!((f_low / low - 1.0).abs() < 2e-3, "{f_low} vs {low}");
    // Without the ratio, the frequency alone changes nothing.
    let (e, p) = freed(&m, &[("mode_board_frequency", f2)]);
    assert_eq!(
        e.simulate(&p).unwrap().data(),
        m.simulate(&m.space().nominal()).unwrap().data()
    );
}

/// A rattle at zero clearance is a spring in parallel: stiffness `3 k` doubles the
/// frequency; at a clearance of the whole travel it never touches, and the travel is the
/// undamped oscillator's peak stretch `max |a| / w^2`; the three rattles are probed at a
/// half, a quarter and an eighth of it, each of which closes.
#[test]
fn a_rattle_acts_past_its_gap_only() {
    let m = model(0.0, 20_000);
    let (e, p) = freed(
        &m,
        &[
            ("rattle_mount_c1_stiffness", 3.0 * k0()),
            ("rattle_mount_c1_gap", 0.0),
        ],
    );
    let f = frequency(e.simulate(&p).unwrap().channel(0), 2.0 * WIDTH);
    assert!((f / (2.0 * F0) - 1.0).abs() < 1e-3, "{f}");
    let linear = m.simulate(&m.space().nominal()).unwrap();
    let z_max = linear
        .channel(0)
        .iter()
        .fold(0.0_f64, |x, v| x.max(v.abs()))
        * G1000
        / (2.0 * PI * F0).powi(2);
    let travel = m.travel(&m.space().nominal()).unwrap()[0];
    assert!((travel / z_max - 1.0).abs() < 1e-9, "{travel} {z_max}");
    let largest = |h: &Histories| {
        h.data()
            .iter()
            .zip(linear.data())
            .fold(0.0_f64, |d, (x, y)| d.max((x - y).abs()))
    };
    let (e, p) = freed(
        &m,
        &[
            ("rattle_mount_c1_stiffness", 3.0 * k0()),
            ("rattle_mount_c1_gap", travel),
        ],
    );
    assert!(largest(&e.simulate(&p).unwrap()) <= 1e-9 * PEAK);
    let cands = m.candidates();
    for (c, fraction) in [("c1", 0.5), ("c2", 0.25), ("c3", 0.125)] {
        let gap = cands
            .iter()
            .find(|x| x.name() == format!("rattle_mount_{c}_gap"))
            .unwrap();
        assert!((gap.parameter.nominal / (fraction * travel) - 1.0).abs() < 1e-12);
        let (e, p) = freed(&m, &[(&format!("rattle_mount_{c}_stiffness"), 3.0 * k0())]);
        assert!(largest(&e.simulate(&p).unwrap()) > 1e-2 * PEAK, "{c}");
    }
}

/// The quasi-static stretch `d_s` solves `K z = M 1 a_pk`: a board on its own mount
/// carries its own mass, a spring in a chain the masses beyond it (closed form).
#[test]
fn the_stretch_scale_carries_the_masses_beyond_each_spring() {
    let text = format!(
        "[base]\nchannel = \"table\"\nunit = {G1000}\n\
         [masses]\na = 0.2\nb = 0.05\nc = 0.03\n\
         [springs.s1]\nbetween = [\"base\", \"a\"]\nstiffness = 4.0e7\n\
         [springs.s2]\nbetween = [\"a\", \"b\"]\nstiffness = 1.0e7\n\
         [springs.s3]\nbetween = [\"base\", \"c\"]\nstiffness = 3.0e7\n\
         [outputs]\n\"accel 1\" = \"b\"\n"
    );
    let sys = LumpedSystem::parse(&text, "chain.toml").unwrap();
    let m = LumpedModel::new(sys, &record(100)).unwrap();
    let a = PEAK * G1000;
    let want = [a * 0.25 / 4.0e7, a * 0.05 / 1.0e7, a * 0.03 / 3.0e7];
    for (got, want) in m.reach().iter().zip(want) {
        assert!((got / want - 1.0).abs() < 1e-12, "{got} {want}");
    }
}

/// A delay of whole samples shifts the outputs exactly; half a sample gives the mean of
/// neighbours.
#[test]
fn a_delay_shifts_the_outputs() {
    let m = model(0.05, 5000);
    let y0 = m.simulate(&m.space().nominal()).unwrap();
    let y0 = y0.channel(0);
    let (e, p) = freed(&m, &[("delay", 7.0 * DT)]);
    let y = e.simulate(&p).unwrap();
    let y = y.channel(0);
    for k in 0..5000 {
        let want = if k >= 7 { y0[k - 7] } else { y0[0] };
        assert!((y[k] - want).abs() <= 1e-9 * PEAK, "{k}");
    }
    let (e, p) = freed(&m, &[("delay", -2.5 * DT)]);
    let y = e.simulate(&p).unwrap();
    let y = y.channel(0);
    for k in 100..4000 {
        let want = 0.5 * (y0[k + 2] + y0[k + 3]);
        assert!((y[k] - want).abs() <= 1e-9 * PEAK, "{k}");
    }
}

/// Saturation clips at the rail `1 / value` and leaves the rest untouched.
#[test]
fn saturation_clips_at_its_rail() {
    let m = model(0.05, 5000);
    let y0 = m.simulate(&m.space().nominal()).unwrap();
    let y0 = y0.channel(0);
    let peak = y0.iter().fold(0.0_f64, |x, v| x.max(v.abs()));
    let rail = 0.6 * peak;
    let (e, p) = freed(&m, &[("saturation_accel_1", 1.0 / rail)]);
    let y = e.simulate(&p).unwrap();
    let mut clipped = 0;
    for (a, b) in y.channel(0).iter().zip(y0) {
        if b.abs() > rail {
            assert_eq!(a.abs(), rail);
            assert_eq!(a.signum(), b.signum());
            clipped += 1;
        } else {
            assert_eq!(a, b);
        }
    }
    assert!(clipped > 10, "{clipped}");
}
