//! Exploratory probe (not committed as is).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use impactcal::shell::airframe::{Airframe, AirframeOptions, AirframeValues, MeshDensity};
use impactcal::shell::{
    Hourglass, HourglassForm, MaterialLaw, PartStiffnessDamping, RunResult, ShellModel, Simulation, WallMethod,
};
use rayon::prelude::*;

fn cfc(x: &[f64], dt: f64, cfc: f64) -> Vec<f64> {
    let wd = 2.0 * std::f64::consts::PI * cfc * 2.0775;
    let wa = (wd * dt / 2.0).tan();
    let s2 = std::f64::consts::SQRT_2;
    let den = 1.0 + s2 * wa + wa * wa;
    let a0 = wa * wa / den;
    let (a1, a2) = (2.0 * a0, a0);
    let b1 = -2.0 * (wa * wa - 1.0) / den;
    let b2 = (-1.0 + s2 * wa - wa * wa) / den;
    let n = x.len();
    let pad = 100.min(n - 1);
    let mut y: Vec<f64> = Vec::with_capacity(n + 2 * pad);
    for k in (1..=pad).rev() {
        y.push(2.0 * x[0] - x[k]);
    }
    y.extend_from_slice(x);
    for k in 1..=pad {
        y.push(2.0 * x[n - 1] - x[n - 1 - k]);
    }
    let pass = |y: &mut Vec<f64>| {
        let (mut x1, mut x2) = (y[0], y[0]);
        let (mut y1, mut y2) = (y[0], y[0]);
        for v in y.iter_mut() {
            let x0 = *v;
            let o = a0 * x0 + a1 * x1 + a2 * x2 + b1 * y1 + b2 * y2;
            x2 = x1;
            x1 = x0;
            y2 = y1;
            y1 = o;
            *v = o;
        }
    };
    pass(&mut y);
    y.reverse();
    pass(&mut y);
    y.reverse();
    y[pad..pad + n].to_vec()
}

fn apply(m: &mut ShellModel, spec: &str) {
    for item in spec.split(',').filter(|s| !s.is_empty()) {
        let (k, v) = item.split_once('=').unwrap_or((item, ""));
        match k {
            "hg" => {
                let (f, q) = v.split_once(':').unwrap();
                let q: f64 = q.parse().unwrap();
                m.hourglass = Hourglass {
                    form: if f == "visc" {
                        HourglassForm::Viscous
                    } else {
                        HourglassForm::Stiffness
                    },
                    membrane: q,
                    transverse: q,
                    rotation: q,
                };
            }
            "wall" => {
                if let Some(a) = v.strip_prefix("penalty:") {
                    let (a, z) = a.split_once(':').unwrap_or((a, "0"));
                    m.walls[0].method = WallMethod::Penalty {
                        alpha: a.parse().unwrap(),
                        damping: z.parse().unwrap(),
                    };
                }
            }
            "tssfac" => m.control.tssfac = v.parse().unwrap(),
            "damp" => m.damping = v.parse().unwrap(),
            "bulk" => {
                let (a, b) = v.split_once(':').unwrap_or(("1.5", "0.06"));
                m.bulk_viscosity = Some(impactcal::shell::BulkViscosity {
                    q1: a.parse().unwrap(),
                    q2: b.parse().unwrap(),
                });
            }
            "inn" => m.control.invariant_numbering = true,
            "nowall" => m.walls.clear(),
            "nograv" => m.body_load_z = None,
            "kick" => {
                let (p, vz) = v.split_once(':').unwrap();
                m.initial_velocities.push(impactcal::shell::InitialVelocity::translation(
                    impactcal::shell::VelocityTarget::Part(p.parse().unwrap()),
                    [0.0, 0.0, vz.parse().unwrap()],
                ));
            }
            "fric" => m.walls[0].friction = v.parse().unwrap(),
            "norate" => {
                for mat in &mut m.materials {
                    if let MaterialLaw::Plastic { rate, .. } = &mut mat.law {
                        *rate = None;
                    }
                }
            }
            "elastic" => {
                for mat in &mut m.materials {
                    mat.law = MaterialLaw::Elastic;
                }
            }
            "sd" => {
                let c: f64 = v.parse().unwrap();
                m.stiffness_damping = m
                    .parts
                    .iter()
                    .map(|p| PartStiffnessDamping { part: p.id, coef: c })
                    .collect();
            }
            "hgw" => m.hourglass.transverse = v.parse().unwrap(),
            "hgm" => m.hourglass.membrane = v.parse().unwrap(),
            "hgb" => m.hourglass.rotation = v.parse().unwrap(),
            _ => panic!("unknown {k}"),
        }
    }
}

