//! Memory: what this process holds, what it may still take, and the guard that stops a
//! stage of the study or the loop before it allocates more than that.
//!
//! A stage's need is estimated from its shapes before it allocates (the loop's in
//! `closeloop::plan`, the study's in `study::plan`), in bytes it adds to what the process
//! already holds. The guard compares `held + need` with the limit: the user's (`max_memory`,
//! `impactcal close-loop --max-memory`), or else what the machine can still give, read from
//! the operating system (Linux: `MemAvailable` of `/proc/meminfo`, and in a control group
//! with a memory limit that limit less the group's use). A stage that would not fit stops
//! with [`CalibrateError::Memory`], naming the stage, its estimate, the limit and what to
//! change, instead of being killed by the kernel's out-of-memory killer; where the system
//! says nothing (another operating system) only a user's limit is checked.

use crate::error::{CalibrateError, Result};

/// Bytes of one `f64`.
pub(crate) const F64: u64 = 8;

/// A field of `/proc/self/status` in bytes (`VmRSS:   1234 kB`).
fn status_field(name: &str) -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    kilobytes(&text, name)
}

/// `<name>: <value> kB` of a `/proc` file's text, in bytes.
fn kilobytes(text: &str, name: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with(name))?;
    let value = line[name.len()..]
        .trim_start_matches(':')
        .split_whitespace()
        .next()?;
    Some(value.parse::<u64>().ok()? * 1024)
}

/// The resident memory of this process (`VmRSS`), where the system says it (Linux).
pub fn resident_bytes() -> Option<u64> {
    status_field("VmRSS")
}

/// The largest resident memory of this process so far (`VmHWM`), where the system says
/// it (Linux).
pub fn peak_resident_bytes() -> Option<u64> {
    status_field("VmHWM")
}

/// The memory the machine can still give this process: `MemAvailable` (the kernel's
/// estimate of what can be allocated without swapping), and in a control group (v2) with a
/// memory limit, that limit less the group's use, whichever is smaller; `None` where the
/// system says neither.
pub fn available_bytes() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|t| kilobytes(&t, "MemAvailable"));
    let group = cgroup_headroom();
    match (meminfo, group) {
        (Some(a), Some(g)) => Some(a.min(g)),
        (a, g) => a.or(g),
    }
}

/// `memory.max - memory.current` of this process's control group (v2), when it has a limit.
fn cgroup_headroom() -> Option<u64> {
    let entry = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let path = entry.lines().find_map(|l| l.strip_prefix("0::"))?.trim();
    let dir = std::path::Path::new("/sys/fs/cgroup").join(path.trim_start_matches('/'));
    let read = |f: &str| std::fs::read_to_string(dir.join(f)).ok();
    let max: u64 = read("memory.max")?.trim().parse().ok()?;
    let current: u64 = read("memory.current")?.trim().parse().ok()?;
    Some(max.saturating_sub(current))
}

/// A size in bytes as people read it: `512 kB`, `3.4 MB`, `12.9 GB` (powers of 1000).
pub fn human(bytes: u64) -> String {
    let b = bytes as f64;
    if b < 1e6 {
        format!("{:.0} kB", b / 1e3)
    } else if b < 1e9 {
        format!("{:.1} MB", b / 1e6)
    } else {
        format!("{:.1} GB", b / 1e9)
    }
}

/// The stages of a study or loop as formulas of its shapes: what it holds throughout and
/// what each kind of stage adds at its peak, in values of 8 bytes, and what to change when
/// one does not fit.
pub(crate) trait Stages {
    /// Who plans (`the loop`, `the study`), for the messages.
    const WHO: &'static str;

    /// Values held throughout (beside what the process holds when it is planned).
    fn held(&self) -> u64;

    /// Each kind of stage with the values it adds at its peak, in order.
    fn stages(&self) -> Vec<(&'static str, u64)>;

    /// What the stage of kind `kind` grows with and what to change.
    fn advice(&self, kind: &str) -> String;

    /// The bytes added at the peak to what the process holds when planned: the held part
    /// and the largest stage.
    fn peak(&self) -> u64 {
        let stage = self.stages().iter().map(|s| s.1).max().unwrap_or(0);
        F64 * (self.held() + stage)
    }
}

/// The memory plan of one study or loop: its shapes and the guard that checks them.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Plan<S> {
    pub shapes: S,
    pub guard: Guard,
}

impl<S: Stages> Plan<S> {
    /// The need of stage `kind` named `stage` (a journal stage, or the step).
    fn need(&self, kind: &str, stage: &str) -> Need {
        let values = self
            .shapes
            .stages()
            .into_iter()
            .find(|s| s.0 == kind)
            .map_or(0, |s| s.1);
        Need {
            stage: stage.to_string(),
            bytes: F64 * values,
            advice: self.shapes.advice(kind),
        }
    }

    /// Checks every stage before the first: what the process holds, the held part and the
    /// stage together.
    ///
    /// # Errors
    /// [`CalibrateError::Memory`] naming the first stage that would not fit.
    pub fn check_all(&self) -> Result<()> {
        let held = F64 * self.shapes.held();
        for (kind, values) in self.shapes.stages() {
            let mut need = self.need(kind, kind);
            need.bytes = held + F64 * values;
            need.advice = format!(
                "{} ({} holds about {} throughout)",
                need.advice,
                S::WHO,
                human(held)
            );
            self.guard.check(&need)?;
        }
        Ok(())
    }

