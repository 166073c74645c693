//! The airframe's geometry and mesh: structured patches joined by merging coincident
//! nodes.
//!
//! Axes: x forward (the direction of the horizontal impact velocity), y to the left, z up;
//! inches. The cabin's belly lies in the plane z = 0, the back panel (rear cabin bulkhead)
//! in the plane x = 0; the nose extends to +x and the engine fairing and tail boom to -x.
//!
//! The cabin cross-section is the same at every cabin station: a flat belly of width `2a`,
//! vertical lower sides up to the floor height `h_f`, and above the floor a
//! half-superellipse (exponent 2.5) of half-width `a` and height `b` (side skins, then the
//! roof). Every cabin part shares its grid lines with its neighbours (cabin stations in x,
//! belly and floor stations in y, subfloor levels in z), so the patches join node to node.

use std::collections::HashMap;

use super::AirframePart;

/// Cabin half-width (in).
pub(crate) const HALF_WIDTH: f64 = 24.0;
/// Floor height above the belly (in).
pub(crate) const FLOOR_HEIGHT: f64 = 10.0;
/// Cabin height above the floor (in).
const CABIN_HEIGHT: f64 = 46.0;
/// Cabin length, back panel to the nose joint (in).
pub(crate) const CABIN_LENGTH: f64 = 84.0;
/// Nose length (in).
const NOSE_LENGTH: f64 = 40.0;
/// Engine fairing length, back panel to the tail boom joint (in).
const FAIRING_LENGTH: f64 = 40.0;
/// Tail boom length (in).
const BOOM_LENGTH: f64 = 120.0;
/// Height of the tail boom axis above the belly (in).
const BOOM_AXIS: f64 = 38.0;
/// Radius of the fairing's aft ring (in).
const FAIRING_END_RADIUS: f64 = 15.0;
/// Radii of the tail boom at its root and at its tip (in).
const BOOM_RADII: (f64, f64) = (11.0, 7.0);

/// Grid counts of one mesh density.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Counts {
    /// Intervals across the belly and the floor (a multiple of 4).
    pub ny: usize,
    /// Intervals along the cabin (a multiple of 4).
    pub nx: usize,
    /// Intervals from the belly to the floor.
    pub nf: usize,
    /// Intervals of each side skin arc above the floor.
    pub ns: usize,
    /// Rings of the nose loft.
    pub nose: usize,
    /// Rings of the fairing loft.
    pub fairing: usize,
    /// Intervals along the tail boom.
    pub boom: usize,
    /// Intervals along the fin roots and the fin heights.
    pub fin: usize,
}

impl Counts {
    /// Counts for a refinement factor `k` (1 = coarse).
    pub fn for_factor(k: f64) -> Counts {
        let r = |v: f64| (v * k).round().max(1.0) as usize;
        Counts {
            ny: 4 * r(2.0),
            nx: 4 * r(5.0),
            nf: r(2.0),
            ns: r(6.0),
            nose: r(5.0),
            fairing: r(6.0),
            boom: r(24.0),
            fin: r(4.0),
        }
    }
}

/// A named group of nodes that carries a concentrated mass.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(crate) enum MassSite {
    RotorTransmission,
    Engine,
    Fuel,
    Occupants,
    Tail,
}

/// The generated mesh: node coordinates (index = id - 1), shells with their part, and the
/// node groups of the concentrated masses.
#[derive(Debug, Clone)]
pub(crate) struct Mesh {
    pub nodes: Vec<[f64; 3]>,
    pub shells: Vec<([u32; 4], AirframePart)>,
    pub sites: Vec<(MassSite, Vec<u32>)>,
}

struct Builder {
    nodes: Vec<[f64; 3]>,
    cells: HashMap<[i64; 3], Vec<u32>>,
    shells: Vec<([u32; 4], AirframePart)>,
}

const MERGE_TOL: f64 = 1e-6;

