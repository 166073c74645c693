//! The contact keywords: `*CONTACT_AUTOMATIC_SINGLE_SURFACE`, `_SURFACE_TO_SURFACE`,
//! `_NODES_TO_SURFACE` with their `_ID` / `_TITLE` cards and optional cards A to C, and
//! `*CONTROL_CONTACT`: every field read into the model (or refused naming it), decks
//! written and read back unchanged, SLSFAC acting on the penalty stiffness, and the public
//! LS-OPT car pole decks read and run unmodified (skipped with a notice when absent).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

mod common;

use std::path::PathBuf;

use impactcal_shell::keyword::{parse_deck, read_deck, write_deck};
use impactcal_shell::{
    Contact, ContactFriction, ContactKind, ContactSurface, ShellError, Simulation,
};

/// A plate of four quads (part 1, nodes 1-9), a second part above it (part 2, one quad) and
/// the `extra` keywords.
fn deck(extra: &str) -> String {
    let mut d = String::from("*KEYWORD\n*CONTROL_TERMINATION\n1.0e-4\n*NODE\n");
    let mut id = 1;
    for j in 0..3 {
        for i in 0..3 {
            d += &format!(
                "{id:8}{:16}{:16}{:16}\n",
                0.05 * i as f64,
                0.05 * j as f64,
                0.0
            );
            id += 1;
        }
    }
    for (k, (x, y)) in [(0.02, 0.02), (0.08, 0.02), (0.08, 0.08), (0.02, 0.08)]
        .iter()
        .enumerate()
    {
        d += &format!("{:8}{:16}{:16}{:16}\n", 20 + k, x, y, 0.003);
    }
    d += "*ELEMENT_SHELL\n";
    for (e, n) in [(1, 1), (2, 2), (3, 4), (4, 5)] {
        d += &format!("{e:8}{:8}{:8}{:8}{:8}{:8}\n", 1, n, n + 1, n + 4, n + 3);
    }
    d += &format!("{:8}{:8}{:8}{:8}{:8}{:8}\n", 10, 2, 20, 21, 22, 23);
    d += "*PART\nplate\n         1         1         1\n*PART\nlid\n         2         1         1\n";
    d += "*SECTION_SHELL\n         1         2       1.0         3\n     0.002\n";
    d += "*MAT_ELASTIC\n         1    7850.0    2.1e11       0.3\n";
    d += "*SET_PART_LIST\n         7\n         1         2\n*SET_NODE_LIST\n         8\n        20        21\n";
    d += extra;
    d += "*END\n";
    d
}

#[test]
fn automatic_contacts_are_read_field_by_field() {
    let extra = "\
*CONTROL_CONTACT
      0.05
$ card 2: SSTHK
                                                           1
$ card 3: SFRIC, DFRIC, EDC, VFC
      0.15      0.12       0.5
*CONTACT_AUTOMATIC_SINGLE_SURFACE_ID
        11self
         7                   2
       0.3       0.2       1.0       0.0      10.0         0      0.01      0.09
       2.0       0.0     0.001       0.0       0.5       0.0       2.0
         0       0.0         0     1.025       0.0         0         0         1
       0.0         0         0         0         0         0       0.0       0.0
         0         1       0.0       0.0
*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE_TITLE
        12plate on lid
         2         1         3         3
$ FS blank: the defaults of *CONTROL_CONTACT, scaled by FSF and VSF
                                          5.0
       1.0       3.0       0.0     0.004       0.0       0.5       2.0       3.0
*CONTACT_AUTOMATIC_NODES_TO_SURFACE
         8         7         4         2
       0.1
       0.0       0.0
";
    let d = parse_deck(&deck(extra), "c.k").unwrap();
    let m = &d.model;
    assert_eq!(m.contact_control.penalty_scale, 0.05);
    assert!(m.contact_control.full_thickness);
    assert_eq!(m.contacts.len(), 3);
    let (a, b, c) = (&m.contacts[0], &m.contacts[1], &m.contacts[2]);
    assert_eq!(
        (a.id, a.kind, a.slave),
        (11, ContactKind::SingleSurface, ContactSurface::PartSet(7))
    );
    // FSF 2 doubles FS and FD; DC as given; VDC 10 %; BT, DT.
    assert_eq!(
        a.friction,
        ContactFriction {
            static_coef: 0.6,
            dynamic: 0.4,
            decay: 1.0,
            viscous: 0.0
        }
    );
    assert_eq!((a.damping, a.birth, a.death), (10.0, 0.01, 0.09));
    assert_eq!(
        (
            a.slave_side.stiffness_scale,
            a.slave_side.thickness,
            a.slave_side.thickness_scale
        ),
        (2.0, 0.001, 0.5)
    );
    assert_eq!(a.master_side.stiffness_scale, 1.0);
    assert_eq!(
        (b.id, b.kind, b.slave, b.master),
        (
            12,
            ContactKind::SurfaceToSurface,
            ContactSurface::Part(2),
            ContactSurface::Part(1)
        )
    );
    // Friction from *CONTROL_CONTACT card 3, FSF 2 and VSF 3 applied to it; VDC 5.
    assert_eq!(
        b.friction,
        ContactFriction {
            static_coef: 0.3,
            dynamic: 0.24,
            decay: 0.5,
            viscous: 0.0
        }
    );
    assert_eq!((b.damping, b.death), (5.0, f64::INFINITY));
    assert_eq!(
        (b.master_side.stiffness_scale, b.master_side.thickness),
        (3.0, 0.004)
    );
    assert_eq!(
        (c.id, c.kind, c.slave, c.master),
        (
            0,
            ContactKind::NodesToSurface,
            ContactSurface::NodeSet(8),
            ContactSurface::PartSet(7)
        )
    );
    assert_eq!(c.friction.static_coef, 0.1);
    // The warnings name what was ignored: MAXPAR 1.025 is the default, nothing else set.
    assert!(
        d.warnings.iter().all(|w| !w.contains("MAXPAR")),
        "{:?}",
        d.warnings
    );
    // And every interface builds.
    Simulation::new(m).unwrap();
}

