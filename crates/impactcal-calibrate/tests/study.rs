//! The calibration study on a fast analytic impact model: M1 against the envelope computed
//! here from the same runs, M1 intervals of a test pushed out of the envelope, recovery of
//! a known interior point, resume after an interrupted study, failed runs.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use std::path::Path;

use impactcal_calibrate::CalibrateError;
use impactcal_calibrate::study::{self, M1, StudyOptions, TestData, Verdict};
use impactcal_core::sampling::sample;
use impactcal_core::{
    CoreError, Histories, Model, ParamGuard, Parameter, ParameterSpace, SamplingMethod,
};

const NODES: usize = 6;
const SAMPLES: usize = 161;
const DT: f64 = 2.5e-4;

/// Velocities of `NODES` nodes (x and z) of a structure hitting the ground: three damped
/// modes whose frequencies scale with `sqrt(stiffness)`, damping ratios with `damping`, and
/// the first mode's amplitude with `mass`; a rebound on z. Fails where `stiffness > fail`.
struct Drop {
    space: ParameterSpace,
    fail: f64,
}

impl Drop {
    fn new(fail: f64) -> Drop {
        Drop {
            space: ParameterSpace::new(vec![
                Parameter::new("stiffness", 0.8, 1.4, 1.0).unwrap(),
                Parameter::new("damping", 0.7, 1.6, 1.0).unwrap(),
                Parameter::new("mass", 0.8, 1.2, 1.0).unwrap(),
            ])
            .unwrap(),
            fail,
        }
    }
}

impl Model for Drop {
    fn space(&self) -> &ParameterSpace {
        &self.space
    }

    fn simulate(&self, p: &[f64]) -> impactcal_core::Result<Histories> {
        if p[0] > self.fail {
            return Err(CoreError::Invalid(format!("stiffness {} diverged", p[0])));
        }
        let freqs = [38.0, 95.0, 170.0].map(|f: f64| f * p[0].sqrt());
        let zetas = [0.08, 0.05, 0.04].map(|z| z * p[1]);
        let amps = [120.0 * p[2], 45.0, 18.0];
        let mut labels = Vec::new();
        let mut channels = Vec::new();
        for n in 0..NODES {
            let s = (n as f64 + 0.5) / NODES as f64;
            for (d, dir) in ["x", "z"].iter().enumerate() {
                labels.push(format!("{}.{dir}", 100 + n));
                let y = (0..SAMPLES)
                    .map(|k| {
                        let t = k as f64 * DT;
                        let modal: f64 = (0..3)
                            .map(|i| {
                                let ph = std::f64::consts::PI * s * (i + 1) as f64;
                                let shape = if d == 0 {
                                    0.3 * ph.cos() + 0.1
                                } else {
                                    ph.sin() + 0.1 * i as f64
                                };
                                let w = 2.0 * std::f64::consts::PI * freqs[i];
                                amps[i] * shape * (-zetas[i] * w * t).exp() * (w * t).sin()
                            })
                            .sum();
                        modal
                            - if d == 1 {
                                312.0 * (-t / 0.02).exp()
                            } else {
                                -100.0
                            }
                    })
                    .collect();
                channels.push(y);
            }
        }
        Histories::from_channels(labels, channels, DT, 0.0, "in/s")
    }
}

fn options(ensemble: usize, reconcile: usize) -> StudyOptions {
    StudyOptions {
        halton_runs: ensemble,
        sensors: 4,
        shapes: 3,
        sensitivity_samples: 256,
        reconcile_runs: reconcile,
        cors_batch: 2,
        seed: 3,
        jitter_runs: 4,
        ..StudyOptions::default()
    }
}

fn run(
    model: &Drop,
    test: &Histories,
    o: StudyOptions,
    dir: &Path,
) -> Result<study::StudyResult, CalibrateError> {
    study::run_model(
        model,
        "analytic drop",
        TestData {
            histories: test,
            map: None,
            cfc: None,
        },
        &o.check()?,
        dir,
        &study::Silent,
    )
}

