//! An in-process model through the runner: results streamed to the caller as they finish,
//! equal bit for bit to what a resumed batch reads back; a batch tied to an identity
//! resumes under another solver command and refuses another identity.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::sync::Mutex;

use impactcal_core::{CoreError, Histories, Model, Parameter, ParameterSpace};
use impactcal_runner::{
    Batch, Cancel, Executor, Hooks, InProcessRun, InProcessSolver, ModelSolver, OutputSpec, Solver,
    SolverCommand, Template, run_batch_with,
};

/// `y(t) = a sin(b t) / 3` on 50 samples (thirds and sines do not print short), failing
/// for `a < 0`.
struct Wave(ParameterSpace);

impl Model for Wave {
    fn space(&self) -> &ParameterSpace {
        &self.0
    }
    fn simulate(&self, p: &[f64]) -> impactcal_core::Result<Histories> {
        if p[0] < 0.0 {
            return Err(CoreError::Simulation("negative amplitude".into()));
        }
        let y: Vec<f64> = (0..50)
            .map(|k| p[0] * (p[1] * k as f64 * 1e-3).sin() / 3.0)
            .collect();
        Histories::from_channels(vec!["1.z".into()], vec![y], 1e-3 / 3.0, 0.0, "in/s")
    }
}

fn wave() -> Wave {
    Wave(
        ParameterSpace::new(vec![
            Parameter::new("amp.a", -1.0, 2.0, 1.0).unwrap(),
            Parameter::new("freq.b", 1.0, 900.0, 100.0).unwrap(),
        ])
        .unwrap(),
    )
}

fn in_process() -> Solver {
    Solver {
        inputs: vec![],
        command: SolverCommand::InProcess {
            description: "wave".into(),
        },
        output: OutputSpec::csv("out.csv"),
    }
}

type Outcomes = Vec<(usize, Result<Histories, String>)>;
type Seen = Mutex<Outcomes>;

fn run(batch: &Batch, model: &Wave) -> (usize, Outcomes) {
    let seen: Seen = Mutex::new(Vec::new());
    let opened = Mutex::new(usize::MAX);
    let finished = |i: usize, o: Result<Histories, &impactcal_runner::RunnerError>| {
        seen.lock().unwrap().push((i, o.map_err(|e| e.to_string())));
    };
    let on_open = |n: usize| *opened.lock().unwrap() = n;
    let solver = ModelSolver(model);
    let hooks = Hooks {
        in_process: Some(&solver),
        opened: Some(&on_open),
        finished: Some(&finished),
    };
    let report = run_batch_with(batch, &Executor::Local, &Cancel::new(), hooks).unwrap();
    let mut seen = seen.into_inner().unwrap();
    seen.sort_by_key(|s| s.0);
    // The report holds where each result is; reading it back gives the streamed bits.
    for (i, o) in &seen {
        match o {
            Ok(h) => assert_eq!(&report.histories(*i).unwrap(), h),
            Err(_) => assert!(report.runs[*i].is_err()),
        }
    }
    (opened.into_inner().unwrap(), seen)
}

