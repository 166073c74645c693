//! The time step of a deck's run, cycle by cycle: which shell sets it, that shell's part,
//! area, longest side and longest diagonal, and what the step would be under each of the
//! characteristic-length rules on the same geometry.
//!
//! ```text
//! cargo run --release -p impactcal-shell --example step_log -- DECK [EVERY [SHELL]] > log.csv
//! ```
//!
//! With SHELL (an element id), the printed lines are followed (on stderr) by that shell's
//! nodal coordinates, its warp (the distance of the corners from the plane of the mean
//! normal, over the longest side) and its normal.
//!
//! Every cycle is examined; one line in EVERY (default 100) is printed, and the summary on
//! stderr integrates over all cycles: the cycles each rule would have needed on this run's
//! geometry (`sum dt / (dt_rule / dt)`, i.e. the time divided by that rule's step, cycle by
//! cycle), and how often the diagonal, rather than the longest side, set the length of the
//! controlling shell. Rules (area `A` of the quad, `s` its longest side, `d` its longest
//! diagonal; triangles `2A / s` in every rule): `side` = `A / s` (LS-DYNA's ISDO 0 as its
//! manuals state it), `max` = `A / max(s, d)`, `min` = `A / min(s, d)`, `diag` = `A / d`
//! (ISDO 1).

use std::collections::HashMap;
use std::process::ExitCode;

use impactcal_shell::Simulation;
use impactcal_shell::keyword::read_deck;

/// Area, longest side and longest diagonal of a shell at positions `x` (a triangle has
/// `x[3] == x[2]` and no diagonal).
fn lengths(x: &[[f64; 3]; 4], triangle: bool) -> (f64, f64, f64) {
    lengths_in(x, triangle, false)
}

/// As [`lengths`], with the sides measured in 3D or, `projected`, in the plane normal to
/// the cross product of the diagonals (where the element's strains live).
fn lengths_in(x: &[[f64; 3]; 4], triangle: bool, projected: bool) -> (f64, f64, f64) {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let norm = |a: [f64; 3]| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    if triangle {
        let area = 0.5 * norm(cross(sub(x[1], x[0]), sub(x[2], x[0])));
        let side = norm(sub(x[1], x[0]))
            .max(norm(sub(x[2], x[1])))
            .max(norm(sub(x[0], x[2])));
        return (area, side, 0.0);
    }
    let d13 = sub(x[2], x[0]);
    let d24 = sub(x[3], x[1]);
    let area = 0.5 * norm(cross(d13, d24));
    let n = cross(d13, d24);
    let nn = norm(n);
    let flat = |a: [f64; 3]| {
        if !projected {
            return a;
        }
        let h = (a[0] * n[0] + a[1] * n[1] + a[2] * n[2]) / (nn * nn);
        [a[0] - h * n[0], a[1] - h * n[1], a[2] - h * n[2]]
    };
    let side = (0..4)
        .map(|k| norm(flat(sub(x[(k + 1) % 4], x[k]))))
        .fold(0.0, f64::max);
    (area, side, norm(d13).max(norm(d24)))
}

/// Prints shell `id`'s corners at positions `x`, its warp and its normal.
fn trace(id: u64, x: &[[f64; 3]; 4], time: f64) {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let (d13, d24) = (sub(x[2], x[0]), sub(x[3], x[1]));
    let n = [
        d13[1] * d24[2] - d13[2] * d24[1],
        d13[2] * d24[0] - d13[0] * d24[2],
        d13[0] * d24[1] - d13[1] * d24[0],
    ];
    let nn = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let n = n.map(|c| c / nn);
    let c: [f64; 3] = std::array::from_fn(|k| x.iter().map(|p| p[k]).sum::<f64>() / 4.0);
    let warp = x
        .iter()
        .map(|p| {
            let r = sub(*p, c);
            (r[0] * n[0] + r[1] * n[1] + r[2] * n[2]).abs()
        })
        .fold(0.0, f64::max);
    let (_, side, _) = lengths(x, false);
    let f = |p: [f64; 3]| format!("({:.2} {:.2} {:.2})", p[0], p[1], p[2]);
    eprintln!(
        "t {time:.5e} shell {id}: {} {} {} {}; warp/side {:.3}; normal {}",
        f(x[0]),
        f(x[1]),
        f(x[2]),
        f(x[3]),
        warp / side,
        f(n)
    );
}

