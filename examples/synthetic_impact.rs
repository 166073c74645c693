//! Writes the small example data set shipped in `examples/data/`: velocity histories of 8
#![allow(clippy::expect_used)]
//! nodes (x, y, z channels) of a structure hitting the ground, once for an "analysis" model
//! and once for a "test" whose stiffness and damping differ, plus a "measured" subset of the
//! test channels for the expansion example.
//!
//! Each channel is a sum of three damped impact responses with known spatial patterns, so the
//! data have three dominant impact shapes. Run with
//! `cargo run --example synthetic_impact -- examples/data`.

use std::path::PathBuf;

use impactcal::core::Histories;

/// Velocity histories of `nodes` nodes over `samples` samples of `dt`, for modal frequencies
/// scaled by `stiffness` and damping ratios scaled by `damping`.
fn impact(nodes: usize, samples: usize, dt: f64, stiffness: f64, damping: f64) -> Histories {
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
    Histories::from_channels(labels, channels, dt, 0.0, "in/s").expect("valid synthetic data")
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "examples/data".into()),
    );
    std::fs::create_dir_all(&dir)?;
    let analysis = impact(8, 401, 2e-4, 1.0, 1.0);
    let test = impact(8, 401, 2e-4, 1.12, 1.3);
    analysis.write_csv(dir.join("analysis.csv"))?;
    test.write_csv(dir.join("test.csv"))?;
    let measured = [
        "100.z", "101.x", "102.z", "103.y", "104.z", "105.x", "106.z", "107.z",
    ];
    test.select(&measured)?
        .write_csv(dir.join("measured.csv"))?;
    println!(
        "wrote analysis.csv, test.csv and measured.csv to {}",
        dir.display()
    );
    Ok(())
}
