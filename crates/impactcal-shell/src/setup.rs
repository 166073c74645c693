//! Validation of a [`ShellModel`] and its translation into the solver's indexed form.

use std::collections::HashMap;

use crate::element::{self, ElementFault, PartProps};
use crate::error::{Result, ShellError};
use crate::geometry::{dot, norm, sub};
use crate::model::{NodeTarget, ShellModel, VelocityTarget, WallMethod};
use crate::validate::{check_hourglass, check_material, check_section, non_negative, positive};

/// An element in solver form: node indices, triangle flag, part index.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Elem {
    pub nodes: [u32; 4],
    pub tri: bool,
    pub part: u32,
}

/// A rigid wall in solver form.
#[derive(Debug, Clone)]
pub(crate) struct Wall {
    pub nodes: Vec<u32>,
    pub point: [f64; 3],
    pub normal: [f64; 3],
    pub mu: f64,
    pub method: WallMethod,
}

/// Everything the solver needs, validated.
pub(crate) struct Compiled {
    pub node_ids: Vec<u64>,
    pub x0: Vec<[f64; 3]>,
    pub elem_ids: Vec<u64>,
    pub elems: Vec<Elem>,
    pub parts: Vec<PartProps>,
    pub part_ids: Vec<u64>,
    pub mass: Vec<f64>,
    pub inertia: Vec<f64>,
    pub fixed: Vec<(u32, [bool; 6])>,
    pub walls: Vec<Wall>,
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
    for s in &model.sections {
        check_section(s)?;
    }
    let hg = &model.hourglass;
    check_hourglass(hg)?;
    let mut parts = Vec::with_capacity(model.parts.len());
    for p in &model.parts {
        let by = format!("part {}", p.id);
        let sec = &model.sections[lookup(&sec_map, p.section, "section", &by)?];
        let mat = &model.materials[lookup(&mat_map, p.material, "material", &by)?];
        parts.push(PartProps::new(sec, mat, hg)?);
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
        let pp = &parts[part];
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

    // Constraints.
    let mut fixed_mask = vec![[false; 6]; nn];
    for (k, spc) in model.spcs.iter().enumerate() {
        let by = format!("constraint {}", k + 1);
        let nodes = match spc.target {
            NodeTarget::Node(n) => vec![lookup(&node_map, n, "node", &by)? as u32],
            NodeTarget::NodeSet(s) => set_nodes(s, &by)?,
        };
        for i in nodes {
            for d in 0..6 {
                fixed_mask[i as usize][d] |= spc.dofs[d];
            }
        }
    }
    // Nodes without mass (not attached to anything) are held fixed.
    for i in 0..nn {
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
            VelocityTarget::Part(p) => {
                let pi = lookup(&part_map, p, "part", &by)? as u32;
                let mut on = vec![false; nn];
                for e in elems.iter().filter(|e| e.part == pi) {
                    for &n in &e.nodes {
                        on[n as usize] = true;
                    }
                }
                (0..nn as u32).filter(|&i| on[i as usize]).collect()
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
    for (k, w) in model.walls.iter().enumerate() {
        let by = format!("rigid wall {}", k + 1);
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
        let nodes = match w.nodes {
            None => (0..nn as u32).filter(|&i| mass[i as usize] > 0.0).collect(),
            Some(s) => set_nodes(s, &by)?,
        };
        let scale_len = model_size(&x0);
        for &i in &nodes {
            let d = dot(sub(x0[i as usize], w.point), normal);
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

    Ok(Compiled {
        node_ids: model.nodes.iter().map(|n| n.id).collect(),
        x0,
        elem_ids: model.shells.iter().map(|s| s.id).collect(),
        elems,
        parts,
        part_ids: model.parts.iter().map(|p| p.id).collect(),
        mass,
        inertia,
        fixed,
        walls,
        v0,
        w0,
        history,
    })
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
