//! Pochhammer-Chree dispersion against closed forms: Rayleigh's long-wave limit, the
//! Rayleigh surface-wave speed at short waves, and a narrow-band pulse that travels at the
//! group velocity of its centre frequency.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use impactcal_models::kolsky::DispersionCurve;

const NU: f64 = 0.33;

#[test]
fn long_waves_follow_rayleighs_correction() {
    let curve = DispersionCurve::solve(NU, 0.2, 0.01).unwrap();
    for (j, ka) in curve.ka.iter().enumerate().skip(1) {
        // c / c0 = 1 - nu^2 pi^2 (a / Lambda)^2 with Lambda = 2 pi / k: 1 - nu^2 (ka)^2 / 4.
        let rayleigh = NU * NU * ka * ka / 4.0;
        let drop = 1.0 - curve.ratio[j];
        // The next term is of order (ka)^2 relative.
        assert!(
            (drop / rayleigh - 1.0).abs() < 2.0 * ka * ka + 1e-6,
            "{ka}: {drop} {rayleigh}"
        );
    }
}

#[test]
fn short_waves_travel_at_the_rayleigh_surface_speed() {
    // Rayleigh's equation in xi = c_R / c_2: (2 - xi^2)^2 = 4 sqrt(1 - xi^2 c2^2/c1^2) sqrt(1 - xi^2).
    let c2c1 = ((1.0 - 2.0 * NU) / (2.0 * (1.0 - NU))).sqrt();
    let g = |xi: f64| {
        (2.0 - xi * xi).powi(2)
            - 4.0 * (1.0 - xi * xi * c2c1 * c2c1).sqrt() * (1.0 - xi * xi).sqrt()
    };
    let (mut lo, mut hi) = (0.5, 0.999);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if g(mid).signum() == g(lo).signum() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let c_r = lo / (2.0 * (1.0 + NU)).sqrt(); // c_R / c_0
    let curve = DispersionCurve::solve(NU, 40.0, 0.02).unwrap();
    let at = |ka: f64| curve.ratio[(ka / 0.02).round() as usize];
    // Within 0.5 % of c_R from k a = 10 on, and closing in (from below, past a shallow
    // minimum near k a = 17).
    for ka in [10.0, 20.0, 30.0, 40.0] {
        assert!((at(ka) / c_r - 1.0).abs() < 5e-3, "{ka}: {} {c_r}", at(ka));
    }
    assert!((at(40.0) - c_r).abs() < (at(20.0) - c_r).abs());
    // The branch falls monotonically from c_0 over the frequencies a bar test holds.
    assert!(curve.ratio[..500].windows(2).all(|w| w[1] < w[0]));
}

#[test]
fn a_narrow_band_pulse_travels_at_its_group_velocity() {
    let (a, c0, z, dt) = (4.735e-3, 4866.0, 1.0, 0.1e-6);
    let curve = DispersionCurve::solve(NU, 6.0, 0.005).unwrap();
    for f0 in [60e3, 150e3] {
        let n = 10_000;
        let width = 40e-6;
        let x: Vec<f64> = (0..n)
            .map(|k| {
                let t = k as f64 * dt - 200e-6;
                (-(t / width).powi(2) / 2.0).exp() * (2.0 * std::f64::consts::PI * f0 * t).cos()
            })
            .collect();
        let y = curve.disperse(&x, dt, z, a, c0, 1.0);
        let centroid = |v: &[f64]| {
            let e: f64 = v.iter().map(|s| s * s).sum();
            v.iter()
                .enumerate()
                .map(|(k, s)| k as f64 * dt * s * s)
                .sum::<f64>()
                / e
        };
        let shift = centroid(&y) - centroid(&x);
        // Group velocity d omega / d k at f0 from the solved branch.
        let w0 = 2.0 * std::f64::consts::PI * f0 * a / c0;
        let h = 1e-4;
        let cg = c0 * 2.0 * h / (curve.ka_at(w0 + h) - curve.ka_at(w0 - h));
        let want = z / cg - z / c0;
        eprintln!(
            "f0 {f0}: c_g / c0 {:.4}, shift {:.3} us, predicted {:.3} us",
            cg / c0,
            shift * 1e6,
            want * 1e6
        );
        assert!(
            want > 0.0 && (shift / want - 1.0).abs() < 1e-2,
            "{shift} {want}"
        );
        // Switched off, nothing moves.
        assert_eq!(curve.disperse(&x, dt, z, a, c0, 0.0), x);
    }
}

#[test]
fn an_impossible_poisson_ratio_is_refused() {
    assert!(DispersionCurve::solve(0.5, 5.0, 0.01).is_err());
    assert!(DispersionCurve::solve(0.3, 5.0, 0.0).is_err());
}
