//! Placement on a symmetric structure: a mirror image repeats its partner's information, so
//! the placement must not pay for both.
//!
//! The structure is a rectangular membrane of `NX x NY` nodes, fixed at its edges, mirror
//! symmetric about its mid-line `j = (NY + 1) / 2`; a symmetric load excites only its
//! symmetric modes `sin(p i pi / (NX + 1)) sin(q j pi / (NY + 1))`, `q` odd, so the row of
//! node `(i, j)` equals the row of its mirror `(i, NY + 1 - j)` (the rows are copied, as a
//! solver exact to the last bit would give them). The truth a merged placement must meet:
//! on the full structure it chooses what plain effective independence chooses on one half
//! (every node on or below the mid-line), since the other half only repeats it.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::f64::consts::PI;

use impactcal_sensors::{CandidateShapes, Grouping, PlacementOptions, place};

const NX: usize = 7;
const NY: usize = 9;
/// The symmetric modes `(p, q)` observed.
const MODES: [(usize, usize); 6] = [(1, 1), (2, 1), (3, 1), (1, 3), (2, 3), (3, 3)];

fn node(i: usize, j: usize) -> usize {
    (i - 1) * NY + j
}

/// The mirror row `j` of the lower half (`j <= (NY + 1) / 2`) of row `j`.
fn lower(j: usize) -> usize {
    j.min(NY + 1 - j)
}

/// Mode `(p, q)` at node `(i, j)`. The nodes are graded along `i` (`x_i = (i / (NX + 1))^1.3`)
/// so that the only symmetry is the mirror about the mid-line: on a uniform grid the modes
/// would also be symmetric or antisymmetric about `i = (NX + 1) / 2`, whose images tie in
/// effective independence without repeating each other (ties go to the lower index, and
/// rounding decides them).
fn mode(p: usize, q: usize, i: usize, j: usize) -> f64 {
    (p as f64 * (i as f64 / (NX + 1) as f64).powf(1.3) * PI).sin()
        * (q as f64 * j as f64 * PI / (NY + 1) as f64).sin()
}

/// The nodes `(i, j)` in candidate order: all of them, or those on or below the mid-line.
fn grid(half_only: bool) -> impl Iterator<Item = (usize, usize)> {
    (1..=NX)
        .flat_map(|i| (1..=NY).map(move |j| (i, j)))
        .filter(move |&(_, j)| !half_only || j == lower(j))
}

/// Out-of-plane DOFs `<node>.z` of every node (or of the lower half only), each row the
/// lower-half node's row times `1 + asym * e` for a fixed pattern `e` in `[-1, 1]` on the
/// upper half (`asym = 0`: exact mirror images).
fn membrane(half_only: bool, asym: f64) -> CandidateShapes {
    let mut labels = Vec::new();
    let mut rows = Vec::new();
    for (i, j) in grid(half_only) {
        let mut row: Vec<f64> = MODES
            .iter()
            .map(|&(p, q)| mode(p, q, i, lower(j)))
            .collect();
        if j != lower(j) {
            for (m, v) in row.iter_mut().enumerate() {
                *v *= 1.0 + asym * ((7 * i + 3 * j + 5 * m) as f64).sin();
            }
        }
        labels.push(format!("{}.z", node(i, j)));
        rows.push(row);
    }
    CandidateShapes::from_rows(labels, &rows).unwrap()
}

/// The mirror image of a label `<node>.<axis>`.
fn mirror(label: &str) -> String {
    let (n, axis) = label.split_once('.').unwrap();
    let n: usize = n.parse().unwrap();
    let (i, j) = ((n - 1) / NY + 1, (n - 1) % NY + 1);
    format!("{}.{axis}", node(i, NY + 1 - j))
}

/// The label itself or its mirror image, whichever lies on the lower half.
fn fold(label: &str) -> String {
    let n: usize = label.split_once('.').unwrap().0.parse().unwrap();
    if (n - 1) % NY + 1 > NY.div_ceil(2) {
        mirror(label)
    } else {
        label.to_string()
    }
}

fn has_mirror_pair(selected: &[String]) -> bool {
    selected
        .iter()
        .any(|l| mirror(l) != *l && selected.contains(&mirror(l)))
}

