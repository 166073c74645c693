//! Times impactcal's thin SVD and truncated (randomized) solver on the benchmark matrices and
//! writes the same matrices as raw little-endian f64 (column-major) for the peer script
//! `benches/peers/svd_numpy.sh`, which times numpy on them in the same run.
//!
//! Usage: `cargo run --release --example svd_timing -- OUT_DIR [REPEATS]`. Prints one JSON
//! line per matrix: `{"m":..,"n":..,"full_s":..,"top20_s":..,"file":..}` (median seconds).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::io::Write;
use std::time::Instant;

use impactcal::shapes::{ImpactShapes, ShapeOptions, SvdMethod, Truncation};
#[path = "../common/svd_matrix.rs"]
mod svd_matrix;
use svd_matrix::benchmark_matrix;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn time(repeats: usize, mut f: impl FnMut()) -> f64 {
    median(
        (0..repeats)
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed().as_secs_f64()
            })
            .collect(),
    )
}

fn main() {
    let dir = std::path::PathBuf::from(std::env::args().nth(1).expect("output directory"));
    let repeats: usize = std::env::args().nth(2).map_or(3, |s| s.parse().unwrap());
    std::fs::create_dir_all(&dir).unwrap();
    for (m, n) in [(1215, 1000), (1215, 3000), (12150, 3000)] {
        let y = benchmark_matrix(m, n, 42);
        let file = dir.join(format!("y_{m}x{n}.f64"));
        let mut w = std::io::BufWriter::new(std::fs::File::create(&file).unwrap());
        for j in 0..n {
            for i in 0..m {
                w.write_all(&y[(i, j)].to_le_bytes()).unwrap();
            }
        }
        w.flush().unwrap();
        let reps = if m * n > 10_000_000 { 1 } else { repeats };
        let full_opts = ShapeOptions {
            truncation: Truncation::All,
            method: SvdMethod::Full,
        };
        let full_s = time(reps, || {
            std::hint::black_box(ImpactShapes::from_matrix(y.as_ref(), &full_opts).unwrap());
        });
        let top20_s = time(repeats, || {
            std::hint::black_box(
                ImpactShapes::from_matrix(y.as_ref(), &ShapeOptions::count(20)).unwrap(),
            );
        });
        println!(
            "{{\"m\":{m},\"n\":{n},\"full_s\":{full_s},\"top20_s\":{top20_s},\"file\":\"{}\"}}",
            file.display()
        );
    }
}
