//! Our side of the scipy peer comparison (benches/peers/erbf_scipy.sh): writes the shared
//! input (N = 150, n_p = 10, T = 10^4, 1000 queries) as little-endian f64 files, times our
//! fits and predictions, and writes a slice of our predictions for the agreement check.
//!
//! With a third argument, the directory of an airframe ensemble written by the
//! `airframe_ensemble` example, it also times the surrogates on it (the last
//! `AIRFRAME_HELD_OUT` runs held out).
//!
//! The impact-shape basis (`--basis shapes`) is timed as a user meets it: fit with the shape
//! count chosen automatically, then 1000 predictions of whole histories (rebuilt from the
//! predicted coordinates); held-out errors are `||prediction - truth||_F / ||truth - mean||_F`.
//! The fit takes ownership of one name per output (28,836 on the airframe); the harness
//! clones them before each timed call, off the clock.
//!
//! `cargo run --release --example erbf_peer -- <dir> [reps] [airframe-dir]` (set
//! `ERBF_PEER_VERBOSE=1` to print every timed call to stderr, `ERBF_PEER_DEFAULT_POOL=1` to
//! keep rayon's default global pool instead of making the main thread one of its workers).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::io::Write;
use std::path::Path;
use std::time::Instant;

use faer::{Mat, MatRef};
use impactcal::core::{Parameter, ParameterSpace};
use impactcal::erbf::{
    Erbf, ErbfOptions, FitOptions, LooMethod, OutputBasis, RadialFunction, RbfInterpolant,
    RbfOptions, ResponseSurrogate, ShapeSpectrum, SurrogateKind, SurrogateModel, Tuning,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[path = "../common/surrogate_data.rs"]
mod surrogate_data;
use surrogate_data::{M, T, family, surrogate_data};

/// Runs of the airframe ensemble held out for the accuracy check.
const AIRFRAME_HELD_OUT: usize = 8;

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
    time_with(reps, || (), |()| f())
}

/// As [`time`], for a call that consumes its input: `setup` makes a fresh one before each
/// call, off the clock (the output names, and the outputs, a fit takes ownership of, which
/// a program holds already; scipy takes none).
fn time_with<I, R>(
    reps: usize,
    mut setup: impl FnMut() -> I,
    mut f: impl FnMut(I) -> R,
) -> (f64, R) {
    let mut times = Vec::new();
    for _ in 0..WARM_UP {
        std::hint::black_box(f(setup()));
    }
    let mut last = None;
    for _ in 0..reps {
        let input = setup();
        let t0 = Instant::now();
        let r = f(input);
        times.push(t0.elapsed().as_secs_f64());
        if std::env::var_os("ERBF_PEER_VERBOSE").is_some() {
            eprintln!("{:.4}", times[times.len() - 1]);
        }
        last = Some(r);
    }
    (median(times), last.unwrap())
}

