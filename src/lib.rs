//! impactcal: multi-dimensional calibration of impact dynamics models.
//!
//! This facade re-exports the workspace crates under short names:
//!
//! | module | crate | what |
//! |---|---|---|
//! | [`core`] | `impactcal-core` | histories, parameter spaces, the `Model` trait, CSV input |
//! | [`shapes`] | `impactcal-shapes` | impact shapes (SVD), contributions, M2, pairing, expansion |
//! | [`sobol`] | `impactcal-sobol` | Sobol' indices of time histories, Saltelli designs, intervals |
//!

pub use impactcal_core as core;
pub use impactcal_shapes as shapes;
pub use impactcal_sobol as sobol;

/// The types most programs need, in one import.
pub mod prelude {
    pub use impactcal_core::{
        BatchResults, CoreError, Histories, Model, Parameter, ParameterSpace, RunFailure, Table,
        TableOptions,
    };
    pub use impactcal_sobol::{
        DesignLayout, OutputView, SaltelliDesign, SobolError, SobolIndices, SobolOptions,
    };
}
