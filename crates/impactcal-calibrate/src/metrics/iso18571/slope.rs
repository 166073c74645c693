//! The smoothed derivative that ISO/TS 18571's slope score compares.

/// The derivative of `x` by central differences (one-sided at the two ends), smoothed by a
/// centred moving average over 9 points that shrinks to 7, 5, 3 and 1 points towards each
/// end. The step is left out (the slope score is a ratio of two such curves).
pub(crate) fn smoothed_derivative(x: &[f64]) -> Vec<f64> {
    let n = x.len();
    let mut g = Vec::with_capacity(n);
    g.push(x[1] - x[0]);
    g.extend(x.windows(3).map(|w| (w[2] - w[0]) / 2.0));
    g.push(x[n - 1] - x[n - 2]);
    let mut out = vec![0.0; n];
    // Interior: 9-point average.
    let mut window: f64 = g[..9.min(n)].iter().sum();
    for k in 4..n.saturating_sub(4) {
        if k > 4 {
            window += g[k + 4] - g[k - 5];
        }
        out[k] = window / 9.0;
    }
    // Ends: averages over the first and last 1, 3, 5 and 7 points.
    for (k, width) in [(0usize, 1usize), (1, 3), (2, 5), (3, 7)] {
        out[k] = g[..width].iter().sum::<f64>() / width as f64;
        out[n - 1 - k] = g[n - width..].iter().sum::<f64>() / width as f64;
    }
    out
}

#[cfg(test)]
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;

    #[test]
    fn exact_on_quadratics_in_the_interior() {
        // x = k^2: central difference 2k, and the 9-point average of 2k is 2k wherever the
        // window avoids the one-sided end differences.
        let x: Vec<f64> = (0..30).map(|k| (k * k) as f64).collect();
        let d = smoothed_derivative(&x);
        for (k, v) in d.iter().enumerate().take(25).skip(5) {
            assert!((v - 2.0 * k as f64).abs() < 1e-9, "{k}: {v}");
        }
        // Ends: g = [1, 2, 4, 6, 8, 10, 12, ...]; first point 1, second mean(1, 2, 4).
        assert!((d[0] - 1.0).abs() < 1e-12);
        assert!((d[1] - 7.0 / 3.0).abs() < 1e-12);
        assert!((d[29] - 57.0).abs() < 1e-12);
        // Next to the ends the window takes the one-sided difference in: (1 + 2 + ... + 16) / 9.
        assert!((d[4] - 73.0 / 9.0).abs() < 1e-12);
    }
}
