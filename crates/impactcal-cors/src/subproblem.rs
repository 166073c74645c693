//! The auxiliary problem of a CORS step and the maximin distance.
//!
//! With `X` the evaluated and pending points, a CORS step solves
//!
//! ```text
//! minimise s(x)  over x in [0, 1]^d
//! subject to |x - x_j| >= r_j for every x_j in X,
//! ```
//!
//! where `r_j = max(beta Delta, floor)` (and at least the failure radius around a failed
//! point) and `Delta = max_x min_j |x - x_j|` is the maximin distance, the radius of the
//! largest empty ball centred in the box.
//!
//! The solver is a multistart: randomly shifted Sobol' candidates (which also estimate `Delta`,
//! refined by a compass search on the maximin point) and Gaussian perturbations of the best
//! point are screened; the `K` feasible candidates with the lowest `s` and the maximin point
//! start a projected-gradient descent (steps along `-grad s`, projection onto the box and
//! radially out of every violated ball, Armijo backtracking, only feasible iterates
//! accepted). The best feasible end point wins; the maximin point, feasible for every
//! `beta <= 1`, is the fallback.

use impactcal_core::sampling::Sobol;
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

use crate::geometry::{Columns, min_of};
use crate::surrogate::RbfSurrogate;

/// Candidates per parallel task: small batches cost more in scheduling than they save.
const PAR_CHUNK: usize = 1024;

/// Screening work (candidates x points x dimension) below which the thread pool costs more
/// than it saves: such screenings run on the calling thread. Either way the results, and
/// their order, are the same.
const PAR_MIN_WORK: usize = 1 << 21;

/// `f` applied to every candidate (row-major, `dim` values each), in order: in parallel
/// when the screening against `points` points is large enough to pay for the thread pool.
fn screen<T: Send>(
    cands: &[f64],
    dim: usize,
    points: usize,
    f: impl Fn(&[f64]) -> T + Sync + Send,
) -> Vec<T> {
    if cands.len() * (points + 1) < PAR_MIN_WORK {
        cands.chunks_exact(dim).map(f).collect()
    } else {
        cands
            .par_chunks_exact(dim)
            .with_min_len(PAR_CHUNK)
            .map(f)
            .collect()
    }
}

/// Points that a new point must keep away from, in the unit box.
#[derive(Debug, Clone, Default)]
pub struct Blockers {
    /// Dimension.
    pub dim: usize,
    /// Successful, pending and already chosen points, row-major.
    pub ok: Vec<f64>,
    /// Failed points, row-major.
    pub failed: Vec<f64>,
}

impl Blockers {
    /// An empty set in `dim` dimensions.
    pub fn new(dim: usize) -> Self {
        Blockers {
            dim,
            ..Default::default()
        }
    }

    /// Whether there is no point at all.
    pub fn is_empty(&self) -> bool {
        self.ok.is_empty() && self.failed.is_empty()
    }
}

/// The points of [`Blockers`] stored coordinate by coordinate, for the many distance
/// queries of one step. Its distances equal those of the row-wise loops bit for bit.
struct BlockerColumns {
    ok: Columns,
    failed: Columns,
}

impl BlockerColumns {
    fn new(blockers: &Blockers) -> Self {
        BlockerColumns {
            ok: Columns::new(&blockers.ok, blockers.dim),
            failed: Columns::new(&blockers.failed, blockers.dim),
        }
    }

    /// `(min distance to ok points, min distance to failed points)`.
    fn min_distances(&self, x: &[f64]) -> (f64, f64) {
        (self.ok.min_distance(x), self.failed.min_distance(x))
    }

    /// Distance to the nearest point of either kind.
    fn min_distance(&self, x: &[f64]) -> f64 {
        let (a, b) = self.min_distances(x);
        a.min(b)
    }
}

/// The box a step searches: the unit box, or a sub-box of it around the best point.
#[derive(Debug, Clone, PartialEq)]
pub struct Region {
    /// Lower corner.
    pub lo: Vec<f64>,
    /// Upper corner.
    pub hi: Vec<f64>,
}

impl Region {
    /// The unit box `[0, 1]^dim`.
    pub fn unit(dim: usize) -> Self {
        Region {
            lo: vec![0.0; dim],
            hi: vec![1.0; dim],
        }
    }