/// `||a - b||_F / ||b - mean(b)||_F` (row means of `b` taken over its rows).
fn held_out_error(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> f64 {
    let (n, t) = b.shape();
    let (mut num, mut den) = (0.0, 0.0);
    for j in 0..t {
        let mean = b.col(j).iter().sum::<f64>() / n as f64;
        for i in 0..n {
            num += (a[(i, j)] - b[(i, j)]).powi(2);
            den += (b[(i, j)] - mean).powi(2);
        }
    }
    (num / den).sqrt()
}

fn read_bin(path: &Path, nrows: usize, ncols: usize) -> Mat<f64> {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(bytes.len(), nrows * ncols * 8, "{}", path.display());
    Mat::from_fn(nrows, ncols, |i, j| {
        let k = (i * ncols + j) * 8;
        f64::from_le_bytes(bytes[k..k + 8].try_into().unwrap())
    })
}

fn shapes_options(kind: SurrogateKind) -> FitOptions {
    FitOptions {
        kind,
        basis: OutputBasis::Shapes { count: None },
        tuning: Tuning::Off,
        ..FitOptions::default()
    }
}

fn shape_count(s: &ResponseSurrogate) -> usize {
    match s.model() {
        SurrogateModel::Components(c) => c.basis().map_or(0, |b| b.len()),
        _ => 0,
    }
}

/// Times the shape-basis cubic RBF and ERBF (fit + `q` predictions) and prints their
/// held-out errors on (`xh`, `fh`), under `prefix`.
#[allow(clippy::too_many_arguments)]
fn shape_cases(
    prefix: &str,
    reps: usize,
    space: &ParameterSpace,
    x: MatRef<'_, f64>,
    f: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    xh: MatRef<'_, f64>,
    fh: MatRef<'_, f64>,
) {
    let names: Vec<String> = (0..f.ncols()).map(|t| format!("y{t}")).collect();
    bounds(prefix, reps, q.nrows(), f);
    for (label, kind) in [
        ("shapes_cubic", SurrogateKind::Cubic),
        ("shapes_erbf", SurrogateKind::Erbf),
    ] {
        let options = shapes_options(kind);
        // A program that has read its ensemble gives it to the fit, as it gives the names;
        // the borrowed fit, which copies the outputs into the model, is reported beside it.
        let (fit, model) = time_with(
            reps,
            || (names.clone(), f.to_owned()),
            |(names, values)| {
                ResponseSurrogate::fit_with(space, x, values, names, &options).unwrap()
            },
        );
        let (fit_borrowed, _) = time_with(
            reps,
            || names.clone(),
            |names| ResponseSurrogate::fit_with(space, x, f, names, &options).unwrap(),
        );
        let (pred, _) = time(reps, || model.predict_batch(q).unwrap());
        let SurrogateModel::Components(components) = model.model() else {
            panic!("a shape-basis fit gives a component model");
        };
        let (coords, _) = time(reps, || components.predict_coordinates(q).unwrap());
        let err = held_out_error(model.predict_batch(xh).unwrap().as_ref(), fh);
        println!("ours {prefix}{label}_coordinates_1000 {coords:.6}");
        println!("ours {prefix}{label}_fit {fit:.6}");
        println!("ours {prefix}{label}_fit_borrowed {fit_borrowed:.6}");
        println!("ours {prefix}{label}_predict_1000 {pred:.6}");
        println!("ours {prefix}{label}_held_out {err:.6e}");
        println!("ours {prefix}{label}_count {}", shape_count(&model));
        println!(
            "ours {prefix}{label}_training_residual {:.3e}",
            model.training_residual()
        );
    }
    for (label, kind) in [
        ("full_cubic", SurrogateKind::Cubic),
        ("full_erbf", SurrogateKind::Erbf),
    ] {
        let model = ResponseSurrogate::fit(space, kind, x, f, names.clone()).unwrap();
        let err = held_out_error(model.predict_batch(xh).unwrap().as_ref(), fh);
        println!("ours {prefix}{label}_held_out {err:.6e}");
    }
}

/// The steps of a shape-basis cubic fit, timed one by one (medians): the spectrum of the
/// deviations (mean, Gram matrix and eigenproblem; or, for a large ensemble of low rank,
/// sketch, projection and time functions of every shape), the time functions of the kept
/// shapes (a copy when the spectrum made them), the coordinate surrogate with its
/// leave-one-out errors, and the coordinate prediction.
fn shape_phases(
    prefix: &str,
    reps: usize,
    space: &ParameterSpace,
    x: MatRef<'_, f64>,
    f: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
) {
    let (spectrum_t, spectrum) = time(reps, || ShapeSpectrum::new(f).unwrap());
    let coords = spectrum.coordinates();
    let unit = space.to_unit_matrix(x).unwrap();
    let (surrogate_t, (model, loo)) = time(reps, || {
        let model =
            RbfInterpolant::fit(unit.as_ref(), coords.as_ref(), RbfOptions::cubic()).unwrap();
        let loo = model.loo_errors(LooMethod::Closed).unwrap();
        (model, loo)
    });
    let energy: Vec<f64> = (0..loo.ncols())
        .map(|c| loo.col(c).iter().map(|e| e * e).sum())
        .collect();
    let k = impactcal::erbf::shape_basis::choose_count(spectrum.singular_values(), &energy);
    let (basis_t, _) = time(reps, || spectrum.basis(f, k).unwrap());
    let uq = space.to_unit_matrix(q).unwrap();
    let (predict_t, _) = time(reps, || model.predict_batch(uq.as_ref()).unwrap());
    println!("ours {prefix}phase_spectrum {spectrum_t:.6}");
    println!("ours {prefix}phase_coordinate_fit_loo {surrogate_t:.6}");
    println!("ours {prefix}phase_time_functions {basis_t:.6}");
    println!("ours {prefix}phase_coordinate_predict {predict_t:.6}");
    println!(
        "ours {prefix}phase_rank {}",
        spectrum.singular_values().len()
    );
}

/// What any prediction of `q` whole histories costs at least: writing the `q x T` result
/// (a fresh buffer, as a prediction allocates it), and the `q x N x T` product of the
/// full-history surrogates (`V^T F`, the step after the basis evaluation).
fn bounds(prefix: &str, reps: usize, q: usize, f: MatRef<'_, f64>) {
    let (n, t) = f.shape();
    let (write, _) = time(reps, || impactcal::erbf::buffer::zeros(q, t));
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let v = Mat::from_fn(n, q, |_, _| rng.random::<f64>());
    let (product, _) = time(reps, || {
        let mut out = impactcal::erbf::buffer::zeros(q, t);
        faer::linalg::matmul::matmul(
            out.as_mut(),
            faer::Accum::Replace,
            v.transpose(),
            f,
            1.0,
            faer::get_global_parallelism(),
        );
        out
    });
    println!("ours {prefix}bound_write_1000 {write:.6}");
    println!("ours {prefix}bound_product_1000 {product:.6}");
}

fn main() {
    if std::env::var_os("ERBF_PEER_DEFAULT_POOL").is_none() {
        // This thread is one of the pool's workers, as numpy's calling thread is one of
        // OpenBLAS's: with rayon's default pool, its workers and this thread are three on
        // two processors, and the scheduler at times leaves both workers on one of them
        // (docs/performance.md, "The calling thread as a worker").
        rayon::ThreadPoolBuilder::new()
            .use_current_thread()
            .build_global()
            .unwrap();
    }
    let dir = std::env::args()
        .nth(1)
        .expect("usage: erbf_peer <dir> [reps] [airframe-dir]");
    let reps: usize = std::env::args().nth(2).map_or(5, |s| s.parse().unwrap());
    let airframe = std::env::args().nth(3);
    let dir = Path::new(&dir);
    std::fs::create_dir_all(dir).unwrap();
    let (space, x, f, q) = surrogate_data();
    write_bin(&dir.join("points.bin"), x.as_ref(), M);
    write_bin(&dir.join("values.bin"), f.as_ref(), T);
    write_bin(&dir.join("queries.bin"), q.as_ref(), M);
    // Held-out runs of the same family for the accuracy of both sides.
    let mut rng = ChaCha8Rng::seed_from_u64(4242);
    let xh = Mat::from_fn(100, M, |_, _| rng.random::<f64>());
    let fh = family(&xh);
    write_bin(&dir.join("held_points.bin"), xh.as_ref(), M);
    write_bin(&dir.join("held_values.bin"), fh.as_ref(), T);

    // The outputs handed over off the clock, as to the shape-basis fits; lent, they are
    // copied (timed beside it).
    let (fit_e, erbf) = time_with(
        reps,
        || f.to_owned(),
        |owned| Erbf::fit(&space, x.as_ref(), owned, ErbfOptions::default()).unwrap(),
    );
    let (fit_e_borrowed, _) = time(reps, || {
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
    println!("ours erbf_fit_borrowed {fit_e_borrowed:.6}");
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
    shape_phases("", reps, &space, x.as_ref(), f.as_ref(), q.as_ref());
    shape_cases(
        "",
        reps,
        &space,
        x.as_ref(),
        f.as_ref(),
        q.as_ref(),
        xh.as_ref(),
        fh.as_ref(),
    );
    if let Some(adir) = airframe {
        airframe_cases(Path::new(&adir), reps);
    }
}

/// The airframe ensemble: the last `AIRFRAME_HELD_OUT` runs held out, 1000 uniform queries
/// in the unit cube; shape-basis cubic and ERBF, full-history cubic, Gaussian and ERBF.
fn airframe_cases(adir: &Path, reps: usize) {
    let shape = std::fs::read_to_string(adir.join("airframe_shape.txt")).unwrap();
    let dims: Vec<usize> = shape
        .split_whitespace()
        .map(|s| s.parse().unwrap())
        .collect();
    let (n, m, t) = (dims[0], dims[1], dims[2]);
    let x_all = read_bin(&adir.join("airframe_points.bin"), n, m);
    let f_all = read_bin(&adir.join("airframe_values.bin"), n, t);
    let nf = n - AIRFRAME_HELD_OUT;
    let (x, f) = (x_all.as_ref().subrows(0, nf), f_all.as_ref().subrows(0, nf));
    let (xh, fh) = (
        x_all.as_ref().subrows(nf, AIRFRAME_HELD_OUT),
        f_all.as_ref().subrows(nf, AIRFRAME_HELD_OUT),
    );
    let space = ParameterSpace::new(
        (0..m)
            .map(|j| Parameter::new(format!("p{j}"), 0.0, 1.0, 0.5).unwrap())
            .collect(),
    )
    .unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(77);
    let q = Mat::from_fn(1000, m, |_, _| rng.random::<f64>());
    write_bin(&adir.join("airframe_queries.bin"), q.as_ref(), m);
    shape_phases("airframe_", reps, &space, x, f, q.as_ref());
    shape_cases("airframe_", reps, &space, x, f, q.as_ref(), xh, fh);
    let (fit_e, erbf) = time_with(
        reps,
        || f.to_owned(),
        |owned| Erbf::fit(&space, x, owned, ErbfOptions::default()).unwrap(),
    );
    let (fit_e_borrowed, _) = time(reps, || {
        Erbf::fit(&space, x, f, ErbfOptions::default()).unwrap()
    });
    let (pred_e, _) = time(reps, || erbf.predict_batch(q.as_ref()).unwrap());
    let (fit_c, cubic) = time(reps, || {
        RbfInterpolant::fit(x, f, RbfOptions::cubic()).unwrap()
    });
    let (pred_c, _) = time(reps, || cubic.predict_batch(q.as_ref()).unwrap());
    println!("ours airframe_erbf_fit {fit_e:.6}");
    println!("ours airframe_erbf_fit_borrowed {fit_e_borrowed:.6}");
    println!("ours airframe_erbf_predict_1000 {pred_e:.6}");
    println!("ours airframe_cubic_fit {fit_c:.6}");
    println!("ours airframe_cubic_predict_1000 {pred_c:.6}");
    println!("ours airframe_n {n}");
    println!("ours airframe_m {m}");
    println!("ours airframe_t {t}");
}
