//! A batch of airframe crashes, the paper's ensemble: `N` points (50 by default) of the
//! Table 2 thickness box on the coarse mesh, run in parallel through `Model::simulate_batch`.
//! Prints the wall time and the spread of the velocity-norm history Q(t).
//!
//! `cargo run --release --example airframe_batch -- [N] [coarse|medium|fine] [end_time]`
#![allow(clippy::unwrap_used, clippy::expect_used)]

use impactcal::prelude::*;
use impactcal::shell::airframe::{Airframe, AirframeModel, AirframeOptions, MeshDensity, Preset};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map_or(50, |s| s.parse().unwrap());
    let mesh = MeshDensity::parse(args.get(2).map_or("coarse", String::as_str)).unwrap();
    let mut options = AirframeOptions::new(mesh);
    if let Some(t) = args.get(3) {
        options.end_time = t.parse().unwrap();
    }
    let airframe = Airframe::new(options).unwrap();
    let shells = airframe.shell_count();
    let model = AirframeModel::preset(airframe, Preset::Table2).unwrap();
    let space = model.space().clone();
    // A low-discrepancy set in the unit cube (additive recurrence on the generalised golden
    // ratio), mapped to the bounds.
    let d = space.dim();
    let mut phi = 2.0f64;
    for _ in 0..50 {
        phi = (1.0 + phi).powf(1.0 / (d as f64 + 1.0));
    }
    let points: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            let u: Vec<f64> = (0..d)
                .map(|k| (0.5 + (i + 1) as f64 / phi.powi(k as i32 + 1)).fract())
                .collect();
            space.from_unit(&u).unwrap()
        })
        .collect();
    let started = std::time::Instant::now();
    let batch = model.simulate_batch(&points);
    let wall = started.elapsed().as_secs_f64();
    let failures: Vec<String> = batch.failures().map(|f| f.to_string()).collect();
    let q: Vec<Vec<f64>> = batch.successes().map(|(_, h)| h.norm_history()).collect();
    let samples = q.first().map_or(0, Vec::len);
    let (mut lo, mut hi) = (vec![f64::INFINITY; samples], vec![0.0f64; samples]);
    for h in &q {
        for k in 0..samples {
            lo[k] = lo[k].min(h[k]);
            hi[k] = hi[k].max(h[k]);
        }
    }
    let widest = (0..samples)
        .map(|k| (hi[k] - lo[k]) / hi[k].max(f64::MIN_POSITIVE))
        .fold(0.0, f64::max);
    println!(
        "{n} runs of {shells} shells to t = {} s on {} threads: {wall:.1} s wall, {:.2} s per run; \
         {} failed; widest Q(t) band (max - min) / max = {widest:.3}",
        options.end_time,
        rayon::current_num_threads(),
        wall / n as f64,
        failures.len()
    );
    for f in failures {
        println!("  {f}");
    }
}