    /// The box of half-width `half` around `centre`, cut to the unit box.
    pub fn around(centre: &[f64], half: f64) -> Self {
        Region {
            lo: centre.iter().map(|c| (c - half).max(0.0)).collect(),
            hi: centre.iter().map(|c| (c + half).min(1.0)).collect(),
        }
    }

    /// Clamps `x` into the box.
    pub fn clip(&self, x: &mut [f64]) {
        for ((v, l), h) in x.iter_mut().zip(&self.lo).zip(&self.hi) {
            *v = v.clamp(*l, *h);
        }
    }

    /// Maps points of the unit box (row-major) affinely into the box.
    fn map_unit(&self, pts: &mut [f64]) {
        let dim = self.lo.len();
        for p in pts.chunks_exact_mut(dim) {
            for ((v, l), h) in p.iter_mut().zip(&self.lo).zip(&self.hi) {
                *v = l + (h - l) * *v;
            }
        }
    }
}

/// The radii of one step.
#[derive(Debug, Clone, Copy)]
pub struct Radii {
    /// Around successful and pending points.
    pub ok: f64,
    /// Around failed points.
    pub failed: f64,
}

impl Radii {
    /// Slack `min_j (|x - x_j| - r_j)`: feasible when non-negative.
    fn slack(&self, dists: (f64, f64)) -> f64 {
        (dists.0 - self.ok).min(dists.1 - self.failed)
    }
}

/// Settings of one step.
#[derive(Debug, Clone, Copy)]
pub struct StepSettings {
    /// `beta` of this step.
    pub beta: f64,
    /// Absolute distance floor.
    pub floor: f64,
    /// Absolute radius around failed points.
    pub failure_radius: f64,
    /// Number of quasi-random candidates.
    pub candidates: usize,
    /// Number of candidates around the best point.
    pub local_candidates: usize,
    /// Number of polished starts.
    pub polish_starts: usize,
    /// Probability of perturbing each coordinate of a candidate around the best point
    /// (`None`: all coordinates move).
    pub perturb: Option<f64>,
    /// The weight `w` of SRBF's merit function for this step (`None`: CORS's constrained
    /// minimisation). See [`merit_choice`].
    pub merit_weight: Option<f64>,
    /// Factor on the standard deviations of the candidates around the best point (1 but
    /// in the local cycles of an adaptive region, where it is the half-width's ratio to its
    /// initial value).
    pub sigma_scale: f64,
}

/// What a step chose.
#[derive(Debug, Clone, PartialEq)]
pub struct Choice {
    /// The point in the unit box.
    pub x: Vec<f64>,
    /// The estimated maximin distance `Delta` before the point was added.
    pub delta: f64,
    /// The distance imposed, `max(beta Delta, floor)`.
    pub radius: f64,
    /// The surrogate value at `x` (NaN for a maximin point chosen without a surrogate).
    pub predicted: f64,
}

/// Sobol' candidates of the unit box with a random digital shift (every coordinate's bits
/// XORed with a random word, which keeps the net structure and is far cheaper than Owen
/// scrambling), drawn from the stream.
fn global_candidates(dim: usize, n: usize, rng: &mut impl Rng) -> Vec<f64> {
    const SCALE: f64 = 1.0 / 4_294_967_296.0;
    let shift: Vec<u32> = (0..dim).map(|_| rng.random()).collect();
    match (Sobol::new(dim), u32::try_from(n)) {
        (Ok(sobol), Ok(n)) => {
            let mut out = Vec::with_capacity(n as usize * dim);
            let mut bits = vec![0u32; dim];
            for i in 0..n {
                sobol.point_bits(i, &mut bits);
                out.extend(
                    bits.iter()
                        .zip(&shift)
                        .map(|(b, s)| (f64::from(b ^ s) + 0.5) * SCALE),
                );
            }
            out
        }
        // Beyond the Sobol' dimensions (thousands): independent uniform points.
        _ => (0..n * dim).map(|_| rng.random::<f64>()).collect(),
    }
}