#[test]
fn contact_decks_are_written_and_read_back_unchanged() {
    let extra = "\
*CONTACT_AUTOMATIC_SINGLE_SURFACE_ID
        11
         7                   2
       0.3       0.2       1.0       0.0      10.0         0      0.01      0.09

*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE
         2         1         3         3
       0.1
       1.5       1.2     0.001     0.004       0.5       2.0
*CONTACT_AUTOMATIC_NODES_TO_SURFACE
         8         0         4         5


*CONTROL_CONTACT
      0.07
";
    let m = parse_deck(&deck(extra), "c.k").unwrap().model;
    let text = write_deck(&m).unwrap();
    let back = parse_deck(&text, "w.k").unwrap().model;
    assert_eq!(back.contacts, m.contacts);
    assert_eq!(back.contact_control, m.contact_control);
    assert_eq!(back, m);
}

#[test]
fn unsupported_contact_settings_are_refused_naming_the_field() {
    let card = |c1: &str, c2: &str, c3: &str, more: &str| {
        format!("*CONTACT_AUTOMATIC_SINGLE_SURFACE\n{c1}\n{c2}\n{c3}\n{more}")
    };
    let base = "         7                   2";
    let cases = [
        (card(base, "", "", "         1\n"), "SOFT"),
        (card("         7                   0", "", "", ""), "SSTYP"),
        (card(base, "      -1.0", "", ""), "FS"),
        (
            card(
                base,
                "",
                "",
                "         0       0.0         0       0.0       0.0         0         0         5\n",
            ),
            "FRCFRQ",
        ),
        (card(base, "", "", "         0\n       0.5\n"), "PENMAX"),
        (
            card(base, "", "", "\n\n\n         1\n"),
            "optional cards after card C",
        ),
        (
            card(
                "         7         0         2         0         1",
                "",
                "",
                "",
            ),
            "SBOXID",
        ),
        (
            card(
                base,
                "                                                                   0.5       0.1",
                "",
                "",
            ),
            "DT",
        ),
        (
            "*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE\n         1         8         3         4\n\n\n"
                .to_string(),
            "MSTYP",
        ),
        ("*CONTROL_CONTACT\n      -0.1\n".to_string(), "SLSFAC"),
        (
            "*CONTROL_CONTACT\n       0.1       0.0         0         0         3\n".to_string(),
            "PENOPT",
        ),
    ];
    for (extra, field) in cases {
        match parse_deck(&deck(&extra), "c.k") {
            Err(ShellError::Keyword { message, .. }) => {
                assert!(message.contains(field), "{field}: {message}");
            }
            other => panic!(
                "{field}: expected a keyword error, got {:?}",
                other.map(|d| d.model.contacts)
            ),
        }
    }
    // A keyword this reader does not take.
    assert!(matches!(
        parse_deck(&deck("*CONTACT_AUTOMATIC_SINGLE_SURFACE_MPP\n"), "c.k"),
        Err(ShellError::UnsupportedKeyword { .. })
    ));
    // Model-level checks: an undefined part set, a negative friction coefficient.
    let mut m = parse_deck(&deck(""), "c.k").unwrap().model;
    m.contacts
        .push(Contact::single_surface(ContactSurface::PartSet(99)));
    assert!(matches!(
        Simulation::new(&m),
        Err(ShellError::Reference {
            what: "part set",
            id: 99,
            ..
        })
    ));
    m.contacts[0] = Contact {
        friction: ContactFriction {
            static_coef: -0.1,
            ..ContactFriction::default()
        },
        ..Contact::single_surface(ContactSurface::PartSet(7))
    };
    assert!(matches!(Simulation::new(&m), Err(ShellError::Value { .. })));
}