const RULES: [&str; 5] = ["side", "max", "min", "diag", "projected_max"];

/// The characteristic length of each rule.
fn rule_lengths(area: f64, side: f64, diag: f64, flat_side: f64, triangle: bool) -> [f64; 5] {
    if triangle {
        return [2.0 * area / side; 5];
    }
    [
        area / side,
        area / side.max(diag),
        area / side.min(diag),
        area / diag,
        area / flat_side.max(diag),
    ]
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else {
        eprintln!("usage: step_log DECK [EVERY]");
        return ExitCode::FAILURE;
    };
    let every: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(100);
    let traced: Option<u64> = args.get(3).and_then(|s| s.parse().ok());
    let deck = match read_deck(path) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    let model = deck.model;
    let mut sim = match Simulation::new(&model) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    let index: HashMap<u64, usize> = sim
        .node_ids()
        .iter()
        .enumerate()
        .map(|(i, &n)| (n, i))
        .collect();
    // Plate wave speed of each shell, from its part's material; rigid parts set no step.
    let speed: Vec<Option<f64>> = model
        .shells
        .iter()
        .map(|s| {
            let part = model.parts.iter().find(|p| p.id == s.part)?;
            let m = model.materials.iter().find(|m| m.id == part.material)?;
            if matches!(m.law, impactcal_shell::MaterialLaw::Rigid { .. }) {
                return None;
            }
            Some((m.youngs / (m.density * (1.0 - m.poisson * m.poisson))).sqrt())
        })
        .collect();
    let tssfac = model.control.tssfac;
    let mut cycles_by_rule = [0.0f64; 5];
    let mut diagonal_binds = 0u64;
    let mut mismatch = 0.0f64;
    println!(
        "cycle,time,dt,shell,part,area,longest_side,longest_diagonal,{}",
        RULES.map(|r| format!("dt_{r}")).join(",")
    );
    loop {
        let dt = sim.dt();
        let x = sim.positions();
        let mut best = [(f64::INFINITY, 0usize); 5];
        for (e, s) in model.shells.iter().enumerate() {
            let Some(c) = speed[e] else { continue };
            let tri = s.is_triangle();
            let p = s.nodes.map(|n| x[index[&n]]);
            let (a, side, diag) = lengths(&p, tri);
            let flat_side = lengths_in(&p, tri, true).1;
            for (k, l) in rule_lengths(a, side, diag, flat_side, tri)
                .iter()
                .enumerate()
            {
                let dte = l / c;
                if dte < best[k].0 {
                    best[k] = (dte, e);
                }
            }
        }
        // `max` is the rule the solver uses: its step must be TSSFAC times that minimum.
        mismatch = mismatch.max((tssfac * best[1].0 / dt - 1.0).abs());
        for k in 0..5 {
            cycles_by_rule[k] += dt / (tssfac * best[k].0);
        }
        let e = best[1].1;
        let s = &model.shells[e];
        let p = s.nodes.map(|n| x[index[&n]]);
        let (a, side, diag) = lengths(&p, s.is_triangle());
        if !s.is_triangle() && diag > side {
            diagonal_binds += 1;
        }
        if sim.cycle() % every == 0 {
            println!(
                "{},{:.6e},{:.6e},{},{},{:.6e},{:.6e},{:.6e},{}",
                sim.cycle(),
                sim.time(),
                dt,
                s.id,
                s.part,
                a,
                side,
                diag,
                best.map(|b| format!("{:.6e}", tssfac * b.0)).join(",")
            );
            if let Some(t) = traced.and_then(|t| model.shells.iter().find(|s| s.id == t)) {
                trace(t.id, &t.nodes.map(|n| x[index[&n]]), sim.time());
            }
        }
        if sim.time() >= model.control.end_time {
            break;
        }
        if let Err(e) = sim.step() {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    }
    eprintln!(
        "cycles {} to t = {:.6e}; the solver's step = TSSFAC x the max-rule minimum to {:.1e}",
        sim.cycle(),
        sim.time(),
        mismatch
    );
    for (k, r) in RULES.iter().enumerate() {
        eprintln!("rule {r}: cycles on this geometry {:.0}", cycles_by_rule[k]);
    }
    eprintln!(
        "the controlling shell's longest diagonal exceeded its longest side in {} of {} cycles",
        diagonal_binds,
        sim.cycle()
    );
    ExitCode::SUCCESS
}
