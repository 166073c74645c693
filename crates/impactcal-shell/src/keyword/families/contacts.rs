//! Contact interfaces (`*CONTACT_AUTOMATIC_...`).

use super::W10;
use crate::contact::{Contact, ContactFriction, ContactKind, ContactSurface, SideSettings};
use crate::error::Result;
use crate::keyword::cards::Fields;
use crate::keyword::reader::{Kw, Reader};

/// `*CONTACT_AUTOMATIC_SINGLE_SURFACE` (`_ID`, `_TITLE`).
pub(crate) fn single_surface(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    automatic(r, kw, ContactKind::SingleSurface)
}

/// `*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE` (`_ID`, `_TITLE`).
pub(crate) fn surface_to_surface(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    automatic(r, kw, ContactKind::SurfaceToSurface)
}

/// `*CONTACT_AUTOMATIC_NODES_TO_SURFACE` (`_ID`, `_TITLE`).
pub(crate) fn nodes_to_surface(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    automatic(r, kw, ContactKind::NodesToSurface)
}

/// A side of the interface from its id and type: 2 part set, 3 part, 4 node set (slave
/// side of a nodes-to-surface contact), 5 every shell.
fn surface(
    f: &Fields<'_>,
    k: usize,
    id_name: &str,
    ty_name: &str,
    slave: bool,
) -> Result<ContactSurface> {
    let id = f.opt_id(k, id_name)?;
    let ty = f.int(k + 2, ty_name, 0)?;
    let need_id = |s: ContactSurface| {
        if id == 0 {
            Err(f.err(format!(
                "field {id_name}: type {ty_name} = {ty} needs an id"
            )))
        } else {
            Ok(s)
        }
    };
    match ty {
        2 => need_id(ContactSurface::PartSet(id)),
        3 => need_id(ContactSurface::Part(id)),
        4 if slave => need_id(ContactSurface::NodeSet(id)),
        5 => Ok(ContactSurface::All),
        0 | 1 => Err(f.err(format!(
            "field {ty_name}: {ty} (a segment or shell element set) is not supported: give the \
             parts (2 part set, 3 part{})",
            if slave {
                ", 4 node set, 5 all"
            } else {
                ", 5 all"
            }
        ))),
        _ => Err(f.err(format!(
            "field {ty_name}: {ty} is not supported (2 part set, 3 part{})",
            if slave {
                ", 4 node set, 5 all"
            } else {
                ", 5 all"
            }
        ))),
    }
}

/// A scale factor field: blank or 0 is 1; negative values (curves) are refused.
fn scale(f: &Fields<'_>, k: usize, name: &str) -> Result<f64> {
    let v = f.real(k, name, 0.0)?;
    if v < 0.0 {
        return Err(f.err(format!(
            "field {name}: negative values (curves) are not supported, got {v}"
        )));
    }
    Ok(if v == 0.0 { 1.0 } else { v })
}

/// A non-negative field.
fn non_negative(f: &Fields<'_>, k: usize, name: &str) -> Result<f64> {
    let v = f.real(k, name, 0.0)?;
    if v < 0.0 {
        return Err(f.err(format!(
            "field {name}: negative values are not supported, got {v}"
        )));
    }
    Ok(v)
}

