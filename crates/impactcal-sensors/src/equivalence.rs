//! Candidates that carry the same information: mirror images on a symmetric structure,
//! duplicated channels.
//!
//! Two candidate DOFs whose rows of `Phi` are parallel (`phi_j = c phi_i`) see the same
//! combination of shape coordinates; a sensor at the second only repeats the first, scaled.
//! Effective independence counts that repeat as information: with both rows in the set each
//! has `E_D = e / 2` where one row alone would have `e`, so removing either loses the factor
//! `1 - e / 2`, which on a symmetric structure is often the dearest removal left, and the
//! greedy pass keeps both. Under independent noise a repeat does halve the variance of what
//! the pair sees, but it adds no direction: it cannot tell apart any shape the first sensor
//! could not, and on a symmetric model the two measure one quantity twice. So the placement
//! treats each set of parallel candidates as one candidate.
//!
//! Parallel is judged on the whitened rows `w_i = phi_i R^-1` (`Phi = Q R` over all usable
//! rows), whose directions do not change when `Phi` becomes `Phi T` (`T` invertible): the
//! test is the same for `U_k`, `U_k S_k` or any other basis of the shapes. A block (a node's
//! rows) repeats another of as many rows when it adds the same information up to scale: the
//! Fisher contributions `G = W^T W` of their whitened rows `W` are proportional. A mirror
//! node (x and z equal, y negated) has the same `G`; two nodes whose rows merely span the
//! same space (every triaxial node does when there are three shapes) do not. Near-proportional
//! counts within `tolerance`: with `c = tr(G_a G_b) / (||G_a||_F ||G_b||_F)` the cosine of
//! the two matrices, `1 - sqrt(c) <= tolerance` (for single rows `c = cos^2 theta`, so this
//! is `1 - |cos theta| <= tolerance`, about `theta^2 / 2`).

use crate::linalg::{dot, r_factor, whiten_row};

