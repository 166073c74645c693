//! The error type of `impactcal-calibrate`.

use impactcal_core::{CoreError, ErrorKind};

/// Everything that can go wrong when judging a model against a test.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CalibrateError {
    /// Reading, filtering or interpolating the data failed.
    #[error(transparent)]
    Core(#[from] CoreError),
    /// A curve on which a metric is undefined: a reference that is identically zero (no
    /// relative error exists), a computed curve that is identically zero (no phase exists),
    /// or a reference that is constant (ISO/TS 18571 has no corridor or slope for it).
    #[error("{what}: {reason}")]
    Degenerate {
        /// The channel or curve.
        what: String,
        /// Why the metric is undefined.
        reason: String,
    },
    /// Two curves of different lengths, or too short for the metric.
    #[error("{what}: {reason}")]
    Length {
        /// The channel or curve.
        what: String,
        /// What is wrong with the lengths.
        reason: String,
    },
    /// A report document that cannot be drawn as given: an invalid or repeated figure name,
    /// an interval or matrix cell outside its plot, a band whose upper edge lies below its
    /// lower edge, abscissae out of order, a blank axis label, negative values to stack.
    /// Wrong lengths, NaN/inf and empty data are the shared [`CoreError`] kinds.
    #[error("{what}: {reason}")]
    Report {
        /// The part of the document (for example ``figure `fig-m1`, series `test` ``).
        what: String,
        /// What is wrong with it.
        reason: String,
    },
    /// The plotting library failed to draw a figure of a valid document.
    #[error("figure `{figure}`: drawing failed: {message}")]
    Render {
        /// The figure's name.
        figure: String,
        /// The plotting library's message.
        message: String,
    },
    /// From the impact shapes (M2, expansion).
    #[error(transparent)]
    Shapes(#[from] impactcal_shapes::ShapesError),
    /// From sensor placement.
    #[error(transparent)]
    Sensors(#[from] impactcal_sensors::SensorsError),
    /// From the surrogates.
    #[error(transparent)]
    Erbf(#[from] impactcal_erbf::ErbfError),
    /// From the sensitivity analysis.
    #[error(transparent)]
    Sobol(#[from] impactcal_sobol::SobolError),
    /// From the CORS-RBF optimiser.
    #[error(transparent)]
    Cors(#[from] impactcal_cors::CorsError),
    /// A study that the data or options cannot support (no channel in common with the
    /// model, more sensors than channels, too few successful runs).
    #[error("{what}: {reason}")]
    Study {
        /// What is at fault.
        what: String,
        /// Why.
        reason: String,
    },
    /// The output folder holds the journal of another study (other model, space, test or
    /// options); nothing was written.
    #[error(
        "{dir}: holds the run journal of another study (fingerprint {found}, this study \
         {expected}); choose another output folder or remove it"
    )]
    ForeignJournal {
        /// The output folder.
        dir: String,
        /// The fingerprint found in the folder.
        found: String,
        /// This study's fingerprint.
        expected: String,
    },
    /// A journal file that cannot be read or written.
    #[error("{path}: {message}")]
    Journal {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// From the runner that executes a study's runs (its journal, its executor).
    #[error(transparent)]
    Runner(#[from] impactcal_runner::RunnerError),
    /// The test's record does not cover the model's window (the test is compared on the
    /// model's time points and is never extrapolated).
    #[error(
        "the test record covers [{}, {}] s but the model's window is [{}, {}] s; the test \
         must cover the whole window: {advice}",
        to_ns(*test_start),
        to_ns(*test_end),
        to_ns(*model_start),
        to_ns(*model_end)
    )]
    TestShorterThanModel {
        /// First time of the test's record.
        test_start: f64,
        /// Last time of the test's record.
        test_end: f64,
        /// First time of the model's window.
        model_start: f64,
        /// Last time of the model's window.
        model_end: f64,
        /// What to change (the key that sets the model's window, where one is known).
        advice: String,
    },
    /// A scalar test names a scalar the model's runs do not have.
    #[error(
        "scalar `{scalar}` of the test is not among the model's outputs ({})",
        available.join(", ")
    )]
    UnknownScalar {
        /// The scalar.
        scalar: String,
        /// The outputs the runs have.
        available: Vec<String>,
    },
    /// A set of model outputs lacks a scalar of the test.
    #[error("{origin}: no output `{scalar}`, which the test needs (it has: {})", available.join(", "))]
    MissingScalar {
        /// The scalar.
        scalar: String,
        /// The outputs (a run, the surrogates at a point).
        origin: String,
        /// The outputs it has.
        available: Vec<String>,
    },
    /// A scalar's value (the test's, its scale, or a model output) that is NaN or infinite.
    #[error("scalar `{scalar}`: {origin} is {value}, not a finite number")]
    NonFiniteScalar {
        /// The scalar.
        scalar: String,
        /// Whose value: the test's value, the scale, run `i`.
        origin: String,
        /// The value.
        value: f64,
    },
    /// A scalar's scale that is zero or negative: its errors cannot be normalised.
    #[error(
        "scalar `{scalar}`: scale {scale} must be positive (the spread or uncertainty its error is measured in)"
    )]
    NonPositiveScale {
        /// The scalar.
        scalar: String,
        /// The scale given.
        scale: f64,
    },
    /// A stage whose memory estimate, beside what the process holds, exceeds the limit (the
    /// user's, or what the machine can still give): stopped before it allocates.
    #[error(
        "stage `{stage}` needs about {} beside the {} this process holds, more than \
         {limit_from} ({}); {advice}",
        crate::memory::human(*estimate),
        crate::memory::human(*held),
        crate::memory::human(*limit)
    )]
    Memory {
        /// The stage.
        stage: String,
        /// Its estimate in bytes.
        estimate: u64,
        /// What the process held when it was checked, in bytes.
        held: u64,
        /// The limit in bytes.
        limit: u64,
        /// Where the limit comes from.
        limit_from: String,
        /// What the stage's size grows with, and what to change.
        advice: String,
    },
}

