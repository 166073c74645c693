//! Rigid walls and spot welds.

use super::W10;
use crate::error::Result;
use crate::keyword::cards::Fields;
use crate::keyword::reader::{Kw, Reader};
use crate::model::{RigidWall, SpotWeld, WallMethod, WallShape, WeldNodes};

/// The Coulomb coefficient of a wall's FRIC field: 0 <= FRIC < 1 Coulomb, 1 no sliding.
fn friction(g: &Fields<'_>, k: usize) -> Result<f64> {
    let fric = g.real(k, "FRIC", 0.0)?;
    if fric == 1.0 {
        Ok(f64::INFINITY)
    } else if (0.0..1.0).contains(&fric) {
        Ok(fric)
    } else {
        Err(g.err(format!(
            "field FRIC: {fric} is not supported (0 <= FRIC <= 1)"
        )))
    }
}

/// The DEATH field of a wall: blank, 0 or at least 1e20 (never).
fn never_dies(f: &Fields<'_>, k: usize) -> Result<()> {
    let death = f.real(k, "DEATH", 1e20)?;
    if death != 0.0 && death < 1e20 {
        return Err(f.err("field DEATH: a finite death time is not supported"));
    }
    Ok(())
}

/// The id of a definition from its `_ID` card (field `name`, then a heading), or 0.
fn id_card(kw: &mut Kw<'_>, name: &str) -> Result<u64> {
    if !kw.has("ID") {
        return Ok(0);
    }
    let c = kw.take(&format!("the id card {name}"))?;
    kw.fields(&c, W10).id(0, name)
}

/// `*RIGIDWALL_PLANAR` (`_ID`): NSID (0 = all nodes), NSIDEX (0), BOXID (0), OFFSET (0),
/// BIRTH (0), DEATH (never), RWKSF (0 or 1); XT, YT, ZT, XH, YH, ZH, FRIC, WVEL (ignored).
pub(crate) fn planar(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    if !kw.more() {
        return Err(kw.err(kw.line, "a wall needs two cards"));
    }
    while kw.more() {
        let id = id_card(kw, "ID")?;
        let c = kw.take("the card NSID, NSIDEX, BOXID, OFFSET, BIRTH, DEATH")?;
        let f = kw.fields(&c, W10);
        let nsid = f.opt_id(0, "NSID")?;
        f.must_be_zero(1, "NSIDEX")?;
        f.must_be_zero(2, "BOXID")?;
        f.must_be_zero(3, "OFFSET")?;
        f.must_be_zero(4, "BIRTH")?;
        never_dies(&f, 5)?;
        let rwksf = f.real(6, "RWKSF", 0.0)?;
        if rwksf != 0.0 && rwksf != 1.0 {
            return Err(f.err(format!("field RWKSF: {rwksf} is not supported (0 or 1)")));
        }
        let d = kw.take("the card XT, YT, ZT, XH, YH, ZH, FRIC")?;
        let g = kw.fields(&d, W10);
        r.model.walls.push(RigidWall {
            id,
            shape: WallShape::Plane,
            nodes: (nsid != 0).then_some(nsid),
            point: g.real3(0, ["XT", "YT", "ZT"])?,
            head: g.real3(3, ["XH", "YH", "ZH"])?,
            friction: friction(&g, 6)?,
            method: WallMethod::Kinematic,
        });
    }
    Ok(())
}