/// For each block, `None` when it represents its class of equivalent blocks, or the index
/// of the block that represents it.
///
/// Blocks are visited forced ones first, then the others by index: a block joins the class
/// of the first representative already seen whose information matches its own (same row
/// count, `1 - sqrt(c) <= tolerance`, see the module docs), else it becomes a representative.
/// Forced blocks never join a class and stay the representative of theirs; any other class
/// is then represented by its member of largest whitened norm (the most signal over noise),
/// the first in candidate order among members within a relative `1e-9` of it. A block of
/// zero rows carries no information and joins none. `tolerance <= 0` merges nothing.
///
/// The search sorts the blocks by a scalar key of their normalised Fisher contribution,
/// `tr(G D) / ||G||_F` with a fixed diagonal `D`; equal contributions have equal keys and
/// contributions within `tolerance` have keys within `||D||_F sqrt(2 - 2 (1 - tolerance)^2)`,
/// so only neighbours in that window are compared (`O(s log s)` for `s` candidates rather
/// than `O(s^2)`).
pub(crate) fn classes(
    phi: &[f64],
    k: usize,
    blocks: &[Vec<usize>],
    forced: &[bool],
    tolerance: f64,
) -> Vec<Option<usize>> {
    let n = blocks.len();
    let mut rep_of = vec![None; n];
    if tolerance <= 0.0 || n < 2 {
        return rep_of;
    }
    let rows = phi.len() / k.max(1);
    let r = r_factor(phi, k, &(0..rows).collect::<Vec<_>>());
    // Each block's whitened rows, the Frobenius norm of its `G = W^T W`, its squared
    // whitened norm `tr G` and its key.
    let d: Vec<f64> = (0..k).map(|m| 1.0 + (m as f64 + 1.0).sqrt()).collect();
    let d_norm = dot(&d, &d).sqrt();
    let mut whitened: Vec<Vec<Vec<f64>>> = Vec::with_capacity(n);
    let mut g_norm = Vec::with_capacity(n);
    let mut energy = Vec::with_capacity(n);
    let mut key = Vec::with_capacity(n);
    for b in blocks {
        let w: Vec<Vec<f64>> = b
            .iter()
            .map(|&row| {
                let mut w = vec![0.0; k];
                whiten_row(&phi[row * k..(row + 1) * k], r.as_ref(), &mut w);
                w
            })
            .collect();
        let norm = gram_inner(&w, &w).sqrt();
        energy.push(w.iter().map(|x| dot(x, x)).sum::<f64>());
        key.push(if norm > 0.0 {
            w.iter()
                .map(|x| x.iter().zip(&d).map(|(v, dm)| v * v * dm).sum::<f64>())
                .sum::<f64>()
                / norm
        } else {
            0.0
        });
        g_norm.push(norm);
        whitened.push(w);
    }
    let mut by_key: Vec<usize> = (0..n).collect();
    by_key.sort_by(|&a, &b| key[a].total_cmp(&key[b]).then(a.cmp(&b)));
    let mut place = vec![0; n];
    for (p, &b) in by_key.iter().enumerate() {
        place[b] = p;
    }
    // Forced blocks first, then the others by index.
    let order: Vec<usize> = (0..n)
        .filter(|&b| forced[b])
        .chain((0..n).filter(|&b| !forced[b]))
        .collect();
    let floor = 1.0 - tolerance.min(1.0);
    let window = d_norm * (2.0 - 2.0 * floor * floor).max(0.0).sqrt();
    // Position in the visiting order of each block already made a representative.
    let mut rank = vec![usize::MAX; n];
    for (visit, &b) in order.iter().enumerate() {
        let mut best: Option<usize> = None;
        if !forced[b] && g_norm[b] > 0.0 {
            let p = place[b];
            let reach = window + 1e-12 * key[b].abs();
            let below = by_key[..p]
                .iter()
                .rev()
                .take_while(|&&a| key[b] - key[a] <= reach);
            let above = by_key[p + 1..]
                .iter()
                .take_while(|&&a| key[a] - key[b] <= reach);
            for &a in below.chain(above) {
                let candidate = rank[a] != usize::MAX
                    && blocks[a].len() == blocks[b].len()
                    && g_norm[a] > 0.0
                    && {
                        let c = gram_inner(&whitened[a], &whitened[b]) / (g_norm[a] * g_norm[b]);
                        c.max(0.0).sqrt() >= floor
                    };
                if candidate && best.is_none_or(|c| rank[a] < rank[c]) {
                    best = Some(a);
                }
            }
        }
        match best {
            Some(a) => rep_of[b] = Some(a),
            None => rank[b] = visit,
        }
    }
    // A class not led by a forced block is represented by its member of largest
    // noise-weighted signal; members within a relative 1e-9 of it count as equal, and the
    // first of them in candidate order stands.
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (b, rep) in rep_of.iter().enumerate() {
        if let Some(a) = rep {
            members[*a].push(b);
        }
    }
    for root in 0..n {
        if members[root].is_empty() || forced[root] {
            continue;
        }
        let mut class = std::mem::take(&mut members[root]);
        class.push(root);
        class.sort_unstable();
        let mut best = class[0];
        for &b in &class[1..] {
            if energy[b] > energy[best] * (1.0 + 1e-9) {
                best = b;
            }
        }
        for &b in &class {
            rep_of[b] = (b != best).then_some(best);
        }
    }
    rep_of
}

