//! The airframe as an `Enrichable` model, against its contract: the candidates are the
//! catalogue minus the declared space, at their held values, in catalogue order; freeing
//! them at their held values changes no run; another condition changes the response as
//! physics says; names that are not held quantities are refused with typed errors.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use impactcal_core::enrich::Enrichable;
use impactcal_core::{CoreError, Model, Parameter};
use impactcal_shell::airframe::{
    Airframe, AirframeModel, AirframeOptions, AirframeValues, GRAVITY, MeshDensity, Preset,
    catalogue,
};

fn coarse(end_time: f64) -> Airframe {
    let mut o = AirframeOptions::new(MeshDensity::Coarse);
    o.end_time = end_time;
    Airframe::new(o).unwrap()
}

fn table2(end_time: f64) -> AirframeModel {
    AirframeModel::preset(coarse(end_time), Preset::Table2).unwrap()
}

fn invalid_option(e: &CoreError) -> bool {
    matches!(e, CoreError::InvalidOption { .. })
}

#[test]
fn candidates_are_the_catalogue_minus_the_space_at_held_values() {
    let mut base = AirframeValues::nominal();
    base.set("ground.friction", 0.5).unwrap();
    // Held outside the catalogue range: the admissible range widens to include it.
    base.set("mass.tail", 0.2).unwrap();
    let model = table2(0.001).with_base(base);
    let c = model.candidates();
    let declared = Preset::Table2.names();
    let expected: Vec<String> = catalogue()
        .into_iter()
        .map(|a| a.name)
        .filter(|n| !declared.contains(&n.as_str()))
        .collect();
    let names: Vec<&str> = c.iter().map(|c| c.name()).collect();
    assert_eq!(names, expected);
    assert_eq!(c.len(), 8 + 5 + 14 * 4 - 6);
    let get = |n: &str| c.iter().find(|c| c.name() == n).unwrap();
    let friction = get("ground.friction");
    assert_eq!(friction.group, "friction");
    assert_eq!(
        (
            friction.parameter.lower,
            friction.parameter.nominal,
            friction.parameter.upper
        ),
        (0.0, 0.5, 0.8)
    );
    let damping = get("damping");
    assert_eq!(damping.group, "damping");
    assert_eq!(
        (damping.parameter.lower, damping.parameter.nominal),
        (0.0, 0.0)
    );
    let tail = get("mass.tail");
    assert_eq!(tail.group, "mass");
    assert_eq!((tail.parameter.nominal, tail.parameter.upper), (0.2, 0.2));
    assert_eq!(get("rate.c").group, "strain-rate");
    assert_eq!(get("attitude.pitch").group, "condition");
    assert_eq!(get("impact.vertical").group, "condition");
    assert_eq!(get("roof.t").group, "thickness");
    assert_eq!(get("roof.sigy").group, "material");
    assert_eq!(get("roof.t").parameter.unit, "in");
    for k in &c {
        let p = &k.parameter;
        assert!(p.lower <= p.nominal && p.nominal <= p.upper, "{}", k.name());
        assert!(!k.description.is_empty());
        // Nothing physical is admissible below zero except attitude angles.
        if k.group != "condition" {
            assert!(p.lower >= 0.0, "{}", k.name());
        }
    }
}

#[test]
fn freed_at_held_values_the_runs_are_identical_and_the_freed_values_act() {
    let model = table2(0.0015);
    let c = model.candidates();
    let added: Vec<Parameter> = ["ground.friction", "damping", "mass.occupants", "roof.E"]
        .iter()
        .map(|n| c.iter().find(|c| c.name() == *n).unwrap().parameter.clone())
        .collect();
    let enriched = model.enrich(&added).unwrap();
    let mut names: Vec<&str> = Preset::Table2.names().to_vec();
    names.extend(["ground.friction", "damping", "mass.occupants", "roof.E"]);
    assert_eq!(enriched.space().names(), names);
    // The freed quantities are no longer candidates.
    assert_eq!(enriched.candidates().len(), c.len() - 4);

    let x = model.space().nominal();
    let mut y = x.clone();
    y.extend(added.iter().map(|p| p.nominal));
    let before = model.simulate(&x).unwrap();
    let after = enriched.simulate(&y).unwrap();
    assert_eq!(before.labels(), after.labels());
    assert!(
        before
            .data()
            .iter()
            .zip(after.data())
            .all(|(a, b)| a.to_bits() == b.to_bits()),
        "freed at the held values, the histories must be bit-identical"
    );
    // Mass-proportional damping D slows the free fall before contact: with D the
    // vertical speed relaxes as v' = -g - D v, so 20 1/s changes it measurably.
    let mut z = y.clone();
    let d = enriched.space().index_of("damping").unwrap();
    z[d] = 20.0;
    let damped = enriched.simulate(&z).unwrap();
    let ch = before
        .labels()
        .iter()
        .position(|l| l.ends_with(".z"))
        .unwrap();
    let (k, t) = (5, 5.0 * before.dt());
    let v0 = -312.0;
    let free = v0 - GRAVITY * t;
    assert!((before.channel(ch)[k] - free).abs() < 1e-6 * free.abs());
    // v(t) = (v0 + g/D) e^{-D t} - g/D for the damped free fall.
    let g_d = GRAVITY / 20.0;
    let damped_exact = (v0 + g_d) * (-20.0 * t).exp() - g_d;
    let got = damped.channel(ch)[k];
    assert!(
        (got - damped_exact).abs() < 2e-3 * (free - damped_exact).abs(),
        "damped free fall {got} vs {damped_exact} (undamped {free})"
    );
}

