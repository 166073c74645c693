//! Sensor placement with labels, options and the quality figures of the chosen set.

use serde::{Deserialize, Serialize};

use crate::candidates::{Axis, CandidateShapes, split_label};
use crate::elimination::{ESSENTIAL, check_rank};
use crate::engine::{self, Engine};
use crate::equivalence;
use crate::error::{Result, SensorsError};
use crate::linalg::{dot, gather, log_det_gram, r_factor, singular_values, small_det, whiten_row};
use crate::options::{Grouping, PlacementMethod, PlacementOptions};
use impactcal_core::error::invalid_option;

/// One step of the greedy pass: the DOF or node moved and its score at that moment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Step {
    /// The DOF label, or the node name with [`Grouping::Node`].
    pub label: String,
    /// Labels of the DOFs moved (one, or a node's DOFs).
    pub dofs: Vec<String>,
    /// Removal: `E_D` (or the node score `1 - det(I - E_bb)`), the fraction of
    /// `det(Phi^T Phi)` lost. Addition: the fractional gain `phi A^-1 phi^T` (or
    /// `det(I + E_bb) - 1`). `None` for the starting rows of the forward method.
    pub score: Option<f64>,
}

/// One exchange made by the swap refinement.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Swap {
    /// The DOF or node taken out.
    pub removed: String,
    /// The DOF or node put in.
    pub added: String,
    /// `det(A_after) / det(A_before) > 1`.
    pub ratio: f64,
}

/// Number of chosen DOFs per axis (labels `<node>.<x|y|z>`; `other` counts the rest).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct AxisCounts {
    /// DOFs along x.
    pub x: usize,
    /// DOFs along y.
    pub y: usize,
    /// DOFs along z.
    pub z: usize,
    /// DOFs whose label has no axis.
    pub other: usize,
}

/// A set of candidates that carry the same information (see
/// [`PlacementOptions::equivalence_tolerance`]): the placement saw only `kept`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Equivalent {
    /// The candidate (DOF label, or node with [`Grouping::Node`]) that stood for the set.
    pub kept: String,
    /// The others, in candidate order: a sensor at any of them measures what one at `kept`
    /// does (on a symmetric structure, its mirror images).
    pub others: Vec<String>,
    /// Whether `kept` is among the chosen sensors.
    pub chosen: bool,
}

/// The result of [`place`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Placement {
    /// Labels of the chosen DOFs, in candidate order.
    pub selected: Vec<String>,
    /// Candidate (row) indices of the chosen DOFs, ascending.
    pub selected_indices: Vec<usize>,
    /// Distinct nodes among the chosen DOFs (labels `<node>.<dir>`), in candidate order.
    pub nodes: Vec<String>,
    /// Backward method: what was removed, in order, with its score at removal.
    pub removal_order: Vec<Step>,
    /// Forward method: the starting rows (no score) then what was added, in order.
    pub addition_order: Vec<Step>,
    /// Exchanges made by the swap refinement, in order.
    pub swaps: Vec<Swap>,
    /// Retained information `det(A_kept) / det(A_full)`, with `A = Phi_w^T Phi_w` over the
    /// noise-weighted rows and `A_full` over every usable candidate (not excluded), each set
    /// of equivalent candidates counted once.
    pub determinant_ratio: f64,
    /// Natural log of `determinant_ratio` (finite where the ratio underflows).
    pub log_determinant_ratio: f64,
    /// `sigma_max / sigma_min` of the chosen rows of the (unweighted) shape matrix.
    pub condition_number: f64,
    /// Largest off-diagonal `|O_ij|` of the normalised Gram (auto-orthogonality) matrix
    /// `O = D^-1/2 Phi_s^T Phi_s D^-1/2`, `D = diag(Phi_s^T Phi_s)`, on the chosen rows.
    pub max_off_diagonal: f64,
    /// `max_off_diagonal^2`: the largest off-diagonal AutoMAC of the chosen shapes.
    pub max_auto_mac: f64,
    /// Chosen DOFs per axis (direction of measurement).
    pub counts_by_direction: AxisCounts,
    /// Sets of candidates that repeat one another's information, each seen by the
    /// placement as one candidate, in the order of their kept candidate.
    #[serde(default)]
    pub equivalents: Vec<Equivalent>,
    /// Notes that did not stop the placement (for example all-zero rows dropped).
    pub warnings: Vec<String>,
}

