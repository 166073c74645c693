//! The keywords and deck forms added for real decks, each against its truth: an equivalent
//! deck in the forms read before (same model or bit-identical results), a closed form, or
//! an invariant.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use std::path::PathBuf;

use impactcal_shell::keyword::{parse_deck, read_deck};
use impactcal_shell::{Hardening, MaterialLaw, ShellError, Simulation};

/// A 4 x 1 strip of quads (two parts: elements 1-2 in part 1, 3-4 in part 2), dropped on a
/// floor; `$PARTS` stands for the part cards, `$EXTRA` for extra keywords.
fn strip(parts: &str, extra: &str) -> String {
    let mut s = String::from(
        "*KEYWORD\n*TITLE\nstrip\n*CONTROL_TERMINATION\n    5.0e-4\n*CONTROL_HOURGLASS\n         4      0.05\n",
    );
    s += "*SECTION_SHELL\n         1         2  0.833333         5\n     0.002\n";
    s += "*MAT_PLASTIC_KINEMATIC\n         1    7850.0  2.100E11       0.3  2.500E+7  1.000E+9       1.0\n       0.0       0.0\n";
    s += parts;
    s += "*NODE\n";
    for j in 0..2 {
        for i in 0..5 {
            s += &format!(
                "{:8}{:16.6}{:16.6}{:16.6}\n",
                1 + i + 5 * j,
                0.05 * i as f64,
                0.05 * j as f64,
                0.005 + 0.002 * i as f64
            );
        }
    }
    s += "*ELEMENT_SHELL\n";
    for i in 0..4 {
        let n = 1 + i;
        s += &format!(
            "{:8}{:8}{:8}{:8}{:8}{:8}\n",
            1 + i,
            1 + i / 2,
            n,
            n + 1,
            n + 6,
            n + 5
        );
    }
    s += "*INITIAL_VELOCITY\n         0\n       1.0       0.0     -40.0       0.0     200.0\n";
    s += "*RIGIDWALL_PLANAR\n         0\n       0.0       0.0       0.0       0.0       0.0       1.0       0.2\n";
    s += "*DATABASE_HISTORY_NODE\n         3         8\n*DATABASE_NODOUT\n    2.0E-5\n";
    s += extra;
    s += "*END\n";
    s
}

const TWO_PARTS: &str =
    "*PART\nleft\n         1         1         1\n*PART\nright\n         2         1         1\n";

fn velocity_bits(text: &str) -> Vec<u64> {
    let deck = parse_deck(text, "t.k").unwrap();
    let r = Simulation::new(&deck.model).unwrap().run().unwrap();
    let v = r.velocity.unwrap();
    (0..v.channels())
        .flat_map(|c| v.channel(c).to_vec())
        .map(f64::to_bits)
        .collect()
}

fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("impactcal-kwf-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn every_file_an_include_names_is_read() {
    let dir = scratch("include");
    let whole = strip(TWO_PARTS, "");
    let (model_part, wall_part) = {
        let at = whole.find("*RIGIDWALL_PLANAR").unwrap();
        let end = whole.find("*DATABASE_HISTORY_NODE").unwrap();
        (
            format!("{}{}", &whole[..at], &whole[end..]),
            format!("*KEYWORD\n{}*END\n", &whole[at..end]),
        )
    };
    std::fs::write(dir.join("model_no_wall.k"), &model_part).unwrap();
    std::fs::write(dir.join("wall.k"), &wall_part).unwrap();
    // One *INCLUDE naming two files, as LS-PrePost writes it, with a long name continued.
    std::fs::create_dir_all(dir.join("parts")).unwrap();
    std::fs::write(dir.join("parts/wall.k"), &wall_part).unwrap();
    std::fs::write(
        dir.join("main.k"),
        "*KEYWORD\n*INCLUDE\nmodel_no_wall.k\n$ the wall\nwall.k\n*END\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("two.k"),
        "*KEYWORD\n*INCLUDE\nmodel_no_wall.k\n*INCLUDE\nwall.k\n*END\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("path.k"),
        "*KEYWORD\n*INCLUDE_PATH\nparts\n*INCLUDE\nmodel_no_wall.k\nwa +\nll.k\n*END\n",
    )
    .unwrap();
    let one = read_deck(dir.join("main.k")).unwrap();
    let two = read_deck(dir.join("two.k")).unwrap();
    assert_eq!(one.model.walls.len(), 1);
    assert_eq!(one.model, two.model);
    let whole = parse_deck(&whole, "whole.k").unwrap();
    assert_eq!(one.model, whole.model);
    assert_eq!(one.cards, whole.cards);
    // A name continued with ` +`, found through *INCLUDE_PATH when not beside the deck.
    std::fs::remove_file(dir.join("wall.k")).unwrap();
    let via = read_deck(dir.join("path.k")).unwrap();
    assert_eq!(via.model, whole.model);
    // A missing file is named with the directories searched.
    match read_deck(dir.join("main.k")).unwrap_err() {
        ShellError::Keyword { line, message, .. } => {
            assert_eq!(line, 5);
            assert!(message.contains("wall.k"), "{message}");
        }
        e => panic!("{e}"),
    }
}

