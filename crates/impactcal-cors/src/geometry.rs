//! Small helpers on points stored as slices, and the derived random streams.

use rand_chacha::ChaCha8Rng;

/// Euclidean distance of two points of equal length.
#[inline]
pub fn distance(a: &[f64], b: &[f64]) -> f64 {
    squared_distance(a, b).sqrt()
}

/// Squared Euclidean distance.
#[inline]
pub fn squared_distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// Points stored coordinate by coordinate (`dim x n`), for the many distance queries of a
/// candidate screening and of surrogate evaluation: the squared distances to a block of
/// points are formed one coordinate at a time, which vectorises across points. Each
/// distance keeps the order of operations of [`squared_distance`], so results equal those
/// of the row-wise loops bit for bit.
#[derive(Debug, Clone, Default)]
pub struct Columns {
    n: usize,
    cols: Vec<f64>,
}

impl Columns {
    /// Points per block of [`Columns::for_each_block`].
    pub const BLOCK: usize = 64;

    /// The points `pts` (row-major, `dim` values each).
    pub fn new(pts: &[f64], dim: usize) -> Self {
        let n = pts.len() / dim.max(1);
        let cols = (0..dim)
            .flat_map(|j| pts.chunks_exact(dim).map(move |p| p[j]))
            .collect();
        Columns { n, cols }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Coordinate `j` of point `i`.
    #[inline]
    pub fn coordinate(&self, i: usize, j: usize) -> f64 {
        self.cols[j * self.n + i]
    }

    /// Writes into `d2` (at most [`Columns::BLOCK`] long) the squared distances from `x` to
    /// the points `start..start + d2.len()`.
    #[inline]
    pub fn squared_distances(&self, x: &[f64], start: usize, d2: &mut [f64]) {
        let (n, len) = (self.n, d2.len());
        d2.fill(0.0);
        for (j, &xj) in x.iter().enumerate() {
            let col = &self.cols[j * n + start..j * n + start + len];
            for (d, &c) in d2.iter_mut().zip(col) {
                *d += (xj - c) * (xj - c);
            }
        }
    }

    /// Calls `f(start, d2)` for consecutive blocks of at most [`Columns::BLOCK`] points,
    /// `d2[k]` being the squared distance from `x` to point `start + k`.
    #[inline]
    pub fn for_each_block(&self, x: &[f64], mut f: impl FnMut(usize, &[f64])) {
        let n = self.n;
        let mut d2 = [0.0; Self::BLOCK];
        for start in (0..n).step_by(Self::BLOCK) {
            let len = Self::BLOCK.min(n - start);
            let d2 = &mut d2[..len];
            self.squared_distances(x, start, d2);
            f(start, d2);
        }
    }

    /// Squared distance from `x` to the nearest point; infinite for none.
    pub fn min_squared_distance(&self, x: &[f64]) -> f64 {
        let mut min = f64::INFINITY;
        self.for_each_block(x, |_, d2| min = min.min(min_of(d2)));
        min
    }

    /// Distance from `x` to the nearest point; infinite for none.
    pub fn min_distance(&self, x: &[f64]) -> f64 {
        self.min_squared_distance(x).sqrt()
    }
}

/// The smallest of `v` (infinite for none), taken over four lanes so that it vectorises;
/// the minimum of numbers that are not NaN does not depend on the order in which it is
/// taken.
#[inline]
pub fn min_of(v: &[f64]) -> f64 {
    let mut lanes = [f64::INFINITY; 4];
    let chunks = v.chunks_exact(4);
    let rest = chunks.remainder();
    for c in chunks {
        for (l, x) in lanes.iter_mut().zip(c) {
            *l = l.min(*x);
        }
    }
    let mut m = lanes[0].min(lanes[1]).min(lanes[2].min(lanes[3]));
    for x in rest {
        m = m.min(*x);
    }
    m
}

/// SplitMix64 finaliser: a bijective scrambling of 64 bits.
pub fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The seed of the random stream that serves evaluation number `index` of a study seeded
/// with `seed`: a pure function of both, so that a study rebuilt from its history draws the
/// same candidates.
pub fn stream_seed(seed: u64, index: usize) -> u64 {
    mix(seed ^ mix(index as u64 ^ 0xC0B5_C0B5_C0B5_C0B5))
}

/// The generator of [`stream_seed`].
pub fn stream(seed: u64, index: usize) -> ChaCha8Rng {
    impactcal_core::sampling::seeded_rng(stream_seed(seed, index))
}
