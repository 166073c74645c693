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

/// `*CONTROL_CONTACT`: RWPNAL (0 constraint walls; 0 < RWPNAL <= 1 penalty walls); the
/// other fields and the optional cards 2 to 6 are ignored with a warning.
pub(crate) fn contact(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let c = kw.take("the card SLSFAC, RWPNAL, ...")?;
    let f = kw.fields(&c, W10);
    let rwpnal = f.real(1, "RWPNAL", 0.0)?;
    if !(0.0..=1.0).contains(&rwpnal) {
        return Err(f.err(format!(
            "field RWPNAL: {rwpnal} is not supported (0: constraint method, \
             0 < RWPNAL <= 1: penalty walls with that stiffness factor)"
        )));
    }
    r.rwpnal = rwpnal;
    let other = (0..8)
        .filter(|&k| k != 1)
        .map(|k| f.real(k, "SLSFAC-ENMASS", 0.0))
        .collect::<Result<Vec<_>>>()?;
    let mut extra = 0;
    while extra < 5 && kw.next().is_some() {
        extra += 1;
    }
    if other.iter().any(|&v| v != 0.0) || extra > 0 {
        r.warnings.push(kw.warning(
            c.line,
            "only RWPNAL is used (there are no contact interfaces)",
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
