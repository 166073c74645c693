//! The built-in toy model of the examples: velocity histories of 8 nodes (x, y, z channels,
//! `<node>.<x|y|z>`) of a structure hitting the ground, 401 samples of 0.2 ms. Each channel
//! is a sum of three damped impact responses with known spatial patterns (so the data have
//! three dominant impact shapes) and a rebound of the z velocity; two parameters scale the
//! modal frequencies (`stiffness`) and damping ratios (`damping`).
//!
//! `examples/data/analysis.csv` is this model at the nominal point (1, 1) and
//! `examples/data/test.csv` the "test" at (1.12, 1.3) (`synthetic_impact.rs` writes them).

use impactcal::prelude::*;

/// Nodes of the model.
pub const NODES: usize = 8;
/// Samples per history.
pub const SAMPLES: usize = 401;
/// Time step of the histories (s).
pub const DT: f64 = 2e-4;
/// The parameters of the "test" of `examples/data/test.csv`.
pub const TEST_POINT: [f64; 2] = [1.12, 1.3];

/// Velocity histories of `nodes` nodes over `samples` samples of `dt`, for modal frequencies
/// scaled by `stiffness` and damping ratios scaled by `damping`.
pub fn impact(nodes: usize, samples: usize, dt: f64, stiffness: f64, damping: f64) -> Histories {
    let freqs = [38.0, 95.0, 170.0].map(|f: f64| f * stiffness.sqrt());
    let zetas = [0.08, 0.05, 0.04].map(|z| z * damping);
    let amps = [120.0, 45.0, 18.0];
    let mut labels = Vec::new();
    let mut channels = Vec::new();
    for n in 0..nodes {
        let s = (n as f64 + 0.5) / nodes as f64;
        for (d, dir) in ["x", "y", "z"].iter().enumerate() {
            labels.push(format!("{}.{dir}", 100 + n));
            let pattern = |i: usize| -> f64 {
                let p = std::f64::consts::PI * s * (i + 1) as f64;
                match d {
                    0 => 0.3 * p.cos() * (1.0 + 0.2 * i as f64),
                    1 => 0.15 * (p + 0.4).sin() * stiffness.powf(0.25 * i as f64),
                    _ => p.sin() + 0.1 * i as f64,
                }
            };
            let y = (0..samples)
                .map(|k| {
                    let t = k as f64 * dt;
                    (0..3)
                        .map(|i| {
                            let w = 2.0 * std::f64::consts::PI * freqs[i];
                            amps[i] * pattern(i) * (-zetas[i] * w * t).exp() * (w * t).sin()
                        })
                        .sum::<f64>()
                        - if d == 2 {
                            312.0 * (-t / 0.02).exp()
                        } else {
                            0.0
                        }
                })
                .collect();
            channels.push(y);
        }
    }
    match Histories::from_channels(labels, channels, dt, 0.0, "in/s") {
        Ok(h) => h,
        Err(e) => unreachable!("the synthetic channels are valid: {e}"),
    }
}

/// The toy model as an impactcal [`Model`]: `stiffness` in [0.8, 1.4], `damping` in
/// [0.7, 1.6], both nominal 1.
pub struct ImpactModel {
    space: ParameterSpace,
}

impl ImpactModel {
    /// The model with its parameter space.
    pub fn new() -> impactcal::Result<Self> {
        Ok(ImpactModel {
            space: ParameterSpace::new(vec![
                Parameter::new("stiffness", 0.8, 1.4, 1.0)?,
                Parameter::new("damping", 0.7, 1.6, 1.0)?,
            ])?,
        })
    }
}

impl Model for ImpactModel {
    fn space(&self) -> &ParameterSpace {
        &self.space
    }

    fn simulate(&self, p: &[f64]) -> impactcal::core::Result<Histories> {
        Ok(impact(NODES, SAMPLES, DT, p[0], p[1]))
    }
}