/// A time in seconds rounded to the nanosecond, as messages print it (`0.0028`, not
/// `0.0027999999999999995`).
pub(crate) fn to_ns(t: f64) -> f64 {
    (t * 1e9).round() / 1e9
}

/// `Result` with [`CalibrateError`].
pub type Result<T, E = CalibrateError> = std::result::Result<T, E>;

impl CalibrateError {
    /// A [`CalibrateError::Study`] error.
    pub fn study(what: impl Into<String>, reason: impl Into<String>) -> Self {
        CalibrateError::Study {
            what: what.into(),
            reason: reason.into(),
        }
    }

    /// The same error with its subject rewritten by `f` (for example to name the channel a
    /// metric failed on); errors without a subject are returned unchanged.
    #[must_use]
    pub fn with_subject(self, f: impl FnOnce(&str) -> String) -> Self {
        match self {
            CalibrateError::Degenerate { what, reason } => CalibrateError::Degenerate {
                what: f(&what),
                reason,
            },
            CalibrateError::Length { what, reason } => CalibrateError::Length {
                what: f(&what),
                reason,
            },
            other => other,
        }
    }

    /// What kind of fault this is: the kind of a wrapped [`CoreError`];
    /// [`ErrorKind::Numerical`] for a figure the plotting library failed to draw; otherwise
    /// [`ErrorKind::BadInput`] (a curve on which a metric is undefined, lengths that do not
    /// fit, a report document that cannot be drawn, or a stage too large for the memory
    /// allowed, are the input's fault: the user can change them).
    pub fn kind(&self) -> ErrorKind {
        match self {
            CalibrateError::Core(e) => e.kind(),
            CalibrateError::Degenerate { .. }
            | CalibrateError::Length { .. }
            | CalibrateError::Report { .. }
            | CalibrateError::Study { .. }
            | CalibrateError::ForeignJournal { .. }
            | CalibrateError::TestShorterThanModel { .. }
            | CalibrateError::Memory { .. }
            | CalibrateError::UnknownScalar { .. }
            | CalibrateError::MissingScalar { .. }
            | CalibrateError::NonFiniteScalar { .. }
            | CalibrateError::NonPositiveScale { .. } => ErrorKind::BadInput,
            CalibrateError::Render { .. } => ErrorKind::Numerical,
            CalibrateError::Shapes(e) => e.kind(),
            CalibrateError::Sensors(e) => e.kind(),
            CalibrateError::Erbf(e) => e.kind(),
            CalibrateError::Sobol(e) => e.kind(),
            CalibrateError::Cors(e) => e.kind(),
            CalibrateError::Journal { .. } => ErrorKind::Io,
            CalibrateError::Runner(e) => e.kind(),
        }
    }
}