/// Chooses `options.target` sensors among the candidates by effective independence.
///
/// With `Phi_w` the noise-weighted shape matrix on the usable candidates (not excluded,
/// not all-zero, and one of each set of candidates that repeat one another's information:
/// [`PlacementOptions::equivalence_tolerance`], [`Placement::equivalents`]), the default backward method removes, one at a time, the DOF of smallest
/// `E_D,i = [Phi_w (Phi_w^T Phi_w)^-1 Phi_w^T]_ii` (with [`Grouping::Node`]: the node of
/// smallest `1 - det(I - E_bb)`), each removal multiplying `det(Phi_w^T Phi_w)` by
/// `1 - score`; DOFs in `keep` are never removed; ties go to the lowest candidate index.
/// The result is the same for `Phi` and `Phi T` with `T` invertible.
///
/// # Errors
/// [`SensorsError::UnknownLabel`] for `keep` or `exclude` labels that are not candidates;
/// [`CoreError::DimensionMismatch`](impactcal_core::CoreError::DimensionMismatch) for noise
/// levels of the wrong length;
/// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) for a forward
/// start larger than the target or a node of more than three DOFs;
/// [`SensorsError::BadNodeLabel`] for a label without `<node>.<x|y|z>` in node mode;
/// [`SensorsError::TooFewCandidates`], [`SensorsError::TargetBelowShapes`],
/// [`SensorsError::TargetAboveCandidates`], [`SensorsError::TooManyKept`] for impossible
/// counts; [`SensorsError::RankDeficient`] (with the numerical rank) when the usable
/// weighted rows do not have full column rank; [`SensorsError::AllEssential`] when the DOFs
/// that must stay leave nothing removable without losing rank.
pub fn place(candidates: &CandidateShapes, options: &PlacementOptions) -> Result<Placement> {
    let problem = Problem::build(candidates, options)?;
    let k = problem.k;
    let nblocks = problem.blocks.len();
    let unit = problem.unit();
    let mut removal_order = Vec::new();
    let mut addition_order = Vec::new();
    let mut in_set;
    match options.method {
        PlacementMethod::Backward => {
            let tracked: Vec<usize> = (0..nblocks).filter(|&b| !problem.forced[b]).collect();
            let mut eng = Engine::new(
                k,
                problem.phi.clone(),
                problem.blocks.clone(),
                vec![true; nblocks],
                tracked,
                engine::Sweep::Remove,
                options.refresh_every,
            );
            let mut count = nblocks;
            while count > options.target {
                let Some((pos, block, score)) = eng.best() else {
                    break;
                };
                if score >= 1.0 - ESSENTIAL {
                    return Err(SensorsError::AllEssential {
                        remaining: count,
                        unit,
                        score,
                    });
                }
                eng.apply(pos);
                removal_order.push(problem.step(block, Some(score)));
                count -= 1;
            }
            in_set = eng.in_set().to_vec();
        }
        PlacementMethod::Forward => {
            let start = problem.forward_start()?;
            if start.iter().filter(|s| **s).count() > options.target {
                return Err(invalid_option(
                    "target",
                    options.target,
                    format!(
                        "the forward start (DOFs that must stay plus {k} pivoted rows) holds {} \
                         {unit}, more than the target",
                        start.iter().filter(|s| **s).count()
                    ),
                ));
            }
            for (b, s) in start.iter().enumerate() {
                if *s {
                    addition_order.push(problem.step(b, None));
                }
            }
            let tracked: Vec<usize> = (0..nblocks).filter(|&b| !start[b]).collect();
            let mut count = start.iter().filter(|s| **s).count();
            let mut eng = Engine::new(
                k,
                problem.phi.clone(),
                problem.blocks.clone(),
                start,
                tracked,
                engine::Sweep::Add,
                options.refresh_every,
            );
            while count < options.target {
                let Some((pos, block, score)) = eng.best() else {
                    break;
                };
                eng.apply(pos);
                addition_order.push(problem.step(block, Some(score)));
                count += 1;
            }
            in_set = eng.in_set().to_vec();
        }
    }
    let swaps = if options.swap_refinement {
        problem.refine(&mut in_set, options.max_swaps)
    } else {
        Vec::new()
    };
    problem.finish(candidates, &in_set, removal_order, addition_order, swaps)
}

