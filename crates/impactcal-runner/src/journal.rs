//! The run journal: an append-only JSON-lines file that records each run before it is
//! submitted and each result after it is read, flushed to disk at every line.
//!
//! A driver killed at any moment leaves a journal whose complete lines are all true; a line
//! cut short by the kill is dropped when the journal is opened again (and the file is cut
//! back to its last complete line before anything is appended). Size: about 150 bytes per
//! event plus the batch line (the points, about 25 bytes per coordinate).

use std::collections::BTreeMap;
use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{Result, RunnerError, io};

/// One line of the journal.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum Entry {
    /// The batch: its study, parameter names, points and a fingerprint of the solver
    /// (templates, command, output), or of whatever the batch was given as its identity
    /// ([`Batch::with_identity`](crate::Batch::with_identity)). Written once, first.
    Batch {
        /// Study name.
        study: String,
        /// Parameter names.
        names: Vec<String>,
        /// One point per run.
        points: Vec<Vec<f64>>,
        /// Fingerprint of the solver configuration (hex).
        solver: String,
        /// Quantities held at given values in every run (a test condition), by name; absent
        /// when there are none ([`Batch::new_at`](crate::Batch::new_at)).
        #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
        set: BTreeMap<String, f64>,
    },
    /// Run `index`, attempt `attempt`, is about to be started by `executor`.
    Submit {
        /// Run.
        index: usize,
        /// 1-based attempt.
        attempt: u32,
        /// `local`, `processes` or `slurm`.
        executor: String,
    },
    /// A local solver process was started: its pid and start time (clock ticks since boot,
    /// from `/proc/<pid>/stat`), so a later driver can tell it from a reused pid.
    Started {
        /// Run.
        index: usize,
        /// Attempt.
        attempt: u32,
        /// Process id.
        pid: u32,
        /// Start time in clock ticks since boot (0 when unknown).
        start_ticks: u64,
    },
    /// A Slurm job array is about to be submitted: its job name (`token`) and the runs of
    /// its tasks, task `k` running `indices[k]`.
    SlurmSubmit {
        /// The job name, unique to this submission.
        token: String,
        /// Run of each array task.
        indices: Vec<usize>,
    },
    /// The array job id sbatch returned for `token`.
    SlurmJob {
        /// The job name.
        token: String,
        /// The array job id.
        job_id: String,
    },
    /// Run `index` succeeded; its histories are in `file` (relative to the runs root).
    Result {
        /// Run.
        index: usize,
        /// Attempt.
        attempt: u32,
        /// The result file.
        file: String,
        /// The unit of the histories (our CSV does not carry it).
        #[serde(default)]
        unit: String,
    },
    /// Run `index` failed; `retry` says whether another attempt follows.
    Failure {
        /// Run.
        index: usize,
        /// Attempt.
        attempt: u32,
        /// The error.
        error: String,
        /// Whether it is retried.
        retry: bool,
    },
}

/// An open journal, appending.
#[derive(Debug)]
pub struct Journal {
    path: PathBuf,
    file: File,
}

impl Journal {
    /// Opens (or creates) the journal at `path` and returns it with the entries it holds. A
    /// last line without its newline (a write cut short) is dropped and cut off the file.
    ///
    /// # Errors
    /// [`RunnerError::Io`] when the file cannot be opened, read or repaired;
    /// [`RunnerError::Journal`] naming the line of a complete line that is not a journal
    /// entry (the file is not ours, or was edited).
    pub fn open(path: &Path) -> Result<(Journal, Vec<Entry>)> {
        let mut file = OpenOptions::new()
            .read(true)
            .create(true)
            .truncate(false)
            .write(true)
            .open(path)
            .map_err(io(path))?;
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes).map_err(io(path))?;
        let complete = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1);
        if complete < bytes.len() {
            file.set_len(complete as u64).map_err(io(path))?;
            file.sync_all().map_err(io(path))?;
        }
        file.seek(SeekFrom::End(0)).map_err(io(path))?;
        let text = String::from_utf8_lossy(&bytes[..complete]);
        let mut entries = Vec::new();
        for (i, line) in text.lines().enumerate() {
            if line.trim().is_empty() {
                continue;
            }
            let e: Entry = serde_json::from_str(line).map_err(|e| RunnerError::Journal {
                path: path.to_path_buf(),
                line: i + 1,
                message: format!("not a journal entry: {e}"),
            })?;
            entries.push(e);
        }
        Ok((
            Journal {
                path: path.to_path_buf(),
                file,
            },
            entries,
        ))
    }

    /// Appends one entry and flushes it to disk before returning.
    ///
    /// # Errors
    /// [`RunnerError::Io`] when the write or the flush fails.
    pub fn append(&mut self, entry: &Entry) -> Result<()> {
        let mut line = serde_json::to_string(entry).map_err(|e| RunnerError::Journal {
            path: self.path.clone(),
            line: 0,
            message: e.to_string(),
        })?;
        line.push('\n');
        self.file
            .write_all(line.as_bytes())
            .map_err(io(&self.path))?;
        self.file.sync_data().map_err(io(&self.path))
    }

    /// The journal's path.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn torn_last_line_is_dropped_and_cut() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("journal.jsonl");
        let (mut j, e) = Journal::open(&p).unwrap();
        assert!(e.is_empty());
        let a = Entry::Submit {
            index: 0,
            attempt: 1,
            executor: "processes".into(),
        };
        let b = Entry::Result {
            index: 0,
            attempt: 1,
            file: "0/result.csv".into(),
            unit: "in/s".into(),
        };
        j.append(&a).unwrap();
        j.append(&b).unwrap();
        drop(j);
        // A kill in the middle of a write leaves half a line.
        let mut f = OpenOptions::new().append(true).open(&p).unwrap();
        f.write_all(b"{\"event\":\"resu").unwrap();
        drop(f);
        let (mut j, e) = Journal::open(&p).unwrap();
        assert_eq!(e, vec![a.clone(), b.clone()]);
        j.append(&a).unwrap();
        let (_, e) = Journal::open(&p).unwrap();
        assert_eq!(e, vec![a.clone(), b, a]);
        std::fs::write(&p, "{\"event\":\"nonsense\"}\n").unwrap();
        let err = Journal::open(&p).unwrap_err();
        assert!(
            err.to_string().contains("line 1: not a journal entry"),
            "{err}"
        );
    }
}
