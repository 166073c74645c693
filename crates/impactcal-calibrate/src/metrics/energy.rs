//! Sprague-Geers and Russell magnitude and phase errors, both built on the integrals
//! `I_mm = int m^2`, `I_cc = int c^2` and `I_mc = int m c`.

use serde::Serialize;

use super::check_pair;
use crate::error::{CalibrateError, Result};

/// `I_mm` and `I_cc` by the trapezoid rule on a uniform grid (the step cancels in every
/// ratio built from them, so it is left out).
fn integrals(m: &[f64], c: &[f64]) -> (f64, f64) {
    let (mut mm, mut cc) = (0.0, 0.0);
    for (a, b) in m.iter().zip(c) {
        mm += a * a;
        cc += b * b;
    }
    let (m0, c0, m1, c1) = (m[0], c[0], m[m.len() - 1], c[c.len() - 1]);
    mm -= 0.5 * (m0 * m0 + m1 * m1);
    cc -= 0.5 * (c0 * c0 + c1 * c1);
    (mm, cc)
}

/// `(I_mm, I_cc, phase)` with the phase `arccos(I_mc / sqrt(I_mm I_cc)) / pi` in `[0, 1]`.
fn magnitude_phase(m: &[f64], c: &[f64], what: &str) -> Result<(f64, f64, f64)> {
    check_pair(m, c, 2, what)?;
    let (mm, cc) = integrals(m, c);
    if mm <= 0.0 {
        return Err(CalibrateError::Degenerate {
            what: what.to_string(),
            reason: "the measured curve is identically zero".into(),
        });
    }
    if cc <= 0.0 {
        return Err(CalibrateError::Degenerate {
            what: what.to_string(),
            reason: "the computed curve is identically zero, so it has no phase".into(),
        });
    }
    Ok((mm, cc, angle(m, c, mm, cc) / std::f64::consts::PI))
}

/// The angle `arccos(I_mc / sqrt(I_mm I_cc))` between the two curves, computed as
/// `2 atan2(|a - b|, |a + b|)` of the unit-energy curves `a = m / sqrt(I_mm)`,
/// `b = c / sqrt(I_cc)` (trapezoid-weighted norms), which stays accurate where the arccos of
/// a cosine near 1 would not.
fn angle(m: &[f64], c: &[f64], mm: f64, cc: f64) -> f64 {
    let (sm, sc) = (1.0 / mm.sqrt(), 1.0 / cc.sqrt());
    let (mut minus, mut plus) = (0.0, 0.0);
    let last = m.len() - 1;
    for (k, (x, y)) in m.iter().zip(c).enumerate() {
        let w = if k == 0 || k == last { 0.5 } else { 1.0 };
        let (a, b) = (x * sm, y * sc);
        minus += w * (a - b) * (a - b);
        plus += w * (a + b) * (a + b);
    }
    2.0 * minus.sqrt().atan2(plus.sqrt())
}

/// Sprague and Geers' comprehensive error of a computed curve `c` against a measured one `m`:
///
/// ```text
/// M = sqrt(I_cc / I_mm) - 1,   P = arccos(I_mc / sqrt(I_mm I_cc)) / pi,   C = sqrt(M^2 + P^2)
/// ```
///
/// `M` sees only amplitude (a pure scaling `c = s m` gives `M = s - 1`, `P = 0`) and `P` only
/// phase (a quarter-period shift of a long sine gives `P = 1/2`). The measured curve is the
/// reference, so the measure is not symmetric.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpragueGeers {
    /// Magnitude error `M` (0 for equal energy; negative when the model is too small).
    #[serde(rename = "m")]
    pub magnitude: f64,
    /// Phase error `P` in `[0, 1]`.
    #[serde(rename = "p")]
    pub phase: f64,
    /// Comprehensive error `C`.
    #[serde(rename = "c")]
    pub comprehensive: f64,
}

impl SpragueGeers {
    /// The errors of `computed` against `measured`, sampled at the same uniform times.
    ///
    /// # Errors
    /// [`CalibrateError::Length`] for curves of different lengths or fewer than two samples;
    /// [`CalibrateError::Degenerate`] when either curve is identically zero.
    pub fn between(measured: &[f64], computed: &[f64]) -> Result<SpragueGeers> {
        let (mm, cc, phase) = magnitude_phase(measured, computed, "Sprague-Geers")?;
        let magnitude = (cc / mm).sqrt() - 1.0;
        Ok(SpragueGeers {
            magnitude,
            phase,
            comprehensive: magnitude.hypot(phase),
        })
    }
}

