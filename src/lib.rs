//! impactcal: multi-dimensional calibration of impact dynamics models.
//!
//! This facade re-exports the workspace crates under short names, adds one error type for
//! all of them ([`Error`], with [`Error::kind`]) and a [`prelude`].
//!
//! | module | crate | what | depends on (of ours) |
//! |---|---|---|---|
//! | [`core`] | `impactcal-core` | histories, test data (CSV, ISO-MME, channel maps), CFC filters, parameter spaces and their unit-cube map, point sets (faer matrices, one point per row), the `Model` trait, sampling, CSV input, test functions, the shared error kinds | nothing |
//! | [`shapes`] | `impactcal-shapes` | impact shapes (SVD), contributions, M2, pairing, expansion | core |
//! | [`sensors`] | `impactcal-sensors` | sensor placement by effective independence (Kammer) | core, shapes |
//! | [`erbf`] | `impactcal-erbf` | ERBF and classic RBF surrogates of whole time histories (with a basis of impact shapes) | core, shapes |
//! | [`sobol`] | `impactcal-sobol` | Sobol' indices of time histories, Saltelli designs, intervals | core |
//! | [`cors`] | `impactcal-cors` | CORS-RBF optimiser of expensive simulations (ask and tell) | core, erbf |
//! | [`shell`] | `impactcal-shell` | explicit shell-impact solver, LS-DYNA keyword decks, the parametric airframe | core |
//! | [`runner`] | `impactcal-runner` | where runs happen: in process, a local process pool, a Slurm cluster; external solvers through deck templates; work directories and a run journal | core (an in-process solver, such as the built-in one, is handed to it from above) |
//! | [`calibrate`] | `impactcal-calibrate` | curve metrics (Sprague-Geers, Russell, ISO/TS 18571); the calibration study (M1, sensors, M2, surrogates, sensitivity, CORS reconciliation); the closed loop (residual, attribution, enrichment, recalibration, errors before and after); journals and reports | core, shapes, sensors, erbf, sobol, cors, runner |
//! | [`models`] | `impactcal-models` | models that are not the shell solver, driven by measured inputs: the split-Hopkinson (Kolsky) bar (the drop tower moves here later) | core |
//! | [`experiment`] | `impactcal-experiment` | experiment files: one schema for studies and closed loops, model assembly (airframe, deck, drop tower, external solver), `Experiment::study`, `close_loop` and `point` | core, shell, runner, calibrate |
//!
//! The calibration path runs through them in this order: histories of an ensemble
//! ([`core`], [`shell`]) give impact shapes ([`shapes`]), which place sensors ([`sensors`]);
//! surrogates of the histories ([`erbf`]) make sensitivity ([`sobol`]) and optimisation
//! ([`cors`]) affordable; [`calibrate`] joins them into the study and the closed loop, and
//! [`experiment`] runs either from a file. The `examples/` directory walks that path step by
//! step; `examples/experiment.rs` runs a study file and a loop file through the library:
//!
//! ```no_run
//! use impactcal::experiment::Experiment;
//!
//! let study = Experiment::from_file("examples/study/deck-processes.toml")?.study("study-out")?;
//! println!("M1: {}", study.result.m1.verdict.as_str());
//! let closed = Experiment::from_file("examples/loop/processes.toml")?.close_loop("loop-out")?;
//! println!("{}", closed.report.lead.join(" "));
//! # Ok::<(), impactcal::Error>(())
//! ```
//!
//! ```
//! use impactcal::prelude::*;
//!
//! let h = Histories::parse_csv("time,1.z,2.z\n0,0,0\n1,1,2\n2,2,4\n", "inline")?;
//! let shapes = ImpactShapes::from_histories(&h, &ShapeOptions::default())?;
//! // Two proportional channels: one shape carries everything.
//! assert_eq!(shapes.len(), 1);
//! assert!((shapes.contributions()[0] - 1.0).abs() < 1e-12);
//!
//! // Every crate's error converts into `impactcal::Error`, which says its kind.
//! let e: Error = Histories::parse_csv("time,a\n0,x\n", "bad.csv").unwrap_err().into();
//! assert_eq!(e.kind(), ErrorKind::BadInput);
//! # Ok::<(), impactcal::Error>(())
//! ```

