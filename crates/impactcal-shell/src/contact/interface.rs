//! A contact interface in solver form: its nodes, its segments with their thickness and
//! penalty stiffness, and which nodes are checked against which segments.

use std::collections::HashMap;

use super::{Contact, ContactControl, ContactFriction, ContactKind, ContactSurface, SideSettings};
use crate::error::{Result, ShellError};
use crate::geometry::{dot, norm, sub};
use crate::model::ShellModel;
use crate::setup::Elem;

/// The side bit of the slave surface's segments.
pub(crate) const SLAVE: u8 = 1;
/// The side bit of the master surface's segments.
pub(crate) const MASTER: u8 = 2;

/// A contact interface ready for the solver. Node indices inside it are local: `nodes`
/// maps them to the model's node indices.
#[derive(Debug, Clone)]
pub(crate) struct Interface {
    /// The interface's id in outputs.
    pub id: u64,
    /// The model index of each local node (every node of a segment or checked), ascending.
    pub nodes: Vec<u32>,
    /// The rigid body of each local node (`usize::MAX`: none).
    pub body: Vec<usize>,
    /// True for a local node on the slave side (the side whose resultant force is
    /// reported): a node checked against master segments or a corner of a slave segment;
    /// every node of a single-surface contact.
    pub on_slave: Vec<bool>,
    /// The local nodes checked against segments.
    pub slaves: Vec<u32>,
    /// Half the contact thickness of each checked node.
    pub slave_half: Vec<f64>,
    /// Penalty stiffness of each checked node (`f64::INFINITY`: the segment's governs).
    pub slave_k: Vec<f64>,
    /// The side bits of the segments each checked node is checked against.
    pub slave_checks: Vec<u8>,
    /// Segment corners (local nodes); a triangle repeats its third corner.
    pub segs: Vec<[u32; 4]>,
    /// True for a triangular segment.
    pub seg_tri: Vec<bool>,
    /// Half the contact thickness of each segment.
    pub seg_half: Vec<f64>,
    /// Penalty stiffness of each segment.
    pub seg_k: Vec<f64>,
    /// The side bits of each segment.
    pub seg_side: Vec<u8>,
    /// Initial area of each segment (for the viscous friction limit).
    pub seg_area: Vec<f64>,
    /// The largest half thickness of a checked node.
    pub max_half: f64,
    /// Search margin: the candidate lists hold every pair within it, and stay valid while
    /// no node moves more than half of it relative to the interface's mean motion.
    pub margin: f64,
    /// Friction.
    pub friction: ContactFriction,
    /// Normal damping as a fraction of critical (VDC / 100).
    pub damping: f64,
    /// Active from `birth` to `death`.
    pub birth: f64,
    pub death: f64,
}

impl Interface {
    /// The number of corners of segment `s`.
    pub fn corners(&self, s: usize) -> usize {
        if self.seg_tri[s] { 3 } else { 4 }
    }
}

/// What the interfaces are built from: the validated model pieces of the set-up.
pub(crate) struct Model<'a> {
    pub model: &'a ShellModel,
    pub node_map: &'a HashMap<u64, usize>,
    pub part_map: &'a HashMap<u64, usize>,
    pub elems: &'a [Elem],
    /// Per element: thickness, bulk modulus (from its material), and whether it is rigid.
    pub elem_t: Vec<f64>,
    pub elem_bulk: Vec<f64>,
    pub x0: &'a [[f64; 3]],
    pub mass: &'a [f64],
    pub body_of: &'a [usize],
}

/// A shell as a segment of one surface, with its contact thickness and stiffness.
struct SegDef {
    elem: usize,
    side: u8,
    half: f64,
    k: f64,
    area: f64,
}

/// Builds the solver form of every contact interface of the model.
///
/// # Errors
/// [`ShellError::Reference`] for an undefined part, part set or node set, and
/// [`ShellError::Value`] for a surface that is not allowed on its side (a node set as a
/// master, a single-surface contact over a node set), out-of-range settings (negative
/// friction, damping outside 0 to 100, a non-positive scale factor, negative thickness,
/// death before birth), an empty surface, or a penalty scale factor that is not positive.
pub(crate) fn compile(m: &Model<'_>, control: &ContactControl) -> Result<Vec<Interface>> {
    let contacts = &m.model.contacts;
    if !contacts.is_empty() && !positive(control.penalty_scale) {
        return Err(ShellError::value(
            "contact penalty scale factor (SLSFAC)",
            format!("must be finite and positive, got {}", control.penalty_scale),
        ));
    }
    let mut out = Vec::with_capacity(contacts.len());
    let mut ids: Vec<u64> = Vec::with_capacity(contacts.len());
    for (k, c) in contacts.iter().enumerate() {
        let id = if c.id > 0 { c.id } else { k as u64 + 1 };
        if ids.contains(&id) {
            return Err(ShellError::Reference {
                what: "contact interface",
                id,
                message: "defined more than once (interfaces without an id take their position)"
                    .into(),
            });
        }
        ids.push(id);
        out.push(build(m, control, c, id)?);
    }
    Ok(out)
}

