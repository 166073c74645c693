//! Materials and curves.

use super::W10;
use crate::error::Result;
use crate::keyword::cards::Card;
use crate::keyword::reader::{Kw, Reader};
use crate::model::{CowperSymonds, Curve, Hardening, Material, MaterialLaw, RigidConstraints};

/// The cards of the block's definitions, `per` cards each (a title card ahead of each,
/// dropped, when the keyword has `_TITLE`), or an error when they do not divide. `short`
/// lists card counts a single definition may stop at (its last cards are optional).
fn definitions<'b>(kw: &mut Kw<'b>, per: usize, short: &[usize]) -> Result<Vec<Vec<Card<'b>>>> {
    let title = usize::from(kw.has("TITLE"));
    let cards: Vec<Card<'b>> = std::iter::from_fn(|| kw.next()).collect();
    let n = cards.len();
    let each = per + title;
    let size = if short.iter().any(|&s| s + title == n) {
        n
    } else if n % each == 0 && n > 0 {
        each
    } else {
        return Err(kw.err(
            kw.line,
            format!(
                "each definition needs {}{per} card(s), found {n} card(s)",
                if title == 1 { "a title card and " } else { "" }
            ),
        ));
    };
    Ok(cards.chunks(size).map(|d| d[title..].to_vec()).collect())
}

/// `*MAT_ELASTIC` / `*MAT_001`: MID, RO, E, PR.
pub(crate) fn elastic(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    for def in definitions(kw, 1, &[])? {
        let f = kw.fields(&def[0], W10);
        r.model.materials.push(Material {
            id: f.id(0, "MID")?,
            density: f.real(1, "RO", 0.0)?,
            youngs: f.real(2, "E", 0.0)?,
            poisson: f.real(3, "PR", 0.0)?,
            law: MaterialLaw::Elastic,
        });
    }
    Ok(())
}

/// `*MAT_PLASTIC_KINEMATIC` / `*MAT_003`: MID, RO, E, PR, SIGY, ETAN, BETA; SRC, SRP, FS,
/// VP (0).
pub(crate) fn plastic_kinematic(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    for def in definitions(kw, 2, &[])? {
        let (c1, c2) = (def[0], def[1]);
        let f = kw.fields(&c1, W10);
        let id = f.id(0, "MID")?;
        let beta = f.real(6, "BETA", 0.0)?;
        if beta != 1.0 {
            let same = if f.real(5, "ETAN", 0.0)? == 0.0 {
                " (the same law here: ETAN = 0, no hardening)"
            } else {
                ""
            };
            r.warnings.push(kw.warning(
                c1.line,
                format!(
                    "material {id}: BETA = {beta}; isotropic hardening (BETA = 1) is used{same}"
                ),
            ));
        }
        let g = kw.fields(&c2, W10);
        let (src, srp) = (g.real(0, "SRC", 0.0)?, g.real(1, "SRP", 0.0)?);
        if g.real(2, "FS", 0.0)? != 0.0 {
            r.warnings.push(kw.warning(
                c2.line,
                format!("material {id}: failure strain FS ignored (no erosion)"),
            ));
        }
        if g.real(3, "VP", 0.0)? != 0.0 {
            return Err(g.err("VP = 1 (viscoplastic rate formulation) is not supported"));
        }
        r.model.materials.push(Material {
            id,
            density: f.real(1, "RO", 0.0)?,
            youngs: f.real(2, "E", 0.0)?,
            poisson: f.real(3, "PR", 0.0)?,
            law: MaterialLaw::Plastic {
                yield_stress: f.real(4, "SIGY", 0.0)?,
                tangent_modulus: f.real(5, "ETAN", 0.0)?,
                rate: (src != 0.0 || srp != 0.0).then_some(CowperSymonds { c: src, p: srp }),
            },
        });
    }
    Ok(())
}

