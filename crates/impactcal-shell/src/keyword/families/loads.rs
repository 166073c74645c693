//! Initial velocities, constraints, prescribed motions, body loads and damping.

use super::W10;
use crate::error::Result;
use crate::keyword::reader::{Kw, Reader};
use crate::model::{
    BodyLoadZ, InitialVelocity, MotionKind, MotionTarget, NodeTarget, PartStiffnessDamping,
    PrescribedMotion, Spc, VelocityTarget,
};

/// `*INITIAL_VELOCITY`: NSID (0 = all nodes), NSIDEX (0), BOXID (0), IRIGID, ICID (0); VX,
/// VY, VZ, VXR, VYR, VZR.
pub(crate) fn initial_velocity(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let c = kw.take("the card NSID, NSIDEX, BOXID, IRIGID, ICID")?;
    let f = kw.fields(&c, W10);
    let nsid = f.opt_id(0, "NSID")?;
    f.must_be_zero(1, "NSIDEX")?;
    f.must_be_zero(2, "BOXID")?;
    f.must_be_zero(4, "ICID")?;
    let c = kw.take("the velocity card VX, VY, VZ, VXR, VYR, VZR")?;
    let g = kw.fields(&c, W10);
    let target = if nsid == 0 {
        VelocityTarget::All
    } else {
        VelocityTarget::NodeSet(nsid)
    };
    let mut iv = InitialVelocity::translation(target, g.real3(0, ["VX", "VY", "VZ"])?);
    iv.rotation = g.real3(3, ["VXR", "VYR", "VZR"])?;
    r.model.initial_velocities.push(iv);
    Ok(())
}

/// `*INITIAL_VELOCITY_GENERATION`: ID, STYP (1 part set, 2 part, 3 node set), OMEGA, VX,
/// VY, VZ, IVATN (0), ICID (0); XC, YC, ZC, NX, NY, NZ.
pub(crate) fn initial_velocity_generation(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    while let Some(c) = kw.next() {
        let d = kw.take("the card XC, YC, ZC, NX, NY, NZ")?;
        let f = kw.fields(&c, W10);
        let id = f.id(0, "ID")?;
        let target = match f.int(1, "STYP", 0)? {
            1 => VelocityTarget::PartSet(id),
            2 => VelocityTarget::Part(id),
            3 => VelocityTarget::NodeSet(id),
            s => {
                return Err(f.err(format!(
                    "STYP {s} is not supported (1: part set, 2: part, 3: node set)"
                )));
            }
        };
        f.must_be_zero(6, "IVATN")?;
        f.must_be_zero(7, "ICID")?;
        let g = kw.fields(&d, W10);
        let mut iv = InitialVelocity::translation(target, f.real3(3, ["VX", "VY", "VZ"])?);
        iv.omega = f.real(2, "OMEGA", 0.0)?;
        iv.centre = g.real3(0, ["XC", "YC", "ZC"])?;
        iv.axis = g.real3(3, ["NX", "NY", "NZ"])?;
        r.model.initial_velocities.push(iv);
    }
    Ok(())
}

/// `*INITIAL_VELOCITY_NODE`: NID, VX, VY, VZ, VXR, VYR, VZR, ICID (0), one card a node.
pub(crate) fn initial_velocity_node(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    while let Some(c) = kw.next() {
        let f = kw.fields(&c, W10);
        let mut iv = InitialVelocity::translation(
            VelocityTarget::Node(f.id(0, "NID")?),
            f.real3(1, ["VX", "VY", "VZ"])?,
        );
        iv.rotation = f.real3(4, ["VXR", "VYR", "VZR"])?;
        f.must_be_zero(7, "ICID")?;
        r.model.initial_velocities.push(iv);
    }
    Ok(())
}

/// `*BOUNDARY_SPC_NODE` / `_SET` (`_ID`: one id card, then the constrained nodes or sets):
/// NID or NSID, CID (0), DOFX, DOFY, DOFZ, DOFRX, DOFRY, DOFRZ (0 or 1).
pub(crate) fn spc(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    if kw.has("ID") {
        kw.take("the id card ID, HEADING")?;
    }
    let set = kw.ctx.keyword.contains("_SET");
    while let Some(c) = kw.next() {
        let f = kw.fields(&c, W10);
        let id = f.id(0, if set { "NSID" } else { "NID" })?;
        f.must_be_zero(1, "CID")?;
        let mut dofs = [false; 6];
        for (k, nm) in ["DOFX", "DOFY", "DOFZ", "DOFRX", "DOFRY", "DOFRZ"]
            .iter()
            .enumerate()
        {
            dofs[k] = match f.int(2 + k, nm, 0)? {
                0 => false,
                1 => true,
                v => return Err(f.err(format!("field {nm}: must be 0 or 1, got {v}"))),
            };
        }
        let target = if set {
            NodeTarget::NodeSet(id)
        } else {
            NodeTarget::Node(id)
        };
        r.model.spcs.push(Spc { target, dofs });
    }
    Ok(())
}

