//! impactcal: multi-dimensional calibration of impact dynamics models.
//!
//! This facade re-exports the workspace crates under short names:
//!
//! | module | crate | what |
//! |---|---|---|
//! | [`core`] | `impactcal-core` | histories, parameter spaces, the `Model` trait, CSV input |
//! | [`shapes`] | `impactcal-shapes` | impact shapes (SVD), contributions, M2, pairing, expansion |
//! | [`erbf`] | `impactcal-erbf` | ERBF and classic RBF surrogates of whole time histories |
//! | [`cors`] | `impactcal-cors` | CORS-RBF optimiser of expensive simulations (ask and tell) |
//! | [`sensors`] | `impactcal-sensors` | sensor placement by effective independence (Kammer) |
//! | [`shell`] | `impactcal-shell` | explicit shell-impact solver, LS-DYNA keyword decks |
//! | [`erbf`] | `impactcal-erbf` | ERBF and classic RBF surrogates of whole time histories |
//! | [`sobol`] | `impactcal-sobol` | Sobol' indices of time histories, Saltelli designs, intervals |
//! | [`shell`] | `impactcal-shell` | explicit shell-impact solver, LS-DYNA keyword decks, the parametric airframe |
//! | [`calibrate`] | `impactcal-calibrate` | curve metrics (Sprague-Geers, Russell, ISO/TS 18571) of a model against a test |
//!
//! ```
//! use impactcal::prelude::*;
//!
//! let h = Histories::parse_csv("time,1.z,2.z\n0,0,0\n1,1,2\n2,2,4\n", "inline")?;
//! let shapes = ImpactShapes::from_histories(&h, &ShapeOptions::default())?;
//! // Two proportional channels: one shape carries everything.
//! assert_eq!(shapes.len(), 1);
//! assert!((shapes.contributions()[0] - 1.0).abs() < 1e-12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!

pub use impactcal_calibrate as calibrate;
pub use impactcal_core as core;
pub use impactcal_cors as cors;
pub use impactcal_erbf as erbf;
pub use impactcal_sensors as sensors;
pub use impactcal_shapes as shapes;
pub use impactcal_shell as shell;
pub use impactcal_sobol as sobol;

/// The types most programs need, in one import.
pub mod prelude {
    pub use impactcal_calibrate::CalibrateError;
    pub use impactcal_calibrate::metrics::{
        ChannelPair, CompareOptions, Comparison, CurveMetrics, Grade, Iso18571, Russell,
        SpragueGeers, compare,
    };
    pub use impactcal_core::{
        BatchResults, Cfc, ChannelMap, CoreError, Histories, IsoMme, Model, Parameter,
        ParameterSpace, RunFailure, Table, TableOptions, TestRecord,
    };
    pub use impactcal_cors::{
        Cors, CorsError, CorsOptions, InitialDesign, Outcome, StopReason, Suggestion, Transform,
    };
    pub use impactcal_erbf::{
        Accuracy, ErbfError, Kernel, LooMethod, PolyDegree, RbfInterpolant, RbfOptions,
    };
    pub use impactcal_sensors::{
        CandidateShapes, Grouping, Method, Placement, PlacementOptions, SensorsError, place,
        place_from_histories,
    };
    pub use impactcal_shapes::{
        Expansion, ImpactShapes, Orthogonality, ShapeOptions, ShapesError, SvdMethod, Truncation,
    };
    pub use impactcal_shell::airframe::{
        Airframe, AirframeModel, AirframeOptions, AirframeValues, MeshDensity, Preset,
    };
    pub use impactcal_shell::{ShellError, ShellModel, Simulation};
    pub use impactcal_sobol::{
        DesignLayout, OutputView, SaltelliDesign, SobolError, SobolIndices, SobolOptions,
    };
}
