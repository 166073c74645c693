//! Nodes, shells, masses, parts, sections and hourglass definitions.

use super::W10;
use crate::error::Result;
use crate::keyword::cards::Card;
use crate::keyword::reader::{Kw, Reader};
use crate::model::{
    ElementThickness, Hourglass, HourglassDef, HourglassForm, Part, PointMass, Section,
    ThicknessRule,
};

/// `*NODE`: NID (8), X, Y, Z (16), TC, RC (8, must be 0).
pub(crate) fn node(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    while let Some(c) = kw.next() {
        let f = kw.fields(&c, &[8, 16, 16, 16, 8, 8]);
        let id = f.id(0, "NID")?;
        let x = f.real3(1, ["X", "Y", "Z"])?;
        if f.int(4, "TC", 0)? != 0 || f.int(5, "RC", 0)? != 0 {
            return Err(f.err("nodal constraints TC/RC are not supported (use *BOUNDARY_SPC_NODE)"));
        }
        r.model.add_node(id, x);
    }
    Ok(())
}

/// The element card of `*ELEMENT_SHELL` and `*ELEMENT_SHELL_THICKNESS`: EID, PID, N1-N4
/// (N4 blank or equal to N3 for a triangle), N5-N8 blank.
fn shell_card(kw: &Kw<'_>, c: &Card<'_>) -> Result<(u64, u64, [u64; 4])> {
    let f = kw.fields(c, &[8]);
    let id = f.id(0, "EID")?;
    let part = f.id(1, "PID")?;
    let mut n = [0u64; 4];
    for k in 0..3 {
        n[k] = f.id(2 + k, &format!("N{}", k + 1))?;
    }
    n[3] = match f.opt_id(5, "N4")? {
        0 => n[2],
        v => v,
    };
    for k in 6..10 {
        if f.opt_id(k, "N5-N8")? != 0 {
            return Err(f.err("mid-side nodes N5-N8 are not supported"));
        }
    }
    Ok((id, part, n))
}

/// `*ELEMENT_SHELL`: one element a card.
pub(crate) fn element_shell(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    while let Some(c) = kw.next() {
        let (id, part, n) = shell_card(kw, &c)?;
        r.model.add_shell(id, part, n);
    }
    Ok(())
}

/// `*ELEMENT_SHELL_THICKNESS`: the element card, then THIC1-THIC4 (16 each, 0 = the
/// section's thickness) and BETA (16; a material angle, which no isotropic material
/// reads).
pub(crate) fn element_shell_thickness(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    while let Some(c) = kw.next() {
        let (id, part, n) = shell_card(kw, &c)?;
        let t = kw.take("the thickness card THIC1-THIC4")?;
        let f = kw.fields(&t, &[16]);
        let mut nodal = [0.0; 4];
        for (k, v) in nodal.iter_mut().enumerate() {
            *v = f.real(k, &format!("THIC{}", k + 1), 0.0)?;
            if *v < 0.0 {
                return Err(f.err(format!("field THIC{}: {} is negative", k + 1, *v)));
            }
        }
        r.model.add_shell(id, part, n);
        if nodal.iter().any(|&v| v != 0.0) {
            let given: Vec<f64> = nodal.iter().copied().filter(|&v| v != 0.0).collect();
            if given
                .iter()
                .any(|&v| (v - given[0]).abs() > 1e-12 * given[0])
                || given.len() < 4
            {
                r.warnings.push(kw.warning(
                    t.line,
                    format!("shell {id}: unequal nodal thicknesses replaced by their mean"),
                ));
            }
            r.model
                .element_thickness
                .push(ElementThickness { shell: id, nodal });
        }
    }
    Ok(())
}

/// `*ELEMENT_MASS`: EID, NID (8 each), MASS (16), PID (8, ignored).
pub(crate) fn element_mass(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    while let Some(c) = kw.next() {
        let f = kw.fields(&c, &[8, 8, 16, 8]);
        r.model.masses.push(PointMass {
            id: f.id(0, "EID")?,
            node: f.id(1, "NID")?,
            mass: f.real(2, "MASS", 0.0)?,
        });
    }
    Ok(())
}

/// `*PART`: a title card and PID, SECID, MID, EOSID (0), HGID, GRAV, ADPOPT, TMID for each
/// part.
pub(crate) fn part(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    while let Some(title) = kw.next() {
        let c = kw.take("the part card PID, SECID, MID after the title")?;
        let f = kw.fields(&c, W10);
        let id = f.id(0, "PID")?;
        let section = f.id(1, "SECID")?;
        let material = f.id(2, "MID")?;
        f.must_be_zero(3, "EOSID")?;
        let hourglass = f.opt_id(4, "HGID")?;
        for (k, name, what) in [
            (6, "ADPOPT", "adaptive remeshing"),
            (7, "TMID", "thermal material"),
        ] {
            if f.opt_id(k, name)? != 0 {
                r.warnings
                    .push(kw.warning(c.line, format!("part {id}: {name} ignored (no {what})")));
            }
        }
        r.model.parts.push(Part {
            id,
            title: title.text.trim().to_string(),
            section,
            material,
            hourglass,
        });
    }
    Ok(())
}

