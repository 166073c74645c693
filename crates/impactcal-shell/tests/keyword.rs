//! Keyword decks: round trip, the supported cards, typed errors.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::float_cmp,
    clippy::needless_range_loop
)]

mod common;

use common::*;
use impactcal_shell::keyword::{parse_deck, write_deck};
use impactcal_shell::{
    BulkViscosity, CowperSymonds, HourglassForm, InitialVelocity, Material, MaterialLaw, NodeSet,
    NodeTarget, PartStiffnessDamping, RigidWall, Section, ShellError, Simulation, Spc,
    VelocityTarget, WallMethod,
};

fn full_model() -> impactcal_shell::ShellModel {
    let mut m = plate(3, 2, 0.3, 0.2, [0.0, 0.0, 0.05]);
    m.title = "round trip".into();
    // Coordinates that fit a 16-character field exactly.
    for n in m.nodes.iter_mut() {
        n.x = n.x.map(|c| (c * 1e6).round() / 1e6);
    }
    m.sections.push(Section {
        id: 1,
        thickness: 0.0015,
        nip: 5,
        shear_factor: 0.833,
        rule: Default::default(),
    });
    m.materials.push(Material {
        id: 1,
        density: 2780.0,
        youngs: 73.1e9,
        poisson: 0.33,
        law: MaterialLaw::Plastic {
            yield_stress: 345e6,
            tangent_modulus: 1.2e9,
            rate: Some(CowperSymonds { c: 6500.0, p: 4.0 }),
        },
    });
    m.materials.push(aluminium(2));
    m.add_part(2, 1, 2);
    m.parts[1].title = "second part".into();
    m.add_node(100, [0.4, 0.0, 0.05])
        .add_node(101, [0.5, 0.0, 0.05])
        .add_node(102, [0.45, 0.1, 0.05]);
    m.add_shell(50, 2, [100, 101, 102, 102]);
    m.add_mass(900, 6, 12.5);
    m.node_sets.push(NodeSet {
        id: 7,
        nodes: vec![1, 2, 3, 4, 5, 6, 7, 8, 9, 10],
    });
    m.spcs.push(Spc {
        target: NodeTarget::Node(1),
        dofs: [true, false, true, false, true, false],
    });
    m.spcs.push(Spc {
        target: NodeTarget::NodeSet(7),
        dofs: [false, true, false, false, false, true],
    });
    m.initial_velocities.push(InitialVelocity::translation(
        VelocityTarget::All,
        [1.0, 0.0, -7.92],
    ));
    let mut g = InitialVelocity::translation(VelocityTarget::Part(2), [0.5, 0.25, 0.0]);
    g.omega = 3.0;
    g.centre = [0.1, 0.2, 0.3];
    g.axis = [0.0, 0.0, 1.0];
    m.initial_velocities.push(g);
    let mut n = InitialVelocity::translation(VelocityTarget::Node(3), [0.0, 1.5, 0.0]);
    n.rotation = [0.1, 0.0, -0.2];
    m.initial_velocities.push(n);
    m.walls.push(RigidWall {
        id: 0,
        shape: impactcal_shell::WallShape::Plane,
        nodes: None,
        point: [0.0; 3],
        head: [0.0, 0.0, 1.0],
        friction: 0.3,
        method: WallMethod::Kinematic,
    });
    m.walls.push(RigidWall {
        id: 0,
        shape: impactcal_shell::WallShape::Plane,
        nodes: Some(7),
        point: [-1.0, 0.0, 0.0],
        head: [0.0, 0.0, 0.0],
        friction: f64::INFINITY,
        method: WallMethod::Kinematic,
    });
    m.set_gravity(9.81);
    m.damping = 2.5;
    m.stiffness_damping = vec![
        PartStiffnessDamping { part: 1, coef: 0.1 },
        PartStiffnessDamping {
            part: 2,
            coef: -2.5e-6,
        },
    ];
    m.bulk_viscosity = Some(BulkViscosity { q1: 1.2, q2: 0.05 });
    m.control.invariant_numbering = true;
    m.hourglass.form = HourglassForm::Viscous;
    m.hourglass.membrane = 0.1;
    m.hourglass.transverse = 0.1;
    m.hourglass.rotation = 0.1;
    m.control.end_time = 0.0125;
    m.control.end_cycles = 100000;
    m.control.tssfac = 0.8;
    m.control.isdo_diagonal = true;
    m.output.history_nodes = vec![1, 5, 12, 100];
    m.output.interval = 1e-4;
    m
}

#[test]
fn a_written_deck_reads_back_into_the_same_model() {
    let m = full_model();
    let text = write_deck(&m).unwrap();
    let back = parse_deck(&text, "written").unwrap();
    assert!(back.warnings.is_empty(), "{:?}", back.warnings);
    assert_eq!(back.model, m);
    // And writing again gives the same text.
    assert_eq!(write_deck(&back.model).unwrap(), text);
    // The model is valid and runs.
    Simulation::new(&back.model).unwrap();
}

