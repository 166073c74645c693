//! The lumped integrator against closed forms (a base-excited single-degree oscillator
//! under a step and a half-sine) and the energy of a rattling pair of masses.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use std::f64::consts::PI;

use impactcal_models::lumped::{Dynamics, GapLink, GapSides, Node, SpringLink};

fn oscillator(m: f64, k: f64, zeta: f64) -> Dynamics {
    Dynamics {
        masses: vec![m],
        springs: vec![SpringLink {
            ends: [Node::Base, Node::Mass(0)],
            k,
            beta: 0.0,
            c: 2.0 * zeta * (k * m).sqrt(),
        }],
        dashpots: vec![],
        gaps: vec![],
    }
}

/// A step of the base acceleration is a straight line between samples, so the integrator
/// must reproduce the damped oscillator's closed form to round-off:
/// `z = -A/w^2 [1 - e^{-zeta w t} (cos w_d t + zeta/sqrt(1-zeta^2) sin w_d t)]`,
/// `z' = -A/w_d e^{-zeta w t} sin w_d t`, absolute acceleration `-(w^2 z + 2 zeta w z')`.
#[test]
fn a_step_of_the_base_is_exact_to_round_off() {
    let (m, f, zeta, amp) = (0.05, 3000.0, 0.03, 5.0e4);
    let w = 2.0 * PI * f;
    let sys = oscillator(m, m * w * w, zeta);
    let dt = 1e-6;
    let input = vec![amp; 5000];
    let run = sys.run(&input, dt, 1.0).unwrap();
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let mut worst: f64 = 0.0;
    for (k, a) in run.accel[0].iter().enumerate() {
        let t = k as f64 * dt;
        let e = (-zeta * w * t).exp();
        let z = -amp / (w * w)
            * (1.0 - e * ((wd * t).cos() + zeta / (1.0 - zeta * zeta).sqrt() * (wd * t).sin()));
        let v = -amp / wd * e * (wd * t).sin();
        let exact = -(w * w * z + 2.0 * zeta * w * v);
        worst = worst.max((a - exact).abs());
        assert!(
            (run.z[0][k] - z).abs() <= 1e-10 * amp / (w * w),
            "{k}: {}",
            (run.z[0][k] - z).abs() / (amp / (w * w))
        );
    }
    // The peak is about 2 A (1.9 A with 3 % damping): error to round-off of it.
    eprintln!("step: worst error {:.2e} of the amplitude", worst / amp);
    assert!(worst < 1e-10 * amp, "{worst}");
}

/// The undamped oscillator under a half-sine base pulse `A sin(pi t / T)` for `t < T`:
/// `z = -A/(w^2 - W^2) (sin W t - W/w sin w t)` during it, free vibration after. The
/// input's straight-line interpolation leaves an error of order `(W dt)^2`; the test
/// bounds it and checks that it falls fourfold when `dt` halves.
#[test]
fn a_half_sine_of_the_base_matches_its_closed_form_to_second_order() {
    let (m, f, amp, width) = (0.02, 4000.0, 2.0e5, 2.0e-4);
    let w = 2.0 * PI * f;
    let big_w = PI / width;
    let sys = oscillator(m, m * w * w, 0.0);
    let exact = |t: f64| -> f64 {
        let c = -amp / (w * w - big_w * big_w);
        let z_of = |t: f64| c * ((big_w * t).sin() - big_w / w * (w * t).sin());
        let v_of = |t: f64| c * big_w * ((big_w * t).cos() - (w * t).cos());
        let z = if t <= width {
            z_of(t)
        } else {
            let (z0, v0, s) = (z_of(width), v_of(width), t - width);
            z0 * (w * s).cos() + v0 / w * (w * s).sin()
        };
        -w * w * z
    };
    let error = |dt: f64| -> (f64, f64) {
        let n = (2e-3 / dt).round() as usize + 1;
        let input: Vec<f64> = (0..n)
            .map(|k| {
                let t = k as f64 * dt;
                if t <= width {
                    amp * (big_w * t).sin()
                } else {
                    0.0
                }
            })
            .collect();
        let run = sys.run(&input, dt, 1.0).unwrap();
        let mut worst: f64 = 0.0;
        let mut peak: f64 = 0.0;
        for (k, a) in run.accel[0].iter().enumerate() {
            let e = exact(k as f64 * dt);
            worst = worst.max((a - e).abs());
            peak = peak.max(e.abs());
        }
        (worst, peak)
    };
    // 2e-4 / 1e-6 and 2e-4 / 5e-7 are whole numbers of samples: the pulse ends on one.
    let (e1, peak) = error(1e-6);
    let (e2, _) = error(5e-7);
    // (W dt)^2 / 8 = 3.1e-5 of the input's amplitude at 1 MHz.
    assert!(e1 < 3e-5 * peak, "{e1} of {peak}");
    let ratio = e1 / e2;
    eprintln!(
        "half-sine: error {:.2e} of the peak at 1 MHz, ratio {ratio:.3}",
        e1 / peak
    );
    assert!((3.5..4.5).contains(&ratio), "{ratio}");
}

