//! Helpers shared by the command's end-to-end tests.

#![allow(dead_code, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the `impactcal` binary built for these tests with `args`.
pub fn impactcal(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_impactcal"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// Runs the `impactcal` binary with `args` and the environment variables `vars` set.
pub fn impactcal_with(args: &[&str], vars: &[(&str, &str)]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_impactcal"))
        .args(args)
        .envs(vars.iter().copied())
        .output()
        .expect("the binary runs")
}

/// The progress lines `impactcal` printed on a stderr that is not a terminal (`impactcal:
/// [<done>/<planned> runs...] ...`): each with its runs done and planned, and its text after
/// the bracket.
pub fn progress_lines(stderr: &str) -> Vec<(usize, usize, String)> {
    stderr
        .lines()
        .filter_map(|l| {
            let rest = l.strip_prefix("impactcal: [")?;
            let (head, text) = rest
                .split_once("] ")
                .unwrap_or((rest.trim_end_matches(']'), ""));
            let counts = head.split(" runs").next()?;
            let (done, planned) = counts.split_once('/')?;
            Some((done.parse().ok()?, planned.parse().ok()?, text.to_string()))
        })
        .collect()
}

/// A file of `examples/<folder>/` of the repository.
pub fn example_file(folder: &str, name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(folder)
        .join(name)
}

/// A file of the shipped example data (`examples/data/`).
pub fn example(name: &str) -> PathBuf {
    example_file("data", name)
}

/// The JSON a successful run printed on stdout (fails the test, with stderr, otherwise).
pub fn json(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("valid JSON on stdout")
}
