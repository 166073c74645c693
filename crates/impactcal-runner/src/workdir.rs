//! Work directories and atomic files.
//!
//! Each run has its own directory `<root>/<index>/` holding its rendered inputs, the
//! solver's `stdout.txt` and `stderr.txt`, its `exit_status` (one line: the exit code, or
//! 128 + the signal number), its outputs, `result.csv` (the histories as read back, in our
//! wide CSV) and `params.json` (parameters, values as written, attempt, timings).
//!
//! `exit_status`, `result.csv` and `params.json` are written atomically: to a temporary file
//! in the same directory, flushed to disk, then renamed over the target (and the directory
//! flushed), so a reader sees the old file or the whole new one, never half of it.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// The solver's standard output, in the run's directory.
pub const STDOUT: &str = "stdout.txt";
/// The solver's standard error.
pub const STDERR: &str = "stderr.txt";
/// The solver's exit status (one line).
pub const EXIT_STATUS: &str = "exit_status";
/// The histories read back from the solver's output.
pub const RESULT: &str = "result.csv";
/// Parameters and timings of the run.
pub const PARAMS: &str = "params.json";

/// Writes `bytes` to `path` atomically (temporary file, flush, rename, flush the
/// directory).
///
/// # Errors
/// The operating system's error.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{name}.tmp{}", std::process::id()));
    {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
    }
    std::fs::rename(&tmp, path)?;
    sync_dir(dir)
}

/// Flushes a directory's entries to disk (so a rename survives a crash).
pub(crate) fn sync_dir(dir: &Path) -> std::io::Result<()> {
    std::fs::File::open(dir)?.sync_all()
}

/// The exit status recorded in a run's directory: `Some(code)` when the file exists and
/// holds a whole number, `None` when it does not exist (the run has not ended, or was
/// lost). A file that exists but does not parse counts as absent (it cannot be half
/// written, see the module docs; a foreign file is not trusted).
pub fn read_exit_status(dir: &Path) -> Option<i32> {
    std::fs::read_to_string(dir.join(EXIT_STATUS))
        .ok()
        .and_then(|s| s.trim().parse().ok())
}

/// The record of one run kept in its `params.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    /// 0-based index of the run in its batch.
    pub index: usize,
    /// 1-based attempt.
    pub attempt: u32,
    /// Parameter names, in the batch's order.
    pub names: Vec<String>,
    /// The values asked for.
    pub values: Vec<f64>,
    /// The values as written into the inputs (after rounding to fit fixed-width fields).
    pub written: Vec<f64>,
    /// Quantities held at given values in this run (a test condition, such as another impact
    /// speed), by name: not coordinates of the point, but part of what the run computes. A
    /// program that reads `params.json` must apply them (or refuse the run). Absent when
    /// there are none.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub set: BTreeMap<String, f64>,
    /// When the inputs were written (seconds since the Unix epoch).
    pub prepared_at: f64,
    /// When the result was read back, if it was.
    pub finished_at: Option<f64>,
    /// Wall time from preparation to the result read back, in seconds.
    pub seconds: Option<f64>,
    /// The solver's exit status, when it ended.
    pub exit_status: Option<i32>,
}

/// Seconds since the Unix epoch.
pub(crate) fn now() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}

/// The directory of run `index` under `root`.
pub fn run_dir(root: &Path, index: usize) -> PathBuf {
    root.join(index.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_replaces_whole_files() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join(EXIT_STATUS);
        assert_eq!(read_exit_status(dir.path()), None);
        write_atomic(&p, b"3\n").unwrap();
        assert_eq!(read_exit_status(dir.path()), Some(3));
        write_atomic(&p, b"0\n").unwrap();
        assert_eq!(read_exit_status(dir.path()), Some(0));
        // No temporary file is left behind.
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from(EXIT_STATUS)]);
        std::fs::write(&p, "garbage").unwrap();
        assert_eq!(read_exit_status(dir.path()), None);
    }
}
