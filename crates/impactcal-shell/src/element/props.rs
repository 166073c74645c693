//! The constants of a part, checked once and prepared for the element loop.

use crate::error::{Result, ShellError};
use crate::geometry::thickness_rule;
use crate::material::MaterialProps;
use crate::model::{Hourglass, HourglassForm, Material, MaterialLaw, Section, ThicknessRule};

/// A material with the elastic constants of `m` (for re-checking a section).
fn material_of(m: &MaterialProps) -> Material {
    Material {
        id: 0,
        density: m.rho,
        youngs: m.e,
        poisson: m.nu,
        law: MaterialLaw::Elastic,
    }
}
use crate::validate::{check_hourglass, check_material, check_section};

/// Number of state values ahead of the thickness points: transverse shear resultants
/// `Q_x, Q_y`, then the five hourglass generalised forces (membrane x, y, out-of-plane w,
/// rotation x, y).
pub const STATE_HEAD: usize = 7;
/// State values per thickness point: `s_xx, s_yy, s_xy`, equivalent plastic strain.
pub const STATE_PER_POINT: usize = 4;

/// Section and material constants of a part, prepared for the element loop.
///
/// Only [`PartProps::new`] builds one, from a checked section, material and hourglass
/// control, so every value the element kernels read is valid (positive thickness, 1 to 10
/// thickness points with weights summing to 1, a usable material).
#[derive(Debug, Clone, PartialEq)]
pub struct PartProps {
    /// Thickness.
    pub(crate) t: f64,
    /// Heights of the thickness points (physical, from the mid-surface).
    pub(crate) z: Vec<f64>,
    /// Weights of the thickness points, summing to 1.
    pub(crate) w: Vec<f64>,
    /// Transverse shear factor.
    pub(crate) shear_factor: f64,
    /// Material constants.
    pub(crate) mat: MaterialProps,
    /// Hourglass form.
    pub(crate) hg_form: HourglassForm,
    /// Hourglass coefficients (membrane, out-of-plane, rotation).
    pub(crate) hg: [f64; 3],
    /// Stiffness-proportional damping coefficient in the sign convention of
    /// [`crate::model::PartStiffnessDamping::coef`] (0: none).
    pub(crate) stiffness_damping: f64,
    /// Moments of the thickness rule `[sum w_k z_k, sum w_k z_k^2]` (physical heights), which
    /// turn strain rates into the resultants of the stiffness damping.
    pub(crate) z_moments: [f64; 2],
    /// Shell bulk viscosity coefficients `[Q1, Q2]` (`[0, 0]`: none), see
    /// [`crate::model::BulkViscosity`].
    pub(crate) bulk: [f64; 2],
    /// A rigid part: its elements are not evaluated (they carry no stress).
    pub(crate) rigid: bool,
    /// The part's section and hourglass control, to make the constants of a shell with its
    /// own thickness.
    pub(crate) section: Section,
    pub(crate) hourglass: Hourglass,
}

impl PartProps {
    /// Checks a part's section, material and the hourglass control and prepares its
    /// constants: thickness points `z_k = zeta_k t / 2` and weights `w_k` (Gauss or Lobatto,
    /// weights summing to 1), the moments `[sum w_k z_k, sum w_k z_k^2]`, the material
    /// constants; no stiffness damping, no bulk viscosity.
    ///
    /// # Errors
    /// [`ShellError::Value`] naming the section or material and the field when the
    /// thickness or shear factor is not positive, the number of thickness points is outside
    /// 1 to 10 (Lobatto: 2 to 10), the material is unusable (density, Young's modulus,
    /// `-1 < nu < 0.5`, yield stress, `0 <= Et < E`, Cowper-Symonds constants) or an
    /// hourglass coefficient is negative or not finite.
    pub fn new(section: &Section, material: &Material, hourglass: &Hourglass) -> Result<Self> {
        check_section(section)?;
        check_material(material)?;
        check_hourglass(hourglass)?;
        let (zeta, w) = thickness_rule(section.nip, section.rule == ThicknessRule::Lobatto);
        let z: Vec<f64> = zeta.iter().map(|z| 0.5 * z * section.thickness).collect();
        let z_moments = [
            z.iter().zip(&w).map(|(z, w)| w * z).sum(),
            z.iter().zip(&w).map(|(z, w)| w * z * z).sum(),
        ];
        Ok(PartProps {
            t: section.thickness,
            z,
            w,
            shear_factor: section.shear_factor,
            mat: MaterialProps::new(material),
            hg_form: hourglass.form,
            hg: [hourglass.membrane, hourglass.transverse, hourglass.rotation],
            stiffness_damping: 0.0,
            z_moments,
            bulk: [0.0, 0.0],
            rigid: false,
            section: *section,
            hourglass: *hourglass,
        })
    }

