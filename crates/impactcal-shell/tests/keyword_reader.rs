//! The keyword reader on decks written the way LS-PrePost writes them: every unsupported
//! keyword in one error, the `_TITLE` / `_ID` variants, `*INCLUDE`, `*PARAMETER`, Fortran
//! exponents, LS-PrePost's `ENDMAS`, Latin-1 files, missing control cards and numbers
//! wider than their field. The truth for the variants is the model of the same deck
//! written with the plain cards.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use std::path::PathBuf;

use impactcal_core::Model;
use impactcal_shell::keyword::{parse_deck, read_deck};
use impactcal_shell::{DeckModel, MaterialLaw, ShellError};

/// A strip of two quads on a wall, in the plain cards, with LS-PrePost's `$#` comments and
/// its `ENDMAS` default (`0.0` and `1.000000E8` touching in columns 31 to 50).
const PLAIN: &str = "\
*KEYWORD
*TITLE
strip
*CONTROL_TERMINATION
$#  endtim    endcyc     dtmin    endeng    endmas     nosol
    0.0010         0       0.0       0.01.000000E8         0
*CONTROL_HOURGLASS
$#     ihq        qh
         4      0.05
*SECTION_SHELL
$#   secid    elform      shrf       nip     propt   qr/irid     icomp     setyp
         1         2  0.833333         5       1.0         0         0         1
$#      t1        t2        t3        t4      nloc     marea      idof    edgset
     0.002     0.002     0.002     0.002       0.0       0.0       0.0         0
*MAT_PLASTIC_KINEMATIC
$#     mid        ro         e        pr      sigy      etan      beta
         1    7850.0  2.100E11       0.3  2.500E+8  1.000E+9       1.0
$#     src       srp        fs        vp
       0.0       0.0       0.0       0.0
*PART
$#                                                                         title
strip
$#     pid     secid       mid     eosid      hgid      grav    adpopt      tmid
         1         1         1         0         0         0         0         0
*DEFINE_CURVE
$#    lcid      sidr       sfa       sfo      offa      offo    dattyp     lcint
         7         0       1.0       1.0       0.0       0.0         0         0
$#                a1                  o1
                 0.0                 1.0
                 1.0                 1.0
*SET_NODE_LIST
$#     sid       da1       da2       da3       da4    solver
         3       0.0       0.0       0.0       0.0MECH
$#    nid1      nid2      nid3      nid4      nid5      nid6      nid7      nid8
         1         4
*BOUNDARY_SPC_NODE
$#     nid       cid      dofx      dofy      dofz     dofrx     dofry     dofrz
         2         0         1         0         0         0         0         0
*INITIAL_VELOCITY
$#    nsid    nsidex     boxid    irigid      icid
         0         0         0         0         0
$#      vx        vy        vz       vxr       vyr       vzr
       0.0       0.0      -5.0       0.0       0.0       0.0
*RIGIDWALL_PLANAR
$#    nsid    nsidex     boxid    offset     birth     death     rwksf
         0         0         0       0.0       0.01.00000E20       1.0
$#      xt        yt        zt        xh        yh        zh      fric      wvel
       0.0       0.0       0.0       0.0       0.0       1.0       0.2       0.0
*DATABASE_HISTORY_NODE
$#     id1       id2       id3       id4       id5       id6       id7       id8
         3         6
*DATABASE_NODOUT
$#      dt    binary      lcur     ioopt
    1.0E-4         0         0         1
*NODE
$#   nid               x               y               z      tc      rc
       1             0.0             0.0           0.005       0       0
       2            0.05             0.0           0.005       0       0
       3             0.1             0.0           0.005       0       0
       4             0.0            0.05           0.005       0       0
       5            0.05            0.05           0.005       0       0
       6             0.1            0.05           0.005       0       0
*ELEMENT_SHELL
$#   eid     pid      n1      n2      n3      n4      n5      n6      n7      n8
       1       1       1       2       5       4       0       0       0       0
       2       1       2       3       6       5       0       0       0       0
*END
";

/// Replaces the first occurrence of `from` (which must occur) in `deck`.
fn edit(deck: &str, from: &str, to: &str) -> String {
    assert!(deck.contains(from), "{from}");
    deck.replacen(from, to, 1)
}