/// True for a finite value above zero.
fn positive(v: f64) -> bool {
    v > 0.0 && v.is_finite()
}

fn check_settings(c: &Contact, by: &str) -> Result<()> {
    let f = c.friction;
    for (name, v) in [
        ("static friction FS", f.static_coef),
        ("dynamic friction FD", f.dynamic),
        ("friction decay DC", f.decay),
        ("viscous friction VC", f.viscous),
    ] {
        if !(v >= 0.0 && v.is_finite()) {
            return Err(ShellError::value(
                by,
                format!("{name} must be finite and >= 0, got {v}"),
            ));
        }
    }
    if !(0.0..=100.0).contains(&c.damping) {
        return Err(ShellError::value(
            by,
            format!(
                "damping VDC must lie in [0, 100] percent of critical, got {}",
                c.damping
            ),
        ));
    }
    for (side, s) in [("slave", c.slave_side), ("master", c.master_side)] {
        let valid = positive(s.stiffness_scale)
            && positive(s.thickness_scale)
            && s.thickness >= 0.0
            && s.thickness.is_finite();
        if !valid {
            return Err(ShellError::value(
                by,
                format!(
                    "{side} side: stiffness scale {} and thickness scale {} must be positive, thickness {} >= 0",
                    s.stiffness_scale, s.thickness_scale, s.thickness
                ),
            ));
        }
    }
    if !(c.birth.is_finite() && c.death > c.birth) {
        return Err(ShellError::value(
            by,
            format!(
                "death time {} must come after birth time {}",
                c.death, c.birth
            ),
        ));
    }
    Ok(())
}

/// The elements of a surface (`None` for a node set).
fn surface_elems(m: &Model<'_>, s: ContactSurface, by: &str) -> Result<Option<Vec<usize>>> {
    let parts: Vec<usize> = match s {
        ContactSurface::NodeSet(_) => return Ok(None),
        ContactSurface::All => return Ok(Some((0..m.elems.len()).collect())),
        ContactSurface::Part(p) => vec![lookup(m.part_map, p, "part", by)?],
        ContactSurface::PartSet(id) => {
            let set = m
                .model
                .part_sets
                .iter()
                .find(|s| s.id == id)
                .ok_or_else(|| ShellError::Reference {
                    what: "part set",
                    id,
                    message: format!("referenced by {by} but not defined"),
                })?;
            set.parts
                .iter()
                .map(|&p| lookup(m.part_map, p, "part", &format!("part set {id}")))
                .collect::<Result<_>>()?
        }
    };
    Ok(Some(
        (0..m.elems.len())
            .filter(|&e| parts.contains(&(m.elems[e].part as usize)))
            .collect(),
    ))
}

fn lookup(map: &HashMap<u64, usize>, id: u64, what: &'static str, by: &str) -> Result<usize> {
    map.get(&id).copied().ok_or_else(|| ShellError::Reference {
        what,
        id,
        message: format!("referenced by {by} but not defined"),
    })
}

/// The corners of element `e` (3 or 4 model node indices).
fn corners<'a>(m: &'a Model<'_>, e: usize) -> &'a [u32] {
    let el = &m.elems[e];
    &el.nodes[..if el.tri { 3 } else { 4 }]
}

/// Area, longest diagonal (longest side for a triangle) and shortest edge of element `e`
/// on the initial geometry.
fn measures(m: &Model<'_>, e: usize) -> (f64, f64, f64) {
    let c = corners(m, e);
    let x: Vec<[f64; 3]> = c.iter().map(|&i| m.x0[i as usize]).collect();
    let n = x.len();
    let edges: Vec<f64> = (0..n).map(|k| norm(sub(x[(k + 1) % n], x[k]))).collect();
    let shortest = edges.iter().copied().fold(f64::INFINITY, f64::min);
    let reach = if n == 3 {
        edges.iter().copied().fold(0.0, f64::max)
    } else {
        norm(sub(x[2], x[0])).max(norm(sub(x[3], x[1])))
    };
    (crate::geometry::polygon_area(&x), reach, shortest)
}