const DECK: &str = "\
$ a small deck in fixed and free format
*KEYWORD
*TITLE
strip on the floor
*CONTROL_TERMINATION
$   endtim    endcyc
    2.0e-3
*CONTROL_TIMESTEP
       0.0       0.9
*NODE
       1             0.0             0.0           0.005
       2            0.05             0.0           0.005
3,0.05,0.05,0.005
       4             0.0            0.05           0.005
*ELEMENT_SHELL
       1       1       1       2       3       4
*PART
strip
         1         1         1
*SECTION_SHELL
         1         2         0         5
     0.002
*MAT_PLASTIC_KINEMATIC
1,7850.,2.1e11,0.3,2.5e8,1.0e9,1.0
0.,0.
*INITIAL_VELOCITY
         0
       0.0       0.0      -5.0
*RIGIDWALL_PLANAR
         0
       0.0       0.0       0.0       0.0       0.0       1.0       0.2
*DATABASE_GLSTAT
   1.0e-5
*DATABASE_HISTORY_NODE
         3
*DATABASE_NODOUT
    1.0e-4
*END
anything after *END is ignored
";

#[test]
fn a_hand_written_deck_with_both_card_formats_runs() {
    let deck = parse_deck(DECK, "inline.k").unwrap();
    // The ignored output keyword, and the hourglass default (no *CONTROL_HOURGLASS).
    assert_eq!(deck.warnings.len(), 2, "{:?}", deck.warnings);
    assert!(deck.warnings[0].contains("*DATABASE_GLSTAT"));
    assert!(deck.warnings[1].contains("no *CONTROL_HOURGLASS"));
    let m = &deck.model;
    assert_eq!(m.title, "strip on the floor");
    assert_eq!(m.nodes[2].x, [0.05, 0.05, 0.005]);
    assert_eq!(m.sections[0].nip, 5);
    assert_eq!(m.sections[0].shear_factor, 1.0);
    assert_eq!(m.output.history_nodes, vec![3]);
    let r = Simulation::new(m).unwrap().run().unwrap();
    let vz = r.velocity.unwrap();
    assert_eq!(vz.labels()[2], "3.z");
    assert_eq!(vz.samples(), 21);
    // Landed, not through the floor.
    assert!(vz.channel(2)[20].abs() < 1.0);
}

/// The damping, bulk viscosity, invariant numbering and penalty cards, as LS-DYNA users
/// write them, with defaults for blank fields.
#[test]
fn damping_bulk_viscosity_accuracy_and_penalty_cards() {
    let extra = "\
*DAMPING_PART_STIFFNESS
$      pid      coef
         1      0.08
*CONTROL_BULK_VISCOSITY
$       q1        q2      type
                        -2
*CONTROL_ACCURACY
$      osu       inn
         0         2
*CONTROL_CONTACT
$   slsfac    rwpnal
       0.1      0.25
*END
";
    let text = DECK.replace("*END\n", extra);
    let deck = parse_deck(&text, "extra.k").unwrap();
    let m = &deck.model;
    assert_eq!(
        m.stiffness_damping,
        vec![PartStiffnessDamping {
            part: 1,
            coef: 0.08
        }]
    );
    assert_eq!(m.bulk_viscosity, Some(BulkViscosity { q1: 1.5, q2: 0.06 }));
    assert!(m.control.invariant_numbering);
    assert_eq!(
        m.walls[0].method,
        WallMethod::Penalty {
            alpha: 0.25,
            damping: 0.0
        }
    );
    // SLSFAC is the contact interfaces' penalty scale (none here); nothing is warned.
    assert_eq!(m.contact_control.penalty_scale, 0.1);
    assert!(
        deck.warnings.iter().all(|w| !w.contains("CONTROL_CONTACT")),
        "{:?}",
        deck.warnings
    );
    // Written and read again: the same model; and it runs.
    let back = parse_deck(&write_deck(m).unwrap(), "again.k")
        .unwrap()
        .model;
    assert_eq!(&back, m);
    let r = Simulation::new(m).unwrap().run().unwrap();
    assert!((r.summary.energy_ratio - 1.0).abs() < 0.05);
    // TYPE 1 (the LS-DYNA default) acts on solids only: no shell bulk viscosity, a warning.
    let solids = text.replace("                        -2", "                         1");
    let d = parse_deck(&solids, "solids.k").unwrap();
    assert_eq!(d.model.bulk_viscosity, None);
    assert!(d.warnings.iter().any(|w| w.contains("solids only")));
    // Bad values are typed errors naming the keyword and line.
    for (from, to, keyword) in [
        (
            "                        -2",
            "                         7",
            "*CONTROL_BULK_VISCOSITY",
        ),
        (
            "         0         2",
            "         0         9",
            "*CONTROL_ACCURACY",
        ),
        (
            "       0.1      0.25",
            "       0.1       1.5",
            "*CONTROL_CONTACT",
        ),
        (
            "         1      0.08",
            "         1       abc",
            "*DAMPING_PART_STIFFNESS",
        ),
    ] {
        match parse_deck(&text.replace(from, to), "bad.k") {
            Err(ShellError::Keyword { keyword: k, .. }) => assert_eq!(k, keyword),
            other => panic!("{keyword}: {other:?}"),
        }
    }
    // Damping of an undefined part, twice for one part, or a non-finite coefficient.
    let undefined = text.replace("         1      0.08", "         9      0.08");
    assert!(matches!(
        err(&undefined),
        ShellError::Reference {
            what: "part",
            id: 9,
            ..
        }
    ));
    let twice = text.replace(
        "         1      0.08",
        "         1      0.08\n         1      0.02",
    );
    assert!(matches!(err(&twice), ShellError::Reference { id: 1, .. }));
    // Features the cards cannot express are refused by the writer.
    let mut damped = m.clone();
    damped.walls[0].method = WallMethod::Penalty {
        alpha: 0.25,
        damping: 0.2,
    };
    assert!(write_deck(&damped).is_err());
    let mut zero = m.clone();
    zero.bulk_viscosity = Some(BulkViscosity { q1: 0.0, q2: 0.06 });
    assert!(write_deck(&zero).is_err());
}

