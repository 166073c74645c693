//! The Kolsky bar model's held quantities, each against a closed form, and the
//! `Enrichable` contract (held values change nothing, ranges are enforced).

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{C, X, bar, test_from, trapezoid};
use impactcal_core::enrich::rebuild;
use impactcal_core::{Enrichable, Model, Parameter};
use impactcal_models::kolsky::{DispersionCurve, KolskyModel, KolskyTest};

/// A test driven by a trapezoid of amplitude `amp` and rise `rise` (plateau to 60 us), the
/// transmitted gauge at `xt` from the specimen.
fn driven(amp: f64, rise: f64, xt: f64) -> KolskyTest {
    let inc = move |t: f64| trapezoid(t, amp, 80e-6, rise, 60e-6 - rise);
    let mut tb = bar(9.5e-3, 200.0, "tra");
    tb.gauge_distance = xt;
    test_from(
        0.4e-6,
        480e-6,
        (bar(9.5e-3, 200.0, "inc"), tb),
        inc,
        move |t| -0.5 * inc(t),
        move |t| 0.5 * inc(t),
    )
}

/// The model with `names` freed at their held values' places: returns the model and the
/// point `A, B, n, modulus, wave speed, delays` followed by `values`.
fn freed(test: &KolskyTest, base: [f64; 4], set: &[(&str, f64)]) -> (KolskyModel, Vec<f64>) {
    let m = KolskyModel::new(test).unwrap();
    let names: Vec<String> = m
        .space()
        .names()
        .iter()
        .map(|s| s.to_string())
        .chain(set.iter().map(|(n, _)| n.to_string()))
        .collect();
    let m = rebuild(&m, &names, &[]).unwrap();
    let mut p = vec![base[0], base[1], base[2], base[3], C, 0.0, 0.0];
    p.extend(set.iter().map(|(_, v)| *v));
    (m, p)
}

const ELASTIC: [f64; 4] = [1000.0, 0.0, 0.5, 30.0];

fn peak(x: &[f64]) -> f64 {
    x.iter().fold(0.0_f64, |m, v| m.max(v.abs()))
}

#[test]
fn freed_at_their_held_values_the_candidates_change_nothing() {
    let test = driven(2e-3, 10e-6, X);
    let m = KolskyModel::new(&test).unwrap();
    let names: Vec<String> = m
        .candidates()
        .iter()
        .map(|c| c.name().to_string())
        .collect();
    assert_eq!(
        names,
        [
            "dispersion",
            "rate_sensitivity",
            "friction",
            "inertia",
            "gain_incident",
            "gain_transmitted",
            "gap"
        ]
    );
    let base = [100.0, 300.0, 0.5, 50.0];
    let (all, p) = freed(
        &test,
        base,
        &m.candidates()
            .iter()
            .map(|c| (c.name(), c.parameter.nominal))
            .collect::<Vec<_>>(),
    );
    let before = m.simulate(&p[..7]).unwrap();
    let after = all.simulate(&p).unwrap();
    assert_eq!(before.data(), after.data());
    assert!(all.candidates().is_empty());
    // Ranges: bounds outside the admissible range, an unknown or repeated name, a value out
    // of range, a declared parameter as a condition.
    let wide = Parameter::new("friction", 0.0, 0.5, 0.0).unwrap();
    assert!(m.enrich(&[wide]).is_err());
    let bogus = Parameter::new("viscosity", 0.0, 1.0, 0.0).unwrap();
    assert!(m.enrich(&[bogus]).is_err());
    let f = m.candidates()[2].parameter.clone();
    assert!(m.enrich(&[f.clone(), f]).is_err());
    assert!(m.at_condition(&[("gap".into(), -0.1)]).is_err());
    assert!(m.at_condition(&[("A".into(), 100.0)]).is_err());
    // A held value set as a condition is the value a freed parameter would take.
    let held = m.at_condition(&[("gain_transmitted".into(), 0.5)]).unwrap();
    let (g, pg) = freed(&test, base, &[("gain_transmitted", 0.5)]);
    assert_eq!(
        held.simulate(&p[..7]).unwrap().data(),
        g.simulate(&pg).unwrap().data()
    );
    assert_eq!(m.describe("wave_speed").unwrap().0, "nuisance");
}

