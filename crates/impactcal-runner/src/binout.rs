//! LS-DYNA's `binout` branches as [`Histories`].
//!
//! A branch (`nodout`, `glstat`, `matsum`, `rwforc/forces`, `rcforc`, `sleout`,
//! `secforc`, `elout/shell`, ...) is a directory of the LSDA tree ([`crate::lsda`]) with a
//! `metadata` directory (ids, titles) and one directory per output time (`d000001`, ...)
//! holding that time's `time` and its variables. A variable with an item per id of
//! `metadata/ids` gives a channel per id, `<id>.<variable>` (`167.x_velocity`, `2.x_force`
//! for rigid wall 2; `rcforc` labels the two sides of an interface `<id>m` and `<id>s`
//! after `metadata/side`); one with a single item in a branch without ids is one channel,
//! labelled with its name (`kinetic_energy`); any other length `n` gives `<variable>.<k>`
//! for `k = 1..n`. States are taken in the order of
//! their times; every state must hold every variable read, with the same length. LS-DYNA
//! writes a state at the first cycle past each output time, so the times stray by up to a
//! solver step: a branch whose steps are not uniform is put on a uniform base by linear
//! interpolation as the other outputs are ([`crate::outputs`]), with a note saying so.

use std::path::{Path, PathBuf};

use impactcal_core::Histories;

use crate::error::{Result, RunnerError};
use crate::lsda::{Entry, Lsda, family};

/// A `binout` file (with its family of continuation and per-process files) opened.
#[derive(Debug)]
pub struct Binout {
    lsda: Lsda,
    path: PathBuf,
}

/// A branch read as it is in the file: its output times and its channels at those times.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch {
    /// Output times, increasing.
    pub times: Vec<f64>,
    /// Channel labels.
    pub labels: Vec<String>,
    /// One column per label, one value per time.
    pub columns: Vec<Vec<f64>>,
}

fn is_state(name: &str) -> bool {
    name.len() > 1 && name.starts_with('d') && name[1..].bytes().all(|b| b.is_ascii_digit())
}

impl Binout {
    /// Opens `path` and the files of its family ([`crate::lsda::family`]).
    ///
    /// # Errors
    /// As [`Lsda::open`].
    pub fn open(path: &Path) -> Result<Binout> {
        Ok(Binout {
            lsda: Lsda::open(&family(path))?,
            path: path.to_path_buf(),
        })
    }

    fn fault(&self, message: String) -> RunnerError {
        RunnerError::Result {
            path: self.path.clone(),
            message,
        }
    }

    /// Every branch of the file, as `/`-separated paths (`glstat`, `rwforc/forces`).
    pub fn branches(&self) -> Vec<String> {
        let mut out = Vec::new();
        fn walk(d: &std::collections::BTreeMap<String, Entry>, path: &str, out: &mut Vec<String>) {
            let states = d.keys().any(|k| is_state(k));
            if states || d.contains_key("metadata") {
                out.push(path.to_string());
            }
            for (k, e) in d {
                if let Entry::Dir(sub) = e
                    && !is_state(k)
                    && k != "metadata"
                {
                    let p = if path.is_empty() {
                        k.clone()
                    } else {
                        format!("{path}/{k}")
                    };
                    walk(sub, &p, out);
                }
            }
        }
        walk(self.lsda.root(), "", &mut out);
        out
    }

    /// The state directories of a branch, and the branch's directory entries.
    fn states(
        &self,
        branch: &str,
    ) -> Result<(Vec<String>, &std::collections::BTreeMap<String, Entry>)> {
        let Some(Entry::Dir(d)) = self.lsda.get(branch) else {
            return Err(self.fault(format!(
                "no branch `{branch}` (the file has: {})",
                self.branches().join(", ")
            )));
        };
        Ok((d.keys().filter(|k| is_state(k)).cloned().collect(), d))
    }

    /// The variables of a branch's states (beside `time`) with their number of items in
    /// the first state, in name order.
    ///
    /// # Errors
    /// [`RunnerError::Result`] for a branch the file does not have.
    pub fn variables(&self, branch: &str) -> Result<Vec<(String, u64)>> {
        let (states, d) = self.states(branch)?;
        let Some(Entry::Dir(first)) = states.first().and_then(|s| d.get(s)) else {
            return Ok(Vec::new());
        };
        Ok(first
            .iter()
            .filter_map(|(k, e)| match e {
                Entry::Var(v) if k != "time" => Some((k.clone(), v.len)),
                _ => None,
            })
            .collect())
    }

