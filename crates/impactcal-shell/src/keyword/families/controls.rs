//! Structure, controls and output requests.

use super::W10;
use super::mesh::hourglass_form;
use crate::error::Result;
use crate::keyword::reader::{Kw, Reader};
use crate::model::BulkViscosity;

/// Keywords read elsewhere or with no cards: `*KEYWORD`, `*END`, `*PARAMETER`,
/// `*PARAMETER_EXPRESSION` (their cards are read before the others).
pub(crate) fn nothing(_: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    if kw.ctx.keyword.starts_with("*PARAMETER") {
        while kw.next().is_some() {}
    }
    Ok(())
}

/// `*TITLE`: one title line.
pub(crate) fn title(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    r.model.title = kw
        .next()
        .map(|c| c.text.trim().to_string())
        .unwrap_or_default();
    Ok(())
}

/// `*CONTROL_BULK_VISCOSITY`: Q1 (default 1.5), Q2 (default 0.06), TYPE (-1 or -2 on the
/// shells; 1 or 2 act on solids only: none, with a warning).
pub(crate) fn bulk_viscosity(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let c = kw.take("the card Q1, Q2, TYPE")?;
    let f = kw.fields(&c, W10);
    let q1 = f.real(0, "Q1", 1.5)?;
    let q2 = f.real(1, "Q2", 0.06)?;
    let b = BulkViscosity {
        q1: if q1 == 0.0 { 1.5 } else { q1 },
        q2: if q2 == 0.0 { 0.06 } else { q2 },
    };
    r.model.bulk_viscosity = match f.int(2, "TYPE", 1)? {
        -2 | -1 => Some(b),
        1 | 2 => {
            r.warnings.push(kw.warning(
                c.line,
                "TYPE 1 or 2 acts on solids only: no bulk viscosity on the shells (TYPE -2 applies it to shells)",
            ));
            None
        }
        v => return Err(f.err(format!("field TYPE: {v} is not supported (1, 2, -1 or -2)"))),
    };
    Ok(())
}

/// `*CONTROL_ACCURACY`: OSU (ignored with a warning), INN (1 off, 2-4 invariant numbering),
/// PIDOSU (0), IACC (0).
pub(crate) fn accuracy(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let c = kw.take("the card OSU, INN, PIDOSU, IACC")?;
    let f = kw.fields(&c, W10);
    if f.int(0, "OSU", 0)? != 0 {
        r.warnings
            .push(kw.warning(c.line, "OSU ignored (shell stresses are corotational)"));
    }
    r.model.control.invariant_numbering = match f.int(1, "INN", 1)? {
        0 | 1 => false,
        2..=4 => true,
        v => {
            return Err(f.err(format!(
                "field INN: {v} is not supported (1 off, 2 to 4 on)"
            )));
        }
    };
    f.must_be_zero(2, "PIDOSU")?;
    f.must_be_zero(3, "IACC")?;
    Ok(())
}

/// `*CONTROL_SHELL`, first card WRPANG, ESORT, IRNXX, ISTUPD, THEORY, BWC, MITER, PROJ.
/// BWC and PROJ choose the warping treatment of the Belytschko-Tsay quad: BWC 2 (LS-DYNA's
/// default, also blank or 0) is the element without one (a deck without the keyword reads
/// the same), BWC 1 with PROJ 1 is the full projection (rigid-body modes removed from the
/// velocities and the forces, [`crate::Control::warping_projection`]); BWC 1 with PROJ 0
/// (the drill projection) is refused. Refused as well: THEORY other than 0 or 2 (another
/// element) and ISTUPD other than 0 (thickness update). WRPANG (a warning threshold),
/// ESORT (degenerate quads are always C0 triangles here), IRNXX (the Hughes-Liu normal
/// update) and MITER (the plane-stress return is exact here) have no effect. Card 4's
/// NFAIL1 chooses the distortion check ([`crate::Control::distortion_check`]): 0 or blank
/// (LS-DYNA's default) none, 2 stop the run; 1 and above 2 (element deletion) are refused.
/// Other cards are ignored with a warning when set.
pub(crate) fn shell(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let c = kw.take("the card WRPANG, ESORT, IRNXX, ISTUPD, THEORY, BWC, MITER, PROJ")?;
    let f = kw.fields(&c, W10);
    f.must_be_zero(3, "ISTUPD")?;
    let theory = f.int(4, "THEORY", 0)?;
    if !(theory == 0 || theory == 2) {
        return Err(f.err(format!(
            "field THEORY: {theory} is not supported (0 or 2, the Belytschko-Tsay shell)"
        )));
    }
    let proj = f.int(7, "PROJ", 0)?;
    r.model.control.warping_projection = match (f.int(5, "BWC", 2)?, proj) {
        (0 | 2, _) => false,
        (1, 1) => true,
        (1, 0) => {
            return Err(f.err(
                "field PROJ: 0 (the drill projection) is not supported with BWC 1; \
                 PROJ 1 (the full projection) is"
                    .to_string(),
            ));
        }
        (1, v) => {
            return Err(f.err(format!(
                "field PROJ: {v} is not supported (1, the full projection)"
            )));
        }
        (v, _) => {
            return Err(f.err(format!(
                "field BWC: {v} is not supported (2 or blank: no warping treatment; 1 with \
                 PROJ 1: the full projection)"
            )));
        }
    };
    let mut card = 1;
    while let Some(d) = kw.next() {
        card += 1;
        if card == 4 {
            let f = kw.fields(&d, W10);
            r.model.control.distortion_check = match f.int(0, "NFAIL1", 0)? {
                0 => false,
                2 => true,
                v => {
                    return Err(f.err(format!(
                        "field NFAIL1: {v} is not supported (0 or blank: no distortion check, \
                         LS-DYNA's default; 2: stop the run; element deletion is not \
                         implemented)"
                    )));
                }
            };
            if (1..f.len()).any(|i| matches!(f.raw(i, "card 4"), Ok(Some(_)))) {
                r.warnings.push(kw.warning(
                    d.line,
                    "card 4: only NFAIL1 is read (its other fields have no effect here)",
                ));
            }
        } else if !d.text.trim().is_empty() {
            r.warnings.push(kw.warning(
                d.line,
                "cards 2, 3 and 5 on are ignored (no effect on this solver's \
                 Belytschko-Tsay shell is read from them)",
            ));
        }
    }
    Ok(())
}