impl Builder {
    fn new() -> Self {
        Builder {
            nodes: Vec::new(),
            cells: HashMap::new(),
            shells: Vec::new(),
        }
    }

    /// The index of the node at `p`, merging with an existing node within the tolerance.
    fn node(&mut self, p: [f64; 3]) -> u32 {
        let key = p.map(|c| (c / MERGE_TOL).floor() as i64);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let k = [key[0] + dx, key[1] + dy, key[2] + dz];
                    if let Some(list) = self.cells.get(&k) {
                        for &i in list {
                            let q = self.nodes[i as usize];
                            let d = (0..3).map(|c| (q[c] - p[c]).abs()).fold(0.0, f64::max);
                            if d <= MERGE_TOL {
                                return i;
                            }
                        }
                    }
                }
            }
        }
        let i = self.nodes.len() as u32;
        self.nodes.push(p);
        self.cells.entry(key).or_default().push(i);
        i
    }

    /// Quads of a structured grid `pts[i][j]`; returns the node indices.
    fn grid(&mut self, part: AirframePart, pts: &[Vec<[f64; 3]>]) -> Vec<Vec<u32>> {
        let ids: Vec<Vec<u32>> = pts
            .iter()
            .map(|row| row.iter().map(|&p| self.node(p)).collect())
            .collect();
        for i in 0..ids.len().saturating_sub(1) {
            for j in 0..ids[i].len().saturating_sub(1) {
                self.quad(
                    part,
                    [ids[i][j], ids[i + 1][j], ids[i + 1][j + 1], ids[i][j + 1]],
                );
            }
        }
        ids
    }

    /// Adds a quad, or two triangles when one corner is nearly flat (an interior angle
    /// above 140 degrees, as at the corners of a patch laid on a smooth curve): the split
    /// along the diagonal through that corner gives two well-shaped triangles where the
    /// quad would be a sliver that governs the time step.
    fn quad(&mut self, part: AirframePart, q: [u32; 4]) {
        let p = q.map(|i| self.nodes[i as usize]);
        let mut flat = None;
        let mut widest = 140f64.to_radians().cos();
        for k in 0..4 {
            let a = sub(p[(k + 3) % 4], p[k]);
            let b = sub(p[(k + 1) % 4], p[k]);
            let cos = dot(a, b) / (dot(a, a) * dot(b, b)).sqrt();
            if cos < widest {
                widest = cos;
                flat = Some(k);
            }
        }
        match flat {
            None => self.shells.push((q, part)),
            Some(k) => {
                let v = |o: usize| q[(k + o) % 4];
                self.shells.push(([v(0), v(1), v(2), v(2)], part));
                self.shells.push(([v(0), v(2), v(3), v(3)], part));
            }
        }
    }

    /// Quads between consecutive closed rings (each ring the same length).
    fn rings(&mut self, parts: &[AirframePart], rings: &[Vec<[f64; 3]>]) -> Vec<Vec<u32>> {
        let ids: Vec<Vec<u32>> = rings
            .iter()
            .map(|r| r.iter().map(|&p| self.node(p)).collect())
            .collect();
        for r in 0..ids.len().saturating_sub(1) {
            let n = ids[r].len();
            for k in 0..n {
                let k1 = (k + 1) % n;
                self.shells.push((
                    [ids[r][k], ids[r][k1], ids[r + 1][k1], ids[r + 1][k]],
                    parts[k],
                ));
            }
        }
        ids
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn lerp(a: [f64; 3], b: [f64; 3], s: f64) -> [f64; 3] {
    [
        a[0] + s * (b[0] - a[0]),
        a[1] + s * (b[1] - a[1]),
        a[2] + s * (b[2] - a[2]),
    ]
}

/// The cabin section above the floor, in (y, z): `2 ns + ny + 1` points at equal arc
/// length from `(a, h_f)` over the roof to `(-a, h_f)`.
fn upper_arc(c: &Counts) -> Vec<[f64; 2]> {
    let (a, b, p) = (HALF_WIDTH, CABIN_HEIGHT, 2.5);
    let dense = 2000;
    let pt = |th: f64| {
        let (cs, sn) = (th.cos(), th.sin());
        [
            a * cs.signum() * cs.abs().powf(2.0 / p),
            FLOOR_HEIGHT + b * sn.abs().powf(2.0 / p),
        ]
    };
    let poly: Vec<[f64; 2]> = (0..=dense)
        .map(|k| pt(std::f64::consts::PI * k as f64 / dense as f64))
        .collect();
    let mut cum = vec![0.0];
    for k in 1..poly.len() {
        let d =
            ((poly[k][0] - poly[k - 1][0]).powi(2) + (poly[k][1] - poly[k - 1][1]).powi(2)).sqrt();
        cum.push(cum[k - 1] + d);
    }
    let total = cum[dense];
    let n = 2 * c.ns + c.ny;
    (0..=n)
        .map(|i| {
            let s = total * i as f64 / n as f64;
            let k = cum.partition_point(|&v| v < s).clamp(1, dense);
            let f = (s - cum[k - 1]) / (cum[k] - cum[k - 1]).max(f64::MIN_POSITIVE);
            let q = [
                poly[k - 1][0] + f * (poly[k][0] - poly[k - 1][0]),
                poly[k - 1][1] + f * (poly[k][1] - poly[k - 1][1]),
            ];
            // Exact end points and symmetry.
            if i == 0 {
                [a, FLOOR_HEIGHT]
            } else if i == n {
                [-a, FLOOR_HEIGHT]
            } else {
                q
            }
        })
        .collect()
}

/// The closed cabin loop in (y, z), counter-clockwise seen from the nose (+x), starting at
/// the belly's left-hand... corner `(-a, 0)`, with the part of each segment (segment `k`
/// joins points `k` and `k + 1`).
fn cabin_loop(c: &Counts) -> (Vec<[f64; 2]>, Vec<AirframePart>) {
    let a = HALF_WIDTH;
    let mut pts = Vec::new();
    let mut parts = Vec::new();
    for j in 0..c.ny {
        pts.push([-a + 2.0 * a * j as f64 / c.ny as f64, 0.0]);
        parts.push(AirframePart::BellyPanel);
    }
    for l in 0..c.nf {
        pts.push([a, FLOOR_HEIGHT * l as f64 / c.nf as f64]);
        parts.push(AirframePart::SideSkins);
    }
    let arc = upper_arc(c);
    for (i, p) in arc[..arc.len() - 1].iter().enumerate() {
        pts.push(*p);
        parts.push(if i < c.ns || i >= c.ns + c.ny {
            AirframePart::SideSkins
        } else {
            AirframePart::Roof
        });
    }
    for l in 0..c.nf {
        pts.push([-a, FLOOR_HEIGHT * (c.nf - l) as f64 / c.nf as f64]);
        parts.push(AirframePart::SideSkins);
    }
    (pts, parts)
}

/// Transfinite (Coons) patch from four boundary point lists: `bottom` and `top` left to
/// right (n + 1 points), `left` and `right` bottom to top (m + 1 points), sharing corners.
fn coons(
    bottom: &[[f64; 3]],
    top: &[[f64; 3]],
    left: &[[f64; 3]],
    right: &[[f64; 3]],
) -> Vec<Vec<[f64; 3]>> {
    let n = bottom.len() - 1;
    let m = left.len() - 1;
    (0..=n)
        .map(|i| {
            let u = i as f64 / n as f64;
            (0..=m)
                .map(|j| {
                    let v = j as f64 / m as f64;
                    let mut p = [0.0; 3];
                    for d in 0..3 {
                        p[d] = (1.0 - v) * bottom[i][d]
                            + v * top[i][d]
                            + (1.0 - u) * left[j][d]
                            + u * right[j][d]
                            - ((1.0 - u) * (1.0 - v) * bottom[0][d]
                                + u * (1.0 - v) * bottom[n][d]
                                + (1.0 - u) * v * top[0][d]
                                + u * v * top[n][d]);
                    }
                    if i == 0 {
                        p = left[j];
                    } else if i == n {
                        p = right[j];
                    } else if j == 0 {
                        p = bottom[i];
                    } else if j == m {
                        p = top[i];
                    }
                    p
                })
                .collect()
        })
        .collect()
}

/// Laplace smoothing of the interior points of a structured patch (Jacobi sweeps of the
/// average of the four neighbours); the boundary stays where it is.
fn smooth(pts: &mut [Vec<[f64; 3]>], sweeps: usize) {
    let n = pts.len();
    let m = pts[0].len();
    for _ in 0..sweeps {
        let old = pts.to_vec();
        for i in 1..n - 1 {
            for j in 1..m - 1 {
                for d in 0..3 {
                    pts[i][j][d] = 0.25
                        * (old[i - 1][j][d]
                            + old[i + 1][j][d]
                            + old[i][j - 1][d]
                            + old[i][j + 1][d]);
                }
            }
        }
    }
}

/// Builds the airframe mesh for the grid counts `c`.
pub(crate) fn build(c: &Counts) -> Mesh {
    use AirframePart as P;
    let mut b = Builder::new();
    let a = HALF_WIDTH;
    let (lp, lparts) = cabin_loop(c);
    let n_loop = lp.len();
    let xs: Vec<f64> = (0..=c.nx)
        .map(|i| CABIN_LENGTH * i as f64 / c.nx as f64)
        .collect();
    let ys: Vec<f64> = (0..=c.ny)
        .map(|j| -a + 2.0 * a * j as f64 / c.ny as f64)
        .collect();
    let zs: Vec<f64> = (0..=c.nf)
        .map(|l| FLOOR_HEIGHT * l as f64 / c.nf as f64)
        .collect();

    // Cabin skins: belly, side skins, roof.
    let cabin_rings: Vec<Vec<[f64; 3]>> = xs
        .iter()
        .map(|&x| lp.iter().map(|p| [x, p[0], p[1]]).collect())
        .collect();
    b.rings(&lparts, &cabin_rings);

    // Cabin floor.
    let floor: Vec<Vec<[f64; 3]>> = xs
        .iter()
        .map(|&x| ys.iter().map(|&y| [x, y, FLOOR_HEIGHT]).collect())
        .collect();
    let floor_ids = b.grid(P::CabinFloor, &floor);

    // Keel beam webs at y = -a/2 and +a/2.
    let keel_j = [c.ny / 4, 3 * c.ny / 4];
    for &j in &keel_j {
        let web: Vec<Vec<[f64; 3]>> = xs
            .iter()
            .map(|&x| zs.iter().map(|&z| [x, ys[j], z]).collect())
            .collect();
        b.grid(P::KeelBeamWeb, &web);
    }

    // Subfloor ribs at five stations; keel stiffeners midway between them, on both sides
    // of each web.
    let rib_every = c.nx / 4;
    for r in 0..=4 {
        let x = xs[r * rib_every];
        let rib: Vec<Vec<[f64; 3]>> = ys
            .iter()
            .map(|&y| zs.iter().map(|&z| [x, y, z]).collect())
            .collect();
        b.grid(P::SubfloorRibs, &rib);
    }
    for r in 0..4 {
        let i = (r * rib_every + rib_every / 2).max(1);
        let x = xs[i];
        for &j in &keel_j {
            for jj in [j - 1, j + 1] {
                let (y0, y1) = if jj < j {
                    (ys[jj], ys[j])
                } else {
                    (ys[j], ys[jj])
                };
                let plate: Vec<Vec<[f64; 3]>> = [y0, y1]
                    .iter()
                    .map(|&y| zs.iter().map(|&z| [x, y, z]).collect())
                    .collect();
                b.grid(P::KeelBeamStiffener, &plate);
            }
        }
    }

    // Back panel: the cabin's rear bulkhead above the floor (Coons patch).
    let arc: Vec<[f64; 3]> = upper_arc(c).iter().map(|p| [0.0, p[0], p[1]]).collect();
    let na = arc.len() - 1;
    let bottom: Vec<[f64; 3]> = ys.iter().map(|&y| [0.0, y, FLOOR_HEIGHT]).collect();
    let top: Vec<[f64; 3]> = (0..=c.ny).map(|j| arc[c.ns + c.ny - j]).collect();
    let left: Vec<[f64; 3]> = (0..=c.ns).map(|l| arc[na - l]).collect();
    let right: Vec<[f64; 3]> = (0..=c.ns).map(|l| arc[l]).collect();
    let mut back = coons(&bottom, &top, &left, &right);
    smooth(&mut back, 50);
    let back_ids = b.grid(P::BackPanel, &back);

    // Nose: a loft of the cabin loop shrinking about a centre, closed by a domed cap.
    let zc = 28.0;
    let xi_end: f64 = 0.85;
    let nose_rings: Vec<Vec<[f64; 3]>> = (0..=c.nose)
        .map(|r| {
            let xi = xi_end * r as f64 / c.nose as f64;
            let s = (1.0 - xi * xi).sqrt();
            let x = CABIN_LENGTH + NOSE_LENGTH * xi;
            lp.iter()
                .map(|p| [x, s * p[0], zc + s * (p[1] - zc)])
                .collect()
        })
        .collect();
    b.rings(&vec![P::Nose; n_loop], &nose_rings);
    let tip = &nose_rings[c.nose];
    let side = c.nf + c.ns;
    let cap_bottom: Vec<[f64; 3]> = (0..=c.ny).map(|j| tip[j]).collect();
    let cap_right: Vec<[f64; 3]> = (0..=side).map(|l| tip[c.ny + l]).collect();
    let cap_top: Vec<[f64; 3]> = (0..=c.ny).map(|j| tip[c.ny + side + c.ny - j]).collect();
    let cap_left: Vec<[f64; 3]> = (0..=side).map(|l| tip[(n_loop - l) % n_loop]).collect();
    let mut cap = coons(&cap_bottom, &cap_top, &cap_left, &cap_right);
    smooth(&mut cap, 50);
    let (ni, nj) = (cap.len() - 1, cap[0].len() - 1);
    for (i, row) in cap.iter_mut().enumerate() {
        for (j, p) in row.iter_mut().enumerate() {
            let u = i as f64 / ni as f64;
            let v = j as f64 / nj as f64;
            p[0] += 10.0 * 16.0 * u * (1.0 - u) * v * (1.0 - v);
        }
    }
    b.grid(P::Nose, &cap);

    // Engine fairing: a loft from the cabin loop to a circle about the boom axis.
    let phi0 = (-zc).atan2(-a);
    let circle = |x: f64, r: f64, n: usize, phase: f64| -> Vec<[f64; 3]> {
        (0..n)
            .map(|k| {
                let phi = phase + std::f64::consts::TAU * k as f64 / n as f64;
                [x, r * phi.cos(), BOOM_AXIS + r * phi.sin()]
            })
            .collect()
    };
    // Phase such that a node of every other one (the boom's) sits on top of the boom.
    let top_k = ((std::f64::consts::FRAC_PI_2 - phi0) / std::f64::consts::TAU
        * (n_loop / 2) as f64)
        .round();
    let phase = std::f64::consts::FRAC_PI_2 - std::f64::consts::TAU * top_k / (n_loop / 2) as f64;
    let end_ring = circle(-FAIRING_LENGTH, FAIRING_END_RADIUS, n_loop, phase);
    let fairing_rings: Vec<Vec<[f64; 3]>> = (0..=c.fairing)
        .map(|r| {
            let w = r as f64 / c.fairing as f64;
            lp.iter()
                .zip(&end_ring)
                .map(|(p, q)| {
                    let s = w * w * (3.0 - 2.0 * w);
                    [
                        -FAIRING_LENGTH * w,
                        p[0] + s * (q[1] - p[0]),
                        p[1] + s * (q[2] - p[1]),
                    ]
                })
                .collect()
        })
        .collect();
    let fairing_ids = b.rings(&vec![P::EngineFairing; n_loop], &fairing_rings);

    // Tail boom: a 2:1 ring of triangles, then a tapered tube.
    let nb = n_loop / 2;
    let boom_len_step = BOOM_LENGTH / c.boom as f64;
    let boom_rings: Vec<Vec<[f64; 3]>> = (0..=c.boom)
        .map(|r| {
            let w = r as f64 / c.boom as f64;
            let radius = BOOM_RADII.0 + w * (BOOM_RADII.1 - BOOM_RADII.0);
            circle(
                -FAIRING_LENGTH - boom_len_step - BOOM_LENGTH * w,
                radius,
                nb,
                phase,
            )
        })
        .collect();
    let boom_ids = b.rings(&vec![P::TailBoom; nb], &boom_rings);
    let ring_a = fairing_ids[c.fairing].clone();
    let ring_b = boom_ids[0].clone();
    for k in 0..nb {
        let (a0, a1, a2) = (
            ring_a[2 * k],
            ring_a[2 * k + 1],
            ring_a[(2 * k + 2) % n_loop],
        );
        let (b0, b1) = (ring_b[k], ring_b[(k + 1) % nb]);
        b.shells.push(([a0, a1, b0, b0], P::TailBoom));
        b.shells.push(([a1, b1, b0, b0], P::TailBoom));
        b.shells.push(([a1, a2, b1, b1], P::TailBoom));
    }

    // Fins and stabiliser on the last boom stations.
    let top_node = top_k as usize % nb;
    let nearest = |angle: f64| -> usize {
        let k = ((angle - phase) / std::f64::consts::TAU * nb as f64).round() as i64;
        k.rem_euclid(nb as i64) as usize
    };
    let bottom_node = nearest(-std::f64::consts::FRAC_PI_2);
    let fin = |b: &mut Builder,
               part,
               node: usize,
               rise: [f64; 3],
               stations: (usize, usize),
               nh: usize| {
        let root: Vec<[f64; 3]> = (stations.0..=stations.1)
            .map(|r| b.nodes[boom_ids[r][node] as usize])
            .collect();
        let pts: Vec<Vec<[f64; 3]>> = root
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let taper = 1.0 - 0.3 * (i as f64 / (root.len() - 1).max(1) as f64);
                (0..=nh)
                    .map(|h| {
                        let s = h as f64 / nh as f64;
                        lerp(
                            *p,
                            [
                                p[0] + rise[0],
                                p[1] + rise[1] * taper,
                                p[2] + rise[2] * taper,
                            ],
                            s,
                        )
                    })
                    .collect()
            })
            .collect();
        b.grid(part, &pts)
    };
    let fin_root = (c.boom - c.fin, c.boom);
    let upper = fin(
        &mut b,
        P::UpperTail,
        top_node,
        [-10.0, 0.0, 28.0],
        fin_root,
        c.fin,
    );
    let lower = fin(
        &mut b,
        P::LowerTail,
        bottom_node,
        [-6.0, 0.0, -16.0],
        fin_root,
        (c.fin / 2).max(1),
    );
    let stab_root = (c.boom - 2 * c.fin, c.boom - c.fin);
    for (angle, dir) in [(0.0, 1.0), (std::f64::consts::PI, -1.0)] {
        fin(
            &mut b,
            P::HorizontalStabilizer,
            nearest(angle),
            [-4.0, 26.0 * dir, 0.0],
            stab_root,
            c.fin,
        );
    }

    // Mass sites.
    let mut sites: Vec<(MassSite, Vec<u32>)> = Vec::new();
    let near_back: Vec<u32> = {
        let mut v: Vec<u32> = Vec::new();
        // Roof nodes over the aft quarter of the cabin and the top of the back panel.
        for (i, x) in xs.iter().enumerate() {
            if *x > 0.25 * CABIN_LENGTH + 1e-9 {
                break;
            }
            let _ = i;
            for (k, p) in lp.iter().enumerate() {
                if lparts[k] == P::Roof || (k > 0 && lparts[k - 1] == P::Roof) {
                    v.push(b.node([*x, p[0], p[1]]));
                }
            }
        }
        for row in &back_ids {
            if let Some(&n) = row.last() {
                v.push(n);
            }
        }
        v
    };
    sites.push((MassSite::RotorTransmission, dedup(near_back)));
    // Engine: the lower half of the first half of the fairing.
    let mut engine = Vec::new();
    for ring in fairing_ids.iter().take(c.fairing / 2 + 1).skip(1) {
        for &n in ring {
            if b.nodes[n as usize][2] < BOOM_AXIS - 5.0 {
                engine.push(n);
            }
        }
    }
    sites.push((MassSite::Engine, dedup(engine)));
    // Fuel over the aft 30 % of the floor, seats and occupants over the floor ahead of it.
    let (mut fuel, mut occupants) = (Vec::new(), Vec::new());
    for (i, row) in floor_ids.iter().enumerate() {
        let x = xs[i];
        for &n in &row[1..row.len() - 1] {
            if x <= 0.3 * CABIN_LENGTH + 1e-9 {
                fuel.push(n);
            } else if x <= 0.9 * CABIN_LENGTH + 1e-9 {
                occupants.push(n);
            }
        }
    }
    sites.push((MassSite::Fuel, dedup(fuel)));
    sites.push((MassSite::Occupants, dedup(occupants)));
    // Tail: the last boom ring and the fin roots.
    let mut tail: Vec<u32> = boom_ids[c.boom].clone();
    tail.extend(upper.iter().map(|r| r[0]));
    tail.extend(lower.iter().map(|r| r[0]));
    sites.push((MassSite::Tail, dedup(tail)));

    Mesh {
        nodes: b.nodes,
        shells: b.shells,
        sites,
    }
}

