//! The Los Alamos copper record through the classic analysis and the bar model: the
//! figures behind docs/kolsky.md and the Kolsky section of docs/validation.md.
//!
//! `cargo run --release -p impactcal-models --example kolsky_copper`
//!
//! With `-- neutral DIR`: only the record converted and written in the neutral form
//! (`DIR/copper.toml` and `DIR/copper-signals.csv`, what examples/kolsky/ holds).
//!
//! With `-- timing N`: only N runs of the plain and the dispersed model at one point, with
//! the wall time per run (run it under `/usr/bin/time -v` for the CPU time).
//!
//! The model's fits here are a plain Nelder-Mead search on the relative L2 error of both
//! signals (a sanity check of the model against the record, not the closed loop's
//! calibration): the plain model with its nuisance terms, then with dispersion held on.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use impactcal_core::enrich::rebuild;
use impactcal_core::testdata::LanlBarRecord;
use impactcal_core::{Histories, Model};
use impactcal_models::kolsky::{ClassicAnalysis, GainRow, KolskyModel, LanlOptions, from_lanl};

fn rel_l2(model: &[f64], test: &[f64]) -> f64 {
    let num: f64 = model.iter().zip(test).map(|(m, t)| (m - t).powi(2)).sum();
    let den: f64 = test.iter().map(|t| t * t).sum();
    (num / den).sqrt()
}

fn errors(h: &Histories, m: &Histories) -> (f64, f64) {
    (
        rel_l2(h.channel(0), m.channel(0)),
        rel_l2(h.channel(1), m.channel(1)),
    )
}