    /// The ids of a branch (`metadata/ids`), with `m`/`s` appended after `metadata/side`
    /// for contact forces; empty when it has none.
    fn ids(&self, branch: &str) -> Result<Vec<String>> {
        let ids = match self.lsda.get(&format!("{branch}/metadata/ids")) {
            Some(Entry::Var(_)) => self.lsda.read(&format!("{branch}/metadata/ids"))?,
            _ => return Ok(Vec::new()),
        };
        let side = match self.lsda.get(&format!("{branch}/metadata/side")) {
            Some(Entry::Var(_)) => Some(self.lsda.read(&format!("{branch}/metadata/side"))?),
            _ => None,
        };
        Ok(ids
            .iter()
            .enumerate()
            .map(|(k, &id)| {
                let s = match side.as_ref().and_then(|s| s.get(k)) {
                    Some(&v) if v != 0.0 => "m",
                    Some(_) => "s",
                    None => "",
                };
                format!("{}{s}", id as i64)
            })
            .collect())
    }

    /// A branch as it is in the file: its times and the channels of the variables
    /// `channels` (variable names, or labels `<id>.<variable>`; all by default).
    ///
    /// # Errors
    /// [`RunnerError::Result`] naming the branch, state or variable: a branch without
    /// states, a state without `time` or without a variable read, lengths that change
    /// between states, a channel that is not there (the message lists the variables).
    pub fn branch(&self, branch: &str, channels: &[String]) -> Result<Branch> {
        let branch = branch.trim_matches('/');
        let (states, _) = self.states(branch)?;
        if states.is_empty() {
            return Err(self.fault(format!("branch `{branch}` holds no output time")));
        }
        let vars = self.variables(branch)?;
        let ids = self.ids(branch)?;
        let label = |var: &str, len: u64, k: usize| -> String {
            if !ids.is_empty() && len as usize == ids.len() {
                format!("{}.{var}", ids[k])
            } else if len == 1 {
                var.to_string()
            } else {
                format!("{var}.{}", k + 1)
            }
        };
        // Which (variable, item) pairs to read.
        let mut want: Vec<(String, u64, usize)> = Vec::new();
        for (v, len) in &vars {
            for k in 0..*len as usize {
                let l = label(v, *len, k);
                if channels.is_empty() || channels.iter().any(|c| c == v || *c == l) {
                    want.push((v.clone(), *len, k));
                }
            }
        }
        for c in channels {
            let known = vars
                .iter()
                .any(|(v, len)| v == c || (0..*len as usize).any(|k| label(v, *len, k) == *c));
            if !known {
                let names: Vec<String> = vars.iter().map(|(v, n)| format!("{v} ({n})")).collect();
                return Err(self.fault(format!(
                    "branch `{branch}` has no channel `{c}`; its variables (items a state): {}",
                    names.join(", ")
                )));
            }
        }
        let mut rows: Vec<(f64, Vec<f64>)> = Vec::with_capacity(states.len());
        let mut cache: Vec<(String, Vec<f64>)> = Vec::new();
        for s in &states {
            let t = self.lsda.read(&format!("{branch}/{s}/time"))?;
            let &[t] = t.as_slice() else {
                return Err(self.fault(format!(
                    "{branch}/{s}: `time` holds {} items, not 1",
                    t.len()
                )));
            };
            cache.clear();
            let mut row = Vec::with_capacity(want.len());
            for (v, len, k) in &want {
                if !cache.iter().any(|c| c.0 == *v) {
                    let data = self.lsda.read(&format!("{branch}/{s}/{v}")).map_err(|_| {
                        self.fault(format!(
                            "{branch}/{s}: no variable `{v}` (the first state has it)"
                        ))
                    })?;
                    if data.len() as u64 != *len {
                        return Err(self.fault(format!(
                            "{branch}/{s}: `{v}` holds {} items where the first state holds {len}",
                            data.len()
                        )));
                    }
                    cache.push((v.clone(), data));
                }
                let data = &cache.iter().find(|c| c.0 == *v).map(|c| &c.1);
                row.push(data.map_or(f64::NAN, |d| d[*k]));
            }
            rows.push((t, row));
        }
        rows.sort_by(|a, b| a.0.total_cmp(&b.0));
        let labels: Vec<String> = want.iter().map(|(v, len, k)| label(v, *len, *k)).collect();
        let columns = (0..want.len())
            .map(|c| rows.iter().map(|r| r.1[c]).collect())
            .collect();
        Ok(Branch {
            times: rows.iter().map(|r| r.0).collect(),
            labels,
            columns,
        })
    }

