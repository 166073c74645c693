//! The Slurm executor against stand-in `sbatch`/`squeue`/`scontrol` scripts that run each
//! array task at once (the real-cluster test is `tests/slurm/run.sh`): a lost task is
//! reported and resubmitted, a refused submission fails its runs with the scheduler's
//! message, and the batch scripts run every task in its own directory.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::os::unix::fs::PermissionsExt;
use std::path::Path;

use impactcal_runner::{
    Batch, Cancel, Executor, OutputSpec, RunnerError, SlurmOptions, Solver, SolverCommand,
    Template, run_batch,
};

fn write_exe(path: &Path, text: &str) {
    std::fs::write(path, text).unwrap();
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).unwrap();
}

/// Stand-ins: sbatch runs every task now (except task 1 of the first array, which is
/// "lost": it never runs) and answers job id 100 + submissions so far.
fn fake_slurm(bin: &Path, refuse: bool) {
    let sbatch = if refuse {
        "#!/bin/bash\necho 'sbatch: error: invalid partition specified: nope' >&2\nexit 1\n"
            .to_string()
    } else {
        format!(
            r#"#!/bin/bash
bin={bin}
n=$(cat "$bin/count" 2>/dev/null || echo 0); n=$((n+1)); echo $n > "$bin/count"
echo "$@" >> "$bin/sbatch.log"
for a in "$@"; do case "$a" in --array=*) r=${{a#--array=0-}}; last=${{r%%%*}};; esac; script="$a"; done
for i in $(seq 0 $last); do
  if [ $n = 1 ] && [ $i = 1 ]; then continue; fi
  SLURM_ARRAY_JOB_ID=$((100+n)) SLURM_ARRAY_TASK_ID=$i bash "$script"
done
echo $((100+n))
"#,
            bin = bin.display()
        )
    };
    write_exe(&bin.join("sbatch"), &sbatch);
    write_exe(&bin.join("squeue"), "#!/bin/bash\nexit 0\n");
    write_exe(
        &bin.join("sacct"),
        "#!/bin/bash\necho 'sacct: error: Slurm accounting storage is disabled' >&2\nexit 1\n",
    );
    write_exe(
        &bin.join("scontrol"),
        "#!/bin/bash\necho \"JobId=$4 JobState=NODE_FAIL ExitCode=0:9\"\n",
    );
}

fn batch(out: &Path) -> Batch {
    let template = Template::parse("time,y\n0,0\n1,<<a>>\n2,0\n", "deck.csv").unwrap();
    let solver = Solver {
        inputs: vec![(template, "deck.csv".into())],
        command: SolverCommand::Argv(vec!["cp".into(), "deck.csv".into(), "out.csv".into()]),
        output: OutputSpec::csv("out.csv"),
    };
    let points: Vec<Vec<f64>> = (0..4).map(|i| vec![i as f64 + 0.5]).collect();
    Batch::new(out, "s", solver, vec!["a".into()], &points).unwrap()
}

#[test]
fn lost_tasks_are_resubmitted() {
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("bin");
    std::fs::create_dir(&bin).unwrap();
    fake_slurm(&bin, false);
    let options = SlurmOptions {
        bin: Some(bin.clone()),
        poll: 0.05,
        max_running: Some(2),
        partition: Some("debug".into()),
        ..SlurmOptions::default()
    };
    let b = batch(&dir.path().join("out"));
    let report = run_batch(&b, &Executor::Slurm(options), &Cancel::new()).unwrap();
    for i in 0..report.runs.len() {
        let h = report.histories(i).unwrap();
        assert_eq!(h.channel(0), [0.0, i as f64 + 0.5, 0.0]);
    }
    assert_eq!(report.attempts, vec![1, 2, 1, 1]);
    let log = std::fs::read_to_string(bin.join("sbatch.log")).unwrap();
    let lines: Vec<&str> = log.lines().collect();
    assert_eq!(lines.len(), 2, "{log}");
    assert!(
        lines[0].starts_with("--parsable --array=0-3%2 --job-name=impactcal-s-"),
        "{log}"
    );
    assert!(lines[0].contains(" --partition=debug "), "{log}");
    assert!(lines[1].contains("--array=0-0%2"), "{log}");
    // The lost task is in the journal with what the scheduler knew.
    let journal = std::fs::read_to_string(b.journal_path()).unwrap();
    assert!(
        journal.contains(
            "Slurm task 101_1 ended without an exit status (state NODE_FAIL, exit code 0:9)"
        ),
        "{journal}"
    );
    // Each task recorded its job and task in its own directory.
    let task = std::fs::read_to_string(b.root().join("2/slurm_task")).unwrap();
    assert_eq!(task.trim(), "101_2");
}

#[test]
fn refused_submission_fails_its_runs_with_the_message() {
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("bin");
    std::fs::create_dir(&bin).unwrap();
    fake_slurm(&bin, true);
    let options = SlurmOptions {
        bin: Some(bin),
        poll: 0.05,
        ..SlurmOptions::default()
    };
    let b = batch(&dir.path().join("out"));
    let report = run_batch(&b, &Executor::Slurm(options), &Cancel::new()).unwrap();
    for (i, r) in report.runs.iter().enumerate() {
        let e = r.as_ref().unwrap_err();
        assert!(matches!(e, RunnerError::Submit { run, .. } if *run == i));
        let m = e.to_string();
        assert!(
            m.starts_with(&format!("run {i}: sbatch refused the job")),
            "{m}"
        );
        assert!(
            m.ends_with("sbatch: error: invalid partition specified: nope"),
            "{m}"
        );
        assert_eq!(e.kind(), impactcal_core::ErrorKind::BadInput);
    }
}
