//! The update engine shared by backward elimination and forward addition.
//!
//! The engine keeps a set `S` of blocks (a block is one candidate DOF, or the DOFs of one
//! node) and, for every tracked block `b` outside or inside `S`, the block
//! `E_bb = Phi_b A^-1 Phi_b^T` of the projector, where `A = Phi_S^T Phi_S`.
//!
//! It never forms `A^-1` in the original coordinates. At a refresh it factors
//! `Phi_S = Q R` (thin QR) and stores the whitened rows `w_i = phi_i R^-1`, for which the
//! information matrix is the identity. Between refreshes it keeps `P`, the inverse
//! information matrix in whitened coordinates (`P = I` right after a refresh), and updates
//! `P` and every tracked `E_bb` after each change of `S` by Sherman-Morrison (one row) or
//! Woodbury (a block of rows): adding (`sigma = +1`) or removing (`sigma = -1`) rows `U`,
//! with `Z = P U^T` and `G = U Z`,
//!
//! ```text
//! P    <- P    - sigma Z (I + sigma G)^-1 Z^T
//! E_bb <- E_bb - sigma B (I + sigma G)^-1 B^T,   B = W_b Z
//! det(A') = det(A) det(I + sigma G)
//! ```
//!
//! Per node, every tracked `E_bb` is updated after each step, `O(s k)`. Per DOF, only `P`
//! is updated (`O(k^2)`); a DOF's score `w_i P w_i^T` is re-evaluated lazily, only when it
//! reaches the top of a heap of earlier scores (see [`Engine::best`]), which gives the same
//! choices as updating every score. A refresh costs `O(s k^2)` and removes rounding drift:
//! per node every `refresh_every` steps, per DOF after `refresh_every` steps or after half
//! of the candidates tracked at the last refresh are gone, whichever is later.

use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

use rayon::prelude::*;

use crate::linalg::{dot, r_factor, small_det, small_spd_inverse, whiten_row};

/// Heap key of a per-DOF position: (score, negated for addition; block id; position),
/// ordered by score then block id.
#[derive(Debug, Clone, Copy)]
struct Key(f64, usize, usize);

impl PartialEq for Key {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Key {}
impl PartialOrd for Key {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Key {
    fn cmp(&self, other: &Self) -> Ordering {
        self.0.total_cmp(&other.0).then(self.1.cmp(&other.1))
    }
}

/// Whether steps remove blocks from the set or add blocks to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Sweep {
    /// Backward elimination: tracked blocks are in the set; the score of a block is the
    /// fraction of `det(A)` lost by removing it, `1 - det(I - E_bb)`.
    Remove,
    /// Forward addition: tracked blocks are outside the set; the score of a block is the
    /// fractional gain of `det(A)` by adding it, `det(I + E_bb) - 1`.
    Add,
}

pub(crate) struct Engine {
    k: usize,
    phi: Vec<f64>,
    blocks: Vec<Vec<usize>>,
    in_set: Vec<bool>,
    sweep: Sweep,
    sigma: f64,
    per_dof: bool,
    /// Tracked block ids, ascending, and whether each is still tracked.
    ids: Vec<usize>,
    alive: Vec<bool>,
    /// Per-DOF mode: whitened rows, row-major (`ids.len() x k`); `e[pos]` is the score of
    /// `pos` as last evaluated, at step `stamp[pos]`; `heap` orders positions by that
    /// (possibly stale) score.
    wc: Vec<f64>,
    e: Vec<f64>,
    stamp: Vec<u64>,
    step: u64,
    heap: BinaryHeap<Reverse<Key>>,
    /// Block mode: whitened rows, row-major, block `pos` at rows `off[pos]..off[pos + 1]`,
    /// and each block's `E_bb` (row-major, up to 3 x 3).
    wr: Vec<f64>,
    off: Vec<usize>,
    gram: Vec<[f64; 9]>,
    /// Inverse information matrix in whitened coordinates, `k x k` row-major.
    p: Vec<f64>,
    since_refresh: usize,
    refresh_every: usize,
}

impl Engine {
    /// Builds the engine. `phi` is row-major `rows x k`; `blocks[b]` lists the rows of block
    /// `b` (at most 3, or exactly 1 when `per_dof`); `in_set[b]` says whether `b` starts in
    /// the set; `tracked` lists (ascending) the blocks whose scores are wanted. The rows of
    /// the starting set must have full column rank.
    pub(crate) fn new(
        k: usize,
        phi: Vec<f64>,
        blocks: Vec<Vec<usize>>,
        in_set: Vec<bool>,
        tracked: Vec<usize>,
        sweep: Sweep,
        refresh_every: usize,
    ) -> Self {
        let per_dof = blocks.iter().all(|b| b.len() == 1);
        let mut engine = Engine {
            k,
            phi,
            blocks,
            in_set,
            sweep,
            sigma: match sweep {
                Sweep::Remove => -1.0,
                Sweep::Add => 1.0,
            },
            per_dof,
            alive: vec![true; tracked.len()],
            ids: tracked,
            wc: Vec::new(),
            e: Vec::new(),
            stamp: Vec::new(),
            step: 0,
            heap: BinaryHeap::new(),
            wr: Vec::new(),
            off: Vec::new(),
            gram: Vec::new(),
            p: Vec::new(),
            since_refresh: 0,
            refresh_every,
        };
        engine.refresh();
        engine
    }