#[test]
fn streamed_results_equal_the_resumed_ones_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let model = wave();
    let names = vec!["amp.a".to_string(), "freq.b".to_string()];
    let points: Vec<Vec<f64>> = (0..6)
        .map(|i| vec![i as f64 * 0.37 - 0.5, 100.0 + 97.0 * i as f64])
        .collect();
    let batch = Batch::new(dir.path(), "wave", in_process(), names.clone(), &points)
        .unwrap()
        .with_retries(0)
        .with_identity("study-1");
    let (opened, first) = run(&batch, &model);
    assert_eq!(opened, 0);
    assert_eq!(first.len(), 6);
    // Runs 0 and 1 have a < 0: their failure is streamed with its message.
    for (i, o) in &first[..2] {
        let e = o.as_ref().unwrap_err();
        assert!(
            e.contains(&format!("run {i}")) && e.contains("stderr.txt"),
            "{e}"
        );
    }
    for (i, o) in &first[2..] {
        let h = o.as_ref().unwrap();
        let direct = model.simulate(&points[*i]).unwrap();
        // Values survive our CSV exactly; the unit comes with them.
        assert_eq!(h.data(), direct.data());
        assert_eq!(h.unit(), "in/s");
        assert_eq!(h.labels(), direct.labels());
    }
    // Again: the four results are reused (and streamed first), the failures are retried.
    let (opened, second) = run(&batch, &model);
    assert_eq!(opened, 4);
    for ((i, a), (j, b)) in first.iter().zip(&second) {
        assert_eq!(i, j);
        if let (Ok(a), Ok(b)) = (a, b) {
            assert_eq!(a, b);
            assert_eq!(a.dt().to_bits(), b.dt().to_bits());
        }
    }
    // Tied to its identity, the batch resumes under another command (a process that
    // would fail every run: nothing is run again)...
    let other = Solver {
        inputs: vec![],
        command: SolverCommand::Argv(vec!["false".into()]),
        output: OutputSpec::csv("out.csv"),
    };
    let resumed = Batch::new(dir.path(), "wave", other.clone(), names.clone(), &points)
        .unwrap()
        .with_retries(0)
        .with_identity("study-1");
    let report = impactcal_runner::run_batch(&resumed, &Executor::Local, &Cancel::new()).unwrap();
    assert_eq!(report.reused, vec![false, false, true, true, true, true]);
    // ... and another identity is refused.
    let foreign = Batch::new(dir.path(), "wave", other, names, &points)
        .unwrap()
        .with_identity("study-2");
    let e = impactcal_runner::run_batch(&foreign, &Executor::Local, &Cancel::new()).unwrap_err();
    assert!(e.to_string().contains("different batch"), "{e}");
}

#[test]
fn an_in_process_solver_must_be_given_and_runs_on_the_local_executor_only() {
    let dir = tempfile::tempdir().unwrap();
    let points = vec![vec![1.0, 100.0]];
    let batch = Batch::new(
        dir.path(),
        "wave",
        in_process(),
        vec!["amp.a".into(), "freq.b".into()],
        &points,
    )
    .unwrap();
    let e = run_batch_with(&batch, &Executor::Local, &Cancel::new(), Hooks::default()).unwrap_err();
    assert!(
        e.to_string().contains("no in-process solver was given"),
        "{e}"
    );
    let model = wave();
    let solver = ModelSolver(&model);
    let hooks = Hooks {
        in_process: Some(&solver),
        ..Hooks::default()
    };
    let processes = Executor::Processes(impactcal_runner::ProcessOptions {
        jobs: 1,
        timeout: None,
    });
    let e = run_batch_with(&batch, &processes, &Cancel::new(), hooks).unwrap_err();
    assert!(e.to_string().contains("runs in process only"), "{e}");
}

/// An in-process solver that is not a model: it reads the deck the runner rendered into the
/// run's directory (a CSV history whose amplitude is the parameter `a`) and returns it, as
/// the built-in shell solver reads its deck.
struct ReadDeck;

impl InProcessSolver for ReadDeck {
    fn solve(&self, run: &InProcessRun<'_>) -> Result<Histories, String> {
        assert_eq!(run.names, ["a"]);
        let deck = run.dir.join(&run.inputs[0]);
        let h = Histories::read_csv(&deck).map_err(|e| e.to_string())?;
        if run.values[0] < 0.0 {
            return Err(format!("run {}: negative amplitude", run.index));
        }
        Ok(h)
    }
}

