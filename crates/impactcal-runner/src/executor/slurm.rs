//! The Slurm executor: one job array per batch (and one per round of retries).
//!
//! Each array task runs a generated bash script that changes into the work directory of its
//! run (looked up from `SLURM_ARRAY_TASK_ID` in a list written into the script: `--chdir`
//! does not expand `%a`), runs the solver command with stdout and stderr to files, and
//! writes the exit status atomically into `exit_status` in that directory. That file is the
//! record the driver trusts: it outlives the scheduler's memory of the job (`MinJobAge`)
//! and needs no accounting database.
//!
//! The driver polls `squeue -h -r -j <ids>` (one line per task still queued or running).
//! A task that has left the queue has either written its exit status (then its output is
//! read) or was lost (killed, node failure, cancelled): it is reported with what `sacct`
//! (where accounting exists) or `scontrol show job` (until `MinJobAge`) still knows, and
//! resubmitted within the batch's retry limit. Every argument of the solver command is
//! single-quoted in the script; nothing else from the configuration reaches it.

use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use std::process::Command;
use std::time::Duration;

use impactcal_core::{CoreError, ParamGuard};
use serde::{Deserialize, Serialize};

use crate::batch::{Driver, InFlight, cancelled};
use crate::error::{Result, RunnerError, io};
use crate::journal::Entry;
use crate::workdir::{self, read_exit_status, write_atomic};

/// Options of the Slurm executor (the `[executor]` table with `kind = "slurm"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlurmOptions {
    /// `--partition`.
    #[serde(default)]
    pub partition: Option<String>,
    /// `--account`.
    #[serde(default)]
    pub account: Option<String>,
    /// `--time` per task (Slurm's forms: `MM`, `HH:MM:SS`, `D-HH`).
    #[serde(default)]
    pub time: Option<String>,
    /// `--mem` per task (`4G`).
    #[serde(default)]
    pub mem: Option<String>,
    /// `--cpus-per-task`.
    #[serde(default)]
    pub cpus_per_task: Option<u32>,
    /// At most this many tasks of an array run at once (`--array=...%max`).
    #[serde(default)]
    pub max_running: Option<usize>,
    /// Largest array submitted at once (the cluster's `MaxArraySize` minus one, at most);
    /// larger batches are split.
    #[serde(default = "default_chunk")]
    pub max_array: usize,
    /// Seconds between two `squeue` polls.
    #[serde(default = "default_poll")]
    pub poll: f64,
    /// Further `sbatch` arguments, passed as they are (for example `["--qos=short"]`).
    #[serde(default)]
    pub sbatch_args: Vec<String>,
    /// The directory holding `sbatch`, `squeue`, `scancel`, `sacct` and `scontrol` (found on
    /// `PATH` when absent).
    #[serde(default)]
    pub bin: Option<PathBuf>,
}

fn default_chunk() -> usize {
    1000
}

fn default_poll() -> f64 {
    5.0
}

impl Default for SlurmOptions {
    fn default() -> Self {
        SlurmOptions {
            partition: None,
            account: None,
            time: None,
            mem: None,
            cpus_per_task: None,
            max_running: None,
            max_array: default_chunk(),
            poll: default_poll(),
            sbatch_args: Vec::new(),
            bin: None,
        }
    }
}

impl ParamGuard for SlurmOptions {
    /// The options themselves: nothing downstream needs a separate checked form.
    type Checked = SlurmOptions;

    /// Checks the options: positive sizes and poll interval, no whitespace in the values
    /// passed to sbatch.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] naming the key (`executor.<key>`).
    fn check_ref(&self) -> impactcal_core::Result<()> {
        let bad = |name: &str, value: &dyn std::fmt::Display, message: &str| {
            Err(CoreError::invalid_option(
                format!("executor.{name}"),
                value,
                message,
            ))
        };
        for (name, v) in [
            ("partition", &self.partition),
            ("account", &self.account),
            ("time", &self.time),
            ("mem", &self.mem),
        ] {
            if let Some(v) = v {
                if v.is_empty() || v.chars().any(char::is_whitespace) {
                    return bad(name, &format!("`{v}`"), "must be one word");
                }
            }
        }
        if self.max_array == 0 {
            return bad("max_array", &self.max_array, "must be at least 1");
        }
        if self.max_running == Some(0) {
            return bad("max_running", &0, "must be at least 1");
        }
        if !(self.poll.is_finite() && self.poll > 0.0) {
            return bad("poll", &self.poll, "must be finite and positive (seconds)");
        }
        Ok(())
    }

    fn check(self) -> impactcal_core::Result<SlurmOptions> {
        self.check_ref()?;
        Ok(self)
    }
}

