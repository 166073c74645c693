//! Checks of model values shared by the solver set-up and the checked constructors.

use crate::error::{Result, ShellError};
use crate::model::{Hourglass, Material, MaterialLaw, Section, ThicknessRule};

/// `v` finite and `> 0`, else [`ShellError::Value`] naming `what`.
pub(crate) fn positive(what: String, v: f64) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(ShellError::value(
            what,
            format!("must be finite and positive, got {v}"),
        ))
    }
}

/// `v` finite and `>= 0`, else [`ShellError::Value`] naming `what`.
pub(crate) fn non_negative(what: String, v: f64) -> Result<()> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(ShellError::value(
            what,
            format!("must be finite and non-negative, got {v}"),
        ))
    }
}

/// A material the solver can use: positive density and Young's modulus, `-1 < nu < 0.5`,
/// and for a plastic law a positive yield stress, `0 <= Et < E` and positive Cowper-Symonds
/// constants.
pub(crate) fn check_material(m: &Material) -> Result<()> {
    let w = |f: &str| format!("material {}, {f}", m.id);
    positive(w("density"), m.density)?;
    positive(w("Young's modulus"), m.youngs)?;
    if !(m.poisson > -1.0 && m.poisson < 0.5) {
        return Err(ShellError::value(
            w("nu"),
            format!("must lie in (-1, 0.5), got {}", m.poisson),
        ));
    }
    if let MaterialLaw::Plastic {
        yield_stress,
        tangent_modulus,
        rate,
    } = m.law
    {
        positive(w("yield stress"), yield_stress)?;
        if !(tangent_modulus.is_finite() && tangent_modulus >= 0.0 && tangent_modulus < m.youngs) {
            return Err(ShellError::value(
                w("tangent modulus"),
                format!("must satisfy 0 <= Et < E, got {tangent_modulus}"),
            ));
        }
        if let Some(r) = rate {
            positive(w("Cowper-Symonds C"), r.c)?;
            positive(w("Cowper-Symonds p"), r.p)?;
        }
    }
    if let MaterialLaw::PlasticCurve { rate: Some(r), .. } = m.law {
        positive(w("Cowper-Symonds C"), r.c)?;
        positive(w("Cowper-Symonds p"), r.p)?;
    }
    Ok(())
}

/// A section the solver can use: positive thickness and shear factor, 1 to 10 points
/// through the thickness, at least 2 for Lobatto's rule.
pub(crate) fn check_section(s: &Section) -> Result<()> {
    let w = |f: &str| format!("section {}, {f}", s.id);
    positive(w("thickness"), s.thickness)?;
    positive(w("shear factor"), s.shear_factor)?;
    if !(1..=10).contains(&s.nip) {
        return Err(ShellError::value(
            w("NIP"),
            format!("must be 1 to 10, got {}", s.nip),
        ));
    }
    if s.rule == ThicknessRule::Lobatto && s.nip < 2 {
        return Err(ShellError::value(
            w("NIP"),
            "Lobatto integration needs at least 2 points",
        ));
    }
    Ok(())
}

/// Hourglass coefficients finite and non-negative.
pub(crate) fn check_hourglass(hg: &Hourglass) -> Result<()> {
    for (name, v) in [
        ("membrane", hg.membrane),
        ("transverse", hg.transverse),
        ("rotation", hg.rotation),
    ] {
        non_negative(format!("hourglass {name} coefficient"), v)?;
    }
    Ok(())
}
