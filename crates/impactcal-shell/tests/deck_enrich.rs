//! A keyword deck as an `Enrichable` model, against its contract: the candidates are the
//! deck's quantities not declared, at their held values, in deck order; freeing them at
//! their held values changes no run; another condition changes the response as physics
//! says; names that are not held quantities are refused with typed errors.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use impactcal_core::enrich::Enrichable;
use impactcal_core::{CoreError, Histories, Model, Parameter, ParameterSpace};
use impactcal_shell::DeckModel;
use impactcal_shell::keyword::parse_deck;

fn strip() -> DeckModel {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/decks/strip_drop.k"
    );
    let text = std::fs::read_to_string(path).unwrap();
    DeckModel::new(parse_deck(&text, "strip_drop.k").unwrap().model).unwrap()
}

fn space(params: &[(&str, f64, f64, f64)]) -> ParameterSpace {
    ParameterSpace::new(
        params
            .iter()
            .map(|&(n, l, u, v)| Parameter::new(n, l, u, v).unwrap())
            .collect(),
    )
    .unwrap()
}

fn bit_identical(a: &Histories, b: &Histories) -> bool {
    a.labels() == b.labels()
        && a.data()
            .iter()
            .zip(b.data())
            .all(|(x, y)| x.to_bits() == y.to_bits())
}

/// The samples of the z channels before the strip (0.004 m above the floor at its lowest,
/// 5 m/s down) can touch it: t < 0.5 ms.
fn free_flight_z(h: &Histories) -> Vec<(f64, f64)> {
    let time = h.time();
    h.labels()
        .iter()
        .enumerate()
        .filter(|(_, l)| l.ends_with(".z"))
        .flat_map(|(i, _)| {
            time.iter()
                .zip(h.channel(i))
                .filter(|(t, _)| **t < 5e-4)
                .map(|(&t, &v)| (t, v))
                .collect::<Vec<_>>()
        })
        .collect()
}

#[test]
fn a_declared_subset_leaves_the_rest_as_candidates_in_deck_order() {
    let full = strip();
    let m = full
        .declare(&space(&[("section.1.t", 0.0018, 0.0022, 0.002)]))
        .unwrap();
    assert_eq!(m.space().names(), ["section.1.t"]);
    let c = m.candidates();
    let names: Vec<&str> = c.iter().map(|c| c.name()).collect();
    assert_eq!(
        names,
        [
            "material.1.E",
            "material.1.sigy",
            "material.1.Et",
            "wall.1.friction",
            "damping",
            "velocity.1.x",
            "velocity.1.y",
            "velocity.1.z"
        ]
    );
    let get = |n: &str| c.iter().find(|c| c.name() == n).unwrap();
    let range = |n: &str| {
        let p = &get(n).parameter;
        (p.lower, p.nominal, p.upper)
    };
    assert_eq!(range("wall.1.friction"), (0.0, 0.3, 0.8));
    assert_eq!(get("wall.1.friction").group, "friction");
    // 2 / end time (2 ms).
    assert_eq!(range("damping"), (0.0, 0.0, 1000.0));
    assert_eq!(get("damping").group, "damping");
    let speed = 29f64.sqrt();
    let (lo, v, hi) = range("velocity.1.y");
    assert_eq!(v, 0.0);
    assert!((lo + 0.2 * speed).abs() < 1e-12 && (hi - 0.2 * speed).abs() < 1e-12);
    assert_eq!(get("velocity.1.z").group, "condition");
    let (lo, v, hi) = range("material.1.E");
    assert_eq!((lo, v, hi), (0.8 * 2.1e11, 2.1e11, 1.2 * 2.1e11));
    assert_eq!(get("material.1.sigy").group, "material");
    // Declaring a held quantity, and errors for what the deck does not have.
    let m2 = full
        .declare(&space(&[("wall.1.friction", 0.1, 0.5, 0.3)]))
        .unwrap();
    assert_eq!(m2.candidates()[0].name(), "section.1.t");
    let e = full
        .declare(&space(&[("wall.2.friction", 0.1, 0.5, 0.3)]))
        .unwrap_err();
    assert!(e.to_string().contains("wall.2.friction"), "{e}");
    let e = full
        .declare(&space(&[("section.1.t", 0.001, 0.003, 0.002)]))
        .unwrap_err();
    assert!(e.to_string().contains("admissible"), "{e}");
}

