//! The lumped system file: reading it, and the typed error of each malformed case a user
//! would produce, naming the file, the key and what is wrong.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use impactcal_models::ModelsError;
use impactcal_models::lumped::{GapSides, LumpedSystem, Node};

const FILE: &str = r#"
[base]
channel = "accel bottom"
unit = 9806.65

[masses]
board = 0.05
shell = 0.2

[springs.mount]
between = ["base", "shell"]
stiffness = 2.0e7
damping_ratio = 0.02

[springs.stand]
between = ["shell", "board"]
stiffness = 5.0e6
range = [1.0e6, 2.0e7]
damping_range = [0.0, 0.3]

[dashpots.potting]
between = ["shell", "board"]
coefficient = 3.0

[gaps.stop]
between = ["shell", "board"]
gap = 1.0e-4
stiffness = 1.0e8
sides = "closing"

[outputs]
"accel 1" = "board"
"accel top" = "shell"
"#;

fn parse(text: &str) -> Result<LumpedSystem, ModelsError> {
    LumpedSystem::parse(text, "unit.toml")
}

#[test]
fn the_file_reads_with_its_defaults() {
    let s = parse(FILE).unwrap();
    assert_eq!(s.base_channel, "accel bottom");
    assert_eq!(s.unit, 9806.65);
    assert_eq!(
        s.masses,
        vec![("board".into(), 0.05), ("shell".into(), 0.2)]
    );
    assert_eq!(s.springs.len(), 2);
    let mount = &s.springs[0];
    assert_eq!(mount.name, "mount");
    assert_eq!(mount.between, [Node::Base, Node::Mass(1)]);
    assert_eq!(mount.range, [5.0e6, 8.0e7]);
    assert_eq!(mount.damping_ratio, 0.02);
    assert_eq!(mount.damping_range, [0.0, 0.5]);
    assert_eq!(s.springs[1].range, [1.0e6, 2.0e7]);
    assert_eq!(s.springs[1].damping_ratio, 0.0);
    assert_eq!(s.dashpots[0].coefficient, 3.0);
    assert_eq!(s.gaps[0].sides, GapSides::Closing);
    assert_eq!(s.outputs[0].channel, "accel 1");
    assert_eq!(s.outputs[0].mass, 0);
    assert_eq!(s.outputs[1].mass, 1);
}

