//! The [`Model`] trait: anything that maps a parameter vector to time histories.

use rayon::prelude::*;

use crate::error::{CoreError, Result};
use crate::histories::Histories;
use crate::points::PointRows;
use crate::space::ParameterSpace;

/// A simulation model: a parameter space and a map from a point of it to time histories.
///
/// Implement it for a built-in solver, a wrapper that launches an external code, or an
/// analytic stand-in. `simulate` must be deterministic for a given point (a stochastic model
/// takes its seed as a parameter) so that studies are reproducible. Implementors are `Sync`
/// so that [`simulate_batch`](Model::simulate_batch) can run points in parallel.
pub trait Model: Sync {
    /// The parameters that [`simulate`](Model::simulate) takes, in order.
    fn space(&self) -> &ParameterSpace;

    /// Runs the model at `params` (length `space().dim()`, in the space's units).
    ///
    /// # Errors
    /// Whatever the model reports; wrap foreign errors with [`CoreError::simulation`].
    fn simulate(&self, params: &[f64]) -> Result<Histories>;

    /// Runs the model at every point (one per row of an `n x dim` matrix, or, for
    /// convenience, a slice of rows), in parallel with rayon, and returns the outcomes in
    /// input order. A failed run (wrong length, non-finite coordinate or an error from
    /// `simulate`) is reported with its index and does not stop or lose the others.
    fn simulate_batch<'p>(&self, points: impl Into<PointRows<'p>>) -> BatchResults
    where
        Self: Sized,
    {
        let points = points.into();
        let runs = (0..points.len())
            .into_par_iter()
            .map(|index| {
                let point = points.point(index);
                check_point(self.space(), &point)
                    .and_then(|()| self.simulate(&point))
                    .map_err(|error| RunFailure { index, error })
            })
            .collect();
        BatchResults { runs }
    }
}

fn check_point(space: &ParameterSpace, point: &[f64]) -> Result<()> {
    // `to_unit` checks the length and finiteness and names the parameter at fault.
    space.to_unit(point).map(|_| ())
}

/// A run of a batch that failed: its position in the batch and why.
#[derive(Debug, thiserror::Error)]
#[error("run {index}: {error}")]
pub struct RunFailure {
    /// 0-based position of the point in the batch.
    pub index: usize,
    /// What went wrong.
    #[source]
    pub error: CoreError,
}

/// The outcomes of [`Model::simulate_batch`], one per input point, in input order.
#[derive(Debug)]
pub struct BatchResults {
    /// `runs[i]` is the outcome of point `i`.
    pub runs: Vec<std::result::Result<Histories, RunFailure>>,
}

impl BatchResults {
    /// Number of runs.
    pub fn len(&self) -> usize {
        self.runs.len()
    }

    /// Whether the batch was empty.
    pub fn is_empty(&self) -> bool {
        self.runs.is_empty()
    }

    /// The failed runs.
    pub fn failures(&self) -> impl Iterator<Item = &RunFailure> {
        self.runs.iter().filter_map(|r| r.as_ref().err())
    }

    /// The successful runs with their indices.
    pub fn successes(&self) -> impl Iterator<Item = (usize, &Histories)> {
        self.runs
            .iter()
            .enumerate()
            .filter_map(|(i, r)| r.as_ref().ok().map(|h| (i, h)))
    }

    /// All histories in input order, or the first failure.
    ///
    /// # Errors
    /// The [`RunFailure`] of the lowest index that failed.
    pub fn into_all(self) -> std::result::Result<Vec<Histories>, RunFailure> {
        self.runs.into_iter().collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::space::Parameter;

    /// y(t) = a sin(b t) on one channel; fails when a < 0.
    struct Sine {
        space: ParameterSpace,
    }

    impl Model for Sine {
        fn space(&self) -> &ParameterSpace {
            &self.space
        }
        fn simulate(&self, p: &[f64]) -> Result<Histories> {
            if p[0] < 0.0 {
                return Err(CoreError::Invalid("negative amplitude".into()));
            }
            let y = (0..50)
                .map(|k| p[0] * (p[1] * k as f64 * 0.01).sin())
                .collect();
            Histories::from_channels(vec!["y".into()], vec![y], 0.01, 0.0, "")
        }
    }

    #[test]
    fn batch_keeps_order_and_failures() {
        let m = Sine {
            space: ParameterSpace::new(vec![
                Parameter::new("a", -1.0, 2.0, 1.0).unwrap(),
                Parameter::new("b", 0.0, 10.0, 1.0).unwrap(),
            ])
            .unwrap(),
        };
        let points: Vec<Vec<f64>> = (0..40)
            .map(|i| {
                if i == 7 {
                    vec![-0.5, 1.0]
                } else if i == 11 {
                    vec![1.0]
                } else {
                    vec![1.0 + i as f64 * 0.01, 2.0]
                }
            })
            .collect();
        let out = m.simulate_batch(&points);
        assert_eq!(out.len(), 40);
        let failed: Vec<usize> = out.failures().map(|f| f.index).collect();
        assert_eq!(failed, vec![7, 11]);
        for (i, h) in out.successes() {
            let expect = m.simulate(&points[i]).unwrap();
            assert_eq!(h, &expect);
        }
        assert_eq!(out.into_all().unwrap_err().index, 7);
        // The same points as a matrix give the same runs.
        let good: Vec<Vec<f64>> = (0..6).map(|i| vec![1.0 + i as f64 * 0.1, 2.0]).collect();
        let x = crate::points::from_rows(&good, "points").unwrap();
        let by_rows = m.simulate_batch(&good).into_all().unwrap();
        let by_matrix = m.simulate_batch(x.as_ref()).into_all().unwrap();
        assert_eq!(by_rows, by_matrix);
    }
}