fn ensemble_points(model: &Drop, n: usize, seed: u64) -> Vec<Vec<f64>> {
    let s = sample(model.space(), SamplingMethod::ScrambledHalton, n, seed).unwrap();
    (0..n)
        .map(|i| s.points.row(i).iter().copied().collect())
        .collect()
}

fn q(h: &Histories) -> Vec<f64> {
    (0..h.samples())
        .map(|k| {
            (0..h.channels())
                .map(|c| h.value(c, k).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .collect()
}

#[test]
fn envelope_and_verdict_match_the_runs_and_a_pushed_test_gives_its_interval() {
    let model = Drop::new(f64::INFINITY);
    let points = ensemble_points(&model, 12, 3);
    // The test is run 5 of the ensemble: inside the envelope at every sample.
    // Runs come back through our CSV value for value: the test equals run 5 exactly.
    let test = model.simulate(&points[5]).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mut o = options(12, 0);
    o.screen_only = true;
    let r = run(&model, &test, o.clone(), dir.path()).unwrap();
    let qs: Vec<Vec<f64>> = points
        .iter()
        .map(|p| q(&model.simulate(p).unwrap()))
        .collect();
    for k in 0..SAMPLES {
        let lo = qs.iter().map(|q| q[k]).fold(f64::INFINITY, f64::min);
        let hi = qs.iter().map(|q| q[k]).fold(f64::NEG_INFINITY, f64::max);
        assert!((r.m1.lower[k] - lo).abs() <= 1e-9 * hi, "{k}");
        assert!((r.m1.upper[k] - hi).abs() <= 1e-9 * hi, "{k}");
    }
    let M1 {
        verdict,
        n_runs,
        exceedance_fraction,
        ..
    } = r.m1;
    assert_eq!(
        (verdict, n_runs, exceedance_fraction),
        (Verdict::CanExplain, 12, 0.0)
    );
    assert!((r.m1.probability_bound - 1.0 / 12.0).abs() < 1e-15);
    assert!(r.sensors.is_none() && r.reconcile.is_none());

    // Push the test out between samples 40 and 59: Q_e leaves the envelope exactly there.
    let mut data = test.data().to_vec();
    for c in 0..test.channels() {
        for k in 40..60 {
            data[c * SAMPLES + k] += 400.0;
        }
    }
    let pushed = Histories::new(test.labels().to_vec(), SAMPLES, DT, 0.0, "in/s", data).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let r = run(&model, &pushed, o, dir.path()).unwrap();
    // 20 of 161 samples is fewer than the 2/13 at which an exchangeable draw leaves 12 runs:
    // no evidence against the parameter set (docs/validation.md, M1 with noise and N).
    assert!((r.m1.expected_exceedance - 2.0 / 13.0).abs() < 1e-12);
    assert!(r.m1.exceedance_fraction < r.m1.expected_exceedance);
    assert_eq!(r.m1.verdict, Verdict::CanExplain, "{}", r.m1.statement);
    // A noiseless test has no quiet part (the drop starts at once) and no band above the
    // ensemble's bandwidth (what lies there is the model's own falling tail, not flat like
    // noise): no noise is counted, the paper's reading.
    assert!(!r.m1.noise_counted);
    for n in &r.measurement_noise {
        assert_eq!(n.sigma, 0.0);
        assert!(
            n.note.as_deref().is_some_and(|t| t.contains("no band")),
            "{n:?}"
        );
    }
    assert_eq!(r.m1.intervals, vec![[40.0 * DT, 59.0 * DT]]);
    assert!((r.m1.exceedance_fraction - 20.0 / SAMPLES as f64).abs() < 1e-15);
}

#[test]
fn reconciliation_recovers_an_interior_point_and_a_resumed_study_is_identical() {
    let model = Drop::new(f64::INFINITY);
    let truth = [1.17, 1.21, 0.93];
    let test = model.simulate(&truth).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let r = run(&model, &test, options(16, 40), dir.path()).unwrap();
    let c = r.reconcile.as_ref().unwrap();
    assert_eq!(c.runs, 40);
    // 40 runs place the worst of the three parameters within 0.15 of its width of the truth
    // on 61 of seeds 0..63 (within 0.05 on only 39; 62 and 40 with the falling candidate
    // count; 63 and 36 with repeated refinement), and below 5 % of the baseline's
    // prediction error on 54 of them (53; 54): seed 3 is a typical one (0.05 of the width,
    // 2.2 %).
    let widths = [0.6, 0.9, 0.4];
    for i in 0..3 {
        let off = (c.calibrated_point[i] - truth[i]).abs() / widths[i];
        assert!(
            off < 0.15,
            "parameter {i}: {} vs {}",
            c.calibrated_point[i],
            truth[i]
        );
    }
    let e = r.errors.as_ref().unwrap();
    assert!(
        e.calibrated.prediction_error < 0.05 * e.baseline.prediction_error,
        "{e:?}"
    );
    assert!(e.calibrated.iso18571_r > e.baseline.iso18571_r);
    let m2 = r.m2.as_ref().unwrap();
    assert!(m2.calibrated.as_ref().unwrap().matched_above_0_9 >= m2.baseline.matched_above_0_9);
    let s = r.sensitivity.as_ref().unwrap();
    assert_eq!(s.ranking.len(), 3);
    assert!(r.surrogate.as_ref().unwrap().loo_rel_error < 0.5);
    // The same study again in the same folder reuses every run and gives the same result.
    let again = run(&model, &test, options(16, 40), dir.path()).unwrap();
    assert_eq!(again, r);
    // An interrupted study (half the ensemble and most reconciliation runs lost): the
    // journal lines of those results are cut (their runs were submitted, never read back),
    // the reconciliation's later batches removed.
    let runs = dir.path().join("runs");
    for entry in std::fs::read_dir(&runs).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_str().unwrap().to_string();
        let first: Option<usize> = name.strip_prefix("reconcile-").map(|k| k.parse().unwrap());
        if first.is_some_and(|f| f > 3) {
            std::fs::remove_dir_all(&path).unwrap();
            continue;
        }
        if name != "ensemble" && first.is_none() {
            continue;
        }
        let journal = path.join("journal.jsonl");
        let text = std::fs::read_to_string(&journal).unwrap();
        let mut kept = String::new();
        let mut cut = 0;
        for line in text.lines() {
            let e: serde_json::Value = serde_json::from_str(line).unwrap();
            if e["event"] == "result" && e["index"].as_u64().unwrap() % 2 == 1 {
                cut += 1;
                continue;
            }
            kept.push_str(line);
            kept.push('\n');
        }
        assert!(cut > 0, "{name}");
        std::fs::write(&journal, kept).unwrap();
    }
    let resumed = run(&model, &test, options(16, 40), dir.path()).unwrap();
    assert_eq!(
        serde_json::to_string(&resumed).unwrap(),
        serde_json::to_string(&r).unwrap()
    );
}

#[test]
fn failed_runs_are_reported_and_kept_out() {
    let model = Drop::new(1.25);
    let points = ensemble_points(&model, 14, 3);
    let expected: Vec<usize> = (0..14).filter(|&i| points[i][0] > 1.25).collect();
    assert!(!expected.is_empty() && expected.len() < 10);
    let test = model.simulate(&[1.0, 1.0, 1.0]).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let r = run(&model, &test, options(14, 0), dir.path()).unwrap();
    let failed: Vec<usize> = r.ensemble.failed.iter().map(|f| f.index).collect();
    assert_eq!(failed, expected);
    assert!(r.ensemble.failed[0].message.contains("diverged"));
    assert_eq!(r.ensemble.succeeded, 14 - expected.len());
    assert_eq!(r.m1.n_runs, 14 - expected.len());
    assert!(r.surrogate.is_some());
}

#[test]
fn bad_studies_are_refused() {
    let model = Drop::new(f64::INFINITY);
    let test = model.simulate(&[1.0, 1.0, 1.0]).unwrap();
    let dir = tempfile::tempdir().unwrap();
    // More sensors than channels (12).
    let mut o = options(6, 0);
    o.sensors = 13;
    o.shapes = 3;
    let e = run(&model, &test, o, dir.path()).unwrap_err();
    assert!(e.to_string().contains("13 sensors"), "{e}");
    // Another study's folder: nothing is overwritten.
    let before = std::fs::read(dir.path().join("runs/fingerprint")).unwrap();
    let e = run(&model, &test, options(7, 0), dir.path()).unwrap_err();
    assert!(matches!(e, CalibrateError::ForeignJournal { .. }), "{e}");
    assert_eq!(
        std::fs::read(dir.path().join("runs/fingerprint")).unwrap(),
        before
    );
    // A budget of 0.
    assert!(options(0, 0).check().is_err());
    // A test with no channel in common.
    let other = Histories::from_channels(
        vec!["9.q".into()],
        vec![vec![1.0; SAMPLES]],
        DT,
        0.0,
        "in/s",
    )
    .unwrap();
    let e = run(
        &model,
        &other,
        options(6, 0),
        tempfile::tempdir().unwrap().path(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("no channel in common"), "{e}");
}

/// The report document of a whole study carries the study's numbers in every figure and
/// table.
#[test]
fn the_report_document_holds_the_study_numbers() {
    use impactcal_calibrate::report::{Block, Plot};
    use impactcal_calibrate::study::document::{Geometry, report};
    let model = Drop::new(f64::INFINITY);
    let test = model.simulate(&[1.1, 0.9, 1.05]).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let r = run(&model, &test, options(12, 6), dir.path()).unwrap();
    let mut geometry = Geometry {
        points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
        unit: "in".into(),
        ..Geometry::default()
    };
    for n in 0..NODES {
        for a in ["x", "z"] {
            geometry
                .channels
                .insert(format!("{}.{a}", 100 + n), [n as f64, 0.0, 0.0]);
        }
    }
    let doc = report(&r, Some(&geometry));
    assert!(doc.lead[0].contains(r.m1.verdict.as_str()));
    let figures: Vec<_> = doc
        .sections
        .iter()
        .flat_map(|s| &s.blocks)
        .filter_map(|b| match b {
            Block::Figure(f) => Some(f),
            _ => None,
        })
        .collect();
    let names: Vec<&str> = figures.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "fig-m1",
            "fig-sensors",
            "fig-m2-baseline",
            "fig-m2-calibrated",
            "fig-shape-1",
            "fig-shape-2",
            "fig-sensitivity",
            "fig-q",
            "fig-sensor"
        ]
    );
    let m2 = r.m2.as_ref().unwrap();
    let s = r.sensitivity.as_ref().unwrap();
    for f in &figures {
        match (&f.plot, f.name.as_str()) {
            (Plot::Envelope(e), _) => {
                assert_eq!(
                    (&e.lower, &e.upper, &e.x),
                    (&r.m1.lower, &r.m1.upper, &r.m1.time)
                );
                assert_eq!(e.series[0].values, r.m1.test);
                let marked: Vec<[f64; 2]> = e.marked.iter().map(|m| [m.0, m.1]).collect();
                assert_eq!(marked, r.m1.intervals);
            }
            (Plot::Structure(st), name) if name.starts_with("fig-shape-") => {
                // Each marker is an entry of the test's shape at its channel's node.
                let j: usize = name["fig-shape-".len()..].parse::<usize>().unwrap() - 1;
                let shape = &m2.baseline.test_shapes[j];
                assert!(!st.marked.is_empty(), "{name}");
                for m in &st.marked {
                    let v = m.value.unwrap();
                    assert!(
                        shape.contains(&v) && geometry.channels.values().any(|at| *at == m.at),
                        "{name}: {m:?}"
                    );
                }
            }
            (Plot::Structure(st), _) => {
                let labels: Vec<&str> = st.marked.iter().map(|m| m.label.as_str()).collect();
                assert_eq!(labels, r.sensors.as_ref().unwrap().selected);
                for m in &st.marked {
                    assert_eq!(m.at, geometry.channels[&m.label]);
                }
            }
            (Plot::HeatMap(h), name) => {
                let m = if name.ends_with("baseline") {
                    &m2.baseline
                } else {
                    m2.calibrated.as_ref().unwrap()
                };
                assert_eq!(h.values, m.matrix);
                let pairs: Vec<(usize, usize)> = m.pairs.iter().map(|p| (p.0, p.1)).collect();
                assert_eq!(h.marked, pairs);
                assert!((h.row_weights[0] - 100.0 * m.model_contributions[0]).abs() < 1e-12);
            }
            (Plot::Stacked(st), _) => {
                assert_eq!(st.stacked.len(), 3);
                for series in &st.stacked {
                    let truth = &s.first_order[&series.name];
                    for (a, b) in series.values.iter().zip(truth) {
                        assert_eq!(*a, b.max(0.0));
                    }
                }
                assert_eq!(st.top.values, r.curves.q_baseline);
            }
            (Plot::Lines(l), "fig-q") => {
                assert_eq!(l.series[0].values, r.curves.q_test);
                assert_eq!(l.series[1].values, r.curves.q_baseline);
                assert_eq!(Some(&l.series[2].values), r.curves.q_calibrated.as_ref());
            }
            (Plot::Lines(l), _) => {
                assert_eq!(l.series[0].values, r.curves.sensor_test);
                assert_eq!(l.series.len(), 3);
            }
        }
    }
    // The before/after table states the computed errors.
    let e = r.errors.as_ref().unwrap();
    let table = doc
        .sections
        .iter()
        .flat_map(|s| &s.blocks)
        .find_map(|b| match b {
            Block::Table(t) if t.caption == "Before and after" => Some(t),
            _ => None,
        })
        .unwrap();
    assert_eq!(
        table.rows[0][1],
        format!("{:.2} %", 100.0 * e.baseline.prediction_error)
    );
    assert_eq!(
        table.rows[0][2],
        format!("{:.2} %", 100.0 * e.calibrated.prediction_error)
    );
    assert!(e.calibrated.prediction_error <= e.baseline.prediction_error);
}

/// The header of run `index` of stage `stage`: its channel labels.
fn stored(dir: &Path, stage: &str, index: usize) -> Vec<String> {
    let text =
        std::fs::read_to_string(dir.join(format!("runs/{stage}/{index}/result.csv"))).unwrap();
    let header = text.lines().next().unwrap();
    header.split(',').skip(1).map(String::from).collect()
}

/// A test of the z channels only: the ensemble and reconciliation runs store those (the
/// objective channels), the nominal and jitter runs every channel; keeping every channel
/// gives the same result, number for number.
#[test]
fn runs_store_the_objective_channels_and_keeping_all_changes_no_number() {
    let model = Drop::new(10.0);
    let full = model.simulate(&[1.1, 0.9, 1.05]).unwrap();
    let z: Vec<String> = full
        .labels()
        .iter()
        .filter(|l| l.ends_with(".z"))
        .cloned()
        .collect();
    let test = full.select(&z).unwrap();
    let lean_dir = tempfile::tempdir().unwrap();
    let lean = run(&model, &test, options(10, 4), lean_dir.path()).unwrap();
    assert_eq!(lean.channels.objective, z);
    assert_eq!(stored(lean_dir.path(), "ensemble", 0), z);
    assert_eq!(stored(lean_dir.path(), "reconcile-0", 0), z);
    assert_eq!(stored(lean_dir.path(), "nominal", 0), full.labels());
    assert_eq!(stored(lean_dir.path(), "noise", 0), full.labels());

    let all_dir = tempfile::tempdir().unwrap();
    let o = StudyOptions {
        keep_all_channels: true,
        ..options(10, 4)
    };
    let all = run(&model, &test, o, all_dir.path()).unwrap();
    assert_eq!(stored(all_dir.path(), "ensemble", 0), full.labels());
    assert_eq!(stored(all_dir.path(), "reconcile-0", 0), full.labels());
    // Only the option (and so the fingerprint) differs.
    let strip = |r: &study::StudyResult| {
        let mut v = serde_json::to_value(r).unwrap();
        let o = v.as_object_mut().unwrap();
        o.remove("options");
        o.remove("fingerprint");
        v
    };
    assert_eq!(strip(&lean), strip(&all));
}