/// `*RIGIDWALL_GEOMETRIC_CYLINDER` (`_ID`, `_DISPLAY`): NSID, NSIDEX (0), BOXID (0), BIRTH
/// (0), DEATH (never); XT, YT, ZT, XH, YH, ZH, FRIC; RADCYL, LENCYL (0 = infinite), NSEGS
/// (0); with `_DISPLAY` an optional display card PID, RO, E, PR (ignored).
pub(crate) fn cylinder(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let total = kw.remaining();
    let head = 3 + usize::from(kw.has("ID"));
    let (with, without) = (total % (head + 1) == 0, total % head == 0);
    let display = kw.has("DISPLAY") && with;
    if total == 0
        || !(with && kw.has("DISPLAY") || without)
        || (kw.has("DISPLAY") && with && without)
    {
        return Err(kw.err(
            kw.line,
            format!(
                "each cylinder needs {head} cards{}, found {total} (one cylinder per keyword reads without doubt)",
                if kw.has("DISPLAY") { " and may have a display card" } else { "" }
            ),
        ));
    }
    while kw.more() {
        let id = id_card(kw, "ID")?;
        let c = kw.take("the card NSID, NSIDEX, BOXID, BIRTH, DEATH")?;
        let d = kw.take("the card XT, YT, ZT, XH, YH, ZH, FRIC")?;
        let e = kw.take("the card RADCYL, LENCYL, NSEGS")?;
        if display {
            kw.take("the display card PID, RO, E, PR")?;
        }
        let f = kw.fields(&c, W10);
        let nsid = f.opt_id(0, "NSID")?;
        f.must_be_zero(1, "NSIDEX")?;
        f.must_be_zero(2, "BOXID")?;
        f.must_be_zero(3, "BIRTH")?;
        never_dies(&f, 4)?;
        let g = kw.fields(&d, W10);
        let h = kw.fields(&e, W10);
        let radius = h.real(0, "RADCYL", 0.0)?;
        let length = h.real(1, "LENCYL", 0.0)?;
        if !(radius > 0.0) || length < 0.0 {
            return Err(h.err(format!(
                "RADCYL {radius} must be positive and LENCYL {length} non-negative"
            )));
        }
        h.must_be_zero(2, "NSEGS")?;
        r.model.walls.push(RigidWall {
            id,
            shape: WallShape::Cylinder { radius, length },
            nodes: (nsid != 0).then_some(nsid),
            point: g.real3(0, ["XT", "YT", "ZT"])?,
            head: g.real3(3, ["XH", "YH", "ZH"])?,
            friction: friction(&g, 6)?,
            method: WallMethod::Kinematic,
        });
    }
    Ok(())
}

/// A warning when a weld's failure fields say anything but "never": failure forces SN,
/// SS, a failure time below 1e20 or a failure strain below 1e20 (0 and blank are never).
fn never_fails(r: &mut Reader<'_>, kw: &Kw<'_>, line: usize, id: u64, f: &[(&str, f64)]) {
    let said: Vec<String> = f
        .iter()
        .filter(|(name, v)| {
            if name.starts_with('S') || *name == "N" || *name == "M" {
                *v != 0.0
            } else {
                *v != 0.0 && *v < 1e20
            }
        })
        .map(|(n, v)| format!("{n} = {v}"))
        .collect();
    if !said.is_empty() {
        r.warnings.push(kw.warning(
            line,
            format!(
                "spot weld {id}: failure fields ignored ({}): the weld never fails",
                said.join(", ")
            ),
        ));
    }
}

/// `*CONSTRAINED_SPOTWELD` (`_ID`: a WID card ahead of each): N1, N2, SN, SS, N, M, TF, EP.
pub(crate) fn spotweld(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    while kw.more() {
        let id = id_card(kw, "WID")?;
        let c = kw.take("the card N1, N2, SN, SS, N, M, TF, EP")?;
        let f = kw.fields(&c, W10);
        let pair = [f.id(0, "N1")?, f.id(1, "N2")?];
        let vals: Vec<(&str, f64)> = ["SN", "SS", "N", "M", "TF", "EP"]
            .iter()
            .enumerate()
            .map(|(k, n)| Ok((*n, f.real(2 + k, n, 0.0)?)))
            .collect::<Result<_>>()?;
        never_fails(r, kw, c.line, id, &vals);
        r.model.spot_welds.push(SpotWeld {
            id,
            nodes: WeldNodes::Pair(pair),
        });
    }
    Ok(())
}

/// `*CONSTRAINED_GENERALIZED_WELD_SPOT` (`_ID`: a WID card ahead of each): NSID, CID (0),
/// FILTER, WINDOW, NPR, NPRT; TFAIL, EPSF, SN, SS, N, M.
pub(crate) fn generalized_weld(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    while kw.more() {
        let id = id_card(kw, "WID")?;
        let c = kw.take("the card NSID, CID, FILTER, WINDOW, NPR, NPRT")?;
        let f = kw.fields(&c, W10);
        let nsid = f.id(0, "NSID")?;
        f.must_be_zero(1, "CID")?;
        let d = kw.take("the card TFAIL, EPSF, SN, SS, N, M")?;
        let g = kw.fields(&d, W10);
        let vals: Vec<(&str, f64)> = ["TF", "EP", "SN", "SS", "N", "M"]
            .iter()
            .enumerate()
            .map(|(k, n)| Ok((*n, g.real(k, n, 0.0)?)))
            .collect::<Result<_>>()?;
        never_fails(r, kw, d.line, id, &vals);
        r.model.spot_welds.push(SpotWeld {
            id,
            nodes: WeldNodes::Set(nsid),
        });
    }
    Ok(())
}