/// Two masses on springs (base - m1 - m2) and a two-sided gap contact between them: a base
/// pulse sets them rattling; afterwards, with no damping and no input, the energy must stay
/// in a narrow band and not drift, over some hundred impacts.
#[test]
fn a_rattling_pair_keeps_its_energy() {
    let (m1, m2) = (0.2, 0.05);
    let (k1, k2) = (
        m1 * (2.0 * PI * 800.0_f64).powi(2),
        m2 * (2.0 * PI * 1500.0_f64).powi(2),
    );
    let sys = Dynamics {
        masses: vec![m1, m2],
        springs: vec![
            SpringLink {
                ends: [Node::Base, Node::Mass(0)],
                k: k1,
                beta: 0.0,
                c: 0.0,
            },
            SpringLink {
                ends: [Node::Mass(0), Node::Mass(1)],
                k: k2,
                beta: 0.0,
                c: 0.0,
            },
        ],
        dashpots: vec![],
        gaps: vec![GapLink {
            ends: [Node::Mass(0), Node::Mass(1)],
            gap: 2e-5,
            k: 2000.0 * k2,
            sides: GapSides::Both,
        }],
    };
    let dt = 1e-6;
    let pulse = 1.0e-4;
    let n = 100_000;
    let input: Vec<f64> = (0..n)
        .map(|k| {
            let t = k as f64 * dt;
            if t <= pulse {
                3.0e4 * (PI * t / pulse).sin()
            } else {
                0.0
            }
        })
        .collect();
    let run = sys.run(&input, dt, 1.0).unwrap();
    assert!(run.substeps > 1, "{}", run.substeps);
    let first = (pulse / dt) as usize + 1;
    let energy: Vec<f64> = (first..n)
        .map(|k| sys.energy(&[run.z[0][k], run.z[1][k]], &[run.v[0][k], run.v[1][k]]))
        .collect();
    // Impacts: samples where the pair has crossed the gap, entered from outside.
    let d: Vec<f64> = (first..n).map(|k| run.z[1][k] - run.z[0][k]).collect();
    let impacts = d
        .windows(2)
        .filter(|p| p[0].abs() <= 2e-5 && p[1].abs() > 2e-5)
        .count();
    assert!(impacts > 100, "{impacts}");
    let mean = energy.iter().sum::<f64>() / energy.len() as f64;
    let (lo, hi) = energy
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), e| {
            (a.min(*e), b.max(*e))
        });
    eprintln!("rattle: {impacts} impacts, {} sub-steps", run.substeps);
    assert!((hi - lo) / mean < 1e-2, "band {}", (hi - lo) / mean);
    // No growth: the energy's mean over the last tenth is that over the first tenth.
    let tenth = energy.len() / 10;
    let avg = |s: &[f64]| s.iter().sum::<f64>() / s.len() as f64;
    let drift = avg(&energy[energy.len() - tenth..]) / avg(&energy[..tenth]) - 1.0;
    eprintln!("rattle: band {:.2e}, drift {drift:.2e}", (hi - lo) / mean);
    assert!(drift.abs() < 1e-3, "drift {drift}");
}

/// Bad input: a non-finite sample is named, a non-positive step refused.
#[test]
fn bad_input_is_refused() {
    let sys = oscillator(1.0, 1.0e6, 0.0);
    let e = sys.run(&[0.0, f64::NAN, 0.0], 1e-6, 1.0).unwrap_err();
    assert!(e.to_string().contains("sample 1"), "{e}");
    assert!(sys.run(&[0.0; 3], 0.0, 1.0).is_err());
    assert!(sys.run(&[0.0; 3], 1e-6, f64::NAN).is_err());
    assert!(sys.run(&[], 1e-6, 1.0).unwrap().accel[0].is_empty());
}