/// The placement problem after validation: weighted usable rows, blocks and constraints.
struct Problem {
    k: usize,
    grouping: Grouping,
    /// Noise-weighted usable rows, row-major.
    phi: Vec<f64>,
    /// Candidate index of each usable row.
    cand: Vec<usize>,
    /// Rows (usable-local) of each block.
    blocks: Vec<Vec<usize>>,
    /// Name of each block (DOF label or node).
    names: Vec<String>,
    /// DOF labels of each block.
    dof_labels: Vec<Vec<String>>,
    /// Blocks that must stay.
    forced: Vec<bool>,
    /// Candidates merged into another, as (kept block, other block names).
    equivalents: Vec<(usize, Vec<String>)>,
    /// Usable blocks merged away.
    merged: usize,
    warnings: Vec<String>,
}

impl Problem {
    fn build(c: &CandidateShapes, o: &PlacementOptions) -> Result<Self> {
        let (s, k) = (c.candidates(), c.shapes_count());
        let lookup = |option: &'static str, labels: &[String]| -> Result<Vec<bool>> {
            let mut mask = vec![false; s];
            for l in labels {
                let i = c.index_of(l).ok_or_else(|| SensorsError::UnknownLabel {
                    option,
                    label: l.clone(),
                })?;
                mask[i] = true;
            }
            Ok(mask)
        };
        let keep = lookup("keep", &o.keep)?;
        let exclude = lookup("exclude", &o.exclude)?;
        if let Some(i) = (0..s).find(|&i| keep[i] && exclude[i]) {
            return Err(SensorsError::KeepExcludeConflict {
                label: c.labels()[i].clone(),
            });
        }
        let weights = match &o.noise {
            None => vec![1.0; s],
            Some(sigma) => {
                if sigma.len() != s {
                    return Err(impactcal_core::CoreError::DimensionMismatch {
                        what: "noise levels (one per candidate)".into(),
                        expected: s,
                        found: sigma.len(),
                    }
                    .into());
                }
                sigma.iter().map(|v| 1.0 / v).collect()
            }
        };
        let shapes = c.shapes();
        let mut phi = Vec::with_capacity(s * k);
        let mut cand = Vec::with_capacity(s);
        let mut zero = Vec::new();
        for i in 0..s {
            if exclude[i] {
                continue;
            }
            let all_zero = (0..k).all(|j| shapes[(i, j)] == 0.0);
            if all_zero && !keep[i] {
                zero.push(c.labels()[i].clone());
                continue;
            }
            phi.extend((0..k).map(|j| shapes[(i, j)] * weights[i]));
            cand.push(i);
        }
        let mut warnings = Vec::new();
        if !zero.is_empty() {
            let shown: Vec<&str> = zero.iter().take(10).map(String::as_str).collect();
            warnings.push(format!(
                "dropped {} all-zero candidate row(s): {}{}",
                zero.len(),
                shown.join(", "),
                if zero.len() > 10 { ", ..." } else { "" }
            ));
        }
        if cand.len() < k {
            return Err(SensorsError::TooFewCandidates {
                candidates: cand.len(),
                shapes: k,
            });
        }
        check_rank(
            &phi,
            k,
            &(0..cand.len()).collect::<Vec<_>>(),
            o.rank_tolerance,
        )?;