/// A fresh directory under the system's temporary directory.
fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("impactcal-reader-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn the_plain_deck_reads_without_warnings_and_endmas_1e8_is_accepted() {
    let deck = parse_deck(PLAIN, "plain.k").unwrap();
    assert!(deck.warnings.is_empty(), "{:?}", deck.warnings);
    let m = &deck.model;
    assert_eq!(m.control.end_time, 0.001);
    assert_eq!(m.nodes.len(), 6);
    assert_eq!(m.output.history_nodes, vec![3, 6]);
    assert_eq!(m.node_sets[0].nodes, vec![1, 4]);
}

#[test]
fn every_unsupported_keyword_is_listed_in_one_error_with_its_line() {
    let text = edit(
        PLAIN,
        "*PART\n",
        "*CONTACT_ERODING_SINGLE_SURFACE\n         1\n*SECTION_SOLID\n         2\n*PART\n",
    );
    let text = edit(&text, "*END\n", "*MAT_SPOTWELD\n         3\n*END\n");
    match parse_deck(&text, "many.k").unwrap_err() {
        ShellError::UnsupportedKeywords { file, found } => {
            assert_eq!(file, "many.k");
            let got: Vec<(usize, &str)> =
                found.iter().map(|u| (u.line, u.keyword.as_str())).collect();
            let line = |kw: &str| 1 + text.lines().position(|l| l == kw).unwrap();
            assert_eq!(
                got,
                [
                    (
                        line("*CONTACT_ERODING_SINGLE_SURFACE"),
                        "*CONTACT_ERODING_SINGLE_SURFACE"
                    ),
                    (line("*SECTION_SOLID"), "*SECTION_SOLID"),
                    (line("*MAT_SPOTWELD"), "*MAT_SPOTWELD"),
                ]
            );
        }
        e => panic!("{e}"),
    }
}

#[test]
fn title_and_id_variants_give_the_model_of_the_plain_cards() {
    let mut t = PLAIN.to_string();
    for (kw, title) in [
        ("*SECTION_SHELL\n", "*SECTION_SHELL_TITLE\nshell 2 mm\n"),
        (
            "*MAT_PLASTIC_KINEMATIC\n",
            "*MAT_PLASTIC_KINEMATIC_TITLE\nsteel\n",
        ),
        ("*DEFINE_CURVE\n", "*DEFINE_CURVE_TITLE\nconstant\n"),
        ("*SET_NODE_LIST\n", "*SET_NODE_LIST_TITLE\nleft edge\n"),
        (
            "*BOUNDARY_SPC_NODE\n",
            "*BOUNDARY_SPC_NODE_ID\n$#      id                                                               heading\n         1fix x\n",
        ),
        (
            "*RIGIDWALL_PLANAR\n",
            "*RIGIDWALL_PLANAR_ID\n$#    rwid                                                               heading\n         1floor\n",
        ),
    ] {
        t = edit(&t, kw, title);
    }
    t = edit(
        &t,
        "*DATABASE_HISTORY_NODE\n$#     id1       id2       id3       id4       id5       id6       id7       id8\n         3         6\n",
        "*DATABASE_HISTORY_NODE_ID\n$#      id                                                               heading\n         3corner\n         6other corner\n",
    );
    let plain = parse_deck(PLAIN, "plain.k").unwrap();
    let variant = parse_deck(&t, "variants.k").unwrap();
    assert!(variant.warnings.is_empty(), "{:?}", variant.warnings);
    // The wall's _ID card gives it its id.
    let mut want = plain.model.clone();
    want.walls[0].id = 1;
    assert_eq!(variant.model, want);
    // A title card missing: the card that is missing is named.
    let bad = edit(PLAIN, "*SECTION_SHELL\n", "*SECTION_SHELL_TITLE\n");
    match parse_deck(&bad, "bad.k").unwrap_err() {
        ShellError::Keyword {
            keyword, message, ..
        } => {
            assert_eq!(keyword, "*SECTION_SHELL_TITLE");
            assert!(message.contains("expected the thickness card"), "{message}");
        }
        e => panic!("{e}"),
    }
}