    /// Rows of all blocks in the set.
    pub(crate) fn set_rows(&self) -> Vec<usize> {
        self.blocks
            .iter()
            .zip(&self.in_set)
            .filter(|(_, s)| **s)
            .flat_map(|(b, _)| b.iter().copied())
            .collect()
    }

    /// Whether block `b` is in the set.
    pub(crate) fn in_set(&self) -> &[bool] {
        &self.in_set
    }

    /// Recomputes the whitening from a fresh QR of the set and every tracked `E_bb`
    /// from it, dropping blocks no longer tracked.
    pub(crate) fn refresh(&mut self) {
        let k = self.k;
        let r = r_factor(&self.phi, k, &self.set_rows());
        let (ids, alive) = (
            std::mem::take(&mut self.ids),
            std::mem::take(&mut self.alive),
        );
        self.ids = ids
            .into_iter()
            .zip(alive)
            .filter(|(_, a)| *a)
            .map(|(id, _)| id)
            .collect();
        let n = self.ids.len();
        self.alive = vec![true; n];
        let whiten = |row: usize| {
            let mut w = vec![0.0; k];
            whiten_row(&self.phi[row * k..(row + 1) * k], r.as_ref(), &mut w);
            w
        };
        if self.per_dof {
            let rows: Vec<Vec<f64>> = self
                .ids
                .par_iter()
                .map(|&b| whiten(self.blocks[b][0]))
                .collect();
            self.wc = rows.concat();
            self.e = rows.iter().map(|w| dot(w, w)).collect();
            self.stamp = vec![self.step; n];
            self.heap = (0..n).map(|pos| Reverse(self.key(pos))).collect();
        } else {
            self.wr.clear();
            self.off = vec![0];
            self.gram.clear();
            for &b in &self.ids {
                let start = self.wr.len();
                for &row in &self.blocks[b] {
                    self.wr.extend(whiten(row));
                }
                let nb = self.blocks[b].len();
                let wb = &self.wr[start..];
                let mut g = [0.0; 9];
                for i in 0..nb {
                    for j in 0..nb {
                        g[i * nb + j] = dot(&wb[i * k..(i + 1) * k], &wb[j * k..(j + 1) * k]);
                    }
                }
                self.gram.push(g);
                self.off.push(self.off[self.off.len() - 1] + nb);
            }
        }
        self.p = vec![0.0; k * k];
        for i in 0..k {
            self.p[i * k + i] = 1.0;
        }
        self.since_refresh = 0;
    }