impl SlurmOptions {
    fn program(&self, name: &str) -> Command {
        match &self.bin {
            Some(dir) => Command::new(dir.join(name)),
            None => Command::new(name),
        }
    }

    /// Runs a scheduler command and returns its stdout, or its stderr as the error.
    fn call(&self, name: &str, args: &[String]) -> Result<String> {
        let out = self
            .program(name)
            .args(args)
            .output()
            .map_err(|e| RunnerError::Scheduler {
                command: name.into(),
                message: format!("cannot run: {e}"),
            })?;
        if out.status.success() {
            Ok(String::from_utf8_lossy(&out.stdout).into_owned())
        } else {
            let mut message = String::from_utf8_lossy(&out.stderr).trim().to_string();
            if message.is_empty() {
                message = format!("exited with {}", out.status);
            }
            Err(RunnerError::Scheduler {
                command: name.into(),
                message,
            })
        }
    }
}

/// A task being watched: its array job, task number and run.
#[derive(Debug, Clone)]
struct Task {
    job: String,
    task: usize,
    index: usize,
    attempt: u32,
    missing_polls: u32,
}

/// Single-quotes `s` for bash (`'` becomes `'\''`).
fn quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

/// The batch script of one array: task k runs in `dirs[k]`.
fn script(dirs: &[PathBuf], argv: &[String]) -> String {
    let mut s = String::from(
        "#!/bin/bash\n# Generated by impactcal: array task k runs the solver in dirs[k].\ndirs=(\n",
    );
    for d in dirs {
        s += &quote(&d.display().to_string());
        s.push('\n');
    }
    s += ")\ncd -- \"${dirs[$SLURM_ARRAY_TASK_ID]}\" || exit 97\n";
    s += "printf '%s_%s\\n' \"$SLURM_ARRAY_JOB_ID\" \"$SLURM_ARRAY_TASK_ID\" > slurm_task\n";
    let command: Vec<String> = argv.iter().map(|a| quote(a)).collect();
    s += &format!(
        "{} < /dev/null > {} 2> {}\n",
        command.join(" "),
        workdir::STDOUT,
        workdir::STDERR
    );
    s += &format!(
        "status=$?\nprintf '%d\\n' \"$status\" > .{0}.tmp && sync .{0}.tmp && mv -f .{0}.tmp {0}\nexit \"$status\"\n",
        workdir::EXIT_STATUS
    );
    s
}

/// Runs the batch on Slurm: attaches to `in_flight` tasks of an earlier driver, submits
/// `pending`, polls until every run has an outcome.
pub(crate) fn run(
    driver: &Driver<'_>,
    pending: Vec<usize>,
    in_flight: BTreeMap<usize, InFlight>,
    options: &SlurmOptions,
) -> Result<()> {
    options.check_ref()?;
    let argv = super::argv(driver)?;
    let mut watch: Vec<Task> = Vec::new();
    let mut todo: Vec<usize> = pending;
    // Re-attach: find the array job of each earlier submission (by id, or by job name when
    // the driver died between sbatch and recording the id).
    let mut jobs_of: BTreeMap<String, Option<String>> = BTreeMap::new();
    for f in in_flight.values() {
        if let Some((token, job, _)) = &f.slurm {
            jobs_of.entry(token.clone()).or_insert_with(|| job.clone());
        }
    }
    for (token, job) in jobs_of.iter_mut() {
        if job.is_none() {
            let out = options
                .call(
                    "squeue",
                    &[
                        "-h".into(),
                        "--name".into(),
                        token.clone(),
                        "-o".into(),
                        "%F".into(),
                    ],
                )
                .unwrap_or_default();
            *job = out
                .lines()
                .next()
                .map(|l| l.trim().to_string())
                .filter(|l| !l.is_empty());
            if let Some(id) = job {
                driver.record(&Entry::SlurmJob {
                    token: token.clone(),
                    job_id: id.clone(),
                })?;
            }
        }
    }
    for (&index, f) in &in_flight {
        let Some((token, _, task)) = &f.slurm else {
            continue;
        };
        match jobs_of.get(token).cloned().flatten() {
            Some(job) => watch.push(Task {
                job,
                task: *task,
                index,
                attempt: f.attempt,
                missing_polls: 0,
            }),
            None => {
                // Never reached the scheduler, or finished and forgotten: its directory
                // says which.
                if read_exit_status(&driver.dir(index)).is_some() {
                    let outcome = driver.collect(index, f.attempt, None);
                    if driver.settle(index, f.attempt, outcome)? {
                        todo.push(index);
                    }
                } else {
                    todo.push(index);
                }
            }
        }
    }
    let poll = Duration::from_secs_f64(options.poll);
    let mut squeue_failures = 0;
    loop {
        if driver.cancel.is_cancelled() {
            return cancel_all(options, &watch);
        }
        if !todo.is_empty() {
            todo.sort_unstable();
            for chunk in std::mem::take(&mut todo).chunks(options.max_array) {
                submit(driver, options, argv, chunk, &mut watch)?;
            }
        }
        if watch.is_empty() {
            return Ok(());
        }
        sleep_unless_cancelled(driver, poll);
        if driver.cancel.is_cancelled() {
            return cancel_all(options, &watch);
        }
        let active = match queued(options, &watch) {
            Ok(a) => {
                squeue_failures = 0;
                a
            }
            Err(e) => {
                squeue_failures += 1;
                if squeue_failures >= 10 {
                    return Err(e);
                }
                continue;
            }
        };
        let mut still = Vec::new();
        for mut t in std::mem::take(&mut watch) {
            if active.contains(&(t.job.clone(), t.task)) {
                still.push(t);
                continue;
            }
            let dir = driver.dir(t.index);
            let outcome = if read_exit_status(&dir).is_some() {
                driver.collect(t.index, t.attempt, None)
            } else if t.missing_polls == 0 {
                // Give the file system one poll to show the exit status.
                t.missing_polls += 1;
                still.push(t);
                continue;
            } else {
                Err(RunnerError::Lost {
                    run: t.index,
                    job: format!("{}_{}", t.job, t.task),
                    state: task_state(options, &t.job, t.task),
                    dir,
                })
            };
            if driver.settle(t.index, t.attempt, outcome)? {
                todo.push(t.index);
            }
        }
        watch = still;
    }
}