#[test]
fn an_spc_id_card_heads_every_node_card_after_it_and_history_ids_take_columns_1_to_10() {
    // LS-DYNA's layout: one id card (the SPC set's id and heading), then as many node
    // cards as necessary. Three constrained nodes under one id read as three plain cards.
    let spc = |header: &str| {
        format!(
            "{header}{}{}{}",
            "         1         0         1         0         0         0         0         0\n",
            "         2         0         1         0         0         0         0         0\n",
            "         3         0         0         0         1         0         0         0\n",
        )
    };
    let plain = edit(
        PLAIN,
        "*BOUNDARY_SPC_NODE\n$#     nid       cid      dofx      dofy      dofz     dofrx     dofry     dofrz\n         2         0         1         0         0         0         0         0\n",
        &spc("*BOUNDARY_SPC_NODE\n"),
    );
    let with_id = edit(
        PLAIN,
        "*BOUNDARY_SPC_NODE\n$#     nid       cid      dofx      dofy      dofz     dofrx     dofry     dofrz\n         2         0         1         0         0         0         0         0\n",
        &spc("*BOUNDARY_SPC_NODE_ID\n        10clamped edge 2\n"),
    );
    let a = parse_deck(&plain, "plain.k").unwrap().model;
    let b = parse_deck(&with_id, "id.k").unwrap().model;
    assert_eq!(a.spcs.len(), 3);
    assert_eq!(b.spcs, a.spcs);
    // History nodes: the id is columns 1-10, the heading (digits and all) the rest; comma
    // separated cards too.
    let history = edit(
        PLAIN,
        "*DATABASE_HISTORY_NODE\n$#     id1       id2       id3       id4       id5       id6       id7       id8\n         3         6\n",
        "*DATABASE_HISTORY_NODE_ID\n         3gauge 12 at 45 deg\n6,other corner\n",
    );
    let h = parse_deck(&history, "h.k").unwrap().model;
    assert_eq!(h.output.history_nodes, [3, 6]);
}