/// `tr(G_a G_b)` for `G = W^T W` of the rows `a` and `b`: `sum_ij (a_i . b_j)^2`.
fn gram_inner(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    a.iter()
        .map(|x| b.iter().map(|y| dot(x, y).powi(2)).sum::<f64>())
        .sum()
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn flat(rows: &[[f64; 2]]) -> Vec<f64> {
        rows.iter().flatten().copied().collect()
    }

    /// Parallel rows (either sign, any scale) form one class represented by the row of
    /// largest whitened norm; near-parallel rows merge exactly when `1 - |cos|` of their
    /// whitened rows, computed here from the projector `E = Phi (Phi^T Phi)^-1 Phi^T` as
    /// `|E_ij| / sqrt(E_ii E_jj)`, is within the tolerance.
    #[test]
    fn parallel_rows_share_a_representative() {
        let rows = [
            [1.0, 0.0],
            [0.0, 1.0],
            [-2.0, 0.0],
            [1.0, 1.0],
            [1.0, 1.0 + 1e-3],
        ];
        let phi = flat(&rows);
        let blocks: Vec<Vec<usize>> = (0..5).map(|i| vec![i]).collect();
        // The whitened cosine of rows 3 and 4 through the 2 x 2 inverse of Phi^T Phi.
        let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
        for r in &rows {
            a += r[0] * r[0];
            b += r[0] * r[1];
            c += r[1] * r[1];
        }
        let det = a * c - b * b;
        let e = |x: [f64; 2], y: [f64; 2]| {
            (x[0] * (c * y[0] - b * y[1]) + x[1] * (-b * y[0] + a * y[1])) / det
        };
        let gap =
            1.0 - e(rows[3], rows[4]).abs() / (e(rows[3], rows[3]) * e(rows[4], rows[4])).sqrt();
        assert!(gap > 1e-9 && gap < 1e-5, "{gap}");
        let rep = classes(&phi, 2, &blocks, &[false; 5], gap / 2.0);
        assert_eq!(rep, [Some(2), None, None, None, None]);
        let rep = classes(&phi, 2, &blocks, &[false; 5], gap * 2.0);
        assert_eq!(rep, [Some(2), None, None, Some(4), None]);
        // A forced block stays its own representative; off merges nothing.
        let rep = classes(&phi, 2, &blocks, &[true, false, false, false, false], 1e-12);
        assert_eq!(rep, [None, None, Some(0), None, None]);
        assert_eq!(classes(&phi, 2, &blocks, &[false; 5], 0.0), [None; 5]);
    }

    /// Two nodes with the same rows up to the sign of one (a mirror pair: x equal, y
    /// negated) are one class; a node with other rows is not.
    #[test]
    fn mirror_nodes_are_equivalent() {
        let phi: Vec<f64> = [
            [1.0, 0.2, 0.0],
            [0.1, 1.0, 0.3],
            [1.0, 0.2, 0.0],
            [-0.1, -1.0, -0.3],
            [0.0, 0.0, 1.0],
            [0.3, 0.1, 0.0],
        ]
        .iter()
        .flatten()
        .copied()
        .collect();
        let blocks = vec![vec![0, 1], vec![2, 3], vec![4, 5]];
        let rep = classes(&phi, 3, &blocks, &[false; 3], 1e-9);
        assert_eq!(rep, [None, Some(0), None]);
    }

    /// With as many shapes as a node has rows, every node's rows span the whole space, yet
    /// two nodes with different rows add different information: they stay apart, and only
    /// the mirror image (y negated) joins its node.
    #[test]
    fn triaxial_nodes_spanning_the_space_are_not_all_equivalent() {
        let phi: Vec<f64> = [
            [1.0, 0.2, 0.0],
            [0.1, 1.0, 0.3],
            [0.0, 0.4, 1.0],
            [2.0, 0.1, 0.5],
            [0.3, 0.7, 0.0],
            [0.2, 0.0, 0.9],
            [1.0, 0.2, 0.0],
            [-0.1, -1.0, -0.3],
            [0.0, 0.4, 1.0],
        ]
        .iter()
        .flatten()
        .copied()
        .collect();
        let blocks = vec![vec![0, 1, 2], vec![3, 4, 5], vec![6, 7, 8]];
        let rep = classes(&phi, 3, &blocks, &[false; 3], 5e-7);
        assert_eq!(rep, [None, None, Some(0)]);
    }
}