/// `*CONTROL_CONTACT`, up to six cards. Read: SLSFAC (the penalty scale factor of the
/// contact interfaces, 0.1 when blank), RWPNAL (0 constraint walls; 0 < RWPNAL <= 1
/// penalty walls), PENOPT (0 or 1: the smaller of the node's and the segment's stiffness);
/// card 2 SSTHK (1: a single-surface contact uses the full shell thickness instead of at
/// most 0.4 of the shortest edge); card 3 SFRIC, DFRIC, EDC, VFC (the friction of
/// interfaces that give none); card 4 IGNORE (0 to 2: initial penetrations are always
/// kept as references). Refused when set: TH, TH_SF, PEN_SF (card 3), SPOTHIN (card 4).
/// Every other field has no effect on the automatic penalty contact of this solver and is
/// ignored, with a warning when it is set.
pub(crate) fn contact(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let c = kw.take("the card SLSFAC, RWPNAL, ...")?;
    let f = kw.fields(&c, W10);
    let slsfac = f.real(0, "SLSFAC", 0.0)?;
    if slsfac < 0.0 {
        return Err(f.err(format!(
            "field SLSFAC: {slsfac} is not supported (a positive scale factor; blank or 0 is 0.1)"
        )));
    }
    r.model.contact_control.penalty_scale = if slsfac == 0.0 { 0.1 } else { slsfac };
    let rwpnal = f.real(1, "RWPNAL", 0.0)?;
    if !(0.0..=1.0).contains(&rwpnal) {
        return Err(f.err(format!(
            "field RWPNAL: {rwpnal} is not supported (0: constraint method, \
             0 < RWPNAL <= 1: penalty walls with that stiffness factor)"
        )));
    }
    r.rwpnal = rwpnal;
    let penopt = f.int(4, "PENOPT", 0)?;
    if !(0..=1).contains(&penopt) {
        return Err(f.err(format!(
            "field PENOPT: {penopt} is not supported (0 or 1: the smaller of the node's and the \
             segment's stiffness)"
        )));
    }
    let mut unused: Vec<&str> = Vec::new();
    for (k, name) in [
        (2, "ISLCHK"),
        (3, "SHLTHK"),
        (5, "THKCHG"),
        (6, "ORIEN"),
        (7, "ENMASS"),
    ] {
        if f.real(k, name, 0.0)? != 0.0 {
            unused.push(name);
        }
    }
    if let Some(c) = kw.next() {
        let g = kw.fields(&c, W10);
        let names = [
            "USRSTR", "USRFRC", "NSBCS", "INTERM", "XPENE", "SSTHK", "ECDT", "TIEDPRJ",
        ];
        for (k, name) in names.iter().enumerate() {
            if k != 5 && g.real(k, name, 0.0)? != 0.0 {
                unused.push(name);
            }
        }
        r.model.contact_control.full_thickness = match g.int(5, "SSTHK", 0)? {
            0 => false,
            1 => true,
            v => return Err(g.err(format!("field SSTHK: {v} is not supported (0 or 1)"))),
        };
    }
    if let Some(c) = kw.next() {
        let g = kw.fields(&c, W10);
        let d = &mut r.default_friction;
        for (k, name, v) in [
            (0, "SFRIC", &mut d.static_coef),
            (1, "DFRIC", &mut d.dynamic),
            (2, "EDC", &mut d.decay),
            (3, "VFC", &mut d.viscous),
        ] {
            *v = g.real(k, name, 0.0)?;
            if *v < 0.0 {
                return Err(g.err(format!("field {name}: must be >= 0, got {v}")));
            }
        }
        for (k, name) in [(4, "TH"), (5, "TH_SF"), (6, "PEN_SF")] {
            g.must_be_zero(k, name)?;
        }
    }
    if let Some(c) = kw.next() {
        let g = kw.fields(&c, W10);
        match g.int(0, "IGNORE", 0)? {
            0..=2 => {}
            v => return Err(g.err(format!("field IGNORE: {v} is not supported (0, 1 or 2)"))),
        }
        g.must_be_zero(6, "SPOTHIN")?;
        for (k, name) in [
            (1, "FRCENG"),
            (2, "SKIPRWG"),
            (3, "OUTSEG"),
            (4, "SPOTSTP"),
            (5, "SPOTDEL"),
        ] {
            if g.real(k, name, 0.0)? != 0.0 {
                unused.push(name);
            }
        }
    }
    let mut extra = 0;
    while extra < 2 && kw.next().is_some() {
        extra += 1;
    }
    if !unused.is_empty() || extra > 0 {
        r.warnings.push(kw.warning(
            c.line,
            format!(
                "{}{} ignored: they have no effect on the automatic penalty contact of this solver",
                unused.join(", "),
                if extra > 0 { " and cards 5, 6" } else { "" }
            ),
        ));
    }
    Ok(())
}

