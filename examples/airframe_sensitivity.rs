//! How predictable is the airframe crash? The measurements behind docs/airframe.md
//! ("Predictability") and the before/after table of docs/validation.md.
//!
//! ```text
//! cargo run --release --example airframe_sensitivity -- targets [--variant SPEC] [--end T]
//! cargo run --release --example airframe_sensitivity -- compare [--variant SPEC] [--end T] CHANGE...
//! cargo run --release --example airframe_sensitivity -- physics [--variant SPEC] [--end T] [--svg FILE]
//! cargo run --release --example airframe_sensitivity -- symmetry [--variant SPEC] [--end T] CHANGE
//! ```
//!
//! Every run is the coarse airframe at nominal values (`--set name=value` changes them), one
//! thread per run, two runs at a time. Histories are the 1,215 sensor velocities, compared
//! after a CFC 60 filter; "relative L2" is `||a - b|| / ||a||` over all channels and the
//! samples of the window.
//!
//! - `targets`: the targets of the predictability work for windows ending at 0.01, 0.02, 0.04
//!   and `T`: +0.1 % of each Table 2 thickness, TSSFAC halved, each thickness from its lower
//!   to its upper bound (relative L2 and max |Q_upper - Q_lower| / max Q), and the energy
//!   balance of the nominal run.
//! - `compare`: relative L2 (raw and CFC 60) of each CHANGE against the nominal run, and the
//!   pointwise relative difference at a few times.
//! - `physics`: centre-of-mass velocity, rigid-body and deformation kinetic energy, energy
//!   split and wall force every 4 ms, internal energy by part; with `--svg` a picture of the
//!   centre-of-mass vertical velocity and the energy split.
//! - `symmetry`: the left-right asymmetry of the nominal run, and for CHANGE the growth of
//!   the difference, its antisymmetric share and the parts where it is largest.
//!
//! CHANGE is `name=value`, `name*=factor` (catalogue names, `impactcal airframe --list`) or
//! `spec:SPEC` (the same model with a variant). SPEC is a comma-separated list applied to
//! the generated model: `before` (the solver settings before the predictability work: edge
//! frames, no bulk viscosity), `inn=0|1`, `bulk=Q1:Q2|off`, `hg=stiff|visc:QH`, `hgm=`,
//! `hgw=`, `hgb=` (one mode's coefficient), `sd=COEF` (*DAMPING_PART_STIFFNESS on every
//! part), `damp=D` (*DAMPING_GLOBAL), `wall=penalty:ALPHA:ZETA`, `tssfac=`, `fric=`,
//! `elastic`, `norate`, `nowall`, `nograv`, `kick=PART:VZ` (an extra initial vertical
//! velocity of one part's nodes). `--mesh medium|fine` changes the mesh.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::needless_range_loop)]

use std::collections::BTreeMap;

use impactcal::core::Cfc;
use impactcal::shell::airframe::{Airframe, AirframeOptions, AirframeValues, MeshDensity, Preset};
use impactcal::shell::{
    BulkViscosity, Hourglass, HourglassForm, InitialVelocity, MaterialLaw, PartEnergies,
    PartStiffnessDamping, RunResult, ShellModel, Simulation, VelocityTarget, WallMethod,
};
use rayon::prelude::*;

