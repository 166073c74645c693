//! Curve metrics: how far a computed time history is from a measured one.
//!
//! | metric | type | what it sees |
//! |---|---|---|
//! | relative L2, RMS, peak, time of peak | [`PointwiseErrors`] | sample-by-sample difference |
//! | Sprague-Geers `M`, `P`, `C` | [`SpragueGeers`] | magnitude and phase apart |
//! | Russell `RM`, `RP`, `RC` | [`Russell`] | the same, magnitude symmetric |
//! | ISO/TS 18571 `R` | [`Iso18571`] | corridor, phase, magnitude, slope, graded |
//!
//! [`CurveMetrics::between`] computes all of them for two slices; [`compare`] for every
//! channel pair of two [`Histories`](impactcal_core::Histories), with the same CFC filter on
//! both sides, the model interpolated onto the test's time points, means over channels, the
//! worst channel, and the same metrics on the norm histories `Q(t)`.

mod compare;
mod energy;
mod iso18571;
mod pointwise;

pub use compare::{
    ChannelMetrics, ChannelPair, CompareOptions, Comparison, CurveMetrics, Dropped, MeanIso,
    MeanTriple, Overall, compare,
};
pub use energy::{Russell, SpragueGeers};
pub use iso18571::{Grade, ISO18571_DT, Iso18571, Iso18571Rating};
pub use pointwise::PointwiseErrors;

use crate::error::{CalibrateError, Result};

/// Checks that two curves have equal lengths of at least `min` samples.
fn check_pair(a: &[f64], b: &[f64], min: usize, what: &str) -> Result<()> {
    if a.len() != b.len() {
        return Err(CalibrateError::Length {
            what: what.to_string(),
            reason: format!("the curves have {} and {} samples", a.len(), b.len()),
        });
    }
    if a.len() < min {
        return Err(CalibrateError::Length {
            what: what.to_string(),
            reason: format!("needs at least {min} samples, found {}", a.len()),
        });
    }
    Ok(())
}
