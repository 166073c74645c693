//! End-to-end tests of `impactcal simulate` on the shipped deck and on malformed decks.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

mod common;
use common::{example_file, impactcal};

use impactcal::core::Histories;

#[test]
fn simulate_writes_histories_energies_and_a_summary() {
    let dir = tempfile::tempdir().unwrap();
    let h = dir.path().join("h.csv");
    let e = dir.path().join("e.csv");
    let d = example_file("decks", "strip_drop.k");
    let run = |threads: &str, q: &str| {
        let out = impactcal(&[
            "simulate",
            "--deck",
            d.to_str().unwrap(),
            "--out",
            h.to_str().unwrap(),
            "--energies",
            e.to_str().unwrap(),
            "--quantity",
            q,
            "--threads",
            threads,
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stderr).to_string()
    };
    let log = run("1", "velocity");
    assert!(
        log.contains("cycles") && log.contains("energy ratio"),
        "{log}"
    );
    let v1 = Histories::read_csv(&h).unwrap();
    assert_eq!(
        v1.labels(),
        ["21.x", "21.y", "21.z", "42.x", "42.y", "42.z"]
    );
    assert_eq!(v1.samples(), 101);
    assert_eq!(v1.channel(2)[0], -5.0);
    let energies = Histories::read_csv(&e).unwrap();
    let ratio = energies.channel_by_label("energy_ratio").unwrap();
    assert!(ratio.iter().all(|r| (r - 1.0).abs() < 0.05));
    // Same histories on two threads.
    run("2", "velocity");
    assert_eq!(Histories::read_csv(&h).unwrap(), v1);
    // Displacement: node 21 starts 6 mm up, comes down and never passes the floor.
    run("2", "displacement");
    let u = Histories::read_csv(&h).unwrap();
    let uz = u.channel_by_label("21.z").unwrap();
    let lowest = uz.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!((-0.006 - 1e-12..-0.004).contains(&lowest), "{lowest}");
}

#[test]
fn a_bad_deck_is_an_input_error_naming_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.k");
    std::fs::write(&bad, "*KEYWORD\n*CONTACT_AUTOMATIC_SINGLE_SURFACE\n*END\n").unwrap();
    let out = impactcal(&["simulate", "--deck", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("line 2") && err.contains("*CONTACT_AUTOMATIC_SINGLE_SURFACE"),
        "{err}"
    );
}

/// Errors found when the deck becomes a model (a node an element needs, a value out of
/// range) name the deck too, not only the ids.
#[test]
fn a_model_error_names_the_deck() {
    let dir = tempfile::tempdir().unwrap();
    let deck = std::fs::read_to_string(example_file("decks", "strip_drop.k")).unwrap();
    let node_21 = deck
        .lines()
        .find(|l| l.split_whitespace().next() == Some("21") && l.contains("0.500000"))
        .unwrap();
    for (name, text, message) in [
        (
            "missing.k",
            deck.replace(&format!("{node_21}\n"), ""),
            "node 21: referenced by shell",
        ),
        (
            "soft.k",
            deck.replace("2.1e+11", "0.0    "),
            "material 1, Young's modulus",
        ),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        let out = impactcal(&["simulate", "--deck", path.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2), "{name}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(&format!("{name}: {message}")), "{err}");
    }
}

#[test]
fn every_unsupported_keyword_is_named_on_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("many.k");
    std::fs::write(
        &bad,
        "*KEYWORD\n*CONTACT_TIED_SURFACE_TO_SURFACE\n1\n*SECTION_SOLID\n2\n*MAT_SPOTWELD\n3\n*END\n",
    )
    .unwrap();
    let out = impactcal(&["simulate", "--deck", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    for (kw, line) in [
        ("*CONTACT_TIED_SURFACE_TO_SURFACE", 2),
        ("*SECTION_SOLID", 4),
        ("*MAT_SPOTWELD", 6),
    ] {
        assert!(err.contains(&format!("{kw} (")), "{err}");
        assert!(err.contains(&format!("line {line})")), "{err}");
    }
}

#[test]
fn a_latin1_deck_runs_with_a_warning_and_a_motion_without_strain_has_no_hourglass_share() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(example_file("decks", "strip_drop.k")).unwrap();
    // Free flight: no wall, so no strain and no internal energy; a Latin-1 title.
    let text = text
        .replace(
            "*RIGIDWALL_PLANAR\n         0\n       0.0       0.0       0.0       0.0       0.0       1.0       0.3\n",
            "",
        )
        .replace("strip drop\n", "strip in free flight, \u{e9}l\u{e8}ve\n")
        .replace("    2.0e-3\n", "    2.0e-4\n");
    assert!(!text.contains("RIGIDWALL"));
    let bytes: Vec<u8> = text
        .chars()
        .map(|c| u8::try_from(u32::from(c)).unwrap())
        .collect();
    let deck = dir.path().join("latin1.k");
    std::fs::write(&deck, bytes).unwrap();
    let out = impactcal(&["simulate", "--deck", deck.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("line 4") && err.contains("Latin-1"), "{err}");
    assert!(err.contains("internal energy negligible"), "{err}");
    assert!(!err.contains("hourglass/internal"), "{err}");
    // The dropped strip deforms: its share is printed.
    let out = impactcal(&[
        "simulate",
        "--deck",
        example_file("decks", "strip_drop.k").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("hourglass/internal"), "{err}");
}

/// `--wall-forces` and `--part-energies`: the wall's sampled force integrates to the
/// momentum the strip lost and regained, the part energies add up to the global ones.
#[test]
fn simulate_writes_wall_forces_and_part_energies() {
    let dir = tempfile::tempdir().unwrap();
    let (w, p, e) = (
        dir.path().join("w.csv"),
        dir.path().join("p.csv"),
        dir.path().join("e.csv"),
    );
    let d = example_file("decks", "strip_drop.k");
    let out = impactcal(&[
        "simulate",
        "--deck",
        d.to_str().unwrap(),
        "--wall-forces",
        w.to_str().unwrap(),
        "--part-energies",
        p.to_str().unwrap(),
        "--energies",
        e.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let walls = Histories::read_csv(&w).unwrap();
    assert_eq!(walls.labels(), ["1.fx", "1.fy", "1.fz", "1.f"]);
    let fz = walls.channel_by_label("1.fz").unwrap();
    assert_eq!(fz[0], 0.0);
    assert!(fz.iter().all(|&f| f >= 0.0));
    let parts = Histories::read_csv(&p).unwrap();
    let energies = Histories::read_csv(&e).unwrap();
    let internal = energies.channel_by_label("internal").unwrap();
    let part_internal = parts.channel_by_label("1.internal").unwrap();
    for (a, b) in internal.iter().zip(part_internal) {
        assert!((a - b).abs() <= 1e-9 * a.abs().max(1e-12), "{a} vs {b}");
    }
    let kinetic = energies.channel_by_label("kinetic").unwrap();
    let part_kinetic = parts.channel_by_label("1.kinetic").unwrap();
    // The deck has no concentrated masses, so its one part holds all the kinetic energy.
    for (a, b) in kinetic.iter().zip(part_kinetic) {
        assert!((a - b).abs() <= 1e-9 * a.abs(), "{a} vs {b}");
    }
}

/// A deck with a nodes-to-surface contact: a 2 x 2 plate (part 1) flying at 5 m/s onto a
/// free one (part 2) 1 mm below, written by the keyword writer.
fn plates_in_contact_deck(path: &std::path::Path) {
    use impactcal::shell::{
        Contact, ContactKind, ContactSurface, InitialVelocity, Material, MaterialLaw, Section,
        ShellModel, VelocityTarget, keyword::write_deck_file,
    };
    let mut m = ShellModel::new("plates in contact");
    for (part, z, base) in [(1, 0.003, 0), (2, 0.0, 100)] {
        for j in 0..3u64 {
            for i in 0..3u64 {
                m.add_node(base + 1 + i + 3 * j, [0.01 * i as f64, 0.01 * j as f64, z]);
            }
        }
        for j in 0..2u64 {
            for i in 0..2u64 {
                let n = base + 1 + i + 3 * j;
                m.add_shell(base + 1 + i + 2 * j, part, [n, n + 1, n + 4, n + 3]);
            }
        }
        m.add_part(part, 1, 1);
    }
    m.sections.push(Section::new(1, 0.002));
    m.materials.push(Material {
        id: 1,
        density: 7850.0,
        youngs: 210e9,
        poisson: 0.3,
        law: MaterialLaw::Elastic,
    });
    m.initial_velocities.push(InitialVelocity::translation(
        VelocityTarget::Part(1),
        [0.0, 0.0, -5.0],
    ));
    m.contacts.push(Contact::between(
        ContactKind::NodesToSurface,
        ContactSurface::Part(1),
        ContactSurface::Part(2),
    ));
    m.control.end_time = 4e-4;
    write_deck_file(&m, path).unwrap();
}

/// `--contact-energies` and `--contact-forces`: one column set per interface, the
/// interface's energy at the end equal to the global contact energy (the deck has no wall),
/// the slave side pushed up (+z) and never pulled, the summary naming the interface's
/// energy; a deck without contact asking for them is an input error naming the option.
#[test]
fn simulate_writes_contact_energies_and_forces() {
    let dir = tempfile::tempdir().unwrap();
    let deck = dir.path().join("plates.k");
    plates_in_contact_deck(&deck);
    let (ce, cf, e) = (
        dir.path().join("ce.csv"),
        dir.path().join("cf.csv"),
        dir.path().join("e.csv"),
    );
    let out = impactcal(&[
        "simulate",
        "--deck",
        deck.to_str().unwrap(),
        "--contact-energies",
        ce.to_str().unwrap(),
        "--contact-forces",
        cf.to_str().unwrap(),
        "--energies",
        e.to_str().unwrap(),
    ]);
    let log = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{log}");
    assert!(log.contains("contact energy: interface 1 "), "{log}");
    let energies = Histories::read_csv(&ce).unwrap();
    assert_eq!(energies.labels(), ["1.energy", "1.friction"]);
    let global = Histories::read_csv(&e).unwrap();
    let contact = global.channel_by_label("contact").unwrap();
    let last = energies.samples() - 1;
    assert_eq!(energies.samples(), global.samples());
    let (a, b) = (energies.value(0, last), contact[last]);
    assert!((a - b).abs() <= 1e-12 * b.abs().max(1e-12), "{a} vs {b}");
    let forces = Histories::read_csv(&cf).unwrap();
    assert_eq!(forces.labels(), ["1.fx", "1.fy", "1.fz", "1.fn"]);
    let fz = forces.channel_by_label("1.fz").unwrap();
    assert!(fz.iter().all(|&f| f >= 0.0), "{fz:?}");
    assert!(fz.iter().any(|&f| f > 0.0));

    let out = impactcal(&[
        "simulate",
        "--deck",
        example_file("decks", "strip_drop.k").to_str().unwrap(),
        "--contact-forces",
        cf.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--contact-forces needs a contact interface"),
        "{err}"
    );
}