/// `*BOUNDARY_PRESCRIBED_MOTION_NODE|SET|RIGID` (`_ID`: an id card ahead of each): NID,
/// NSID or PID, DOF (1-3 translations x, y, z; 5-7 rotations about x, y, z), VAD (0
/// velocity, 1 acceleration, 2 displacement; rotations of nodes: 0 or 1), LCID, SF (default
/// 1), VID (0), DEATH (default 1e28), BIRTH.
pub(crate) fn prescribed(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let kind_of = kw.ctx.keyword.clone();
    while kw.more() {
        if kw.has("ID") {
            kw.take("the id card ID, HEADING")?;
        }
        let c = kw.take("the card TYPEID, DOF, VAD, LCID, SF, VID, DEATH, BIRTH")?;
        let f = kw.fields(&c, W10);
        let (target, rigid) = if kind_of.contains("_RIGID") {
            (MotionTarget::Rigid(f.id(0, "PID")?), true)
        } else if kind_of.contains("_SET") {
            (MotionTarget::NodeSet(f.id(0, "NSID")?), false)
        } else {
            (MotionTarget::Node(f.id(0, "NID")?), false)
        };
        let dof = match f.int(1, "DOF", 0)? {
            d @ 1..=3 => (d - 1) as usize,
            d @ 5..=7 => (d - 2) as usize,
            d => {
                return Err(f.err(format!(
                    "field DOF: {d} is not supported (1-3 translations x, y, z; 5-7 rotations)"
                )));
            }
        };
        let kind = match f.int(2, "VAD", 0)? {
            0 => MotionKind::Velocity,
            1 => MotionKind::Acceleration,
            2 if dof < 3 => MotionKind::Displacement,
            2 => {
                return Err(f.err(format!(
                    "field VAD: a prescribed rotation angle is not supported{}",
                    if rigid {
                        ""
                    } else {
                        " (nodes carry no rotation)"
                    }
                )));
            }
            v => {
                return Err(f.err(format!(
                    "field VAD: {v} is not supported (0 velocity, 1 acceleration, 2 displacement)"
                )));
            }
        };
        let curve = f.id(3, "LCID")?;
        let scale = f.real(4, "SF", 1.0)?;
        f.must_be_zero(5, "VID")?;
        let death = f.real(6, "DEATH", 1e28)?;
        let death = if death == 0.0 { 1e28 } else { death };
        let birth = f.real(7, "BIRTH", 0.0)?;
        r.model.prescribed.push(PrescribedMotion {
            target,
            dof,
            kind,
            curve,
            scale: if scale == 0.0 { 1.0 } else { scale },
            birth,
            death,
        });
    }
    Ok(())
}

/// `*LOAD_BODY_Z`: LCID, SF (default 1), LCIDDR (0), XC-ZC (ignored), CID (0).
pub(crate) fn load_body_z(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let c = kw.take("the card LCID, SF, LCIDDR, ...")?;
    let f = kw.fields(&c, W10);
    let curve = f.id(0, "LCID")?;
    let scale = f.real(1, "SF", 1.0)?;
    f.must_be_zero(2, "LCIDDR")?;
    f.must_be_zero(6, "CID")?;
    r.model.body_load_z = Some(BodyLoadZ { curve, scale });
    Ok(())
}

/// `*DAMPING_GLOBAL`: LCID (0), VALDMP, STX-SRZ (blank or 1).
pub(crate) fn damping_global(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let c = kw.take("the card LCID, VALDMP, STX-SRZ")?;
    let f = kw.fields(&c, W10);
    f.must_be_zero(0, "LCID")?;
    r.model.damping = f.real(1, "VALDMP", 0.0)?;
    let s: Vec<f64> = (2..8)
        .map(|k| f.real(k, "STX-SRZ", 0.0))
        .collect::<Result<_>>()?;
    if s.iter().any(|&v| v != 0.0) && s[..3].iter().any(|&v| v != 1.0) {
        return Err(f.err("direction scale factors STX..SRZ are not supported"));
    }
    Ok(())
}

/// `*DAMPING_PART_STIFFNESS` (`_SET`: a part set, given to every part of it): PID or PSID,
/// COEF, one card each.
pub(crate) fn damping_part_stiffness(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let set = kw.has("SET");
    while let Some(c) = kw.next() {
        let f = kw.fields(&c, W10);
        let id = f.id(0, if set { "PSID" } else { "PID" })?;
        let coef = f.real(1, "COEF", 0.0)?;
        let parts = if set {
            r.model
                .part_sets
                .iter()
                .find(|s| s.id == id)
                .map(|s| s.parts.clone())
                .ok_or_else(|| f.err(format!("part set {id} is not defined above this card")))?
        } else {
            vec![id]
        };
        for part in parts {
            r.model
                .stiffness_damping
                .push(PartStiffnessDamping { part, coef });
        }
    }
    Ok(())
}
