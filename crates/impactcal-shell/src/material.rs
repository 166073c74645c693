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
//! found by safeguarded Newton iteration to a relative tolerance of 1e-12.

use crate::model::{Material, MaterialLaw};

/// Material constants prepared for the element loop.
#[derive(Debug, Clone, Copy, PartialEq)]
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
}

impl MaterialProps {
    /// Prepares the constants of a material (assumed validated).
    pub fn new(m: &Material) -> Self {
        let (e, nu, rho) = (m.youngs, m.poisson, m.density);
        let c11 = e / (1.0 - nu * nu);
        let (yield0, hardening, rate) = match m.law {
            MaterialLaw::Elastic => (f64::INFINITY, 0.0, (0.0, 0.0)),
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
        if !self.is_plastic() {
            return;
        }
        let s = sx + sy;
        let d = sx - sy;
        let a = 0.25 * s * s;
        let b = 0.75 * d * d + 3.0 * txy * txy;
        let vm2 = a + b;
        let hf = self.hardening * factor;
        let sy0 = (self.yield0 + self.hardening * *epsp) * factor;
        if vm2 <= sy0 * sy0 {
            return;
        }
        let (e, nu) = (self.e, self.nu);
        let f_of = |dp: f64| {
            let syn = sy0 + hf * dp;
            let dr = e * dp / (2.0 * syn);
            let p = 1.0 / (1.0 + dr / (1.0 - nu));
            let q = 1.0 / (1.0 + 3.0 * dr / (1.0 + nu));
            let f = a * p * p + b * q * q - syn * syn;
            let df = -(a * p * p * p / (1.0 - nu) + 3.0 * b * q * q * q / (1.0 + nu))
                * (e - 2.0 * dr * hf)
                / syn
                - 2.0 * hf * syn;
            (f, df, p, q)
        };
        // Bracket: F(0) > 0; find hi with F(hi) < 0.
        let mut lo = 0.0;
        let mut hi = (vm2.sqrt() - sy0) / (3.0 * self.g + hf);
        let mut guard = 0;
        while f_of(hi).0 > 0.0 && guard < 200 {
            lo = hi;
            hi *= 2.0;
            guard += 1;
        }
        let mut dp = 0.5 * (lo + hi);
        let tol = 1e-12 * sy0 * sy0;
        for _ in 0..60 {
            let (f, df, _, _) = f_of(dp);
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
            } else {
                0.5 * (lo + hi)
            };
        }
        let (_, _, p, q) = f_of(dp);
        let s = p * s;
        let d = q * d;
        *sig = [0.5 * (s + d), 0.5 * (s - d), q * txy];
        *epsp += dp;
    }
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
