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
//!   loop's channels and the working vectors of the fits (`8 n`), and up to four fits alive
//!   at once (the first calibration, the current one, a recalibration and its control),
//!   each its response, residual and factored Jacobian (`q + 2` vectors): `R + (8 + 4 (q +
//!   4)) n`;
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

use crate::error::Result;
use crate::memory::{F64, Guard, Need, human};

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

    fn runs(&self) -> u64 {
        self.threads as u64 * 6 * self.run_values as u64
    }

    /// Values held through the loop (beside what the process holds when it is planned).
    pub fn held(&self) -> u64 {
        self.run_values as u64 + (8 + 4 * (self.dense as u64 + 4)) * self.n()
    }

    /// Each kind of stage with the values it adds at its peak, in the loop's order.
    pub fn stages(&self) -> Vec<(&'static str, u64)> {
        let (n, q, k) = (self.n(), self.dense as u64, self.candidates as u64);
        let draws = self.read() + 6 * n;
        vec![
            ("the model's runs", self.runs()),
            ("a pass over the jitter ensemble", draws),
            (
                "a Gauss-Newton Jacobian",
                ((3 * q + 8) * n).max((q + 1) * n + self.read()),
            ),
            (
                "an attribution",
                (k + 1) * n + 5 * n + self.read().max(draws) + 8 * k * self.channels as u64,
            ),
            (
                "an M1 ensemble and a detection",
                4 * n + (self.m1_members * self.samples) as u64,
            ),
        ]
    }

    /// The bytes the loop adds at its peak to what the process holds when it is planned:
    /// the held part and the largest stage.
    pub fn peak_bytes(&self) -> u64 {
        let stage = self.stages().iter().map(|s| s.1).max().unwrap_or(0);
        F64 * (self.held() + stage)
    }

    /// What to change when a stage does not fit.
    fn advice(&self, stage: &str) -> String {
        let base = format!(
            "it grows with the channels compared times their samples ({} x {} = {} values)",
            self.channels,
            self.samples,
            self.n()
        );
        let what = match stage {
            "the model's runs" | "a pass over the jitter ensemble" => format!(
                "it grows with the values each run writes ({}) and the runs at a time ({})",
                self.run_values, self.threads
            ),
            "an attribution" => format!("{base} and the candidates ({})", self.candidates),
            _ => base,
        };
        format!(
            "{what}: compare fewer channels, a shorter window or a coarser output interval{}, \
             or give more memory (--max-memory)",
            if stage == "an attribution" {
                ", narrow [loop] candidates"
            } else if stage == "the model's runs" {
                ", run fewer at a time (--threads)"
            } else {
                ""
            }
        )
    }

    /// The need of stage `kind` (one of [`stages`](Self::stages)) as checked before it
    /// allocates, named `stage` (a journal stage, or the step).
    pub(crate) fn need(&self, kind: &str, stage: &str) -> Need {
        let values = self
            .stages()
            .into_iter()
            .find(|s| s.0 == kind)
            .map_or(0, |s| s.1);
        Need {
            stage: stage.to_string(),
            bytes: F64 * values,
            advice: self.advice(kind),
        }
    }
}

/// The bytes a loop of `shapes` adds at its peak to what the process holds when it starts
/// (its nominal run aside): the plan the memory guard checks (see the module docs).
pub fn estimated_peak(shapes: &LoopShapes) -> u64 {
    shapes.peak_bytes()
}

/// The plan of one loop: its shapes and the guard that checks them.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Plan {
    pub shapes: LoopShapes,
    pub guard: Guard,
}

impl Plan {
    /// Checks the whole loop before its first stage: for each stage, what the process
    /// holds, the loop's held part and the stage together.
    ///
    /// # Errors
    /// [`crate::CalibrateError::Memory`] naming the first stage that would not fit.
    pub fn check_all(&self) -> Result<()> {
        let held = F64 * self.shapes.held();
        for (kind, values) in self.shapes.stages() {
            let mut need = self.shapes.need(kind, kind);
            need.bytes = held + F64 * values;
            need.advice = format!(
                "{} (the loop holds about {} throughout)",
                need.advice,
                human(held)
            );
            self.guard.check(&need)?;
        }
        Ok(())
    }

    /// Checks stage `kind` named `stage` against what the process holds now.
    ///
    /// # Errors
    /// [`crate::CalibrateError::Memory`] when it would not fit.
    pub fn check(&self, kind: &str, stage: &str) -> Result<()> {
        self.guard.check(&self.shapes.need(kind, stage))
    }
}
