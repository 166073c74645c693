//! Times `impactcal_sensors::place` on a shape-matrix CSV, for the peer comparison in
//! `benches/peers/sdynpy_efi.sh`. Prints the median time of the placement alone (reading the
//! file excluded) and writes the chosen candidate indices, one per line.
//!
//! `cargo run --release --example place_timing -- MATRIX.csv TARGET REPEATS OUT.txt`

use std::time::Instant;

use impactcal::sensors::{CandidateShapes, PlacementOptions, place};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 5 {
        return Err("usage: place_timing MATRIX.csv TARGET REPEATS OUT.txt".into());
    }
    let candidates = CandidateShapes::read_csv(&args[1])?;
    let target: usize = args[2].parse()?;
    let repeats: usize = args[3].parse()?;
    let options = PlacementOptions::new(target);
    let mut times = Vec::with_capacity(repeats);
    let mut selected = Vec::new();
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        let p = place(&candidates, &options)?;
        times.push(start.elapsed().as_secs_f64());
        selected = p.selected_indices;
    }
    times.sort_by(f64::total_cmp);
    println!(
        "impactcal: {} x {} -> {target}: median {:.6} s over {} runs",
        candidates.candidates(),
        candidates.shapes_count(),
        times[times.len() / 2],
        times.len()
    );
    let text: String = selected.iter().map(|i| format!("{i}\n")).collect();
    std::fs::write(&args[4], text)?;
    Ok(())
}
