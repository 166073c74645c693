//! Pochhammer-Chree dispersion of the first longitudinal mode of a round elastic bar, and
//! its application to a wave travelling along a bar.
//!
//! **Frequency equation** (Pochhammer 1876, Chree 1889; in the form of Graff, "Wave Motion
//! in Elastic Solids", 1975, section 8.2). For a bar of radius `a`, dilatational and shear
//! speeds `c_1`, `c_2` (`c_1^2 = c_0^2 (1 - nu) / ((1 + nu)(1 - 2 nu))`,
//! `c_2^2 = c_0^2 / (2 (1 + nu))`, `c_0 = sqrt(E / rho)`), a wave `exp(i (omega t - k z))`
//! exists when
//!
//! `(2 alpha / a)(beta^2 + k^2) J1(alpha a) J1(beta a) - (beta^2 - k^2)^2 J0(alpha a)
//! J1(beta a) - 4 k^2 alpha beta J1(alpha a) J0(beta a) = 0`,
//!
//! `alpha^2 = omega^2 / c_1^2 - k^2`, `beta^2 = omega^2 / c_2^2 - k^2`. For the first mode
//! the phase velocity `c = omega / k` lies below `c_0 < c_1`, so `alpha = i p` is
//! imaginary, and `beta` is real (`c > c_2`) or imaginary (`c < c_2`); written with the
//! modified Bessel functions and divided by `beta a` (the root `beta = 0` is spurious), the
//! equation is real and continuous in `c` ([`frequency_function`]). For each `k a` the
//! phase velocity is the root found by bisection, followed from `c = c_0` at `k a -> 0`
//! down the branch ([`DispersionCurve::solve`]). Its limits: Rayleigh's
//! `c / c_0 = 1 - nu^2 pi^2 (a / Lambda)^2` at long wavelengths `Lambda = 2 pi / k`, and
//! the Rayleigh surface-wave speed at short ones (for `nu = 0.33` the branch falls
//! monotonically to a shallow minimum 0.3 % below it near `k a = 17` and closes in on it
//! from below).
//!
//! **Propagation.** A wave `x(t)` measured at one section arrives a distance `z` further
//! along the bar as `sum X(omega) exp(i omega t - i k(omega) z)`. The model moves waves by
//! the non-dispersive delay `z / c_0` in the time domain; [`DispersionCurve::disperse`]
//! applies the rest, the phase `-(k(omega) - omega / c_0) z` (scaled by a factor in
//! `[0, 1]`, 0 switching it off), by a zero-padded FFT. `z > 0` moves a wave forward (from
//! the incident gauge to the specimen, from the specimen to a gauge): its high frequencies,
//! slower, arrive later. The radial variation of the strain over the section (the
//! amplitude factors of Tyas and Wilson 2001) is not applied: the gauges read the surface
//! strain, which the model takes as the mean strain.

use crate::error::{ModelsError, Result};

/// Points of the trapezoidal rule for the Bessel integrals: its error is of the order of
/// `J_80(x)` or `I_80(x) / I_0(x)`, below rounding for arguments up to about 40, beyond the
/// range used.
const BESSEL_POINTS: usize = 40;

/// `J_n(x)` (`n` = 0 or 1) by Bessel's integral `(1/pi) int_0^pi cos(n t - x sin t) dt`
/// (trapezoidal rule on a periodic integrand: exponentially convergent).
pub fn bessel_j(n: u32, x: f64) -> f64 {
    let m = BESSEL_POINTS;
    let h = std::f64::consts::PI / m as f64;
    let f = |t: f64| (n as f64 * t - x * t.sin()).cos();
    let mut s = 0.5 * (f(0.0) + f(std::f64::consts::PI));
    for j in 1..m {
        s += f(j as f64 * h);
    }
    s * h / std::f64::consts::PI
}

/// `I_n(x)` (`n` = 0 or 1) by `(1/pi) int_0^pi exp(x cos t) cos(n t) dt`.
pub fn bessel_i(n: u32, x: f64) -> f64 {
    let m = BESSEL_POINTS;
    let h = std::f64::consts::PI / m as f64;
    let f = |t: f64| (x * t.cos()).exp() * (n as f64 * t).cos();
    let mut s = 0.5 * (f(0.0) + f(std::f64::consts::PI));
    for j in 1..m {
        s += f(j as f64 * h);
    }
    s * h / std::f64::consts::PI
}

/// `J1(x) / x`, and its limit 1/2 at 0.
fn j1_over(x: f64) -> f64 {
    if x.abs() < 1e-8 {
        0.5
    } else {
        bessel_j(1, x) / x
    }
}

/// `I1(x) / x`, and its limit 1/2 at 0.
fn i1_over(x: f64) -> f64 {
    if x.abs() < 1e-8 {
        0.5
    } else {
        bessel_i(1, x) / x
    }
}