    /// Score of tracked position `pos` (see [`Sweep`]).
    fn score(&self, pos: usize) -> f64 {
        if self.per_dof {
            // 1 - (1 - E_ii) when removing, (1 + E_ii) - 1 when adding.
            return self.exact_dof(pos);
        }
        let nb = self.off[pos + 1] - self.off[pos];
        let mut m = [0.0; 9];
        for i in 0..nb {
            for j in 0..nb {
                m[i * nb + j] =
                    f64::from(u8::from(i == j)) + self.sigma * self.gram[pos][i * nb + j];
            }
        }
        let d = small_det(&mut m[..nb * nb], nb);
        match self.sweep {
            Sweep::Remove => 1.0 - d,
            Sweep::Add => d - 1.0,
        }
    }

    /// The tracked blocks still available with their current scores, ascending block id.
    pub(crate) fn scores(&self) -> Vec<(usize, f64)> {
        (0..self.ids.len())
            .filter(|&p| self.alive[p])
            .map(|p| (self.ids[p], self.score(p)))
            .collect()
    }

    /// Heap key of per-DOF position `pos` from its last evaluated score.
    fn key(&self, pos: usize) -> Key {
        let v = match self.sweep {
            Sweep::Remove => self.e[pos],
            Sweep::Add => -self.e[pos],
        };
        Key(v, self.ids[pos], pos)
    }

    /// `E_ii = w_i P w_i^T` of per-DOF position `pos` under the current `P` (`O(k^2)`).
    fn exact_dof(&self, pos: usize) -> f64 {
        let k = self.k;
        let w = &self.wc[pos * k..(pos + 1) * k];
        (0..k)
            .map(|i| w[i] * dot(&self.p[i * k..(i + 1) * k], w))
            .sum()
    }

    /// The best tracked block (lowest score when removing, highest when adding; ties go to
    /// the lowest block id) as (position, block id, score).
    ///
    /// Per DOF this is a lazy search: a score only grows as rows are removed (`A` shrinks,
    /// so `A^-1` grows) and only falls as rows are added, so a score evaluated at an earlier
    /// step bounds the current one. The heap is ordered by those bounds; the top is
    /// re-evaluated until its score is current, and then no other block can beat it. The
    /// result is the same as re-scoring every block, at `O(k^2)` per re-evaluation.
    pub(crate) fn best(&mut self) -> Option<(usize, usize, f64)> {
        if self.per_dof {
            while let Some(&Reverse(Key(_, id, pos))) = self.heap.peek() {
                if !self.alive[pos] {
                    self.heap.pop();
                } else if self.stamp[pos] == self.step {
                    return Some((pos, id, self.e[pos]));
                } else {
                    self.heap.pop();
                    self.e[pos] = self.exact_dof(pos);
                    self.stamp[pos] = self.step;
                    let key = self.key(pos);
                    self.heap.push(Reverse(key));
                }
            }
            return None;
        }
        let mut best: Option<(usize, f64)> = None;
        for pos in 0..self.ids.len() {
            if !self.alive[pos] {
                continue;
            }
            let s = self.score(pos);
            let better = match best {
                None => true,
                Some((_, b)) => match self.sweep {
                    Sweep::Remove => s < b,
                    Sweep::Add => s > b,
                },
            };
            if better {
                best = Some((pos, s));
            }
        }
        best.map(|(pos, s)| (pos, self.ids[pos], s))
    }

    /// Moves tracked position `pos` across the set boundary, updates `P` and every tracked
    /// score, and returns `det(A_new) / det(A_old)`.
    pub(crate) fn apply(&mut self, pos: usize) -> f64 {
        let ratio = if self.per_dof {
            self.apply_dof(pos)
        } else {
            self.apply_block(pos)
        };
        self.alive[pos] = false;
        let b = self.ids[pos];
        self.in_set[b] = !self.in_set[b];
        self.since_refresh += 1;
        // Per DOF a refresh costs far more than a step, so it waits until half of the
        // blocks tracked at the last refresh are gone as well (a geometric schedule).
        let due = if self.per_dof {
            self.refresh_every.max(self.ids.len() / 2)
        } else {
            self.refresh_every
        };
        if self.refresh_every > 0 && self.since_refresh >= due {
            self.refresh();
        }
        ratio
    }

