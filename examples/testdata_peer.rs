//! Our side of `benches/peers/testdata_metrics.sh`: reads the inputs the peer script wrote to
//! WORK (ISO/TS 18571 curve pairs, CFC filter inputs, ISO-MME data sets written by pyisomme),
//! answers them, times the ISO/TS 18571 rating of the benchmark pairs, writes those pairs to
//! WORK/bench_pairs.bin for the peer to time, and prints everything as JSON.
//!
//! Usage: `cargo run --release --example testdata_peer -- WORK [REPEATS]`

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::io::Write;
use std::path::Path;
use std::time::Instant;

use impactcal::calibrate::metrics::Iso18571;
use impactcal::core::{Cfc, IsoMme};
use serde_json::{Value, json};

#[path = "../benches/common/metric_pairs.rs"]
mod metric_pairs;
use metric_pairs::{DT, PAIRS, SAMPLES, metric_pairs};

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("readable")).expect("JSON")
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let work = Path::new(args.get(1).expect("usage: testdata_peer WORK [REPEATS]"));
    let repeats: usize = args.get(2).map_or(5, |r| r.parse().expect("repeats"));
    let iso = Iso18571::new();

    let pairs = read_json(&work.join("iso18571_pairs.json"));
    let dt = pairs["dt"].as_f64().unwrap();
    let ratings: Vec<Value> = pairs["cases"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            let reference = floats(&pairs["references"][c["reference"].as_str().unwrap()]);
            let r = iso.rate(&reference, &floats(&c["comparison"]), dt).unwrap();
            serde_json::to_value(r).unwrap()
        })
        .collect();

    let cfc: Vec<Value> = read_json(&work.join("cfc_pyisomme.json"))["cases"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            let class = Cfc::from_class(c["cfc"].as_u64().unwrap() as u32).unwrap();
            let y = class
                .filter(&floats(&c["input"]), c["dt"].as_f64().unwrap(), "peer case")
                .unwrap();
            json!(y)
        })
        .collect();

    let expected = read_json(&work.join("isomme_expected.json"));
    let mut sets = serde_json::Map::new();
    for list in expected.as_object().unwrap().values() {
        for e in list.as_array().unwrap() {
            let rel = e["path"].as_str().unwrap();
            let set = IsoMme::read(work.join(rel), &[]).unwrap();
            let lab = set
                .test_info
                .iter()
                .find(|(k, _)| k == "Laboratory name")
                .and_then(|(_, v)| v.clone());
            let channels: Vec<Value> = set
                .channels
                .iter()
                .map(|c| {
                    json!({"code": c.code, "unit": c.unit, "name": c.name, "start": c.start,
                           "dt": c.dt, "values": c.values, "notes": c.notes})
                })
                .collect();
            sets.insert(
                rel.to_string(),
                json!({"laboratory": lab, "encoding": set.encoding.to_string(), "channels": channels}),
            );
        }
    }

    let bench = metric_pairs();
    let mut file =
        std::io::BufWriter::new(std::fs::File::create(work.join("bench_pairs.bin")).unwrap());
    for (r, c) in &bench {
        for v in r.iter().chain(c) {
            file.write_all(&v.to_le_bytes()).unwrap();
        }
    }
    file.flush().unwrap();
    let mut times = Vec::new();
    let mut rated = Vec::new();
    for _ in 0..repeats {
        let t0 = Instant::now();
        rated = iso.rate_many(&bench, DT).unwrap();
        times.push(t0.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    let out = json!({
        "iso18571": ratings,
        "cfc": cfc,
        "isomme": sets,
        "bench": {"pairs": PAIRS, "samples": SAMPLES, "seconds": times[times.len() / 2],
                  "repeats": repeats, "threads": rayon::current_num_threads(),
                  "r": rated.iter().map(|r| r.r).collect::<Vec<f64>>()},
    });
    println!("{out}");
}
