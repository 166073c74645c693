//! Where runs happen: in this process, a local process pool or a Slurm cluster; external
//! solvers through deck templates; work directories and a journal that lose nothing.
//!
//! A [`Batch`] is a set of parameter points (one per row, coordinates named) run through a
//! [`Solver`]: its deck template (with `<<name>>` placeholders or LS-DYNA `*PARAMETER`
//! cards, see [`template`]), a command run without a shell, and an output read back as
//! [`Histories`](impactcal_core::Histories) (our CSV, LS-DYNA's ASCII `nodout`, or a CSV the
//! user names: [`outputs`]). [`run_batch`] runs it on an [`Executor`] and returns one
//! outcome per point, in order; a failed run names itself and its file and leaves the others
//! alone. Each run has its own directory `<out>/runs/<study>/<index>/`; the [`journal`]
//! records every run before it starts and every result after it is read, so a batch
//! interrupted at any moment (Ctrl-C, SIGKILL of the driver, a lost node) is resumed by
//! running it again, with the same results. [`SolverModel`] makes a solver an
//! [`impactcal_core::Model`] for code written against that trait.
//!
//! The runner knows only that a run is a directory with its inputs and an output: a solver
//! that runs in this process (the built-in shell solver, a [`Model`](impactcal_core::Model))
//! is handed to it as an [`InProcessSolver`] by the layer above. A [`Runner`] bundles a
//! solver, its [`Executor`], retries and cancel token for code that submits batches.
//!
//! ```
//! use impactcal_runner::{Batch, Cancel, Executor, OutputSpec, Solver, SolverCommand, Template, run_batch};
//!
//! // A "solver" that copies its input to its output: the deck is a CSV history whose
//! // amplitude is the parameter `a`.
//! let template = Template::parse("time,y\n0,0\n1,<<a>>\n2,0\n", "deck.csv")?;
//! let solver = Solver {
//!     inputs: vec![(template, "deck.csv".into())],
//!     command: SolverCommand::Argv(vec!["cp".into(), "deck.csv".into(), "out.csv".into()]),
//!     output: OutputSpec::csv("out.csv"),
//! };
//! let out = tempfile::tempdir()?;
//! let points = vec![vec![1.5], vec![-2.0]];
//! let batch = Batch::new(out.path(), "demo", solver, vec!["a".into()], &points)?;
//! let report = run_batch(&batch, &Executor::Local, &Cancel::new())?;
//! let second = report.histories(1)?;
//! assert_eq!(second.channel(0), [0.0, -2.0, 0.0]);
//! // Run again: every result comes from the journal.
//! let again = run_batch(&batch, &Executor::Local, &Cancel::new())?;
//! assert!(again.reused.iter().all(|&r| r));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod batch;
pub mod binout;
pub mod config;
pub mod error;
pub mod executor;
pub mod journal;
pub mod lsda;
pub mod model;
pub mod outputs;
pub mod runner;
pub mod solver;
pub mod template;
pub mod workdir;

pub use batch::{Batch, BatchReport, Cancel, Hooks, OnFinished, RunResult};
pub use binout::Binout;
pub use config::{BatchConfig, ExecutorTable};
pub use error::{Result, RunnerError};
pub use executor::{Executor, ProcessOptions, SlurmOptions, run_batch, run_batch_with};
pub use model::SolverModel;
pub use outputs::{OutputFormat, OutputSpec, read_nodout};
pub use runner::Runner;
pub use solver::{InProcessRun, InProcessSolver, ModelSolver, Solver, SolverCommand, fingerprint};
pub use template::Template;
