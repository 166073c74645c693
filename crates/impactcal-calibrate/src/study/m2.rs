//! Calibration metric M2: the orthogonality of test and model impact shapes.

use impactcal_core::Histories;
use impactcal_shapes::{ImpactShapes, Orthogonality, ShapeOptions};
use serde::{Deserialize, Serialize};

use crate::error::Result;

/// M2 of one model run against the test on the same channels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct M2Result {
    /// `|M2|`, model shapes as rows, test shapes as columns.
    pub matrix: Vec<Vec<f64>>,
    /// The optimal one-to-one pairing `(model shape, test shape, |M2|)`.
    pub pairs: Vec<(usize, usize, f64)>,
    /// Pairs with `|M2| > 0.9` (the paper: 1 before calibration, 7 after).
    pub matched_above_0_9: usize,
    /// Contributions `sigma_i / sum sigma` of the model's shapes.
    pub model_contributions: Vec<f64>,
    /// Contributions of the test's shapes.
    pub test_contributions: Vec<f64>,
    /// The test's first impact shapes (at most [`SHAPES_DRAWN`]), each one value per
    /// compared channel in the channels' order, of unit norm, its sign chosen so that its
    /// entry of largest magnitude is positive (an SVD fixes a shape only up to sign): what
    /// a report draws on the structure. Empty in results written before it was kept.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub test_shapes: Vec<Vec<f64>>,
}

/// How many of the test's impact shapes an [`M2Result`] keeps for drawing.
pub const SHAPES_DRAWN: usize = 2;

/// Column `j` of `shapes` with its sign chosen so that the entry of largest magnitude is
/// positive.
fn signed_shape(shapes: faer::MatRef<'_, f64>, j: usize) -> Vec<f64> {
    let col: Vec<f64> = (0..shapes.nrows()).map(|i| shapes[(i, j)]).collect();
    let peak = col
        .iter()
        .copied()
        .fold(0.0_f64, |a, v| if v.abs() > a.abs() { v } else { a });
    let sign = if peak < 0.0 { -1.0 } else { 1.0 };
    col.into_iter().map(|v| sign * v).collect()
}

/// M2 of `model` against `test` on `channels` with `shapes` shapes a side (capped by the
/// rank the data can carry).
///
/// # Errors
/// Shape errors (for example a run without signal on these channels).
pub fn m2(
    model: &Histories,
    test: &Histories,
    channels: &[String],
    shapes: usize,
) -> Result<M2Result> {
    let m = model.select(channels)?;
    let t = test.select(channels)?;
    let k = shapes.min(channels.len()).min(t.samples()).max(1);
    let sm = ImpactShapes::from_histories(&m, &ShapeOptions::count(k))?;
    let st = ImpactShapes::from_histories(&t, &ShapeOptions::count(k))?;
    let o = Orthogonality::between(&sm, &st)?;
    let mat = o.matrix();
    Ok(M2Result {
        matrix: (0..mat.nrows())
            .map(|i| (0..mat.ncols()).map(|j| mat[(i, j)]).collect())
            .collect(),
        pairs: o
            .pairs()
            .iter()
            .map(|p| (p.analysis, p.test, p.value))
            .collect(),
        matched_above_0_9: o.matched_above(0.9),
        model_contributions: sm.contributions(),
        test_contributions: st.contributions(),
        test_shapes: (0..st.len().min(SHAPES_DRAWN))
            .map(|j| signed_shape(st.shapes(), j))
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use impactcal_core::Histories;

    /// Two channels moving in proportion 3 : -4 make one shape, (0.6, -0.8) up to sign;
    /// kept with its larger entry positive: (-0.6, 0.8).
    #[test]
    fn keeps_the_test_shapes_with_a_fixed_sign() {
        let t: Vec<f64> = (0..50).map(|k| k as f64 * 1e-3).collect();
        let pulse: Vec<f64> = t.iter().map(|t| (60.0 * t).sin()).collect();
        let other: Vec<f64> = t.iter().map(|t| (150.0 * t).sin() * 0.01).collect();
        let mut data: Vec<f64> = pulse.iter().zip(&other).map(|(p, o)| 3.0 * p + o).collect();
        data.extend(pulse.iter().zip(&other).map(|(p, o)| -4.0 * p + o));
        let h = Histories::new(
            vec!["a".into(), "b".into()],
            t.len(),
            1e-3,
            0.0,
            "in/s",
            data,
        )
        .expect("histories");
        let r = m2(&h, &h, &["a".into(), "b".into()], 2).expect("m2");
        assert_eq!(r.test_shapes.len(), 2);
        let s = &r.test_shapes[0];
        assert!(
            (s[0] + 0.6).abs() < 1e-3 && (s[1] - 0.8).abs() < 1e-3,
            "{s:?}"
        );
        let norm: f64 = r.test_shapes[1].iter().map(|v| v * v).sum();
        assert!((norm - 1.0).abs() < 1e-9);
    }
}
