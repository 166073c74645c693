//! The loop's memory plan: what each stage holds and adds, as a formula of the loop's
//! shapes, checked before the stage allocates ([`crate::memory`]).
//!
//! Shapes: `S` channels compared over `T` samples (`n = S T` values), `R` values in one run
//! of the model (all its channels over its samples, what a run writes and the loop reads
//! back), `q` dense Jacobian columns at most (the declared parameters, `max_added`
//! candidates and the trigger offset), `K` candidates, `P` runs at a time in this process (0
//! when a worker runs them), `N` members of an M1 ensemble. In values of 8 bytes:
//!
//! - a run read back from its result file: its text (about 2.5 values' worth per value),
//!   the parsed histories, a filtered copy, the loop's channels: `6 R` (measured: reading,
//!   filtering and writing 1,215 channels x 501 samples peaks at 6.5 values per value);
//! - a run in this process: its histories, the text written and read back: `6 R` each, `P`
//!   at a time;
//! - held for the whole loop, beside what the caller holds: the nominal run (`R`), the test
//!   on the model's time base, the frame's test and weights, the spread, the nominal on the
//!   loop's channels and the working vectors of the fits (`8 n`), and up to five fits alive
//!   at once (the first calibration, the current one, a recalibration, its second polish
//!   from the best start and its control), each its response, residual and factored
//!   Jacobian (`q + 2` vectors): `R + (8 + 5 (q + 4)) n`;
//! - a Gauss-Newton Jacobian: its dense columns, their copy for the factorisation, the
//!   SVD's basis and work space, the nuisance columns and their orthonormal bases, the
//!   residual and the shifted responses: `(3 q + 8) n`, or `(q + 1) n` plus a run read back
//!   while its columns are made;
//! - an attribution: every candidate's unfitted direction and the time-scale signature
//!   kept for the scores, their coherences and the model-noise pass (`(K + 1) n`), the one
//!   being made (`5 n`), a run read back, a pass over the draws (`6 n`), the sensor
//!   patterns (`8 K S`, a map entry of about 64 bytes each);
//! - a pass over the model-noise draws: a run read back and `6 n` of working vectors;
//! - an M1 ensemble and a detection: `4 n + N T` and the residual's SVD, `4 n`.
//!
//! The loop's peak is what the process holds when the plan is made, plus the held part,
//! plus the largest stage; [`estimated_peak`] gives it for given shapes.

use crate::memory::Stages;

/// The shapes a loop's memory depends on (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LoopShapes {
    /// `S`: channels compared.
    pub channels: usize,
    /// `T`: samples compared per channel.
    pub samples: usize,
    /// `R`: values one model run writes (all its channels over all its samples).
    pub run_values: usize,
    /// `q`: dense Jacobian columns at most (declared parameters + `max_added` + 1).
    pub dense: usize,
    /// `K`: candidates the loop may consider.
    pub candidates: usize,
    /// `P`: runs at a time in this process (0 when a worker runs them).
    pub threads: usize,
    /// `N`: members of an M1 ensemble.
    pub m1_members: usize,
}

impl LoopShapes {
    fn n(&self) -> u64 {
        (self.channels * self.samples) as u64
    }

    fn read(&self) -> u64 {
        6 * self.run_values as u64
    }
}

impl Stages for LoopShapes {
    const WHO: &'static str = "the loop";

    fn held(&self) -> u64 {
        self.run_values as u64 + (8 + 5 * (self.dense as u64 + 4)) * self.n()
    }

    fn stages(&self) -> Vec<(&'static str, u64)> {
        let (n, q, k) = (self.n(), self.dense as u64, self.candidates as u64);
        let draws = self.read() + 6 * n;
        vec![
            (RUNS, self.threads as u64 * self.read()),
            ("a pass over the jitter ensemble", draws),
            (JACOBIAN, ((3 * q + 8) * n).max((q + 1) * n + self.read())),
            (
                ATTRIBUTION,
                (k + 1) * n + 5 * n + self.read().max(draws) + 8 * k * self.channels as u64,
            ),
            (
                "an M1 ensemble and a detection",
                4 * n + (self.m1_members * self.samples) as u64,
            ),
        ]
    }

    fn advice(&self, kind: &str) -> String {
        let what = if kind == RUNS || kind == "a pass over the jitter ensemble" {
            format!(
                "it grows with the values each run writes ({}) and the runs at a time ({})",
                self.run_values, self.threads
            )
        } else {
            format!(
                "it grows with the channels compared times their samples ({} x {} = {} \
                 values){}",
                self.channels,
                self.samples,
                self.n(),
                if kind == ATTRIBUTION {
                    format!(" and the candidates ({})", self.candidates)
                } else {
                    String::new()
                }
            )
        };
        let more = match kind {
            ATTRIBUTION => ", narrow [loop] candidates",
            RUNS => ", run fewer at a time (--threads)",
            _ => "",
        };
        format!(
            "{what}: compare fewer channels, a shorter window or a coarser output interval\
             {more}, or give more memory (--max-memory)"
        )
    }
}

/// The stage kind of a stage of model runs.
pub(crate) const RUNS: &str = "the model's runs";
/// The stage kind of a Gauss-Newton Jacobian.
pub(crate) const JACOBIAN: &str = "a Gauss-Newton Jacobian";
/// The stage kind of an attribution.
pub(crate) const ATTRIBUTION: &str = "an attribution";

/// The bytes a loop of `shapes` adds at its peak to what the process holds when it starts
/// (its nominal run aside): the plan the memory guard checks (see the module docs).
pub fn estimated_peak(shapes: &LoopShapes) -> u64 {
    shapes.peak()
}

/// The plan of one loop.
pub(crate) type Plan = crate::memory::Plan<LoopShapes>;