#[test]
fn a_card_the_keyword_does_not_take_is_an_error_naming_its_line() {
    // A second file name under *INCLUDE with the keyword line lost: the name is a stray
    // card of the keyword above it.
    let text = strip(TWO_PARTS, "").replace(
        "*DATABASE_NODOUT\n    2.0E-5\n",
        "*DATABASE_NODOUT\n    2.0E-5\nwall.k\n",
    );
    match parse_deck(&text, "stray.k").unwrap_err() {
        ShellError::Keyword {
            keyword,
            line,
            message,
            ..
        } => {
            assert_eq!(keyword, "*DATABASE_NODOUT");
            assert_eq!(line, 1 + text.lines().position(|l| l == "wall.k").unwrap());
            assert!(message.contains("does not take"), "{message}");
        }
        e => panic!("{e}"),
    }
}

/// The same deck in the long format: every field 20 columns (or its standard width when
/// wider).
fn long_form(text: &str, plus: bool) -> String {
    let widths = |kw: &str| -> Vec<usize> {
        match kw {
            "*NODE" => vec![8, 16, 16, 16, 8, 8],
            "*ELEMENT_SHELL" => vec![8],
            "*TITLE" => vec![80],
            _ => vec![10],
        }
    };
    let mut out = String::new();
    let mut kw = String::new();
    for line in text.lines() {
        if line.starts_with('*') {
            kw = line.to_string();
            if plus && kw != "*KEYWORD" && kw != "*END" {
                out += &format!("{line}+\n");
            } else if !plus && kw == "*KEYWORD" {
                out += "*KEYWORD LONG=Y\n";
            } else {
                out += &format!("{line}\n");
            }
            continue;
        }
        let w = widths(&kw);
        let mut pos = 0;
        let mut k = 0;
        let mut fields = Vec::new();
        while pos < line.len() {
            let width = w[k.min(w.len() - 1)];
            let end = (pos + width).min(line.len());
            fields.push(line[pos..end].trim().to_string());
            pos = end;
            k += 1;
        }
        let wide: String = fields
            .iter()
            .enumerate()
            .map(|(k, f)| {
                let width = w[k.min(w.len() - 1)].max(20);
                format!("{f:>width$}")
            })
            .collect();
        out += &format!("{wide}\n");
    }
    out
}

#[test]
fn long_format_decks_read_as_the_standard_ones() {
    let text = strip(TWO_PARTS, "");
    let plain = parse_deck(&text, "plain.k").unwrap();
    for plus in [false, true] {
        let long = long_form(&text, plus);
        let deck = parse_deck(&long, "long.k").unwrap();
        assert_eq!(deck.model, plain.model, "plus suffix: {plus}");
    }
    // Read as standard, the long cards misread: ENDTIM and the end cycles.
    let long = long_form(&text, true).replace("*CONTROL_TERMINATION+", "*CONTROL_TERMINATION");
    let deck = parse_deck(&long, "wrong.k");
    assert!(deck.map(|d| d.model != plain.model).unwrap_or(true));
    // Ten-digit ids.
    let i10 = text
        .replace("*KEYWORD", "*KEYWORD I10=Y")
        .lines()
        .map(|l| l.to_string())
        .collect::<Vec<_>>();
    let mut kw = "";
    let mut widened = String::new();
    for l in &i10 {
        if l.starts_with('*') {
            kw = l;
            widened += &format!("{l}\n");
        } else if kw == "*NODE" {
            widened += &format!("{:>10}{}\n", l[..8].trim(), &l[8..]);
        } else if kw == "*ELEMENT_SHELL" {
            let f: Vec<&str> = l.split_whitespace().collect();
            widened += &f.iter().map(|x| format!("{x:>10}")).collect::<String>();
            widened += "\n";
        } else {
            widened += &format!("{l}\n");
        }
    }
    assert_eq!(parse_deck(&widened, "i10.k").unwrap().model, plain.model);
}

