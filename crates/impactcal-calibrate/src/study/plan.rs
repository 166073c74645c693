//! The study's memory plan: what each stage holds and adds, as a formula of the study's
//! shapes, checked before the stage allocates ([`crate::memory`]).
//!
//! Shapes: `R` values in one run of the model (all its channels over its `T` samples),
//! `C` objective channels, `N` ensemble runs, `k` impact shapes, `K` sensors, `d`
//! parameters, `B` base rows of the Sobol' design, `P` runs at a time in this process. In
//! values of 8 bytes:
//!
//! - held through the study: the nominal run and its filtered copy, the jitter ensemble's
//!   nominal and spread (`4 R`), the test and the baseline on the objective channels and
//!   the ensemble's norm histories (`2 C T + N T`);
//! - a run in this process, or read back from its result file: `6 R` (its text, the parsed
//!   histories, a filtered copy), `P` at a time;
//! - the spread of the jitter ensemble: a run read back and two accumulators, `8 R`;
//! - sensor placement: the ensemble's objective channels as one matrix, `C x N T`, and its
//!   SVD: the thin SVD's bases and work space, `3 C N T`, or with the randomized solver
//!   (`min(C, N T) >= 400`, `k + 10 <= min / 4`) the matrix and `4 (C + N T) (k + 10)`;
//! - the surrogates of `Q(t)` and of the sensor histories: the `N x K T` matrix of sensor
//!   histories and the fit's tables, `4 N K T`;
//! - the Sobol' indices over time: `2 B (d + 2) T` surrogate values.

use crate::memory::Stages;

/// The shapes a study's memory depends on (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StudyShapes {
    /// `R`: values one model run writes.
    pub run_values: usize,
    /// `T`: samples per channel.
    pub samples: usize,
    /// `C`: objective channels.
    pub channels: usize,
    /// `N`: ensemble runs.
    pub runs: usize,
    /// `k`: impact shapes kept for placement.
    pub shapes: usize,
    /// `K`: sensors.
    pub sensors: usize,
    /// `d`: parameters.
    pub parameters: usize,
    /// `B`: base rows of the Sobol' design.
    pub sobol_rows: usize,
    /// `P`: runs at a time in this process.
    pub threads: usize,
}

impl Stages for StudyShapes {
    const WHO: &'static str = "the study";

    fn held(&self) -> u64 {
        (4 * self.run_values + 2 * self.channels * self.samples + self.runs * self.samples) as u64
    }

    fn stages(&self) -> Vec<(&'static str, u64)> {
        let (r, t, c, n) = (
            self.run_values as u64,
            self.samples as u64,
            self.channels as u64,
            self.runs as u64,
        );
        let small = c.min(n * t);
        let randomized = small >= 400 && (self.shapes as u64) + 10 <= small / 4;
        let placement = if randomized {
            c * n * t + 4 * (c + n * t) * (self.shapes as u64 + 10)
        } else {
            3 * c * n * t
        };
        vec![
            ("the model's runs", 6 * r * (self.threads as u64).max(1)),
            ("the spread of the jitter ensemble", 8 * r),
            (PLACEMENT, placement + 6 * r),
            (SURROGATES, 4 * n * self.sensors as u64 * t + 6 * r),
            (
                SENSITIVITY,
                2 * (self.sobol_rows * (self.parameters + 2)) as u64 * t,
            ),
        ]
    }

    fn advice(&self, kind: &str) -> String {
        let what = match kind {
            PLACEMENT => format!(
                "it grows with the objective channels times the ensemble's runs times the \
                 samples ({} x {} x {}): fewer channels, fewer runs ([study] ensemble), a \
                 shorter window or a coarser output interval",
                self.channels, self.runs, self.samples
            ),
            SURROGATES => format!(
                "it grows with the runs times the sensors times the samples ({} x {} x {}): \
                 fewer sensors or runs, a shorter window or a coarser output interval",
                self.runs, self.sensors, self.samples
            ),
            SENSITIVITY => format!(
                "it grows with the design's rows times the samples ({} x {} x {}): fewer \
                 [study] sensitivity_samples, a shorter window or a coarser output interval",
                self.sobol_rows,
                self.parameters + 2,
                self.samples
            ),
            _ => format!(
                "it grows with the values each run writes ({}) and the runs at a time ({}): \
                 a model with fewer output channels, a shorter window or a coarser output \
                 interval, fewer runs at a time (--threads)",
                self.run_values, self.threads
            ),
        };
        format!("{what}, or give more memory (--max-memory)")
    }
}

/// The stage kind of the sensor placement.
pub(crate) const PLACEMENT: &str = "sensor placement on the ensemble's impact shapes";
/// The stage kind of the surrogates.
pub(crate) const SURROGATES: &str = "the surrogates";
/// The stage kind of the Sobol' indices.
pub(crate) const SENSITIVITY: &str = "the Sobol' indices over time";

/// The bytes a study of `shapes` adds at its peak to what the process holds when it is
/// planned (its nominal run aside).
pub fn estimated_peak(shapes: &StudyShapes) -> u64 {
    shapes.peak()
}

/// The plan of one study.
pub(crate) type Plan = crate::memory::Plan<StudyShapes>;
