//! The Kolsky bar model against closed forms: a linear elastic specimen (the exact solution
//! of its equation, and at long times the impedance-mismatch split of a bar junction), and
//! the energy balance of a hardening specimen.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{C, E, LS, X, bar, test_from, trapezoid};
use impactcal_core::Model;
use impactcal_models::kolsky::{KolskyModel, KolskyTest};

/// A test whose incident gauge sees a trapezoid of amplitude `amp`, the rest silent except
/// for a small reflected and transmitted wave (the model reads only the incident wave and
/// the windows), with transmitted bar diameter `dt_bar`.
fn driven(amp: f64, rise: f64, dt_bar: f64) -> KolskyTest {
    let inc = move |t: f64| trapezoid(t, amp, 80e-6, rise, 60e-6 - rise);
    test_from(
        0.4e-6,
        480e-6,
        (bar(9.5e-3, 200.0, "inc"), bar(dt_bar, 200.0, "tra")),
        inc,
        move |t| -0.5 * inc(t),
        move |t| 0.5 * inc(t),
    )
}

/// The point: A, B, n, modulus (GPa), wave speed, delays.
fn point(a: f64, b: f64, n: f64, es: f64) -> Vec<f64> {
    vec![a, b, n, es, C, 0.0, 0.0]
}

#[test]
fn a_linear_elastic_specimen_follows_its_exact_solution_and_the_junction_split() {
    // The transmitted bar thinner: impedances differ by (8 / 9.5)^2.
    let test = driven(1e-4, 4e-6, 8e-3);
    let model = KolskyModel::new(&test).unwrap();
    let es = 20.0; // GPa: tau about 1.3 us
    let run = model.faces(&point(1000.0, 0.0, 0.5, es)).unwrap();
    assert!(run.plastic.iter().all(|p| *p == 0.0));
    let (bi, bt) = (&test.incident, &test.transmitted);
    let (zi, zt) = (bi.impedance(), bt.impedance());
    let a_s = test.specimen.section.area();
    let k = a_s * (1.0 / zi + 1.0 / zt);
    let tau = LS / (es * 1e9 * k);
    // dsigma/dt = (sigma_target - sigma) / tau with sigma_target = 2 c eps_I / K, linear
    // between samples: exact step by step.
    let dt = run.time[1] - run.time[0];
    let mut sigma = 0.0;
    let mut peak = 0.0_f64;
    let mut worst = 0.0_f64;
    for j in 1..run.time.len() {
        let (u0, u1) = (run.waves[0][j - 1], run.waves[0][j]);
        let a = 2.0 * C * u0 / k;
        let b = 2.0 * C * (u1 - u0) / (k * dt);
        sigma = a + b * (dt - tau) + (sigma - (a - b * tau)) * (-dt / tau).exp();
        peak = peak.max(sigma.abs());
        worst = worst.max((run.stress[j] - sigma).abs());
    }
    assert!(worst < 2e-3 * peak, "{worst} of {peak}");
    // On the plateau (many tau after the rise): the junction's split of a rigid, massless
    // interface, eps_R / eps_I = (Z_t - Z_i) / (Z_t + Z_i), and force transmitted
    // 2 Z_t / (Z_i + Z_t) of the incident force.
    let j = run
        .time
        .iter()
        .position(|t| *t > 80e-6 + X / C + 30e-6)
        .unwrap();
    let ei = run.waves[0][j];
    assert!((ei - 1e-4).abs() < 1e-12);
    let r = run.waves[1][j] / ei;
    assert!((r - (zt - zi) / (zt + zi)).abs() < 2e-3, "{r}");
    let ft = run.waves[2][j] * E * bt.area();
    let fi = ei * E * bi.area();
    assert!((ft / fi - 2.0 * zt / (zi + zt)).abs() < 2e-3, "{}", ft / fi);
}

#[test]
fn a_hardening_specimen_balances_energy() {
    let test = driven(2e-3, 10e-6, 9.5e-3);
    let model = KolskyModel::new(&test).unwrap();
    let run = model.faces(&point(100.0, 300.0, 0.5, 50.0)).unwrap();
    let b = &test.incident;
    let flux = E * b.area() * C; // power = E A c eps^2
    let dt = run.time[1] - run.time[0];
    let integral = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>() * dt;
    let e_in = flux * integral(&run.waves[0]);
    let e_out = flux * (integral(&run.waves[1]) + integral(&run.waves[2]));
    // Work done on the specimen: plastic (int sigma dp) and elastic stored at the end.
    let volume = test.specimen.section.area() * test.specimen.length;
    let mut plastic_work = 0.0;
    for j in 1..run.time.len() {
        plastic_work +=
            0.5 * (run.stress[j] + run.stress[j - 1]) * (run.plastic[j] - run.plastic[j - 1]);
    }
    let last = *run.stress.last().unwrap();
    let stored = last * last / (2.0 * 50e9);
    let absorbed = (plastic_work + stored) * volume;
    let final_plastic = *run.plastic.last().unwrap();
    eprintln!(
        "energy: in {e_in:.4} J, out {e_out:.4} J, specimen {absorbed:.4} J; plastic strain {final_plastic:.4}"
    );
    assert!(final_plastic > 0.05, "{final_plastic}");
    assert!(((e_in - e_out) / absorbed - 1.0).abs() < 1e-2);
    // Momentum: the quasi-static specimen passes the incident bar's force on whole.
    let fi: f64 = run.waves[0]
        .iter()
        .zip(&run.waves[1])
        .map(|(i, r)| i + r)
        .sum();
    let ft: f64 = run.waves[2].iter().sum();
    assert!((fi / ft - 1.0).abs() < 1e-9);
    // The run's histories hold the waves moved to the gauges.
    let h = model.simulate(&point(100.0, 300.0, 0.5, 50.0)).unwrap();
    let m = model.measured().unwrap();
    assert_eq!(h.labels(), m.labels());
    assert_eq!(h.samples(), m.samples());
}

#[test]
fn a_point_of_the_wrong_length_or_a_negative_modulus_is_refused() {
    let model = KolskyModel::new(&driven(1e-3, 5e-6, 9.5e-3)).unwrap();
    assert!(model.simulate(&[1.0, 2.0]).is_err());
    assert!(model.faces(&point(100.0, 300.0, 0.5, -1.0)).is_err());
}
