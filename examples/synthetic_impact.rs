//! Writes the small example data set shipped in `examples/data/`: velocity histories of 8
//! nodes (x, y, z channels) of a structure hitting the ground, once for an "analysis" model
//! (the examples' toy model at its nominal point) and once for a "test" whose stiffness and
//! damping differ, plus a "measured" subset of the test channels for the expansion example.
//!
//! Each channel is a sum of three damped impact responses with known spatial patterns, so the
//! data have three dominant impact shapes (`common/impact_model.rs`). Run with
//! `cargo run --example synthetic_impact -- examples/data`.

use std::path::PathBuf;

#[path = "common/impact_model.rs"]
#[allow(dead_code)]
mod impact_model;
use impact_model::{DT, NODES, SAMPLES, TEST_POINT, impact};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "examples/data".into()),
    );
    std::fs::create_dir_all(&dir)?;
    let analysis = impact(NODES, SAMPLES, DT, 1.0, 1.0);
    let test = impact(NODES, SAMPLES, DT, TEST_POINT[0], TEST_POINT[1]);
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
