//! Sobol' sequences with Joe-Kuo direction numbers, plain and Owen-scrambled.

use faer::Mat;

use super::BELOW_ONE;
use crate::error::{CoreError, Result};

/// Joe & Kuo (2008) D6 direction numbers, dimensions 2..=2048, one line `s a m_1 .. m_s`
/// per dimension (see the file's header for its source and licence).
const JOE_KUO_D6: &str = include_str!("joe_kuo_d6.txt");

/// Bits of every coordinate: the sequence has 2^32 distinct points.
const BITS: usize = 32;

/// The Sobol' sequence in base 2 with the direction numbers of Joe & Kuo (2008, criterion
/// D6), in Gray-code order (the order of scipy's `qmc.Sobol`).
///
/// Dimension `j` has 32-bit direction numbers `v_{j,k} = m_{j,k} 2^(32-k)`, `k = 1..32`,
/// with `m_{j,1..s}` from the table and, for `k > s`, the recurrence of the primitive
/// polynomial `x^s + a_1 x^(s-1) + ... + a_(s-1) x + 1`:
/// `m_k = 2 a_1 m_(k-1) ^ 4 a_2 m_(k-2) ^ ... ^ 2^s m_(k-s) ^ m_(k-s)`.
/// Point `n` is `x_j = (XOR of v_{j,k+1} over the set bits k of g(n)) / 2^32` with the Gray
/// code `g(n) = n ^ (n >> 1)`. The first dimension is the van der Corput sequence.
///
/// The first `2^m` points form a (t, m, s)-net: every dyadic box of the right volume holds
/// its share of points. That balance holds only for powers of two, and only when the
/// sequence starts at index 0, including the origin (Owen 2020, "On dropping the first
/// Sobol' point").
///
/// The scrambled variant applies Owen's nested uniform scrambling: bit `k` of a coordinate
/// is flipped or not according to a random bit attached to the node of the binary tree
/// reached by the bits above it, independently per dimension. The random bits come from a
/// 64-bit hash of (seed, dimension, depth, prefix), so the scrambling needs no storage. The
/// bits beyond the 32nd are filled uniformly at random as well, so each scrambled point is
/// uniform on `[0, 1)^dim` and the first `2^m` points still form the same net.
#[derive(Debug, Clone)]
pub struct Sobol {
    dim: usize,
    /// `directions[j * BITS + k]` = `v_{j,k+1}`.
    directions: Vec<u32>,
    /// Per-dimension scrambling keys, or `None` for the plain sequence.
    keys: Option<Vec<u64>>,
}

impl Sobol {
    /// The largest supported dimension (the size of the shipped table).
    pub const MAX_DIM: usize = 2048;

    /// The plain sequence in `dim` dimensions.
    ///
    /// # Errors
    /// [`CoreError::Invalid`] when `dim` is 0 or above [`Sobol::MAX_DIM`].
    pub fn new(dim: usize) -> Result<Self> {
        if dim == 0 || dim > Self::MAX_DIM {
            return Err(CoreError::Invalid(format!(
                "Sobol' sequences support 1 to {} dimensions; {dim} were asked for",
                Self::MAX_DIM
            )));
        }
        Ok(Sobol {
            dim,
            directions: direction_numbers(dim)?,
            keys: None,
        })
    }

    /// The Owen-scrambled sequence in `dim` dimensions; `seed` fixes the scrambling.
    ///
    /// # Errors
    /// As [`Sobol::new`].
    pub fn owen_scrambled(dim: usize, seed: u64) -> Result<Self> {
        let mut s = Sobol::new(dim)?;
        s.keys = Some(
            (0..dim as u64)
                .map(|j| mix64(seed ^ mix64(j.wrapping_add(0x5851_F42D_4C95_7F2D))))
                .collect(),
        );
        Ok(s)
    }

    /// The dimension.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// The 32-bit integer coordinates of point `index` (plain, before scrambling).
    pub fn point_bits(&self, index: u32, out: &mut [u32]) {
        let gray = index ^ (index >> 1);
        for (j, x) in out.iter_mut().enumerate().take(self.dim) {
            let v = &self.directions[j * BITS..(j + 1) * BITS];
            let mut acc = 0u32;
            let mut g = gray;
            let mut k = 0;
            while g != 0 {
                if g & 1 == 1 {
                    acc ^= v[k];
                }
                g >>= 1;
                k += 1;
            }
            *x = acc;
        }
    }

    /// Writes point `index` into `out` (length [`dim`](Self::dim); extra entries are left
    /// alone).
    pub fn point(&self, index: u32, out: &mut [f64]) {
        let mut bits = vec![0u32; self.dim];
        self.point_bits(index, &mut bits);
        for (j, (x, &b)) in out.iter_mut().zip(&bits).enumerate() {
            *x = self.to_unit(j, b);
        }
    }

    /// Points `start .. start + n`, one per row of an `n x dim` matrix, generated
    /// incrementally in Gray-code order.
    ///
    /// # Errors
    /// [`CoreError::Invalid`] when `start + n` exceeds 2^32.
    pub fn points(&self, start: usize, n: usize) -> Result<Mat<f64>> {
        let end = start.checked_add(n).filter(|&e| e <= 1usize << BITS);
        let Some(end) = end else {
            return Err(CoreError::Invalid(format!(
                "a Sobol' sequence has 2^32 points; indices {start}..{start}+{n} go past it"
            )));
        };
        let dim = self.dim;
        let mut data = vec![0.0; n * dim];
        if n == 0 {
            return Ok(Mat::zeros(0, dim));
        }
        let mut bits = vec![0u32; dim];
        self.point_bits(start as u32, &mut bits);
        for (i, row) in data.chunks_exact_mut(dim).enumerate() {
            let index = start + i;
            for (j, (x, &b)) in row.iter_mut().zip(&bits).enumerate() {
                *x = self.to_unit(j, b);
            }
            if index + 1 < end {
                // Gray code: g(i+1) differs from g(i) in the lowest zero bit of i.
                let k = (!(index as u32)).trailing_zeros() as usize;
                for (j, b) in bits.iter_mut().enumerate() {
                    *b ^= self.directions[j * BITS + k];
                }
            }
        }
        Ok(Mat::from_fn(n, dim, |i, j| data[i * dim + j]))
    }