/// Applies a variant SPEC to a generated model.
fn apply(m: &mut ShellModel, spec: &str) {
    for item in spec.split(',').filter(|s| !s.is_empty()) {
        let (k, v) = item.split_once('=').unwrap_or((item, ""));
        let num = || {
            v.parse::<f64>()
                .unwrap_or_else(|_| panic!("bad number in `{item}`"))
        };
        match k {
            "before" => {
                m.control.invariant_numbering = false;
                m.bulk_viscosity = None;
            }
            "inn" => m.control.invariant_numbering = v == "1",
            "bulk" => {
                m.bulk_viscosity = v.split_once(':').map(|(a, b)| BulkViscosity {
                    q1: a.parse().unwrap(),
                    q2: b.parse().unwrap(),
                });
            }
            "hg" => {
                let (form, q) = v.split_once(':').expect("hg=stiff:QH or hg=visc:QH");
                let q: f64 = q.parse().unwrap();
                m.hourglass = Hourglass {
                    form: if form == "visc" {
                        HourglassForm::Viscous
                    } else {
                        HourglassForm::Stiffness
                    },
                    membrane: q,
                    transverse: q,
                    rotation: q,
                };
            }
            "hgm" => m.hourglass.membrane = num(),
            "hgw" => m.hourglass.transverse = num(),
            "hgb" => m.hourglass.rotation = num(),
            "sd" => {
                let coef = num();
                m.stiffness_damping = m
                    .parts
                    .iter()
                    .map(|p| PartStiffnessDamping { part: p.id, coef })
                    .collect();
            }
            "damp" => m.damping = num(),
            "wall" => {
                let p: Vec<&str> = v.split(':').collect();
                assert_eq!(p[0], "penalty", "wall=penalty:ALPHA:ZETA");
                m.walls[0].method = WallMethod::Penalty {
                    alpha: p[1].parse().unwrap(),
                    damping: p.get(2).map_or(0.0, |z| z.parse().unwrap()),
                };
            }
            "tssfac" => m.control.tssfac = num(),
            "fric" => m.walls[0].friction = num(),
            "nowall" => m.walls.clear(),
            "nograv" => m.body_load_z = None,
            "kick" => {
                let (p, vz) = v.split_once(':').expect("kick=PART:VZ");
                m.initial_velocities.push(InitialVelocity::translation(
                    VelocityTarget::Part(p.parse().unwrap()),
                    [0.0, 0.0, vz.parse().unwrap()],
                ));
            }
            "elastic" => m
                .materials
                .iter_mut()
                .for_each(|x| x.law = MaterialLaw::Elastic),
            "norate" => {
                for x in &mut m.materials {
                    if let MaterialLaw::Plastic { rate, .. } = &mut x.law {
                        *rate = None;
                    }
                }
            }
            _ => panic!("unknown variant item `{item}`"),
        }
    }
}

/// One run: its result, and (when asked) the nodal velocities, positions and part energies
/// every millisecond.
struct Run {
    result: RunResult,
    masses: Vec<f64>,
    velocities: Vec<Vec<[f64; 3]>>,
    positions: Vec<Vec<[f64; 3]>>,
    parts: Vec<Vec<PartEnergies>>,
    elastic: Vec<f64>,
}

fn run(model: &ShellModel, snapshots: bool) -> Run {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    pool.install(|| {
        let result = Simulation::new(model).unwrap().run().unwrap();
        let mut sim = Simulation::new(model).unwrap();
        let masses = sim.masses().to_vec();
        let (mut velocities, mut positions, mut parts) = (Vec::new(), Vec::new(), Vec::new());
        let mut elastic = Vec::new();
        if snapshots {
            velocities.push(sim.velocities().to_vec());
            positions.push(sim.positions().to_vec());
            parts.push(sim.part_energies());
            elastic.push(sim.elastic_energy());
            let mut next = 1e-3;
            while sim.time() < model.control.end_time {
                sim.step().unwrap();
                if sim.time() >= next {
                    velocities.push(sim.velocities().to_vec());
                    positions.push(sim.positions().to_vec());
                    parts.push(sim.part_energies());
                    elastic.push(sim.elastic_energy());
                    next += 1e-3;
                }
            }
        }
        Run {
            result,
            masses,
            velocities,
            positions,
            parts,
            elastic,
        }
    })
}

/// The sensor velocities, CFC 60 filtered (or raw), channel by channel.
fn channels(r: &RunResult, filtered: bool) -> Vec<Vec<f64>> {
    let h = r.velocity.as_ref().unwrap();
    (0..h.channels())
        .map(|c| {
            if filtered {
                Cfc::Cfc60
                    .filter(h.channel(c), h.dt(), "airframe channel")
                    .unwrap()
            } else {
                h.channel(c).to_vec()
            }
        })
        .collect()
}