struct Run {
    r: RunResult,
    /// Full nodal velocities every 1 ms.
    snaps: Vec<Vec<[f64; 3]>>,
    xs: Vec<Vec<[f64; 3]>>,
    pe: Vec<Vec<impactcal::shell::PartEnergies>>,
    mass: Vec<f64>,
}

fn run(af: &Airframe, values: &AirframeValues, spec: &str) -> Run {
    let mut m = af.model(values).unwrap();
    apply(&mut m, spec);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let r = pool.install(|| Simulation::new(&m).unwrap().run().unwrap());
    if std::env::var("PROBE_SNAP").is_err() {
        return Run { r, snaps: Vec::new(), xs: Vec::new(), pe: Vec::new(), mass: Vec::new() };
    }
    let mut mass = Vec::new();
    let mut xs = Vec::new();
    let mut pe = Vec::new();
    let snaps = pool.install(|| {
        let mut sim = Simulation::new(&m).unwrap();
        mass = sim.masses().to_vec();
        let mut out = vec![sim.velocities().to_vec()];
        xs.push(sim.positions().to_vec());
        let mut next = 1e-3;
        while sim.time() < m.control.end_time {
            sim.step().unwrap();
            if sim.time() >= next {
                out.push(sim.velocities().to_vec());
                xs.push(sim.positions().to_vec());
                pe.push(sim.part_energies());
                next += 1e-3;
            }
        }
        out
    });
    Run { r, snaps, xs, pe, mass }
}

fn filtered(r: &RunResult, c: f64) -> Vec<Vec<f64>> {
    let h = r.velocity.as_ref().unwrap();
    (0..h.channels())
        .map(|i| {
            if c > 0.0 {
                cfc(h.channel(i), h.dt(), c)
            } else {
                h.channel(i).to_vec()
            }
        })
        .collect()
}

fn rel(a: &[Vec<f64>], b: &[Vec<f64>], upto: usize) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        for k in 0..upto.min(x.len()) {
            num += (x[k] - y[k]).powi(2);
            den += x[k] * x[k];
        }
    }
    (num / den).sqrt()
}

