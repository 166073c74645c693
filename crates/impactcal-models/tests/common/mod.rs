//! Synthetic bar tests with known answers, shared by the Kolsky tests.

#![allow(dead_code, clippy::unwrap_used)]

use impactcal_core::Histories;
use impactcal_models::kolsky::{BarSetup, GaugeBridge, KolskyTest, Section, SpecimenSetup};

/// Bar modulus (Pa), wave speed (m/s) and gauge distance (m: 100 us of travel).
pub const E: f64 = 110e9;
pub const C: f64 = 5000.0;
pub const X: f64 = 0.5;
/// Specimen length (m).
pub const LS: f64 = 3e-3;

/// A titanium-like bar of diameter `d` read by a half bridge with gain `gain`.
pub fn bar(d: f64, gain: f64, channel: &str) -> BarSetup {
    BarSetup {
        modulus: E,
        density: E / (C * C),
        poisson: 0.33,
        section: Section::Round { diameter: d },
        wave_speed: None,
        gauge_distance: X,
        gauge_factor: 2.0,
        gain,
        excitation: 8.0,
        bridge: GaugeBridge::Half,
        polarity: 1.0,
        channels: vec![channel.to_string()],
    }
}

/// A 6 mm, 3 mm long copper-like specimen.
pub fn specimen() -> SpecimenSetup {
    SpecimenSetup {
        section: Section::Round { diameter: 6e-3 },
        length: LS,
        density: 8960.0,
    }
}

/// Volts a half bridge of `b` (polarity +1) reads for compressive strain `e`.
pub fn volts(e: f64, b: &BarSetup) -> f64 {
    let a = b.gauge_factor * (-e);
    -(a / (2.0 + a)) * b.gain * b.excitation
}

/// A trapezoidal pulse of amplitude `amp` from `t0`: rise `r`, plateau `p`, fall `r`.
pub fn trapezoid(t: f64, amp: f64, t0: f64, r: f64, p: f64) -> f64 {
    let u = (t - t0) / r;
    amp * (u.min(2.0 + p / r - u)).clamp(0.0, 1.0)
}

/// A test sampled at `dt` over `span` seconds whose incident gauge reads
/// `incident(t) + reflected(t - 2 X / C)` and whose transmitted gauge reads
/// `transmitted(t - 2 X / C)` (face waves given as functions of incident-gauge time).
pub fn test_from(
    dt: f64,
    span: f64,
    bars: (BarSetup, BarSetup),
    incident: impl Fn(f64) -> f64,
    reflected: impl Fn(f64) -> f64,
    transmitted: impl Fn(f64) -> f64,
) -> KolskyTest {
    let (bi, bt) = bars;
    let n = (span / dt).round() as usize;
    let (mut inc, mut tra) = (vec![0.0; n], vec![0.0; n]);
    for k in 0..n {
        let t = k as f64 * dt;
        let late = t - 2.0 * X / C;
        inc[k] = volts(incident(t) + reflected(late), &bi);
        tra[k] = volts(transmitted(late), &bt);
    }
    let signals = Histories::from_channels(
        vec![bi.channels[0].clone(), bt.channels[0].clone()],
        vec![inc, tra],
        dt,
        0.0,
        "V",
    )
    .unwrap();
    KolskyTest {
        incident: bi,
        transmitted: bt,
        specimen: specimen(),
        striker_length: None,
        signals,
        source: "synthetic".into(),
    }
}
