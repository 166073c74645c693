//! An ensemble of coarse airframe crashes for the surrogate comparison
//! (benches/peers/erbf_scipy.sh): `N` runs (40 by default) of a Latin hypercube (seed 7) in
//! the Table 2 thickness box, the velocity histories (x, y, z) of 12 sensor nodes, written as
//! little-endian f64 files that both sides read:
//!
//! - `<dir>/airframe_points.bin`: `N x m` parameter values scaled to the unit cube by the
//!   box (row-major);
//! - `<dir>/airframe_values.bin`: `N x T` histories, channel after channel (row-major);
//! - `<dir>/airframe_shape.txt`: `N m T`.
//!
//! `cargo run --release --example airframe_ensemble -- <dir> [N]`. It takes minutes (a
//! coarse run is several seconds); the peer script runs it once and keeps the files.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::io::Write;

use impactcal::core::sampling::latin_hypercube;
use impactcal::prelude::*;
use impactcal::shell::airframe::{Airframe, AirframeModel, AirframeOptions, MeshDensity, Preset};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dir = std::path::PathBuf::from(args.get(1).expect("usage: airframe_ensemble <dir> [N]"));
    let n: usize = args.get(2).map_or(40, |s| s.parse().unwrap());
    std::fs::create_dir_all(&dir).unwrap();
    let mut options = AirframeOptions::new(MeshDensity::Coarse);
    options.sensors = 12;
    let airframe = Airframe::new(options).unwrap();
    let model = AirframeModel::preset(airframe, Preset::Table2).unwrap();
    let space = model.space().clone();
    let unit = latin_hypercube(n, space.dim(), &mut ChaCha8Rng::seed_from_u64(7)).unwrap();
    let x = space.from_unit_matrix(unit.as_ref()).unwrap();
    let points: Vec<Vec<f64>> = (0..n).map(|i| x.row(i).iter().copied().collect()).collect();
    let started = std::time::Instant::now();
    let batch = model.simulate_batch(&points);
    let runs: Vec<&Histories> = batch.successes().map(|(_, h)| h).collect();
    assert_eq!(runs.len(), n, "every run must succeed");
    let t = runs[0].channels() * runs[0].samples();
    let mut p =
        std::io::BufWriter::new(std::fs::File::create(dir.join("airframe_points.bin")).unwrap());
    let mut v =
        std::io::BufWriter::new(std::fs::File::create(dir.join("airframe_values.bin")).unwrap());
    for (i, h) in runs.iter().enumerate() {
        for value in unit.row(i).iter() {
            p.write_all(&value.to_le_bytes()).unwrap();
        }
        for c in 0..h.channels() {
            for value in h.channel(c) {
                v.write_all(&value.to_le_bytes()).unwrap();
            }
        }
    }
    std::fs::write(
        dir.join("airframe_shape.txt"),
        format!("{n} {} {t}\n", space.dim()),
    )
    .unwrap();
    eprintln!(
        "{n} coarse airframe runs, {} channels x {} samples, in {:.0} s",
        runs[0].channels(),
        runs[0].samples(),
        started.elapsed().as_secs_f64()
    );
}
