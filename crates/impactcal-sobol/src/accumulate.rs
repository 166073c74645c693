//! The one-pass accumulation of design moments, for the point estimate and every bootstrap
//! resample at once.
//!
//! The output matrix is cut into tiles of [`TILE`] columns. A work item is one tile and a
//! block of resamples; it walks the base rows `j` in order, computes the centred per-row
//! terms of the tile once into a scratch buffer, and adds them, weighted by how often
//! resample `g` drew row `j`, into the accumulators of each resample of its block. Every
//! accumulator is a sum over `j` in a fixed order, so results do not depend on the number of
//! threads or on how the work was split.

use faer::MatRef;
use rayon::prelude::*;

use crate::design::DesignLayout;
use crate::estimators::SHARED;

/// Output columns per tile.
pub(crate) const TILE: usize = 32;
/// Accumulator bytes per work item to aim for (cache resident).
const ACC_BYTES: usize = 384 * 1024;

/// What to accumulate.
#[derive(Debug, Clone)]
pub(crate) struct Plan {
    pub layout: DesignLayout,
    pub full: bool,
    pub pairs: Vec<(usize, usize)>,
}

impl Plan {
    pub fn per_param(&self) -> usize {
        if self.full { 5 } else { 2 }
    }

    /// Number of accumulated terms per column.
    pub fn terms(&self) -> usize {
        SHARED + self.layout.d() * self.per_param() + self.pairs.len()
    }

    pub fn param_offset(&self, i: usize) -> usize {
        SHARED + i * self.per_param()
    }

    pub fn pair_offset(&self, p: usize) -> usize {
        SHARED + self.layout.d() * self.per_param() + p
    }
}

/// Resampling weights: `weights[j * groups + g]` is how many times resample `g` drew base
/// row `j` (`g = 0` is the point estimate, weight 1 everywhere). Stored as `u16`: a count
/// is Binomial(N, 1/N), about Poisson(1), so it never comes near 65 535.
pub(crate) struct Weights {
    pub groups: usize,
    pub data: Vec<u16>,
}

/// The sums of one work item: `acc[(g - g0) * terms * width + k * width + t]`.
pub(crate) struct ItemSums {
    pub tile_start: usize,
    pub width: usize,
    pub groups: std::ops::Range<usize>,
    pub acc: Vec<f64>,
}

/// Splits the resamples into blocks whose accumulators fit [`ACC_BYTES`], and into enough
/// blocks to keep every thread busy when there are few tiles.
pub(crate) fn group_blocks(
    plan: &Plan,
    groups: usize,
    tiles: usize,
) -> Vec<std::ops::Range<usize>> {
    let per_group = plan.terms() * TILE * 8;
    let by_cache = (ACC_BYTES / per_group).max(1);
    let threads = rayon::current_num_threads().max(1);
    let wanted_blocks = (4 * threads).div_ceil(tiles.max(1)).max(1);
    let by_threads = groups.div_ceil(wanted_blocks).max(1);
    let size = by_cache.min(by_threads).max(1);
    (0..groups)
        .step_by(size)
        .map(|g| g..(g + size).min(groups))
        .collect()
}

/// Runs every work item over `outputs` (one row per model run) and returns their sums (in
/// no particular order).
pub(crate) fn accumulate(
    plan: &Plan,
    outputs: MatRef<'_, f64>,
    centre: &[f64],
    weights: &Weights,
) -> Vec<ItemSums> {
    let cols = outputs.ncols();
    let tiles: Vec<usize> = (0..cols).step_by(TILE).collect();
    let blocks = group_blocks(plan, weights.groups, tiles.len());
    let items: Vec<(usize, std::ops::Range<usize>)> = tiles
        .iter()
        .flat_map(|&t| blocks.iter().map(move |b| (t, b.clone())))
        .collect();
    items
        .into_par_iter()
        .map(|(t0, groups)| {
            let width = TILE.min(cols - t0);
            accumulate_item(plan, outputs, centre, weights, t0, width, groups)
        })
        .collect()
}

