//! Halton sequences, plain and with random digit permutations.

use rand::Rng;
use rand::seq::SliceRandom;

use faer::Mat;

use super::BELOW_ONE;
use crate::error::{CoreError, Result};

/// The Halton sequence in the first `dim` primes.
///
/// Point `n` has coordinate `j` equal to the radical inverse of `n` in base `p_j` (the j-th
/// prime): with `n = sum_k a_k p^k`, `phi_p(n) = sum_k pi_k(a_k) p^(-k-1)`, where `pi_k` is
/// the identity for the plain sequence and, for the scrambled one, an independent random
/// permutation of `0..p` for every digit position `k` of every base. Scrambling is applied to
/// all the digits that a double resolves (about `53 / log2 p` of them), including the
/// leading zeros of `n`, so scrambled points fill `[0, 1)` without a lattice bias.
///
/// Plain Halton starts at index 0 (the origin), as scipy and MATLAB do. Between dimensions
/// with large neighbouring primes the first points of the plain sequence are strongly
/// correlated (0.72 between bases 29 and 31 at 50 points); the scrambled sequence removes
/// this.
#[derive(Debug, Clone)]
pub struct Halton {
    bases: Vec<u32>,
    scramble: Option<Vec<DigitScramble>>,
}

/// The digit permutations of one base: full permutations for the positions that indices
/// below the capacity use, and for the deeper positions the image of the digit 0 (the only
/// digit those indices have there), extended to a cyclic shift for larger indices.
#[derive(Debug, Clone)]
struct DigitScramble {
    /// `perms[k * base + a]` = `pi_k(a)` for `k < perms.len() / base`.
    perms: Vec<u32>,
    /// `shifts[k - full]` = `pi_k(0)` for the deeper positions.
    shifts: Vec<u32>,
}

impl Halton {
    /// The largest supported dimension (bases up to the 1000th prime, 7919).
    pub const MAX_DIM: usize = 1000;

    /// The plain sequence in `dim` dimensions.
    ///
    /// # Errors
    /// [`CoreError::Invalid`] when `dim` is 0 or above [`Halton::MAX_DIM`].
    pub fn new(dim: usize) -> Result<Self> {
        if dim == 0 || dim > Self::MAX_DIM {
            return Err(CoreError::Invalid(format!(
                "Halton sequences support 1 to {} dimensions; {dim} were asked for",
                Self::MAX_DIM
            )));
        }
        Ok(Halton {
            bases: first_primes(dim),
            scramble: None,
        })
    }

    /// The sequence with random digit permutations drawn from `rng`.
    ///
    /// `capacity` is the number of indices (from 0) the caller intends to use: their digits
    /// get fully random permutations. Larger indices still give a valid scrambled sequence,
    /// with cyclic shifts as the permutations of the digit positions beyond the capacity.
    ///
    /// # Errors
    /// As [`Halton::new`].
    pub fn scrambled(dim: usize, capacity: usize, rng: &mut impl Rng) -> Result<Self> {
        let mut h = Halton::new(dim)?;
        let scramble = h
            .bases
            .iter()
            .map(|&b| {
                let total = digits_resolved(b);
                let full = digits_of(capacity.saturating_sub(1), b).min(total);
                let mut perms = Vec::with_capacity(full * b as usize);
                for _ in 0..full {
                    let mut p: Vec<u32> = (0..b).collect();
                    p.shuffle(rng);
                    perms.extend_from_slice(&p);
                }
                let shifts = (full..total).map(|_| rng.random_range(0..b)).collect();
                DigitScramble { perms, shifts }
            })
            .collect();
        h.scramble = Some(scramble);
        Ok(h)
    }

    /// The dimension.
    pub fn dim(&self) -> usize {
        self.bases.len()
    }

    /// The prime bases in order.
    pub fn bases(&self) -> &[u32] {
        &self.bases
    }