        let (blocks, names): (Vec<Vec<usize>>, Vec<String>) = match o.grouping {
            Grouping::Dof => (
                (0..cand.len()).map(|r| vec![r]).collect(),
                cand.iter().map(|&i| c.labels()[i].clone()).collect(),
            ),
            Grouping::Node => {
                let mut names: Vec<String> = Vec::new();
                let mut blocks: Vec<Vec<usize>> = Vec::new();
                let mut index = std::collections::HashMap::new();
                for (r, &i) in cand.iter().enumerate() {
                    let label = &c.labels()[i];
                    let (node, _) =
                        split_label(label).ok_or_else(|| SensorsError::BadNodeLabel {
                            label: label.clone(),
                        })?;
                    let b = *index.entry(node.to_string()).or_insert_with(|| {
                        names.push(node.to_string());
                        blocks.push(Vec::new());
                        blocks.len() - 1
                    });
                    blocks[b].push(r);
                }
                if let Some(b) = blocks.iter().position(|b| b.len() > 3) {
                    return Err(invalid_option(
                        "grouping",
                        "node",
                        format!(
                            "node `{}` has {} candidate DOFs (at most 3: x, y, z)",
                            names[b],
                            blocks[b].len()
                        ),
                    ));
                }
                (blocks, names)
            }
        };
        let dof_labels: Vec<Vec<String>> = blocks
            .iter()
            .map(|b| b.iter().map(|&r| c.labels()[cand[r]].clone()).collect())
            .collect();
        let forced: Vec<bool> = blocks
            .iter()
            .map(|b| b.iter().any(|&r| keep[cand[r]]))
            .collect();
        let mut problem = Problem {
            k,
            grouping: o.grouping,
            phi,
            cand,
            blocks,
            names,
            dof_labels,
            forced,
            equivalents: Vec::new(),
            merged: 0,
            warnings,
        };
        problem.merge_equivalents(o.equivalence_tolerance);
        problem.check_target(o.target)?;
        Ok(problem)
    }

    /// Keeps one block of each set of blocks that repeat one another's information
    /// ([`crate::equivalence::classes`]) and drops the others from the problem, remembering
    /// them for the result.
    fn merge_equivalents(&mut self, tolerance: f64) {
        let rep_of = equivalence::classes(&self.phi, self.k, &self.blocks, &self.forced, tolerance);
        if rep_of.iter().all(Option::is_none) {
            return;
        }
        let k = self.k;
        let mut others: Vec<Vec<String>> = vec![Vec::new(); self.blocks.len()];
        for (b, rep) in rep_of.iter().enumerate() {
            if let Some(a) = rep {
                others[*a].push(self.names[b].clone());
            }
        }
        let mut phi = Vec::new();
        let mut cand = Vec::new();
        let mut blocks = Vec::new();
        let mut names = Vec::new();
        let mut dof_labels = Vec::new();
        let mut forced = Vec::new();
        let mut equivalents = Vec::new();
        for (b, rows) in self.blocks.iter().enumerate() {
            if rep_of[b].is_some() {
                self.merged += 1;
                continue;
            }
            let mut new_rows = Vec::with_capacity(rows.len());
            for &r in rows {
                new_rows.push(cand.len());
                cand.push(self.cand[r]);
                phi.extend_from_slice(&self.phi[r * k..(r + 1) * k]);
            }
            if !others[b].is_empty() {
                equivalents.push((blocks.len(), std::mem::take(&mut others[b])));
            }
            blocks.push(new_rows);
            names.push(std::mem::take(&mut self.names[b]));
            dof_labels.push(std::mem::take(&mut self.dof_labels[b]));
            forced.push(self.forced[b]);
        }
        self.phi = phi;
        self.cand = cand;
        self.blocks = blocks;
        self.names = names;
        self.dof_labels = dof_labels;
        self.forced = forced;
        self.warnings.push(format!(
            "{} candidate {} repeat the information of others (within an equivalence \
             tolerance of {tolerance:e}) and count as one with them: see `equivalents`",
            self.merged,
            self.unit()
        ));
        self.equivalents = equivalents;
    }

    fn unit(&self) -> &'static str {
        match self.grouping {
            Grouping::Dof => "sensors",
            Grouping::Node => "nodes",
        }
    }

    fn check_target(&self, target: usize) -> Result<()> {
        let unit = self.unit();
        let available = self.blocks.len();
        if target > available {
            return Err(SensorsError::TargetAboveCandidates {
                target,
                unit,
                available,
                equivalent: self.merged,
            });
        }
        let mut sizes: Vec<usize> = self.blocks.iter().map(Vec::len).collect();
        sizes.sort_unstable_by(|a, b| b.cmp(a));
        let dofs: usize = sizes.iter().take(target).sum();
        if dofs < self.k {
            return Err(SensorsError::TargetBelowShapes {
                target,
                unit,
                dofs,
                shapes: self.k,
            });
        }
        let kept = self.forced.iter().filter(|f| **f).count();
        if kept > target {
            return Err(SensorsError::TooManyKept { kept, unit, target });
        }
        Ok(())
    }

    fn step(&self, block: usize, score: Option<f64>) -> Step {
        Step {
            label: self.names[block].clone(),
            dofs: self.dof_labels[block].clone(),
            score,
        }
    }

    /// Starting set of the forward method: forced blocks plus the blocks of the `k` rows
    /// picked by QR with column pivoting of `Phi_w^T`.
    fn forward_start(&self) -> Result<Vec<bool>> {
        let k = self.k;
        let n = self.cand.len();
        let phit = faer::Mat::from_fn(k, n, |i, j| self.phi[j * k + i]);
        let qr = phit.col_piv_qr();
        let (fwd, _) = qr.P().arrays();
        let mut block_of = vec![0; n];
        for (b, rows) in self.blocks.iter().enumerate() {
            for &r in rows {
                block_of[r] = b;
            }
        }
        let mut start = self.forced.clone();
        for &row in fwd.iter().take(k) {
            start[block_of[row]] = true;
        }
        Ok(start)
    }

    /// Fedorov-type exchange: repeatedly makes the single swap (a chosen, not forced block
    /// out, an unchosen block in) that raises `det(A)` the most, while it raises it by more
    /// than a relative `1e-12`.
    fn refine(&self, in_set: &mut [bool], max_swaps: usize) -> Vec<Swap> {
        let k = self.k;
        let mut swaps = Vec::new();
        while swaps.len() < max_swaps {
            let rows: Vec<usize> = self.set_rows(in_set);
            let r = r_factor(&self.phi, k, &rows);
            let w: Vec<Vec<Vec<f64>>> = self
                .blocks
                .iter()
                .map(|b| {
                    b.iter()
                        .map(|&row| {
                            let mut v = vec![0.0; k];
                            whiten_row(&self.phi[row * k..(row + 1) * k], r.as_ref(), &mut v);
                            v
                        })
                        .collect()
                })
                .collect();
            let outs: Vec<usize> = (0..self.blocks.len()).filter(|&b| !in_set[b]).collect();
            let ins: Vec<usize> = (0..self.blocks.len())
                .filter(|&b| in_set[b] && !self.forced[b])
                .collect();
            let mut best: Option<(usize, usize, f64)> = None;
            for &rem in &ins {
                for &add in &outs {
                    let ratio = swap_ratio(&w[add], &w[rem]);
                    if best.is_none_or(|(_, _, b)| ratio > b) {
                        best = Some((rem, add, ratio));
                    }
                }
            }
            match best {
                Some((rem, add, ratio)) if ratio > 1.0 + 1e-12 => {
                    in_set[rem] = false;
                    in_set[add] = true;
                    swaps.push(Swap {
                        removed: self.names[rem].clone(),
                        added: self.names[add].clone(),
                        ratio,
                    });
                }
                _ => break,
            }
        }
        swaps
    }

    fn set_rows(&self, in_set: &[bool]) -> Vec<usize> {
        self.blocks
            .iter()
            .zip(in_set)
            .filter(|(_, s)| **s)
            .flat_map(|(b, _)| b.iter().copied())
            .collect()
    }

    fn finish(
        self,
        c: &CandidateShapes,
        in_set: &[bool],
        removal_order: Vec<Step>,
        addition_order: Vec<Step>,
        swaps: Vec<Swap>,
    ) -> Result<Placement> {
        let k = self.k;
        let rows = self.set_rows(in_set);
        let all: Vec<usize> = (0..self.cand.len()).collect();
        let log_ratio = log_det_gram(&self.phi, k, &rows) - log_det_gram(&self.phi, k, &all);
        let mut selected_indices: Vec<usize> = rows.iter().map(|&r| self.cand[r]).collect();
        selected_indices.sort_unstable();
        let selected: Vec<String> = selected_indices
            .iter()
            .map(|&i| c.labels()[i].clone())
            .collect();
        let (condition_number, max_off_diagonal) = quality(c, &selected_indices)?;
        let mut counts = AxisCounts::default();
        let mut nodes: Vec<String> = Vec::new();
        for l in &selected {
            match split_label(l) {
                Some((node, dir)) => {
                    match dir {
                        Axis::X => counts.x += 1,
                        Axis::Y => counts.y += 1,
                        Axis::Z => counts.z += 1,
                    }
                    if !nodes.iter().any(|n| n == node) {
                        nodes.push(node.to_string());
                    }
                }
                None => counts.other += 1,
            }
        }
        Ok(Placement {
            selected,
            selected_indices,
            nodes,
            removal_order,
            addition_order,
            swaps,
            determinant_ratio: log_ratio.exp(),
            log_determinant_ratio: log_ratio,
            condition_number,
            max_off_diagonal,
            max_auto_mac: max_off_diagonal * max_off_diagonal,
            counts_by_direction: counts,
            equivalents: self
                .equivalents
                .iter()
                .map(|(b, others)| Equivalent {
                    kept: self.names[*b].clone(),
                    others: others.clone(),
                    chosen: in_set[*b],
                })
                .collect(),
            warnings: self.warnings,
        })
    }
}