fn sleep_unless_cancelled(driver: &Driver<'_>, total: Duration) {
    let step = Duration::from_millis(50);
    let mut left = total;
    while !left.is_zero() && !driver.cancel.is_cancelled() {
        let d = left.min(step);
        std::thread::sleep(d);
        left -= d;
    }
}

/// Submits one array for `indices`: prepares their directories, records the submission,
/// calls sbatch, records the job id. A refusal fails these runs (with the scheduler's
/// message) and not the others.
fn submit(
    driver: &Driver<'_>,
    options: &SlurmOptions,
    argv: &[String],
    indices: &[usize],
    watch: &mut Vec<Task>,
) -> Result<()> {
    let mut ready = Vec::new();
    for &index in indices {
        let (attempt, dir) = driver.prepare(index)?;
        match dir {
            Ok(dir) => ready.push((index, attempt, dir)),
            Err(e) => {
                driver.settle(index, attempt, Err(e))?;
            }
        }
    }
    if ready.is_empty() {
        return Ok(());
    }
    let slurm_dir = driver.batch.root().join("slurm");
    std::fs::create_dir_all(&slurm_dir).map_err(io(&slurm_dir))?;
    let stamp = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    let token = format!("impactcal-{}-{stamp:x}", driver.batch.study());
    let dirs: Vec<PathBuf> = ready
        .iter()
        .map(|(_, _, d)| std::path::absolute(d).unwrap_or_else(|_| d.clone()))
        .collect();
    let script_path = slurm_dir.join(format!("{token}.sh"));
    write_atomic(&script_path, script(&dirs, argv).as_bytes()).map_err(io(&script_path))?;
    for (index, attempt, _) in &ready {
        driver.record(&Entry::Submit {
            index: *index,
            attempt: *attempt,
            executor: "slurm".into(),
        })?;
    }
    driver.record(&Entry::SlurmSubmit {
        token: token.clone(),
        indices: ready.iter().map(|r| r.0).collect(),
    })?;
    let mut array = format!("--array=0-{}", ready.len() - 1);
    if let Some(m) = options.max_running {
        array += &format!("%{m}");
    }
    let log = std::path::absolute(&slurm_dir).unwrap_or(slurm_dir.clone());
    let mut args = vec![
        "--parsable".to_string(),
        array,
        format!("--job-name={token}"),
        format!("--output={}/%A_%a.out", log.display()),
    ];
    for (flag, v) in [
        ("--partition", &options.partition),
        ("--account", &options.account),
        ("--time", &options.time),
        ("--mem", &options.mem),
    ] {
        if let Some(v) = v {
            args.push(format!("{flag}={v}"));
        }
    }
    if let Some(c) = options.cpus_per_task {
        args.push(format!("--cpus-per-task={c}"));
    }
    args.extend(options.sbatch_args.iter().cloned());
    args.push(
        std::path::absolute(&script_path)
            .unwrap_or(script_path)
            .display()
            .to_string(),
    );
    match options.call("sbatch", &args) {
        Ok(out) => {
            let job = out
                .trim()
                .split(';')
                .next()
                .unwrap_or("")
                .trim()
                .to_string();
            if job.is_empty() || !job.chars().all(|c| c.is_ascii_digit()) {
                return Err(RunnerError::Scheduler {
                    command: "sbatch".into(),
                    message: format!("unexpected answer `{}` (expected a job id)", out.trim()),
                });
            }
            driver.record(&Entry::SlurmJob {
                token,
                job_id: job.clone(),
            })?;
            for (task, (index, attempt, _)) in ready.into_iter().enumerate() {
                watch.push(Task {
                    job: job.clone(),
                    task,
                    index,
                    attempt,
                    missing_polls: 0,
                });
            }
        }
        Err(RunnerError::Scheduler { message, .. }) => {
            for (index, attempt, _) in ready {
                let refused = RunnerError::Submit {
                    run: index,
                    script: log.join(format!("{token}.sh")),
                    message: message.clone(),
                };
                driver.settle(index, attempt, Err(refused))?;
            }
        }
        Err(e) => return Err(e),
    }
    Ok(())
}