    fn to_unit(&self, j: usize, bits: u32) -> f64 {
        match &self.keys {
            None => f64::from(bits) / 4_294_967_296.0,
            Some(keys) => {
                let key = keys[j];
                let scrambled = owen_scramble(bits, key);
                // Uniform fill of the digits below the 32nd, keyed by the scrambled prefix.
                let fill = (mix64(key ^ mix64(u64::from(scrambled) | (1 << 40))) >> 11) as f64
                    / 9_007_199_254_740_992.0;
                ((f64::from(scrambled) + fill) / 4_294_967_296.0).min(BELOW_ONE)
            }
        }
    }
}

/// Nested uniform scrambling of a 32-bit binary fraction: bit `k` (from the top) is flipped
/// by a random bit of the tree node given by depth `k` and the `k` original bits above it.
fn owen_scramble(bits: u32, key: u64) -> u32 {
    let mut out = 0u32;
    for k in 0..BITS {
        let shift = BITS - 1 - k;
        let prefix = if k == 0 {
            0
        } else {
            u64::from(bits >> (shift + 1))
        };
        let node = prefix | ((k as u64) << 32);
        let flip = (mix64(key ^ mix64(node)) >> 63) as u32;
        out |= (((bits >> shift) & 1) ^ flip) << shift;
    }
    out
}

/// A 64-bit finaliser (the one of SplitMix64): a bijection whose output bits each depend on
/// every input bit.
fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The 32 direction numbers of each of the first `dim` dimensions.
fn direction_numbers(dim: usize) -> Result<Vec<u32>> {
    let mut v = vec![0u32; dim * BITS];
    // Dimension 1: m_k = 1 for every k.
    for (k, vk) in v.iter_mut().enumerate().take(BITS) {
        *vk = 1 << (BITS - 1 - k);
    }
    let lines = JOE_KUO_D6
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty());
    for (j, line) in (1..dim).zip(lines) {
        let bad = || {
            CoreError::Invalid(format!(
                "corrupt direction-number table, dimension {}",
                j + 1
            ))
        };
        let fields: Vec<u64> = line
            .split_whitespace()
            .map(str::parse)
            .collect::<std::result::Result<_, _>>()
            .map_err(|_| bad())?;
        let (s, a) = match fields.as_slice() {
            [s, a, ..] => (*s as usize, *a),
            _ => return Err(bad()),
        };
        if s == 0 || s > BITS || fields.len() != s + 2 {
            return Err(bad());
        }
        let mut m = [0u64; BITS];
        m[..s].copy_from_slice(&fields[2..]);
        for k in s..BITS {
            let mut mk = m[k - s] ^ (m[k - s] << s);
            for l in 1..s {
                if (a >> (s - 1 - l)) & 1 == 1 {
                    mk ^= m[k - l] << l;
                }
            }
            m[k] = mk;
        }
        for k in 0..BITS {
            v[j * BITS + k] = (m[k] << (BITS - 1 - k)) as u32;
        }
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_covers_the_maximum_dimension() {
        let s = Sobol::new(Sobol::MAX_DIM).unwrap();
        // Every direction number of dimension j > 1 is odd before its shift: m_k < 2^k.
        for j in 0..Sobol::MAX_DIM {
            for k in 0..BITS {
                let v = s.directions[j * BITS + k];
                assert_eq!(v >> (BITS - 1 - k) & 1, 1, "dimension {j}, bit {k}");
            }
        }
        assert!(Sobol::new(Sobol::MAX_DIM + 1).is_err());
    }

    #[test]
    fn incremental_and_direct_points_agree() {
        let s = Sobol::owen_scrambled(5, 11).unwrap();
        let block = s.points(37, 20).unwrap();
        let mut x = vec![0.0; 5];
        for i in 0..20 {
            s.point(37 + i as u32, &mut x);
            assert_eq!(crate::points::row(block.as_ref(), i), x);
        }
    }

    #[test]
    fn owen_scrambling_keeps_the_net() {
        // 2^6 points: in every dimension one point per interval [k/64, (k+1)/64), and in the
        // (t = 0) pair of dimensions 1 and 2 one point per 8 x 8 box.
        let s = Sobol::owen_scrambled(3, 99).unwrap();
        let p = s.points(0, 64).unwrap();
        for j in 0..3 {
            let mut cells: Vec<usize> = p.col(j).iter().map(|x| (x * 64.0) as usize).collect();
            cells.sort_unstable();
            assert_eq!(cells, (0..64).collect::<Vec<_>>(), "dimension {j}");
        }
        let mut boxes: Vec<usize> = p
            .row_iter()
            .map(|r| (r[0] * 8.0) as usize * 8 + (r[1] * 8.0) as usize)
            .collect();
        boxes.sort_unstable();
        assert_eq!(boxes, (0..64).collect::<Vec<_>>());
        // Different seeds give different points.
        let q = Sobol::owen_scrambled(3, 100)
            .unwrap()
            .points(0, 64)
            .unwrap();
        assert_ne!(p, q);
    }
}