#[test]
fn per_part_hourglass_definitions_are_honoured() {
    // Both parts through HGID 5 = the model-wide control with the same values, bit for bit.
    let hg = "*HOURGLASS\n         5         4      0.07\n";
    let parts_hg = "*PART\nleft\n         1         1         1         0         5\n*PART\nright\n         2         1         1         0         5\n";
    let control = strip(TWO_PARTS, "").replace(
        "*CONTROL_HOURGLASS\n         4      0.05\n",
        "*CONTROL_HOURGLASS\n         4      0.07\n",
    );
    let by_part = strip(parts_hg, hg).replace(
        "*CONTROL_HOURGLASS\n         4      0.05\n",
        "*CONTROL_HOURGLASS\n         1      0.15\n",
    );
    assert_eq!(velocity_bits(&control), velocity_bits(&by_part));
    // QB and QW: the bending and warping coefficients default to QM.
    let deck = parse_deck(
        &strip(
            parts_hg,
            "*HOURGLASS\n         5         4      0.07         0       0.0       0.0      0.03\n",
        ),
        "qb.k",
    )
    .unwrap();
    let h = deck.model.hourglass_defs[0].hourglass;
    assert_eq!((h.membrane, h.rotation, h.transverse), (0.07, 0.03, 0.07));
    // One part on its own control: the results differ from both.
    let one = strip(
        "*PART\nleft\n         1         1         1         0         5\n*PART\nright\n         2         1         1\n",
        hg,
    );
    let b = velocity_bits(&one);
    assert_ne!(b, velocity_bits(&control));
    // An undefined HGID is named.
    let bad = strip(
        "*PART\nleft\n         1         1         1         0         9\n*PART\nright\n         2         1         1\n",
        "",
    );
    let model = parse_deck(&bad, "bad.k").unwrap().model;
    match Simulation::new(&model).err().unwrap() {
        ShellError::Reference { what, id, .. } => {
            assert_eq!((what, id), ("hourglass definition", 9))
        }
        e => panic!("{e}"),
    }
}

#[test]
fn element_thickness_replaces_the_section_thickness() {
    // Every shell 3 mm by *ELEMENT_SHELL_THICKNESS = a 3 mm section, bit for bit.
    let three = strip(TWO_PARTS, "").replace("\n     0.002\n", "\n     0.003\n");
    let mut cards = String::from("*ELEMENT_SHELL_THICKNESS\n");
    let base = strip(TWO_PARTS, "");
    let shells: Vec<&str> = base
        .split("*ELEMENT_SHELL\n")
        .nth(1)
        .unwrap()
        .lines()
        .take(4)
        .collect();
    for l in &shells {
        cards += &format!(
            "{l}\n{:>16}{:>16}{:>16}{:>16}\n",
            "0.003", "0.003", "0.003", "0.003"
        );
    }
    let own = base.replace(&format!("*ELEMENT_SHELL\n{}\n", shells.join("\n")), &cards);
    assert_eq!(velocity_bits(&three), velocity_bits(&own));
    // Two shells thicker: the mass is rho sum t_e A_e.
    let mut half = String::from("*ELEMENT_SHELL\n");
    half += &format!("{}\n{}\n*ELEMENT_SHELL_THICKNESS\n", shells[0], shells[1]);
    for l in &shells[2..] {
        half += &format!(
            "{l}\n{:>16}{:>16}{:>16}{:>16}\n",
            "0.004", "0.0", "0.004", "0.004"
        );
    }
    let text = base.replace(&format!("*ELEMENT_SHELL\n{}\n", shells.join("\n")), &half);
    let deck = parse_deck(&text, "half.k").unwrap();
    // A zero nodal thickness is the section's, and unequal values are warned.
    assert!(
        deck.warnings
            .iter()
            .any(|w| w.contains("unequal nodal thicknesses"))
    );
    let sim = Simulation::new(&deck.model).unwrap();
    let total: f64 = sim.masses().iter().sum();
    // Areas of the warped strip elements from the model's own geometry.
    let area = |e: usize| {
        let s = deck.model.shells[e];
        let x = |n: u64| deck.model.nodes.iter().find(|p| p.id == n).unwrap().x;
        let (a, b, c, d) = (x(s.nodes[0]), x(s.nodes[1]), x(s.nodes[2]), x(s.nodes[3]));
        let d1 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let d2 = [d[0] - b[0], d[1] - b[1], d[2] - b[2]];
        let cr = [
            d1[1] * d2[2] - d1[2] * d2[1],
            d1[2] * d2[0] - d1[0] * d2[2],
            d1[0] * d2[1] - d1[1] * d2[0],
        ];
        0.5 * (cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]).sqrt()
    };
    let t_mean = (0.004 + 0.002 + 0.004 + 0.004) / 4.0;
    let want = 7850.0 * (0.002 * (area(0) + area(1)) + t_mean * (area(2) + area(3)));
    assert!((total - want).abs() < 1e-9 * want, "{total} vs {want}");
}

