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
