//! Shared helpers of the integration tests.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use impactcal_sensors::CandidateShapes;

/// The fixed-free chain of 10 unit masses: phi_j(i) = sin((2j-1) i pi / 21), j = 1..3.
pub fn chain() -> Mat<f64> {
    Mat::from_fn(10, 3, |i, j| {
        ((2 * j + 1) as f64 * (i + 1) as f64 * std::f64::consts::PI / 21.0).sin()
    })
}

/// Chain candidates labelled `1.x` .. `10.x`.
pub fn chain_candidates() -> CandidateShapes {
    let labels = (1..=10).map(|i| format!("{i}.x")).collect();
    CandidateShapes::new(labels, chain().as_ref()).unwrap()
}

/// The triaxial example: P(r, j) = sin(0.45 r j), r = 1..18, j = 1..4.
pub fn triaxial() -> Mat<f64> {
    Mat::from_fn(18, 4, |r, j| (0.45 * (r + 1) as f64 * (j + 1) as f64).sin())
}

/// Labels `<node>.<dir>` for rows r = 1..n: node ceil(r/3), direction (r-1) mod 3.
pub fn triaxial_labels(n: usize) -> Vec<String> {
    (0..n)
        .map(|r| format!("{}.{}", r / 3 + 1, ["x", "y", "z"][r % 3]))
        .collect()
}

/// det(Phi_rows^T Phi_rows) by Gaussian elimination with partial pivoting.
pub fn gram_det(phi: &Mat<f64>, rows: &[usize]) -> f64 {
    let k = phi.ncols();
    let mut a: Vec<f64> = (0..k * k)
        .map(|ij| {
            let (i, j) = (ij / k, ij % k);
            rows.iter().map(|&r| phi[(r, i)] * phi[(r, j)]).sum()
        })
        .collect();
    let mut det = 1.0;
    for c in 0..k {
        let p = (c..k)
            .max_by(|&x, &y| a[x * k + c].abs().total_cmp(&a[y * k + c].abs()))
            .unwrap();
        if p != c {
            for j in 0..k {
                a.swap(p * k + j, c * k + j);
            }
            det = -det;
        }
        let piv = a[c * k + c];
        det *= piv;
        if piv == 0.0 {
            return 0.0;
        }
        for i in c + 1..k {
            let f = a[i * k + c] / piv;
            for j in c..k {
                a[i * k + j] -= f * a[c * k + j];
            }
        }
    }
    det
}

/// All subsets of `0..n` of size `m`, in lexicographic order.
pub fn subsets(n: usize, m: usize) -> Vec<Vec<usize>> {
    let mut out = Vec::new();
    let mut cur = Vec::new();
    fn rec(start: usize, n: usize, m: usize, cur: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
        if cur.len() == m {
            out.push(cur.clone());
            return;
        }
        for i in start..n {
            if n - i < m - cur.len() {
                break;
            }
            cur.push(i);
            rec(i + 1, n, m, cur, out);
            cur.pop();
        }
    }
    rec(0, n, m, &mut cur, &mut out);
    out
}

/// The D-optimal subset of size `m` by exhaustive search, and its determinant.
pub fn exhaustive(phi: &Mat<f64>, m: usize) -> (Vec<usize>, f64) {
    subsets(phi.nrows(), m)
        .into_iter()
        .map(|s| {
            let d = gram_det(phi, &s);
            (s, d)
        })
        .fold((Vec::new(), f64::NEG_INFINITY), |best, cur| {
            if cur.1 > best.1 { cur } else { best }
        })
}
