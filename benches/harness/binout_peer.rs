//! Compares impactcal's binout reader with lasso-python's reading of the same files (the
//! JSON written by `benches/peers/binout_lasso.sh`): for every branch and state variable,
//! the times and the values, and prints the largest absolute and relative differences.
//!
//! Run: `benches/peers/binout_lasso.sh` (it runs this with the JSON).

use std::path::Path;

use impactcal::runner::Binout;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let json = std::env::args()
        .nth(1)
        .ok_or("usage: binout_peer LASSO.json")?;
    let peer: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(json)?)?;
    let files = peer.as_object().ok_or("not a JSON object")?;
    println!(
        "{:<48} {:<20} {:>6} {:>8} {:>12} {:>12}",
        "file", "branch", "times", "values", "max |diff|", "max rel"
    );
    let mut worst: f64 = 0.0;
    for (file, branches) in files {
        let ours = Binout::open(Path::new(file))?;
        let ours_branches = ours.branches();
        for (branch, vars) in branches.as_object().ok_or("branches")? {
            if !ours_branches.contains(branch) {
                println!("{file:<48} {branch:<20} missing on our side");
                worst = f64::INFINITY;
                continue;
            }
            let vars = vars.as_object().ok_or("variables")?;
            let times: Vec<f64> = vars["time"]
                .as_array()
                .ok_or("time")?
                .iter()
                .filter_map(serde_json::Value::as_f64)
                .collect();
            let b = ours.branch(branch, &[])?;
            let (mut n, mut abs, mut rel) = (0usize, 0.0_f64, 0.0_f64);
            let mut cmp = |a: f64, b: f64| {
                n += 1;
                let d = (a - b).abs();
                abs = abs.max(d);
                if d > 0.0 {
                    rel = rel.max(d / a.abs().max(b.abs()));
                }
            };
            if b.times.len() != times.len() {
                println!(
                    "{file:<48} {branch:<20} {} times here, {} in lasso",
                    b.times.len(),
                    times.len()
                );
                worst = f64::INFINITY;
                continue;
            }
            for (a, t) in b.times.iter().zip(&times) {
                cmp(*a, *t);
            }
            for (name, rows) in vars {
                if name == "time" {
                    continue;
                }
                let rows = rows.as_array().ok_or("rows")?;
                let width = rows.first().and_then(|r| r.as_array()).map_or(0, Vec::len);
                let ours_cols: Vec<(usize, &Vec<f64>)> = b
                    .labels
                    .iter()
                    .zip(&b.columns)
                    .enumerate()
                    .filter(|(_, (l, _))| {
                        l.as_str() == name
                            || l.ends_with(&format!(".{name}"))
                            || l.starts_with(&format!("{name}."))
                    })
                    .map(|(k, (_, c))| (k, c))
                    .collect();
                if ours_cols.len() != width {
                    println!(
                        "{file:<48} {branch:<20} {name}: {} columns here, {width} in lasso",
                        ours_cols.len()
                    );
                    worst = f64::INFINITY;
                    continue;
                }
                for (j, (_, col)) in ours_cols.iter().enumerate() {
                    for (s, row) in rows.iter().enumerate() {
                        let v = row
                            .as_array()
                            .and_then(|r| r[j].as_f64())
                            .unwrap_or(f64::NAN);
                        cmp(col[s], v);
                    }
                }
            }
            worst = worst.max(rel);
            println!(
                "{file:<48} {branch:<20} {:>6} {n:>8} {abs:>12.3e} {rel:>12.3e}",
                times.len()
            );
        }
    }
    println!("largest relative difference: {worst:e}");
    Ok(())
}