/// Gaussian perturbations of `centre`, clipped to the box, with the standard deviation
/// cycling through 0.1, 0.02, 0.004 times `scale`. With `perturb = Some(p)` only a subset
/// of the coordinates moves: each with probability `p`, one drawn uniformly when none is
/// (DYCORS).
fn local_candidates(
    centre: &[f64],
    n: usize,
    region: &Region,
    (perturb, scale): (Option<f64>, f64),
    rng: &mut impl Rng,
) -> Vec<f64> {
    const SIGMAS: [f64; 3] = [0.1, 0.02, 0.004];
    let dim = centre.len();
    let mut out = Vec::with_capacity(n * dim);
    let mut mask = vec![true; dim];
    for k in 0..n {
        let sigma = SIGMAS[k % SIGMAS.len()] * scale;
        if let Some(p) = perturb {
            mask.iter_mut().for_each(|m| *m = rng.random::<f64>() < p);
            if !mask.iter().any(|m| *m) && dim > 0 {
                mask[rng.random_range(0..dim)] = true;
            }
        }
        let mut x: Vec<f64> = centre
            .iter()
            .zip(&mask)
            .map(|(c, moves)| {
                if *moves {
                    let z: f64 = StandardNormal.sample(rng);
                    c + sigma * z
                } else {
                    *c
                }
            })
            .collect();
        region.clip(&mut x);
        out.extend(x);
    }
    out
}

/// Maximises the distance to the nearest blocker from `x` by a compass search.
fn refine_maximin(
    blockers: &BlockerColumns,
    region: &Region,
    mut x: Vec<f64>,
    mut h: f64,
) -> (Vec<f64>, f64) {
    let mut best = blockers.min_distance(&x);
    while h > 1e-5 {
        let mut improved = false;
        for j in 0..x.len() {
            for sign in [1.0, -1.0] {
                let mut y = x.clone();
                y[j] = (y[j] + sign * h).clamp(region.lo[j], region.hi[j]);
                let m = blockers.min_distance(&y);
                if m > best {
                    best = m;
                    x = y;
                    improved = true;
                }
            }
        }
        if !improved {
            h *= 0.5;
        }
    }
    (x, best)
}

/// The maximin point of the box with respect to `blockers` and its distance `Delta`,
/// estimated from `n` shifted Sobol' candidates and refined by a compass search.
pub fn maximin(blockers: &Blockers, n: usize, rng: &mut impl Rng) -> (Vec<f64>, f64) {
    let dim = blockers.dim;
    let cands = global_candidates(dim, n.max(1), rng);
    let near = BlockerColumns::new(blockers);
    let n_points = (blockers.ok.len() + blockers.failed.len()) / dim.max(1);
    let dists: Vec<f64> = screen(&cands, dim, n_points, |c| near.min_distance(c));
    let i = argmax(&dists);
    let start = cands[i * dim..(i + 1) * dim].to_vec();
    let h = 0.5 / (n.max(2) as f64).powf(1.0 / dim as f64);
    refine_maximin(&near, &Region::unit(dim), start, h)
}

fn argmax(v: &[f64]) -> usize {
    let mut k = 0;
    for (i, x) in v.iter().enumerate() {
        if *x > v[k] {
            k = i;
        }
    }
    k
}

