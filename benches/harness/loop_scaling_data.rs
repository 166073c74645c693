//! The test data of the scaling record (docs/performance.md, "Closed loop and study at the
//! size of a whole test"): the coarse airframe with structural damping the model holds at
//! zero (10 1/s, as in the loop demo), crashed over `0..END` s and measured on its `S`
//! channels that move most after CFC 60 (all 1,215 when `S` is 1,215 or more), with a trigger
//! offset of two samples, white noise at 40 dB and one sensor reading 1.2 times too high;
//! the holdout is the same truth at a sink speed of 280 in/s. Writes into `<dir>`:
//!
//! - `test.csv`, `holdout.csv`: the measured histories;
//! - `loop.toml`: `impactcal close-loop` on them (Table 2 declared, CFC 60, the holdout,
//!   `[loop]` jitter_runs 30, reconcile_runs 30, recalibrate_runs 30);
//! - `study.toml`: `impactcal study` on the test (Table 2, CFC 60, ensemble 30, 12 sensors,
//!   reconciliation 30 runs, every channel kept in the objective: over 50 ms the channels
//!   that move most are beyond the airframe's predictability horizon, and a study that
//!   drops them has no objective channel left at 24 channels).
//!
//! `cargo run --release --example loop_scaling_data -- <dir> <S> <END>`; two airframe runs.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use impactcal::core::synthetic::{Measurement, measured};
use impactcal::core::{Cfc, Enrichable, Histories, Model};
use impactcal::shell::airframe::{Airframe, AirframeModel, AirframeOptions, MeshDensity, Preset};

/// What the test hides: structural damping (1/s) the model holds at zero.
const HIDDEN_DAMPING: f64 = 10.0;
/// The holdout's sink speed (in/s).
const HOLDOUT_SPEED: f64 = 280.0;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: loop_scaling_data <dir> <channels> <end time (s)>";
    let dir = std::path::PathBuf::from(args.get(1).expect(usage));
    let count: usize = args.get(2).expect(usage).parse().expect(usage);
    let end: f64 = args.get(3).expect(usage).parse().expect(usage);
    std::fs::create_dir_all(&dir).unwrap();
    let mut o = AirframeOptions::new(MeshDensity::Coarse);
    o.end_time = end;
    let model = AirframeModel::preset(Airframe::new(o).unwrap(), Preset::Table2).unwrap();
    let truth = model
        .at_condition(&[("damping".into(), HIDDEN_DAMPING)])
        .unwrap();
    let speed = [("impact.vertical".to_string(), HOLDOUT_SPEED)];
    let x = model.space().nominal();
    let (y, yh) = rayon::join(
        || truth.simulate(&x).unwrap(),
        || truth.at_condition(&speed).unwrap().simulate(&x).unwrap(),
    );
    let filtered = y.filtered(Cfc::from_class(60).unwrap()).unwrap();
    let channels = filtered.most_varying(count);
    let measure = |h: &Histories, seed: u64| -> Histories {
        let m = Measurement {
            time_shift: 2e-4,
            gains: vec![(channels[0].clone(), 1.2)],
            snr_db: Some(40.0),
            seed,
            ..Measurement::default()
        };
        measured(&h.select(&channels).unwrap(), &m).unwrap()
    };
    measure(&y, 1).write_csv(dir.join("test.csv")).unwrap();
    measure(&yh, 2).write_csv(dir.join("holdout.csv")).unwrap();
    let model_lines = format!(
        "[model]\nairframe = \"coarse\"\nend_time = {end}\n\n[space]\npreset = \"table2\"\n\n\
         [test]\ndata = \"test.csv\"\ncfc = 60\n"
    );
    std::fs::write(
        dir.join("loop.toml"),
        format!(
            "{model_lines}\n[holdout]\ndata = \"holdout.csv\"\nset = {{ \"impact.vertical\" = \
             {HOLDOUT_SPEED:?} }}\n\n[loop]\njitter_runs = 30\nreconcile_runs = 30\nrecalibrate_runs = 30\n\
             seed = 1\n"
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("study.toml"),
        format!(
            "{model_lines}\n[study]\nhalton_runs = 30\nsensors = 12\nreconcile_runs = 30\nseed = 1\n\
             keep_unpredictable = true\n"
        ),
    )
    .unwrap();
    eprintln!(
        "loop_scaling_data: {} channels x {} samples in {}",
        channels.len(),
        y.samples(),
        dir.display()
    );
}