#[test]
fn an_in_process_solver_runs_on_the_rendered_deck_in_the_run_directory() {
    let dir = tempfile::tempdir().unwrap();
    let template = Template::parse("time,y\n0,0\n1,<<a>>\n2,0\n", "deck.csv").unwrap();
    let mut output = OutputSpec::csv("out.csv");
    output.unit = Some("mm".into());
    let solver = Solver {
        inputs: vec![(template, "deck.csv".into())],
        command: SolverCommand::InProcess {
            description: "read the deck".into(),
        },
        output,
    };
    let points = vec![vec![1.5], vec![-2.0], vec![0.25]];
    let batch = Batch::new(dir.path(), "deck", solver, vec!["a".into()], &points).unwrap();
    let hooks = Hooks {
        in_process: Some(&ReadDeck),
        ..Hooks::default()
    };
    let report = run_batch_with(&batch, &Executor::Local, &Cancel::new(), hooks).unwrap();
    for (i, a) in [(0, 1.5), (2, 0.25)] {
        let h = report.histories(i).unwrap();
        assert_eq!(h.channel(0), [0.0, a, 0.0]);
        // Histories without a unit take the output specification's.
        assert_eq!(h.unit(), "mm");
    }
    let e = report.runs[1].as_ref().unwrap_err().to_string();
    assert!(e.contains("exit"), "{e}");
    let stderr = std::fs::read_to_string(batch.root().join("1").join("stderr.txt")).unwrap();
    assert_eq!(stderr, "run 1: negative amplitude\n");
    // The runner's own executor type carries the solver to any caller.
    let runner = impactcal_runner::Runner {
        in_process: Some(std::sync::Arc::new(ReadDeck)),
        ..impactcal_runner::Runner::new(batch.solver().clone(), Executor::Local)
    };
    let again = runner.run(&batch, Hooks::default()).unwrap();
    assert_eq!(again.reused, [true, false, true]);
}

/// Three channels `<n>.z = n a sin(b t) / 3`.
struct Three(ParameterSpace);

impl Model for Three {
    fn space(&self) -> &ParameterSpace {
        &self.0
    }
    fn simulate(&self, p: &[f64]) -> impactcal_core::Result<Histories> {
        let ch = |n: f64| -> Vec<f64> {
            (0..50)
                .map(|k| n * p[0] * (p[1] * k as f64 * 1e-3).sin() / 3.0)
                .collect()
        };
        Histories::from_channels(
            vec!["1.z".into(), "2.z".into(), "3.z".into()],
            vec![ch(1.0), ch(2.0), ch(3.0)],
            1e-3 / 3.0,
            0.0,
            "in/s",
        )
    }
}

/// A batch storing two of three channels writes only those (in the order asked for) to
/// each `result.csv`, with the bits the model gave; a channel the model lacks fails every
/// run naming the label.
#[test]
fn stored_channels_are_the_only_ones_written() {
    let dir = tempfile::tempdir().unwrap();
    let model = Three(wave().0);
    let points = vec![vec![1.0, 100.0], vec![0.5, 300.0]];
    let stored = vec!["3.z".to_string(), "1.z".to_string()];
    let batch = Batch::for_space(dir.path(), "kept", in_process(), model.space(), &points)
        .unwrap()
        .with_stored_channels(Some(stored.clone()));
    assert_eq!(batch.stored_channels(), Some(stored.as_slice()));
    let solver = ModelSolver(&model);
    let hooks = Hooks {
        in_process: Some(&solver),
        opened: None,
        finished: None,
    };
    let report = run_batch_with(&batch, &Executor::Local, &Cancel::new(), hooks).unwrap();
    for (i, p) in points.iter().enumerate() {
        let h = report.histories(i).unwrap();
        assert_eq!(h.labels(), stored.as_slice());
        let full = model.simulate(p).unwrap();
        for l in &stored {
            assert_eq!(
                h.channel_by_label(l).unwrap(),
                full.channel_by_label(l).unwrap()
            );
        }
        let header =
            std::fs::read_to_string(dir.path().join(format!("runs/kept/{i}/result.csv"))).unwrap();
        assert!(header.starts_with("time,3.z,1.z\n"), "{}", &header[..40]);
    }

    let missing = Batch::for_space(dir.path(), "missing", in_process(), model.space(), &points)
        .unwrap()
        .with_retries(0)
        .with_stored_channels(Some(vec!["4.z".to_string()]));
    let hooks = Hooks {
        in_process: Some(&solver),
        opened: None,
        finished: None,
    };
    let report = run_batch_with(&missing, &Executor::Local, &Cancel::new(), hooks).unwrap();
    for r in &report.runs {
        let e = r.as_ref().unwrap_err().to_string();
        assert!(e.contains("4.z") && e.contains("channels to store"), "{e}");
    }
}