#[test]
fn dispersion_moves_each_wave_over_its_own_gauge_distance_forwards() {
    // Different gauge distances tell the directions apart: an elastic (linear,
    // time-invariant) specimen commutes with dispersion, so the dispersed run's
    // transmitted signal is the plain run's moved over x_i + x_t, its reflected over 2 x_i.
    let (xi, xt) = (X, 0.3);
    // A rise of 12 us: the pulse's content above 200 kHz, which the bars slow by more than
    // the window's margins hold, is small (the model simulates the window only and cuts
    // what dispersion carries past it).
    let test = driven(1e-4, 12e-6, xt);
    let (m, p) = freed(&test, ELASTIC, &[("dispersion", 1.0)]);
    let mut p0 = p.clone();
    p0[7] = 0.0;
    let on = m.simulate(&p).unwrap();
    let off = m.simulate(&p0).unwrap();
    let b = &test.incident;
    let curve = DispersionCurve::solve(b.poisson, 20.0, 0.02).unwrap();
    let a = b.section.radius();
    let dt = on.dt();
    for (ch, z) in [(0, 2.0 * xi), (1, xi + xt)] {
        let want = curve.disperse(off.channel(ch), dt, z, a, C, 1.0);
        let got = on.channel(ch);
        let scale = peak(off.channel(ch));
        let worst = got
            .iter()
            .zip(&want)
            .fold(0.0_f64, |m, (g, w)| m.max((g - w).abs()));
        // And not the backwards composition over |x_i - x_t|.
        let wrong = curve.disperse(off.channel(ch), dt, (xi - xt).abs(), a, C, 1.0);
        let off_by = got
            .iter()
            .zip(&wrong)
            .fold(0.0_f64, |m, (g, w)| m.max((g - w).abs()));
        eprintln!(
            "channel {ch}: worst {:.2e}, backwards {:.2e} of {scale:.2e}",
            worst, off_by
        );
        assert!(worst < 2e-2 * scale, "{ch}: {worst} of {scale}");
        assert!(off_by > 10.0 * worst, "{ch}");
    }
}

#[test]
fn gauge_gains_scale_their_bars_signals() {
    // Linear specimen: a transmitted gain multiplies the transmitted signal; an incident
    // gain divides the input and multiplies the reflected output, so the reflected signal
    // stays and the transmitted one is divided.
    let test = driven(1e-4, 5e-6, X);
    let (m, p) = freed(
        &test,
        ELASTIC,
        &[("gain_incident", 1.0), ("gain_transmitted", 1.0)],
    );
    let base = m.simulate(&p).unwrap();
    let run = |gi: f64, gt: f64| {
        let mut q = p.clone();
        q[7] = gi;
        q[8] = gt;
        m.simulate(&q).unwrap()
    };
    let t = run(1.0, 0.4);
    let i = run(2.0, 1.0);
    let s = peak(base.channel(1));
    let mut worst_i = 0.0_f64;
    for k in 0..base.samples() {
        assert!((t.value(1, k) - 0.4 * base.value(1, k)).abs() < 1e-12 * s);
        assert!((t.value(0, k) - base.value(0, k)).abs() < 1e-12 * s);
        worst_i = worst_i.max((i.value(0, k) - base.value(0, k)).abs());
        worst_i = worst_i.max((i.value(1, k) - 0.5 * base.value(1, k)).abs());
    }
    eprintln!("incident gain: worst {worst_i:.3e} of {s:.3e}");
    // Linear but for the specimen's change of section (a strain of 1e-4).
    assert!(worst_i < 1e-3 * s, "{worst_i} {s}");
}

#[test]
fn a_gap_delays_the_load_until_the_faces_have_closed_it() {
    // The faces close at 2 c eps_I with no force: with a rise R to amplitude a, the gap g
    // closes at the face time t with 2 c a (t - R / 2) = g (after the rise).
    let (amp, rise) = (1e-3, 2e-6);
    let test = driven(amp, rise, X);
    let gap_mm = 0.05;
    let (m, p) = freed(&test, ELASTIC, &[("gap", gap_mm)]);
    let run = m.faces(&p).unwrap();
    let onset = run.waves[0].iter().position(|e| *e > 0.0).unwrap();
    let t_in = run.time[onset - 1];
    let closes = t_in + rise / 2.0 + gap_mm * 1e-3 / (2.0 * C * amp);
    let first = run.waves[2].iter().position(|e| *e > 1e-6 * amp).unwrap();
    let dt = run.time[1] - run.time[0];
    assert!(
        (run.time[first] - closes).abs() <= 1.5 * dt,
        "{} {closes}",
        run.time[first]
    );
    // Before it closes the whole incident wave reflects (eps_R = -eps_I).
    for k in onset..first {
        assert!((run.waves[1][k] + run.waves[0][k]).abs() < 1e-15);
    }
}

#[test]
fn friction_raises_the_mean_pressure_by_the_schmid_boas_factor() {
    // A stiff, perfectly plastic specimen flowing at A: the bars see
    // A (1 + mu d / (3 L)) on the current section, d and L from constant volume.
    let test = driven(2e-3, 5e-6, X);
    let mu = 0.2;
    let (m, p) = freed(&test, [200.0, 0.0, 0.5, 300.0], &[("friction", mu)]);
    let run = m.faces(&p).unwrap();
    let sp = &test.specimen;
    let (d0, l0) = (2.0 * sp.section.radius(), sp.length);
    let kt = common::E * test.transmitted.area();
    let mut checked = 0;
    for k in 0..run.time.len() {
        // Flowing on the incident plateau.
        let plateau = (run.waves[0][k] - 2e-3).abs() < 1e-12;
        if plateau && run.plastic[k] > 1e-3 && k > 0 && run.plastic[k] > run.plastic[k - 1] {
            let l = l0 * (-run.strain[k]).exp();
            let area = sp.section.area() * l0 / l;
            let d = d0 * (l0 / l).sqrt();
            let want = 200e6 * area * (1.0 + mu * d / (3.0 * l));
            let got = run.waves[2][k] * kt;
            assert!((got / want - 1.0).abs() < 1e-9, "{k}: {got} {want}");
            checked += 1;
        }
    }
    assert!(checked > 50, "{checked}");
}