    /// Writes point `index` into `out` (length [`dim`](Self::dim); extra entries are left
    /// alone, missing ones skipped).
    pub fn point(&self, index: usize, out: &mut [f64]) {
        for (j, (x, &b)) in out.iter_mut().zip(&self.bases).enumerate() {
            *x = match &self.scramble {
                None => radical_inverse(index, b),
                Some(s) => scrambled_radical_inverse(index, b, &s[j]),
            };
        }
    }

    /// Points `start .. start + n`, one per row of an `n x dim` matrix.
    pub fn points(&self, start: usize, n: usize) -> Mat<f64> {
        let dim = self.dim();
        let mut data = vec![0.0; n * dim];
        for (i, row) in data.chunks_exact_mut(dim).enumerate() {
            self.point(start + i, row);
        }
        Mat::from_fn(n, dim, |i, j| data[i * dim + j])
    }
}

fn radical_inverse(mut index: usize, base: u32) -> f64 {
    let b = base as usize;
    let inv = 1.0 / f64::from(base);
    let mut factor = inv;
    let mut x = 0.0;
    while index > 0 {
        x += (index % b) as f64 * factor;
        index /= b;
        factor *= inv;
    }
    x
}

fn scrambled_radical_inverse(mut index: usize, base: u32, s: &DigitScramble) -> f64 {
    let b = base as usize;
    let full = s.perms.len() / b;
    let total = full + s.shifts.len();
    let mut digits = [0u32; 64];
    for (k, d) in digits.iter_mut().enumerate().take(total) {
        let a = index % b;
        index /= b;
        *d = if k < full {
            s.perms[k * b + a]
        } else {
            (s.shifts[k - full] + a as u32) % base
        };
    }
    // Horner from the least significant digit keeps the rounding error at one ulp.
    let fb = f64::from(base);
    let x = digits[..total]
        .iter()
        .rev()
        .fold(0.0, |acc, &d| (acc + f64::from(d)) / fb);
    x.min(BELOW_ONE)
}

/// How many base-`b` digits a double resolves below 1: `ceil(53 / log2 b)`.
fn digits_resolved(b: u32) -> usize {
    (53.0 / f64::from(b).log2()).ceil() as usize
}

/// Number of base-`b` digits of `n` (at least 1).
fn digits_of(mut n: usize, b: u32) -> usize {
    let mut k = 1;
    while n >= b as usize {
        n /= b as usize;
        k += 1;
    }
    k
}

fn first_primes(count: usize) -> Vec<u32> {
    let mut primes: Vec<u32> = Vec::with_capacity(count);
    let mut candidate = 2u32;
    while primes.len() < count {
        if primes
            .iter()
            .take_while(|&&p| p * p <= candidate)
            .all(|&p| candidate % p != 0)
        {
            primes.push(candidate);
        }
        candidate += 1;
    }
    primes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::points::{column, row, to_row_major};
    use crate::sampling::seeded_rng;

    #[test]
    fn primes_and_plain_points() {
        assert_eq!(first_primes(6), vec![2, 3, 5, 7, 11, 13]);
        assert_eq!(first_primes(1000)[999], 7919);
        let h = Halton::new(2).unwrap();
        let p = h.points(0, 4);
        assert_eq!(column(p.as_ref(), 0), vec![0.0, 0.5, 0.25, 0.75]); // exact binary fractions
        assert!((row(p.as_ref(), 3)[1] - 1.0 / 9.0).abs() < 1e-16);
    }

    #[test]
    fn scrambled_points_keep_the_strata() {
        // Scrambling permutes digits, so the first b^k points of base b still hold one point
        // in each interval [m / b^k, (m + 1) / b^k).
        let h = Halton::scrambled(3, 125, &mut seeded_rng(3)).unwrap();
        let p = h.points(0, 125);
        let mut seen = [false; 125];
        for x in column(p.as_ref(), 2) {
            let cell = (x * 125.0) as usize;
            assert!(!seen[cell], "two points in stratum {cell}");
            seen[cell] = true;
        }
        // Beyond the capacity the sequence stays inside [0, 1).
        let far = h.points(10_000, 10);
        assert!(
            to_row_major(far.as_ref())
                .iter()
                .all(|&x| (0.0..1.0).contains(&x))
        );
    }
}