/// One CORS step: the feasible point of lowest surrogate value found by the multistart.
/// `best` is the best successful point (centre of the local candidates).
pub fn cors_step(
    surrogate: &RbfSurrogate,
    best: &[f64],
    blockers: &Blockers,
    settings: &StepSettings,
    region: &Region,
    rng: &mut impl Rng,
) -> Choice {
    let dim = blockers.dim;
    let n_global = settings.candidates.max(1);
    let mut cands = global_candidates(dim, n_global, rng);
    region.map_unit(&mut cands);
    cands.extend(local_candidates(
        best,
        settings.local_candidates,
        region,
        (settings.perturb, settings.sigma_scale),
        rng,
    ));
    let near = BlockerColumns::new(blockers);
    // Distances to the blockers and the surrogate: about twice the points.
    let n_points = 2 * (blockers.ok.len() + blockers.failed.len()) / dim.max(1);
    // When the surrogate's centres are the first ok points (the usual case: no merged
    // duplicates), the distances its evaluation forms give their nearest one too.
    let centres = surrogate.centres();
    let shared = blockers.ok.len() >= centres.len()
        && blockers.ok[..centres.len()]
            .iter()
            .zip(centres)
            .all(|(a, b)| a.to_bits() == b.to_bits());
    let others = Columns::new(&blockers.ok[centres.len().min(blockers.ok.len())..], dim);
    let screened: Vec<((f64, f64), f64)> = screen(&cands, dim, n_points, |c| {
        if shared {
            let (value, nearest) = surrogate.value_and_nearest(c);
            let ok = nearest.min(others.min_squared_distance(c)).sqrt();
            ((ok, near.failed.min_distance(c)), value)
        } else {
            (near.min_distances(c), surrogate.value(c))
        }
    });
    // Delta from the global candidates, refined around the best of them.
    let global_min: Vec<f64> = screened[..n_global]
        .iter()
        .map(|((a, b), _)| a.min(*b))
        .collect();
    let i = argmax(&global_min);
    let h = 0.5 / (n_global.max(2) as f64).powf(1.0 / dim as f64);
    let (maximin_x, delta) =
        refine_maximin(&near, region, cands[i * dim..(i + 1) * dim].to_vec(), h);
    if let Some(w) = settings.merit_weight {
        return merit_choice(&cands, &screened, settings, w, delta);
    }
    let r = settings.beta * delta;
    let radii = Radii {
        ok: r.max(settings.floor),
        failed: r.max(settings.failure_radius).max(settings.floor),
    };
    let radius = radii.ok;
    // The K feasible candidates of lowest surrogate value (ties by index).
    let mut feasible: Vec<usize> = (0..screened.len())
        .filter(|&k| radii.slack(screened[k].0) >= 0.0)
        .collect();
    feasible.sort_by(|&a, &b| screened[a].1.total_cmp(&screened[b].1).then(a.cmp(&b)));
    feasible.truncate(settings.polish_starts);
    let mut starts: Vec<Vec<f64>> = feasible
        .iter()
        .map(|&k| cands[k * dim..(k + 1) * dim].to_vec())
        .collect();
    let maximin_ok = radii.slack(near.min_distances(&maximin_x)) >= 0.0;
    if maximin_ok {
        starts.push(maximin_x.clone());
    }
    // A handful of short descents: cheaper in sequence than through the thread pool.
    let polished: Vec<(Vec<f64>, f64)> = starts
        .into_iter()
        .map(|x0| polish(surrogate, &near, region, radii, x0))
        .collect();
    let mut chosen: Option<(Vec<f64>, f64)> = None;
    for (x, f) in polished {
        if chosen.as_ref().is_none_or(|(_, g)| f < *g) {
            chosen = Some((x, f));
        }
    }
    match chosen {
        Some((x, predicted)) => Choice {
            x,
            delta,
            radius,
            predicted,
        },
        None => {
            // No feasible start (only when failed points crowd the maximin point): the
            // candidate with the largest slack.
            let k = argmax(
                &screened
                    .iter()
                    .map(|(d, _)| radii.slack(*d))
                    .collect::<Vec<_>>(),
            );
            let x = if maximin_ok || screened.is_empty() {
                maximin_x
            } else {
                cands[k * dim..(k + 1) * dim].to_vec()
            };
            let predicted = surrogate.value(&x);
            Choice {
                x,
                delta,
                radius,
                predicted,
            }
        }
    }
}

