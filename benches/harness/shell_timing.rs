//! Times whole explicit cycles of the shell solver on the benchmark plate
//! (`benches/common/shell_plate.rs`, 21,000 elastic-plastic quads, 5 thickness points) and
//! prints microseconds per element-cycle, plus a checksum of the final state so that runs on
//! different thread counts can be compared bit for bit.
//!
//! `cargo run --release --example shell_timing -- THREADS CYCLES REPEATS [VARIANT]`
//! (after 20 warm-up cycles; prints the median over the repeats). VARIANT, for profiling
//! by ablation: `full` (default), `noproj` (warping projection off), `elastic` (elastic
//! material), `nip1` (one thickness point).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use impactcal::shell::Simulation;

#[path = "../common/shell_plate.rs"]
mod shell_plate;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let arg = |k: usize, d: usize| args.get(k).map_or(Ok(d), |s| s.parse::<usize>());
    let threads = arg(1, 1)?;
    let cycles = arg(2, 50)?;
    let repeats = arg(3, 5)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let mut m = shell_plate::plate();
    match args.get(4).map_or("full", String::as_str) {
        "full" => {}
        "noproj" => m.control.warping_projection = false,
        "elastic" => m.materials[0].law = impactcal::shell::MaterialLaw::Elastic,
        "nip1" => m.sections[0].nip = 1,
        other => return Err(format!("unknown variant {other}").into()),
    }
    let nip = m.sections[0].nip;
    let ne = m.shells.len();
    let (times, checksum, yielded) =
        pool.install(|| -> Result<_, impactcal::shell::ShellError> {
            let mut sim = Simulation::new(&m)?;
            for _ in 0..20 {
                sim.step()?;
            }
            let mut times = Vec::with_capacity(repeats);
            for _ in 0..repeats.max(1) {
                let start = Instant::now();
                for _ in 0..cycles {
                    sim.step()?;
                }
                times.push(start.elapsed().as_secs_f64());
            }
            let mut h: u64 = 0;
            for p in sim.positions().iter().chain(sim.velocities()) {
                for c in p {
                    h = h.rotate_left(5) ^ c.to_bits();
                }
            }
            let e = sim.energies();
            h = h.rotate_left(5) ^ e.internal.to_bits() ^ e.kinetic.to_bits();
            let yielded = (0..ne)
                .flat_map(|k| (0..nip).map(move |p| (k, p)))
                .filter(|&(k, p)| sim.point_state(k, p).is_some_and(|s| s[3] > 0.0))
                .count();
            Ok((times, h, yielded as f64 / (nip * ne) as f64))
        })?;
    let mut times = times;
    times.sort_by(f64::total_cmp);
    let med = times[times.len() / 2];
    println!(
        "shell_timing: {ne} shells, {threads} thread(s), {cycles} cycles x {}: median {:.3} ms/cycle, {:.4} us/element-cycle, {:.0} % of the points have yielded, checksum {checksum:016x}",
        times.len(),
        1e3 * med / cycles as f64,
        1e6 * med / (cycles as f64 * ne as f64),
        100.0 * yielded
    );
    Ok(())
}