/// The frequency equation (see the module docs), times `a^4 / (beta a)`, at `K = k a` and
/// phase velocity `c = r c_0` for Poisson's ratio `nu`: zero on a mode.
pub fn frequency_function(ka: f64, r: f64, nu: f64) -> f64 {
    let c1 = ((1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu))).sqrt(); // c_1 / c_0
    let c2 = (1.0 / (2.0 * (1.0 + nu))).sqrt(); // c_2 / c_0
    let k2 = ka * ka;
    let p = ka * (1.0 - (r / c1).powi(2)).max(0.0).sqrt();
    let (i0p, i1p) = (bessel_i(0, p), bessel_i(1, p));
    let b2 = k2 * ((r / c2).powi(2) - 1.0); // (beta a)^2
    if b2 >= 0.0 {
        let q = b2.sqrt();
        -2.0 * p * (b2 + k2) * i1p * j1_over(q) - (b2 - k2).powi(2) * i0p * j1_over(q)
            + 4.0 * k2 * p * i1p * bessel_j(0, q)
    } else {
        let q = (-b2).sqrt();
        -2.0 * p * (k2 - q * q) * i1p * i1_over(q) - (q * q + k2).powi(2) * i0p * i1_over(q)
            + 4.0 * k2 * p * i1p * bessel_i(0, q)
    }
}

/// The first-mode phase velocity over a range of `k a`, solved from the frequency equation
/// for one Poisson ratio; dimensionless (`c / c_0` against `k a` and `omega a / c_0`), so
/// one curve serves any bar of that ratio.
#[derive(Debug, Clone, PartialEq)]
pub struct DispersionCurve {
    /// Poisson's ratio.
    pub poisson: f64,
    /// `k a` at each point, increasing from 0.
    pub ka: Vec<f64>,
    /// `c / c_0` at each point.
    pub ratio: Vec<f64>,
}

