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
    })
}
