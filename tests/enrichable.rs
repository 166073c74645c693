//! The models as the study builds them (a subspace of the airframe's whole catalogue, a
//! subspace of a deck's quantities) list the same candidate effects as the models that
//! declare the study's space themselves, and freeing a candidate through the subspace at its
//! held value changes no run.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use impactcal::calibrate::study::Subspace;
use impactcal::core::enrich::Enrichable;
use impactcal::core::{Model, Parameter, ParameterSpace};
use impactcal::shell::DeckModel;
use impactcal::shell::airframe::{
    Airframe, AirframeModel, AirframeOptions, MeshDensity, Preset, catalogue, space_of,
};
use impactcal::shell::keyword::read_deck;

fn coarse(end_time: f64) -> Airframe {
    let mut o = AirframeOptions::new(MeshDensity::Coarse);
    o.end_time = end_time;
    Airframe::new(o).unwrap()
}

#[test]
fn the_studys_airframe_subspace_lists_the_airframes_candidates() {
    let names: Vec<String> = catalogue().into_iter().map(|a| a.name).collect();
    let full = AirframeModel::new(coarse(0.0012), space_of(&names).unwrap()).unwrap();
    let table2 = Preset::Table2.space().unwrap();
    let sub = Subspace::new(full, table2).unwrap();
    let direct = AirframeModel::preset(coarse(0.0012), Preset::Table2).unwrap();
    assert_eq!(sub.candidates(), direct.candidates());
    assert_eq!(
        sub.describe("belly_panel.t"),
        Some(("thickness".into(), "belly panel thickness".into()))
    );

    let pick = |m: &[impactcal::core::Candidate], n: &str| {
        m.iter().find(|c| c.name() == n).unwrap().parameter.clone()
    };
    let c = sub.candidates();
    let added = [pick(&c, "damping"), pick(&c, "ground.friction")];
    let e = sub.enrich(&added).unwrap();
    let x = sub.space().nominal();
    let mut y = x.clone();
    y.extend([0.0, 0.3]);
    let a = sub.simulate(&x).unwrap();
    let b = e.simulate(&y).unwrap();
    assert!(
        a.data()
            .iter()
            .zip(b.data())
            .all(|(p, q)| p.to_bits() == q.to_bits())
    );
    // A holdout condition through the subspace: the free fall starts at the new speed.
    let slow = sub
        .at_condition(&[("impact.vertical".into(), 280.0)])
        .unwrap();
    let h = slow.simulate(&x).unwrap();
    let z = h.labels().iter().position(|l| l.ends_with(".z")).unwrap();
    assert_eq!(h.channel(z)[0], -280.0);
}

#[test]
fn the_studys_deck_subspace_lists_the_other_quantities_then_the_decks_candidates() {
    let deck = read_deck(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/decks/strip_drop.k"
    ))
    .unwrap();
    let model = DeckModel::new(deck.model).unwrap();
    // The study's [parameters] table: `thickness = "section.1.t"`.
    let space = ParameterSpace::new(vec![
        Parameter::new("thickness", 0.0018, 0.0022, 0.002).unwrap(),
    ])
    .unwrap();
    let sub = Subspace::aliased(model.clone(), space.clone(), &["section.1.t".into()]).unwrap();
    let names: Vec<String> = sub
        .candidates()
        .iter()
        .map(|c| format!("{}:{}", c.name(), c.group))
        .collect();
    assert_eq!(
        names,
        [
            "material.1.E:material",
            "material.1.sigy:material",
            "material.1.Et:material",
            "wall.1.friction:friction",
            "damping:damping",
            "velocity.1.x:condition",
            "velocity.1.y:condition",
            "velocity.1.z:condition"
        ]
    );
    // The same list as the deck model declaring the thickness itself.
    let declared = model
        .declare(
            &ParameterSpace::new(vec![
                Parameter::new("section.1.t", 0.0018, 0.0022, 0.002).unwrap(),
            ])
            .unwrap(),
        )
        .unwrap();
    assert_eq!(sub.candidates(), declared.candidates());
    // The aliased parameter is declared: a condition cannot set it.
    assert!(
        sub.at_condition(&[("section.1.t".into(), 0.002)])
            .unwrap_err()
            .to_string()
            .contains("declared")
    );
}