/// `||a - b|| / ||a||` over all channels and the first `n` samples.
fn rel_l2(a: &[Vec<f64>], b: &[Vec<f64>], n: usize) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        for k in 0..n.min(x.len()) {
            num += (x[k] - y[k]).powi(2);
            den += x[k] * x[k];
        }
    }
    (num / den).sqrt()
}

/// `||a(t_k) - b(t_k)|| / ||a(t_k)||` across channels at sample `k`.
fn rel_at(a: &[Vec<f64>], b: &[Vec<f64>], k: usize) -> f64 {
    rel_l2(
        &a.iter().map(|x| vec![x[k]]).collect::<Vec<_>>(),
        &b.iter().map(|x| vec![x[k]]).collect::<Vec<_>>(),
        1,
    )
}

/// The 2-norm over channels at every sample (the paper's Q(t)).
fn q_norm(a: &[Vec<f64>]) -> Vec<f64> {
    let n = a[0].len();
    (0..n)
        .map(|k| a.iter().map(|x| x[k] * x[k]).sum::<f64>().sqrt())
        .collect()
}

struct Setup {
    airframe: Airframe,
    values: AirframeValues,
    variant: String,
    end: f64,
    /// `physics --svg FILE`: where to draw the centre-of-mass velocity and energy split.
    svg: Option<String>,
}

impl Setup {
    fn model(&self, values: &AirframeValues, extra: &str) -> ShellModel {
        let mut m = self.airframe.model(values).unwrap();
        apply(&mut m, &self.variant);
        apply(&mut m, extra);
        m
    }

    /// The model of a CHANGE argument.
    fn changed(&self, change: &str) -> ShellModel {
        if let Some(spec) = change.strip_prefix("spec:") {
            return self.model(&self.values, spec);
        }
        let mut v = self.values.clone();
        if let Some((name, f)) = change.split_once("*=") {
            let x = v.get(name).unwrap();
            v.set(name, x * f.parse::<f64>().unwrap()).unwrap();
        } else {
            v.assign(change).unwrap();
        }
        self.model(&v, "")
    }
}

fn energy_line(r: &RunResult) -> String {
    let e = r.summary.energies;
    format!(
        "KE0 {:.0}, KE {:.0}, internal {:.0}, hourglass {:.0} ({:.1} % of internal), contact {:.0} \
         (friction {:.0}), damping {:.0} ({:.1} % of KE0), external work {:.0}; \
         |total - KE0 - W| = {:.2} % of KE0; {} cycles",
        e.initial,
        e.kinetic,
        e.internal,
        e.hourglass,
        100.0 * e.hourglass / e.internal,
        e.contact,
        e.friction,
        e.damping,
        100.0 * e.damping / e.initial,
        e.external_work,
        100.0 * (e.total() - e.initial - e.external_work).abs() / e.initial,
        r.summary.cycles
    )
}

