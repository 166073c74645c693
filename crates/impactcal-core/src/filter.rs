//! A minimal channel-frequency-class (CFC) low-pass filter in the manner of SAE J211: a
//! 2-pole Butterworth section run forward and then backward (no phase shift, 4 poles in
//! effect), with the design frequency `2.0775 CFC` prewarped for the bilinear transform.
//!
//! For a sampling step `T`, `w_d = 2 pi 2.0775 CFC`, `w_a = tan(w_d T / 2)` and
//! `D = 1 + sqrt(2) w_a + w_a^2`:
//! `a_0 = w_a^2 / D`, `a_1 = 2 a_0`, `a_2 = a_0`, `b_1 = -2 (w_a^2 - 1) / D`,
//! `b_2 = (-1 + sqrt(2) w_a - w_a^2) / D`, and each pass computes
//! `y_k = a_0 x_k + a_1 x_{k-1} + a_2 x_{k-2} + b_1 y_{k-1} + b_2 y_{k-2}`.
//! Both ends are extended by an odd reflection about the end value over `2 / CFC`
//! seconds (at most the length of the signal less one sample) and each pass starts from the
//! steady state of its first value, so that a constant or a straight line passes unchanged
//! and the ends do not ring. The amplitude response of the two passes is
//! `1 / (1 + (f / 2.0775 CFC)^4)` in the analogue limit (exact at the design frequency):
//! 0.5 (-6 dB) at `2.0775 CFC`, 0.707 (-3 dB) at `1.667 CFC` (100 Hz for CFC 60), 0.95 at
//! `CFC` Hz.

use crate::error::{CoreError, Result};

/// Filters `signal`, sampled every `dt`, with the channel frequency class `cfc` (in Hz when
/// `dt` is in seconds; CFC 60 is used for structural velocities, CFC 1000 for head
/// accelerations).
///
/// # Errors
/// [`CoreError::Invalid`] for an empty signal, a step or class that is not finite and
/// positive, or a design frequency `2.0775 cfc` at or above the Nyquist frequency
/// `1 / (2 dt)`; [`CoreError::NonFinite`] for a NaN or infinite sample.
pub fn cfc_filter(signal: &[f64], dt: f64, cfc: f64) -> Result<Vec<f64>> {
    if signal.is_empty() {
        return Err(CoreError::Invalid("CFC filter: the signal is empty".into()));
    }
    if !(dt.is_finite() && dt > 0.0) {
        return Err(CoreError::Invalid(format!(
            "CFC filter: the time step must be finite and positive, got {dt}"
        )));
    }
    if !(cfc.is_finite() && cfc > 0.0) {
        return Err(CoreError::Invalid(format!(
            "CFC filter: the class must be finite and positive, got {cfc}"
        )));
    }
    let design = 2.0775 * cfc;
    if design * dt >= 0.5 {
        return Err(CoreError::Invalid(format!(
            "CFC filter: CFC {cfc} needs a design frequency of {design} Hz, at or above the \
             Nyquist frequency {} Hz of the step {dt}",
            0.5 / dt
        )));
    }
    crate::check_finite("CFC filter input", signal)?;
    let wa = (std::f64::consts::PI * design * dt).tan();
    let s2 = std::f64::consts::SQRT_2;
    let den = 1.0 + s2 * wa + wa * wa;
    let a0 = wa * wa / den;
    let b1 = -2.0 * (wa * wa - 1.0) / den;
    let b2 = (-1.0 + s2 * wa - wa * wa) / den;
    let n = signal.len();
    let pad = ((2.0 / (cfc * dt)).round() as usize).min(n - 1);
    let mut y = Vec::with_capacity(n + 2 * pad);
    let (first, last) = (signal[0], signal[n - 1]);
    y.extend((1..=pad).rev().map(|k| 2.0 * first - signal[k]));
    y.extend_from_slice(signal);
    y.extend((1..=pad).map(|k| 2.0 * last - signal[n - 1 - k]));
    let pass = |y: &mut [f64]| {
        let start = y[0];
        let (mut x1, mut x2, mut y1, mut y2) = (start, start, start, start);
        for v in y.iter_mut() {
            let x0 = *v;
            let out = a0 * (x0 + 2.0 * x1 + x2) + b1 * y1 + b2 * y2;
            (x2, x1, y2, y1) = (x1, x0, y1, out);
            *v = out;
        }
    };
    pass(&mut y);
    y.reverse();
    pass(&mut y);
    y.reverse();
    Ok(y[pad..pad + n].to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sine(f: f64, dt: f64, n: usize) -> Vec<f64> {
        (0..n)
            .map(|k| (2.0 * std::f64::consts::PI * f * k as f64 * dt).sin())
            .collect()
    }

    /// Amplitude of a filtered sine over the middle half of the record.
    fn gain(f: f64, cfc: f64) -> f64 {
        let (dt, n) = (1e-4, 4000);
        let x = sine(f, dt, n);
        let y = cfc_filter(&x, dt, cfc).unwrap();
        let mid = n / 4..3 * n / 4;
        let rms = |v: &[f64]| (v.iter().map(|a| a * a).sum::<f64>() / v.len() as f64).sqrt();
        rms(&y[mid.clone()]) / rms(&x[mid])
    }

    /// The two passes give `|H|^2` of the section, close to the analogue
    /// `1 / (1 + (f / f_d)^4)` below a tenth of the sampling rate.
    #[test]
    fn amplitude_response_follows_the_butterworth_magnitude() {
        let cfc = 60.0;
        let fd = 2.0775 * cfc;
        for f in [5.0f64, 30.0, 60.0, 100.0, fd, 250.0, 500.0] {
            let want = 1.0 / (1.0 + (f / fd).powi(4));
            let got = gain(f, cfc);
            assert!((got - want).abs() < 0.01, "f = {f}: {got} vs {want}");
        }
        assert!(gain(2000.0, cfc) < 1e-3);
    }

    #[test]
    fn constants_and_lines_pass_unchanged() {
        let line: Vec<f64> = (0..800).map(|k| 3.0 - 0.01 * k as f64).collect();
        let y = cfc_filter(&line, 1e-4, 60.0).unwrap();
        for (a, b) in line.iter().zip(&y) {
            assert!((a - b).abs() < 1e-7, "{a} vs {b}");
        }
        let flat = vec![-1.25; 300];
        for v in cfc_filter(&flat, 1e-4, 60.0).unwrap() {
            assert!((v + 1.25).abs() < 1e-12);
        }
        let one = cfc_filter(&[2.5], 1e-4, 60.0).unwrap();
        assert!(one.len() == 1 && (one[0] - 2.5).abs() < 1e-12);
    }

    #[test]
    fn bad_input_is_refused() {
        assert!(cfc_filter(&[], 1e-4, 60.0).is_err());
        assert!(cfc_filter(&[1.0, 2.0], 0.0, 60.0).is_err());
        assert!(cfc_filter(&[1.0, 2.0], 1e-4, -1.0).is_err());
        assert!(cfc_filter(&[1.0, f64::NAN], 1e-4, 60.0).is_err());
        // CFC 1000 needs a design frequency of 2077.5 Hz: a 1 kHz sampling rate is too slow.
        assert!(cfc_filter(&[1.0, 2.0], 1e-3, 1000.0).is_err());
    }
}
