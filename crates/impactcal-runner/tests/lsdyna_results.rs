//! LS-DYNA's result files as written by LS-DYNA itself (`tests/data/lsdyna`, see its
//! README for sources and licences): `binout` files of R7.1.2, R9.3.1 and R12.2.1 and ASCII
//! `nodout` files. The values are checked against LS-DYNA's own printed summary (`d3hsp`)
//! and against the layout of the files; the independent reading by lasso-python is
//! compared in `benches/peers/binout_lasso.sh` (docs/validation.md).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use std::path::PathBuf;

use impactcal_core::NodalQuantity;
use impactcal_runner::{Binout, OutputFormat, OutputSpec, read_nodout};

fn data(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/lsdyna")
        .join(p)
}

#[test]
fn binouts_of_three_ls_dyna_versions_read_with_their_branches() {
    for v in ["R7_1_2", "R9_3_1", "R12_2_1"] {
        let b = Binout::open(&data(&format!("binout/{v}/binout"))).unwrap();
        assert_eq!(
            b.branches(),
            [
                "glstat",
                "matsum",
                "rcforc",
                "rwforc/forces",
                "rwforc/transducer"
            ],
            "{v}"
        );
        let g = b.branch("glstat", &[]).unwrap();
        assert_eq!(g.times.len(), 88, "{v}");
        assert_eq!(g.times[0], 0.0);
        // Every channel finite; times increasing.
        assert!(g.times.windows(2).all(|w| w[1] > w[0]));
        assert!(g.columns.iter().flatten().all(|x| x.is_finite()));
        let m = b.branch("matsum", &["internal_energy".into()]).unwrap();
        assert_eq!(m.labels.len(), 2, "{v}: {:?}", m.labels);
        let w = b.branch("rwforc/forces", &[]).unwrap();
        assert!(
            w.labels.iter().all(|l| l.starts_with("1.")),
            "{:?}",
            w.labels
        );
        // The empty contact branch says it has no output time.
        let e = b.histories("rcforc", &[]).unwrap_err().to_string();
        assert!(
            e.contains("no output time") || e.contains("at least two"),
            "{e}"
        );
    }
}

#[test]
fn the_last_glstat_state_is_the_one_ls_dyna_printed() {
    let b = Binout::open(&data("binout/R12_2_1/binout")).unwrap();
    let g = b
        .branch("glstat", &["cycle".into(), "time_step".into()])
        .unwrap();
    // d3hsp prints the time of cycle 512 (a d3plot state): "512 t 2.7961E-02 dt 5.47E-05";
    // glstat has a state at that cycle too.
    let d3hsp = std::fs::read_to_string(data("binout/R12_2_1/d3hsp")).unwrap();
    assert!(d3hsp.contains("     512 t 2.7961E-02 dt 5.47E-05 write d3plot file"));
    assert_eq!(g.labels, ["cycle", "time_step"]);
    let k = g.columns[0].iter().position(|&c| c == 512.0).unwrap();
    assert!((g.times[k] - 2.7961e-2).abs() < 5e-7, "{}", g.times[k]);
    assert!(
        (g.columns[1][k] - 5.47e-5).abs() < 5e-8,
        "{}",
        g.columns[1][k]
    );
    // The cycles increase, and the last state comes before the end time printed.
    assert!(g.columns[0].windows(2).all(|w| w[1] > w[0]));
    assert!(d3hsp.contains("Problem time       =    3.5031E-02"));
    assert!(*g.times.last().unwrap() <= 3.5031e-2);
    // Uniform histories: 88 states whose times stray by a solver step, same count.
    let (h, note) = b.histories("glstat", &["kinetic_energy".into()]).unwrap();
    assert_eq!(h.samples(), 88);
    assert!(note.unwrap().contains("their mean"));
}

#[test]
fn a_runner_output_names_a_binout_branch_and_its_channels() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(data("binout/R9_3_1/binout"), dir.path().join("binout")).unwrap();
    let mut spec = OutputSpec::csv("binout");
    spec.format = OutputFormat::Binout;
    spec.branch = Some("matsum".into());
    spec.channels = Some(vec!["kinetic_energy".into()]);
    spec.check("batch.toml").unwrap();
    let h = spec.read(3, dir.path()).unwrap();
    assert_eq!(h.channels(), 2);
    assert!(h.labels().iter().all(|l| l.ends_with(".kinetic_energy")));
    spec.channels = Some(vec!["speed".into()]);
    let e = spec.read(3, dir.path()).unwrap_err().to_string();
    assert!(
        e.starts_with("run 3: ") && e.contains("no channel `speed`"),
        "{e}"
    );
    spec.branch = None;
    assert!(spec.check("batch.toml").is_err());
}

#[test]
fn real_nodout_files_read_with_run_together_fields_and_letterless_exponents() {
    let (h, note) = read_nodout(&data("nodout/nodout"), NodalQuantity::Displacement, None).unwrap();
    assert_eq!(
        h.labels(),
        [
            "6.x", "6.y", "6.z", "7.x", "7.y", "7.z", "8.x", "8.y", "8.z"
        ]
    );
    // Output times 0, 0.1, 0.3: the interval changed, so the smallest step keeps them all.
    assert_eq!(h.samples(), 4);
    assert!(note.unwrap().contains("smallest step"));
    // `-1.5000E+00`, `-1.5000-345` (below the smallest double: 0) and the run-together
    // `0.00000E+00-1.50000E+00` of node 8.
    for k in 0..4 {
        assert_eq!(h.value(2, k), -1.5);
        assert_eq!(h.value(5, k), 0.0);
        assert_eq!(h.value(8, k), -1.5);
    }
    let (v, _) = read_nodout(
        &data("nodout/nodout1"),
        NodalQuantity::Velocity,
        Some(&[1000, 3]),
    )
    .unwrap();
    assert_eq!(
        v.labels(),
        ["1000.x", "1000.y", "1000.z", "3.x", "3.y", "3.z"]
    );
    assert_eq!(v.samples(), 3);
    assert!((v.dt() - 1.9962452e-4 / 2.0).abs() < 1e-15);
    let e = read_nodout(
        &data("nodout/nodout1"),
        NodalQuantity::Velocity,
        Some(&[1001]),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("node 1001 is not in the file"), "{e}");
}