fn targets(s: &Setup) {
    let space = Preset::Table2.space().unwrap();
    let mut jobs: Vec<(String, ShellModel)> = vec![("nominal".into(), s.model(&s.values, ""))];
    for p in space.parameters() {
        let nominal = s.values.get(&p.name).unwrap();
        for (tag, value) in [
            ("+0.1%", nominal * 1.001),
            ("lower", p.lower),
            ("upper", p.upper),
        ] {
            let mut v = s.values.clone();
            v.set(&p.name, value).unwrap();
            jobs.push((format!("{} {tag}", p.name), s.model(&v, "")));
        }
    }
    let tssfac = jobs[0].1.control.tssfac;
    jobs.push((
        "TSSFAC halved".into(),
        s.model(&s.values, &format!("tssfac={}", 0.5 * tssfac)),
    ));
    let runs: Vec<Run> = jobs.par_iter().map(|(_, m)| run(m, false)).collect();
    let f: Vec<Vec<Vec<f64>>> = runs.iter().map(|r| channels(&r.result, true)).collect();
    println!("variant [{}], end {} s", s.variant, s.end);
    println!("nominal: {}", energy_line(&runs[0].result));
    let q0 = q_norm(&f[0]);
    let mut windows: Vec<f64> = vec![0.01, 0.02, 0.04];
    windows.retain(|&w| w < s.end - 1e-9);
    windows.push(s.end);
    for w in windows {
        let n = (w / 1e-4).round() as usize + 1;
        let qmax = q0[..n].iter().cloned().fold(0.0, f64::max);
        println!("\nwindow 0 to {w} s (CFC 60, relative L2 over 1,215 channels)");
        println!("| thickness | +0.1 % | lower to upper | ratio | max dQ / max Q |");
        println!("|---|---|---|---|---|");
        for (i, p) in space.parameters().iter().enumerate() {
            let (small, lo, hi) = (1 + 3 * i, 2 + 3 * i, 3 + 3 * i);
            let d_small = rel_l2(&f[0], &f[small], n);
            let d_range = rel_l2(&f[lo], &f[hi], n);
            let (ql, qh) = (q_norm(&f[lo]), q_norm(&f[hi]));
            let dq = (0..n).map(|k| (qh[k] - ql[k]).abs()).fold(0.0, f64::max) / qmax;
            println!(
                "| `{}` | {:.2} % | {:.2} % | {:.1} | {:.2} % |",
                p.name,
                100.0 * d_small,
                100.0 * d_range,
                d_range / d_small,
                100.0 * dq
            );
        }
        let last = runs.len() - 1;
        println!("TSSFAC halved: {:.2} %", 100.0 * rel_l2(&f[0], &f[last], n));
    }
}

fn compare(s: &Setup, changes: &[String]) {
    let mut jobs = vec![s.model(&s.values, "")];
    jobs.extend(changes.iter().map(|c| s.changed(c)));
    let runs: Vec<Run> = jobs.par_iter().map(|m| run(m, false)).collect();
    println!("variant [{}], end {} s", s.variant, s.end);
    println!("nominal: {}", energy_line(&runs[0].result));
    let hg: Vec<String> = runs[0]
        .result
        .parts
        .iter()
        .map(|p| {
            format!(
                "{}:{:.0}%",
                p.part,
                100.0 * p.hourglass / p.internal.max(1e-12)
            )
        })
        .collect();
    println!("hourglass / internal by part id: {}", hg.join(" "));
    let (f0, r0) = (
        channels(&runs[0].result, true),
        channels(&runs[0].result, false),
    );
    let n = f0[0].len();
    for (c, r) in changes.iter().zip(&runs[1..]) {
        let (f, raw) = (channels(&r.result, true), channels(&r.result, false));
        let marks: Vec<String> = [0.01, 0.02, 0.03, 0.04, 0.06, 0.08]
            .iter()
            .filter(|&&t| t <= s.end + 1e-9)
            .map(|&t| {
                format!(
                    "{t}: {:.4}",
                    rel_at(&f0, &f, ((t / 1e-4) as usize).min(n - 1))
                )
            })
            .collect();
        println!(
            "{c:<32} raw {:.4}  CFC 60 {:.4}  | at {}",
            rel_l2(&r0, &raw, n),
            rel_l2(&f0, &f, n),
            marks.join(", ")
        );
        if c.starts_with("spec:") {
            println!("{:<32} {}", "", energy_line(&r.result));
        }
    }
}