    /// Checks stage `kind`, named `stage`, against what the process holds now.
    ///
    /// # Errors
    /// [`CalibrateError::Memory`] when it would not fit.
    pub fn check(&self, kind: &str, stage: &str) -> Result<()> {
        self.guard.check(&self.need(kind, stage))
    }

    /// The line shown once the plan is made: the peak it plans beside what the process
    /// holds, and the limit.
    pub fn line(&self) -> String {
        let held = resident_bytes().unwrap_or(0);
        let limit = match self.guard.limit {
            Some(l) => format!("the limit given is {}", human(l)),
            None => available_bytes().map_or_else(
                || "the machine does not say what it has available".to_string(),
                |a| format!("the machine has {} available", human(a)),
            ),
        };
        format!(
            "memory: {} plans about {} at its peak ({} held now); {limit}",
            S::WHO,
            human(held.saturating_add(self.shapes.peak())),
            human(held)
        )
    }
}

/// What a stage needs, from its shapes.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Need {
    /// The stage (a journal stage's name, or the step).
    pub stage: String,
    /// Bytes the stage adds to what the process holds, at its peak.
    pub bytes: u64,
    /// What its size grows with and what to change, for the message.
    pub advice: String,
}

/// The memory guard of one study or loop: the user's limit, or the machine's.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Guard {
    limit: Option<u64>,
}

impl Guard {
    /// A guard with the user's limit in bytes (`None`: what the machine has available).
    pub fn new(limit: Option<u64>) -> Self {
        Guard { limit }
    }

    /// Checks that `need` fits beside what the process holds now.
    ///
    /// # Errors
    /// [`CalibrateError::Memory`] when `held + need` exceeds the limit.
    pub fn check(&self, need: &Need) -> Result<()> {
        let held = resident_bytes().unwrap_or(0);
        let (limit, limit_from) = match self.limit {
            Some(l) => (l, "the limit given (max_memory)".to_string()),
            None => match available_bytes() {
                Some(a) => (
                    held.saturating_add(a),
                    "what this process and the memory the machine has available add up to"
                        .to_string(),
                ),
                None => return Ok(()),
            },
        };
        if held.saturating_add(need.bytes) > limit {
            return Err(CalibrateError::Memory {
                stage: need.stage.clone(),
                estimate: need.bytes,
                held,
                limit,
                limit_from,
                advice: need.advice.clone(),
            });
        }
        Ok(())
    }
}

/// Bytes a stage of runs holds per run beside the runs' histories, at least: the run's
/// point (`8 d` bytes and a vector's 24), and its record in the runner (the result file's
/// path and unit, the run's state: 232 bytes taken for them).
pub(crate) fn run_record_bytes(dim: usize) -> u64 {
    8 * dim as u64 + 256
}

/// Checks, before any run, that a stage of each of `counts` runs (`(option, runs)`, the
/// option named as the message names it, e.g. `loop.jitter_runs`) can hold its points and
/// run records ([`run_record_bytes`] for `dim` parameters) within `guard`'s limit.
///
/// # Errors
/// [`CalibrateError::Memory`] naming the option and its value, the bytes, and what to
/// change.
pub(crate) fn check_run_counts(guard: Guard, counts: &[(&str, usize)], dim: usize) -> Result<()> {
    for (option, runs) in counts {
        let bytes = (*runs as u64).saturating_mul(run_record_bytes(dim));
        guard.check(&Need {
            stage: format!("{option} = {runs}"),
            bytes,
            advice: format!(
                "a stage of {runs} runs holds at least {} for its points and run records \
                 ({} bytes a run) before any run writes a value: give {option} a number of \
                 runs the machine can hold",
                human(bytes),
                run_record_bytes(dim)
            ),
        })?;
    }
    Ok(())
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn proc_fields_parse_and_the_guard_refuses_what_does_not_fit() {
        let text = "Name:\tx\nVmHWM:\t  2048 kB\nVmRSS:\t    1024 kB\n";
        assert_eq!(kilobytes(text, "VmRSS"), Some(1024 * 1024));
        assert_eq!(kilobytes(text, "VmHWM"), Some(2048 * 1024));
        assert_eq!(kilobytes(text, "VmSwap"), None);
        assert_eq!(human(512_000), "512 kB");
        assert_eq!(human(3_400_000), "3.4 MB");
        assert_eq!(human(12_900_000_000), "12.9 GB");
        if cfg!(target_os = "linux") {
            let held = resident_bytes().unwrap();
            assert!(held > 0 && peak_resident_bytes().unwrap() >= held);
            assert!(available_bytes().unwrap() > 0);
        }
        let need = Need {
            stage: "r0-gn0-jac".into(),
            bytes: 5_000_000_000,
            advice: "use fewer channels".into(),
        };
        let e = Guard::new(Some(1_000_000_000)).check(&need).unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("r0-gn0-jac") && text.contains("5.0 GB"),
            "{text}"
        );
        assert!(
            text.contains("1.0 GB") && text.contains("use fewer channels"),
            "{text}"
        );
        assert_eq!(e.kind(), impactcal_core::ErrorKind::BadInput);
        let small = Need {
            bytes: 1000,
            ..need
        };
        Guard::new(Some(u64::MAX)).check(&small).unwrap();
    }
}
