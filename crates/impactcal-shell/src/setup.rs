//! Validation of a [`ShellModel`] and its translation into the solver's indexed form.

use std::collections::HashMap;

use crate::element::{self, ElementFault, PartProps};
use crate::error::{Result, ShellError};
use crate::geometry::{dot, norm, sub};
use crate::model::{
    Curve, MaterialLaw, MotionKind, MotionTarget, NodeTarget, Section, ShellModel, VelocityTarget,
    WallMethod, WallShape, WeldNodes,
};
use crate::rigid::{RigidDef, rigid_bodies};
use crate::validate::{check_hourglass, check_material, check_section, non_negative, positive};

/// An element in solver form: node indices, triangle flag, part index and the index of its
/// constants in `Compiled::props` (the part's, or its own for an element with its own
/// thickness).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Elem {
    pub nodes: [u32; 4],
    pub tri: bool,
    pub part: u32,
    pub props: u32,
}

/// A rigid wall in solver form: its id, shape, nodes, a point of it (the tail), its unit
/// normal (plane) or axis (cylinder).
#[derive(Debug, Clone)]
pub(crate) struct Wall {
    pub id: u64,
    pub shape: WallShape,
    pub nodes: Vec<u32>,
    pub point: [f64; 3],
    pub normal: [f64; 3],
    pub mu: f64,
    pub method: WallMethod,
}

/// What a prescribed motion drives in solver form.
#[derive(Debug, Clone)]
pub(crate) enum DriveTarget {
    /// Node indices.
    Nodes(Vec<u32>),
    /// A rigid body index.
    Body(usize),
}

/// A prescribed motion in solver form.
#[derive(Debug, Clone)]
pub(crate) struct Drive {
    pub target: DriveTarget,
    pub dof: usize,
    pub kind: MotionKind,
    pub curve: Curve,
    pub scale: f64,
    pub birth: f64,
    pub death: f64,
}

/// Everything the solver needs, validated.
pub(crate) struct Compiled {
    pub node_ids: Vec<u64>,
    pub x0: Vec<[f64; 3]>,
    pub elem_ids: Vec<u64>,
    pub elems: Vec<Elem>,
    /// Element constants: one per part, then one per element with its own thickness.
    pub parts: Vec<PartProps>,
    pub part_ids: Vec<u64>,
    pub rigid: Vec<RigidDef>,
    pub drives: Vec<Drive>,
    pub mass: Vec<f64>,
    pub inertia: Vec<f64>,
    pub fixed: Vec<(u32, [bool; 6])>,
    pub walls: Vec<Wall>,
    pub contacts: Vec<crate::contact::Interface>,
    pub v0: Vec<[f64; 3]>,
    pub w0: Vec<[f64; 3]>,
    pub history: Vec<u32>,
}

fn unique<T>(
    items: &[T],
    id: impl Fn(&T) -> u64,
    what: &'static str,
) -> Result<HashMap<u64, usize>> {
    let mut map = HashMap::with_capacity(items.len());
    for (i, it) in items.iter().enumerate() {
        if map.insert(id(it), i).is_some() {
            return Err(ShellError::Reference {
                what,
                id: id(it),
                message: "defined more than once".into(),
            });
        }
    }
    Ok(map)
}

fn lookup(map: &HashMap<u64, usize>, id: u64, what: &'static str, by: &str) -> Result<usize> {
    map.get(&id).copied().ok_or_else(|| ShellError::Reference {
        what,
        id,
        message: format!("referenced by {by} but not defined"),
    })
}