impl DispersionCurve {
    /// Solves the curve for `nu` on `k a = 0, step, 2 step, ..., ka_max`.
    ///
    /// # Errors
    /// [`ModelsError::Invalid`] for `nu` outside (0, 0.5) or a step or range that is not
    /// positive; [`ModelsError::Numerical`] when the branch is lost (no sign change below
    /// the previous root).
    pub fn solve(nu: f64, ka_max: f64, step: f64) -> Result<DispersionCurve> {
        if !(nu > 0.0 && nu < 0.5) {
            return Err(ModelsError::invalid(
                "poisson",
                nu,
                "dispersion needs 0 < nu < 0.5",
            ));
        }
        if !(step > 0.0 && ka_max > step && ka_max.is_finite()) {
            return Err(ModelsError::invalid(
                "k a range",
                format!("{ka_max} by {step}"),
                "must be positive, the range above the step",
            ));
        }
        let n = (ka_max / step).ceil() as usize + 1;
        let mut ka = Vec::with_capacity(n);
        let mut ratio = Vec::with_capacity(n);
        ka.push(0.0);
        ratio.push(1.0);
        let floor = 0.5 * (1.0 / (2.0 * (1.0 + nu))).sqrt(); // half the shear speed
        for j in 1..n {
            let x = j as f64 * step;
            let prev: f64 = ratio[j - 1];
            // Scan down from just above the previous root for the first sign change.
            let f = |r: f64| frequency_function(x, r, nu);
            let ds = 2e-3;
            let mut hi = (prev + 1e-6).min(1.0);
            let mut f_hi = f(hi);
            let mut lo = hi - ds;
            let mut found = false;
            while lo > floor {
                let f_lo = f(lo);
                if f_lo.signum() != f_hi.signum() {
                    found = true;
                    break;
                }
                hi = lo;
                f_hi = f_lo;
                lo -= ds;
            }
            if !found {
                return Err(ModelsError::Numerical {
                    what: "Pochhammer-Chree frequency equation".into(),
                    message: format!("no first-mode root below c/c0 = {prev} at k a = {x}"),
                });
            }
            // 2e-3 / 2^45: below rounding of c / c0.
            for _ in 0..45 {
                let mid = 0.5 * (lo + hi);
                if f(mid).signum() == f_hi.signum() {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            ka.push(x);
            ratio.push(0.5 * (lo + hi));
        }
        Ok(DispersionCurve {
            poisson: nu,
            ka,
            ratio,
        })
    }

    /// `k a` at the dimensionless angular frequency `w = omega a / c_0` (interpolated on
    /// the curve's `omega a / c_0 = k a c / c_0`, which increases along the first mode);
    /// beyond the curve, extrapolated at its last phase velocity.
    pub fn ka_at(&self, w: f64) -> f64 {
        let om = |j: usize| self.ka[j] * self.ratio[j];
        let last = self.ka.len() - 1;
        if w >= om(last) {
            return w / self.ratio[last];
        }
        // Binary search on the increasing frequency.
        let (mut lo, mut hi) = (0, last);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if om(mid) <= w {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let f = (w - om(lo)) / (om(hi) - om(lo));
        self.ka[lo] + f * (self.ka[hi] - self.ka[lo])
    }

    /// The phase velocity ratio `c / c_0` at `w = omega a / c_0`.
    pub fn ratio_at(&self, w: f64) -> f64 {
        if w <= 0.0 { 1.0 } else { w / self.ka_at(w) }
    }

    /// The wave `x` (sampled at `dt`) moved a further `z` metres along a bar of radius `a`
    /// and speed `c0`, less the non-dispersive delay `z / c0` (see the module docs), with
    /// the dispersive phase scaled by `amount` (0: `x` unchanged). The result has `x`'s
    /// length; the signal is zero-padded to at least twice its length, so what the
    /// dispersion carries past the end is cut, never wrapped.
    pub fn disperse(&self, x: &[f64], dt: f64, z: f64, a: f64, c0: f64, amount: f64) -> Vec<f64> {
        if amount == 0.0 || x.is_empty() {
            return x.to_vec();
        }
        let n = (2 * x.len()).next_power_of_two();
        let mut re = vec![0.0; n];
        let mut im = vec![0.0; n];
        re[..x.len()].copy_from_slice(x);
        fft(&mut re, &mut im, false);
        for j in 0..=n / 2 {
            let omega = 2.0 * std::f64::consts::PI * j as f64 / (n as f64 * dt);
            let k = self.ka_at(omega * a / c0) / a;
            let phase = -amount * (k - omega / c0) * z;
            let (s, c) = phase.sin_cos();
            let (r, i) = (re[j], im[j]);
            re[j] = r * c - i * s;
            im[j] = r * s + i * c;
            if j > 0 && j < n / 2 {
                // Hermitian symmetry keeps the signal real.
                re[n - j] = re[j];
                im[n - j] = -im[j];
            }
        }
        im[n / 2] = 0.0;
        fft(&mut re, &mut im, true);
        re.truncate(x.len());
        re
    }
}

/// In-place radix-2 FFT of `(re, im)` (length a power of two); `inverse` divides by `n`.
pub(crate) fn fft(re: &mut [f64], im: &mut [f64], inverse: bool) {
    let n = re.len();
    let mut j = 0;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            re.swap(i, j);
            im.swap(i, j);
        }
    }
    let sign = if inverse { 1.0 } else { -1.0 };
    let mut len = 2;
    while len <= n {
        let ang = sign * 2.0 * std::f64::consts::PI / len as f64;
        let (ws, wc) = ang.sin_cos();
        for start in (0..n).step_by(len) {
            let (mut cr, mut ci) = (1.0, 0.0);
            for k in 0..len / 2 {
                let (a, b) = (start + k, start + k + len / 2);
                let tr = re[b] * cr - im[b] * ci;
                let ti = re[b] * ci + im[b] * cr;
                re[b] = re[a] - tr;
                im[b] = im[a] - ti;
                re[a] += tr;
                im[a] += ti;
                let next = cr * wc - ci * ws;
                ci = cr * ws + ci * wc;
                cr = next;
            }
        }
        len <<= 1;
    }
    if inverse {
        let s = 1.0 / n as f64;
        re.iter_mut().for_each(|v| *v *= s);
        im.iter_mut().for_each(|v| *v *= s);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bessel_values_match_published_ones() {
        // Abramowitz and Stegun, tables 9.1 and 9.8 (I_n scaled there by exp(-x)).
        let cases = [
            (bessel_j(0, 1.0), 0.765_197_686_557_966_6),
            (bessel_j(1, 1.0), 0.440_050_585_744_933_5),
            (bessel_j(0, 10.0), -0.245_935_764_451_348_3),
            (bessel_j(1, 10.0), 0.043_472_746_168_861_44),
            (bessel_i(0, 1.0), 1.266_065_877_752_008_4),
            (bessel_i(1, 1.0), 0.565_159_103_992_485_1),
            (bessel_i(0, 10.0), 2_815.716_628_466_254),
        ];
        for (got, want) in cases {
            assert!(
                (got - want).abs() < 1e-13 * want.abs().max(1.0),
                "{got} {want}"
            );
        }
        // The first zero of J0.
        assert!(bessel_j(0, 2.404_825_557_695_773).abs() < 1e-14);
    }

    #[test]
    fn the_fft_inverts_and_matches_a_direct_transform() {
        let x: Vec<f64> = (0..16).map(|k| ((k * k) as f64 * 0.37).sin()).collect();
        let (mut re, mut im) = (x.clone(), vec![0.0; 16]);
        fft(&mut re, &mut im, false);
        for j in 0..16 {
            let (mut r, mut i) = (0.0, 0.0);
            for (k, v) in x.iter().enumerate() {
                let a = -2.0 * std::f64::consts::PI * (j * k) as f64 / 16.0;
                r += v * a.cos();
                i += v * a.sin();
            }
            assert!((re[j] - r).abs() < 1e-12 && (im[j] - i).abs() < 1e-12);
        }
        fft(&mut re, &mut im, true);
        for (a, b) in re.iter().zip(&x) {
            assert!((a - b).abs() < 1e-14);
        }
    }
}
