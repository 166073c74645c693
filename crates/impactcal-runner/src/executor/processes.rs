//! The local process pool: at most `jobs` solver processes at a time, each with a time
//! limit.

use std::collections::VecDeque;
use std::fs::File;
use std::os::unix::process::ExitStatusExt;
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use crate::batch::{Driver, cancelled, start_ticks};
use crate::error::{Result, RunnerError, run_io};
use crate::journal::Entry;
use crate::workdir::{STDERR, STDOUT};

/// Runs `pending` on `jobs` worker threads, each starting one solver process at a time.
pub(crate) fn run(
    driver: &Driver<'_>,
    pending: &[usize],
    jobs: usize,
    timeout: Option<Duration>,
) -> Result<()> {
    let argv = super::argv(driver)?;
    let queue = Mutex::new(pending.iter().copied().collect::<VecDeque<usize>>());
    let next = || {
        queue
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .pop_front()
    };
    std::thread::scope(|scope| {
        let workers: Vec<_> = (0..jobs.min(pending.len()).max(1))
            .map(|_| {
                scope.spawn(|| -> Result<()> {
                    while let Some(index) = next() {
                        driver.drive(index, |d, index, attempt, dir| {
                            run_process(d, index, attempt, dir, argv, timeout).map(|s| (s, None))
                        })?;
                    }
                    Ok(())
                })
            })
            .collect();
        let mut first_error = None;
        for w in workers {
            let outcome = w.join().unwrap_or_else(|_| {
                Err(RunnerError::Config {
                    file: "runner".into(),
                    message: "a worker thread panicked".into(),
                })
            });
            if let Err(e) = outcome {
                first_error.get_or_insert(e);
            }
        }
        first_error.map_or(Ok(()), Err)
    })
}

/// Starts `argv` in `dir` without a shell (stdout and stderr to files, no stdin), records
/// its pid, and waits for it: killed after `timeout`, or when the batch is cancelled.
/// Returns its exit status (128 + the signal number when a signal ended it).
pub(crate) fn run_process(
    driver: &Driver<'_>,
    index: usize,
    attempt: u32,
    dir: &Path,
    argv: &[String],
    timeout: Option<Duration>,
) -> Result<i32> {
    let stdout = File::create(dir.join(STDOUT)).map_err(run_io(index, dir.join(STDOUT)))?;
    let stderr = File::create(dir.join(STDERR)).map_err(run_io(index, dir.join(STDERR)))?;
    let mut child = Command::new(&argv[0])
        .args(&argv[1..])
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(stdout)
        .stderr(stderr)
        .spawn()
        .map_err(|e| RunnerError::SolverStart {
            run: index,
            program: argv[0].clone(),
            message: if e.kind() == std::io::ErrorKind::NotFound {
                "not found (give a path, or a program on PATH)".into()
            } else {
                e.to_string()
            },
        })?;
    let pid = child.id();
    let recorded = driver.record(&Entry::Started {
        index,
        attempt,
        pid,
        start_ticks: start_ticks(pid),
    });
    if let Err(e) = recorded {
        let _ = child.kill();
        let _ = child.wait();
        return Err(e);
    }
    let started = Instant::now();
    let mut pause = Duration::from_millis(1);
    loop {
        match child.try_wait() {
            Ok(Some(status)) => {
                return Ok(status
                    .code()
                    .unwrap_or_else(|| 128 + status.signal().unwrap_or(0)));
            }
            Ok(None) => {}
            Err(e) => return Err(run_io(index, dir)(e)),
        }
        if driver.cancel.is_cancelled() {
            let _ = child.kill();
            let _ = child.wait();
            return Err(cancelled("running solver processes were killed"));
        }
        if let Some(limit) = timeout {
            if started.elapsed() > limit {
                let _ = child.kill();
                let _ = child.wait();
                return Err(RunnerError::Timeout {
                    run: index,
                    seconds: limit.as_secs_f64(),
                    dir: dir.to_path_buf(),
                });
            }
        }
        std::thread::sleep(pause);
        pause = (pause * 2).min(Duration::from_millis(20));
    }
}