/// Kinetic energy of the rigid-body motion (translation of the centre of mass and rotation
/// about it), the centre-of-mass velocity and the angular velocity.
fn rigid_body(v: &[[f64; 3]], x: &[[f64; 3]], m: &[f64]) -> (f64, [f64; 3], [f64; 3]) {
    let mt: f64 = m.iter().sum();
    let (mut p, mut c) = ([0.0; 3], [0.0; 3]);
    for ((vi, xi), mi) in v.iter().zip(x).zip(m) {
        for d in 0..3 {
            p[d] += mi * vi[d];
            c[d] += mi * xi[d];
        }
    }
    let (vc, c) = (p.map(|q| q / mt), c.map(|q| q / mt));
    let (mut h, mut inertia) = ([0.0; 3], [[0.0; 3]; 3]);
    for ((vi, xi), mi) in v.iter().zip(x).zip(m) {
        let r = [xi[0] - c[0], xi[1] - c[1], xi[2] - c[2]];
        let u = [vi[0] - vc[0], vi[1] - vc[1], vi[2] - vc[2]];
        h[0] += mi * (r[1] * u[2] - r[2] * u[1]);
        h[1] += mi * (r[2] * u[0] - r[0] * u[2]);
        h[2] += mi * (r[0] * u[1] - r[1] * u[0]);
        let rr = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        for a in 0..3 {
            for b in 0..3 {
                inertia[a][b] += mi * (if a == b { rr } else { 0.0 } - r[a] * r[b]);
            }
        }
    }
    let det = |a: [[f64; 3]; 3]| {
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
            - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    };
    let d = det(inertia);
    let w: [f64; 3] = std::array::from_fn(|k| {
        let mut a = inertia;
        for row in 0..3 {
            a[row][k] = h[row];
        }
        det(a) / d
    });
    let ke = 0.5 * mt * (vc[0] * vc[0] + vc[1] * vc[1] + vc[2] * vc[2])
        + 0.5 * (w[0] * h[0] + w[1] * h[1] + w[2] * h[2]);
    (ke, vc, w)
}

