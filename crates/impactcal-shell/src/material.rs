//! Plane-stress material update: elasticity and von Mises plasticity with linear isotropic
//! hardening by the exact plane-stress return.
//!
//! Stresses are `[s_xx, s_yy, s_xy]` in the element frame; strain increments
//! `[de_xx, de_yy, dgamma_xy]` (engineering shear). The elastic predictor is
//! `s* = s + C de` with the plane-stress stiffness `C = E/(1-nu^2) [[1, nu, 0], [nu, 1, 0],
//! [0, 0, (1-nu)/2]]`. When the von Mises stress
//! `s_vm^2 = s_xx^2 + s_yy^2 - s_xx s_yy + 3 s_xy^2` of the predictor exceeds the current
//! yield stress `s_y(p) = s_y0 + H p` (`H = E Et/(E - Et)`), the return solves for the
//! equivalent plastic strain increment `dp` with associative flow. In the variables
//! `s = s_xx + s_yy`, `d = s_xx - s_yy`, the flow rule gives
//! `s = s*/(1 + E dp/(2 s_y (1-nu)))`, `d = d*/(1 + 3 E dp/(2 s_y (1+nu)))` and the same
//! factor as `d` on `s_xy`, and `dp` is the root of
//! `F(dp) = s*^2/4 P^2 + (3 d*^2/4 + 3 s_xy*^2) Q^2 - s_y(p + dp)^2 = 0`
//! found by Newton iteration from the radial-return estimate `(s_vm* - s_y) / (3 G + H)`,
//! safeguarded by bisection, to a relative tolerance of 1e-12 on `F`.

use std::sync::Arc;

use crate::model::{Curve, Hardening, Material, MaterialLaw};

/// Material constants prepared for the element loop.
#[derive(Debug, Clone, PartialEq)]
pub struct MaterialProps {
    /// Young's modulus.
    pub e: f64,
    /// Poisson's ratio.
    pub nu: f64,
    /// Density.
    pub rho: f64,
    /// Shear modulus `E / (2 (1 + nu))`.
    pub g: f64,
    /// Plane-stress modulus `E / (1 - nu^2)`.
    pub c11: f64,
    /// Initial yield stress (infinite for elastic materials).
    pub yield0: f64,
    /// Plastic modulus `H`.
    pub hardening: f64,
    /// Cowper-Symonds `(1/C, 1/p)`, or `(0, 0)` for no rate scaling.
    pub rate: (f64, f64),
    /// Plate wave speed `sqrt(E / (rho (1 - nu^2)))`.
    pub wave_speed: f64,
    /// A piecewise-linear hardening curve `(plastic strain, yield stress)` in place of
    /// `yield0 + hardening p` (abscissae increasing, stresses not decreasing).
    pub curve: Option<Arc<[(f64, f64)]>>,
}

/// The points `(plastic strain, yield stress)` of a hardening, from its curve (with the
/// curve's scale factors and offsets applied) or its point table, checked: at least two
/// points, abscissae increasing from at most 0, positive stresses that do not decrease.
///
/// # Errors
/// A message saying what is wrong.
pub fn hardening_points(h: Hardening, curves: &[Curve]) -> Result<Vec<(f64, f64)>, String> {
    let pts: Vec<(f64, f64)> = match h {
        Hardening::Curve(id) => {
            let c = curves
                .iter()
                .find(|c| c.id == id)
                .ok_or_else(|| format!("curve {id} (LCSS) is not defined"))?;
            c.points
                .iter()
                .map(|&(a, _)| {
                    let x = (a + c.offa) * c.sfa;
                    (x, c.eval(x))
                })
                .collect()
        }
        Hardening::Points { len, points } => points[..len.min(8)].to_vec(),
    };
    if pts.len() < 2 {
        return Err("needs at least 2 points".into());
    }
    if pts.iter().any(|p| !(p.0.is_finite() && p.1.is_finite())) {
        return Err("a point is not finite".into());
    }
    if pts.windows(2).any(|w| !(w[1].0 > w[0].0)) {
        return Err("plastic strains must increase".into());
    }
    if !(pts[0].0 <= 0.0) {
        return Err(format!(
            "the first point's plastic strain {} must be 0 (or below)",
            pts[0].0
        ));
    }
    if pts.windows(2).any(|w| w[1].1 < w[0].1) || !(pts[0].1 > 0.0) {
        return Err("yield stresses must be positive and must not decrease (no softening)".into());
    }
    Ok(pts)
}