/// Plain effective independence keeps mirror pairs; the default placement keeps none and
/// chooses exactly what plain effective independence chooses on one half, with the same
/// retained information, and lists each chosen sensor's mirror image as its equivalent.
#[test]
fn mirror_images_are_one_candidate() {
    let full = membrane(false, 0.0);
    let target = 12;
    let plain = place(
        &full,
        &PlacementOptions::new(target)
            .equivalence_tolerance(0.0)
            .unwrap(),
    )
    .unwrap();
    assert!(
        has_mirror_pair(&plain.selected),
        "plain EfI keeps mirror pairs: {:?}",
        plain.selected
    );
    assert!(plain.equivalents.is_empty());

    let merged = place(&full, &PlacementOptions::new(target)).unwrap();
    assert!(!has_mirror_pair(&merged.selected), "{:?}", merged.selected);
    let half = place(
        &membrane(true, 0.0),
        &PlacementOptions::new(target)
            .equivalence_tolerance(0.0)
            .unwrap(),
    )
    .unwrap();
    assert_eq!(merged.selected, half.selected);
    assert!((merged.log_determinant_ratio - half.log_determinant_ratio).abs() < 1e-9);
    // Every off-plane node has its mirror as equivalent; on-plane nodes have none.
    let off_plane = NX * (NY / 2);
    assert_eq!(merged.equivalents.len(), off_plane);
    for e in &merged.equivalents {
        assert_eq!(e.others, [mirror(&e.kept)]);
        assert_eq!(e.chosen, merged.selected.contains(&e.kept));
    }
    assert!(
        merged
            .warnings
            .iter()
            .any(|w| w.contains(&format!("{off_plane} candidate sensors")))
    );
}

/// Mirror rows that differ by rounding (relative 1e-6, as a solver that is symmetric up to
/// its summation order gives) are still one candidate; a real asymmetry of 5 % is not.
#[test]
fn near_mirror_rows_merge_and_an_asymmetry_does_not() {
    let half = place(
        &membrane(true, 0.0),
        &PlacementOptions::new(12)
            .equivalence_tolerance(0.0)
            .unwrap(),
    )
    .unwrap();
    // Each set keeps its member of largest signal, here either image: compared up to
    // mirror images.
    let rounding = place(&membrane(false, 1e-6), &PlacementOptions::new(12)).unwrap();
    let mut folded: Vec<String> = rounding.selected.iter().map(|l| fold(l)).collect();
    folded.sort_by_key(|l| l.split_once('.').unwrap().0.parse::<usize>().unwrap());
    assert_eq!(folded, half.selected);
    assert_eq!(rounding.equivalents.len(), NX * (NY / 2));
    let asymmetric = place(&membrane(false, 0.05), &PlacementOptions::new(12)).unwrap();
    assert!(asymmetric.equivalents.is_empty());
}

/// More sensors than distinct candidates: the error says how many repeat others.
#[test]
fn a_target_above_the_distinct_candidates_names_the_repeats() {
    let distinct = NX * NY.div_ceil(2);
    let e = place(&membrane(false, 0.0), &PlacementOptions::new(distinct + 1)).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains(&format!("exceeds the {distinct} usable sensors"))
            && text.contains(&format!("{} more repeat the information", NX * (NY / 2))),
        "{text}"
    );
}

/// Triaxial sensors: at node `(i, j)` the x and z rows are symmetric fields and the y row
/// an antisymmetric one (negated at the mirror node), so a node and its mirror span the
/// same rows; node-grouped placement chooses what it chooses on the lower half.
#[test]
fn mirror_nodes_are_one_triaxial_candidate() {
    let build = |half_only: bool| {
        let mut labels = Vec::new();
        let mut rows = Vec::new();
        for (i, j) in grid(half_only) {
            let jl = lower(j);
            let sign = if j == jl { 1.0 } else { -1.0 };
            let x: Vec<f64> = MODES
                .iter()
                .map(|&(p, q)| 0.5 * mode(2 * p, q, i, jl))
                .collect();
            // sin(2 q j pi / (NY + 1)) is odd about the mid-line.
            let y: Vec<f64> = MODES
                .iter()
                .map(|&(p, q)| sign * 0.3 * mode(p, 2 * q, i, jl))
                .collect();
            let z: Vec<f64> = MODES.iter().map(|&(p, q)| mode(p, q, i, jl)).collect();
            for (axis, row) in [("x", x), ("y", y), ("z", z)] {
                labels.push(format!("{}.{axis}", node(i, j)));
                rows.push(row);
            }
        }
        CandidateShapes::from_rows(labels, &rows).unwrap()
    };
    let nodes = |o: PlacementOptions| o.grouping(Grouping::Node);
    let plain = place(
        &build(false),
        &nodes(
            PlacementOptions::new(10)
                .equivalence_tolerance(0.0)
                .unwrap(),
        ),
    )
    .unwrap();
    let merged = place(&build(false), &nodes(PlacementOptions::new(10))).unwrap();
    let half = place(
        &build(true),
        &nodes(
            PlacementOptions::new(10)
                .equivalence_tolerance(0.0)
                .unwrap(),
        ),
    )
    .unwrap();
    let mirror_node = |n: &String| mirror(&format!("{n}.z")).trim_end_matches(".z").to_string();
    let pairs = |ns: &[String]| {
        ns.iter()
            .any(|n| mirror_node(n) != *n && ns.contains(&mirror_node(n)))
    };
    assert!(
        pairs(&plain.nodes),
        "plain EfI keeps mirror nodes: {:?}",
        plain.nodes
    );
    assert!(!pairs(&merged.nodes), "{:?}", merged.nodes);
    assert_eq!(merged.nodes, half.nodes);
    assert_eq!(merged.equivalents.len(), NX * (NY / 2));
}
