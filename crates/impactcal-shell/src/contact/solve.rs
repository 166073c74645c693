//! One cycle of a contact interface: the search lists kept valid, each checked node's
//! contact (penalty, damping, friction), the forces added to the nodes, the energies.

use rayon::prelude::*;

use super::geometry::closest_on_segment;
use super::interface::{Interface, segment_normal};
use super::search::{Candidates, candidates, inside, segment_box};
use crate::geometry::{dot, sub};

/// Checked nodes per rayon task.
const CHUNK: usize = 256;

/// The contact of one checked node in one cycle: the segment, the weights of the closest
/// point on its corners, the force on the node (the segment's corners take `-w_k f`) and
/// its normal part (penalty and damping, >= 0).
#[derive(Debug, Clone, Copy)]
struct Hit {
    seg: u32,
    w: [f64; 4],
    f: [f64; 3],
    normal: f64,
}

/// What the node remembers between cycles.
#[derive(Debug, Clone, Copy, Default)]
struct Memory {
    /// The tangential (friction) force carried to the next cycle.
    friction: [f64; 3],
    /// The direction the node was pushed in the last cycle (zero: no contact).
    normal: [f64; 3],
    /// The segment of the last contact (`u32::MAX`: none).
    seg: u32,
    /// The penetration present at the start, which only additional penetration acts
    /// against; it shrinks when the node moves out.
    reference: f64,
}

/// The state of one interface between cycles.
#[derive(Debug, Clone)]
pub(crate) struct ContactState {
    cand: Candidates,
    /// Positions of the interface's nodes at the last sort.
    x_sort: Vec<[f64; 3]>,
    memory: Vec<Memory>,
    hits: Vec<Option<Hit>>,
    /// Each segment's box this cycle, grown by its half thickness and the largest node
    /// half thickness.
    boxes: Vec<[f64; 6]>,
    /// Per chunk of checked nodes, the friction work of the cycle.
    chunk_work: Vec<f64>,
    /// Force on each of the interface's nodes, this cycle and the last.
    force: Vec<[f64; 3]>,
    force_old: Vec<[f64; 3]>,
    /// Energy of the interface (the work its forces took from the structure) and the
    /// friction share of it.
    pub energy: f64,
    pub friction: f64,
    /// This cycle's resultant force on the slave side `[x, y, z]` and the sum of the
    /// normal force over the contacts.
    pub resultant: [f64; 4],
    /// Number of bucket sorts so far.
    pub sorts: u64,
    /// The number of nodes that penetrated at the start and the largest penetration.
    initial: (usize, f64),
}

/// The model state a cycle of contact reads.
pub(crate) struct Nodes<'a> {
    pub x: &'a [[f64; 3]],
    pub v: &'a [[f64; 3]],
    pub mass: &'a [f64],
}

impl ContactState {
    /// The state at the start: candidate lists on the positions `x`, no contact yet.
    pub fn new(f: &Interface, x: &[[f64; 3]]) -> Self {
        let n = f.slaves.len();
        ContactState {
            cand: candidates(f, x, f.margin),
            x_sort: f.nodes.iter().map(|&i| x[i as usize]).collect(),
            memory: vec![
                Memory {
                    seg: u32::MAX,
                    ..Memory::default()
                };
                n
            ],
            hits: vec![None; n],
            boxes: vec![[0.0; 6]; f.segs.len()],
            chunk_work: vec![0.0; n.div_ceil(CHUNK)],
            force: vec![[0.0; 3]; f.nodes.len()],
            force_old: vec![[0.0; 3]; f.nodes.len()],
            energy: 0.0,
            friction: 0.0,
            resultant: [0.0; 4],
            sorts: 1,
            initial: (0, 0.0),
        }
    }

    /// Sorts again when a node has moved more than half the margin relative to the
    /// interface's mean motion since the last sort: a pair outside the margin then could
    /// have come into reach.
    fn refresh(&mut self, f: &Interface, x: &[[f64; 3]]) {
        let n = f.nodes.len() as f64;
        let mut mean = [0.0; 3];
        for (l, &i) in f.nodes.iter().enumerate() {
            let d = sub(x[i as usize], self.x_sort[l]);
            for k in 0..3 {
                mean[k] += d[k];
            }
        }
        let mean = mean.map(|m| m / n);
        let mut worst = 0.0f64;
        for (l, &i) in f.nodes.iter().enumerate() {
            let d = sub(sub(x[i as usize], self.x_sort[l]), mean);
            worst = worst.max(dot(d, d));
        }
        if 2.0 * worst.sqrt() > f.margin {
            self.sort(f, x);
        }
    }

