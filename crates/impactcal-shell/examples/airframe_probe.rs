//! Probe: mesh statistics and one airframe run.
#![allow(clippy::unwrap_used, clippy::expect_used)]
use impactcal_shell::Simulation;
use impactcal_shell::airframe::*;
fn main() {
    let mesh = match std::env::args().nth(1).as_deref() {
        Some("fine") => MeshDensity::Fine,
        Some("medium") => MeshDensity::Medium,
        _ => MeshDensity::Coarse,
    };
    let end: f64 = std::env::args()
        .nth(2)
        .map(|s| s.parse().unwrap())
        .unwrap_or(0.08);
    let mut o = AirframeOptions::new(mesh);
    o.end_time = end.max(1e-3);
    let af = Airframe::new(o).unwrap();
    println!(
        "shells {} nodes {} sensors {}",
        af.shell_count(),
        af.node_count(),
        af.sensor_nodes().len()
    );
    for (p, n) in af.part_counts() {
        println!("  {:24} {n}", p.name());
    }
    let v = AirframeValues::nominal();
    let m = af.model(&v).unwrap();
    let s = af.structural_mass(&v).unwrap();
    println!(
        "total mass {:.4} structure {:.4} ballast share {:.3}",
        m.total_mass(),
        s,
        1.0 - s / m.total_mass()
    );
    charlen(&af);
    if end <= 0.0 {
        return;
    }
    std::fs::write("/tmp/af/parts.svg", af.parts_svg()).unwrap();
    let t0 = std::time::Instant::now();
    let mut sim = Simulation::new(&m).unwrap();
    println!("dt first {:.3e}", sim.dt());
    let r = sim.run_with_progress(|p| {
        if p.cycle % 2000 == 0 {
            eprintln!("t {:.4} cyc {}", p.time, p.cycle)
        }
    });
    let el = t0.elapsed().as_secs_f64();
    match r {
        Ok(r) => {
            let s = &r.summary;
            println!(
                "wall {el:.2}s cycles {} dt {:.3e}..{:.3e} ratio {:.4} hg share {:.4} peak wall {:.1} us/el-cyc {:.3}",
                s.cycles,
                s.dt_min,
                s.dt_max,
                s.energy_ratio,
                s.hourglass_share,
                s.peak_wall_force,
                el * 1e6 / (s.cycles as f64 * s.elements as f64)
            );
            println!("{:?}", s.energies);
            let q = r.velocity.as_ref().unwrap().norm_history();
            let k = q.len();
            println!(
                "Q: {:?}",
                (0..k)
                    .step_by(k / 16)
                    .map(|i| q[i].round())
                    .collect::<Vec<_>>()
            );
        }
        Err(e) => println!("FAILED after {el:.2}s: {e}"),
    }
}
#[allow(dead_code)]
pub fn charlen(af: &Airframe) {
    let x = af.node_positions();
    let mut best: std::collections::BTreeMap<&str, (f64, u64)> = Default::default();
    for (k, (n, p)) in af.shells().enumerate() {
        let q: Vec<[f64; 3]> = n.iter().map(|&i| x[i as usize - 1]).collect();
        let d = |a: [f64; 3], b: [f64; 3]| {
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        };
        let cr = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| {
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let w = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            0.5 * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt()
        };
        let l = if n[2] == n[3] {
            let a = cr(q[0], q[1], q[2]);
            2.0 * a / d(q[0], q[1]).max(d(q[1], q[2])).max(d(q[2], q[0]))
        } else {
            let a = cr(q[0], q[1], q[2]) + cr(q[0], q[2], q[3]);
            let m = [
                d(q[0], q[1]),
                d(q[1], q[2]),
                d(q[2], q[3]),
                d(q[3], q[0]),
                d(q[0], q[2]),
                d(q[1], q[3]),
            ]
            .iter()
            .cloned()
            .fold(0.0, f64::max);
            a / m
        };
        let e = best.entry(p.name()).or_insert((f64::INFINITY, 0));
        if l < e.0 {
            *e = (l, k as u64 + 1);
        }
    }
    for (k, v) in best {
        println!("  charlen {k:24} {:.3} (shell {})", v.0, v.1);
    }
}