/// The cards of one automatic contact: the id card (`_ID`, `_TITLE`: CID and a heading),
/// cards 1 to 3 and the optional cards A to C.
///
/// - Card 1: SSID, MSID, SSTYP, MSTYP (2 part set, 3 part, 4 node set, 5 all), SBOXID (0),
///   MBOXID (0), SPR, MPR (interface force output: warned, not written).
/// - Card 2: FS, FD, DC, VC, VDC, PENCHK (0), BT, DT (0: never).
/// - Card 3: SFS, SFM, SST, MST, SFST, SFMT, FSF, VSF (0: 1; FSF scales FS and FD, VSF
///   scales VC).
/// - Card A: SOFT (0), SOFSCL, SBOPT, DEPTH (used by SOFT 1, 2 only: no effect), LCIDAB
///   (0), MAXPAR, BSORT (search controls: warned, the search here never misses a
///   contact), FRCFRQ (0 or 1).
/// - Card B: PENMAX (0), THKOPT (0), SHLTHK (automatic contacts always use the thickness),
///   SNLOG, ISYM (0), I2D3D (0), SLDTHK, SLDSTF (solids: no effect).
/// - Card C: IGAP (implicit only), IGNORE (0 to 2; initial penetrations are always kept
///   as references, see the contact docs), DPRFAC, DTSTIF, FLANGL (SOFT 2 only), CID_RCF.
fn automatic(r: &mut Reader<'_>, kw: &mut Kw<'_>, kind: ContactKind) -> Result<()> {
    let id = if kw.has("ID") || kw.has("TITLE") {
        let c = kw.take("the id card CID, HEADING")?;
        kw.fields(&c, W10).opt_id(0, "CID")?
    } else {
        0
    };
    let c1 = kw.take("card 1: SSID, MSID, SSTYP, MSTYP, SBOXID, MBOXID, SPR, MPR")?;
    let c2 = kw.take("card 2: FS, FD, DC, VC, VDC, PENCHK, BT, DT")?;
    let c3 = kw.take("card 3: SFS, SFM, SST, MST, SFST, SFMT, FSF, VSF")?;
    let f = kw.fields(&c1, W10);
    let slave = surface(&f, 0, "SSID", "SSTYP", kind == ContactKind::NodesToSurface)?;
    let master = if kind == ContactKind::SingleSurface {
        ContactSurface::All
    } else {
        surface(&f, 1, "MSID", "MSTYP", false)?
    };
    f.must_be_zero(4, "SBOXID")?;
    f.must_be_zero(5, "MBOXID")?;
    if f.real(6, "SPR", 0.0)? != 0.0 || f.real(7, "MPR", 0.0)? != 0.0 {
        r.warnings.push(kw.warning(
            c1.line,
            "SPR, MPR ignored: interface force files are not written (the interface energies are)",
        ));
    }
    let g = kw.fields(&c2, W10);
    let fs = g.real(0, "FS", 0.0)?;
    if fs < 0.0 || fs == 2.0 {
        return Err(g.err(format!(
            "field FS: {fs} (part-based friction or a friction table) is not supported"
        )));
    }
    let fd = non_negative(&g, 1, "FD")?;
    let dc = non_negative(&g, 2, "DC")?;
    let vc = non_negative(&g, 3, "VC")?;
    let vdc = non_negative(&g, 4, "VDC")?;
    g.must_be_zero(5, "PENCHK")?;
    let birth = non_negative(&g, 6, "BT")?;
    let dt = g.real(7, "DT", 0.0)?;
    let death = if dt == 0.0 || dt >= 1e20 {
        f64::INFINITY
    } else if dt > birth {
        dt
    } else {
        return Err(g.err(format!("field DT: {dt} must come after BT {birth}")));
    };
    let h = kw.fields(&c3, W10);
    let sfs = scale(&h, 0, "SFS")?;
    let sfm = scale(&h, 1, "SFM")?;
    let sst = non_negative(&h, 2, "SST")?;
    let mst = non_negative(&h, 3, "MST")?;
    let sfst = scale(&h, 4, "SFST")?;
    let sfmt = scale(&h, 5, "SFMT")?;
    let fsf = scale(&h, 6, "FSF")?;
    let vsf = scale(&h, 7, "VSF")?;
    optional_cards(r, kw)?;
    r.friction_scales.push((fsf, vsf));
    r.model.contacts.push(Contact {
        id,
        kind,
        slave,
        master,
        slave_side: SideSettings {
            stiffness_scale: sfs,
            thickness: sst,
            thickness_scale: sfst,
        },
        master_side: SideSettings {
            stiffness_scale: sfm,
            thickness: mst,
            thickness_scale: sfmt,
        },
        // The scale factors FSF, VSF are applied once the defaults of *CONTROL_CONTACT
        // are known.
        friction: ContactFriction {
            static_coef: fs,
            dynamic: fd,
            decay: dc,
            viscous: vc,
        },
        damping: vdc,
        birth,
        death,
    });
    Ok(())
}

/// The optional cards A, B and C of an automatic contact (any further card is refused).
fn optional_cards(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    if let Some(c) = kw.next() {
        let f = kw.fields(&c, W10);
        match f.int(0, "SOFT", 0)? {
            0 => {}
            v => {
                return Err(f.err(format!(
                    "field SOFT: {v} is not supported (0: the penalty stiffness from the segments' \
                     bulk modulus and size)"
                )));
            }
        }
        f.must_be_zero(2, "LCIDAB")?;
        let maxpar = f.real(3, "MAXPAR", 0.0)?;
        let bsort = f.real(6, "BSORT", 0.0)?;
        if (maxpar != 0.0 && maxpar != 1.025) || bsort != 0.0 {
            r.warnings.push(kw.warning(
                c.line,
                "MAXPAR, BSORT ignored: the bucket sort here runs whenever a node could have come \
                 into reach, so no contact is missed",
            ));
        }
        let frcfrq = f.int(7, "FRCFRQ", 0)?;
        if !(0..=1).contains(&frcfrq) {
            return Err(f.err(format!(
                "field FRCFRQ: {frcfrq} is not supported (forces are updated every cycle)"
            )));
        }
    }
    if let Some(c) = kw.next() {
        let f = kw.fields(&c, W10);
        f.must_be_zero(0, "PENMAX")?;
        f.must_be_zero(1, "THKOPT")?;
        f.must_be_zero(4, "ISYM")?;
        f.must_be_zero(5, "I2D3D")?;
    }
    if let Some(c) = kw.next() {
        let f = kw.fields(&c, W10);
        match f.int(1, "IGNORE", 0)? {
            0..=2 => {}
            v => return Err(f.err(format!("field IGNORE: {v} is not supported (0, 1 or 2)"))),
        }
    }
    if let Some(c) = kw.next() {
        return Err(kw.err(
            c.line,
            "optional cards after card C are not supported (one interface per keyword)",
        ));
    }
    Ok(())
}