    /// The bucket sort on the positions `x`: new candidate lists and the positions they
    /// were found on; returns the number of candidate pairs.
    pub fn sort(&mut self, f: &Interface, x: &[[f64; 3]]) -> usize {
        self.cand = candidates(f, x, f.margin);
        for (l, &i) in f.nodes.iter().enumerate() {
            self.x_sort[l] = x[i as usize];
        }
        self.sorts += 1;
        self.cand.list.len()
    }

    /// One cycle at time `t`: contact forces on the positions `x` with the mid-step
    /// velocities `v` (the step just taken was `dt`; 0 at the start, when penetrations
    /// found become references and no force acts). Adds `f / m` to the accelerations `a`
    /// of the interface's nodes and books the work of the forces over the step just taken
    /// (trapezoidal: `-sum (f_old + f) / 2 . v dt`) and the friction work.
    pub fn cycle(&mut self, f: &Interface, s: &Nodes<'_>, t: f64, dt: f64, a: &mut [[f64; 3]]) {
        let start = dt == 0.0;
        let active = t >= f.birth && t <= f.death;
        if active {
            if !start {
                self.refresh(f, s.x);
            }
            self.boxes
                .par_iter_mut()
                .enumerate()
                .with_min_len(4 * CHUNK)
                .for_each(|(k, b)| *b = segment_box(f, k, s.x, f.seg_half[k] + f.max_half));
            let (cand, boxes) = (&self.cand, &self.boxes);
            self.memory
                .par_chunks_mut(CHUNK)
                .zip(self.hits.par_chunks_mut(CHUNK))
                .zip(self.chunk_work.par_iter_mut())
                .enumerate()
                .for_each(|(c, ((mem, hits), work))| {
                    let mut w = 0.0;
                    for (k, (m, h)) in mem.iter_mut().zip(hits.iter_mut()).enumerate() {
                        let j = c * CHUNK + k;
                        let (hit, dw) = node_contact(f, j, cand.of(j), boxes, s, m, dt, start);
                        *h = hit;
                        w += dw;
                    }
                    *work = w;
                });
        } else {
            self.hits.iter_mut().for_each(|h| *h = None);
            self.chunk_work.iter_mut().for_each(|w| *w = 0.0);
        }
        // Forces on the interface's nodes, added in node order.
        std::mem::swap(&mut self.force, &mut self.force_old);
        self.force.iter_mut().for_each(|g| *g = [0.0; 3]);
        let mut normal = 0.0;
        for (j, h) in self.hits.iter().enumerate() {
            let Some(h) = h else { continue };
            normal += h.normal;
            let u = f.slaves[j] as usize;
            for d in 0..3 {
                self.force[u][d] += h.f[d];
            }
            let seg = h.seg as usize;
            for (k, &c) in f.segs[seg][..f.corners(seg)].iter().enumerate() {
                for d in 0..3 {
                    self.force[c as usize][d] -= h.w[k] * h.f[d];
                }
            }
        }
        let mut work = 0.0;
        let mut resultant = [0.0, 0.0, 0.0, normal];
        for (l, &i) in f.nodes.iter().enumerate() {
            let i = i as usize;
            let (g, g0, v) = (self.force[l], self.force_old[l], s.v[i]);
            if f.on_slave[l] {
                for d in 0..3 {
                    resultant[d] += g[d];
                }
            }
            work += 0.5 * (dot(g, v) + dot(g0, v)) * dt;
            if s.mass[i] > 0.0 && g.iter().any(|&c| c != 0.0) {
                for d in 0..3 {
                    a[i][d] += g[d] / s.mass[i];
                }
            }
        }
        self.energy -= work;
        self.friction += self.chunk_work.iter().sum::<f64>();
        self.resultant = resultant;
        if start {
            let refs = self.memory.iter().filter(|m| m.reference > 0.0);
            self.initial = refs.fold((0, 0.0), |(n, x), m| (n + 1, f64::max(x, m.reference)));
        }
    }

    /// The number of checked nodes that penetrated a segment at the start and the largest
    /// penetration (the references recorded then).
    pub fn initial_penetrations(&self) -> (usize, f64) {
        (self.initial.0, self.initial.1)
    }
}

/// The corners of segment `s` at the positions `x`.
fn corners_at(f: &Interface, s: usize, x: &[[f64; 3]]) -> [[f64; 3]; 4] {
    f.segs[s].map(|l| x[f.nodes[l as usize] as usize])
}

