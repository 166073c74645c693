//! What an element evaluation returns, and its options.

/// What one element returns for one cycle.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ElementOutput {
    /// Internal nodal forces and moments `[fx, fy, fz, mx, my, mz]` in the global frame, one
    /// row per node (row 3 unused for triangles).
    pub f: [[f64; 6]; 4],
    /// Stable time step of the element (before the safety factor).
    pub dt: f64,
    /// Internal (strain) energy increment of the cycle.
    pub internal: f64,
    /// Hourglass energy increment of the cycle.
    pub hourglass: f64,
    /// Energy removed by stiffness-proportional damping in the cycle.
    pub damping: f64,
}

/// Why an element could not be evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ElementFault {
    /// Zero area or coincident nodes.
    Degenerate,
    /// Negative area in the element frame (the element turned inside out).
    Inverted,
}

impl std::fmt::Display for ElementFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ElementFault::Degenerate => f.write_str("degenerate element (zero area)"),
            ElementFault::Inverted => f.write_str("inverted element (negative area)"),
        }
    }
}

/// Options of the element kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KernelOptions {
    /// Apply the rigid-body (warping) projection to quads.
    pub projection: bool,
    /// ISDO 1: characteristic length = area / longest diagonal.
    pub isdo_diagonal: bool,
    /// Invariant node numbering (LS-DYNA INN 2): the quad frame's first axis bisects the
    /// diagonals instead of following the edges 1-2 and 4-3.
    pub invariant: bool,
    /// Report a quad with a non-positive corner Jacobian as [`ElementFault::Inverted`]
    /// (`Control::distortion_check`); without it such a quad is evaluated at its centre.
    pub distortion_check: bool,
}