    fn apply_dof(&mut self, pos: usize) -> f64 {
        let k = self.k;
        let w = &self.wc[pos * k..(pos + 1) * k];
        let z: Vec<f64> = (0..k)
            .map(|i| dot(&self.p[i * k..(i + 1) * k], w))
            .collect();
        let g = dot(w, &z);
        let denom = 1.0 + self.sigma * g;
        let f = self.sigma / denom;
        for i in 0..k {
            for j in 0..k {
                self.p[i * k + j] -= f * z[i] * z[j];
            }
        }
        self.step += 1;
        denom
    }

    fn apply_block(&mut self, pos: usize) -> f64 {
        let k = self.k;
        let nr = self.off[pos + 1] - self.off[pos];
        let wr_r: Vec<f64> = self.wr[self.off[pos] * k..self.off[pos + 1] * k].to_vec();
        // Z = P U^T (k x nr), stored column by column: z[a] is P u_a.
        let z: Vec<Vec<f64>> = (0..nr)
            .map(|a| {
                let u = &wr_r[a * k..(a + 1) * k];
                (0..k)
                    .map(|i| dot(&self.p[i * k..(i + 1) * k], u))
                    .collect()
            })
            .collect();
        let mut m = vec![0.0; nr * nr];
        for a in 0..nr {
            for c in 0..nr {
                m[a * nr + c] = f64::from(u8::from(a == c))
                    + self.sigma * dot(&wr_r[a * k..(a + 1) * k], &z[c]);
            }
        }
        let minv = small_spd_inverse(&m, nr).unwrap_or_else(|| vec![f64::INFINITY; nr * nr]);
        let ratio = small_det(&mut m.clone(), nr);
        let sigma = self.sigma;
        let (wr, off) = (&self.wr, &self.off);
        let z_ref = &z;
        let minv_ref = &minv;
        self.gram
            .par_iter_mut()
            .enumerate()
            .filter(|(q, _)| self.alive[*q] && *q != pos)
            .for_each(|(q, g)| {
                let nb = off[q + 1] - off[q];
                let wb = &wr[off[q] * k..off[q + 1] * k];
                let mut bm = [0.0; 9];
                for i in 0..nb {
                    for a in 0..nr {
                        bm[i * nr + a] = dot(&wb[i * k..(i + 1) * k], &z_ref[a]);
                    }
                }
                for i in 0..nb {
                    for j in 0..nb {
                        let mut s = 0.0;
                        for a in 0..nr {
                            for c in 0..nr {
                                s += bm[i * nr + a] * minv_ref[a * nr + c] * bm[j * nr + c];
                            }
                        }
                        g[i * nb + j] -= sigma * s;
                    }
                }
            });
        for i in 0..k {
            for j in 0..k {
                let mut s = 0.0;
                for a in 0..nr {
                    for c in 0..nr {
                        s += z[a][i] * minv[a * nr + c] * z[c][j];
                    }
                }
                self.p[i * k + j] -= sigma * s;
            }
        }
        ratio
    }

    /// Fresh scores of the tracked blocks, from a new QR of the set (for checks).
    pub(crate) fn fresh_scores(&self) -> Vec<(usize, f64)> {
        let k = self.k;
        let r = r_factor(&self.phi, k, &self.set_rows());
        let mut out = Vec::new();
        for (pos, &b) in self.ids.iter().enumerate() {
            if !self.alive[pos] {
                continue;
            }
            let rows = &self.blocks[b];
            let nb = rows.len();
            let ws: Vec<Vec<f64>> = rows
                .iter()
                .map(|&row| {
                    let mut w = vec![0.0; k];
                    whiten_row(&self.phi[row * k..(row + 1) * k], r.as_ref(), &mut w);
                    w
                })
                .collect();
            let mut m = vec![0.0; nb * nb];
            for i in 0..nb {
                for j in 0..nb {
                    m[i * nb + j] = f64::from(u8::from(i == j)) + self.sigma * dot(&ws[i], &ws[j]);
                }
            }
            let d = small_det(&mut m, nb);
            let s = match self.sweep {
                Sweep::Remove => 1.0 - d,
                Sweep::Add => d - 1.0,
            };
            out.push((b, s));
        }
        out
    }
}
