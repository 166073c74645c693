//! The curve pairs shared by `benches/metrics.rs` and `examples/testdata_peer.rs`, so that the
//! criterion figure and the objective-rating-metrics comparison rate the same input: 1,215
//! channel pairs of 801 samples at 10 kHz (the size of the airframe's sensor set over 80 ms).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Channel pairs.
pub const PAIRS: usize = 1215;
/// Samples per curve.
pub const SAMPLES: usize = 801;
/// Sampling interval (10 kHz).
pub const DT: f64 = 1e-4;

/// `(reference, computed)` pairs: damped velocity pulses with random arrival, width, ringing
/// and amplitude; the computed curve is the reference shifted by up to 30 samples, scaled by
/// 0.8 to 1.2, with a changed ringing frequency and noise of 2 % of the amplitude (seed 13).
pub fn metric_pairs() -> Vec<(Vec<f64>, Vec<f64>)> {
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    (0..PAIRS)
        .map(|_| {
            let at = rng.random_range(50.0..250.0);
            let width = rng.random_range(40.0..160.0);
            let ring = rng.random_range(0.01..0.06);
            let amp = rng.random_range(-400.0..400.0);
            let shift = rng.random_range(-30.0..30.0);
            let scale = rng.random_range(0.8..1.2);
            let ring_c = ring * rng.random_range(0.9..1.1);
            let curve = |at: f64, ring: f64, amp: f64, k: usize| {
                let s = (k as f64 - at) / width;
                if s < 0.0 {
                    0.0
                } else {
                    amp * s * (-s).exp() * (1.0 + 0.3 * (ring * (k as f64 - at)).sin())
                }
            };
            let reference = (0..SAMPLES).map(|k| curve(at, ring, amp, k)).collect();
            let computed = (0..SAMPLES)
                .map(|k| {
                    curve(at + shift, ring_c, scale * amp, k)
                        + 0.02 * amp.abs() * (rng.random::<f64>() - 0.5)
                })
                .collect();
            (reference, computed)
        })
        .collect()
}