/// The deepest penetration of checked node `j` among its candidates: the segment, the
/// closest point's weights, the penetration and the direction that pushes the node out.
fn deepest(
    f: &Interface,
    j: usize,
    cand: &[u32],
    boxes: &[[f64; 6]],
    x: &[[f64; 3]],
    m: &Memory,
) -> Option<(usize, [f64; 4], f64, [f64; 3])> {
    let p = x[f.nodes[f.slaves[j] as usize] as usize];
    let was = m.normal.iter().any(|&c| c != 0.0);
    let mut best: Option<(usize, [f64; 4], f64, [f64; 3])> = None;
    for &s in cand {
        let s = s as usize;
        if !inside(&boxes[s], p) {
            continue;
        }
        let reach = f.slave_half[j] + f.seg_half[s];
        let xs = corners_at(f, s, x);
        let (w, q, d2) = closest_on_segment(p, &xs, f.seg_tri[s]);
        // A node that was pushed out of this segment in the last cycle and is now on the
        // other side of its mid-surface went through it. (Only the same segment: across a
        // bend, the side of a neighbour cannot be told from the direction alone.)
        let follows = was && m.seg as usize == s;
        let r = sub(p, q);
        let d = d2.sqrt();
        let (pen, n) = if d > 0.0 {
            let n = [r[0] / d, r[1] / d, r[2] / d];
            if follows && dot(n, m.normal) < 0.0 {
                (reach + d, n.map(|c| -c))
            } else {
                (reach - d, n)
            }
        } else {
            let n = if was {
                m.normal
            } else {
                match segment_normal(&xs, f.seg_tri[s]) {
                    Some(n) => n,
                    None => continue,
                }
            };
            (reach, n)
        };
        if pen > 0.0 && best.as_ref().is_none_or(|b| pen > b.2) {
            best = Some((s, w, pen, n));
        }
    }
    best
}

/// The contact of checked node `j` this cycle and its friction work; updates its memory.
#[allow(clippy::too_many_arguments)]
fn node_contact(
    f: &Interface,
    j: usize,
    cand: &[u32],
    boxes: &[[f64; 6]],
    s: &Nodes<'_>,
    m: &mut Memory,
    dt: f64,
    start: bool,
) -> (Option<Hit>, f64) {
    let Some((seg, w, pen, n)) = deepest(f, j, cand, boxes, s.x, m) else {
        *m = Memory {
            seg: u32::MAX,
            ..Memory::default()
        };
        return (None, 0.0);
    };
    m.normal = n;
    m.seg = seg as u32;
    if start {
        m.reference = pen;
        return (None, 0.0);
    }
    if pen < m.reference {
        m.reference = pen;
    }
    let pen = pen - m.reference;
    let i = f.nodes[f.slaves[j] as usize] as usize;
    let k = f.seg_k[seg].min(f.slave_k[j]);
    // Relative velocity of the node against the segment's closest point, and the
    // segment's mass there.
    let mut v = s.v[i];
    let mut ms = 0.0;
    for (c, &l) in f.segs[seg][..f.corners(seg)].iter().enumerate() {
        let g = f.nodes[l as usize] as usize;
        for d in 0..3 {
            v[d] -= w[c] * s.v[g][d];
        }
        ms += w[c] * s.mass[g];
    }
    let vn = dot(v, n);
    let mn = s.mass[i];
    let damping = if f.damping > 0.0 && pen > 0.0 && mn > 0.0 && ms > 0.0 {
        let omega = (k * (mn + ms) / (mn * ms)).sqrt();
        f.damping * 2.0 * mn.min(ms) * omega
    } else {
        0.0
    };
    let fn_ = (k * pen - damping * vn).max(0.0);
    let mut ft = [0.0; 3];
    let mut work = 0.0;
    let fr = f.friction;
    if fr.static_coef > 0.0 || fr.dynamic > 0.0 {
        // Carried force in the current tangent plane, less the stiffness times the slip.
        let slip = [
            (v[0] - vn * n[0]) * dt,
            (v[1] - vn * n[1]) * dt,
            (v[2] - vn * n[2]) * dt,
        ];
        let carried = dot(m.friction, n);
        for d in 0..3 {
            ft[d] = m.friction[d] - carried * n[d] - k * slip[d];
        }
        let speed = dot(slip, slip).sqrt() / dt;
        let mu = fr.dynamic + (fr.static_coef - fr.dynamic) * (-fr.decay * speed).exp();
        let mut limit = mu * fn_;
        if fr.viscous > 0.0 {
            limit = limit.min(fr.viscous * f.seg_area[seg]);
        }
        let size = dot(ft, ft).sqrt();
        if size > limit {
            let scale = if size > 0.0 { limit / size } else { 0.0 };
            ft = ft.map(|c| c * scale);
        }
        work = -dot(ft, slip);
    }
    m.friction = ft;
    let force = [fn_ * n[0] + ft[0], fn_ * n[1] + ft[1], fn_ * n[2] + ft[2]];
    (
        Some(Hit {
            seg: seg as u32,
            w,
            f: force,
            normal: fn_,
        }),
        work,
    )
}