/// `(what the user did, the edit, the key the error must name, a phrase of its message)`.
#[test]
fn each_malformed_file_names_its_file_key_and_fault() {
    let cases: [(&str, &str, &str, &str, &str); 16] = [
        (
            "unknown mass in a spring",
            "between = [\"shell\", \"board\"]\nstiffness = 5.0e6",
            "between = [\"shell\", \"bord\"]\nstiffness = 5.0e6",
            "springs.stand.between",
            "`bord` names no mass",
        ),
        (
            "negative mass",
            "board = 0.05",
            "board = -0.05",
            "masses.board",
            "must be positive",
        ),
        (
            "zero mass",
            "board = 0.05",
            "board = 0",
            "masses.board",
            "must be positive",
        ),
        (
            "a spring from a mass to itself",
            "between = [\"shell\", \"board\"]\nstiffness = 5.0e6",
            "between = [\"board\", \"board\"]\nstiffness = 5.0e6",
            "springs.stand.between",
            "to itself",
        ),
        (
            "a spring from the base to the base",
            "between = [\"base\", \"shell\"]",
            "between = [\"base\", \"base\"]",
            "springs.mount.between",
            "to itself",
        ),
        (
            "an output naming no mass",
            "\"accel 1\" = \"board\"",
            "\"accel 1\" = \"boards\"",
            "outputs.\"accel 1\"",
            "names no mass",
        ),
        (
            "an output naming the base",
            "\"accel 1\" = \"board\"",
            "\"accel 1\" = \"base\"",
            "outputs.\"accel 1\"",
            "names no mass",
        ),
        (
            "a spring named like a mass",
            "[springs.stand]",
            "[springs.board]",
            "springs.board",
            "already used in [masses]",
        ),
        (
            "a gap named like a dashpot",
            "[gaps.stop]",
            "[gaps.potting]",
            "gaps.potting",
            "already used in [dashpots]",
        ),
        (
            "a mass named base",
            "shell = 0.2",
            "shell = 0.2\nbase = 1.0",
            "masses.base",
            "moving base",
        ),
        (
            "an unknown side of a gap",
            "sides = \"closing\"",
            "sides = \"shut\"",
            "gaps.stop.sides",
            "unknown `shut`",
        ),
        (
            "a misspelt key",
            "damping_ratio = 0.02",
            "damping_raito = 0.02",
            "springs.mount.damping_raito",
            "unknown key",
        ),
        (
            "a range that leaves out the nominal",
            "range = [1.0e6, 2.0e7]",
            "range = [1.0e7, 2.0e7]",
            "springs.stand.range",
            "hold the nominal 5000000",
        ),
        (
            "a negative gap",
            "gap = 1.0e-4",
            "gap = -1.0e-4",
            "gaps.stop.gap",
            "must not be negative",
        ),
        (
            "a stiffness given as text",
            "stiffness = 2.0e7",
            "stiffness = \"2e7\"",
            "springs.mount.stiffness",
            "must be a number, found string",
        ),
        (
            "no base channel",
            "channel = \"accel bottom\"",
            "",
            "base.channel",
            "missing",
        ),
    ];
    for (what, from, to, key, phrase) in cases {
        assert!(FILE.contains(from), "{what}: the edit does not apply");
        let text = FILE.replacen(from, to, 1);
        let e = parse(&text).expect_err(what);
        match &e {
            ModelsError::Key {
                file,
                key: k,
                message,
            } => {
                assert_eq!(file, "unit.toml", "{what}");
                assert_eq!(k, key, "{what}: {e}");
                assert!(message.contains(phrase), "{what}: {e}");
            }
            other => panic!("{what}: expected a key error, got {other}"),
        }
    }
}

#[test]
fn structural_faults_are_refused() {
    // A mass tied to the rest by a dashpot only: nothing holds it.
    let untied = FILE.replace(
        "[springs.stand]\nbetween = [\"shell\", \"board\"]\nstiffness = 5.0e6\nrange = [1.0e6, 2.0e7]\ndamping_range = [0.0, 0.3]\n",
        "",
    );
    assert_ne!(untied, FILE);
    let e = parse(&untied).unwrap_err();
    assert!(
        matches!(&e, ModelsError::Key { key, .. } if key == "masses.board"),
        "{e}"
    );
    assert!(e.to_string().contains("no path of springs"), "{e}");
    // A spring named twice: the TOML parser refuses it, with the line.
    let twice = FILE.replace("[dashpots.potting]", "[springs.mount]");
    let e = parse(&twice).unwrap_err();
    assert!(matches!(e, ModelsError::Toml { .. }), "{e}");
    assert!(e.to_string().contains("unit.toml"), "{e}");
    // Two springs between the same pair of masses are not a fault.
    let mut pair = FILE.to_string();
    pair.push_str("[springs.second]\nbetween = [\"board\", \"shell\"]\nstiffness = 1.0e6\n");
    assert_eq!(parse(&pair).unwrap().springs.len(), 3);
    // No outputs, no masses.
    let e =
        parse(&FILE.replace("\"accel 1\" = \"board\"\n\"accel top\" = \"shell\"", "")).unwrap_err();
    assert!(e.to_string().contains("no output"), "{e}");
    // An unreadable file names its path.
    let e = LumpedSystem::read("/nonexistent/unit.toml").unwrap_err();
    assert!(matches!(e, ModelsError::Io { .. }) && e.to_string().contains("/nonexistent"));
}
