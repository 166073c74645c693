//! The one-dimensional non-radial basis functions (N-RBF) of ERBF.
//!
//! For an offset `xi = x^j - x_i^j` along one coordinate, an even order `n >= 2` and a
//! half-width `gamma > 0`:
//!
//! | region | `xi` | `phi_L(xi)` | `phi_R(xi)` |
//! |---|---|---|---|
//! | I | `xi <= -gamma` | `-n gamma^(n-1) xi + (1-n) gamma^n` | 0 |
//! | II | `-gamma <= xi <= 0` | `xi^n` | 0 |
//! | III | `0 <= xi <= gamma` | 0 | `xi^n` |
//! | IV | `xi >= gamma` | 0 | `n gamma^(n-1) xi + (1-n) gamma^n` |
//!
//! and `phi_beta(xi) = xi`. The outer pieces are the tangent lines of the monomial at
//! `+-gamma`, so the functions are C1 (not C2) and grow linearly away from the data, and
//! `phi_L(xi) = phi_R(-xi)`. The tangent-line form written here,
//! `phi_L = (-gamma)^n + n (-gamma)^(n-1) (xi + gamma)`, equals the table for every `n`.

/// `phi_L` and `phi_R` of one order and half-width with their constants precomputed, for
/// evaluating many offsets (the inner loop of ERBF basis construction).
#[derive(Debug, Clone, Copy)]
pub struct LeftRight {
    n: i32,
    gamma: f64,
    /// `n gamma^(n-1)`, the magnitude of the slope beyond `+-gamma`.
    slope: f64,
}

impl LeftRight {
    /// Constants for an even order `n >= 2` and `gamma > 0`.
    pub fn new(n: i32, gamma: f64) -> Self {
        LeftRight {
            n,
            gamma,
            slope: f64::from(n) * gamma.powi(n - 1),
        }
    }

    /// `(phi_L(xi), phi_R(xi))` for an even order (at most one of them is non-zero).
    #[inline]
    pub fn values(&self, xi: f64) -> (f64, f64) {
        // Branch-free, as the offsets of random queries have random signs and regions:
        // |xi|^n inside the half-width, the tangent line beyond, written as
        // min(|xi|, gamma)^n + slope max(|xi| - gamma, 0); then split by sign.
        let a = xi.abs();
        let v = even_power(a.min(self.gamma), self.n) + self.slope * (a - self.gamma).max(0.0);
        let left = v * f64::from(u8::from(xi < 0.0));
        (left, v - left)
    }
}

/// `x^n` by repeated squaring.
#[inline]
pub(crate) fn even_power(x: f64, n: i32) -> f64 {
    match n {
        2 => x * x,
        4 => {
            let x2 = x * x;
            x2 * x2
        }
        _ => x.powi(n),
    }
}

/// The left function `phi_L(xi)`.
#[inline]
pub fn phi_l(xi: f64, n: i32, gamma: f64) -> f64 {
    if xi <= -gamma {
        (-gamma).powi(n) + f64::from(n) * (-gamma).powi(n - 1) * (xi + gamma)
    } else if xi <= 0.0 {
        xi.powi(n)
    } else {
        0.0
    }
}

/// The right function `phi_R(xi)`.
#[inline]
pub fn phi_r(xi: f64, n: i32, gamma: f64) -> f64 {
    if xi >= gamma {
        gamma.powi(n) + f64::from(n) * gamma.powi(n - 1) * (xi - gamma)
    } else if xi >= 0.0 {
        xi.powi(n)
    } else {
        0.0
    }
}

/// The derivative `phi_L'(xi)`: `n (-gamma)^(n-1)` in I, `n xi^(n-1)` in II, 0 beyond.
#[inline]
pub fn dphi_l(xi: f64, n: i32, gamma: f64) -> f64 {
    if xi <= -gamma {
        f64::from(n) * (-gamma).powi(n - 1)
    } else if xi <= 0.0 {
        f64::from(n) * xi.powi(n - 1)
    } else {
        0.0
    }
}

/// The derivative `phi_R'(xi)`: 0 below 0, `n xi^(n-1)` in III, `n gamma^(n-1)` in IV.
#[inline]
pub fn dphi_r(xi: f64, n: i32, gamma: f64) -> f64 {
    if xi >= gamma {
        f64::from(n) * gamma.powi(n - 1)
    } else if xi >= 0.0 {
        f64::from(n) * xi.powi(n - 1)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    const N: i32 = 4;
    const G: f64 = 0.15;

    #[test]
    fn values_at_the_region_boundaries() {
        assert_relative_eq!(phi_l(-G, N, G), G.powi(4));
        assert_relative_eq!(phi_r(G, N, G), G.powi(4));
        assert_relative_eq!(phi_l(0.0, N, G), 0.0);
        assert_relative_eq!(phi_r(0.0, N, G), 0.0);
        // Region I from the table: -n g^(n-1) xi + (1-n) g^n.
        let xi = -0.7;
        assert_relative_eq!(
            phi_l(xi, N, G),
            -4.0 * G.powi(3) * xi - 3.0 * G.powi(4),
            epsilon = 1e-15
        );
        assert_relative_eq!(
            phi_r(-xi, N, G),
            -4.0 * G.powi(3) * xi - 3.0 * G.powi(4),
            epsilon = 1e-15
        );
    }

    #[test]
    fn precomputed_pair_equals_the_definitions() {
        for n in [2, 4, 6] {
            let lr = LeftRight::new(n, G);
            for k in -300..=300 {
                let xi = f64::from(k) * 0.0041;
                let (l, r) = lr.values(xi);
                assert_relative_eq!(l, phi_l(xi, n, G), epsilon = 1e-15, max_relative = 1e-13);
                assert_relative_eq!(r, phi_r(xi, n, G), epsilon = 1e-15, max_relative = 1e-13);
            }
        }
    }

    #[test]
    fn mirror_symmetry_and_c1_continuity() {
        for k in -200..=200 {
            let xi = f64::from(k) * 0.004;
            assert_relative_eq!(phi_l(xi, N, G), phi_r(-xi, N, G), epsilon = 1e-16);
            assert_relative_eq!(dphi_l(xi, N, G), -dphi_r(-xi, N, G), epsilon = 1e-16);
        }
        for at in [-G, 0.0, G] {
            let h = 1e-7;
            for (f, df) in [
                (
                    phi_l as fn(f64, i32, f64) -> f64,
                    dphi_l as fn(f64, i32, f64) -> f64,
                ),
                (phi_r, dphi_r),
            ] {
                // C0: equal one-sided limits; C1: one-sided slopes agree with the derivative.
                assert_relative_eq!(f(at - h, N, G), f(at + h, N, G), epsilon = 1e-8);
                let left = (f(at, N, G) - f(at - h, N, G)) / h;
                let right = (f(at + h, N, G) - f(at, N, G)) / h;
                assert_relative_eq!(left, df(at, N, G), epsilon = 1e-7);
                assert_relative_eq!(right, df(at, N, G), epsilon = 1e-7);
            }
        }
        // Derivatives against central differences inside every region.
        for xi in [-0.5, -0.07, 0.05, 0.4] {
            let h = 1e-6;
            let fd = (phi_l(xi + h, N, G) - phi_l(xi - h, N, G)) / (2.0 * h);
            assert_relative_eq!(fd, dphi_l(xi, N, G), epsilon = 1e-9);
            let fd = (phi_r(xi + h, N, G) - phi_r(xi - h, N, G)) / (2.0 * h);
            assert_relative_eq!(fd, dphi_r(xi, N, G), epsilon = 1e-9);
        }
    }
}