/// `det(A + U_a^T U_a - U_r^T U_r) / det(A)` from whitened rows (`A = I` in those
/// coordinates): `det(I + S G)` with `G` the Gram matrix of the stacked rows `[U_a; U_r]`
/// and `S = diag(+1 for added rows, -1 for removed rows)`.
fn swap_ratio(add: &[Vec<f64>], rem: &[Vec<f64>]) -> f64 {
    let rows: Vec<(&[f64], f64)> = add
        .iter()
        .map(|v| (v.as_slice(), 1.0))
        .chain(rem.iter().map(|v| (v.as_slice(), -1.0)))
        .collect();
    let n = rows.len();
    let mut m = vec![0.0; n * n];
    for (i, (wi, si)) in rows.iter().enumerate() {
        for (j, (wj, _)) in rows.iter().enumerate() {
            m[i * n + j] = f64::from(u8::from(i == j)) + si * dot(wi, wj);
        }
    }
    small_det(&mut m, n)
}

/// Condition number and largest off-diagonal normalised Gram entry of the chosen rows of
/// the unweighted shape matrix.
fn quality(c: &CandidateShapes, rows: &[usize]) -> Result<(f64, f64)> {
    let k = c.shapes_count();
    let shapes = c.shapes();
    let flat: Vec<f64> = (0..c.candidates())
        .flat_map(|i| (0..k).map(move |j| shapes[(i, j)]))
        .collect();
    let m = gather(&flat, k, rows);
    let s = singular_values(m.as_ref())?;
    let smin = s.last().copied().unwrap_or(0.0);
    let cond = if smin > 0.0 {
        s[0] / smin
    } else {
        f64::INFINITY
    };
    let cols: Vec<Vec<f64>> = (0..k)
        .map(|j| (0..rows.len()).map(|i| m[(i, j)]).collect())
        .collect();
    let mut worst: f64 = 0.0;
    for i in 0..k {
        for j in i + 1..k {
            let den = (dot(&cols[i], &cols[i]) * dot(&cols[j], &cols[j])).sqrt();
            if den > 0.0 {
                worst = worst.max((dot(&cols[i], &cols[j]) / den).abs());
            }
        }
    }
    Ok((cond, worst))
}