/// Russell's error measures of a computed curve `c` against a measured one `m`:
///
/// ```text
/// r = (I_cc - I_mm) / sqrt(I_cc I_mm),   RM = sign(r) log10(1 + |r|),
/// RP = arccos(I_mc / sqrt(I_mm I_cc)) / pi,   RC = sqrt(pi/4 (RM^2 + RP^2))
/// ```
///
/// Unlike Sprague-Geers the magnitude is symmetric in the two curves (swapping them flips
/// its sign only); the sign says which curve carries more energy.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Russell {
    /// Magnitude error `RM`.
    #[serde(rename = "m")]
    pub magnitude: f64,
    /// Phase error `RP` in `[0, 1]`.
    #[serde(rename = "p")]
    pub phase: f64,
    /// Comprehensive error `RC`.
    #[serde(rename = "c")]
    pub comprehensive: f64,
}

impl Russell {
    /// The errors of `computed` against `measured`, sampled at the same uniform times.
    ///
    /// # Errors
    /// As [`SpragueGeers::between`].
    pub fn between(measured: &[f64], computed: &[f64]) -> Result<Russell> {
        let (mm, cc, phase) = magnitude_phase(measured, computed, "Russell")?;
        let r = (cc - mm) / (cc * mm).sqrt();
        let magnitude = r.signum() * r.abs().ln_1p() / std::f64::consts::LN_10;
        let magnitude = if r == 0.0 { 0.0 } else { magnitude };
        Ok(Russell {
            magnitude,
            phase,
            comprehensive: (std::f64::consts::FRAC_PI_4 * (magnitude * magnitude + phase * phase))
                .sqrt(),
        })
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::PI;

    fn pulse(n: usize) -> Vec<f64> {
        (0..n)
            .map(|k| {
                let t = k as f64 / (n - 1) as f64;
                (PI * t).sin().powi(2) * (1.0 + 0.3 * (7.0 * t).cos())
            })
            .collect()
    }

    #[test]
    fn pure_scaling_has_magnitude_only() {
        let m = pulse(801);
        for s in [0.5, 0.9, 1.0, 1.25, 3.0] {
            let c: Vec<f64> = m.iter().map(|v| s * v).collect();
            let sg = SpragueGeers::between(&m, &c).unwrap();
            assert_relative_eq!(sg.magnitude, s - 1.0, epsilon = 1e-12);
            assert!(sg.phase.abs() < 1e-12, "phase {}", sg.phase);
            assert_relative_eq!(sg.comprehensive, (s - 1.0f64).abs(), epsilon = 1e-12);
            let r = Russell::between(&m, &c).unwrap();
            let expect = (s * s - 1.0) / s;
            assert_relative_eq!(
                r.magnitude,
                expect.signum() * (1.0 + expect.abs()).log10(),
                epsilon = 1e-12
            );
            assert!(r.phase.abs() < 1e-12);
        }
    }

    #[test]
    fn quarter_period_shift_of_a_long_sine_is_half_phase() {
        // 50 whole periods sampled 40 times each: sin and cos are orthogonal under the
        // trapezoid rule, so P = arccos(0) / pi = 1/2 and M = 0.
        let n = 50 * 40 + 1;
        let w = 2.0 * PI / 40.0;
        let m: Vec<f64> = (0..n).map(|k| (w * k as f64).sin()).collect();
        let c: Vec<f64> = (0..n).map(|k| (w * k as f64 - PI / 2.0).sin()).collect();
        let sg = SpragueGeers::between(&m, &c).unwrap();
        assert_relative_eq!(sg.phase, 0.5, epsilon = 1e-12);
        assert!(sg.magnitude.abs() < 1e-12);
        let r = Russell::between(&m, &c).unwrap();
        assert_relative_eq!(r.phase, 0.5, epsilon = 1e-12);
        assert_relative_eq!(r.comprehensive, (PI / 4.0 * 0.25).sqrt(), epsilon = 1e-12);
        // Half a period: opposite sign, P = 1.
        let c: Vec<f64> = m.iter().map(|v| -v).collect();
        assert_relative_eq!(
            SpragueGeers::between(&m, &c).unwrap().phase,
            1.0,
            epsilon = 1e-12
        );
    }

    #[test]
    fn russell_magnitude_is_antisymmetric() {
        let m = pulse(300);
        let c: Vec<f64> = m
            .iter()
            .enumerate()
            .map(|(k, v)| 1.4 * v + 0.01 * (k as f64).sin())
            .collect();
        let a = Russell::between(&m, &c).unwrap();
        let b = Russell::between(&c, &m).unwrap();
        assert_relative_eq!(a.magnitude, -b.magnitude, epsilon = 1e-14);
        assert_relative_eq!(a.phase, b.phase, epsilon = 1e-14);
    }

    #[test]
    fn zero_curves_are_errors() {
        let m = pulse(50);
        assert!(SpragueGeers::between(&[0.0; 50], &m).is_err());
        assert!(Russell::between(&m, &[0.0; 50]).is_err());
        assert!(SpragueGeers::between(&m, &m[..49]).is_err());
    }
}