/// SRBF's choice (Regis & Shoemaker, INFORMS J. Comput. 19:497-509, 2007): among the
/// candidates at least the floor from every point (and the failure radius from failed
/// ones), the minimiser of `w V_S + (1 - w) V_D`, with `V_S = (s - s_min)/(s_max - s_min)`
/// and `V_D = (d_max - d)/(d_max - d_min)` scaled over those candidates (`d` the distance
/// to the nearest successful or pending point; a constant criterion scores 1). No
/// polishing: the candidates are the search. Falls back to the candidate of largest slack
/// when none is at the floor.
fn merit_choice(
    cands: &[f64],
    screened: &[((f64, f64), f64)],
    settings: &StepSettings,
    w: f64,
    delta: f64,
) -> Choice {
    let dim = cands.len() / screened.len().max(1);
    let radii = Radii {
        ok: settings.floor,
        failed: settings.failure_radius.max(settings.floor),
    };
    let ok: Vec<usize> = (0..screened.len())
        .filter(|&k| radii.slack(screened[k].0) >= 0.0)
        .collect();
    let k = if ok.is_empty() {
        argmax(
            &screened
                .iter()
                .map(|(d, _)| radii.slack(*d))
                .collect::<Vec<_>>(),
        )
    } else {
        let range = |f: &dyn Fn(usize) -> f64| {
            ok.iter()
                .map(|&k| f(k))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                    (a.min(v), b.max(v))
                })
        };
        let (s_lo, s_hi) = range(&|k| screened[k].1);
        let (d_lo, d_hi) = range(&|k| screened[k].0.0);
        let scale = |v: f64, lo: f64, hi: f64| if hi > lo { (v - lo) / (hi - lo) } else { 1.0 };
        let score = |k: usize| {
            w * scale(screened[k].1, s_lo, s_hi)
                + (1.0 - w) * (1.0 - scale(screened[k].0.0, d_lo, d_hi))
        };
        ok.iter()
            .copied()
            .fold(ok[0], |b, k| if score(k) < score(b) { k } else { b })
    };
    Choice {
        x: cands[k * dim..(k + 1) * dim].to_vec(),
        delta,
        radius: radii.ok,
        predicted: screened[k].1,
    }
}

/// Moves `y` into the box and radially out of every ball it violates (a few passes, each
/// visiting the points in order and moving `y` out of a ball as soon as it lies inside).
/// Returns the distances to the nearest ok and failed points of the final `y` when the
/// last pass moved nothing (`None` when the passes ran out while still moving).
fn project(
    near: &BlockerColumns,
    region: &Region,
    radii: Radii,
    y: &mut [f64],
) -> Option<(f64, f64)> {
    region.clip(y);
    let mut d2 = [0.0; Columns::BLOCK];
    for _ in 0..4 {
        let mut moved = false;
        let mut nearest = [f64::INFINITY; 2];
        for (set, (pts, r)) in [(&near.ok, radii.ok), (&near.failed, radii.failed)]
            .into_iter()
            .enumerate()
        {
            // A squared distance of at least `clear` has a distance of at least `r` (the
            // margin covers the rounding of `r * r` and of the square root), so a block
            // without a smaller positive one needs no square root.
            let clear = r * r * (1.0 + 1e-12);
            let mut i = 0;
            while i < pts.len() {
                let d2 = &mut d2[..Columns::BLOCK.min(pts.len() - i)];
                pts.squared_distances(y, i, d2);
                let suspect = d2.iter().fold(false, |s, &q| s | ((q < clear) & (q > 0.0)));
                let inside = if suspect {
                    d2.iter().position(|&q| {
                        let dist = q.sqrt();
                        dist < r && dist > 0.0
                    })
                } else {
                    None
                };
                match inside {
                    None => {
                        nearest[set] = nearest[set].min(min_of(d2));
                        i += d2.len();
                    }
                    Some(k) => {
                        let p = i + k;
                        let scale = r * (1.0 + 1e-9) / d2[k].sqrt();
                        for (j, yj) in y.iter_mut().enumerate() {
                            let pj = pts.coordinate(p, j);
                            *yj = pj + (*yj - pj) * scale;
                        }
                        moved = true;
                        i = p + 1;
                    }
                }
            }
        }
        region.clip(y);
        if !moved {
            return Some((nearest[0].sqrt(), nearest[1].sqrt()));
        }
    }
    None
}

