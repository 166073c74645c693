//! The neutral Kolsky test form: reading, the typed errors of malformed files, the bridges,
//! writing it back, and the Los Alamos record converted into it.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use impactcal_core::testdata::LanlBarRecord;
use impactcal_models::ModelsError;
use impactcal_models::kolsky::{GainRow, GaugeBridge, KolskyTest, LanlOptions, Section, from_lanl};

const FORM: &str = r#"
[incident]
modulus = 109.3e9
density = 4416.0
poisson = 0.33
diameter = 9.47e-3
wave_speed = 4866.0
gauge_distance = 0.381
gauge_factor = 2.061
gain = 200.0
excitation = 8.0
bridge = "half"
polarity = 1
channels = ["inc"]
[transmitted]
modulus = 109.3e9
density = 4416.0
poisson = 0.33
side = 9.0e-3
gauge_distance = 0.381
gauge_factor = 2.062
gain = 200.0
excitation = 8.0
bridge = "quarter"
polarity = -1
channels = ["tra1", "tra2"]
[specimen]
diameter = 6.34e-3
length = 3.204e-3
density = 8960.0
[striker]
length = 0.127
[signals]
file = "signals.csv"
"#;

const SIGNALS: &str = "time,inc,tra1,tra2\n0,0.0,0.0,0.0\n1e-7,1.6,-0.4,-0.6\n2e-7,3.2,-1.0,-1.0\n";

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("kolsky_form_{name}"));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("signals.csv"), SIGNALS).unwrap();
    dir
}

fn parse(text: &str, dir: &Path) -> Result<KolskyTest, ModelsError> {
    KolskyTest::parse(text, "copper.toml", dir)
}

#[test]
fn the_form_reads_and_converts_volts_to_compressive_strain() {
    let dir = scratch("reads");
    let t = parse(FORM, &dir).unwrap();
    assert_eq!(t.incident.bridge, GaugeBridge::Half);
    assert_eq!(
        t.transmitted.section,
        Section::Rectangle {
            width: 9e-3,
            depth: 9e-3
        }
    );
    assert!((t.incident.wave_speed() - 4866.0).abs() < 1e-12);
    // Without `wave_speed`: the rod speed sqrt(E / rho).
    assert!((t.transmitted.wave_speed() - (109.3e9_f64 / 4416.0).sqrt()).abs() < 1e-9);
    assert_eq!(t.striker_length, Some(0.127));
    let s = t.strains().unwrap();
    // Half bridge, compression positive in volts: V_r = -3.2 / 1600 (tension-positive
    // bridge ratio), strain = -(2 V_r / (GF (1 - V_r))), positive.
    let vr: f64 = -3.2 / 1600.0;
    let want = -(2.0 * vr / (2.061 * (1.0 - vr)));
    assert!((s.value(0, 2) - want).abs() < 1e-15 && want > 0.0);
    // Quarter bridge, polarity -1, two gauges averaged: -0.4 and -0.6 V.
    let q = |v: f64| {
        let vr: f64 = v / 1600.0;
        -(4.0 * vr / (2.062 * (1.0 - 2.0 * vr)))
    };
    let want = 0.5 * (q(-0.4) + q(-0.6));
    assert!((s.value(1, 1) - want).abs() < 1e-15 && want > 0.0);
}

#[test]
fn the_half_bridge_inverts_its_divider_equation() {
    // Arms 1 and 3 active: V_r = R1/(R1+R2) - R4/(R3+R4) with R1 = R3 = 1 + GF eps.
    for eps in [-5e-3, -1e-4, 2e-4, 3e-3] {
        let a = 2.06 * eps;
        let vr = (1.0 + a) / (2.0 + a) - 1.0 / (2.0 + (a));
        let back = GaugeBridge::Half.strain(vr, 2.06, 0.3);
        assert!(
            (back - eps).abs() < 1e-15 * eps.abs().max(1.0),
            "{eps} {back}"
        );
    }
}

#[test]
fn the_form_writes_and_reads_back_bit_for_bit() {
    let dir = scratch("write");
    let t = parse(FORM, &dir).unwrap();
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let path = t.write(&out, "copper").unwrap();
    let back = KolskyTest::read(&path).unwrap();
    assert_eq!(back.incident, t.incident);
    assert_eq!(back.transmitted, t.transmitted);
    assert_eq!(back.specimen, t.specimen);
    assert_eq!(back.signals.data(), t.signals.data());
}