/// `*CONTROL_TERMINATION`: ENDTIM, ENDCYC, DTMIN, ENDENG (0), ENDMAS (0 or 1e8; others
/// ignored with a warning), NOSOL (0).
pub(crate) fn termination(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let c = kw.take("the card ENDTIM, ENDCYC, DTMIN, ENDENG, ENDMAS")?;
    let f = kw.fields(&c, W10);
    r.model.control.end_time = f.real(0, "ENDTIM", 0.0)?;
    r.model.control.end_cycles = f.opt_id(1, "ENDCYC")?;
    r.model.control.dtmin_factor = f.real(2, "DTMIN", 0.0)?;
    f.must_be_zero(3, "ENDENG")?;
    // ENDMAS acts only with mass scaling, which this solver does not do; LS-PrePost writes
    // 1.0e8 by default.
    let endmas = f.real(4, "ENDMAS", 0.0)?;
    if endmas != 0.0 && endmas != 1.0e8 {
        r.warnings.push(kw.warning(
            c.line,
            format!("ENDMAS {endmas} ignored (it acts only with mass scaling)"),
        ));
    }
    f.must_be_zero(5, "NOSOL")?;
    Ok(())
}

/// `*CONTROL_TIMESTEP`: DTINIT (ignored), TSSFAC (default 0.9), ISDO (0 or 1), TSLIMT
/// (ignored), DT2MS (0), LCTM (0); optional card DT2MSF (0), DT2MSLC (0), IMSCL (0) and
/// fields past them (ignored).
pub(crate) fn timestep(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let c = kw.take("the card DTINIT, TSSFAC, ISDO, TSLIMT, DT2MS, LCTM")?;
    let f = kw.fields(&c, W10);
    let tssfac = f.real(1, "TSSFAC", 0.9)?;
    r.model.control.tssfac = if tssfac == 0.0 { 0.9 } else { tssfac };
    r.model.control.isdo_diagonal = match f.int(2, "ISDO", 0)? {
        0 => false,
        1 => true,
        v => return Err(f.err(format!("field ISDO: {v} is not supported (0 or 1)"))),
    };
    f.must_be_zero(4, "DT2MS")?;
    f.must_be_zero(5, "LCTM")?;
    // The optional second card holds further mass-scaling controls: none may be set.
    if let Some(d) = kw.next() {
        let g = kw.fields(&d, W10);
        for (k, name) in ["DT2MSF", "DT2MSLC", "IMSCL"].iter().enumerate() {
            g.must_be_zero(k, name)?;
        }
    }
    Ok(())
}

/// `*CONTROL_HOURGLASS`: IHQ (0-3 viscous, 4-6 stiffness), QH (default 0.1).
pub(crate) fn hourglass(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let c = kw.take("the card IHQ, QH")?;
    let f = kw.fields(&c, W10);
    let form = hourglass_form(kw, c.line, f.int(0, "IHQ", 0)?)?;
    let qh = f.real(1, "QH", 0.1)?;
    let qh = if qh == 0.0 { 0.1 } else { qh };
    let h = &mut r.model.hourglass;
    h.form = form;
    h.membrane = qh;
    h.transverse = qh;
    h.rotation = qh;
    Ok(())
}

/// `*DATABASE_HISTORY_NODE`: node ids, 8 a card; `_ID`: one node a card, its id in
/// columns 1-10 and a heading after it.
pub(crate) fn history_node(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let per_card = if kw.has("ID") { 1 } else { 8 };
    while let Some(c) = kw.next() {
        let f = kw.fields(&c, W10);
        for k in 0..per_card {
            match f.opt_id(k, "ID")? {
                0 => {}
                n => r.model.output.history_nodes.push(n),
            }
        }
    }
    Ok(())
}

/// `*DATABASE_NODOUT`: DT, the sampling interval of histories and energies (the other
/// fields select binary or ASCII files, which this solver does not write).
pub(crate) fn nodout(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let c = kw.take("the card DT, BINARY, ...")?;
    r.model.output.interval = kw.fields(&c, W10).real(0, "DT", 0.0)?;
    Ok(())
}