#[test]
fn rate_sensitivity_follows_johnson_cook_at_the_rate_the_bars_impose() {
    // Perfectly plastic with C: while it flows, sigma = A (1 + C ln(deps_p/dt)), the rate
    // being what the bars impose at that stress, (2 c eps_I - sigma A_s (2 / Z)) / L.
    let test = driven(2e-3, 5e-6, X);
    let c_jc = 0.05;
    let (m, p) = freed(
        &test,
        [200.0, 0.0, 0.5, 300.0],
        &[("rate_sensitivity", c_jc)],
    );
    let run = m.faces(&p).unwrap();
    let sp = &test.specimen;
    let z = test.incident.impedance();
    let mut checked = 0;
    for k in 1..run.time.len() {
        let dt = run.time[k] - run.time[k - 1];
        let rate_p = (run.plastic[k] - run.plastic[k - 1]) / dt;
        // Steady flow: on the incident plateau, past the first microseconds of flow.
        let plateau =
            (run.waves[0][k] - 2e-3).abs() < 1e-12 && (run.waves[0][k - 1] - 2e-3).abs() < 1e-12;
        if plateau && run.plastic[k - 1] > 1e-2 && rate_p > 100.0 {
            let l = sp.length * (-run.strain[k]).exp();
            let area = sp.section.area() * sp.length / l;
            let rate = (2.0 * C * run.waves[0][k] - run.stress[k] * area * 2.0 / z) / l;
            let want = 200e6 * (1.0 + c_jc * rate.ln());
            assert!(
                (run.stress[k] / want - 1.0).abs() < 2e-3,
                "{k}: {} {want}",
                run.stress[k]
            );
            checked += 1;
        }
    }
    assert!(checked > 50, "{checked}");
}

#[test]
fn inertia_gives_the_davies_hunter_term() {
    // Four elements with the specimen's mass: with a linear velocity field the mean
    // stress exceeds the back face's by rho L (a_1 / 6 + a_2 / 3), which is Davies and
    // Hunter's (1963) axial term rho L^2 / 6 d2eps/dt2 when the back face is still.
    let test = driven(1.5e-3, 30e-6, X);
    let (m, p) = freed(&test, [100.0, 600.0, 0.5, 100.0], &[("inertia", 1.0)]);
    let run = m.faces(&p).unwrap();
    let (mq, pq) = freed(&test, [100.0, 600.0, 0.5, 100.0], &[("inertia", 0.0)]);
    let quasi = mq.faces(&pq).unwrap();
    let sp = &test.specimen;
    let kt = common::E * test.transmitted.area();
    let dt = run.time[1] - run.time[0];
    let rho = sp.density;
    let ci = C;
    let v1: Vec<f64> = (0..run.time.len())
        .map(|k| ci * (run.waves[0][k] - run.waves[1][k]))
        .collect();
    let v2: Vec<f64> = run.waves[2].iter().map(|e| ci * e).collect();
    // Over the loading ramp (the incident wave rising, its first 2 us aside): the mean
    // of the measured difference against the mean of the Davies-Hunter term.
    let (mut measured, mut term, mut count) = (0.0, 0.0, 0);
    let rise_start = run.waves[0].iter().position(|e| *e > 0.0).unwrap() + 5;
    for k in rise_start..run.time.len() - 1 {
        if run.waves[0][k + 1] <= run.waves[0][k] {
            break;
        }
        let a1 = (v1[k + 1] - v1[k - 1]) / (2.0 * dt);
        let a2 = (v2[k + 1] - v2[k - 1]) / (2.0 * dt);
        let l = sp.length * (-run.strain[k]).exp();
        let area = sp.section.area() * sp.length / l;
        let back = run.waves[2][k] * kt / area;
        // Linear velocity field: mean stress = back + rho L (a1 / 6 + a2 / 3); with the
        // back face still, rho L^2 / 6 d2eps/dt2.
        measured += run.stress[k] - back;
        term += rho * l * (a1 / 6.0 + a2 / 3.0);
        count += 1;
    }
    eprintln!(
        "Davies-Hunter over {count} samples: measured {:.3e} Pa, term {:.3e} Pa",
        measured / count as f64,
        term / count as f64
    );
    assert!(count > 50 && term / (count as f64) > 1e6);
    assert!((measured / term - 1.0).abs() < 0.1, "{measured} {term}");
    // Without the mass the two formulations agree.
    let (m0, p0) = freed(&test, [100.0, 600.0, 0.5, 100.0], &[("inertia", 1e-2)]);
    let light = m0.faces(&p0).unwrap();
    let s = peak(&quasi.waves[2]);
    let diff = light.waves[2]
        .iter()
        .zip(&quasi.waves[2])
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(diff < 1e-2 * s, "{diff} {s}");
}