fn physics(s: &Setup) {
    let r = run(&s.model(&s.values, ""), true);
    println!("variant [{}]: {}", s.variant, energy_line(&r.result));
    let e = &r.result.energies;
    let col = |l: &str| e.channel_by_label(l).unwrap().to_vec();
    let (ke_all, ie, hg, ct, fr, dp, wf) = (
        col("kinetic"),
        col("internal"),
        col("hourglass"),
        col("contact"),
        col("friction"),
        col("damping"),
        col("wall_force"),
    );
    println!(
        "| t (ms) | v_x com | v_z com | pitch rate (rad/s) | KE rigid | KE deformation | KE nodal rotations | internal | elastic | plastic | hourglass | wall, normal | wall, friction | damping | wall force (lbf) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    // Per millisecond: v_z of the centre of mass, and the energy split for the plot.
    let mut vz = Vec::new();
    let mut split: Vec<[f64; 7]> = Vec::new();
    for ms in 0..r.velocities.len() {
        let v = &r.velocities[ms];
        let (ke_rigid, vc, w) = rigid_body(v, &r.positions[ms], &r.masses);
        let ke: f64 = v
            .iter()
            .zip(&r.masses)
            .map(|(vi, m)| 0.5 * m * (vi[0] * vi[0] + vi[1] * vi[1] + vi[2] * vi[2]))
            .sum();
        let k = (ms * 10).min(ie.len() - 1);
        vz.push(vc[2]);
        split.push([
            ke_rigid,
            ke_all[k] - ke_rigid,
            r.elastic[ms],
            ie[k] - r.elastic[ms],
            fr[k],
            ct[k] - fr[k],
            hg[k] + dp[k],
        ]);
        if ms % 4 != 0 {
            continue;
        }
        println!(
            "| {ms} | {:.1} | {:.1} | {:.2} | {:.0} | {:.0} | {:.0} | {:.0} | {:.0} | {:.0} | {:.0} | {:.0} | {:.0} | {:.0} | {:.0} |",
            vc[0],
            vc[2],
            w[1],
            ke_rigid,
            ke - ke_rigid,
            ke_all[k] - ke,
            ie[k],
            r.elastic[ms],
            ie[k] - r.elastic[ms],
            hg[k],
            ct[k] - fr[k],
            fr[k],
            dp[k],
            wf[k]
        );
    }
    let last = wf.iter().rposition(|f| f.abs() > 0.0).unwrap_or(0);
    println!("last sample with a wall force: {:.4} s", last as f64 * 1e-4);
    if let Some(path) = &s.svg {
        std::fs::write(path, physics_svg(&vz, &split, last as f64 * 1e-4)).unwrap();
        println!("wrote {path}");
    }
    println!("internal energy by part id, every 8 ms:");
    for (k, p) in r.parts.iter().enumerate().skip(8).step_by(8) {
        let l: Vec<String> = p
            .iter()
            .map(|q| format!("{}:{:.0}", q.part, q.internal))
            .collect();
        println!("  {k} ms: {}", l.join(" "));
    }
}

fn symmetry(s: &Setup, change: &str) {
    let models = [s.model(&s.values, ""), s.changed(change)];
    let runs: Vec<Run> = models.par_iter().map(|m| run(m, true)).collect();
    let pos = s.airframe.node_positions();
    let nn = pos.len();
    let key = |p: [f64; 3]| p.map(|c| (c * 1e4).round() as i64);
    let index: BTreeMap<[i64; 3], usize> =
        pos.iter().enumerate().map(|(i, p)| (key(*p), i)).collect();
    let mirror: Vec<Option<usize>> = pos
        .iter()
        .map(|p| index.get(&key([p[0], -p[1], p[2]])).copied())
        .collect();
    println!(
        "variant [{}]: {} of {} nodes have a mirror node",
        s.variant,
        mirror.iter().flatten().count(),
        nn
    );
    let part_of: Vec<_> = (1..=nn as u64)
        .map(|id| s.airframe.part_of_node(id))
        .collect();
    for ms in [1usize, 2] {
        let v = &runs[0].velocities[ms.min(runs[0].velocities.len() - 1)];
        let mut per: BTreeMap<&str, f64> = BTreeMap::new();
        for i in 0..nn {
            if let Some(j) = mirror[i] {
                let d = (v[i][0] - v[j][0])
                    .abs()
                    .max((v[i][1] + v[j][1]).abs())
                    .max((v[i][2] - v[j][2]).abs());
                let e = per
                    .entry(part_of[i].map_or("none", |p| p.name()))
                    .or_default();
                *e = e.max(d);
            }
        }
        println!(
            "largest |v - mirrored v| (in/s) at {ms} ms: {}",
            largest(per.into_iter().collect(), 4, |x| format!("{x:.1e}"))
        );
    }
    println!("| t (ms) | asymmetry of the nominal run | difference | antisymmetric share of it |");
    println!("|---|---|---|---|");
    for ms in (0..runs[0].velocities.len()).step_by(4) {
        let (a, b) = (&runs[0].velocities[ms], &runs[1].velocities[ms]);
        let (mut asym, mut norm, mut diff, mut anti) = (0.0, 0.0, 0.0, 0.0);
        for i in 0..nn {
            for d in 0..3 {
                norm += a[i][d] * a[i][d];
                diff += (a[i][d] - b[i][d]).powi(2);
            }
            if let Some(j) = mirror[i] {
                let sign = [1.0, -1.0, 1.0];
                for d in 0..3 {
                    asym += (0.5 * (a[i][d] - sign[d] * a[j][d])).powi(2);
                    let (di, dj) = (a[i][d] - b[i][d], sign[d] * (a[j][d] - b[j][d]));
                    anti += (0.5 * (di - dj)).powi(2);
                }
            }
        }
        println!(
            "| {ms} | {:.1e} | {:.1e} | {:.0} % |",
            (asym / norm.max(1e-300)).sqrt(),
            (diff / norm.max(1e-300)).sqrt(),
            100.0 * anti / diff.max(1e-300)
        );
    }
    println!("rms velocity difference (in/s) by part, largest five:");
    for ms in [10usize, 15, 20, 25, 30, 40] {
        if ms >= runs[0].velocities.len() {
            continue;
        }
        let (a, b) = (&runs[0].velocities[ms], &runs[1].velocities[ms]);
        let mut per: BTreeMap<&str, (f64, f64)> = BTreeMap::new();
        for i in 0..nn {
            let e = per
                .entry(part_of[i].map_or("none", |p| p.name()))
                .or_default();
            for d in 0..3 {
                e.0 += (a[i][d] - b[i][d]).powi(2);
                e.1 += 1.0;
            }
        }
        let rms = per
            .into_iter()
            .map(|(k, (s2, c))| (k, (s2 / c).sqrt()))
            .collect();
        println!("  {ms} ms: {}", largest(rms, 5, |x| format!("{x:.1}")));
    }
}

/// Two panels, one sample per millisecond: the vertical velocity of the centre of mass,
/// and the split of the initial kinetic energy (stacked areas).
fn physics_svg(vz: &[f64], split: &[[f64; 7]], contact_end: f64) -> String {
    use std::fmt::Write;
    let names = [
        "kinetic, rigid body",
        "kinetic, deformation and nodal rotations",
        "elastic",
        "plastic",
        "friction",
        "wall, normal",
        "hourglass and damping",
    ];
    let colours = [
        "#4e79a7", "#a0cbe8", "#59a14f", "#e15759", "#f28e2b", "#b07aa1", "#9c755f",
    ];
    let (w, h, left, top) = (640.0, 260.0, 70.0, 30.0);
    let n = vz.len() - 1;
    let x = |k: usize| left + w * k as f64 / n as f64;
    let mut svg = String::new();
    let height = 2.0 * (h + 2.0 * top) + 20.0;
    let _ = writeln!(
        svg,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{height}\" \
         font-family=\"sans-serif\" font-size=\"12\">",
        w + left + 330.0
    );
    // Panel 1: v_z of the centre of mass, -320 to 80 in/s.
    let y1 = |v: f64| top + h * (80.0 - v) / 400.0;
    let _ = writeln!(
        svg,
        "<text x=\"{left}\" y=\"18\">vertical velocity of the centre of mass (in/s)</text>"
    );
    for v in [-300.0, -200.0, -100.0, 0.0, 60.0] {
        let _ = writeln!(
            svg,
            "<line x1=\"{left}\" x2=\"{}\" y1=\"{y}\" y2=\"{y}\" stroke=\"#ddd\"/>\
             <text x=\"{}\" y=\"{}\" text-anchor=\"end\">{v}</text>",
            left + w,
            left - 6.0,
            y1(v) + 4.0,
            y = y1(v)
        );
    }
    let xc = left + w * contact_end * 1e3 / n as f64;
    let _ = writeln!(
        svg,
        "<line x1=\"{xc}\" x2=\"{xc}\" y1=\"{top}\" y2=\"{}\" stroke=\"#999\" stroke-dasharray=\"4\"/>\
         <text x=\"{}\" y=\"{}\">last ground contact</text>",
        top + h,
        xc + 4.0,
        top + 14.0
    );
    let pts: Vec<String> = vz
        .iter()
        .enumerate()
        .map(|(k, v)| format!("{:.1},{:.1}", x(k), y1(*v)))
        .collect();
    let _ = writeln!(
        svg,
        "<polyline fill=\"none\" stroke=\"#4e79a7\" stroke-width=\"2\" points=\"{}\"/>",
        pts.join(" ")
    );
    // Panel 2: stacked energy split, 0 to the initial kinetic energy.
    let top2 = 2.0 * top + h + 20.0;
    let total = split[0].iter().sum::<f64>();
    let y2 = |e: f64| top2 + h * (1.0 - e / total);
    let _ = writeln!(
        svg,
        "<text x=\"{left}\" y=\"{}\">where the initial kinetic energy goes (in·lbf, stacked)</text>",
        top2 - 12.0
    );
    let mut below = vec![0.0; split.len()];
    for (c, (name, colour)) in names.iter().zip(colours).enumerate() {
        let upper: Vec<f64> = split
            .iter()
            .zip(&below)
            .map(|(s, b)| b + s[c].max(0.0))
            .collect();
        let mut pts: Vec<String> = upper
            .iter()
            .enumerate()
            .map(|(k, e)| format!("{:.1},{:.1}", x(k), y2(*e)))
            .collect();
        pts.extend(
            below
                .iter()
                .enumerate()
                .rev()
                .map(|(k, e)| format!("{:.1},{:.1}", x(k), y2(*e))),
        );
        let _ = writeln!(
            svg,
            "<polygon fill=\"{colour}\" stroke=\"none\" points=\"{}\"/>",
            pts.join(" ")
        );
        let ly = top2 + 16.0 * c as f64 + 10.0;
        let _ = writeln!(
            svg,
            "<rect x=\"{}\" y=\"{}\" width=\"12\" height=\"12\" fill=\"{colour}\"/><text x=\"{}\" y=\"{}\">{name}</text>",
            left + w + 14.0,
            ly - 10.0,
            left + w + 30.0,
            ly
        );
        below = upper;
    }
    for e in [0.0, 100_000.0, 200_000.0, 300_000.0] {
        let _ = writeln!(
            svg,
            "<text x=\"{}\" y=\"{}\" text-anchor=\"end\">{e}</text>",
            left - 6.0,
            y2(e) + 4.0
        );
    }
    for (panel_top, label_y) in [(top, top + h + 16.0), (top2, top2 + h + 16.0)] {
        for ms in (0..=n).step_by(10) {
            let _ = writeln!(
                svg,
                "<text x=\"{}\" y=\"{label_y}\" text-anchor=\"middle\">{ms}</text>",
                x(ms)
            );
        }
        let _ = writeln!(
            svg,
            "<rect x=\"{left}\" y=\"{panel_top}\" width=\"{w}\" height=\"{h}\" fill=\"none\" stroke=\"#333\"/>\
             <text x=\"{}\" y=\"{}\">t (ms)</text>",
            left + w + 10.0,
            label_y
        );
    }
    svg.push_str("</svg>\n");
    svg
}

/// The `count` largest values with their names, largest first, as `name value, ...`.
fn largest(mut v: Vec<(&str, f64)>, count: usize, fmt: impl Fn(f64) -> String) -> String {
    v.sort_by(|a, b| b.1.total_cmp(&a.1));
    v.iter()
        .take(count)
        .map(|(k, x)| format!("{k} {}", fmt(*x)))
        .collect::<Vec<_>>()
        .join(", ")
}

fn main() {
    let mut args = std::env::args().skip(1);
    let command = args.next().unwrap_or_else(|| "targets".into());
    let (mut variant, mut end, mut sets, mut rest) = (String::new(), 0.08, Vec::new(), Vec::new());
    let mut mesh = MeshDensity::Coarse;
    let mut svg = None;
    while let Some(a) = args.next() {
        match a.as_str() {
            "--svg" => svg = Some(args.next().expect("--svg FILE")),
            "--mesh" => mesh = MeshDensity::parse(&args.next().expect("--mesh NAME")).unwrap(),
            "--variant" => variant = args.next().expect("--variant SPEC"),
            "--end" => end = args.next().expect("--end T").parse().unwrap(),
            "--set" => sets.push(args.next().expect("--set name=value")),
            _ => rest.push(a),
        }
    }
    let mut options = AirframeOptions::new(mesh);
    options.end_time = end;
    let mut values = AirframeValues::nominal();
    for a in &sets {
        values.assign(a).unwrap();
    }
    let setup = Setup {
        airframe: Airframe::new(options).unwrap(),
        values,
        variant,
        end,
        svg,
    };
    let started = std::time::Instant::now();
    match command.as_str() {
        "targets" => targets(&setup),
        "compare" => compare(&setup, &rest),
        "physics" => physics(&setup),
        "symmetry" => symmetry(
            &setup,
            rest.first().map_or("belly_panel.t*=1.001", String::as_str),
        ),
        c => panic!("unknown command `{c}` (targets, compare, physics, symmetry)"),
    }
    eprintln!("{:.0} s wall time", started.elapsed().as_secs_f64());
}