pub use impactcal_calibrate as calibrate;
pub use impactcal_core as core;
pub use impactcal_cors as cors;
pub use impactcal_erbf as erbf;
pub use impactcal_experiment as experiment;
pub use impactcal_models as models;
pub use impactcal_runner as runner;
pub use impactcal_sensors as sensors;
pub use impactcal_shapes as shapes;
pub use impactcal_shell as shell;
pub use impactcal_sobol as sobol;

pub use impactcal_core::ErrorKind;

use impactcal_calibrate::CalibrateError;
use impactcal_core::CoreError;
use impactcal_cors::CorsError;
use impactcal_erbf::ErbfError;
use impactcal_experiment::ExperimentError;
use impactcal_models::ModelsError;
use impactcal_runner::RunnerError;
use impactcal_sensors::SensorsError;
use impactcal_shapes::ShapesError;
use impactcal_shell::ShellError;
use impactcal_sobol::SobolError;

/// An error of any impactcal crate, with the [`ErrorKind`] that says what to do about it:
/// fix the input, or look at a numerical or I/O failure.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// From `impactcal-core`: files, histories, parameter spaces, and the kinds of fault
    /// shared by every crate.
    #[error(transparent)]
    Core(#[from] CoreError),
    /// From `impactcal-shapes`.
    #[error(transparent)]
    Shapes(#[from] ShapesError),
    /// From `impactcal-sensors`.
    #[error(transparent)]
    Sensors(#[from] SensorsError),
    /// From `impactcal-erbf`.
    #[error(transparent)]
    Erbf(#[from] ErbfError),
    /// From `impactcal-sobol`.
    #[error(transparent)]
    Sobol(#[from] SobolError),
    /// From `impactcal-cors`.
    #[error(transparent)]
    Cors(#[from] CorsError),
    /// From `impactcal-shell`.
    #[error(transparent)]
    Shell(#[from] ShellError),
    /// From `impactcal-calibrate`.
    #[error(transparent)]
    Calibrate(#[from] CalibrateError),
    /// From `impactcal-runner`: solver runs, executors, the run journal.
    #[error(transparent)]
    Runner(#[from] RunnerError),
    /// From `impactcal-experiment`: experiment files, model assembly, study and loop runs
    /// (boxed: its messages carry the file, line and key).
    #[error(transparent)]
    Experiment(Box<ExperimentError>),
    /// From `impactcal-models`: bar tests (files, keys, records) and their models.
    #[error(transparent)]
    Models(#[from] ModelsError),
}

impl From<ExperimentError> for Error {
    fn from(e: ExperimentError) -> Self {
        Error::Experiment(Box::new(e))
    }
}

impl Error {
    /// What kind of fault this is: [`ErrorKind::BadInput`] for input the user can fix,
    /// [`ErrorKind::Numerical`] for a computation (or a model run) that failed on valid
    /// input, [`ErrorKind::Io`] for a file that could not be read or written.
    pub fn kind(&self) -> ErrorKind {
        match self {
            Error::Core(e) => e.kind(),
            Error::Shapes(e) => e.kind(),
            Error::Sensors(e) => e.kind(),
            Error::Erbf(e) => e.kind(),
            Error::Sobol(e) => e.kind(),
            Error::Cors(e) => e.kind(),
            Error::Shell(e) => e.kind(),
            Error::Calibrate(e) => e.kind(),
            Error::Runner(e) => e.kind(),
            Error::Experiment(e) => e.kind(),
            Error::Models(e) => e.kind(),
        }
    }
}

/// `Result` with [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// The types most programs need, in one import. Names are unique across the crates:
/// sampling methods are `SamplingMethod`, sensor-placement methods `PlacementMethod`.
pub mod prelude {
    pub use crate::{Error, ErrorKind};
    pub use impactcal_calibrate::CalibrateError;
    pub use impactcal_calibrate::metrics::{
        ChannelPair, CompareOptions, Comparison, CurveMetrics, Grade, Iso18571, Russell,
        SpragueGeers, compare,
    };
    pub use impactcal_core::sampling::{Sample, latin_hypercube, sample};
    pub use impactcal_core::{
        BatchResults, Cfc, ChannelMap, CoreError, Histories, IsoMme, Model, ParamGuard, Parameter,
        ParameterSpace, RunFailure, SamplingMethod, Table, TableOptions, TestRecord, read_samples,
    };
    pub use impactcal_cors::{
        Cors, CorsError, CorsOptions, FillReason, InitialDesign, Outcome, StopReason, Suggestion,
        Transform,
    };
    pub use impactcal_erbf::{
        Accuracy, Erbf, ErbfError, ErbfOptions, LooMethod, PolyDegree, RadialFunction,
        RbfInterpolant, RbfOptions, ResponseSurrogate, SurrogateKind,
    };
    pub use impactcal_sensors::{
        CandidateShapes, Grouping, Placement, PlacementMethod, PlacementOptions, SensorsError,
        place, place_from_histories,
    };
    pub use impactcal_shapes::{
        Expansion, ImpactShapes, Orthogonality, ShapeOptions, ShapesError, SvdMethod, Truncation,
    };
    pub use impactcal_shell::airframe::{
        Airframe, AirframeModel, AirframeOptions, AirframeValues, MeshDensity, Preset,
    };
    pub use impactcal_shell::{ShellError, ShellModel, Simulation};
    pub use impactcal_sobol::{
        DesignLayout, SaltelliDesign, SobolError, SobolIndices, SobolOptions, analyze,
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every crate's error converts into `Error` and keeps its kind.
    #[test]
    fn kinds_survive_the_conversion() {
        let io = CoreError::Io {
            path: "x".into(),
            source: std::io::Error::from(std::io::ErrorKind::NotFound),
        };
        assert_eq!(Error::from(io).kind(), ErrorKind::Io);
        let singular = ErbfError::Singular {
            ratio: 0.0,
            threshold: 1e-15,
        };
        assert_eq!(Error::from(singular).kind(), ErrorKind::Numerical);
        let unstable = ShellError::Unstable {
            time: 0.0,
            cycle: 1,
            element: 2,
            cause: "energy growth".into(),
        };
        assert_eq!(Error::from(unstable).kind(), ErrorKind::Numerical);
        let bad_deck = ShellError::Reference {
            what: "node",
            id: 3,
            message: "not defined".into(),
        };
        assert_eq!(Error::from(bad_deck).kind(), ErrorKind::BadInput);
        // A wrong length is the same kind whichever crate finds it.
        let mismatch = || CoreError::DimensionMismatch {
            what: "x".into(),
            expected: 2,
            found: 1,
        };
        for e in [
            Error::from(ErbfError::from(mismatch())),
            Error::from(CorsError::from(mismatch())),
            Error::from(SobolError::from(mismatch())),
            Error::from(SensorsError::from(mismatch())),
            Error::from(ShapesError::from(mismatch())),
        ] {
            assert_eq!(e.kind(), ErrorKind::BadInput);
            assert_eq!(e.to_string(), "x: expected 2, found 1");
        }
        assert_eq!(
            Error::from(ShapesError::NoConvergence).kind(),
            ErrorKind::Numerical
        );
        assert_eq!(
            Error::from(SensorsError::Numerical("SVD".into())).kind(),
            ErrorKind::Numerical
        );
    }
}
