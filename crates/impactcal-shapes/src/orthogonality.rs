//! Orthogonality of two shape sets (calibration metric M2, source paper Eq. 4.4), optimal
//! pairing and principal angles.

use faer::{Mat, MatRef};

use crate::assignment::max_weight_assignment;
use crate::checks::{finite_nonempty, numerical_rank};
use crate::decompose::ImpactShapes;
use crate::error::{Result, ShapesError};
use impactcal_core::error::{dimension_mismatch, invalid_option};

/// One analysis shape paired with one test shape.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ShapePair {
    /// 0-based index of the analysis shape.
    pub analysis: usize,
    /// 0-based index of the test shape.
    pub test: usize,
    /// `|M2|` of the pair: the cosine of the angle between the two shapes.
    pub value: f64,
}

/// The orthogonality matrix `|M2| = |Phi~^T Psi~|` of analysis shapes `Phi` and test shapes
/// `Psi` on the same channels, each column scaled to unit length (the tilde), read in
/// absolute value so that shape signs do not matter. Entry `(i, j)` is the cosine of the
/// angle between analysis shape `i` and test shape `j`; 1 means identical up to sign.
#[derive(Debug, Clone)]
pub struct Orthogonality {
    matrix: Mat<f64>,
    pairs: Vec<ShapePair>,
    principal_cosines: Vec<f64>,
}

impl Orthogonality {
    /// Compares two decompositions on the same channels. When both carry the same labels in
    /// another order, the analysis rows are reordered to the test's order first.
    ///
    /// # Errors
    /// [`ShapesError::LabelMismatch`] naming a channel present on one side only;
    /// otherwise as [`Orthogonality::from_matrices`].
    pub fn between(analysis: &ImpactShapes, test: &ImpactShapes) -> Result<Self> {
        let a = align_rows(
            analysis.shapes(),
            analysis.labels(),
            test.labels(),
            "analysis",
        )?;
        Self::from_matrices(a.as_ref(), test.shapes())
    }

    /// Compares shape matrices `analysis` (m x k_a) and `test` (m x k_t) whose rows are the
    /// same channels in the same order.
    ///
    /// # Errors
    /// [`CoreError::Empty`](impactcal_core::CoreError::Empty),
    /// [`CoreError::NonFinite`](impactcal_core::CoreError::NonFinite), a row-count mismatch,
    /// or a zero
    /// column (a shape of zero length cannot be normalised).
    pub fn from_matrices(analysis: MatRef<'_, f64>, test: MatRef<'_, f64>) -> Result<Self> {
        finite_nonempty("analysis shapes", analysis)?;
        finite_nonempty("test shapes", test)?;
        if analysis.nrows() != test.nrows() {
            return Err(dimension_mismatch(
                "channels of the analysis shapes (rows) vs test shapes",
                test.nrows(),
                analysis.nrows(),
            ));
        }
        let a = normalise_columns(analysis, "analysis")?;
        let t = normalise_columns(test, "test")?;
        let mut matrix = a.transpose() * &t;
        matrix
            .col_iter_mut()
            .for_each(|c| c.iter_mut().for_each(|x| *x = x.abs().min(1.0)));
        let (ka, kt) = matrix.shape();
        let weights: Vec<f64> = (0..ka)
            .flat_map(|i| (0..kt).map(move |j| (i, j)))
            .map(|(i, j)| matrix[(i, j)])
            .collect();
        let pairs = max_weight_assignment(&weights, ka, kt)
            .into_iter()
            .map(|(i, j)| ShapePair {
                analysis: i,
                test: j,
                value: matrix[(i, j)],
            })
            .collect();
        let qa = orthonormal_basis(a.as_ref())?;
        let qt = orthonormal_basis(t.as_ref())?;
        let cross = qa.transpose() * &qt;
        let principal_cosines = cross
            .singular_values()
            .map_err(|_| ShapesError::NoConvergence)?
            .into_iter()
            .map(|c| c.min(1.0))
            .collect();
        Ok(Orthogonality {
            matrix,
            pairs,
            principal_cosines,
        })
    }

    /// The matrix `|M2|`, analysis shapes as rows, test shapes as columns.
    pub fn matrix(&self) -> MatRef<'_, f64> {
        self.matrix.as_ref()
    }

    /// The one-to-one pairing of analysis and test shapes that maximises the sum of `|M2|`
    /// over `min(k_a, k_t)` pairs (Hungarian method), sorted by analysis index.
    pub fn pairs(&self) -> &[ShapePair] {
        &self.pairs
    }

    /// How many pairs have `|M2|` strictly above `threshold` (the paper counts `> 0.9`).
    pub fn matched_above(&self, threshold: f64) -> usize {
        self.pairs.iter().filter(|p| p.value > threshold).count()
    }

    /// Cosines of the principal angles between the two spanned subspaces, non-increasing:
    /// the singular values of `Q_a^T Q_t` for orthonormal bases of both sets. All ones means
    /// the subspaces coincide even when individual shapes rotate within them.
    pub fn principal_cosines(&self) -> &[f64] {
        &self.principal_cosines
    }
}

fn normalise_columns(a: MatRef<'_, f64>, side: &str) -> Result<Mat<f64>> {
    let mut out = a.to_owned();
    for j in 0..out.ncols() {
        let norm = out.col(j).norm_l2();
        if norm == 0.0 {
            return Err(invalid_option(
                format!("{side} shape {j}"),
                0,
                "a shape of zero length cannot be normalised",
            ));
        }
        out.col_mut(j).iter_mut().for_each(|x| *x /= norm);
    }
    Ok(out)
}

/// Orthonormal basis of the column space, truncated at the numerical rank.
fn orthonormal_basis(a: MatRef<'_, f64>) -> Result<Mat<f64>> {
    let svd = a.thin_svd().map_err(|_| ShapesError::NoConvergence)?;
    let s: Vec<f64> = svd.S().column_vector().iter().copied().collect();
    let r = numerical_rank(&s, a.nrows(), a.ncols()).max(1);
    Ok(svd.U().subcols(0, r).to_owned())
}

/// Rows of `shapes` (labelled `labels`) reordered to `target` order.
pub(crate) fn align_rows(
    shapes: MatRef<'_, f64>,
    labels: &[String],
    target: &[String],
    side: &str,
) -> Result<Mat<f64>> {
    if labels == target {
        return Ok(shapes.to_owned());
    }
    let index: std::collections::HashMap<&str, usize> = labels
        .iter()
        .enumerate()
        .map(|(i, l)| (l.as_str(), i))
        .collect();
    let mut rows = Vec::with_capacity(target.len());
    for l in target {
        match index.get(l.as_str()) {
            Some(&i) => rows.push(i),
            None => {
                return Err(ShapesError::LabelMismatch {
                    label: l.clone(),
                    side: if side == "analysis" {
                        "test"
                    } else {
                        "analysis"
                    }
                    .into(),
                });
            }
        }
    }
    if let Some(extra) = labels.iter().find(|l| !target.contains(l)) {
        return Err(ShapesError::LabelMismatch {
            label: extra.clone(),
            side: side.into(),
        });
    }
    Ok(Mat::from_fn(target.len(), shapes.ncols(), |i, j| {
        shapes[(rows[i], j)]
    }))
}