/// Each malformed file a user would write is refused with the file, the key and the fault.
#[test]
fn malformed_forms_name_file_key_and_fault() {
    let dir = scratch("malformed");
    let cases: Vec<(String, &str, &str)> = vec![
        (
            FORM.replace("gauge_factor = 2.061\n", ""),
            "incident.gauge_factor",
            "missing",
        ),
        (
            FORM.replace(
                "modulus = 109.3e9\ndensity = 4416.0\npoisson = 0.33\ndiameter",
                "modulus = -109.3e9\ndensity = 4416.0\npoisson = 0.33\ndiameter",
            ),
            "incident.modulus",
            "positive",
        ),
        (
            FORM.replace("bridge = \"quarter\"", "bridge = \"halve\""),
            "transmitted.bridge",
            "unknown bridge `halve`",
        ),
        (
            FORM.replace("[\"tra1\", \"tra2\"]", "[\"tra1\", \"tra3\"]"),
            "transmitted.channels",
            "`tra3` is not a column",
        ),
        (
            FORM.replace("side = 9.0e-3", "side = 9.0e-3\ndiameter = 9.0e-3"),
            "transmitted.side",
            "given with `diameter`",
        ),
        (
            FORM.replace("side = 9.0e-3\n", ""),
            "transmitted.diameter",
            "missing",
        ),
        (
            FORM.replace("diameter = 6.34e-3\n", "width = 6e-3\n"),
            "specimen.depth",
            "missing",
        ),
        (
            FORM.replace("polarity = -1", "polarity = 2"),
            "transmitted.polarity",
            "1 or -1",
        ),
        (
            FORM.replace("poisson = 0.33\ndiameter", "poisson = 0.6\ndiameter"),
            "incident.poisson",
            "outside",
        ),
        (
            FORM.replace(
                "gain = 200.0\nexcitation = 8.0\nbridge = \"half\"",
                "gain = \"200\"\nexcitation = 8.0\nbridge = \"half\"",
            ),
            "incident.gain",
            "must be a number, found string",
        ),
        (
            FORM.replace("wave_speed = 4866.0", "wavespeed = 4866.0"),
            "incident.wavespeed",
            "unknown key",
        ),
        (FORM.replace("[striker]\nlength = 0.127\n", ""), "", ""),
        (
            FORM.replace("[signals]\nfile = \"signals.csv\"\n", ""),
            "signals",
            "missing",
        ),
        (
            FORM.replace("channels = [\"inc\"]", "channels = []"),
            "incident.channels",
            "names 0 channels",
        ),
    ];
    for (text, key, fault) in cases {
        let r = parse(&text, &dir);
        if key.is_empty() {
            assert!(r.is_ok(), "the striker is optional: {:?}", r.err());
            continue;
        }
        match r {
            Err(ModelsError::Key {
                file,
                key: k,
                message,
            }) => {
                assert_eq!(file, "copper.toml");
                assert_eq!(k, key, "{message}");
                assert!(message.contains(fault), "{key}: {message}");
            }
            other => panic!("{key}: expected a key error, got {other:?}"),
        }
    }
    // Not TOML at all, and a signals file that is not there.
    assert!(matches!(
        parse("[incident\n", &dir),
        Err(ModelsError::Toml { .. })
    ));
    let e = parse(&FORM.replace("signals.csv", "nowhere.csv"), &dir).unwrap_err();
    assert!(e.to_string().contains("nowhere.csv"), "{e}");
}

fn copper_raw() -> &'static str {
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/kolsky/20061201_1148HE_CuOFE_273K.raw"
    )
}

