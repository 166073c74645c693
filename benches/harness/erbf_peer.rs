//! Our side of the scipy peer comparison (benches/peers/erbf_scipy.sh): writes the shared
//! input (N = 150, n_p = 10, T = 10^4, 1000 queries) as little-endian f64 files, times our
//! fits and predictions, and writes a slice of our predictions for the agreement check.
//!
//! `cargo run --release --example erbf_peer -- <dir> [reps]` (set `ERBF_PEER_VERBOSE=1` to
//! print every timed call to stderr).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::io::Write;
use std::path::Path;
use std::time::Instant;

use faer::MatRef;
use impactcal::erbf::{Erbf, ErbfOptions, RadialFunction, RbfInterpolant, RbfOptions};

#[path = "../common/surrogate_data.rs"]
mod surrogate_data;
use surrogate_data::{M, T, surrogate_data};

/// Untimed calls before the timed ones, so that both sides are measured warm (allocator
/// and page mappings settled).
const WARM_UP: usize = 2;

/// Output columns written for the agreement check.
const CHECK: usize = 8;

fn write_bin(path: &Path, m: MatRef<'_, f64>, cols: usize) {
    let mut w = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    for i in 0..m.nrows() {
        for j in 0..cols {
            w.write_all(&m[(i, j)].to_le_bytes()).unwrap();
        }
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median time of `reps` calls after `WARM_UP` untimed ones (the same on the scipy side).
fn time<R>(reps: usize, mut f: impl FnMut() -> R) -> (f64, R) {
    let mut times = Vec::new();
    for _ in 0..WARM_UP {
        std::hint::black_box(f());
    }
    let mut last = None;
    for _ in 0..reps {
        let t0 = Instant::now();
        let r = f();
        times.push(t0.elapsed().as_secs_f64());
        if std::env::var_os("ERBF_PEER_VERBOSE").is_some() {
            eprintln!("{:.4}", times[times.len() - 1]);
        }
        last = Some(r);
    }
    (median(times), last.unwrap())
}

fn main() {
    let dir = std::env::args()
        .nth(1)
        .expect("usage: erbf_peer <dir> [reps]");
    let reps: usize = std::env::args().nth(2).map_or(5, |s| s.parse().unwrap());
    let dir = Path::new(&dir);
    std::fs::create_dir_all(dir).unwrap();
    let (space, x, f, q) = surrogate_data();
    write_bin(&dir.join("points.bin"), x.as_ref(), M);
    write_bin(&dir.join("values.bin"), f.as_ref(), T);
    write_bin(&dir.join("queries.bin"), q.as_ref(), M);

    let (fit_e, erbf) = time(reps, || {
        Erbf::fit(&space, x.as_ref(), f.as_ref(), ErbfOptions::default()).unwrap()
    });
    let (pred_e, _) = time(reps, || erbf.predict_batch(q.as_ref()).unwrap());
    let one: Vec<f64> = q.row(0).iter().copied().collect();
    let (pred1_e, _) = time(reps * 4, || erbf.predict(&one).unwrap());
    let gauss_opts = RbfOptions::new(RadialFunction::Gaussian { width: 0.15 });
    let (fit_g, gauss) = time(reps, || {
        RbfInterpolant::fit(x.as_ref(), f.as_ref(), gauss_opts).unwrap()
    });
    let (pred_g, yg) = time(reps, || gauss.predict_batch(q.as_ref()).unwrap());
    let (fit_c, cubic) = time(reps, || {
        RbfInterpolant::fit(x.as_ref(), f.as_ref(), RbfOptions::cubic()).unwrap()
    });
    let (pred_c, yc) = time(reps, || cubic.predict_batch(q.as_ref()).unwrap());
    write_bin(&dir.join("ours_gaussian.bin"), yg.as_ref(), CHECK);
    write_bin(&dir.join("ours_cubic.bin"), yc.as_ref(), CHECK);
    println!("ours erbf_fit {fit_e:.6}");
    println!("ours erbf_predict_1000 {pred_e:.6}");
    println!("ours erbf_predict_1 {pred1_e:.6}");
    println!("ours gaussian_fit {fit_g:.6}");
    println!("ours gaussian_predict_1000 {pred_g:.6}");
    println!("ours cubic_fit {fit_c:.6}");
    println!("ours cubic_predict_1000 {pred_c:.6}");
    println!(
        "ours erbf_training_residual {:.3e}",
        erbf.training_residual()
    );
}