/// The `(job, task)` pairs still queued or running.
fn queued(options: &SlurmOptions, watch: &[Task]) -> Result<BTreeSet<(String, usize)>> {
    let jobs: BTreeSet<&str> = watch.iter().map(|t| t.job.as_str()).collect();
    let ids = jobs.into_iter().collect::<Vec<_>>().join(",");
    let out = match options.call(
        "squeue",
        &[
            "-h".into(),
            "-r".into(),
            "-j".into(),
            ids,
            "-o".into(),
            "%i".into(),
        ],
    ) {
        Ok(out) => out,
        // Every job already purged from the controller's memory.
        Err(RunnerError::Scheduler { message, .. }) if message.contains("Invalid job id") => {
            String::new()
        }
        Err(e) => return Err(e),
    };
    Ok(out
        .lines()
        .filter_map(|l| {
            let (job, task) = l.trim().split_once('_')?;
            Some((job.to_string(), task.parse().ok()?))
        })
        .collect())
}

/// What the scheduler still knows of a task that left the queue without an exit status:
/// `sacct` where accounting exists, else `scontrol show job` (until `MinJobAge`).
fn task_state(options: &SlurmOptions, job: &str, task: usize) -> String {
    let id = format!("{job}_{task}");
    if let Ok(out) = options.call(
        "sacct",
        &[
            "-n".into(),
            "-P".into(),
            "-X".into(),
            "-j".into(),
            id.clone(),
            "-o".into(),
            "State,ExitCode".into(),
        ],
    ) {
        if let Some(line) = out.lines().find(|l| !l.trim().is_empty()) {
            let mut parts = line.split('|');
            return format!(
                "state {}, exit code {}",
                parts.next().unwrap_or("?"),
                parts.next().unwrap_or("?")
            );
        }
    }
    if let Ok(out) = options.call("scontrol", &["-o".into(), "show".into(), "job".into(), id]) {
        let field = |key: &str| {
            out.split_whitespace()
                .find_map(|w| w.strip_prefix(key))
                .unwrap_or("?")
                .to_string()
        };
        return format!(
            "state {}, exit code {}",
            field("JobState="),
            field("ExitCode=")
        );
    }
    "unknown to the scheduler".into()
}

/// Cancels every array still watched and returns [`RunnerError::Cancelled`].
fn cancel_all(options: &SlurmOptions, watch: &[Task]) -> Result<()> {
    let jobs: BTreeSet<String> = watch.iter().map(|t| t.job.clone()).collect();
    if jobs.is_empty() {
        return Err(cancelled("nothing was queued"));
    }
    let list: Vec<String> = jobs.into_iter().collect();
    options.call("scancel", &list)?;
    Err(cancelled(&format!("scancel {}", list.join(" "))))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn script_quotes_every_argument() {
        let s = script(
            &[PathBuf::from("/r/0"), PathBuf::from("/r/it's 1")],
            &["solver".into(), "a;rm -rf ~".into(), "$(x)".into()],
        );
        assert!(s.contains("'/r/it'\\''s 1'\n"), "{s}");
        assert!(
            s.contains("'solver' 'a;rm -rf ~' '$(x)' < /dev/null"),
            "{s}"
        );
        assert!(s.contains("cd -- \"${dirs[$SLURM_ARRAY_TASK_ID]}\""));
    }
}
