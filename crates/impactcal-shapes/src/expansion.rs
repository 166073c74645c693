//! Expansion of measured channels to unmeasured ones through model shapes (source paper
//! Eqs. 4.5-4.8, the SEREP form).

use faer::{Mat, MatRef};
use impactcal_core::Histories;

use crate::checks::{finite_nonempty, numerical_rank};
use crate::decompose::ImpactShapes;
use crate::error::{Result, ShapesError};
use impactcal_core::error::{dimension_mismatch, invalid_option};

/// Unmeasured responses estimated from measured ones.
///
/// With the model's shapes split into rows at the measured channels `Phi` (n_a x k) and at
/// the unmeasured channels `K` (n_o x k), the measured data `y(t)` (n_a x L) is fitted in
/// the least-squares sense, `q(t) = argmin ||Phi q - y(t)||`, and the expansion is
/// `y_e(t) = K q(t) = K (Phi^T Phi)^-1 Phi^T y(t)`. The fit uses the SVD of `Phi`
/// (`q = V S^-1 U^T y`), never the normal equations. Noise in `y` is amplified by at most
/// `sigma_max(K) / sigma_min(Phi)`, so [`condition`](Self::condition) = `cond(Phi)` is
/// reported with every expansion.
#[derive(Debug, Clone)]
pub struct Expansion {
    histories: Histories,
    condition: f64,
    sigma_min: f64,
    coordinates: Mat<f64>,
}

impl Expansion {
    /// Expands `measured` (a subset of the model's channels, by label) to every model
    /// channel it does not contain, using the first `shapes` model shapes (all kept shapes
    /// when `None`). The result is on `measured`'s time base and unit.
    ///
    /// # Errors
    /// [`ShapesError::LabelMismatch`] for a measured channel the model lacks;
    /// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) when every
    /// model channel is measured (nothing to
    /// expand), or `shapes` is zero or exceeds the model's; [`ShapesError::RankDeficient`]
    /// when fewer channels are measured than shapes are used, or `Phi` is numerically
    /// rank deficient.
    pub fn compute(
        model: &ImpactShapes,
        measured: &Histories,
        shapes: Option<usize>,
    ) -> Result<Self> {
        let k = shapes.unwrap_or(model.len());
        if k == 0 || k > model.len() {
            return Err(invalid_option(
                "shapes",
                k,
                format!("cannot use {k} shapes: the model has {}", model.len()),
            ));
        }
        let index: std::collections::HashMap<&str, usize> = model
            .labels()
            .iter()
            .enumerate()
            .map(|(i, l)| (l.as_str(), i))
            .collect();
        let mut measured_rows = Vec::with_capacity(measured.channels());
        for l in measured.labels() {
            match index.get(l.as_str()) {
                Some(&i) => measured_rows.push(i),
                None => {
                    return Err(ShapesError::LabelMismatch {
                        label: l.clone(),
                        side: "measured data".into(),
                    });
                }
            }
        }
        let unmeasured: Vec<usize> = (0..model.channels())
            .filter(|i| !measured_rows.contains(i))
            .collect();
        if unmeasured.is_empty() {
            return Err(invalid_option(
                "measured channels",
                measured_rows.len(),
                "every model channel is measured: nothing to expand",
            ));
        }
        let u = model.shapes();
        let phi = Mat::from_fn(measured_rows.len(), k, |i, j| u[(measured_rows[i], j)]);
        let kmat = Mat::from_fn(unmeasured.len(), k, |i, j| u[(unmeasured[i], j)]);
        let samples = measured.samples();
        let data = measured.data();
        let y = Mat::from_fn(measured.channels(), samples, |i, j| data[i * samples + j]);
        let (ye, q, condition, sigma_min) = expand_matrix(phi.as_ref(), kmat.as_ref(), y.as_ref())?;
        let labels = unmeasured
            .iter()
            .map(|&i| model.labels()[i].clone())
            .collect();
        let values: Vec<f64> = (0..ye.nrows())
            .flat_map(|i| (0..samples).map(move |j| (i, j)))
            .map(|(i, j)| ye[(i, j)])
            .collect();
        let histories = Histories::new(
            labels,
            samples,
            measured.dt(),
            measured.start(),
            measured.unit(),
            values,
        )?;
        Ok(Expansion {
            histories,
            condition,
            sigma_min,
            coordinates: q,
        })
    }

    /// The expanded histories of the unmeasured channels, in model channel order.
    pub fn histories(&self) -> &Histories {
        &self.histories
    }

    /// `cond(Phi) = sigma_max / sigma_min` of the shapes at the measured channels.
    pub fn condition(&self) -> f64 {
        self.condition
    }

    /// `sigma_min(Phi)`: the noise amplification bound is `sigma_max(K) / sigma_min(Phi)`.
    pub fn sigma_min(&self) -> f64 {
        self.sigma_min
    }

    /// The fitted shape coordinates `q(t)` (k x L).
    pub fn coordinates(&self) -> MatRef<'_, f64> {
        self.coordinates.as_ref()
    }
}

/// `Y_e = K Phi^+ Y` for `phi` (n_a x k), `k_rows` (n_o x k), `y` (n_a x L), with `Phi^+`
/// applied through the thin SVD of `Phi`. Returns `(Y_e, Q = Phi^+ Y, cond(Phi),
/// sigma_min(Phi))`.
///
/// # Errors
/// [`CoreError::Empty`](impactcal_core::CoreError::Empty) /
/// [`CoreError::NonFinite`](impactcal_core::CoreError::NonFinite) for bad input, a dimension mismatch,
/// [`ShapesError::RankDeficient`] when `n_a < k` or `Phi` has numerical rank below `k`.
pub fn expand_matrix(
    phi: MatRef<'_, f64>,
    k_rows: MatRef<'_, f64>,
    y: MatRef<'_, f64>,
) -> Result<(Mat<f64>, Mat<f64>, f64, f64)> {
    finite_nonempty("shapes at measured channels", phi)?;
    finite_nonempty("measured data", y)?;
    if k_rows.ncols() != phi.ncols() {
        return Err(dimension_mismatch(
            "shapes at unmeasured channels (columns)",
            phi.ncols(),
            k_rows.ncols(),
        ));
    }
    if y.nrows() != phi.nrows() {
        return Err(dimension_mismatch(
            "measured channels (rows of the data)",
            phi.nrows(),
            y.nrows(),
        ));
    }
    let (na, k) = phi.shape();
    if na < k {
        return Err(ShapesError::RankDeficient {
            rank: na,
            shapes: k,
            channels: na,
            condition: f64::INFINITY,
        });
    }
    let svd = phi.thin_svd().map_err(|_| ShapesError::NoConvergence)?;
    let s: Vec<f64> = svd.S().column_vector().iter().copied().collect();
    let rank = numerical_rank(&s, na, k);
    let sigma_min = s[k - 1];
    let condition = if sigma_min > 0.0 {
        s[0] / sigma_min
    } else {
        f64::INFINITY
    };
    if rank < k {
        return Err(ShapesError::RankDeficient {
            rank,
            shapes: k,
            channels: na,
            condition,
        });
    }
    let mut uty = svd.U().transpose() * y;
    for (i, &si) in s.iter().enumerate() {
        uty.row_mut(i).iter_mut().for_each(|x| *x /= si);
    }
    let q = svd.V() * &uty;
    let ye = k_rows * &q;
    Ok((ye, q, condition, sigma_min))
}