fn err(text: &str) -> ShellError {
    match parse_deck(text, "bad.k").and_then(|d| Simulation::new(&d.model).map(|_| ())) {
        Err(e) => e,
        Ok(()) => panic!("expected an error"),
    }
}

#[test]
fn unsupported_keywords_and_bad_cards_are_typed_errors_with_lines() {
    match err("*KEYWORD\n*CONTACT_SINGLE_SURFACE\n1\n*END\n") {
        ShellError::UnsupportedKeyword { line, keyword, .. } => {
            assert_eq!(line, 2);
            assert_eq!(keyword, "*CONTACT_SINGLE_SURFACE");
        }
        e => panic!("{e}"),
    }
    match err("*KEYWORD\n*NODE\n       1             abc\n*END\n") {
        ShellError::Keyword {
            line,
            keyword,
            message,
            ..
        } => {
            assert_eq!((line, keyword.as_str()), (3, "*NODE"));
            assert!(message.contains('X'), "{message}");
        }
        e => panic!("{e}"),
    }
    match err("*KEYWORD\n*CONTROL_TIMESTEP\n0.0,0.9,0,0.0,-1.0e-6\n*END\n") {
        ShellError::Keyword { message, .. } => assert!(message.contains("DT2MS")),
        e => panic!("{e}"),
    }
}

fn with_line(deck: &str, from: &str, to: &str) -> String {
    assert!(deck.contains(from));
    deck.replace(from, to)
}

#[test]
fn build_time_checks_name_the_entity_at_fault() {
    // Undefined part.
    let d = with_line(
        DECK,
        "       1       1       1       2       3       4",
        "       1       9       1       2       3       4",
    );
    assert!(matches!(
        err(&d),
        ShellError::Reference {
            what: "part",
            id: 9,
            ..
        }
    ));
    // Undefined section and material.
    let d = with_line(
        DECK,
        "         1         1         1\n*SECTION",
        "         1         4         1\n*SECTION",
    );
    assert!(matches!(
        err(&d),
        ShellError::Reference {
            what: "section",
            id: 4,
            ..
        }
    ));
    let d = with_line(
        DECK,
        "         1         1         1\n*SECTION",
        "         1         1         5\n*SECTION",
    );
    assert!(matches!(
        err(&d),
        ShellError::Reference {
            what: "material",
            id: 5,
            ..
        }
    ));
    // Missing node.
    let d = with_line(
        DECK,
        "       1       1       1       2       3       4",
        "       1       1       1       2       3       8",
    );
    assert!(matches!(
        err(&d),
        ShellError::Reference {
            what: "node",
            id: 8,
            ..
        }
    ));
    // Degenerate (collinear) and inverted (bow-tie) elements.
    let d = with_line(DECK, "3,0.05,0.05,0.005", "3,0.1,0.0,0.005");
    let d = with_line(
        &d,
        "       4             0.0            0.05           0.005",
        "       4            0.15             0.0           0.005",
    );
    assert!(matches!(err(&d), ShellError::Element { element: 1, .. }));
    let d = with_line(DECK, "3,0.05,0.05,0.005", "3,0.0,0.05,0.005");
    let d = with_line(
        &d,
        "       4             0.0            0.05           0.005",
        "       4            0.05            0.05           0.005",
    );
    assert!(matches!(err(&d), ShellError::Element { element: 1, .. }));
    // Non-positive thickness and density, nu out of range.
    let d = with_line(DECK, "     0.002", "    -0.002");
    assert!(matches!(err(&d), ShellError::Value { ref what, .. } if what.contains("thickness")));
    let d = with_line(DECK, "1,7850.,2.1e11,0.3", "1,0.0,2.1e11,0.3");
    assert!(matches!(err(&d), ShellError::Value { ref what, .. } if what.contains("density")));
    let d = with_line(DECK, "1,7850.,2.1e11,0.3", "1,7850.,2.1e11,0.5");
    assert!(matches!(err(&d), ShellError::Value { ref what, .. } if what.contains("nu")));
}
