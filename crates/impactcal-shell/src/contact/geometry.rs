//! The closest point of a segment's mid-surface to a node.

use crate::geometry::{dot, sub};

/// The point of triangle `(a, b, c)` closest to `p`, as barycentric weights `(wa, wb, wc)`
/// (non-negative, summing to 1). The regions of the triangle's plane are tested in turn:
/// the three vertices, the three edges, the face.
pub(crate) fn closest_on_triangle(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denom = 1.0 / (va + vb + vc);
    if !denom.is_finite() {
        // A triangle without area (a collapsed segment): its first corner.
        return [1.0, 0.0, 0.0];
    }
    let v = vb * denom;
    let w = vc * denom;
    [1.0 - v - w, v, w]
}

/// The point of a segment's mid-surface closest to `p`: the segment's corner positions
/// `x` (a triangle when `tri`, then `x[3]` is unused) and the result as weights on the
/// corners (summing to 1), with the closest point itself and its squared distance to `p`.
/// A quad is taken as the four triangles between its edges and its centroid, so the
/// surface is continuous and exact for a flat quad.
pub(crate) fn closest_on_segment(
    p: [f64; 3],
    x: &[[f64; 3]; 4],
    tri: bool,
) -> ([f64; 4], [f64; 3], f64) {
    let point = |w: &[f64; 4], n: usize| {
        let mut q = [0.0; 3];
        for k in 0..n {
            for d in 0..3 {
                q[d] += w[k] * x[k][d];
            }
        }
        q
    };
    if tri {
        let b = closest_on_triangle(p, x[0], x[1], x[2]);
        let w = [b[0], b[1], b[2], 0.0];
        let q = point(&w, 3);
        let r = sub(p, q);
        return (w, q, dot(r, r));
    }
    let mut c = [0.0; 3];
    for k in 0..4 {
        for d in 0..3 {
            c[d] += 0.25 * x[k][d];
        }
    }
    let mut best = ([0.0; 4], [0.0; 3], f64::INFINITY);
    for k in 0..4 {
        let j = (k + 1) % 4;
        let b = closest_on_triangle(p, x[k], x[j], c);
        let mut w = [0.25 * b[2]; 4];
        w[k] += b[0];
        w[j] += b[1];
        let q = point(&w, 4);
        let r = sub(p, q);
        let d2 = dot(r, r);
        if d2 < best.2 {
            best = (w, q, d2);
        }
    }
    best
}

#[cfg(test)]
// A point in a vertex region gets that vertex's weight exactly 1.
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;

    #[test]
    fn closest_points_of_a_triangle_by_region() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
        // Above the face.
        let w = closest_on_triangle([0.5, 0.5, 3.0], a, b, c);
        assert!((w[0] - 0.5).abs() < 1e-15 && (w[1] - 0.25).abs() < 1e-15);
        // Beyond each vertex and edge.
        assert_eq!(
            closest_on_triangle([-1.0, -1.0, 1.0], a, b, c),
            [1.0, 0.0, 0.0]
        );
        assert_eq!(
            closest_on_triangle([3.0, -1.0, 0.0], a, b, c),
            [0.0, 1.0, 0.0]
        );
        assert_eq!(
            closest_on_triangle([-1.0, 3.0, 0.0], a, b, c),
            [0.0, 0.0, 1.0]
        );
        let w = closest_on_triangle([1.0, -1.0, 0.0], a, b, c);
        assert!((w[1] - 0.5).abs() < 1e-15 && w[2] == 0.0);
        let w = closest_on_triangle([2.0, 2.0, 0.0], a, b, c);
        assert!((w[1] - 0.5).abs() < 1e-15 && (w[2] - 0.5).abs() < 1e-15);
    }

    #[test]
    fn a_quad_is_exact_when_flat() {
        let x = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        for p in [[0.3, 0.8, 0.2], [0.9, 0.1, -0.4], [0.5, 0.5, 1.0]] {
            let (w, q, d2) = closest_on_segment(p, &x, false);
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
            assert!((q[0] - p[0]).abs() < 1e-14 && (q[1] - p[1]).abs() < 1e-14);
            assert!((d2 - p[2] * p[2]).abs() < 1e-14);
        }
        // Off an edge: distance to the edge.
        let (_, q, d2) = closest_on_segment([1.5, 0.5, 0.0], &x, false);
        assert!((q[0] - 1.0).abs() < 1e-15 && (d2 - 0.25).abs() < 1e-14);
    }
}