#[test]
fn part_sets_list_and_generate_the_same_parts() {
    let gen_v = |set: &str| {
        strip(
            TWO_PARTS,
            &format!(
                "{set}*INITIAL_VELOCITY_GENERATION\n         7         1       0.0       0.0       0.0      -3.0\n       0.0       0.0       0.0       0.0       0.0       1.0\n"
            ),
        )
    };
    let list = gen_v("*SET_PART_LIST\n         7\n         1         2\n");
    let generate = gen_v("*SET_PART_LIST_GENERATE_TITLE\nboth\n         7\n         1         2\n");
    let by_part = strip(
        TWO_PARTS,
        "*INITIAL_VELOCITY_GENERATION\n         1         2       0.0       0.0       0.0      -3.0\n       0.0       0.0       0.0       0.0       0.0       1.0\n         2         2       0.0       0.0       0.0      -3.0\n       0.0       0.0       0.0       0.0       0.0       1.0\n",
    );
    let a = parse_deck(&list, "a.k").unwrap();
    let b = parse_deck(&generate, "b.k").unwrap();
    assert_eq!(a.model.part_sets, b.model.part_sets);
    assert_eq!(a.model.part_sets[0].parts, [1, 2]);
    assert_eq!(velocity_bits(&list), velocity_bits(&by_part));
    assert_eq!(velocity_bits(&generate), velocity_bits(&by_part));
}

#[test]
fn parameter_expressions_follow_the_parameters_before_them() {
    let text = strip(TWO_PARTS, "").replace(
        "*SECTION_SHELL\n         1         2  0.833333         5\n     0.002\n",
        "*PARAMETER\nR thk     0.001\n*PARAMETER_EXPRESSION\nR t2      2*thk\nR t3      max(&t2, 0.0015) + 0*sin(thk)\n*SECTION_SHELL\n         1         2  0.833333         5\n&t3\n",
    );
    let deck = parse_deck(&text, "expr.k").unwrap();
    assert_eq!(deck.model.sections[0].thickness, 0.002);
    let names: Vec<(&str, Option<&str>)> = deck
        .parameters
        .iter()
        .map(|p| (p.name.as_str(), p.expression.as_deref()))
        .collect();
    assert_eq!(
        names,
        [
            ("thk", None),
            ("t2", Some("2*thk")),
            ("t3", Some("max(&t2, 0.0015) + 0*sin(thk)"))
        ]
    );
    let again = deck.with_parameters(&[("thk", 0.0004)]).unwrap();
    assert_eq!(again.model.sections[0].thickness, 0.0015);
    // An expression over a parameter defined later is an error naming it.
    let bad = text.replace("R t2      2*thk", "R t2      2*t3");
    match parse_deck(&bad, "bad.k").unwrap_err() {
        ShellError::Keyword { message, .. } => {
            assert!(
                message.contains("`t3` is no parameter defined before"),
                "{message}"
            )
        }
        e => panic!("{e}"),
    }
}