/// Validates `model` and builds the solver's form.
pub(crate) fn compile(model: &ShellModel) -> Result<Compiled> {
    let node_map = unique(&model.nodes, |n| n.id, "node")?;
    let part_map = unique(&model.parts, |p| p.id, "part")?;
    let sec_map = unique(&model.sections, |s| s.id, "section")?;
    let mat_map = unique(&model.materials, |m| m.id, "material")?;
    let set_map = unique(&model.node_sets, |s| s.id, "node set")?;
    let curve_map = unique(&model.curves, |c| c.id, "curve")?;
    unique(&model.shells, |s| s.id, "shell")?;
    if model.shells.is_empty() {
        return Err(ShellError::value("model", "has no shell elements"));
    }
    for n in &model.nodes {
        if n.x.iter().any(|c| !c.is_finite()) {
            return Err(ShellError::value(
                format!("node {}", n.id),
                "non-finite coordinate",
            ));
        }
    }

    // Materials and sections (every one, referenced or not).
    for m in &model.materials {
        check_material(m)?;
    }
    // A section of thickness 0 serves shells that give their own thickness
    // (*ELEMENT_SHELL_THICKNESS); its other fields are checked here, and a shell that
    // takes its thickness from it is an error below.
    let placeholder = |s: &Section| Section {
        thickness: if s.thickness == 0.0 { 1.0 } else { s.thickness },
        ..*s
    };
    for s in &model.sections {
        check_section(&placeholder(s))?;
    }
    let hg = &model.hourglass;
    check_hourglass(hg)?;
    let hg_map = unique(&model.hourglass_defs, |h| h.id, "hourglass definition")?;
    for h in &model.hourglass_defs {
        check_hourglass(&h.hourglass)?;
    }
    let mut parts = Vec::with_capacity(model.parts.len());
    let mut part_sections = Vec::with_capacity(model.parts.len());
    for p in &model.parts {
        let by = format!("part {}", p.id);
        let sec = &model.sections[lookup(&sec_map, p.section, "section", &by)?];
        let mat = &model.materials[lookup(&mat_map, p.material, "material", &by)?];
        let hg = match p.hourglass {
            0 => hg,
            h => &model.hourglass_defs[lookup(&hg_map, h, "hourglass definition", &by)?].hourglass,
        };
        let mut props = PartProps::new(&placeholder(sec), mat, hg)?;
        if let MaterialLaw::PlasticCurve { hardening, .. } = mat.law {
            let points = crate::material::hardening_points(hardening, &model.curves)
                .map_err(|m| ShellError::value(format!("material {}, hardening", mat.id), m))?;
            props = props.with_hardening(points)?;
        }
        parts.push(props);
        part_sections.push(*sec);
    }
    if let Some(b) = model.bulk_viscosity {
        for (name, v) in [("Q1", b.q1), ("Q2", b.q2)] {
            non_negative(format!("bulk viscosity {name}"), v)?;
        }
        for p in &mut parts {
            p.bulk = [b.q1, b.q2];
        }
    }
    let mut damped = vec![false; parts.len()];
    for d in &model.stiffness_damping {
        let by = "*DAMPING_PART_STIFFNESS";
        let k = lookup(&part_map, d.part, "part", by)?;
        if !d.coef.is_finite() {
            return Err(ShellError::value(
                format!("stiffness damping of part {}", d.part),
                format!("coefficient must be finite, got {}", d.coef),
            ));
        }
        if std::mem::replace(&mut damped[k], true) {
            return Err(ShellError::Reference {
                what: "part",
                id: d.part,
                message: "has stiffness damping defined more than once".into(),
            });
        }
        parts[k].stiffness_damping = d.coef;
    }

    // Elements with their own thickness.
    let own_thickness = unique(&model.element_thickness, |t| t.shell, "element thickness")?;
    let shell_ids = unique(&model.shells, |s| s.id, "shell")?;
    for t in &model.element_thickness {
        lookup(&shell_ids, t.shell, "shell", "*ELEMENT_SHELL_THICKNESS")?;
    }

    // Elements, masses, inertias.
    let nn = model.nodes.len();
    let x0: Vec<[f64; 3]> = model.nodes.iter().map(|n| n.x).collect();
    let mut mass = vec![0.0; nn];
    let mut inertia = vec![0.0; nn];
    let mut elems = Vec::with_capacity(model.shells.len());
    for s in &model.shells {
        let by = format!("shell {}", s.id);
        let part = lookup(&part_map, s.part, "part", &by)?;
        let mut idx = [0u32; 4];
        for k in 0..4 {
            idx[k] = lookup(&node_map, s.nodes[k], "node", &by)? as u32;
        }
        let tri = s.is_triangle();
        let distinct = if tri { 3 } else { 4 };
        for a in 0..distinct {
            for b in (a + 1)..distinct {
                if idx[a] == idx[b] {
                    return Err(ShellError::Element {
                        element: s.id,
                        message: format!("node {} appears twice", s.nodes[a]),
                    });
                }
            }
        }
        let xs: Vec<[f64; 3]> = idx[..distinct].iter().map(|&i| x0[i as usize]).collect();
        let area = element::signed_area(&xs, tri).map_err(|f| ShellError::Element {
            element: s.id,
            message: match f {
                ElementFault::Degenerate => {
                    "degenerate geometry (zero area or collinear nodes)".into()
                }
                ElementFault::Inverted => {
                    "inverted or non-convex geometry (check the node order)".into()
                }
            },
        })?;
        let props = match own_thickness.get(&s.id) {
            None if part_sections[part].thickness == 0.0 => {
                return Err(ShellError::value(
                    format!("shell {}, thickness", s.id),
                    format!(
                        "its section {} has thickness 0 and the shell gives none (*ELEMENT_SHELL_THICKNESS)",
                        part_sections[part].id
                    ),
                ));
            }
            None => part,
            Some(&k) => {
                let sec: Section = part_sections[part];
                let nodal = model.element_thickness[k].nodal;
                let t = nodal[..distinct]
                    .iter()
                    .map(|&v| if v == 0.0 { sec.thickness } else { v })
                    .sum::<f64>()
                    / distinct as f64;
                let pp = parts[part].with_thickness(t, &sec).map_err(|_| {
                    ShellError::value(
                        format!("shell {}, thickness", s.id),
                        format!("must be positive, got {t}"),
                    )
                })?;
                parts.push(pp);
                parts.len() - 1
            }
        };
        let pp = &parts[props];
        let m = pp.mat.rho * pp.t * area / distinct as f64;
        let inr = m * (pp.t * pp.t / 12.0).max(area / 8.0);
        for &i in &idx[..distinct] {
            mass[i as usize] += m;
            inertia[i as usize] += inr;
        }
        elems.push(Elem {
            nodes: idx,
            tri,
            part: part as u32,
            props: props as u32,
        });
    }
    for pm in &model.masses {
        let i = lookup(
            &node_map,
            pm.node,
            "node",
            &format!("mass element {}", pm.id),
        )?;
        non_negative(format!("mass element {}, mass", pm.id), pm.mass)?;
        mass[i] += pm.mass;
    }

    let set_nodes = |sid: u64, by: &str| -> Result<Vec<u32>> {
        let set = &model.node_sets[lookup(&set_map, sid, "node set", by)?];
        set.nodes
            .iter()
            .map(|&n| lookup(&node_map, n, "node", &format!("node set {sid}")).map(|i| i as u32))
            .collect()
    };

    // Rigid bodies: rigid parts and spot welds, joined where they share nodes.
    let mut groups: Vec<(Vec<u32>, Option<usize>)> = Vec::new();
    for (k, p) in model.parts.iter().enumerate() {
        let mat = &model.materials[lookup(&mat_map, p.material, "material", "a part")?];
        if matches!(mat.law, MaterialLaw::Rigid { .. }) {
            parts[k].rigid = true;
            let mut on = vec![false; nn];
            for e in elems.iter().filter(|e| e.part as usize == k) {
                for &n in &e.nodes {
                    on[n as usize] = true;
                }
            }
            groups.push((
                (0..nn as u32).filter(|&i| on[i as usize]).collect(),
                Some(k),
            ));
        }
    }
    for e in &mut elems {
        if parts[e.part as usize].rigid {
            parts[e.props as usize].rigid = true;
        }
    }
    for (k, w) in model.spot_welds.iter().enumerate() {
        let by = format!("spot weld {}", if w.id > 0 { w.id } else { k as u64 + 1 });
        let nodes = match w.nodes {
            WeldNodes::Pair(p) => p
                .iter()
                .map(|&n| lookup(&node_map, n, "node", &by).map(|i| i as u32))
                .collect::<Result<Vec<_>>>()?,
            WeldNodes::Set(s) => set_nodes(s, &by)?,
        };
        if nodes.len() < 2 {
            return Err(ShellError::value(by, "welds fewer than 2 nodes"));
        }
        groups.push((nodes, None));
    }
    let rigid = rigid_bodies(model, &groups, &x0, &mass, &inertia)?;
    let mut body_of = vec![usize::MAX; nn];
    for (b, body) in rigid.iter().enumerate() {
        for &i in &body.nodes {
            body_of[i as usize] = b;
        }
    }

    // Constraints.
    let mut fixed_mask = vec![[false; 6]; nn];
    for (k, spc) in model.spcs.iter().enumerate() {
        let by = format!("constraint {}", k + 1);
        let nodes = match spc.target {
            NodeTarget::Node(n) => vec![lookup(&node_map, n, "node", &by)? as u32],
            NodeTarget::NodeSet(s) => set_nodes(s, &by)?,
        };
        for i in nodes {
            if body_of[i as usize] != usize::MAX && spc.dofs.iter().any(|&d| d) {
                return Err(ShellError::value(
                    by,
                    format!(
                        "node {} moves with a rigid body: hold the body with *MAT_RIGID CMO, CON1, CON2 or a prescribed motion",
                        model.nodes[i as usize].id
                    ),
                ));
            }
            for d in 0..6 {
                fixed_mask[i as usize][d] |= spc.dofs[d];
            }
        }
    }
    // Nodes without mass (not attached to anything) are held fixed.
    for i in 0..nn {
        if body_of[i] != usize::MAX {
            continue;
        }
        if mass[i] <= 0.0 {
            fixed_mask[i] = [true; 6];
        } else if inertia[i] <= 0.0 {
            fixed_mask[i][3] = true;
            fixed_mask[i][4] = true;
            fixed_mask[i][5] = true;
        }
    }
    let fixed: Vec<(u32, [bool; 6])> = fixed_mask
        .iter()
        .enumerate()
        .filter(|(_, m)| m.iter().any(|&b| b))
        .map(|(i, m)| (i as u32, *m))
        .collect();

    // Initial velocities.
    let mut v0 = vec![[0.0; 3]; nn];
    let mut w0 = vec![[0.0; 3]; nn];
    for (k, iv) in model.initial_velocities.iter().enumerate() {
        let by = format!("initial velocity {}", k + 1);
        let nodes: Vec<u32> = match iv.target {
            VelocityTarget::All => (0..nn as u32).collect(),
            VelocityTarget::Node(n) => vec![lookup(&node_map, n, "node", &by)? as u32],
            VelocityTarget::NodeSet(s) => set_nodes(s, &by)?,
            VelocityTarget::Part(p) => part_nodes(&[p], &part_map, &elems, nn, &by)?,
            VelocityTarget::PartSet(s) => {
                let set_map = unique(&model.part_sets, |s| s.id, "part set")?;
                let set = &model.part_sets[lookup(&set_map, s, "part set", &by)?];
                part_nodes(&set.parts, &part_map, &elems, nn, &by)?
            }
        };
        let all = [iv.translation, iv.rotation, iv.centre, iv.axis];
        if all
            .iter()
            .flatten()
            .chain([&iv.omega])
            .any(|c| !c.is_finite())
        {
            return Err(ShellError::value(by, "non-finite velocity component"));
        }
        let axis = if iv.omega != 0.0 {
            let n = norm(iv.axis);
            if n <= 0.0 {
                return Err(ShellError::value(
                    by,
                    "zero rotation axis with a non-zero spin rate",
                ));
            }
            [iv.axis[0] / n, iv.axis[1] / n, iv.axis[2] / n]
        } else {
            [0.0; 3]
        };
        for i in nodes {
            let i = i as usize;
            let r = sub(x0[i], iv.centre);
            let spin = crate::geometry::cross(crate::geometry::scale(iv.omega, axis), r);
            v0[i] = crate::geometry::add(iv.translation, spin);
            w0[i] = crate::geometry::add(iv.rotation, crate::geometry::scale(iv.omega, axis));
        }
    }
    for &(i, m) in &fixed {
        for d in 0..3 {
            if m[d] {
                v0[i as usize][d] = 0.0;
            }
            if m[3 + d] {
                w0[i as usize][d] = 0.0;
            }
        }
    }

    // Walls.
    let mut walls = Vec::with_capacity(model.walls.len());
    let mut wall_ids: Vec<u64> = Vec::new();
    for (k, w) in model.walls.iter().enumerate() {
        let id = if w.id > 0 { w.id } else { k as u64 + 1 };
        if wall_ids.contains(&id) {
            return Err(ShellError::Reference {
                what: "rigid wall",
                id,
                message: "defined more than once (walls without an id take their position)".into(),
            });
        }
        wall_ids.push(id);
        let by = format!("rigid wall {id}");
        if let WallShape::Cylinder { radius, length } = w.shape
            && !(radius > 0.0 && radius.is_finite() && length >= 0.0 && length.is_finite())
        {
            return Err(ShellError::value(
                by,
                format!(
                    "cylinder radius {radius} must be positive and length {length} non-negative"
                ),
            ));
        }
        let nvec = sub(w.head, w.point);
        let len = norm(nvec);
        if !(len > 0.0 && len.is_finite()) {
            return Err(ShellError::value(
                by,
                "head and tail points coincide (no normal)",
            ));
        }
        let normal = [nvec[0] / len, nvec[1] / len, nvec[2] / len];
        if !(w.friction >= 0.0) {
            return Err(ShellError::value(
                by,
                format!("friction must be >= 0, got {}", w.friction),
            ));
        }
        if let WallMethod::Penalty { alpha, damping } = w.method {
            if !(alpha > 0.0 && alpha <= 1.0) {
                return Err(ShellError::value(
                    by,
                    format!("penalty factor must lie in (0, 1], got {alpha}"),
                ));
            }
            if !((0.0..=1.0).contains(&damping)) {
                return Err(ShellError::value(
                    by,
                    format!("contact damping must lie in [0, 1] of critical, got {damping}"),
                ));
            }
        }
        // Walls do not check the nodes of rigid bodies (LS-DYNA's rule for RWPNAL = 0).
        let nodes: Vec<u32> = match w.nodes {
            None => (0..nn as u32).filter(|&i| mass[i as usize] > 0.0).collect(),
            Some(s) => set_nodes(s, &by)?,
        }
        .into_iter()
        .filter(|&i| body_of[i as usize] == usize::MAX)
        .collect();
        let scale_len = model_size(&x0);
        for &i in &nodes {
            let d = wall_gap(w.shape, x0[i as usize], w.point, normal).0;
            if d < -1e-9 * scale_len {
                return Err(ShellError::value(
                    by,
                    format!(
                        "node {} starts {:.3e} behind the wall",
                        model.nodes[i as usize].id, -d
                    ),
                ));
            }
        }
        walls.push(Wall {
            id,
            shape: w.shape,
            nodes,
            point: w.point,
            normal,
            mu: w.friction,
            method: w.method,
        });
    }

    // Loads, curves, controls, outputs.
    for c in &model.curves {
        let w = format!("curve {}", c.id);
        if c.points.is_empty() {
            return Err(ShellError::value(w, "has no points"));
        }
        if c.points.windows(2).any(|p| !(p[1].0 > p[0].0)) {
            return Err(ShellError::value(w, "abscissae must increase strictly"));
        }
        if c.points
            .iter()
            .any(|p| !(p.0.is_finite() && p.1.is_finite()))
            || !(c.sfa.is_finite() && c.sfa != 0.0 && c.sfo.is_finite())
        {
            return Err(ShellError::value(
                w,
                "non-finite value or zero abscissa scale",
            ));
        }
    }
    if let Some(b) = &model.body_load_z {
        lookup(&curve_map, b.curve, "curve", "*LOAD_BODY_Z")?;
        if !b.scale.is_finite() {
            return Err(ShellError::value("body load", "non-finite scale factor"));
        }
    }
    non_negative("damping constant".into(), model.damping)?;
    let mut drives = Vec::with_capacity(model.prescribed.len());
    for (k, pm) in model.prescribed.iter().enumerate() {
        let by = format!("prescribed motion {}", k + 1);
        let curve = model.curves[lookup(&curve_map, pm.curve, "curve", &by)?].clone();
        if pm.dof > 5 || !(pm.scale.is_finite() && pm.birth.is_finite() && pm.death.is_finite()) {
            return Err(ShellError::value(
                by,
                "degree of freedom above 5 or a non-finite scale, birth or death",
            ));
        }
        let target = match pm.target {
            MotionTarget::Node(n) => {
                DriveTarget::Nodes(vec![lookup(&node_map, n, "node", &by)? as u32])
            }
            MotionTarget::NodeSet(s) => DriveTarget::Nodes(set_nodes(s, &by)?),
            MotionTarget::Rigid(p) => {
                let pi = lookup(&part_map, p, "part", &by)?;
                let b = rigid
                    .iter()
                    .position(|r| r.parts.contains(&pi))
                    .ok_or_else(|| {
                        ShellError::value(by.clone(), format!("part {p} is not rigid (*MAT_RIGID)"))
                    })?;
                DriveTarget::Body(b)
            }
        };
        if let DriveTarget::Nodes(nodes) = &target {
            if let Some(&i) = nodes.iter().find(|&&i| body_of[i as usize] != usize::MAX) {
                return Err(ShellError::value(
                    by,
                    format!(
                        "node {} moves with a rigid body: prescribe the body's motion (*BOUNDARY_PRESCRIBED_MOTION_RIGID)",
                        model.nodes[i as usize].id
                    ),
                ));
            }
            if pm.dof >= 3 && pm.kind == MotionKind::Displacement {
                return Err(ShellError::value(
                    by,
                    "a prescribed rotation angle of nodes (nodes carry no rotation)",
                ));
            }
        }
        if matches!(target, DriveTarget::Body(_))
            && pm.dof >= 3
            && pm.kind == MotionKind::Displacement
        {
            return Err(ShellError::value(
                by,
                "a prescribed rotation angle of a rigid body",
            ));
        }
        drives.push(Drive {
            target,
            dof: pm.dof,
            kind: pm.kind,
            curve,
            scale: pm.scale,
            birth: pm.birth,
            death: pm.death,
        });
    }
    let c = &model.control;
    positive("end time".into(), c.end_time)?;
    if !(c.tssfac > 0.0 && c.tssfac <= 1.0) {
        return Err(ShellError::value(
            "time-step scale factor",
            format!("must lie in (0, 1], got {}", c.tssfac),
        ));
    }
    if let Some(dt) = c.fixed_dt {
        positive("fixed time step".into(), dt)?;
    }
    non_negative("DTMIN factor".into(), c.dtmin_factor)?;
    positive("energy-ratio bound".into(), c.energy_ratio_bound)?;
    non_negative("output interval".into(), model.output.interval)?;
    let history = model
        .output
        .history_nodes
        .iter()
        .map(|&n| lookup(&node_map, n, "node", "the history output").map(|i| i as u32))
        .collect::<Result<Vec<_>>>()?;

    let contacts = crate::contact::compile(
        &crate::contact::ContactModel {
            model,
            node_map: &node_map,
            part_map: &part_map,
            elems: &elems,
            elem_t: elems.iter().map(|e| parts[e.props as usize].t).collect(),
            elem_bulk: elems
                .iter()
                .map(|e| {
                    let m = &parts[e.props as usize].mat;
                    m.e / (3.0 * (1.0 - 2.0 * m.nu))
                })
                .collect(),
            x0: &x0,
            mass: &mass,
            body_of: &body_of,
        },
        &model.contact_control,
    )?;

    Ok(Compiled {
        node_ids: model.nodes.iter().map(|n| n.id).collect(),
        x0,
        elem_ids: model.shells.iter().map(|s| s.id).collect(),
        elems,
        parts,
        part_ids: model.parts.iter().map(|p| p.id).collect(),
        rigid,
        drives,
        mass,
        inertia,
        fixed,
        walls,
        contacts,
        v0,
        w0,
        history,
    })
}