#[test]
fn freed_at_held_values_the_runs_are_identical_and_damping_acts_as_physics_says() {
    let m = strip()
        .declare(&space(&[("section.1.t", 0.0018, 0.0022, 0.002)]))
        .unwrap();
    let c = m.candidates();
    let added: Vec<Parameter> = ["material.1.E", "wall.1.friction", "damping", "velocity.1.z"]
        .iter()
        .map(|n| c.iter().find(|c| c.name() == *n).unwrap().parameter.clone())
        .collect();
    let e = m.enrich(&added).unwrap();
    assert_eq!(
        e.space().names(),
        [
            "section.1.t",
            "material.1.E",
            "wall.1.friction",
            "damping",
            "velocity.1.z"
        ]
    );
    assert_eq!(e.candidates().len(), c.len() - 4);
    let mut x = vec![0.002];
    let before = m.simulate(&x).unwrap();
    x.extend(added.iter().map(|p| p.nominal));
    let after = e.simulate(&x).unwrap();
    assert!(bit_identical(&before, &after));
    // Mass-proportional damping D in free flight: vz = -5 e^{-D t} (no gravity here).
    x[3] = 400.0;
    let damped = e.simulate(&x).unwrap();
    let ff = free_flight_z(&damped);
    assert!(ff.len() > 4);
    for (t, v) in ff {
        let exact = -5.0 * (-400.0 * t).exp();
        assert!(
            (v - exact).abs() < 5e-3 * (5.0 - exact.abs()).max(1e-3),
            "{t}: {v} vs {exact}"
        );
    }
    // And the freed friction acts: without friction the strip slides differently.
    let mut y = x.clone();
    y[3] = 0.0;
    y[2] = 0.0;
    let frictionless = e.simulate(&y).unwrap();
    assert!(!bit_identical(&before, &frictionless));
}

#[test]
fn another_impact_velocity_sets_the_free_flight_and_errors_are_typed() {
    let m = strip();
    let slow = m.at_condition(&[("velocity.1.z".into(), -4.5)]).unwrap();
    assert_eq!(slow.space(), m.space());
    assert_eq!(slow.base().initial_velocities[0].translation[2], -4.5);
    let h = slow.simulate(&m.space().nominal()).unwrap();
    for (t, v) in free_flight_z(&h) {
        assert!((v + 4.5).abs() < 1e-9, "{t}: {v}");
    }
    // The candidate's held value follows the condition.
    let z = slow.candidates();
    let vz = z.iter().find(|c| c.name() == "velocity.1.z").unwrap();
    assert_eq!(vz.parameter.nominal, -4.5);

    let invalid = |e: CoreError| matches!(e, CoreError::InvalidOption { .. });
    let e = m
        .at_condition(&[("section.1.t".into(), 0.002)])
        .unwrap_err();
    assert!(e.to_string().contains("declared parameter"), "{e}");
    assert!(invalid(e));
    let e = m.at_condition(&[("gravity".into(), 9.81)]).unwrap_err();
    assert!(e.to_string().contains("gravity"), "{e}");
    assert!(invalid(e));
    let e = m
        .at_condition(&[("wall.1.friction".into(), -0.1)])
        .unwrap_err();
    assert!(e.to_string().contains("[0, 0.8]"), "{e}");
    assert!(invalid(e));
    let p = |n: &str, l: f64, u: f64, v: f64| Parameter::new(n, l, u, v).unwrap();
    let e = m
        .enrich(&[p("section.1.t", 0.0018, 0.0022, 0.002)])
        .unwrap_err();
    assert!(e.to_string().contains("already a parameter"), "{e}");
    let e = m
        .enrich(&[p("wall.7.friction", 0.0, 0.5, 0.3)])
        .unwrap_err();
    assert!(e.to_string().contains("not a candidate"), "{e}");
    let f = p("damping", 0.0, 10.0, 0.0);
    let e = m.enrich(&[f.clone(), f]).unwrap_err();
    assert!(e.to_string().contains("twice"), "{e}");
    let e = m.enrich(&[p("damping", -1.0, 10.0, 0.0)]).unwrap_err();
    assert!(e.to_string().contains("admissible"), "{e}");
}