#[test]
fn piecewise_plasticity_follows_its_curve_and_matches_the_bilinear_material() {
    // SIGY/ETAN without a curve is the bilinear law of *MAT_003 (BETA 1), bit for bit.
    let mat3 = "*MAT_PLASTIC_KINEMATIC\n         1    7850.0  2.100E11       0.3  2.500E+7  1.000E+9       1.0\n       0.0       0.0\n";
    let mat24 = "*MAT_PIECEWISE_LINEAR_PLASTICITY\n         1    7850.0  2.100E11       0.3  2.500E+7  1.000E+9\n       0.0       0.0\n";
    let base = strip(TWO_PARTS, "");
    assert_eq!(
        velocity_bits(&base),
        velocity_bits(&base.replace(mat3, mat24))
    );
    // The same hardening as an LCSS curve and as EPS/ES points: the same model results,
    // and every yielded point on the curve sigma_y = 2.5e7 + 1.225e9 p.
    let lcss = base.replace(
        mat3,
        "*MAT_PIECEWISE_LINEAR_PLASTICITY\n         1    7850.0  2.100E11       0.3\n       0.0       0.0        12\n*DEFINE_CURVE\n        12\n                 0.0              2.5e+7\n                 1.0             1.25e+9\n",
    );
    let points = base.replace(
        mat3,
        "*MAT_PIECEWISE_LINEAR_PLASTICITY\n         1    7850.0  2.100E11       0.3\n       0.0       0.0\n       0.0       1.0\n    2.5e+7   1.25e+9\n",
    );
    let d = parse_deck(&lcss, "lcss.k").unwrap();
    assert!(matches!(
        d.model.materials[0].law,
        MaterialLaw::PlasticCurve {
            hardening: Hardening::Curve(12),
            ..
        }
    ));
    assert_eq!(velocity_bits(&lcss), velocity_bits(&points));
    let mut sim = Simulation::new(&d.model).unwrap();
    sim.run().unwrap();
    let mut yielded = 0;
    for e in 0..4 {
        for k in 0..5 {
            let [sx, sy, txy, p] = sim.point_state(e, k).unwrap();
            let vm = (sx * sx + sy * sy - sx * sy + 3.0 * txy * txy).sqrt();
            let y = 2.5e7 + 1.225e9 * p;
            assert!(
                vm <= y * (1.0 + 1e-9),
                "element {e} point {k}: {vm} above {y}"
            );
            if p > 0.0 {
                yielded += 1;
            }
        }
    }
    assert!(yielded > 0);
    // A softening curve is refused with the material named.
    let soft = lcss.replace("1.25e+9\n", "1.0e+6\n");
    let model = parse_deck(&soft, "soft.k").unwrap().model;
    let e = Simulation::new(&model).err().unwrap().to_string();
    assert!(
        e.contains("material 1, hardening") && e.contains("softening"),
        "{e}"
    );
}

#[test]
fn sensors_and_output_keywords_are_skipped_with_a_warning() {
    let text = strip(
        TWO_PARTS,
        "*SENSOR_DEFINE_FORCE\n         1RWALL              2X                  0\n*DATABASE_RBDOUT\n   1.0e-5\n*DATABASE_BINARY_RUNRSF\n      1000\n",
    );
    let deck = parse_deck(&text, "s.k").unwrap();
    for kw in [
        "*SENSOR_DEFINE_FORCE",
        "*DATABASE_RBDOUT",
        "*DATABASE_BINARY_RUNRSF",
    ] {
        assert!(
            deck.warnings
                .iter()
                .any(|w| w.contains(kw) && w.contains("ignored")),
            "{kw}: {:?}",
            deck.warnings
        );
    }
}

#[test]
fn a_deck_with_the_new_keywords_is_written_and_read_back_the_same() {
    use impactcal_shell::keyword::write_deck;
    let extra = "\
*HOURGLASS
         5         4      0.07         0       0.0       0.0      0.03      0.06
*SET_PART_LIST
         7
         1         2
*INITIAL_VELOCITY_GENERATION
         7         1       0.0       0.0       0.0      -3.0
       0.0       0.0       0.0       0.0       0.0       1.0
*MAT_RIGID
         9    7850.0   2.1e+11       0.3
       1.0         7         0
*MAT_PIECEWISE_LINEAR_PLASTICITY
         8    7850.0   2.1e+11       0.3
       0.0       0.0
       0.0       0.1       0.5
     2.5e7     3.0e7     4.0e7
*RIGIDWALL_GEOMETRIC_CYLINDER_ID
        12
         0
       0.0      -1.0      -0.2       0.0       1.0      -0.2       0.1
      0.15       0.0
*CONSTRAINED_SPOTWELD
         1         2
*DEFINE_CURVE
         3
                 0.0                 0.0
                 1.0                 1.0
*BOUNDARY_PRESCRIBED_MOTION_NODE
         4         3         0         3      -2.0
*ELEMENT_SHELL_THICKNESS
      11       1       6       7      12      11
           0.003           0.003           0.003           0.003
";
    let parts = "*PART\nleft\n         1         1         1         0         5\n*PART\nright\n         2         1         1\n";
    let text = strip(parts, extra);
    let deck = parse_deck(&text, "new.k").unwrap();
    assert!(!deck.model.spot_welds.is_empty() && !deck.model.prescribed.is_empty());
    let written = write_deck(&deck.model).unwrap();
    let back = parse_deck(&written, "written.k").unwrap();
    assert_eq!(back.model, deck.model);
    assert_eq!(write_deck(&back.model).unwrap(), written);
}