/// Nelder-Mead on the box of `model`'s space (coordinates scaled to [0, 1]).
fn fit(model: &KolskyModel, start: &[f64], measured: &Histories, evals: usize) -> (Vec<f64>, f64) {
    let space = model.space();
    let lo: Vec<f64> = space.parameters().iter().map(|p| p.lower).collect();
    let hi: Vec<f64> = space.parameters().iter().map(|p| p.upper).collect();
    let d = lo.len();
    let to = |u: &[f64]| -> Vec<f64> {
        (0..d)
            .map(|i| lo[i] + u[i].clamp(0.0, 1.0) * (hi[i] - lo[i]))
            .collect()
    };
    let cost = |u: &[f64]| -> f64 {
        match model.simulate(&to(u)) {
            Ok(h) => {
                let (r, t) = errors(&h, measured);
                (r * r + t * t).sqrt()
            }
            Err(_) => f64::INFINITY,
        }
    };
    let u0: Vec<f64> = (0..d)
        .map(|i| (start[i] - lo[i]) / (hi[i] - lo[i]))
        .collect();
    let mut simplex: Vec<(Vec<f64>, f64)> = (0..=d)
        .map(|j| {
            let mut u = u0.clone();
            if j > 0 {
                u[j - 1] = (u[j - 1] + 0.1).min(1.0);
            }
            let c = cost(&u);
            (u, c)
        })
        .collect();
    let mut n = d + 1;
    while n < evals {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let centroid: Vec<f64> = (0..d)
            .map(|i| simplex[..d].iter().map(|s| s.0[i]).sum::<f64>() / d as f64)
            .collect();
        let worst = simplex[d].clone();
        let along = |t: f64| -> Vec<f64> {
            (0..d)
                .map(|i| (centroid[i] + t * (worst.0[i] - centroid[i])).clamp(0.0, 1.0))
                .collect()
        };
        let r = along(-1.0);
        let fr = cost(&r);
        n += 1;
        if fr < simplex[0].1 {
            let e = along(-2.0);
            let fe = cost(&e);
            n += 1;
            simplex[d] = if fe < fr { (e, fe) } else { (r, fr) };
        } else if fr < simplex[d - 1].1 {
            simplex[d] = (r, fr);
        } else {
            let c = along(0.5);
            let fc = cost(&c);
            n += 1;
            if fc < worst.1 {
                simplex[d] = (c, fc);
            } else {
                let best = simplex[0].0.clone();
                for s in simplex.iter_mut().skip(1) {
                    s.0 = (0..d).map(|i| best[i] + 0.5 * (s.0[i] - best[i])).collect();
                    s.1 = cost(&s.0);
                    n += 1;
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    (to(&simplex[0].0), simplex[0].1)
}

fn main() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/kolsky/20061201_1148HE_CuOFE_273K.raw"
    );
    let record = LanlBarRecord::read(path).unwrap();
    let conv = from_lanl(&record, &LanlOptions::default()).unwrap();
    for n in &conv.notes {
        println!("note: {n}");
    }
    let test = conv.test;
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).map(String::as_str) == Some("neutral") {
        let dir = args.get(2).expect("neutral DIR");
        let written = test.write(dir, "copper").unwrap();
        println!("wrote {}", written.display());
        return;
    }
    if args.get(1).map(String::as_str) == Some("timing") {
        let n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(2000);
        let model = KolskyModel::new(&test).unwrap();
        let mut names: Vec<String> = model
            .space()
            .names()
            .iter()
            .map(|s| s.to_string())
            .collect();
        names.push("dispersion".into());
        let dispersed = rebuild(&model, &names, &[]).unwrap();
        let p = [60.0, 450.0, 0.45, 40.0, 4865.9, 0.0, 0.0, 1.0];
        dispersed.simulate(&p).unwrap();
        for (what, m, q) in [
            ("plain", &model, &p[..7]),
            ("dispersion", &dispersed, &p[..]),
        ] {
            let t0 = std::time::Instant::now();
            for _ in 0..n {
                std::hint::black_box(m.simulate(q).unwrap());
            }
            println!(
                "{what}: {:.1} us per run (wall, {n} runs)",
                t0.elapsed().as_secs_f64() / n as f64 * 1e6
            );
        }
        return;
    }
    let a = ClassicAnalysis::of(&test).unwrap();
    let cal = LanlOptions {
        transmitted_gain: GainRow::Calibrated,
        ..LanlOptions::default()
    };
    let b = ClassicAnalysis::of(&from_lanl(&record, &cal).unwrap().test).unwrap();
    let peak = |v: &[f64]| v.iter().fold(0.0_f64, |m, x| m.max(*x));
    let (et, st) = a.true_curve();
    println!(
        "classic: resampled {:?}; equilibrium {:.3} (gain 200), {:.3} (gain 500); peak \
         three-wave stress {:.1} MPa, final engineering strain {:.3} (true {:.3}); true stress \
         at mid-window {:.1} MPa; peak strain rate {:.0}/s",
        a.resampling,
        a.equilibrium,
        b.equilibrium,
        peak(&a.stress_three) / 1e6,
        a.strain_three.last().unwrap(),
        et.last().unwrap(),
        st[st.len() / 2] / 1e6,
        peak(&a.rate_three)
    );
    let model = KolskyModel::new(&test).unwrap();
    let measured = model.measured().unwrap();
    let start = [
        60.0,
        450.0,
        0.45,
        40.0,
        test.incident.wave_speed(),
        0.0,
        0.0,
    ];
    let t0 = std::time::Instant::now();
    let (p, _) = fit(&model, &start, &measured, 3000);
    let (r, t) = errors(&model.simulate(&p).unwrap(), &measured);
    println!(
        "plain model fitted ({:.1} s): reflected {:.1} %, transmitted {:.1} %; A {:.1} MPa, \
         B {:.1} MPa, n {:.3}, E_s {:.1} GPa, c {:.1} m/s, delays {:.2} / {:.2} us",
        t0.elapsed().as_secs_f64(),
        100.0 * r,
        100.0 * t,
        p[0],
        p[1],
        p[2],
        p[3],
        p[4],
        p[5],
        p[6]
    );
    let mut names: Vec<String> = model
        .space()
        .names()
        .iter()
        .map(|s| s.to_string())
        .collect();
    names.push("dispersion".into());
    let dispersed = rebuild(&model, &names, &[]).unwrap();
    let mut s2 = p.clone();
    s2.push(1.0);
    let (q, _) = fit(&dispersed, &s2, &measured, 3000);
    let (r2, t2) = errors(&dispersed.simulate(&q).unwrap(), &measured);
    println!(
        "with dispersion (fraction {:.2}): reflected {:.1} %, transmitted {:.1} %; A {:.1} MPa, \
         B {:.1} MPa, n {:.3}, E_s {:.1} GPa, c {:.1} m/s, delays {:.2} / {:.2} us",
        q[7],
        100.0 * r2,
        100.0 * t2,
        q[0],
        q[1],
        q[2],
        q[3],
        q[4],
        q[5],
        q[6]
    );
}
