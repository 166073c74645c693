//! One hidden case of the closed loop's family on the coarse airframe (docs/validation.md,
//! "The closed loop over a family of hidden effects"), run from a short spec, ending with
//! one JSON line on stdout.
//!
//! The setting is the one the loop is documented for: the coarse airframe with Table 2
//! declared (six thicknesses at their nominal values), the test made from the truth (the
//! model with one catalogue quantity moved from its held value, made here from the
//! catalogue) measured on the `channels` vertical channels that move most after CFC 1000,
//! over 0 to `end` s, compared after CFC 1000, with white noise of 0.5 % of each channel's
//! RMS (46 dB), a trigger offset of 0.3 ms and a gain of 1.12 on the channel that moves
//! most; the holdout is the same truth at a sink speed of 280 in/s and a pitch of 4 deg
//! (noise seed `seed + 100`). Every catalogue quantity not declared is a candidate unless
//! `--candidates` narrows them; `[budget]` reconcile and recalibrate 24 unless given.
//!
//! ```text
//! cargo run --release --example loop_family -- <dir> <kind> <level> <seed>
//!     [--end 0.015] [--channels 24] [--candidates a,b,c] [--reconcile 24]
//!     [--recalibrate 24] [--polish 8] [--jitter 1e-4] [--known-gains] [--declare START] [--keep]
//! ```
//!
//! `kind` is one of `damping`, `mass`, `friction`, `rate`, `material`, `none`; `level` 1 or
//! 2 picks the kind's amplitude (table `KINDS`); a kind `QUANTITY=VALUE` hides any catalogue
//! quantity at any value (`level` is then ignored). The loop's journal goes to
//! `<dir>/<kind>-<level>-<seed>` and is deleted after the record is printed unless
//! `--keep`. Probes of one case: `--known-gains` fixes the gains at 1 (`fit_gains = false`);
//! `--declare START` declares the hidden quantity beside Table 2 from `START` and adds
//! nothing (`max_added = 0`): the problem the loop's recalibration solves, from a chosen
//! start and with its own budget (`--reconcile`).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use std::time::Instant;

use impactcal::calibrate::closeloop::{Holdout, LoopOptions, LoopResult, Verdict, run_loop};
use impactcal::calibrate::study::{Silent, TestData};
use impactcal::core::synthetic::{Measurement, measured};
use impactcal::core::{Cfc, Enrichable, Histories, Model, Parameter, ParameterSpace};
use impactcal::shell::airframe::{Airframe, AirframeModel, AirframeOptions, MeshDensity, Preset};
use serde_json::json;

/// The family: a kind, the catalogue quantity it moves, and two true values (the held
/// value is the catalogue's nominal). Amplitudes are about a third and two thirds of the
/// way from the held value to an end of the admissible range, on either side where the
/// range allows, so that the truth is inside the range the loop searches.
const KINDS: [(&str, &str, [f64; 2]); 5] = [
    ("damping", "damping", [5.0, 20.0]),
    ("mass", "mass.occupants", [0.8, 0.6]),
    ("friction", "ground.friction", [0.5, 0.1]),
    ("rate", "rate.c", [2000.0, 40000.0]),
    ("material", "subfloor_ribs.sigy", [53000.0, 41000.0]),
];
/// Trigger offset of both tests (s): three samples late.
const TAU: f64 = 3e-4;
/// Gain of the channel that moves most.
const GAIN: f64 = 1.12;
/// Signal-to-noise ratio (dB): noise of 0.5 % of each channel's RMS.
const SNR_DB: f64 = 46.0206;
/// The comparison's filter.
const CFC: u32 = 1000;
/// The holdout's condition.
const HOLDOUT: [(&str, f64); 2] = [("impact.vertical", 280.0), ("attitude.pitch", 4.0)];

struct Spec {
    dir: std::path::PathBuf,
    kind: String,
    level: usize,
    seed: u64,
    end: f64,
    channels: usize,
    candidates: Option<Vec<String>>,
    reconcile: usize,
    recalibrate: usize,
    polish: usize,
    fit_gains: bool,
    declare: Option<f64>,
    jitter: f64,
    keep: bool,
}

