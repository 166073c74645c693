//! Small 3-vector helpers and through-thickness quadrature rules.

/// `a + b`.
#[inline(always)]
pub(crate) fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a - b`.
#[inline(always)]
pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `s a`.
#[inline(always)]
pub(crate) fn scale(s: f64, a: [f64; 3]) -> [f64; 3] {
    [s * a[0], s * a[1], s * a[2]]
}

/// `a . b`.
#[inline(always)]
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a x b`.
#[inline(always)]
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `|a|`.
#[inline(always)]
pub(crate) fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Area of a triangle or quad (`xs` of length 3 or 4; a quad with `x4 == x3` is a
/// triangle): half the norm of the cross product of the diagonals.
pub(crate) fn polygon_area(xs: &[[f64; 3]]) -> f64 {
    match xs.len() {
        3 => 0.5 * norm(cross(sub(xs[1], xs[0]), sub(xs[2], xs[0]))),
        4 => 0.5 * norm(cross(sub(xs[2], xs[0]), sub(xs[3], xs[1]))),
        _ => 0.0,
    }
}

/// Through-thickness points `zeta` in [-1, 1] and weights normalised to sum 1.
///
/// Gauss-Legendre for any `n >= 1` (Newton on the Legendre polynomial), Gauss-Lobatto for
/// `n >= 2` (the end points and the roots of P'_{n-1}).
pub(crate) fn thickness_rule(n: usize, lobatto: bool) -> (Vec<f64>, Vec<f64>) {
    if lobatto && n >= 2 {
        lobatto_rule(n)
    } else {
        gauss_rule(n)
    }
}

/// Legendre polynomial P_n(x) and its derivative.
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let kf = k as f64;
        let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
        p0 = p1;
        p1 = p2;
    }
    let nf = n as f64;
    let dp = if (1.0 - x * x).abs() < 1e-300 {
        0.0
    } else {
        nf * (x * p1 - p0) / (x * x - 1.0)
    };
    (p1, dp)
}

fn gauss_rule(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut z = Vec::with_capacity(n);
    let mut w = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = -(std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        for _ in 0..100 {
            let (p, dp) = legendre(n, x);
            let dx = p / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let (_, dp) = legendre(n, x);
        z.push(x);
        // Weight 2/((1-x^2) P'^2) on [-1,1]; halved so the weights sum to 1.
        w.push(1.0 / ((1.0 - x * x) * dp * dp));
    }
    (z, w)
}

fn lobatto_rule(n: usize) -> (Vec<f64>, Vec<f64>) {
    let m = n - 1;
    let mut z = vec![-1.0];
    // Interior points: roots of P'_m, found by Newton on P'_m with P''_m from the Legendre
    // equation (1-x^2) P'' = 2x P' - m(m+1) P.
    for i in 1..m {
        let mut x = -(std::f64::consts::PI * i as f64 / m as f64).cos();
        for _ in 0..100 {
            let (p, dp) = legendre(m, x);
            let ddp = (2.0 * x * dp - (m * (m + 1)) as f64 * p) / (1.0 - x * x);
            let dx = dp / ddp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        z.push(x);
    }
    z.push(1.0);
    let nf = n as f64;
    let w = z
        .iter()
        .map(|&x| {
            let (p, _) = legendre(m, x);
            // 2/(n(n-1) P_m^2), halved.
            1.0 / (nf * (nf - 1.0) * p * p)
        })
        .collect();
    (z, w)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_five_points_match_the_tables() {
        let (z, w) = thickness_rule(5, false);
        assert!((z[4] - 0.906_179_845_938_664).abs() < 1e-14);
        assert!((z[3] - 0.538_469_310_105_683).abs() < 1e-14);
        assert!(z[2].abs() < 1e-15);
        assert!((2.0 * w[2] - 0.568_888_888_888_889).abs() < 1e-14);
        assert!((2.0 * w[4] - 0.236_926_885_056_189).abs() < 1e-14);
    }

    #[test]
    fn rules_integrate_polynomials_exactly() {
        for n in 1..=10 {
            let (z, w) = thickness_rule(n, false);
            // Gauss: exact to degree 2n-1; mean of zeta^k over [-1,1].
            for k in 0..(2 * n) {
                let q: f64 = z.iter().zip(&w).map(|(z, w)| w * z.powi(k as i32)).sum();
                let exact = if k % 2 == 1 {
                    0.0
                } else {
                    1.0 / (k as f64 + 1.0)
                };
                assert!(
                    (q - exact).abs() < 1e-13,
                    "gauss n={n} k={k}: {q} vs {exact}"
                );
            }
        }
        for n in 2..=10 {
            let (z, w) = thickness_rule(n, true);
            for k in 0..(2 * n - 2) {
                let q: f64 = z.iter().zip(&w).map(|(z, w)| w * z.powi(k as i32)).sum();
                let exact = if k % 2 == 1 {
                    0.0
                } else {
                    1.0 / (k as f64 + 1.0)
                };
                assert!(
                    (q - exact).abs() < 1e-13,
                    "lobatto n={n} k={k}: {q} vs {exact}"
                );
            }
        }
        let (z, w) = thickness_rule(5, true);
        assert!((z[3] - 0.654_653_670_707_977).abs() < 1e-14);
        assert!((2.0 * w[0] - 0.1).abs() < 1e-14);
    }
}