#[test]
fn includes_are_read_relative_to_the_including_file_nested_and_cycles_are_errors() {
    let dir = scratch("include");
    std::fs::create_dir_all(dir.join("mesh")).unwrap();
    let at = PLAIN.find("*NODE\n").unwrap();
    let end = PLAIN.find("*END\n").unwrap();
    let (head, mesh) = (&PLAIN[..at], &PLAIN[at..end]);
    let el = mesh.find("*ELEMENT_SHELL").unwrap();
    // main.k includes mesh/mesh.k, which includes nodes.k beside it (mesh/nodes.k).
    std::fs::write(
        dir.join("main.k"),
        format!("{head}*INCLUDE\nmesh/mesh.k\n*END\n"),
    )
    .unwrap();
    std::fs::write(
        dir.join("mesh/mesh.k"),
        format!("*KEYWORD\n*INCLUDE\nnodes.k\n{}*END\n", &mesh[el..]),
    )
    .unwrap();
    std::fs::write(
        dir.join("mesh/nodes.k"),
        format!("*KEYWORD\n{}*END\n", &mesh[..el]),
    )
    .unwrap();
    let deck = read_deck(dir.join("main.k")).unwrap();
    assert_eq!(deck.model, parse_deck(PLAIN, "plain.k").unwrap().model);

    // An error in an included file names that file and its line.
    std::fs::write(
        dir.join("mesh/nodes.k"),
        format!("*KEYWORD\n{}", &mesh[..el]).replacen("0.005", "0.0x5", 1),
    )
    .unwrap();
    match read_deck(dir.join("main.k")).unwrap_err() {
        ShellError::Keyword { file, line, .. } => {
            assert!(file.ends_with("nodes.k"), "{file}");
            assert_eq!(line, 4);
        }
        e => panic!("{e}"),
    }

    // nodes.k includes ../main.k: a cycle, named from the deck round to itself.
    std::fs::write(
        dir.join("mesh/nodes.k"),
        "*KEYWORD\n*INCLUDE\n../main.k\n*END\n",
    )
    .unwrap();
    let e = read_deck(dir.join("main.k")).unwrap_err().to_string();
    assert!(e.contains("include each other"), "{e}");
    assert!(
        e.contains("main.k -> ") && e.contains("mesh.k -> ") && e.contains("nodes.k -> "),
        "{e}"
    );

    // A missing file: the including file, its line and the path.
    std::fs::write(
        dir.join("mesh/mesh.k"),
        "*KEYWORD\n*INCLUDE\nnone.k\n*END\n",
    )
    .unwrap();
    match read_deck(dir.join("main.k")).unwrap_err() {
        ShellError::Keyword {
            file,
            line,
            message,
            ..
        } => {
            assert!(file.ends_with("mesh.k"), "{file}");
            assert_eq!(line, 3);
            assert!(message.contains("none.k"), "{message}");
        }
        e => panic!("{e}"),
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The plain deck with its thickness, yield stress and impact speed as parameters, in
/// LS-PrePost's layout (10-column name and value pairs, `R` type then the name).
fn parameterised() -> String {
    let pair = |name: &str, value: &str| format!("{name:<10}{value:>10}");
    let cards = format!(
        "*PARAMETER\n$#   prmr1      val1     prmr2      val2     prmr3      val3\n{}{}{}\n{}\n*CONTROL_TERMINATION\n",
        pair("R thick", "0.002"),
        pair("R sigy", "2.500E+8"),
        pair("R speed", "-5.0"),
        pair("I nips", "5"),
    );
    let t = edit(PLAIN, "*CONTROL_TERMINATION\n", &cards);
    let t = edit(
        &t,
        "     0.002     0.002     0.002     0.002",
        "    &thick    &thick    &thick    &thick",
    );
    let t = edit(
        &t,
        "         1         2  0.833333         5",
        "         1         2  0.833333     &nips",
    );
    let t = edit(&t, "  2.500E+8  1.000E+9", "     &sigy  1.000E+9");
    edit(
        &t,
        "       0.0       0.0      -5.0",
        "       0.0       0.0   -&speed",
    )
}

#[test]
fn parameters_and_references_give_the_model_of_the_values_and_become_quantities() {
    let text = parameterised();
    let deck = parse_deck(&text, "param.k").unwrap();
    // -&speed with speed = -5 is +5: flip the plain deck's sign to compare.
    let plain = parse_deck(
        &edit(
            PLAIN,
            "       0.0       0.0      -5.0",
            "       0.0       0.0       5.0",
        ),
        "plain.k",
    )
    .unwrap();
    assert_eq!(deck.model, plain.model);
    let names: Vec<(&str, f64, bool)> = deck
        .parameters
        .iter()
        .map(|p| (p.name.as_str(), p.value, p.integer))
        .collect();
    assert_eq!(
        names,
        [
            ("thick", 0.002, false),
            ("sigy", 2.5e8, false),
            ("speed", -5.0, false),
            ("nips", 5.0, true)
        ]
    );
    // Other values: the deck read again.
    let thin = deck.with_parameters(&[("THICK", 0.0015)]).unwrap();
    assert_eq!(thin.model.sections[0].thickness, 0.0015);
    assert!(deck.with_parameters(&[("nothing", 1.0)]).is_err());

    // The deck model: the real parameters are the quantities, +-20 % about the values.
    let model = DeckModel::from_deck(deck.clone(), None).unwrap();
    assert_eq!(model.space().names(), ["thick", "sigy", "speed"]);
    let p = &model.space().parameters()[2];
    assert_eq!((p.lower, p.upper, p.nominal), (-6.0, -4.0, -5.0));
    let m = model.model_at(&[0.0018, 3.0e8, -4.5]).unwrap();
    assert_eq!(m.sections[0].thickness, 0.0018);
    match m.materials[0].law {
        MaterialLaw::Plastic { yield_stress, .. } => assert_eq!(yield_stress, 3.0e8),
        _ => panic!("plastic material expected"),
    }
    assert_eq!(m.initial_velocities[0].translation[2], 4.5);
}

#[test]
fn an_unknown_reference_names_its_line_and_field() {
    let text = edit(
        &parameterised(),
        "     &sigy  1.000E+9",
        "     &sigx  1.000E+9",
    );
    match parse_deck(&text, "param.k").unwrap_err() {
        ShellError::Keyword {
            line,
            keyword,
            message,
            ..
        } => {
            assert_eq!(keyword, "*MAT_PLASTIC_KINEMATIC");
            assert_eq!(
                line,
                1 + text.lines().position(|l| l.contains("&sigx")).unwrap()
            );
            assert!(
                message.contains("SIGY") && message.contains("&sigx"),
                "{message}"
            );
        }
        e => panic!("{e}"),
    }
}

#[test]
fn fortran_exponents_are_read() {
    let text = edit(PLAIN, "    0.0010         0", " 1.00000-3         0");
    let text = edit(&text, "    7850.0  2.100E11", "   78.5+02  2.100E11");
    let m = parse_deck(&text, "fortran.k").unwrap().model;
    assert_eq!(m.control.end_time, 1.0e-3);
    assert_eq!(m.materials[0].density, 7850.0);
}

#[test]
fn a_latin1_deck_is_read_with_a_warning_naming_the_line() {
    let dir = scratch("latin1");
    let mut bytes = Vec::new();
    let text = edit(
        PLAIN,
        "*TITLE\nstrip\n",
        "*TITLE\nstrip \u{e9}paisseur 2 mm\n",
    );
    for ch in text.chars() {
        bytes.push(u8::try_from(u32::from(ch)).unwrap());
    }
    let path = dir.join("latin1.k");
    std::fs::write(&path, &bytes).unwrap();
    let deck = read_deck(&path).unwrap();
    assert_eq!(deck.model.title, "strip \u{e9}paisseur 2 mm");
    assert_eq!(deck.warnings.len(), 1, "{:?}", deck.warnings);
    assert!(
        deck.warnings[0].contains("line 3") && deck.warnings[0].contains("Latin-1"),
        "{}",
        deck.warnings[0]
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn missing_termination_and_hourglass_cards_are_warned_with_the_defaults() {
    let text = edit(
        PLAIN,
        "*CONTROL_TERMINATION\n$#  endtim    endcyc     dtmin    endeng    endmas     nosol\n    0.0010         0       0.0       0.01.000000E8         0\n",
        "",
    );
    let text = edit(
        &text,
        "*CONTROL_HOURGLASS\n$#     ihq        qh\n         4      0.05\n",
        "",
    );
    let deck = parse_deck(&text, "bare.k").unwrap();
    assert_eq!(deck.warnings.len(), 2, "{:?}", deck.warnings);
    assert!(deck.warnings[0].contains("no *CONTROL_TERMINATION"));
    assert!(deck.warnings[0].contains(&format!("{:e}", deck.model.control.end_time)));
    assert!(deck.warnings[1].contains("no *CONTROL_HOURGLASS"));
}

#[test]
fn a_number_wider_than_its_field_is_warned_with_the_fields_as_read() {
    let text = edit(
        PLAIN,
        "    0.0010         0       0.0       0.01.000000E8         0",
        "0.00016099689437998487",
    );
    let deck = parse_deck(&text, "wide.k").unwrap();
    let line = 1 + text
        .lines()
        .position(|l| l == "0.00016099689437998487")
        .unwrap();
    assert_eq!(deck.warnings.len(), 1, "{:?}", deck.warnings);
    let w = &deck.warnings[0];
    assert!(w.contains(&format!("line {line}")), "{w}");
    assert!(
        w.contains("`0.00016099`, `6894379984`, `87`"),
        "the fields as read: {w}"
    );
    // LS-PrePost's touching ENDENG / ENDMAS pair (0.0 then 1.000000E8) is not such a case.
    assert!(parse_deck(PLAIN, "plain.k").unwrap().warnings.is_empty());
}

#[test]
fn a_parameterised_deck_holds_the_parameters_it_does_not_declare() {
    use impactcal_core::enrich::Enrichable;
    use impactcal_core::{Parameter, ParameterSpace};
    let deck = parse_deck(&parameterised(), "param.k").unwrap();
    let bounds = ParameterSpace::new(vec![
        Parameter::new("THICK", 0.0018, 0.0022, 0.002).unwrap(),
    ])
    .unwrap();
    let model = DeckModel::from_deck(deck, Some(&bounds)).unwrap();
    let c = model.candidates();
    let names: Vec<(&str, &str, f64)> = c
        .iter()
        .map(|c| (c.name(), c.group.as_str(), c.parameter.nominal))
        .collect();
    assert_eq!(
        names,
        [("sigy", "parameter", 2.5e8), ("speed", "parameter", -5.0)]
    );
    assert_eq!((c[1].parameter.lower, c[1].parameter.upper), (-6.0, -4.0));
    // Freed at the held value: the same run; at another speed: the deck read with it.
    let enriched = model.enrich(&[c[0].parameter.clone()]).unwrap();
    assert_eq!(enriched.space().names(), ["THICK", "sigy"]);
    let a = model.simulate(&[0.002]).unwrap();
    let b = enriched.simulate(&[0.002, 2.5e8]).unwrap();
    assert!(
        a.data()
            .iter()
            .zip(b.data())
            .all(|(x, y)| x.to_bits() == y.to_bits())
    );
    let slow = enriched.at_condition(&[("speed".into(), -4.5)]).unwrap();
    let m = slow.model_at(&[0.002, 2.5e8]).unwrap();
    assert_eq!(m.initial_velocities[0].translation[2], 4.5);
    assert_eq!(slow.candidates()[0].parameter.nominal, -4.5);
    assert!(slow.at_condition(&[("sigy".into(), 3e8)]).is_err());
    assert!(slow.at_condition(&[("speed".into(), -7.0)]).is_err());
    assert!(slow.at_condition(&[("nips".into(), 3.0)]).is_err());
}