fn spec() -> Spec {
    let usage = "usage: loop_family <dir> <kind> <level 1|2> <seed> [--end S] [--channels N] \
                 [--candidates a,b] [--reconcile N] [--recalibrate N] [--keep]";
    let a: Vec<String> = std::env::args().skip(1).collect();
    assert!(a.len() >= 4, "{usage}");
    let mut s = Spec {
        dir: a[0].clone().into(),
        kind: a[1].clone(),
        level: a[2].parse().expect(usage),
        seed: a[3].parse().expect(usage),
        end: 0.015,
        channels: 24,
        candidates: None,
        reconcile: 24,
        recalibrate: 24,
        polish: LoopOptions::default().polish,
        fit_gains: true,
        declare: None,
        jitter: LoopOptions::default().jitter,
        keep: false,
    };
    let mut i = 4;
    while i < a.len() {
        let v = a.get(i + 1);
        match a[i].as_str() {
            "--end" => s.end = v.expect(usage).parse().expect(usage),
            "--channels" => s.channels = v.expect(usage).parse().expect(usage),
            "--candidates" => {
                s.candidates = Some(v.expect(usage).split(',').map(String::from).collect());
            }
            "--reconcile" => s.reconcile = v.expect(usage).parse().expect(usage),
            "--recalibrate" => s.recalibrate = v.expect(usage).parse().expect(usage),
            "--polish" => s.polish = v.expect(usage).parse().expect(usage),
            "--jitter" => s.jitter = v.expect(usage).parse().expect(usage),
            "--declare" => s.declare = Some(v.expect(usage).parse().expect(usage)),
            "--keep" | "--known-gains" => {
                if a[i] == "--keep" {
                    s.keep = true;
                } else {
                    s.fit_gains = false;
                }
                i += 1;
                continue;
            }
            other => panic!("unknown option {other}; {usage}"),
        }
        i += 2;
    }
    assert!(s.level == 1 || s.level == 2, "{usage}");
    s
}

/// The hidden quantity and its true value, `None` for the effect-free control.
fn hidden(kind: &str, level: usize) -> Option<(String, f64)> {
    if kind == "none" {
        return None;
    }
    if let Some((q, v)) = kind.split_once('=') {
        return Some((q.to_string(), v.parse().expect("kind QUANTITY=VALUE")));
    }
    let (_, q, v) = KINDS
        .iter()
        .find(|(k, _, _)| *k == kind)
        .unwrap_or_else(|| panic!("unknown kind {kind}"));
    Some(((*q).to_string(), v[level - 1]))
}

fn main() {
    let s = spec();
    let started = Instant::now();
    let mut o = AirframeOptions::new(MeshDensity::Coarse);
    o.end_time = s.end;
    let airframe = Airframe::new(o).unwrap();
    let model = AirframeModel::preset(airframe.clone(), Preset::Table2).unwrap();
    let truth_set: Vec<(String, f64)> = hidden(&s.kind, s.level).into_iter().collect();
    let held = truth_set.first().map(|(q, _)| {
        model
            .candidates()
            .iter()
            .find(|c| c.name() == q)
            .map(|c| c.parameter.nominal)
            .unwrap()
    });
    let truth = model.at_condition(&truth_set).unwrap();
    let hold: Vec<(String, f64)> = HOLDOUT.iter().map(|(n, v)| (n.to_string(), *v)).collect();
    let x = model.space().nominal();
    let (y, yh) = rayon::join(
        || truth.simulate(&x).unwrap(),
        || truth.at_condition(&hold).unwrap().simulate(&x).unwrap(),
    );
    let cfc = Cfc::from_class(CFC).unwrap();
    let f = y.filtered(cfc).unwrap();
    let vertical: Vec<&String> = f.labels().iter().filter(|l| l.ends_with(".z")).collect();
    let channels = f.select(&vertical).unwrap().most_varying(s.channels);
    let wrong = channels[0].clone();
    let measure = |h: &Histories, seed: u64| -> Histories {
        let m = Measurement {
            time_shift: TAU,
            gains: vec![(wrong.clone(), GAIN)],
            snr_db: Some(SNR_DB),
            seed,
            ..Measurement::default()
        };
        measured(&h.select(&channels).unwrap(), &m).unwrap()
    };
    let (test, holdout) = (measure(&y, s.seed), measure(&yh, s.seed + 100));
    let mut options = LoopOptions {
        reconcile: s.reconcile,
        recalibrate: s.recalibrate,
        polish: s.polish,
        fit_gains: s.fit_gains,
        jitter: s.jitter,
        candidates: s.candidates.clone(),
        seed: 1,
        ..LoopOptions::default()
    };
    // A probe: the hidden quantity declared beside Table 2, calibrated from `start` with
    // nothing added (the 7-parameter problem the loop's recalibration solves).
    let probe = match (s.declare, truth_set.first()) {
        (Some(start), Some((q, _))) => {
            let c = model
                .candidates()
                .into_iter()
                .find(|c| c.name() == q)
                .unwrap();
            let p = &c.parameter;
            let mut params = model.space().parameters().to_vec();
            params.push(Parameter::new(q.clone(), p.lower, p.upper, start).unwrap());
            options.max_added = 0;
            Some(AirframeModel::new(airframe, ParameterSpace::new(params).unwrap()).unwrap())
        }
        _ => None,
    };
    let loop_model = probe.as_ref().unwrap_or(&model);
    let run_dir = s.dir.join(format!(
        "{}-{}-{}{}{}{}{}",
        s.kind,
        s.level,
        s.seed,
        s.declare
            .map_or(String::new(), |v| format!("-declared-{v}")),
        if s.fit_gains { "" } else { "-known-gains" },
        if s.jitter == LoopOptions::default().jitter {
            String::new()
        } else {
            format!("-jitter-{}", s.jitter)
        },
        if s.polish == LoopOptions::default().polish {
            String::new()
        } else {
            format!("-polish-{}", s.polish)
        }
    ));
    let data = TestData {
        histories: &test,
        map: None,
        cfc: Some(cfc),
    };
    let h = Holdout {
        histories: &holdout,
        set: &hold,
    };
    let r = run_loop(
        loop_model,
        &format!("coarse airframe, 0-{} s, Table2 declared", s.end),
        data,
        Some(h),
        &options,
        &run_dir,
        &Silent,
    )
    .unwrap();
    let line = record(
        &s,
        &truth_set,
        held,
        &r,
        &wrong,
        started.elapsed().as_secs_f64(),
    );
    println!("{line}");
    if s.keep {
        std::fs::write(
            run_dir.join("loop.json"),
            serde_json::to_string_pretty(&r).unwrap(),
        )
        .unwrap();
    } else {
        let _ = std::fs::remove_dir_all(&run_dir);
    }
}

