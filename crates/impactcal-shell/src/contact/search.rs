//! The bucket sort of a contact interface: for each checked node, the segments whose box
//! (grown by both contact thicknesses and the search margin) holds it.
//!
//! Space is cut into cubic cells of the mean size of the grown segment boxes; cells are
//! hashed into a table of about twice as many buckets as segments (a collision only adds
//! candidates, which the exact box test removes), and each segment is entered in the
//! buckets of the cells its box touches. A node looks in the bucket of its own cell. The
//! work is linear in the number of nodes and segments. Segments far larger than the cells
//! (a coarse rigid floor under a fine mesh) are kept in a list every node checks, so one
//! big segment cannot flood the table.

use rayon::prelude::*;

use super::interface::Interface;

/// Nodes per rayon task.
const CHUNK: usize = 512;
/// A segment touching more cells than this goes to the list every node checks.
const MAX_CELLS: i64 = 512;

/// Candidate segments per checked node, in compressed rows (each row ascending).
#[derive(Debug, Clone, Default)]
pub(crate) struct Candidates {
    pub start: Vec<u32>,
    pub list: Vec<u32>,
}

impl Candidates {
    /// The candidates of checked node `j`.
    pub fn of(&self, j: usize) -> &[u32] {
        &self.list[self.start[j] as usize..self.start[j + 1] as usize]
    }
}

/// The box of segment `s` at the positions `x` (model indexed), grown by `grow`:
/// `[lo_x, lo_y, lo_z, hi_x, hi_y, hi_z]`.
pub(crate) fn segment_box(f: &Interface, s: usize, x: &[[f64; 3]], grow: f64) -> [f64; 6] {
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for &l in &f.segs[s][..f.corners(s)] {
        let p = x[f.nodes[l as usize] as usize];
        for d in 0..3 {
            b[d] = b[d].min(p[d]);
            b[3 + d] = b[3 + d].max(p[d]);
        }
    }
    for d in 0..3 {
        b[d] -= grow;
        b[3 + d] += grow;
    }
    b
}

/// True when `p` lies in box `b`.
pub(crate) fn inside(b: &[f64; 6], p: [f64; 3]) -> bool {
    p[0] >= b[0] && p[0] <= b[3] && p[1] >= b[1] && p[1] <= b[4] && p[2] >= b[2] && p[2] <= b[5]
}

/// True when checked node `j` may touch segment `s`: the segment is on a side the node is
/// checked against and does not hold the node, nor a node of the node's rigid body (a
/// node welded to a corner of a segment cannot be pushed away from that corner, so it is
/// taken as part of the segment).
pub(crate) fn allowed(f: &Interface, j: usize, s: usize) -> bool {
    if f.seg_side[s] & f.slave_checks[j] == 0 {
        return false;
    }
    let u = f.slaves[j];
    let corners = &f.segs[s][..f.corners(s)];
    if corners.contains(&u) {
        return false;
    }
    let body = f.body[u as usize];
    !(body != usize::MAX && corners.iter().any(|&c| f.body[c as usize] == body))
}

fn cell_of(p: [f64; 3], h: f64) -> [i64; 3] {
    p.map(|c| (c / h).floor() as i64)
}

fn bucket(c: [i64; 3], mask: u64) -> usize {
    let h = (c[0].wrapping_mul(73_856_093) as u64)
        ^ (c[1].wrapping_mul(19_349_663) as u64)
        ^ (c[2].wrapping_mul(83_492_791) as u64);
    (h.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 20 & mask) as usize
}

/// The buckets of the cells from `lo` to `hi` (inclusive).
fn buckets(r: &([i64; 3], [i64; 3]), mask: u64) -> impl Iterator<Item = usize> + '_ {
    let (lo, hi) = r;
    (lo[0]..=hi[0]).flat_map(move |ix| {
        (lo[1]..=hi[1])
            .flat_map(move |iy| (lo[2]..=hi[2]).map(move |iz| bucket([ix, iy, iz], mask)))
    })
}

/// The candidate segments of every checked node of `f` at the positions `x`: segments
/// whose box, grown by the segment's and the largest node half thickness and `margin`,
/// holds the node, and that the node may touch ([`allowed`]).
pub(crate) fn candidates(f: &Interface, x: &[[f64; 3]], margin: f64) -> Candidates {
    let ns = f.segs.len();
    let boxes: Vec<[f64; 6]> = (0..ns)
        .into_par_iter()
        .with_min_len(CHUNK)
        .map(|s| segment_box(f, s, x, f.seg_half[s] + f.max_half + margin))
        .collect();
    let mean_extent = boxes
        .iter()
        .map(|b| (b[3] - b[0]).max(b[4] - b[1]).max(b[5] - b[2]))
        .sum::<f64>()
        / ns.max(1) as f64;
    let h = if mean_extent.is_finite() && mean_extent > 0.0 {
        mean_extent
    } else {
        1.0
    };
    let size = (2 * ns).next_power_of_two().max(64);
    let mask = size as u64 - 1;
    // Cell ranges of each box; oversized boxes go to the list every node checks.
    let ranges: Vec<Option<([i64; 3], [i64; 3])>> = boxes
        .iter()
        .map(|b| {
            let lo = cell_of([b[0], b[1], b[2]], h);
            let hi = cell_of([b[3], b[4], b[5]], h);
            let n: i64 = (0..3).map(|d| (hi[d] - lo[d] + 1).max(1)).product();
            (n <= MAX_CELLS).then_some((lo, hi))
        })
        .collect();
    let big: Vec<u32> = (0..ns as u32)
        .filter(|&s| ranges[s as usize].is_none())
        .collect();
    let mut count = vec![0u32; size + 1];
    for r in ranges.iter().flatten() {
        for b in buckets(r, mask) {
            count[b + 1] += 1;
        }
    }
    for k in 0..size {
        count[k + 1] += count[k];
    }
    let mut fill = count.clone();
    let mut table = vec![0u32; count[size] as usize];
    for (s, r) in ranges.iter().enumerate() {
        if let Some(r) = r {
            for b in buckets(r, mask) {
                table[fill[b] as usize] = s as u32;
                fill[b] += 1;
            }
        }
    }
    // Each node: the segments of its cell's bucket and the big ones, tested exactly.
    let rows: Vec<Vec<u32>> = (0..f.slaves.len())
        .collect::<Vec<_>>()
        .par_chunks(CHUNK)
        .map(|js| {
            let mut out = Vec::new();
            let mut row = Vec::new();
            for &j in js {
                let p = x[f.nodes[f.slaves[j] as usize] as usize];
                let b = bucket(cell_of(p, h), mask);
                row.clear();
                for &s in table[count[b] as usize..count[b + 1] as usize]
                    .iter()
                    .chain(&big)
                {
                    let si = s as usize;
                    let grown = segment_box(f, si, x, f.seg_half[si] + f.slave_half[j] + margin);
                    if inside(&grown, p) && allowed(f, j, si) {
                        row.push(s);
                    }
                }
                row.sort_unstable();
                row.dedup();
                out.push(row.len() as u32);
                out.extend_from_slice(&row);
            }
            out
        })
        .collect();
    let mut start = Vec::with_capacity(f.slaves.len() + 1);
    let mut list = Vec::new();
    start.push(0u32);
    for chunk in rows {
        let mut k = 0;
        while k < chunk.len() {
            let n = chunk[k] as usize;
            list.extend_from_slice(&chunk[k + 1..k + 1 + n]);
            start.push(list.len() as u32);
            k += 1 + n;
        }
    }
    Candidates { start, list }
}
