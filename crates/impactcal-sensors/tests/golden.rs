//! Golden values of reference/shapes-efi.md §4.1 (spring-mass chain) and §4.2 (triaxial).
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use approx::assert_abs_diff_eq;
use common::*;
use impactcal_sensors::{
    CandidateShapes, Elimination, Grouping, PlacementMethod, PlacementOptions, leverage_scores,
    place,
};

const CHAIN_E0: [f64; 10] = [
    0.128210, 0.322392, 0.333333, 0.245720, 0.264995, 0.333333, 0.285714, 0.217459, 0.333333,
    0.535510,
];

#[test]
fn chain_initial_leverages() {
    let e = leverage_scores(chain().as_ref()).unwrap();
    for (a, b) in e.iter().zip(CHAIN_E0) {
        assert_abs_diff_eq!(*a, b, epsilon = 1e-6);
    }
    assert_abs_diff_eq!(e.iter().sum::<f64>(), 3.0, epsilon = 1e-12);
    let el = Elimination::new(chain().as_ref(), 100).unwrap();
    for ((_, a), b) in el.scores().iter().zip(CHAIN_E0) {
        assert_abs_diff_eq!(*a, b, epsilon = 1e-6);
    }
}

#[test]
fn chain_removal_order_and_scores() {
    let expected = [
        (1, 0.128210),
        (8, 0.220060),
        (4, 0.261148),
        (5, 0.331246),
        (9, 0.392799),
        (2, 0.466563),
        (7, 0.491847),
    ];
    let mut el = Elimination::new(chain().as_ref(), 100).unwrap();
    for (dof, e) in expected {
        let (row, score) = el.remove_next().unwrap();
        assert_eq!(row + 1, dof);
        assert_abs_diff_eq!(score, e, epsilon = 1e-6);
    }
    // Three rows left for three shapes: every one is essential.
    assert_eq!(el.remove_next(), None);
    assert_eq!(el.remaining(), vec![2, 5, 9]);
    assert_abs_diff_eq!(el.log_determinant_ratio().exp(), 0.055298, epsilon = 1e-6);
}

#[test]
fn chain_kept_sets_and_determinant_ratios() {
    let c = chain_candidates();
    let cases: [(usize, &[usize], f64); 4] = [
        (6, &[2, 3, 6, 7, 9, 10], 0.335967),
        (5, &[2, 3, 6, 7, 10], 0.203999),
        (4, &[3, 6, 7, 10], 0.108821),
        (3, &[3, 6, 10], 0.055298),
    ];
    for (n, kept, ratio) in cases {
        let p = place(&c, &PlacementOptions::new(n)).unwrap();
        let labels: Vec<String> = kept.iter().map(|i| format!("{i}.x")).collect();
        assert_eq!(p.selected, labels, "N = {n}");
        assert_abs_diff_eq!(p.determinant_ratio, ratio, epsilon = 1e-6);
        // The ratio is the product of (1 - E) over the removals.
        let product: f64 = p
            .removal_order
            .iter()
            .map(|s| 1.0 - s.score.unwrap())
            .product();
        assert_abs_diff_eq!(product, p.determinant_ratio, epsilon = 1e-12);
        assert_eq!(p.counts_by_direction.x, n);
    }
}

#[test]
fn chain_matches_exhaustive_search() {
    let phi = chain();
    let full = gram_det(&phi, &(0..10).collect::<Vec<_>>());
    for n in 3..=5 {
        let (best, det) = exhaustive(&phi, n);
        let p = place(&chain_candidates(), &PlacementOptions::new(n)).unwrap();
        assert_eq!(p.selected_indices, best, "N = {n}");
        assert_abs_diff_eq!(p.determinant_ratio, det / full, epsilon = 1e-12);
    }
}