fn record(
    s: &Spec,
    truth: &[(String, f64)],
    held: Option<f64>,
    r: &LoopResult,
    wrong: &str,
    wall: f64,
) -> String {
    let hidden = truth.first();
    let rank = hidden.and_then(|(q, _)| r.candidates.iter().position(|c| &c.name == q));
    let hidden_score = rank.map(|k| &r.candidates[k]);
    let added_hidden = hidden.and_then(|(q, _)| r.added.iter().find(|a| &a.name == q));
    let inside = match (hidden, added_hidden) {
        (Some((_, v)), Some(a)) => Some(a.lower <= *v && *v <= a.upper),
        _ => None,
    };
    let gains = &r.nuisance.gains;
    let worst_other_gain = gains
        .iter()
        .filter(|(l, _)| l.as_str() != wrong)
        .map(|(_, g)| (g - 1.0).abs())
        .fold(0.0, f64::max);
    let e = &r.errors;
    let verdict = match r.verdict {
        Verdict::NoModelFormError => "no-model-form-error",
        Verdict::Attributed => "attributed",
        Verdict::Unattributed => "unattributed",
    };
    json!({
        "kind": s.kind,
        "level": s.level,
        "seed": s.seed,
        "probe": {"declared_from": s.declare, "fit_gains": s.fit_gains,
                  "reconcile": s.reconcile, "jitter": s.jitter, "recalibrate": s.recalibrate, "polish": s.polish},
        "end": s.end,
        "channels": s.channels,
        "hidden": hidden.map(|(q, v)| json!({"name": q, "truth": v, "held": held})),
        "first": r.candidates.first().map(|c| json!({
            "name": c.name, "kappa": c.kappa, "explained": c.explained_fraction,
            "status": c.status})),
        "hidden_rank": rank.map(|k| k + 1),
        "hidden_kappa": hidden_score.map(|c| c.kappa),
        "hidden_status": hidden_score.map(|c| c.status.clone()),
        "hidden_twins": hidden.map(|(q, _)| r.indistinguishable.iter()
            .filter(|(a, b, _)| a == q || b == q)
            .map(|(a, b, mu)| json!({"name": if a == q { b } else { a }, "coherence": mu}))
            .collect::<Vec<_>>()),
        "added": r.added.iter().map(|a| json!({
            "name": a.name, "value": a.value, "lower": a.lower, "upper": a.upper,
            "model_noise_sd": a.model_noise_sd, "roughness_sd": a.roughness_sd,
            "pending_step": a.pending_step}))
            .collect::<Vec<_>>(),
        "truth_inside": inside,
        "verdict": verdict,
        "stopped": r.stopped,
        "chi2_red": [r.detection.chi2_red, r.detection_final.chi2_red],
        "threshold": r.detection_final.threshold,
        "gain": gains.get(wrong),
        "gain_true": GAIN,
        "other_gains_max_dev": worst_other_gain,
        "tau": r.nuisance.time_shift,
        "tau_true": TAU,
        "dt": r.time_step,
        "calibration": [e.calibration.nominal, e.calibration.calibrated, e.calibration.enriched],
        "holdout": e.holdout.as_ref().map(|h| [h.nominal, h.calibrated, h.enriched]),
        "calibrated": r.calibrated,
        "runs": r.runs,
        "wall_s": wall,
    })
    .to_string()
}
