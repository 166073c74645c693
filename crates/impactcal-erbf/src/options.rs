//! Options of the ERBF metamodel and their checked form.

use impactcal_core::{CoreError, ParamGuard};
use serde::{Deserialize, Serialize};

/// Multipliers of the three basis families. The minimum-norm solution is not invariant
/// to them (rescaling a family changes how much of the data it carries), so they are an
/// implicit hyper-parameter; the paper's form is all ones.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FamilyWeights {
    /// Weight of the Gaussian radial functions `psi_i`.
    pub radial: f64,
    /// Weight of the `phi_L` and `phi_R` functions.
    pub left_right: f64,
    /// Weight of the linear functions `xi`.
    pub beta: f64,
}

impl Default for FamilyWeights {
    fn default() -> Self {
        FamilyWeights {
            radial: 1.0,
            left_right: 1.0,
            beta: 1.0,
        }
    }
}

/// Options of an ERBF model, checked into [`ValidErbfOptions`] (by [`ParamGuard::check`],
/// or by [`Erbf::fit`](crate::Erbf::fit) itself) before they reach a fit. The defaults are
/// those of Horta et al.: local polynomial order `n_t = 4`, smoothness (half-width)
/// `gamma = 0.15`, Gaussian radius `r_c = 0.15`, all in unit-scaled inputs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ErbfOptions {
    /// Order `n_t` of the local monomials; even, at least 2.
    pub order: u32,
    /// Half-width `gamma > 0` of the polynomial region of the N-RBFs.
    pub gamma: f64,
    /// Gaussian radius `r_c > 0`.
    pub rc: f64,
    /// Family weights (all 1 by default).
    pub weights: FamilyWeights,
    /// Subtract each output column's mean before fitting and add it back when predicting
    /// (off by default; not part of the original method).
    pub center_outputs: bool,
    /// Two samples closer than this (Euclidean distance in unit-scaled inputs) are
    /// rejected as duplicates.
    pub duplicate_tolerance: f64,
    /// Smoothing: a ridge `lambda = smoothing tr(A A^T) / N` on the coefficients, so that
    /// the fit minimises `||A c - F||^2 + lambda ||c||^2` instead of interpolating; `0`
    /// (the default, the original method) interpolates. With smoothing the outputs are
    /// centred whatever [`center_outputs`](Self::center_outputs) says. Finite,
    /// non-negative.
    #[serde(default)]
    pub smoothing: f64,
}

impl Default for ErbfOptions {
    fn default() -> Self {
        ErbfOptions {
            order: 4,
            gamma: 0.15,
            rc: 0.15,
            weights: FamilyWeights::default(),
            center_outputs: false,
            duplicate_tolerance: 1e-9,
            smoothing: 0.0,
        }
    }
}

impl ParamGuard for ErbfOptions {
    type Checked = ValidErbfOptions;

    /// Checks every option.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for an odd order or one below 2, a `gamma` or `r_c`
    /// that is not finite and positive, a negative or non-finite family weight, duplicate
    /// tolerance or smoothing, or all weights zero.
    fn check_ref(&self) -> impactcal_core::Result<()> {
        let bad = |name: &'static str, value: String, message: &str| {
            Err(CoreError::invalid_option(name, value, message))
        };
        if self.order < 2 || self.order % 2 != 0 || self.order > 64 {
            return bad(
                "order (n_t)",
                self.order.to_string(),
                "must be an even integer between 2 and 64",
            );
        }
        for (name, v) in [("gamma", self.gamma), ("r_c", self.rc)] {
            if !(v.is_finite() && v > 0.0) {
                return bad(name, v.to_string(), "must be finite and positive");
            }
        }
        let w = self.weights;
        for (name, v) in [
            ("radial weight", w.radial),
            ("left/right weight", w.left_right),
            ("beta weight", w.beta),
            ("duplicate tolerance", self.duplicate_tolerance),
            ("smoothing", self.smoothing),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(name, v.to_string(), "must be finite and non-negative");
            }
        }
        if w.radial == 0.0 && w.left_right == 0.0 && w.beta == 0.0 {
            return bad(
                "weights",
                "0".into(),
                "at least one family weight must be positive",
            );
        }
        Ok(())
    }

    fn check(self) -> impactcal_core::Result<ValidErbfOptions> {
        ValidErbfOptions::checked(self)
    }
}

impactcal_core::valid_options! {
    /// [`ErbfOptions`] that passed their checks: the only form a fit works with. Read the
    /// options through `Deref`; serialises as the plain options and is checked again when
    /// read.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct ValidErbfOptions(ErbfOptions);
}

impl Default for ValidErbfOptions {
    /// The defaults of [`ErbfOptions::default`], which are valid.
    fn default() -> Self {
        ValidErbfOptions(ErbfOptions::default())
    }
}