/// `*SECTION_SHELL`: SECID, ELFORM, SHRF, NIP, PROPT, QR/IRID (0), ICOMP (0), SETYP; T1-T4,
/// NLOC (0), MAREA (0), IDOF, EDGSET.
pub(crate) fn section_shell(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    while kw.more() {
        if kw.has("TITLE") {
            kw.take("the title card")?;
        }
        let c = kw.take("the section card SECID, ELFORM, ...")?;
        let t = kw.take("the thickness card T1-T4")?;
        let f = kw.fields(&c, W10);
        let id = f.id(0, "SECID")?;
        let elform = f.int(1, "ELFORM", 2)?;
        if ![0, 2, 4].contains(&elform) {
            return Err(f.err(format!(
                "ELFORM {elform} is not supported (2: Belytschko-Tsay, 4: C0 triangle)"
            )));
        }
        let shrf = f.real(2, "SHRF", 1.0)?;
        let nip = f.int(3, "NIP", 2)?;
        let nip = if nip == 0 { 2 } else { nip };
        f.must_be_zero(5, "QR/IRID")?;
        f.must_be_zero(6, "ICOMP")?;
        let g = kw.fields(&t, W10);
        let t1 = g.real(0, "T1", 0.0)?;
        let ts = [
            t1,
            g.real(1, "T2", t1)?,
            g.real(2, "T3", t1)?,
            g.real(3, "T4", t1)?,
        ];
        g.must_be_zero(4, "NLOC")?;
        g.must_be_zero(5, "MAREA")?;
        let ts = ts.map(|t| if t == 0.0 { t1 } else { t });
        if ts.iter().any(|&t| (t - t1).abs() > 1e-12 * t1.abs()) {
            r.warnings.push(kw.warning(
                t.line,
                format!("section {id}: unequal nodal thicknesses replaced by their mean"),
            ));
        }
        r.model.sections.push(Section {
            id,
            thickness: ts.iter().sum::<f64>() / 4.0,
            nip: usize::try_from(nip).map_err(|_| f.err(format!("NIP {nip} out of range")))?,
            shear_factor: if shrf == 0.0 { 1.0 } else { shrf },
            rule: ThicknessRule::Gauss,
        });
    }
    Ok(())
}

/// The hourglass form of an IHQ value: 0 to 3 viscous (0 is LS-DYNA's type 1), 4 to 6
/// stiffness.
pub(crate) fn hourglass_form(kw: &Kw<'_>, line: usize, ihq: i64) -> Result<HourglassForm> {
    match ihq {
        0..=3 => Ok(HourglassForm::Viscous),
        4..=6 => Ok(HourglassForm::Stiffness),
        v => Err(kw.err(
            line,
            format!("field IHQ: {v} is not supported (1-3 viscous, 4-6 stiffness)"),
        )),
    }
}

/// `*HOURGLASS`: HGID, IHQ, QM (default 0.1), IBQ, Q1, Q2, QB (default QM), QW (default
/// QM), one definition a card. QM is the membrane coefficient, QB the bending (rotation)
/// one and QW the warping (out-of-plane) one.
pub(crate) fn hourglass(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    while kw.more() {
        if kw.has("TITLE") {
            kw.take("the title card")?;
        }
        let c = kw.take("the card HGID, IHQ, QM, ...")?;
        let f = kw.fields(&c, W10);
        let id = f.id(0, "HGID")?;
        let form = hourglass_form(kw, c.line, f.int(1, "IHQ", 0)?)?;
        let qm = f.real(2, "QM", 0.1)?;
        let qm = if qm == 0.0 { 0.1 } else { qm };
        if f.real(4, "Q1", 0.0)? != 0.0 || f.real(5, "Q2", 0.0)? != 0.0 {
            r.warnings.push(kw.warning(
                c.line,
                format!("hourglass {id}: Q1, Q2 ignored (*CONTROL_BULK_VISCOSITY sets the shells' bulk viscosity)"),
            ));
        }
        let or_qm = |v: f64| if v == 0.0 { qm } else { v };
        r.model.hourglass_defs.push(HourglassDef {
            id,
            hourglass: Hourglass {
                form,
                membrane: qm,
                rotation: or_qm(f.real(6, "QB", 0.0)?),
                transverse: or_qm(f.real(7, "QW", 0.0)?),
            },
        });
    }
    Ok(())
}