impl MaterialProps {
    /// Prepares the constants of a material (assumed validated).
    pub fn new(m: &Material) -> Self {
        let (e, nu, rho) = (m.youngs, m.poisson, m.density);
        let c11 = e / (1.0 - nu * nu);
        let (yield0, hardening, rate) = match m.law {
            MaterialLaw::Elastic | MaterialLaw::Rigid { .. } => (f64::INFINITY, 0.0, (0.0, 0.0)),
            // The curve comes with `with_hardening`; until then the material is elastic.
            MaterialLaw::PlasticCurve { rate, .. } => (
                f64::INFINITY,
                0.0,
                rate.map_or((0.0, 0.0), |r| (1.0 / r.c, 1.0 / r.p)),
            ),
            MaterialLaw::Plastic {
                yield_stress,
                tangent_modulus,
                rate,
            } => (
                yield_stress,
                e * tangent_modulus / (e - tangent_modulus),
                rate.map_or((0.0, 0.0), |r| (1.0 / r.c, 1.0 / r.p)),
            ),
        };
        MaterialProps {
            e,
            nu,
            rho,
            g: e / (2.0 * (1.0 + nu)),
            c11,
            yield0,
            hardening,
            rate,
            wave_speed: (c11 / rho).sqrt(),
            curve: None,
        }
    }

    /// The same material with the hardening curve `points` (checked as by
    /// [`hardening_points`]): the initial yield stress is the curve at `p = 0`.
    ///
    /// # Errors
    /// A message when the points are not a usable hardening curve.
    pub fn with_hardening(mut self, points: Vec<(f64, f64)>) -> Result<Self, String> {
        let checked = hardening_points(Hardening::Curve(0), &[Curve::new(0, points)])?;
        self.yield0 = curve_yield(&checked, 0.0).0;
        self.hardening = 0.0;
        self.curve = Some(checked.into());
        Ok(self)
    }

    /// The yield stress at plastic strain `p` (before rate scaling).
    #[inline]
    pub fn yield_stress(&self, p: f64) -> f64 {
        match &self.curve {
            Some(c) => curve_yield(c, p).0,
            None => self.yield0 + self.hardening * p,
        }
    }

    /// True when the material can yield.
    #[inline(always)]
    pub fn is_plastic(&self) -> bool {
        self.yield0.is_finite()
    }

    /// The Cowper-Symonds factor `1 + (rate/C)^(1/p)` for an effective strain rate (1 when
    /// there is no rate scaling).
    #[inline]
    pub fn rate_factor(&self, rate: f64) -> f64 {
        if self.rate.0 > 0.0 && rate > 0.0 {
            1.0 + (rate * self.rate.0).powf(self.rate.1)
        } else {
            1.0
        }
    }

    /// Updates the stress `sig` and the equivalent plastic strain `epsp` of one point for
    /// the strain increment `de`, with the yield stress scaled by `factor` (the rate factor).
    #[inline]
    pub fn update(&self, sig: &mut [f64; 3], epsp: &mut f64, de: [f64; 3], factor: f64) {
        let c12 = self.nu * self.c11;
        let sx = sig[0] + self.c11 * de[0] + c12 * de[1];
        let sy = sig[1] + c12 * de[0] + self.c11 * de[1];
        let txy = sig[2] + self.g * de[2];
        *sig = [sx, sy, txy];
        if self.is_plastic() {
            *sig = self.plastic_return(*sig, epsp, factor);
        }
    }

    /// The return of a trial (elastic predictor) stress to the yield surface: returns the
    /// trial stress itself when it lies within the current yield stress `s_y(p) factor`,
    /// else the returned stress, adding the plastic strain increment to `epsp`.
    #[inline]
    pub fn plastic_return(&self, trial: [f64; 3], epsp: &mut f64, factor: f64) -> [f64; 3] {
        match &self.curve {
            Some(c) => {
                let p0 = *epsp;
                self.return_to(trial, epsp, |dp| {
                    let (y, h) = curve_yield(c, p0 + dp);
                    (y * factor, h * factor)
                })
            }
            None => {
                let hf = self.hardening * factor;
                let sy0 = (self.yield0 + self.hardening * *epsp) * factor;
                self.return_to(trial, epsp, move |dp| (sy0 + hf * dp, hf))
            }
        }
    }

    /// The return for the yield stress `yield_at(dp) = (sigma_y, d sigma_y / d dp)` after a
    /// plastic strain increment `dp` (scaled by the rate factor).
    #[inline(always)]
    fn return_to(
        &self,
        trial: [f64; 3],
        epsp: &mut f64,
        yield_at: impl Fn(f64) -> (f64, f64),
    ) -> [f64; 3] {
        let [sx, sy, txy] = trial;
        let s = sx + sy;
        let d = sx - sy;
        let a = 0.25 * s * s;
        let b = 0.75 * d * d + 3.0 * txy * txy;
        let vm2 = a + b;
        let (sy0, h0) = yield_at(0.0);
        if vm2 <= sy0 * sy0 {
            return trial;
        }
        let (e, c1, c3) = (self.e, 1.0 / (1.0 - self.nu), 3.0 / (1.0 + self.nu));
        let f_of = |dp: f64| {
            let (syn, hf) = yield_at(dp);
            let inv_syn = 1.0 / syn;
            let dr = 0.5 * e * dp * inv_syn;
            let p = 1.0 / (1.0 + c1 * dr);
            let q = 1.0 / (1.0 + c3 * dr);
            let (ap2, bq2) = (a * p * p, b * q * q);
            let f = ap2 + bq2 - syn * syn;
            let df =
                -(c1 * ap2 * p + c3 * bq2 * q) * (e - 2.0 * dr * hf) * inv_syn - 2.0 * hf * syn;
            (f, df, p, q)
        };
        // Safeguarded Newton from the radial-return estimate (exact in pure shear); F(0) > 0
        // and F decreases, so every evaluation narrows the bracket [lo, hi] of the root.
        let tol = 1e-12 * sy0 * sy0;
        let (mut lo, mut hi) = (0.0, f64::INFINITY);
        let mut dp = (vm2.sqrt() - sy0) / (3.0 * self.g + h0);
        let mut fv = f_of(dp);
        for _ in 0..100 {
            let (f, df, _, _) = fv;
            if f.abs() <= tol {
                break;
            }
            if f > 0.0 {
                lo = dp;
            } else {
                hi = dp;
            }
            let next = dp - f / df;
            dp = if next > lo && next < hi {
                next
            } else if hi.is_finite() {
                0.5 * (lo + hi)
            } else {
                (2.0 * dp).max(f64::MIN_POSITIVE)
            };
            fv = f_of(dp);
        }
        let (_, _, p, q) = fv;
        let s = p * s;
        let d = q * d;
        *epsp += dp;
        [0.5 * (s + d), 0.5 * (s - d), q * txy]
    }
}