#[test]
fn chain_forward_greedy_from_pivoted_qr() {
    let c = chain_candidates();
    let p = place(
        &c,
        &PlacementOptions::new(3).method(PlacementMethod::Forward),
    )
    .unwrap();
    let mut start: Vec<&str> = p.addition_order.iter().map(|s| s.label.as_str()).collect();
    start.sort_unstable();
    assert_eq!(start, ["10.x", "3.x", "6.x"]);
    assert!(p.addition_order.iter().all(|s| s.score.is_none()));
    for n in 4..=6 {
        let fwd = place(
            &c,
            &PlacementOptions::new(n).method(PlacementMethod::Forward),
        )
        .unwrap();
        let bwd = place(&c, &PlacementOptions::new(n)).unwrap();
        assert_eq!(fwd.selected, bwd.selected, "N = {n}");
        assert_abs_diff_eq!(
            fwd.determinant_ratio,
            bwd.determinant_ratio,
            epsilon = 1e-12
        );
    }
}

#[test]
fn chain_quality_figures_for_four_sensors() {
    let p = place(&chain_candidates(), &PlacementOptions::new(4)).unwrap();
    assert_abs_diff_eq!(p.condition_number, 1.406667, epsilon = 1e-6);
    assert_abs_diff_eq!(p.max_auto_mac, 0.048640, epsilon = 1e-6);
    assert_abs_diff_eq!(p.max_off_diagonal, 0.048640_f64.sqrt(), epsilon = 1e-5);
}

const NODE_SCORES: [f64; 6] = [0.556343, 0.677179, 0.559299, 0.537234, 0.522569, 0.541720];

#[test]
fn triaxial_node_scores_are_exact_determinant_losses() {
    let phi = triaxial();
    let blocks: Vec<Vec<usize>> = (0..6).map(|b| vec![3 * b, 3 * b + 1, 3 * b + 2]).collect();
    let el = Elimination::with_blocks(phi.as_ref(), blocks, 100).unwrap();
    let full = gram_det(&phi, &(0..18).collect::<Vec<_>>());
    for ((b, score), golden) in el.scores().into_iter().zip(NODE_SCORES) {
        assert_abs_diff_eq!(score, golden, epsilon = 1e-6);
        let rest: Vec<usize> = (0..18).filter(|r| r / 3 != b).collect();
        assert_abs_diff_eq!(gram_det(&phi, &rest) / full, 1.0 - score, epsilon = 1e-10);
    }
}

#[test]
fn triaxial_backward_node_elimination() {
    let c = CandidateShapes::new(triaxial_labels(18), triaxial().as_ref()).unwrap();
    let p = place(&c, &PlacementOptions::new(3).grouping(Grouping::Node)).unwrap();
    let removed: Vec<&str> = p.removal_order.iter().map(|s| s.label.as_str()).collect();
    assert_eq!(removed, ["5", "3", "6"]);
    for (s, golden) in p.removal_order.iter().zip([0.522569, 0.568423, 0.592195]) {
        assert_abs_diff_eq!(s.score.unwrap(), golden, epsilon = 1e-6);
        assert_eq!(s.dofs.len(), 3);
    }
    assert_eq!(p.nodes, ["1", "2", "4"]);
    assert_eq!(p.selected.len(), 9);
    assert_abs_diff_eq!(p.determinant_ratio, 0.084028, epsilon = 1e-6);
    assert_eq!(
        (
            p.counts_by_direction.x,
            p.counts_by_direction.y,
            p.counts_by_direction.z
        ),
        (3, 3, 3)
    );

    let p = place(&c, &PlacementOptions::new(2).grouping(Grouping::Node)).unwrap();
    assert_eq!(p.removal_order[3].label, "4");
    assert_abs_diff_eq!(p.removal_order[3].score.unwrap(), 0.754829, epsilon = 1e-6);
    assert_eq!(p.nodes, ["1", "2"]);
    assert_abs_diff_eq!(p.determinant_ratio, 0.020601, epsilon = 1e-6);
}

#[test]
fn triaxial_per_dof_keeps_rows_8_11_15_18() {
    let c = CandidateShapes::new(triaxial_labels(18), triaxial().as_ref()).unwrap();
    let p = place(&c, &PlacementOptions::new(4)).unwrap();
    assert_eq!(p.selected_indices, [7, 10, 14, 17]);
    assert_eq!(p.nodes, ["3", "4", "5", "6"]);
}
