//! The fallback when no candidate explains the residual: a low-rank discrepancy
//! `delta_s(t) = sum_i sigma_i u_is v_i(t) / w_s(t)`, the leading singular components of the
//! whitened residual that stand above the noise edge (at least one, at most three),
//! reported as **unattributed model-form error** with its sensor pattern `u_i` and time
//! pattern `v_i`. It is a description of what is missing, never a physical effect.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::linalg::svd_rows;
use crate::error::Result;

/// One component of the discrepancy.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Component {
    /// Its singular value (whitened units).
    pub sigma: f64,
    /// Sensor pattern `u` (label -> entry).
    pub sensors: BTreeMap<String, f64>,
    /// Time pattern `v` (unit norm).
    pub time: Vec<f64>,
}

/// The unattributed model-form error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Discrepancy {
    /// The components kept.
    pub components: Vec<Component>,
    /// Fraction of the residual's weighted sum of squares they carry.
    pub energy_fraction: f64,
    /// The directions that came closest, with their explained fractions.
    pub closest: Vec<(String, f64)>,
}

/// The low-rank discrepancy of the whitened residual `e` (`S x T`) with `rank` components
/// (clamped to 1..=3).
///
/// # Errors
/// When the SVD fails.
pub(crate) fn fit(
    labels: &[String],
    e: &[f64],
    samples: usize,
    rank: usize,
    closest: Vec<(String, f64)>,
) -> Result<Discrepancy> {
    let (s, u, v) = svd_rows(e, labels.len(), samples)?;
    let keep = rank.clamp(1, 3).min(s.len());
    let total: f64 = e.iter().map(|x| x * x).sum();
    let kept: f64 = s[..keep].iter().map(|x| x * x).sum();
    Ok(Discrepancy {
        components: (0..keep)
            .map(|i| Component {
                sigma: s[i],
                sensors: labels
                    .iter()
                    .enumerate()
                    .map(|(r, l)| (l.clone(), u[(r, i)]))
                    .collect(),
                time: (0..samples).map(|k| v[(k, i)]).collect(),
            })
            .collect(),
        energy_fraction: if total > 0.0 { kept / total } else { 0.0 },
        closest,
    })
}