/// The yield stress of a hardening curve at plastic strain `p` and its slope there: linear
/// between points, the first value below the first point, the last segment's slope past
/// the last point.
#[inline]
fn curve_yield(c: &[(f64, f64)], p: f64) -> (f64, f64) {
    let n = c.len();
    if p <= c[0].0 {
        return (c[0].1, 0.0);
    }
    let k = c.partition_point(|q| q.0 <= p).clamp(1, n - 1) - 1;
    let (a, b) = (c[k], c[k + 1]);
    let slope = (b.1 - a.1) / (b.0 - a.0);
    (a.1 + slope * (p - a.0), slope)
}

/// Von Mises stress of a plane-stress state `[s_xx, s_yy, s_xy]`.
pub fn von_mises(sig: [f64; 3]) -> f64 {
    (sig[0] * sig[0] + sig[1] * sig[1] - sig[0] * sig[1] + 3.0 * sig[2] * sig[2]).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Material, MaterialLaw};

    fn plastic(et: f64) -> MaterialProps {
        MaterialProps::new(&Material {
            id: 1,
            density: 2700.0,
            youngs: 70e9,
            poisson: 0.3,
            law: MaterialLaw::Plastic {
                yield_stress: 250e6,
                tangent_modulus: et,
                rate: None,
            },
        })
    }

    #[test]
    fn uniaxial_stress_follows_the_bilinear_curve() {
        // Drive s_yy = 0 by choosing de_yy = -nu_eff de_xx iteratively: simpler to check
        // equibiaxial and pure shear, where the return is radial.
        let m = plastic(7e9);
        // Equibiaxial: s_vm = s_xx; elastic slope E/(1-nu), plastic stress sy0 + H p.
        let mut sig = [0.0; 3];
        let mut p = 0.0;
        for _ in 0..200 {
            m.update(&mut sig, &mut p, [1e-4, 1e-4, 0.0], 1.0);
        }
        let vm = von_mises(sig);
        assert!((vm - (250e6 + m.hardening * p)).abs() < 1e-6 * vm);
        assert!((sig[0] - sig[1]).abs() < 1e-6);
        // Total strain 0.02 equibiaxial: elastic part s/(E/(1-nu)), plastic strain in the
        // x direction = p/2 (flow direction (2s-s)/(2s) = 1/2).
        let eps = 0.02;
        let el = sig[0] / (m.e / (1.0 - m.nu));
        assert!((el + 0.5 * p - eps).abs() < 1e-9, "{el} {p}");
    }

    #[test]
    fn pure_shear_return_is_exact() {
        let m = plastic(0.0);
        let mut sig = [0.0; 3];
        let mut p = 0.0;
        m.update(&mut sig, &mut p, [0.0, 0.0, 0.02], 1.0);
        // Perfect plasticity: s_xy = sy0 / sqrt(3).
        assert!((sig[2] - 250e6 / 3f64.sqrt()).abs() < 1e-3);
        // dp: gamma_p = sqrt(3) dp, elastic gamma = tau/G.
        let gamma_e = sig[2] / m.g;
        assert!((gamma_e + 3f64.sqrt() * p - 0.02).abs() < 1e-12);
    }

    #[test]
    fn return_lands_on_the_yield_surface_for_any_direction() {
        let m = plastic(3e9);
        for k in 0..36 {
            let a = k as f64 * std::f64::consts::PI / 18.0;
            let mut sig = [10e6, -30e6, 5e6];
            let mut p = 0.01;
            let de = [0.01 * a.cos(), 0.01 * a.sin(), 0.004 * (2.0 * a).sin()];
            m.update(&mut sig, &mut p, de, 1.0);
            let vm = von_mises(sig);
            let sy = 250e6 + m.hardening * p;
            assert!((vm - sy).abs() < 1e-9 * sy, "direction {k}: {vm} vs {sy}");
            assert!(p > 0.01);
        }
    }
}