    /// The same part with the thickness `t` (a shell of `*ELEMENT_SHELL_THICKNESS`): the
    /// thickness points scale with it; everything else is kept.
    ///
    /// # Errors
    /// [`ShellError::Value`] when `t` is not finite and positive.
    pub(crate) fn with_thickness(&self, t: f64, section: &Section) -> Result<Self> {
        let sec = Section {
            thickness: t,
            ..*section
        };
        let mut p = PartProps::new(&sec, &material_of(&self.mat), &self.hourglass)?;
        p.mat = self.mat.clone();
        p.stiffness_damping = self.stiffness_damping;
        p.bulk = self.bulk;
        p.rigid = self.rigid;
        Ok(p)
    }

    /// The same part with a piecewise-linear hardening curve `(plastic strain, yield
    /// stress)` (see [`MaterialProps::with_hardening`]).
    ///
    /// # Errors
    /// [`ShellError::Value`] when the curve is not usable.
    pub(crate) fn with_hardening(mut self, points: Vec<(f64, f64)>) -> Result<Self> {
        self.mat = self
            .mat
            .with_hardening(points)
            .map_err(|m| ShellError::value("hardening curve", m))?;
        Ok(self)
    }

    /// The same part with stiffness-proportional damping `coef` (see
    /// [`crate::model::PartStiffnessDamping`]: `coef > 0` a fraction of the element's
    /// stable step, `coef < 0` the Rayleigh `beta = -coef` in time units, 0 none).
    ///
    /// # Errors
    /// [`ShellError::Value`] when `coef` is not finite.
    pub fn with_stiffness_damping(mut self, coef: f64) -> Result<Self> {
        if !coef.is_finite() {
            return Err(ShellError::value(
                "stiffness damping",
                format!("coefficient must be finite, got {coef}"),
            ));
        }
        self.stiffness_damping = coef;
        Ok(self)
    }

    /// Thickness `t`.
    pub fn thickness(&self) -> f64 {
        self.t
    }

    /// Heights `z_k` of the thickness points from the mid-surface (physical units).
    pub fn heights(&self) -> &[f64] {
        &self.z
    }

    /// Weights `w_k` of the thickness points (summing to 1).
    pub fn weights(&self) -> &[f64] {
        &self.w
    }

    /// The material constants.
    pub fn material(&self) -> &MaterialProps {
        &self.mat
    }

    /// The number of state values of one element of this part:
    /// `STATE_HEAD + STATE_PER_POINT * nip`.
    pub fn state_len(&self) -> usize {
        STATE_HEAD + STATE_PER_POINT * self.z.len()
    }

    /// The Rayleigh coefficient `beta` of an element whose undamped stable step is `dt_e`,
    /// and the factor `sqrt(1 + zeta^2) - zeta` on its stable step, `zeta = beta / dt_e`
    /// (the fraction of critical damping at the element's highest frequency `2 / dt_e`).
    #[inline]
    pub fn damping_beta(&self, dt_e: f64) -> (f64, f64) {
        let c = self.stiffness_damping;
        let beta = if c > 0.0 { c * dt_e } else { -c };
        let zeta = beta / dt_e;
        (beta, (1.0 + zeta * zeta).sqrt() - zeta)
    }

    /// Shell bulk viscosity for the areal strain rate `rate` (`d_xx + d_yy`) of an element
    /// of characteristic length `len`: the in-plane pressure
    /// `q = rho len (Q1^2 len rate^2 - Q2 c rate)` while the area shrinks (`rate < 0`, else
    /// 0) and the stable step `len / (Q + sqrt(Q^2 + c^2))`, `Q = Q1^2 len |rate| + Q2 c`.
    #[inline]
    pub fn bulk_pressure(&self, rate: f64, len: f64) -> (f64, f64) {
        let c = self.mat.wave_speed;
        if !(rate < 0.0) || self.bulk == [0.0, 0.0] {
            return (0.0, len / c);
        }
        let [q1, q2] = self.bulk;
        let a = q1 * q1 * len * rate.abs();
        let q = self.mat.rho * len * (a * rate.abs() + q2 * c * rate.abs());
        let big_q = a + q2 * c;
        (q, len / (big_q + (big_q * big_q + c * c).sqrt()))
    }
}