fn dedup(mut v: Vec<u32>) -> Vec<u32> {
    v.sort_unstable();
    v.dedup();
    v
}

/// Farthest-point sampling of `count` nodes (indices), starting from the node nearest to
/// `start`: each new node is the one farthest from all chosen so far (ties to the lower
/// index). Deterministic; returns the indices sorted.
pub(crate) fn spread_nodes(nodes: &[[f64; 3]], count: usize, start: [f64; 3]) -> Vec<u32> {
    let n = nodes.len();
    let count = count.min(n);
    if count == 0 {
        return Vec::new();
    }
    let d2 = |p: [f64; 3], q: [f64; 3]| (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>();
    let mut best = f64::INFINITY;
    let mut first = 0;
    for (i, p) in nodes.iter().enumerate() {
        let d = d2(*p, start);
        if d < best {
            best = d;
            first = i;
        }
    }
    let mut dist: Vec<f64> = nodes.iter().map(|p| d2(*p, nodes[first])).collect();
    let mut chosen = vec![first as u32];
    while chosen.len() < count {
        let mut arg = 0;
        let mut far = -1.0;
        for (i, &d) in dist.iter().enumerate() {
            if d > far {
                far = d;
                arg = i;
            }
        }
        chosen.push(arg as u32);
        let p = nodes[arg];
        for (i, q) in nodes.iter().enumerate() {
            let d = d2(*q, p);
            if d < dist[i] {
                dist[i] = d;
            }
        }
    }
    chosen.sort_unstable();
    chosen
}
