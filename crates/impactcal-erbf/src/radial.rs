//! Radial functions of the classic RBF interpolant and the polynomial tail degrees.

use serde::{Deserialize, Serialize};

use impactcal_core::CoreError;

use crate::error::Result;
use impactcal_core::error::invalid_option;

/// A radial function `phi(r)` of the distance `r = |x - x_i|` (the "kernel" of an RBF
/// interpolant).
///
/// The signs follow the convention under which each function is conditionally positive
/// definite of the order that its minimum polynomial tail ([`RadialFunction::min_degree`])
/// removes, so that smoothing (a positive diagonal) keeps the system well posed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case")]
pub enum RadialFunction {
    /// `phi(r) = r^3`; needs at least a linear tail.
    Cubic,
    /// Thin-plate spline `phi(r) = r^2 ln r` (0 at `r = 0`); needs at least a linear tail.
    ThinPlate,
    /// Gaussian `phi(r) = exp(-r^2 / (2 w^2))` with width `w > 0` (the `r_c` of ERBF);
    /// positive definite, needs no tail. scipy's `epsilon` is `1 / (sqrt(2) w)`.
    Gaussian {
        /// The width `w` (same units as the points).
        width: f64,
    },
    /// Multiquadric `phi(r) = -sqrt(r^2 + c^2)` with shape `c > 0`; needs at least a
    /// constant tail.
    Multiquadric {
        /// The shape parameter `c` (same units as the points).
        c: f64,
    },
}

impl RadialFunction {
    /// `phi(r)` for `r >= 0`.
    #[inline]
    pub fn value(&self, r: f64) -> f64 {
        match *self {
            RadialFunction::Cubic => r * r * r,
            RadialFunction::ThinPlate => {
                if r > 0.0 {
                    r * r * r.ln()
                } else {
                    0.0
                }
            }
            RadialFunction::Gaussian { width } => (-0.5 * (r / width) * (r / width)).exp(),
            RadialFunction::Multiquadric { c } => -(r * r + c * c).sqrt(),
        }
    }

    /// `phi'(r) / r`, so that `grad_x phi(|x - x_i|) = (phi'(r) / r) (x - x_i)`. At `r = 0`
    /// the gradient of every kernel here is zero; this returns a finite value there (0 for
    /// the thin-plate spline, whose ratio diverges only logarithmically while `x - x_i`
    /// vanishes linearly).
    #[inline]
    pub fn derivative_over_r(&self, r: f64) -> f64 {
        match *self {
            RadialFunction::Cubic => 3.0 * r,
            RadialFunction::ThinPlate => {
                if r > 0.0 {
                    2.0 * r.ln() + 1.0
                } else {
                    0.0
                }
            }
            RadialFunction::Gaussian { width } => -self.value(r) / (width * width),
            RadialFunction::Multiquadric { c } => -1.0 / (r * r + c * c).sqrt(),
        }
    }

    /// The lowest polynomial tail that makes the interpolation problem uniquely solvable
    /// for distinct (and, for the linear tail, affinely spanning) points.
    pub fn min_degree(&self) -> PolyDegree {
        match self {
            RadialFunction::Cubic | RadialFunction::ThinPlate => PolyDegree::Linear,
            RadialFunction::Multiquadric { .. } => PolyDegree::Constant,
            RadialFunction::Gaussian { .. } => PolyDegree::None,
        }
    }

    /// Checks the shape parameter.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for a width or `c` that is not finite and positive.
    pub fn validate(&self) -> impactcal_core::Result<()> {
        let (name, v): (&'static str, f64) = match *self {
            RadialFunction::Gaussian { width } => ("Gaussian width", width),
            RadialFunction::Multiquadric { c } => ("multiquadric c", c),
            RadialFunction::Cubic | RadialFunction::ThinPlate => return Ok(()),
        };
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(CoreError::invalid_option(
                name,
                v,
                "must be finite and positive",
            ))
        }
    }
}

/// Degree of the polynomial tail added to a classic RBF interpolant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PolyDegree {
    /// No tail (degree -1).
    None,
    /// A constant (degree 0): one extra coefficient.
    Constant,
    /// An affine function (degree 1): `1 + d` extra coefficients.
    Linear,
}

impl PolyDegree {
    /// The degree as an integer: -1, 0 or 1.
    pub fn as_i32(self) -> i32 {
        match self {
            PolyDegree::None => -1,
            PolyDegree::Constant => 0,
            PolyDegree::Linear => 1,
        }
    }

    /// The degree from an integer -1, 0 or 1.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for any other
    /// integer.
    pub fn from_i32(degree: i32) -> Result<Self> {
        match degree {
            -1 => Ok(PolyDegree::None),
            0 => Ok(PolyDegree::Constant),
            1 => Ok(PolyDegree::Linear),
            _ => Err(invalid_option(
                "polynomial degree",
                degree,
                "must be -1 (none), 0 (constant) or 1 (linear)",
            )),
        }
    }

    /// Number of polynomial terms in `d` dimensions: 0, 1 or `1 + d`.
    pub fn terms(self, d: usize) -> usize {
        match self {
            PolyDegree::None => 0,
            PolyDegree::Constant => 1,
            PolyDegree::Linear => 1 + d,
        }
    }
}