/// SLSFAC scales the penalty stiffness: a mass dropped on a held plate stays in contact
/// `sqrt(2)` times longer with SLSFAC 0.05 than with the default 0.1.
#[test]
fn slsfac_scales_the_penalty_stiffness() {
    let duration = |slsfac: &str| {
        let extra = format!(
            "*CONTROL_CONTACT\n{slsfac}\n*SET_NODE_LIST\n         9\n        30\n\
             *NODE\n      30            0.05            0.05         0.00101\n\
             *ELEMENT_MASS\n     100      30             1.0\n\
             *INITIAL_VELOCITY_NODE\n      30       0.0       0.0      -1.0\n\
             *BOUNDARY_SPC_SET\n         1         0         1         1         1         1         1         1\n\
             *SET_NODE_LIST\n         1\n         1         2         3         4         5         6         7         8\n         9\n\
             *CONTACT_AUTOMATIC_NODES_TO_SURFACE\n         9         1         4         3\n\n\n"
        );
        let text = deck(&extra).replace("1.0e-4", "4.0e-4");
        let mut m = parse_deck(&text, "c.k").unwrap().model;
        m.control.fixed_dt = Some(1e-7);
        m.output.history_nodes = vec![30];
        m.output.interval = 1e-7;
        let r = Simulation::new(&m).unwrap().run().unwrap();
        let uz = r
            .displacement
            .as_ref()
            .unwrap()
            .channel_by_label("30.z")
            .unwrap();
        // In contact while the mass is below the plate's surface (half of 2 mm).
        let below = uz.iter().filter(|u| 0.00101 + **u < 0.001).count();
        below as f64 * 1e-7
    };
    let (a, b) = (duration("       0.1"), duration("      0.05"));
    eprintln!("contact time {a:.4e} s at SLSFAC 0.1, {b:.4e} s at 0.05");
    assert!(a > 1e-5);
    assert!(common::rel(b / a, 2f64.sqrt()) < 0.01, "ratio {}", b / a);
}

fn car_decks() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/car_pole/decks");
    if dir.join("main_v223.k").is_file() {
        Some(dir)
    } else {
        eprintln!(
            "note: {} is absent: the car pole decks are not run",
            dir.display()
        );
        None
    }
}

/// The LS-OPT car pole decks (GPL-3, read where they are kept) read with every keyword
/// understood, and their first 300 cycles run with the single-surface contact active, the
/// energy balanced.
#[test]
fn car_pole_decks_run_unmodified() {
    let Some(dir) = car_decks() else { return };
    for name in ["main_v223.k", "main_v223_param.k"] {
        let d = read_deck(dir.join(name)).unwrap();
        for w in &d.warnings {
            assert!(
                w.contains("output-only keyword")
                    || w.contains("sensor keyword")
                    || w.contains("(the same law here: ETAN = 0, no hardening)"),
                "{name}: unexpected warning {w}"
            );
        }
        let mut m = d.model;
        assert_eq!(m.contacts.len(), 1);
        assert_eq!(m.contacts[0].slave, ContactSurface::PartSet(1));
        m.control.end_cycles = 300;
        let mut sim = Simulation::new(&m).unwrap();
        let r = sim.run().unwrap();
        let (_, energy, _) = sim.contact_energies()[0];
        eprintln!(
            "{name}: {} cycles, energy ratio {:.5}, interface energy {energy:.3e}, initial penetrations {:?}",
            r.summary.cycles,
            r.summary.energy_ratio,
            sim.initial_penetrations()
        );
        assert_eq!(r.summary.cycles, 300);
        assert!((r.summary.energy_ratio - 1.0).abs() < 0.01);
    }
}