/// A surface's segments: each element's contact half thickness (its thickness times the
/// side's scale, or the side's thickness; in a single-surface contact without a given
/// thickness at most 0.4 of the shortest edge) and stiffness `SLSFAC SF K A / D`.
fn segments(
    m: &Model<'_>,
    elems: &[usize],
    side: u8,
    s: SideSettings,
    single: bool,
    control: &ContactControl,
) -> Vec<SegDef> {
    let (slsfac, full) = (control.penalty_scale, control.full_thickness);
    elems
        .iter()
        .map(|&e| {
            let (area, reach, shortest) = measures(m, e);
            let mut t = if s.thickness > 0.0 {
                s.thickness
            } else {
                m.elem_t[e] * s.thickness_scale
            };
            if single && s.thickness == 0.0 && !full {
                t = t.min(0.4 * shortest);
            }
            SegDef {
                elem: e,
                side,
                half: 0.5 * t,
                k: slsfac * s.stiffness_scale * m.elem_bulk[e] * area / reach,
                area,
            }
        })
        .collect()
}

fn build(m: &Model<'_>, control: &ContactControl, c: &Contact, id: u64) -> Result<Interface> {
    let by = format!("contact interface {id}");
    check_settings(c, &by)?;
    let nn = m.x0.len();
    let single = c.kind == ContactKind::SingleSurface;
    let slave_elems = surface_elems(m, c.slave, &by)?;
    let master_elems = if single {
        None
    } else {
        if matches!(c.master, ContactSurface::NodeSet(_)) {
            return Err(ShellError::value(
                &by,
                "a master surface must be made of shells (a part, a part set or all), not a node set",
            ));
        }
        surface_elems(m, c.master, &by)?
    };
    if slave_elems.is_none() && c.kind != ContactKind::NodesToSurface {
        return Err(ShellError::value(
            &by,
            "a node set can only be the slave side of a nodes-to-surface contact",
        ));
    }
    // Segments: the slave surface's (single surface, surface to surface), the master's.
    let mut defs: Vec<SegDef> = Vec::new();
    if c.kind != ContactKind::NodesToSurface
        && let Some(el) = &slave_elems
    {
        defs.extend(segments(m, el, SLAVE, c.slave_side, single, control));
    }
    if let Some(el) = &master_elems {
        let master = segments(m, el, MASTER, c.master_side, false, control);
        for d in master {
            match defs.iter_mut().find(|s| s.elem == d.elem) {
                Some(s) => s.side |= MASTER,
                None => defs.push(d),
            }
        }
    }
    defs.sort_by_key(|d| d.elem);
    if defs.is_empty() {
        return Err(ShellError::value(
            &by,
            "has no segments (its surfaces hold no shells)",
        ));
    }
    // Checked nodes and the sides they are checked against, with thickness and stiffness
    // from the shells of their own surface.
    let mut checks = vec![0u8; nn];
    let mut half = vec![0.0f64; nn];
    let mut k_sum = vec![0.0f64; nn];
    let mut k_n = vec![0u32; nn];
    let mut own = |elems: &[usize], settings: SideSettings, check: u8, single: bool| {
        for d in segments(m, elems, 0, settings, single, control) {
            for &i in corners(m, d.elem) {
                let i = i as usize;
                checks[i] |= check;
                half[i] = half[i].max(d.half);
                k_sum[i] += d.k;
                k_n[i] += 1;
            }
        }
    };
    match c.kind {
        ContactKind::SingleSurface => {
            if let Some(el) = &slave_elems {
                own(el, c.slave_side, SLAVE, true);
            }
        }
        ContactKind::SurfaceToSurface => {
            if let Some(el) = &slave_elems {
                own(el, c.slave_side, MASTER, false);
            }
            if let Some(el) = &master_elems {
                own(el, c.master_side, SLAVE, false);
            }
        }
        ContactKind::NodesToSurface => match (&slave_elems, c.slave) {
            (Some(el), _) => own(el, c.slave_side, MASTER, false),
            (None, ContactSurface::NodeSet(sid)) => {
                let set = m
                    .model
                    .node_sets
                    .iter()
                    .find(|s| s.id == sid)
                    .ok_or_else(|| ShellError::Reference {
                        what: "node set",
                        id: sid,
                        message: format!("referenced by {by} but not defined"),
                    })?;
                let mut on_set = vec![false; nn];
                for &n in &set.nodes {
                    let i = lookup(m.node_map, n, "node", &format!("node set {sid}"))?;
                    on_set[i] = true;
                }
                // Thickness and stiffness from every shell holding a node of the set.
                let all: Vec<usize> = (0..m.elems.len())
                    .filter(|&e| corners(m, e).iter().any(|&i| on_set[i as usize]))
                    .collect();
                own(&all, c.slave_side, 0, false);
                for i in 0..nn {
                    if on_set[i] {
                        checks[i] |= MASTER;
                    }
                }
            }
            (None, _) => {
                return Err(ShellError::value(
                    &by,
                    "the slave side is neither shells nor a node set",
                ));
            }
        },
    }
    // Local numbering: every node of a segment or checked, ascending.
    let mut local = vec![u32::MAX; nn];
    for d in &defs {
        for &i in corners(m, d.elem) {
            local[i as usize] = 0;
        }
    }
    for i in 0..nn {
        if checks[i] != 0 && m.mass[i] > 0.0 {
            local[i] = 0;
        }
    }
    let nodes: Vec<u32> = (0..nn as u32).filter(|&i| local[i as usize] == 0).collect();
    for (l, &i) in nodes.iter().enumerate() {
        local[i as usize] = l as u32;
    }
    let mut slaves = Vec::new();
    let mut slave_half = Vec::new();
    let mut slave_k = Vec::new();
    let mut slave_checks = Vec::new();
    for &i in &nodes {
        let i = i as usize;
        if checks[i] == 0 || m.mass[i] <= 0.0 {
            continue;
        }
        slaves.push(local[i]);
        slave_half.push(half[i]);
        slave_k.push(if k_n[i] > 0 {
            k_sum[i] / f64::from(k_n[i])
        } else {
            f64::INFINITY
        });
        slave_checks.push(checks[i]);
    }
    if slaves.is_empty() {
        return Err(ShellError::value(&by, "has no nodes to check"));
    }
    let mut segs = Vec::with_capacity(defs.len());
    let mut seg_tri = Vec::with_capacity(defs.len());
    for d in &defs {
        let el = &m.elems[d.elem];
        segs.push(el.nodes.map(|i| local[i as usize]));
        seg_tri.push(el.tri);
    }
    let mut on_slave: Vec<bool> = nodes
        .iter()
        .map(|&i| single || checks[i as usize] & MASTER != 0)
        .collect();
    if c.kind == ContactKind::SurfaceToSurface {
        for (d, seg) in defs.iter().zip(&segs) {
            if d.side & SLAVE != 0 {
                for &l in &seg[..if m.elems[d.elem].tri { 3 } else { 4 }] {
                    on_slave[l as usize] = true;
                }
            }
        }
    }
    let max_half = slave_half.iter().copied().fold(0.0, f64::max);
    let mean_size = defs.iter().map(|d| d.area.sqrt()).sum::<f64>() / defs.len() as f64;
    let max_seg_half = defs.iter().map(|d| d.half).fold(0.0, f64::max);
    Ok(Interface {
        id,
        body: nodes.iter().map(|&i| m.body_of[i as usize]).collect(),
        on_slave,
        nodes,
        slaves,
        slave_half,
        slave_k,
        slave_checks,
        segs,
        seg_tri,
        seg_half: defs.iter().map(|d| d.half).collect(),
        seg_k: defs.iter().map(|d| d.k).collect(),
        seg_side: defs.iter().map(|d| d.side).collect(),
        seg_area: defs.iter().map(|d| d.area).collect(),
        max_half,
        margin: (0.5 * mean_size).max(2.0 * (max_half + max_seg_half)),
        friction: c.friction,
        damping: c.damping / 100.0,
        birth: c.birth,
        death: c.death,
    })
}

/// The unit normal of a segment's mid-surface (the cross product of its diagonals, or of
/// two edges for a triangle), `None` when it has no area.
pub(crate) fn segment_normal(x: &[[f64; 3]; 4], tri: bool) -> Option<[f64; 3]> {
    let (a, b) = if tri {
        (sub(x[1], x[0]), sub(x[2], x[0]))
    } else {
        (sub(x[2], x[0]), sub(x[3], x[1]))
    };
    let n = crate::geometry::cross(a, b);
    let l = dot(n, n).sqrt();
    (l > 0.0).then(|| [n[0] / l, n[1] / l, n[2] / l])
}