/// Columns `t0 .. t0 + w` of row `r` of `m`: borrowed where the row is contiguous (a
/// row-major view), else copied into `buf`.
fn tile<'a>(m: MatRef<'a, f64>, r: usize, t0: usize, w: usize, buf: &'a mut [f64]) -> &'a [f64] {
    let row = m.row(r).subcols(t0, w);
    match row.try_as_row_major() {
        Some(contiguous) => contiguous.as_slice(),
        None => {
            for (b, v) in buf.iter_mut().zip(row.iter()) {
                *b = *v;
            }
            &buf[..w]
        }
    }
}

fn accumulate_item(
    plan: &Plan,
    outputs: MatRef<'_, f64>,
    centre: &[f64],
    weights: &Weights,
    t0: usize,
    width: usize,
    groups: std::ops::Range<usize>,
) -> ItemSums {
    let layout = &plan.layout;
    let (d, w) = (layout.d(), width);
    let k_terms = plan.terms();
    let per = plan.per_param();
    let mut acc = vec![0.0; groups.len() * k_terms * w];
    let mut scratch = vec![0.0; k_terms * w];
    let mut ab = vec![0.0; d * w];
    let mut ba = vec![0.0; if layout.second_order() { d * w } else { 0 }];
    let mu = &centre[t0..t0 + w];
    let (mut buf_a, mut buf_b, mut buf_x) = (vec![0.0; w], vec![0.0; w], vec![0.0; w]);
    for j in 0..layout.n() {
        let wrow =
            &weights.data[j * weights.groups + groups.start..j * weights.groups + groups.end];
        if wrow.iter().all(|&x| x == 0) {
            continue;
        }
        let ra = tile(outputs, layout.a_row(j), t0, w, &mut buf_a);
        let rb = tile(outputs, layout.b_row(j), t0, w, &mut buf_b);
        let (shared, rest) = scratch.split_at_mut(SHARED * w);
        let (sa, tail) = shared.split_at_mut(w);
        let (sb, tail) = tail.split_at_mut(w);
        let (saa, tail) = tail.split_at_mut(w);
        let (sbb, sab) = tail.split_at_mut(w);
        for t in 0..w {
            let (ca, cb) = (ra[t] - mu[t], rb[t] - mu[t]);
            sa[t] = ca;
            sb[t] = cb;
            saa[t] = ca * ca;
            sbb[t] = cb * cb;
            sab[t] = ca * cb;
        }
        for i in 0..d {
            let rx = tile(outputs, layout.ab_row(j, i), t0, w, &mut buf_x);
            let cx = &mut ab[i * w..(i + 1) * w];
            for t in 0..w {
                cx[t] = rx[t] - mu[t];
            }
            let base = i * per * w;
            let (e1, tail) = rest[base..base + per * w].split_at_mut(w);
            let (e2, tail) = tail.split_at_mut(w);
            for t in 0..w {
                let (ca, cb, x) = (sa[t], sb[t], cx[t]);
                e1[t] = cb * (x - ca);
                e2[t] = (ca - x) * (ca - x);
            }
            if plan.full {
                let (e3, tail) = tail.split_at_mut(w);
                let (mx, qx) = tail.split_at_mut(w);
                for t in 0..w {
                    let (cb, x) = (sb[t], cx[t]);
                    e3[t] = (cb - x) * (cb - x);
                    mx[t] = x;
                    qx[t] = x * x;
                }
            }
        }
        if layout.second_order() {
            for i in 0..d {
                let rx = tile(outputs, layout.ba_row(j, i), t0, w, &mut buf_x);
                for t in 0..w {
                    ba[i * w + t] = rx[t] - mu[t];
                }
            }
            let base = d * per * w;
            for (p, &(i, k)) in plan.pairs.iter().enumerate() {
                let out = &mut rest[base + p * w..base + (p + 1) * w];
                let (x, y) = (&ba[i * w..(i + 1) * w], &ab[k * w..(k + 1) * w]);
                for t in 0..w {
                    out[t] = x[t] * y[t];
                }
            }
        }
        for (g, &weight) in wrow.iter().enumerate() {
            if weight == 0 {
                continue;
            }
            let weight = f64::from(weight);
            let target = &mut acc[g * k_terms * w..(g + 1) * k_terms * w];
            for (s, &v) in target.iter_mut().zip(&scratch) {
                *s += weight * v;
            }
        }
    }
    ItemSums {
        tile_start: t0,
        width: w,
        groups,
        acc,
    }
}