#[test]
fn the_los_alamos_copper_record_converts_and_its_header_faults_are_reported() {
    let record = LanlBarRecord::read(copper_raw()).unwrap();
    let c = from_lanl(&record, &LanlOptions::default()).unwrap();
    let t = &c.test;
    // The density row is written in g/cm^3 under a kg/m^3 label: read from the rod speed.
    assert!(
        (t.incident.density - 4416.0).abs() < 1e-9,
        "{}",
        t.incident.density
    );
    assert!((t.incident.rod_speed() / 4974.964141 - 1.0).abs() < 1e-4);
    assert!(
        c.notes.iter().any(|n| n.contains("g/cm^3")),
        "{:?}",
        c.notes
    );
    // The measured speed, the gauge distance and the two transmitted gain rows.
    assert_eq!(t.incident.wave_speed, Some(4865.900383));
    assert!((t.transmitted.gauge_distance - 0.381).abs() < 1e-15);
    assert!((t.transmitted.gain - 200.0).abs() < 1e-12);
    assert!(
        c.notes
            .iter()
            .any(|n| n.contains("two gains") && n.contains("500")),
        "{:?}",
        c.notes
    );
    assert!((t.specimen.length - 3.204e-3).abs() < 1e-15);
    assert_eq!(t.signals.samples(), 5000);
    // The calibration row gives the other gain.
    let cal = LanlOptions {
        transmitted_gain: GainRow::Calibrated,
        ..LanlOptions::default()
    };
    let c500 = from_lanl(&record, &cal).unwrap();
    assert!((c500.test.transmitted.gain - 500.0).abs() < 1e-12);
    // Volts to strain through the half bridge: sample by sample.
    let s = t.strains().unwrap();
    let v = record.histories.value(0, 700);
    let vr = -v / (200.0 * 8.0);
    assert!((s.value(0, 700) + 2.0 * vr / (2.061 * (1.0 - vr))).abs() < 1e-15);
    // The incident plateau, about 3.3 V: 2.06e-3 of strain, a striker of about 20 m/s.
    assert!(
        s.value(0, 700) > 1.8e-3 && s.value(0, 700) < 2.3e-3,
        "{}",
        s.value(0, 700)
    );
    // The neutral form of the record reads back.
    let dir = scratch("lanl");
    let back = KolskyTest::read(t.write(&dir, "copper").unwrap()).unwrap();
    assert_eq!(back.strains().unwrap().data(), s.data());
}

#[test]
fn a_record_without_a_needed_row_names_it() {
    let text = std::fs::read_to_string(copper_raw()).unwrap_or_else(|_| {
        String::from_utf8_lossy(&std::fs::read(copper_raw()).unwrap()).into_owned()
    });
    let cut = text.replace("Incident Bar Poisson Ratio", "Incident Bar Poisson");
    let record = LanlBarRecord::parse(&cut, "cu.raw").unwrap();
    match from_lanl(&record, &LanlOptions::default()) {
        Err(ModelsError::Key { file, key, .. }) => {
            assert_eq!(file, "cu.raw");
            assert_eq!(key, "Incident Bar Poisson Ratio");
        }
        other => panic!("{other:?}"),
    }
    let bad = LanlOptions {
        polarity: 0.5,
        ..LanlOptions::default()
    };
    let full = LanlBarRecord::parse(&text, "cu.raw").unwrap();
    assert!(matches!(
        from_lanl(&full, &bad),
        Err(ModelsError::Invalid { .. })
    ));
}

/// Core's reading of a Los Alamos record (`LanlBarRecord::bridge`) and this crate's
/// (`from_lanl` with its default options) are one reading: the same bridge, and the same
/// strain sample by sample on both bars, bit for bit. The record's compression reads
/// positive in volts, so core's tension-positive conversion takes the gain negated (a bridge
/// wired the other way, as its docs say) and gives the strain with the opposite sign.
#[test]
fn core_and_the_models_crate_read_a_los_alamos_record_alike() {
    use impactcal_core::testdata::lanl_bar::Bar;
    let record = LanlBarRecord::read(copper_raw()).unwrap();
    let options = LanlOptions::default();
    let t = from_lanl(&record, &options).unwrap().test;
    assert_eq!(
        options.bridge.core(t.incident.poisson),
        LanlBarRecord::BRIDGE
    );
    let strains = t.strains().unwrap();
    for (c, bar, setup) in [
        (0, Bar::Incident, &t.incident),
        (1, Bar::Transmitted, &t.transmitted),
    ] {
        let core = record.bridge(bar, -setup.gain).unwrap();
        for k in 0..record.histories.samples() {
            let v = record.histories.value(c, k);
            assert_eq!(
                strains.value(c, k).to_bits(),
                (-core.apply(v)).to_bits(),
                "{bar:?} sample {k}"
            );
        }
    }
}