/// Projected-gradient descent of `s` from the feasible `x0`; returns the end point and its
/// value. Every accepted iterate is feasible.
fn polish(
    s: &RbfSurrogate,
    near: &BlockerColumns,
    region: &Region,
    radii: Radii,
    x0: Vec<f64>,
) -> (Vec<f64>, f64) {
    const MAX_ITER: usize = 100;
    let dim = s.dim();
    let mut x = x0;
    let mut grad = vec![0.0; dim];
    let mut f = s.value_gradient(&x, &mut grad);
    let mut step = 0.05;
    let mut y = vec![0.0; dim];
    for _ in 0..MAX_ITER {
        let gnorm = grad.iter().map(|g| g * g).sum::<f64>().sqrt();
        if !(gnorm > 0.0 && gnorm.is_finite()) {
            break;
        }
        let mut accepted = false;
        while step > 1e-9 {
            for ((yj, xj), gj) in y.iter_mut().zip(&x).zip(&grad) {
                *yj = xj - step * gj / gnorm;
            }
            let nearest = project(near, region, radii, &mut y);
            let descent: f64 = grad
                .iter()
                .zip(&x)
                .zip(&y)
                .map(|((g, a), b)| g * (a - b))
                .sum();
            if descent > 0.0
                && radii.slack(nearest.unwrap_or_else(|| near.min_distances(&y))) >= 0.0
            {
                let fy = s.value(&y);
                if fy <= f - 1e-4 * descent {
                    x.copy_from_slice(&y);
                    f = s.value_gradient(&x, &mut grad);
                    step = (step * 2.0).min(0.5);
                    accepted = true;
                    break;
                }
            }
            step *= 0.5;
        }
        if !accepted {
            break;
        }
    }
    (x, f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// With a perturbation probability each candidate moves at least one coordinate and,
    /// at probability 0, exactly one; without it every coordinate moves.
    #[test]
    #[allow(clippy::float_cmp)] // exact values by construction
    fn perturbation_masks_coordinates() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let centre = vec![0.5; 6];
        let region = Region::unit(6);
        let moved = |c: &[f64]| c.iter().filter(|v| **v != 0.5).count();
        let none = local_candidates(&centre, 300, &region, (Some(0.0), 1.0), &mut rng);
        assert!(none.chunks_exact(6).all(|c| moved(c) == 1));
        let half = local_candidates(&centre, 300, &region, (Some(0.5), 1.0), &mut rng);
        let counts: Vec<usize> = half.chunks_exact(6).map(moved).collect();
        assert!(counts.iter().all(|n| *n >= 1));
        let mean = counts.iter().sum::<usize>() as f64 / 300.0;
        assert!((mean - 3.0).abs() < 0.4, "{mean}");
        let all = local_candidates(&centre, 300, &region, (None, 1.0), &mut rng);
        assert!(all.chunks_exact(6).all(|c| moved(c) == 6));
    }

    /// SRBF's merit: weight 1 takes the lowest surrogate value, weight 0 the candidate
    /// farthest from the points, among those at the floor distance.
    #[test]
    #[allow(clippy::float_cmp)] // exact values by construction
    fn merit_weights_trade_value_for_distance() {
        let cands = vec![0.0, 1.0, 2.0, 3.0];
        // ((distance to ok points, to failed points), surrogate value)
        let screened = vec![
            ((0.0005, 9.0), -5.0),
            ((0.1, 9.0), 1.0),
            ((0.2, 9.0), 2.0),
            ((0.4, 9.0), 3.0),
        ];
        let settings = StepSettings {
            beta: 0.0,
            floor: 0.001,
            failure_radius: 0.0,
            candidates: 4,
            local_candidates: 0,
            polish_starts: 1,
            perturb: None,
            merit_weight: None,
            sigma_scale: 1.0,
        };
        let pick = |w| merit_choice(&cands, &screened, &settings, w, 0.5).x[0];
        assert_eq!(pick(1.0), 1.0);
        assert_eq!(pick(0.0), 3.0);
        // w = 0.4: scores 0.4 (0, 1/2, 1) + 0.6 (1, 2/3, 0) = (0.6, 0.6, 0.4).
        assert_eq!(pick(0.4), 3.0);
        assert_eq!(pick(0.8), 1.0);
    }

    /// The column-wise screening distance equals the row-wise one bit for bit, for point
    /// counts below, at and above the block size and for no points at all.
    #[test]
    fn column_distances_equal_row_distances_exactly() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for (n, dim) in [(0, 3), (1, 2), (63, 6), (64, 4), (200, 10)] {
            let mut b = Blockers::new(dim);
            b.ok = (0..n * dim).map(|_| rng.random::<f64>()).collect();
            let cols = Columns::new(&b.ok, dim);
            for _ in 0..50 {
                let x: Vec<f64> = (0..dim).map(|_| rng.random_range(-0.2..1.2)).collect();
                let row =
                    b.ok.chunks_exact(dim)
                        .map(|p| crate::geometry::squared_distance(&x, p))
                        .fold(f64::INFINITY, f64::min)
                        .sqrt();
                assert_eq!(cols.min_distance(&x).to_bits(), row.to_bits(), "n = {n}");
            }
        }
    }
}
