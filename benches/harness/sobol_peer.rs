//! Our side of benches/peers/sobol_salib.py: the plain Sobol' Saltelli design of `d`
//! parameters on the unit cube (the rows SALib's `sample.sobol(scramble=False)` makes), a
//! time-dependent G-function output with `T` columns, and `analyze` timed over repeats.
//!
//! Usage: cargo run --release --example sobol_peer -- N D T RESAMPLES SECOND_ORDER(0|1) REPEATS
//! Prints one JSON line: medians, peak memory, and the indices of the first columns for the
//! cross-check with SALib.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use faer::MatRef;
use impactcal::core::points::to_rows;
use impactcal::core::sampling::Method;
use impactcal::core::{Parameter, ParameterSpace};
use impactcal::sobol::{SaltelliDesign, SobolOptions, analyze};

/// The output of run `x` at column `t` of `cols`: a G-function whose weights drift with t,
/// identical to `outputs()` in benches/peers/sobol_salib.py.
fn fill_row(x: &[f64], cols: usize, out: &mut [f64]) {
    let a = [0.0, 0.5, 3.0, 9.0, 99.0, 99.0];
    let g: f64 = x
        .iter()
        .enumerate()
        .map(|(i, &xi)| {
            let ai = a.get(i).copied().unwrap_or(99.0);
            ((4.0 * xi - 2.0).abs() + ai) / (1.0 + ai)
        })
        .product();
    for (t, y) in out.iter_mut().enumerate() {
        let s = t as f64 / cols as f64;
        *y = g * (1.0 + s) + x[0] * s + x[1] * x[2] * (1.0 - s);
    }
}

fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("numeric arguments"))
        .collect();
    let [n, d, cols, resamples, second, repeats] = args[..] else {
        panic!("usage: sobol_peer N D T RESAMPLES SECOND_ORDER REPEATS");
    };
    let space = ParameterSpace::new(
        (0..d)
            .map(|i| Parameter::new(format!("x{}", i + 1), 0.0, 1.0, 0.5).unwrap())
            .collect(),
    )
    .unwrap();
    let design = SaltelliDesign::generate(&space, n, Method::Sobol, second == 1, 0).unwrap();
    let rows = design.points.nrows();
    let mut y = vec![0.0; rows * cols];
    for (x, out) in to_rows(design.points.as_ref())
        .iter()
        .zip(y.chunks_exact_mut(cols))
    {
        fill_row(x, cols, out);
    }
    let options = SobolOptions {
        bootstrap: resamples,
        seed: 1,
        ..SobolOptions::default()
    };
    let mut times = Vec::new();
    let mut result = None;
    for _ in 0..repeats {
        let start = Instant::now();
        let s = analyze(
            &design.layout,
            MatRef::from_row_major_slice(&y, rows, cols),
            &options,
        )
        .unwrap();
        times.push(start.elapsed().as_secs_f64());
        result = Some(s);
    }
    times.sort_by(f64::total_cmp);
    let s = result.unwrap();
    let show = cols.min(10);
    let line = serde_json::json!({
        "median_s": times[times.len() / 2],
        "times_s": times,
        "rows": rows,
        "cols": cols,
        "threads": rayon::current_num_threads(),
        "output_bytes": rows * cols * 8,
        "peak_rss_bytes": peak_rss_bytes(),
        "first_order": &s.first_order[..show],
        "total": &s.total[..show],
        "second_order": s.second_order.as_ref().map(|m| m[..show].to_vec()),
    });
    println!("{line}");
}