    /// A branch as [`Histories`] on a uniform time base (see the module docs), and a note
    /// when its times had to be resampled.
    ///
    /// # Errors
    /// As [`Binout::branch`]; [`RunnerError::Result`] for fewer than two output times,
    /// times that do not increase, or a value that is not finite.
    pub fn histories(
        &self,
        branch: &str,
        channels: &[String],
    ) -> Result<(Histories, Option<String>)> {
        let b = self.branch(branch, channels)?;
        for (l, c) in b.labels.iter().zip(&b.columns) {
            if let Some(k) = c.iter().position(|v| !v.is_finite()) {
                return Err(self.fault(format!(
                    "branch `{branch}`: `{l}` is not finite at t = {}",
                    b.times[k]
                )));
            }
        }
        let lines: Vec<usize> = (1..=b.times.len()).collect();
        let uniform = crate::outputs::uniform(b.labels, &b.times, b.columns, &lines)
            .map_err(|(k, m)| self.fault(format!("branch `{branch}`, output time {k}: {m}")))?;
        Ok(uniform)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lsda::write::{Var, file, ints, reals};

    #[test]
    fn a_nodout_branch_gives_a_channel_per_node_and_variable() {
        let dir = tempfile::tempdir().unwrap();
        let mut vars = vec![Var {
            dir: "/nodout/metadata",
            name: "ids",
            code: 3,
            items: ints(&[21, 42], false),
            len: 2,
        }];
        let states = ["d000001", "d000002", "d000003"];
        let dirs: Vec<String> = states.iter().map(|s| format!("/nodout/{s}")).collect();
        for (k, d) in dirs.iter().enumerate() {
            // States written out of order of time: read back in time order.
            let t = [0.0, 2e-4, 1e-4][k];
            vars.push(Var {
                dir: d,
                name: "time",
                code: 10,
                items: reals(&[t], false),
                len: 1,
            });
            vars.push(Var {
                dir: d,
                name: "x_velocity",
                code: 10,
                items: reals(&[t * 10.0, -t], false),
                len: 2,
            });
        }
        let p = dir.path().join("binout");
        std::fs::write(&p, file(&vars, 8, false)).unwrap();
        let b = Binout::open(&p).unwrap();
        assert_eq!(b.branches(), ["nodout"]);
        let (h, note) = b.histories("nodout", &[]).unwrap();
        assert!(note.is_none());
        assert_eq!(h.labels(), ["21.x_velocity", "42.x_velocity"]);
        assert_eq!(h.channel(0), [0.0, 1e-3, 2e-3]);
        let (h, _) = b.histories("nodout", &["42.x_velocity".into()]).unwrap();
        assert_eq!(h.channel(0), [0.0, -1e-4, -2e-4]);
        let e = b
            .histories("nodout", &["y_velocity".into()])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("no channel `y_velocity`") && e.contains("x_velocity (2)"),
            "{e}"
        );
        let e = b.histories("glstat", &[]).unwrap_err().to_string();
        assert!(
            e.contains("no branch `glstat` (the file has: nodout)"),
            "{e}"
        );
    }

    #[test]
    fn per_process_files_and_continuations_read_as_one_branch() {
        let dir = tempfile::tempdir().unwrap();
        let state = |d: &'static str, t: f64, big: bool| {
            vec![
                Var {
                    dir: d,
                    name: "time",
                    code: 10,
                    items: reals(&[t], big),
                    len: 1,
                },
                Var {
                    dir: d,
                    name: "kinetic_energy",
                    code: 10,
                    items: reals(&[100.0 - t], big),
                    len: 1,
                },
            ]
        };
        let mut first = state("/glstat/d000001", 0.0, false);
        first.extend(state("/glstat/d000002", 1.0, false));
        std::fs::write(dir.path().join("binout0000"), file(&first, 8, false)).unwrap();
        // The second file big-endian with 4-byte fields: each file has its own header.
        std::fs::write(
            dir.path().join("binout0001"),
            file(&state("/glstat/d000003", 2.0, true), 4, true),
        )
        .unwrap();
        std::fs::write(
            dir.path().join("binout0000%001"),
            file(&state("/glstat/d000004", 3.0, false), 8, false),
        )
        .unwrap();
        let b = Binout::open(&dir.path().join("binout0000")).unwrap();
        let (h, _) = b.histories("glstat", &[]).unwrap();
        assert_eq!(h.labels(), ["kinetic_energy"]);
        assert_eq!(h.channel(0), [100.0, 99.0, 98.0, 97.0]);
        // A file cut short is an error naming the byte, not a panic.
        let whole = std::fs::read(dir.path().join("binout0001")).unwrap();
        for cut in [0, 5, 9, 20, whole.len() - 3] {
            let p = dir.path().join("cut");
            std::fs::write(&p, &whole[..cut]).unwrap();
            let r = Binout::open(&p).and_then(|b| b.histories("glstat", &[]).map(|_| ()));
            assert!(r.is_err(), "cut at {cut}");
        }
    }
}