/// The nodes of the shells of the parts `ids`.
fn part_nodes(
    ids: &[u64],
    part_map: &HashMap<u64, usize>,
    elems: &[Elem],
    nn: usize,
    by: &str,
) -> Result<Vec<u32>> {
    let mut on = vec![false; nn];
    for &p in ids {
        let pi = lookup(part_map, p, "part", by)? as u32;
        for e in elems.iter().filter(|e| e.part == pi) {
            for &n in &e.nodes {
                on[n as usize] = true;
            }
        }
    }
    Ok((0..nn as u32).filter(|&i| on[i as usize]).collect())
}

/// The signed gap of a point `x` to a wall (positive outside, on the side the nodes belong)
/// and the wall's outward unit normal there: for a plane through `point` with unit normal
/// `axis`, the distance along it; for a cylinder of axis `axis` through `point`, the
/// distance to the axis less the radius, with the radial direction (a point outside the
/// length of a finite cylinder, or on its axis, is reported as far outside).
pub(crate) fn wall_gap(
    shape: WallShape,
    x: [f64; 3],
    point: [f64; 3],
    axis: [f64; 3],
) -> (f64, [f64; 3]) {
    let r = sub(x, point);
    match shape {
        WallShape::Plane => (dot(r, axis), axis),
        WallShape::Cylinder { radius, length } => {
            let s = dot(r, axis);
            let radial = [r[0] - s * axis[0], r[1] - s * axis[1], r[2] - s * axis[2]];
            let d = norm(radial);
            if (length > 0.0 && !(0.0..=length).contains(&s)) || !(d > 0.0) {
                return (f64::INFINITY, axis);
            }
            (d - radius, [radial[0] / d, radial[1] / d, radial[2] / d])
        }
    }
}

fn model_size(x: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in x {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    norm(sub(hi, lo)).max(f64::MIN_POSITIVE)
}
