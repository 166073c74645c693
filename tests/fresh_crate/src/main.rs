//! `impactcal-fresh-crate STUDY.toml LOOP.toml OUT`: a study file and a loop file run
//! through the impactcal library.

use impactcal::experiment::Experiment;

fn main() -> Result<(), impactcal::Error> {
    let args: Vec<String> = std::env::args().collect();
    let [_, study, closed_loop, out] = args.as_slice() else {
        eprintln!("usage: impactcal-fresh-crate STUDY.toml LOOP.toml OUT");
        std::process::exit(2);
    };
    let out = std::path::Path::new(out);
    let s = Experiment::from_file(study)?.study(out.join("study"))?;
    println!("study: {}", s.result.m1.verdict.as_str());
    let l = Experiment::from_file(closed_loop)?.close_loop(out.join("loop"))?;
    println!("loop: {:?}", l.result.verdict);
    Ok(())
}
