//! Step-by-step backward elimination on a plain shape matrix.

use faer::MatRef;

use crate::engine::{Engine, Sweep};
use impactcal_core::CoreError;

use crate::error::{Result, SensorsError};
use crate::linalg::singular_values;
use impactcal_core::error::invalid_option;

/// Scores at or above `1 - ESSENTIAL` mark a block whose removal would make
/// `Phi^T Phi` singular.
pub const ESSENTIAL: f64 = 1e-10;

/// Kammer's backward elimination, one removal at a time, on an `s x k` shape matrix `Phi`
/// whose rows are grouped into blocks (one row per block for uniaxial sensors, the rows of a
/// node for triaxial ones).
///
/// The score of block `b` is `1 - det(I - E_bb)`, where `E_bb` is its block of the projector
/// `E = Phi (Phi^T Phi)^-1 Phi^T` on the rows still in the set; for a single row this is the
/// effective-independence value `E_D,i`. Removing the block multiplies `det(Phi^T Phi)` by
/// exactly `1 - score`. Scores are updated by Sherman-Morrison/Woodbury after each removal,
/// `O(s k)` per step, and recomputed from a fresh QR every `refresh_every` removals.
///
/// [`place`](crate::place) wraps this with labels, options and diagnostics; use
/// `Elimination` to watch the scores step by step or to stop on your own criterion.
///
/// ```
/// use faer::mat;
/// use impactcal_sensors::Elimination;
/// let phi = mat![[1.0, 0.0], [0.0, 1.0], [1.0, 1.0], [0.1, 0.0]];
/// let mut el = Elimination::new(phi.as_ref(), 100)?;
/// let (row, e) = el.remove_next().unwrap();
/// assert_eq!(row, 3);              // the weakest row goes first
/// assert!(e < 0.01);
/// assert_eq!(el.remaining(), vec![0, 1, 2]);
/// # Ok::<(), impactcal_sensors::SensorsError>(())
/// ```
pub struct Elimination {
    engine: Engine,
    log_ratio: f64,
}

impl Elimination {
    /// One block per row (uniaxial sensors).
    ///
    /// # Errors
    /// As [`Elimination::with_blocks`].
    pub fn new(phi: MatRef<'_, f64>, refresh_every: usize) -> Result<Self> {
        let blocks = (0..phi.nrows()).map(|i| vec![i]).collect();
        Elimination::with_blocks(phi, blocks, refresh_every)
    }

    /// Rows grouped into `blocks` (each of 1 to 3 rows; every row in at most one block; rows
    /// in no block are ignored).
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for an empty, oversized or out-of-range block or a row in
    /// two blocks; [`CoreError::NonFinite`] for a non-finite value; [`SensorsError::TooFewCandidates`] for fewer rows
    /// than columns; [`SensorsError::RankDeficient`] when the rows do not have full column
    /// rank (`sigma_min / sigma_max <= 1e-10`).
    pub fn with_blocks(
        phi: MatRef<'_, f64>,
        blocks: Vec<Vec<usize>>,
        refresh_every: usize,
    ) -> Result<Self> {
        let (s, k) = (phi.nrows(), phi.ncols());
        let mut seen = vec![false; s];
        for (b, rows) in blocks.iter().enumerate() {
            if rows.is_empty() || rows.len() > 3 {
                return Err(invalid_option(
                    format!("block {b}"),
                    format!("{} rows", rows.len()),
                    "a block has 1 to 3 rows",
                ));
            }
            for &r in rows {
                if r >= s || seen[r] {
                    return Err(invalid_option(
                        format!("block {b}"),
                        format!("row {r}"),
                        "the row is out of range or in two blocks",
                    ));
                }
                seen[r] = true;
            }
        }
        let used: Vec<usize> = (0..s).filter(|&r| seen[r]).collect();
        if used.len() < k || k == 0 {
            return Err(SensorsError::TooFewCandidates {
                candidates: used.len(),
                shapes: k,
            });
        }
        let mut flat = vec![0.0; s * k];
        for i in 0..s {
            for j in 0..k {
                let v = phi[(i, j)];
                if !v.is_finite() {
                    return Err(CoreError::NonFinite {
                        what: "shape matrix".into(),
                        location: format!("row {i}, column {j} (0-based)"),
                        value: v,
                    }
                    .into());
                }
                flat[i * k + j] = v;
            }
        }
        check_rank(&flat, k, &used, 1e-10)?;
        let nblocks = blocks.len();
        Ok(Elimination {
            engine: Engine::new(
                k,
                flat,
                blocks,
                vec![true; nblocks],
                (0..nblocks).collect(),
                Sweep::Remove,
                refresh_every,
            ),
            log_ratio: 0.0,
        })
    }

    /// Current scores `(block, score)` of the blocks still in the set, ascending block
    /// (for one row per block, the block is the row and the score is `E_D`).
    pub fn scores(&self) -> Vec<(usize, f64)> {
        self.engine.scores()
    }

    /// The same scores recomputed from scratch by a fresh QR of the remaining rows (a check
    /// on the updates; costs `O(s k^2)`).
    pub fn fresh_scores(&self) -> Vec<(usize, f64)> {
        self.engine.fresh_scores()
    }

    /// Blocks still in the set, ascending.
    pub fn remaining(&self) -> Vec<usize> {
        self.engine
            .in_set()
            .iter()
            .enumerate()
            .filter(|(_, s)| **s)
            .map(|(b, _)| b)
            .collect()
    }

    /// Removes the block of lowest score (ties: lowest block index) and returns it with its
    /// score at removal; `None` when every remaining block is essential (score
    /// `>= 1 - 1e-10`), which happens once the rows left number `k`.
    pub fn remove_next(&mut self) -> Option<(usize, f64)> {
        let (pos, block, score) = self.engine.best()?;
        if score >= 1.0 - ESSENTIAL {
            return None;
        }
        let ratio = self.engine.apply(pos);
        self.log_ratio += ratio.ln();
        Some((block, score))
    }

    /// `ln(det(A_now) / det(A_start))`, the sum of `ln(1 - score)` over the removals.
    pub fn log_determinant_ratio(&self) -> f64 {
        self.log_ratio
    }
}

/// Checks that `rows` of the row-major `phi` have full column rank; returns the singular
/// values.
pub(crate) fn check_rank(phi: &[f64], k: usize, rows: &[usize], tol: f64) -> Result<Vec<f64>> {
    let m = crate::linalg::gather(phi, k, rows);
    let s = singular_values(m.as_ref())?;
    let smax = s.first().copied().unwrap_or(0.0);
    let rank = s.iter().filter(|&&v| v > tol * smax).count();
    if rank < k {
        return Err(SensorsError::RankDeficient {
            rank,
            shapes: k,
            ratio: if smax > 0.0 { s[k - 1] / smax } else { 0.0 },
        });
    }
    Ok(s)
}