/// `*MAT_PIECEWISE_LINEAR_PLASTICITY` / `*MAT_024`: MID, RO, E, PR, SIGY, ETAN, FAIL,
/// TDEL; C, P, LCSS, LCSR (0), VP (0); EPS1-EPS8; ES1-ES8 (the last two cards may be left
/// out of a single definition). The hardening is the LCSS curve when given, else the
/// EPS/ES points when an ES is non-zero, else linear from SIGY with ETAN.
pub(crate) fn piecewise(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    for def in definitions(kw, 4, &[2])? {
        let (c1, c2) = (def[0], def[1]);
        let f = kw.fields(&c1, W10);
        let id = f.id(0, "MID")?;
        let g = kw.fields(&c2, W10);
        let fail = f.real(6, "FAIL", 0.0)?;
        if fail != 0.0 && fail < 1e20 {
            r.warnings.push(kw.warning(
                c1.line,
                format!("material {id}: failure FAIL = {fail} ignored (no erosion)"),
            ));
        }
        let (c, p) = (g.real(0, "C", 0.0)?, g.real(1, "P", 0.0)?);
        let lcss = g.opt_id(2, "LCSS")?;
        g.must_be_zero(3, "LCSR")?;
        if g.real(4, "VP", 0.0)? != 0.0 {
            return Err(g.err("VP other than 0 (viscoplastic rate formulations) is not supported"));
        }
        let rate = (c != 0.0 || p != 0.0).then_some(CowperSymonds { c, p });
        let mut points = [(0.0, 0.0); 8];
        let mut len = 0;
        if def.len() == 4 {
            let (e, s) = (def[2], def[3]);
            let (fe, fs) = (kw.fields(&e, W10), kw.fields(&s, W10));
            for k in 0..8 {
                let sk = fs.real(k, &format!("ES{}", k + 1), 0.0)?;
                let ek = fe.real(k, &format!("EPS{}", k + 1), 0.0)?;
                if sk != 0.0 {
                    points[len] = (ek, sk);
                    len += 1;
                }
            }
        }
        let law = if lcss != 0 {
            MaterialLaw::PlasticCurve {
                hardening: Hardening::Curve(lcss),
                rate,
            }
        } else if len > 0 {
            if len < 2 {
                return Err(kw.err(
                    c1.line,
                    format!("material {id}: the EPS/ES table needs at least 2 points"),
                ));
            }
            MaterialLaw::PlasticCurve {
                hardening: Hardening::Points { len, points },
                rate,
            }
        } else {
            MaterialLaw::Plastic {
                yield_stress: f.real(4, "SIGY", 0.0)?,
                tangent_modulus: f.real(5, "ETAN", 0.0)?,
                rate,
            }
        };
        r.model.materials.push(Material {
            id,
            density: f.real(1, "RO", 0.0)?,
            youngs: f.real(2, "E", 0.0)?,
            poisson: f.real(3, "PR", 0.0)?,
            law,
        });
    }
    Ok(())
}

/// The global directions of a `*MAT_RIGID` CON1 or CON2 code: 0 none, 1 x, 2 y, 3 z, 4 x
/// and y, 5 y and z, 6 z and x, 7 all.
fn directions(code: i64) -> Option<[bool; 3]> {
    Some(match code {
        0 => [false, false, false],
        1 => [true, false, false],
        2 => [false, true, false],
        3 => [false, false, true],
        4 => [true, true, false],
        5 => [false, true, true],
        6 => [true, false, true],
        7 => [true, true, true],
        _ => return None,
    })
}

/// `*MAT_RIGID` / `*MAT_020`: MID, RO, E, PR, N (0), COUPLE, M (0), ALIAS; CMO (0 or 1),
/// CON1, CON2; LCO or A1-V3 (output axes, ignored). Cards 2 and 3 may be left out of a
/// single definition.
pub(crate) fn rigid(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    for def in definitions(kw, 3, &[1, 2])? {
        let c1 = def[0];
        let f = kw.fields(&c1, W10);
        let id = f.id(0, "MID")?;
        f.must_be_zero(4, "N")?;
        f.must_be_zero(6, "M")?;
        let mut constraints = RigidConstraints::default();
        if let Some(c2) = def.get(1) {
            let g = kw.fields(c2, W10);
            let cmo = g.real(0, "CMO", 0.0)?;
            if cmo == 1.0 {
                for (i, name) in [(1, "CON1"), (2, "CON2")] {
                    let code = g.int(i, name, 0)?;
                    let d = directions(code).ok_or_else(|| {
                        g.err(format!("field {name}: {code} is not a code 0 to 7"))
                    })?;
                    if i == 1 {
                        constraints.translation = d;
                    } else {
                        constraints.rotation = d;
                    }
                }
            } else if cmo != 0.0 {
                return Err(g.err(format!(
                    "field CMO: {cmo} is not supported (0 free, 1 held in global directions)"
                )));
            }
        }
        r.model.materials.push(Material {
            id,
            density: f.real(1, "RO", 0.0)?,
            youngs: f.real(2, "E", 0.0)?,
            poisson: f.real(3, "PR", 0.0)?,
            law: MaterialLaw::Rigid { constraints },
        });
    }
    Ok(())
}

/// `*DEFINE_CURVE`: LCID, SIDR (0), SFA, SFO (0 = 1), OFFA, OFFO, DATTYP (0); then the
/// points A, O (20 columns each).
pub(crate) fn define_curve(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    if kw.has("TITLE") {
        kw.take("the title card")?;
    }
    let c = kw.take("the card LCID, SIDR, SFA, SFO, ...")?;
    let f = kw.fields(&c, W10);
    let id = f.id(0, "LCID")?;
    f.must_be_zero(1, "SIDR")?;
    f.must_be_zero(6, "DATTYP")?;
    let mut curve = Curve::new(id, Vec::new());
    curve.sfa = f.real(2, "SFA", 1.0)?;
    curve.sfo = f.real(3, "SFO", 1.0)?;
    curve.sfa = if curve.sfa == 0.0 { 1.0 } else { curve.sfa };
    curve.sfo = if curve.sfo == 0.0 { 1.0 } else { curve.sfo };
    curve.offa = f.real(4, "OFFA", 0.0)?;
    curve.offo = f.real(5, "OFFO", 0.0)?;
    while let Some(p) = kw.next() {
        let g = kw.fields(&p, &[20]);
        curve
            .points
            .push((g.real(0, "A", 0.0)?, g.real(1, "O", 0.0)?));
    }
    r.model.curves.push(curve);
    Ok(())
}
