//! Repeated tests aligned in time on their input channel.
//!
//! Two tests of one article seldom trigger at the same instant: a drop's record may start a
//! few microseconds earlier than the next one's. Compared sample by sample, that offset
//! alone makes a sharp pulse scatter by tens of percent between repeats, which is not what
//! the article does. The input (the base acceleration) is the same physical event in each
//! test, so the offset is read from it.
//!
//! **Shift.** For a reference input `x` and another test's `y` (same step `dt`), the
//! cross-correlation over the overlap, `c(l) = sum_t x(t) y(t + l)`, is computed for whole
//! lags `|l| <= L`; its largest value at `l*` is refined to a fraction of a sample by the
//! vertex of the parabola through `c(l* - 1)`, `c(l*)`, `c(l* + 1)`:
//! `s = l* + (c(l*-1) - c(l*+1)) / (2 (c(l*-1) - 2 c(l*) + c(l*+1)))`. Why a parabola: near
//! its peak the correlation of a pulse sampled many times across its width is smooth,
//! `c(l* + d) = c0 - c2 d^2 / 2 + O(d^4)`, so the vertex is exact to the quartic term's
//! share, which is the square of the sample step over the pulse's width (a 0.2 ms pulse
//! sampled at 1 MHz: about `1e-4` of a sample, well below what the noise allows). `y(t + s)`
//! then matches `x(t)`: `y` triggered `s dt` later.
//!
//! **Aligned repeat.** `y(t + s dt)` is read from the samples of `y` by a fractional delay
//! in the frequency domain ([`delay_exact`]): the record, padded with zeros to a power of two
//! at least twice its length, is transformed, each bin `m` multiplied by
//! `exp(-2 pi i m shift / M)`, and transformed back. This is an all-pass filter: it moves a
//! band-limited signal exactly and keeps the variance of white noise, where a linear
//! interpolation between samples would halve it at half a sample (its weights `1 - f` and
//! `f` give `(1 - f)^2 + f^2`), so the scatter between repeats would under-report their
//! noise. Only the Nyquist bin, whose delay is not real, is scaled by `cos(pi shift)`.

use crate::error::{ModelsError, Result};
use crate::kolsky::dispersion::fft;

/// `y(k - shift)` for each sample `k` (`shift` in samples), linear between samples, the first
/// value before the record and the last after it. A positive shift delays `y`.
pub fn shift_by(y: &[f64], shift: f64) -> Vec<f64> {
    let n = y.len();
    (0..n)
        .map(|k| {
            let x = k as f64 - shift;
            if x <= 0.0 {
                y[0]
            } else if x >= (n - 1) as f64 {
                y[n - 1]
            } else {
                let i = x.floor() as usize;
                let f = x - i as f64;
                if f == 0.0 {
                    y[i]
                } else {
                    y[i] + f * (y[i + 1] - y[i])
                }
            }
        })
        .collect()
}

/// `y(k - shift)` for each sample `k` (`shift` in samples; positive delays `y`), by the
/// all-pass fractional delay of the module docs. The record's ends meet zeros, not each
/// other: a shift smaller than the record's length does not wrap.
pub fn delay_exact(y: &[f64], shift: f64) -> Vec<f64> {
    let n = y.len();
    if n == 0 {
        return Vec::new();
    }
    let m = (2 * n).next_power_of_two();
    let mut re = vec![0.0; m];
    let mut im = vec![0.0; m];
    re[..n].copy_from_slice(y);
    fft(&mut re, &mut im, false);
    for k in 0..m {
        // Frequency index of bin k, signed: k for the lower half, k - m above.
        let f = if k <= m / 2 {
            k as f64
        } else {
            k as f64 - m as f64
        };
        let (c, s) = if k == m / 2 {
            ((std::f64::consts::PI * shift).cos(), 0.0)
        } else {
            let ph = -2.0 * std::f64::consts::PI * f * shift / m as f64;
            (ph.cos(), ph.sin())
        };
        let (a, b) = (re[k], im[k]);
        re[k] = a * c - b * s;
        im[k] = a * s + b * c;
    }
    fft(&mut re, &mut im, true);
    re.truncate(n);
    re
}

/// The shift `s` (samples) at which `y(t + s)` best matches `x(t)` (see the module docs):
/// the cross-correlation's peak over whole lags `|l| <= max_lag`, refined by a parabola.
///
/// # Errors
/// [`ModelsError::Record`] for records of different lengths, of fewer than three samples,
/// with a non-finite sample, a `max_lag` not below the length, or a correlation with no
/// positive peak (an input that is zero, or unlike the other at every lag).
pub fn input_shift(x: &[f64], y: &[f64], max_lag: usize) -> Result<f64> {
    let n = x.len();
    let what = "alignment of repeated tests";
    if y.len() != n || n < 3 {
        return Err(ModelsError::record(
            what,
            format!(
                "inputs of {} and {} samples: two of one length, at least 3, are needed",
                n,
                y.len()
            ),
        ));
    }
    if let Some(k) = x.iter().chain(y).position(|v| !v.is_finite()) {
        return Err(ModelsError::record(
            what,
            format!("input sample {} is not finite", k % n),
        ));
    }
    if max_lag + 1 >= n {
        return Err(ModelsError::record(
            what,
            format!("a largest lag of {max_lag} samples needs more than {n} samples"),
        ));
    }
    let lag = max_lag as isize;
    let corr = |l: isize| -> f64 {
        let (a, b) = if l >= 0 {
            (&x[..n - l as usize], &y[l as usize..])
        } else {
            (&x[(-l) as usize..], &y[..n - (-l) as usize])
        };
        a.iter().zip(b).map(|(p, q)| p * q).sum()
    };
    let c: Vec<f64> = (-lag..=lag).map(corr).collect();
    let (best, peak) =
        c.iter().enumerate().fold(
            (0, f64::NEG_INFINITY),
            |m, (i, v)| if *v > m.1 { (i, *v) } else { m },
        );
    if peak <= 0.0 {
        return Err(ModelsError::record(
            what,
            "the inputs' cross-correlation has no positive peak (an input is zero or unlike \
             the other at every lag)",
        ));
    }
    let whole = best as f64 - max_lag as f64;
    if best == 0 || best + 1 == c.len() {
        return Ok(whole);
    }
    let (a, b, d) = (c[best - 1], c[best], c[best + 1]);
    let curvature = a - 2.0 * b + d;
    Ok(if curvature < 0.0 {
        whole + (a - d) / (2.0 * curvature)
    } else {
        whole
    })
}