fn rel_at(a: &[Vec<f64>], b: &[Vec<f64>], k: usize) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        num += (x[k] - y[k]).powi(2);
        den += x[k] * x[k];
    }
    (num / den).sqrt()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let end: f64 = args[1].parse().unwrap();
    let spec = args.get(2).cloned().unwrap_or_default();
    let perturb: Vec<String> = args[3..].to_vec();
    let mesh = MeshDensity::parse(&std::env::var("PROBE_MESH").unwrap_or("coarse".into())).unwrap();
    let mut o = AirframeOptions::new(mesh);
    o.end_time = end;
    let af = Airframe::new(o).unwrap();
    let mut nominal = AirframeValues::nominal();
    if let Ok(base) = std::env::var("PROBE_BASE") {
        for a in base.split(',').filter(|s| !s.is_empty()) {
            nominal.assign(a).unwrap();
        }
    }
    let mut jobs: Vec<(String, AirframeValues, String)> =
        vec![("nominal".into(), nominal.clone(), spec.clone())];
    for p in &perturb {
        let mut v = nominal.clone();
        let mut s = spec.clone();
        if let Some(t) = p.strip_prefix("spec:") {
            s = format!("{spec},{t}");
        } else if let Some((n, f)) = p.split_once("*=") {
            let x = v.get(n).unwrap();
            v.set(n, x * f.parse::<f64>().unwrap()).unwrap();
        } else {
            v.assign(p).unwrap();
        }
        jobs.push((p.clone(), v, s));
    }
    let mut tri = std::collections::BTreeMap::new();
    for (n, p) in af.shells() {
        let e = tri.entry(p.name()).or_insert((0, 0));
        e.0 += 1;
        if n[3] == n[2] {
            e.1 += 1;
        }
    }
    eprintln!("shells (triangles) by part: {tri:?}");
    let t0 = std::time::Instant::now();
    let runs: Vec<Run> = jobs.par_iter().map(|(_, v, s)| run(&af, v, s)).collect();
    eprintln!("wall {:.1} s", t0.elapsed().as_secs_f64());
    let base = &runs[0];
    let e = base.r.summary.energies;
    println!(
        "spec [{spec}] end {end}: KE0 {:.0} KE {:.0} IE {:.0} HG {:.0} ({:.1}%) contact {:.0} fric {:.0} damp {:.0} ext {:.0} err {:.2}% cycles {}",
        e.initial,
        e.kinetic,
        e.internal,
        e.hourglass,
        100.0 * e.hourglass / e.internal,
        e.contact,
        e.friction,
        e.damping,
        e.external_work,
        100.0 * (e.total() - e.initial - e.external_work) / e.initial,
        base.r.summary.cycles
    );
    let hgp: Vec<String> = base
        .r
        .parts
        .iter()
        .map(|p| format!("{}:{:.0}%", p.part, 100.0 * p.hourglass / p.internal.max(1e-9)))
        .collect();
    println!("  hourglass/internal by part: {}", hgp.join(" "));
    let fb = filtered(&base.r, 60.0);
    let rb = filtered(&base.r, 0.0);
    let n = fb[0].len();
    for (j, r) in runs.iter().enumerate().skip(1) {
        let f = filtered(&r.r, 60.0);
        let raw = filtered(&r.r, 0.0);
        let marks: Vec<String> = [0.01, 0.02, 0.03, 0.04, 0.06, 0.08]
            .iter()
            .filter(|&&t| t <= end + 1e-9)
            .map(|&t| {
                let k = ((t / 1e-4).round() as usize).min(n - 1);
                format!("{t}:{:.4}", rel_at(&fb, &f, k))
            })
            .collect();
        println!(
            "  {:<32} raw {:.4} cfc60 {:.4} | {}",
            jobs[j].0,
            rel(&rb, &raw, n),
            rel(&fb, &f, n),
            marks.join(" ")
        );
    }

    if base.snaps.is_empty() {
        return;
    }
    let pos = af.node_positions();
    let nn = pos.len();
    {
        let e = &base.r.energies;
        let col = |l: &str| e.channel_by_label(l).unwrap().to_vec();
        let (ie, hg, ct, fr, dp, wf) = (
            col("internal"),
            col("hourglass"),
            col("contact"),
            col("friction"),
            col("damping"),
            col("wall_force"),
        );
        let mt: f64 = base.mass.iter().sum();
        println!("t(ms) vcom_x vcom_z wy | KE KE_rigid KE_deform | IE HG contact friction damping | wall force (lbf)");
        for (ms, v) in base.snaps.iter().enumerate() {
            if ms % 4 != 0 {
                continue;
            }
            let x = &base.xs[ms];
            let mut p = [0.0; 3];
            let mut c = [0.0; 3];
            for ((vi, xi), m) in v.iter().zip(x).zip(&base.mass) {
                for d in 0..3 {
                    p[d] += m * vi[d];
                    c[d] += m * xi[d];
                }
            }
            let c = c.map(|q| q / mt);
            let vc = p.map(|q| q / mt);
            // Angular momentum and inertia tensor about the centre of mass.
            let mut hl = [0.0; 3];
            let mut ii = [[0.0; 3]; 3];
            let mut ke = 0.0;
            for ((vi, xi), m) in v.iter().zip(x).zip(&base.mass) {
                let r = [xi[0] - c[0], xi[1] - c[1], xi[2] - c[2]];
                let u = [vi[0] - vc[0], vi[1] - vc[1], vi[2] - vc[2]];
                hl[0] += m * (r[1] * u[2] - r[2] * u[1]);
                hl[1] += m * (r[2] * u[0] - r[0] * u[2]);
                hl[2] += m * (r[0] * u[1] - r[1] * u[0]);
                let rr = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
                for a in 0..3 {
                    for b in 0..3 {
                        ii[a][b] += m * (if a == b { rr } else { 0.0 } - r[a] * r[b]);
                    }
                }
                ke += 0.5 * m * (vi[0] * vi[0] + vi[1] * vi[1] + vi[2] * vi[2]);
            }
            // Solve I w = h (Cramer).
            let det = |a: [[f64; 3]; 3]| {
                a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
                    - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                    + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
            };
            let dd = det(ii);
            let w: Vec<f64> = (0..3)
                .map(|k| {
                    let mut a = ii;
                    for row in 0..3 {
                        a[row][k] = hl[row];
                    }
                    det(a) / dd
                })
                .collect();
            let ke_rigid = 0.5 * mt * (vc[0] * vc[0] + vc[1] * vc[1] + vc[2] * vc[2])
                + 0.5 * (w[0] * hl[0] + w[1] * hl[1] + w[2] * hl[2]);
            let k = (ms * 10).min(ie.len() - 1);
            println!(
                "{ms:3} {:7.1} {:7.1} {:6.2} | {:.0} {:.0} {:.0} | {:.0} {:.0} {:.0} {:.0} {:.0} | {:.0}",
                p[0] / mt,
                p[2] / mt,
                w[1],
                ke,
                ke_rigid,
                ke - ke_rigid,
                ie[k],
                hg[k],
                ct[k],
                fr[k],
                dp[k],
                wf[k]
            );
        }
        println!("internal energy by part (parts 1..14) every 4 ms:");
        for (k, p) in base.pe.iter().enumerate() {
            if (k + 1) % 4 == 0 {
                let l: Vec<String> = p.iter().map(|q| format!("{:.0}", q.internal)).collect();
                println!("  {:2} ms: {}", k + 1, l.join(" "));
            }
        }
        let last = wf.iter().rposition(|f| f.abs() > 0.0).unwrap_or(0);
        println!("last sample with a wall force: {:.4} s", last as f64 * 1e-4);
    }
    // Mirror map y -> -y.
    let mut key = std::collections::HashMap::new();
    for (i, p) in pos.iter().enumerate() {
        key.insert(p.map(|c| (c * 1e4).round() as i64), i);
    }
    let mirror: Vec<Option<usize>> = pos
        .iter()
        .map(|p| key.get(&[p[0], -p[1], p[2]].map(|c| (c * 1e4).round() as i64)).copied())
        .collect();
    {
        // Mesh symmetry: mirrored element node sets, mirrored masses.
        let mut sets = std::collections::HashSet::new();
        for (n, _) in af.shells() {
            let mut v: Vec<u64> = n.to_vec();
            v.sort();
            v.dedup();
            sets.insert(v);
        }
        let mut bad = 0;
        let mut badtri = 0;
        for (n, p) in af.shells() {
            let mut v: Vec<u64> = n
                .iter()
                .map(|&id| mirror[id as usize - 1].map_or(0, |j| j as u64 + 1))
                .collect();
            v.sort();
            v.dedup();
            if !sets.contains(&v) {
                bad += 1;
                if n[2] == n[3] {
                    badtri += 1;
                }
                if bad < 5 {
                    eprintln!("unmirrored element {:?} of {}", n, p.name());
                }
            }
        }
        let mut mbad = 0.0f64;
        for i in 0..nn {
            if let Some(j) = mirror[i] {
                mbad = mbad.max((base.mass[i] - base.mass[j]).abs() / base.mass[i]);
            }
        }
        println!("elements without a mirror: {bad} ({badtri} triangles); largest mass mismatch {mbad:.2e}");
    }
    println!(
        "mirror pairs found for {} of {} nodes",
        mirror.iter().filter(|m| m.is_some()).count(),
        nn
    );
    let mut line = String::from("asymmetry of the nominal run:");
    for (ms, v) in base.snaps.iter().enumerate() {
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..nn {
            if let Some(j) = mirror[i] {
                let w = [v[j][0], -v[j][1], v[j][2]];
                for d in 0..3 {
                    num += (v[i][d] - w[d]).powi(2);
                    den += v[i][d] * v[i][d];
                }
            }
        }
        if ms % 2 == 0 {
            line += &format!(" {ms}:{:.1e}", (num / den).sqrt() / 2.0);
        }
    }
    println!("{line}");
    {
        let mut part_of = vec![None; nn];
        for (n, p) in af.shells() {
            for &id in &n {
                let i = id as usize - 1;
                if part_of[i].is_none() {
                    part_of[i] = Some(p);
                }
            }
        }
        for ms in [1usize, 2, 5] {
            if ms >= base.snaps.len() {
                continue;
            }
            let v = &base.snaps[ms];
            let mut per: std::collections::BTreeMap<&str, f64> = Default::default();
            for i in 0..nn {
                if let Some(j) = mirror[i] {
                    let w = [v[j][0], -v[j][1], v[j][2]];
                    let d: f64 = (0..3).map(|d| (v[i][d] - w[d]).abs()).fold(0.0, f64::max);
                    let e = per.entry(part_of[i].map_or("none", |p| p.name())).or_default();
                    *e = e.max(d);
                }
            }
            println!("  max |v - mirror v| by part at {ms} ms: {per:?}");
        }
    }
    // Node -> part (first part listing the node).
    let mut part_of = vec![None; nn];
    for (n, p) in af.shells() {
        for &id in &n {
            let i = id as usize - 1;
            if part_of[i].is_none() {
                part_of[i] = Some(p);
            }
        }
    }
    for (j, r) in runs.iter().enumerate().skip(1) {
        println!("divergence by time (all nodes, relative) for {}:", jobs[j].0);
        let mut line = String::new();
        for ms in (0..r.snaps.len()).step_by(2) {
            let (a, b) = (&base.snaps[ms], &r.snaps[ms]);
            let (mut num, mut den) = (0.0, 0.0);
            for i in 0..nn {
                for d in 0..3 {
                    num += (a[i][d] - b[i][d]).powi(2);
                    den += a[i][d] * a[i][d];
                }
            }
            // Antisymmetric part of the difference.
            let mut anti = 0.0;
            for i in 0..nn {
                if let Some(j) = mirror[i] {
                    let di = [a[i][0] - b[i][0], a[i][1] - b[i][1], a[i][2] - b[i][2]];
                    let dj = [a[j][0] - b[j][0], -(a[j][1] - b[j][1]), a[j][2] - b[j][2]];
                    for d in 0..3 {
                        anti += (0.5 * (di[d] - dj[d])).powi(2);
                    }
                }
            }
            line += &format!(" {ms}:{:.1e}(a{:.0}%)", (num / den).sqrt(), 100.0 * anti / num.max(1e-300));
        }
        println!("   {line}");
        for ms in [15usize, 20, 25, 30, 40] {
            if ms >= r.snaps.len() {
                continue;
            }
            let (a, b) = (&base.snaps[ms], &r.snaps[ms]);
            let mut per: std::collections::BTreeMap<String, (f64, f64)> = Default::default();
            for i in 0..nn {
                let name = part_of[i].map_or("none".to_string(), |p| p.name().to_string());
                let e = per.entry(name).or_default();
                for d in 0..3 {
                    e.0 += (a[i][d] - b[i][d]).powi(2);
                    e.1 += 1.0;
                }
            }
            let mut v: Vec<(String, f64)> =
                per.into_iter().map(|(k, (n, c))| (k, (n / c).sqrt())).collect();
            v.sort_by(|x, y| y.1.total_cmp(&x.1));
            let top: Vec<String> = v.iter().take(5).map(|(k, x)| format!("{k} {x:.2e}")).collect();
            println!("   {ms} ms rms |dv| by part: {}", top.join(", "));
        }
    }
}