#[test]
fn another_impact_velocity_changes_the_free_fall_as_physics_says() {
    let model = table2(0.0006);
    let holdout = model
        .at_condition(&[
            ("impact.vertical".into(), 280.0),
            ("impact.horizontal".into(), 300.0),
        ])
        .unwrap();
    assert_eq!(holdout.space(), model.space());
    let h = holdout.simulate(&model.space().nominal()).unwrap();
    // Before contact (0.25 in gap at 280 in/s: 0.9 ms) every node falls freely: vz = -280 -
    // g t, vx = 300, vy = 0.
    let time = h.time();
    for (i, label) in h.labels().iter().enumerate() {
        for (&v, &t) in h.channel(i).iter().zip(&time) {
            let exact = match label.rsplit('.').next().unwrap() {
                "x" => 300.0,
                "y" => 0.0,
                _ => -280.0 - GRAVITY * t,
            };
            assert!(
                (v - exact).abs() < 1e-6 * 300.0,
                "{label} at {t}: {v} vs {exact}"
            );
        }
    }
    // A pitched airframe: nose up by 5 degrees about y, so any two nodes' height
    // difference becomes dx sin(5) + dz cos(5) of their level positions.
    let pitched = model
        .at_condition(&[("attitude.pitch".into(), 5.0)])
        .unwrap();
    let a = model.airframe().model(model.base()).unwrap();
    let b = pitched.airframe().model(pitched.base()).unwrap();
    let (s5, c5) = 5f64.to_radians().sin_cos();
    let (n, m) = (0, a.nodes.len() - 1);
    let d = |k: usize, ab: &impactcal_shell::ShellModel| ab.nodes[m].x[k] - ab.nodes[n].x[k];
    let exact = d(0, &a) * s5 + d(2, &a) * c5;
    assert!(
        (d(2, &b) - exact).abs() < 1e-9 * a.nodes.len() as f64,
        "{} vs {exact}",
        d(2, &b)
    );
    assert!((d(2, &b) - d(2, &a)).abs() > 1.0);
    assert_eq!(pitched.base().get("attitude.pitch").unwrap(), 5.0);
    assert_eq!(model.base().get("attitude.pitch").unwrap(), 0.0);
}

#[test]
fn names_that_are_not_held_quantities_are_refused() {
    let model = table2(0.001);
    // at_condition: a declared parameter, an unknown name, a value out of range.
    let e = model
        .at_condition(&[("belly_panel.t".into(), 0.1)])
        .unwrap_err();
    assert!(
        invalid_option(&e) && e.to_string().contains("declared parameter"),
        "{e}"
    );
    let e = model
        .at_condition(&[("impact.sideways".into(), 10.0)])
        .unwrap_err();
    assert!(
        invalid_option(&e) && e.to_string().contains("impact.sideways"),
        "{e}"
    );
    let e = model
        .at_condition(&[("attitude.roll".into(), 30.0)])
        .unwrap_err();
    assert!(
        invalid_option(&e) && e.to_string().contains("[-10, 10]"),
        "{e}"
    );
    let e = model
        .at_condition(&[("impact.vertical".into(), f64::NAN)])
        .unwrap_err();
    assert!(invalid_option(&e), "{e}");
    // enrich: a declared parameter, an unknown name, a repeat, bounds beyond the range.
    let p = |n: &str, l: f64, u: f64, v: f64| Parameter::new(n, l, u, v).unwrap();
    let e = model
        .enrich(&[p("belly_panel.t", 0.08, 0.1, 0.09)])
        .unwrap_err();
    assert!(
        invalid_option(&e) && e.to_string().contains("already a parameter"),
        "{e}"
    );
    let e = model
        .enrich(&[p("ground.stickiness", 0.0, 1.0, 0.3)])
        .unwrap_err();
    assert!(
        invalid_option(&e) && e.to_string().contains("not a candidate"),
        "{e}"
    );
    let f = p("ground.friction", 0.0, 0.8, 0.3);
    let e = model.enrich(&[f.clone(), f]).unwrap_err();
    assert!(invalid_option(&e) && e.to_string().contains("twice"), "{e}");
    let e = model.enrich(&[p("damping", -5.0, 10.0, 0.0)]).unwrap_err();
    assert!(
        invalid_option(&e) && e.to_string().contains("admissible"),
        "{e}"
    );
    // Narrower bounds than the admissible range are the caller's to choose.
    let narrowed = model
        .enrich(&[p("ground.friction", 0.1, 0.5, 0.3)])
        .unwrap();
    assert_eq!(narrowed.space().parameters()[6].upper, 0.5);
}
