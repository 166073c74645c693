//! The solver of a batch: its templated inputs, how it is run, and where its output is.

use std::path::Path;

use impactcal_core::{Histories, Model};

use crate::error::{Result, RunnerError};
use crate::outputs::{OutputFormat, OutputSpec};
use crate::template::Template;

/// How the solver is run.
#[derive(Debug, Clone, PartialEq)]
pub enum SolverCommand {
    /// A solver in this process: the [`InProcessSolver`] handed to
    /// [`run_batch_with`](crate::run_batch_with) in [`Hooks::in_process`](crate::Hooks)
    /// (the built-in shell solver on the run's deck, a [`Model`] at the run's point through
    /// [`ModelSolver`], ...). Its histories are written to the output file as our CSV (a
    /// failure's message to `stderr.txt`, exit status 1), as if it were a process. Only the
    /// in-process executor runs it. `description` names it in the fingerprint.
    InProcess {
        /// What runs (enters the solver's fingerprint).
        description: String,
    },
    /// An external program: `argv[0]` (a path, or a name looked up on `PATH`) with the
    /// arguments `argv[1..]`, started without a shell in the run's directory. Nothing is
    /// substituted into it: the inputs and outputs have fixed names inside the directory.
    Argv(Vec<String>),
}

/// One run as an [`InProcessSolver`] sees it: its directory, with the rendered inputs and
/// `params.json` written, and its point.
#[derive(Debug, Clone, Copy)]
pub struct InProcessRun<'a> {
    /// The run's index in its batch.
    pub index: usize,
    /// The run's work directory.
    pub dir: &'a Path,
    /// The names of the rendered inputs in `dir`, the deck first (empty for a solver
    /// without templates).
    pub inputs: &'a [String],
    /// The point's coordinate names.
    pub names: &'a [String],
    /// The point's values, in the order of `names`.
    pub values: &'a [f64],
}

/// A solver that runs in this process: what [`SolverCommand::InProcess`] runs. The runner
/// knows only that a run is a directory with its inputs and an output; what computes the
/// output is handed to it from above (the built-in shell solver by the experiment layer, a
/// [`Model`] through [`ModelSolver`]).
pub trait InProcessSolver: Sync {
    /// Runs `run` and returns its histories, or the failure's message (written to the run's
    /// `stderr.txt`, as a process's would be). The histories' unit is kept; histories
    /// without one take the output specification's (as a program writing our CSV, which
    /// carries no unit).
    ///
    /// # Errors
    /// A message saying why the run failed; it fails the run, not the batch.
    fn solve(&self, run: &InProcessRun<'_>) -> std::result::Result<Histories, String>;
}

/// A [`Model`] as an in-process solver: each run is `model.simulate` at the run's values
/// (checked against the model's space first), its histories keeping the model's unit.
#[derive(Clone, Copy)]
pub struct ModelSolver<'a>(pub &'a dyn Model);

impl std::fmt::Debug for ModelSolver<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple("ModelSolver").field(&self.0.space()).finish()
    }
}

impl InProcessSolver for ModelSolver<'_> {
    fn solve(&self, run: &InProcessRun<'_>) -> std::result::Result<Histories, String> {
        let model = self.0;
        model
            .space()
            .to_unit(run.values)
            .and_then(|_| model.simulate(run.values))
            .map_err(|e| e.to_string())
    }
}

/// A solver: templated inputs (the deck first), the command, and the output to read back.
///
/// A solver without inputs takes its parameters from the run's `params.json` (the names
/// and values of the point, see [`RunRecord`](crate::workdir::RunRecord)), as
/// `impactcal study-point` does for the built-in models.
#[derive(Debug, Clone)]
pub struct Solver {
    /// Each template with the file name it is written to in a run's directory.
    pub inputs: Vec<(Template, String)>,
    /// How the solver is run.
    pub command: SolverCommand,
    /// Its output.
    pub output: OutputSpec,
}

impl Solver {
    /// Checks the solver: input names that are plain file names, a non-empty command, an
    /// output spec inside the directory (and our CSV for an in-process solver).
    ///
    /// # Errors
    /// [`RunnerError::Config`] naming what is wrong.
    pub fn check(&self, file: &str) -> Result<()> {
        let config = |message: String| RunnerError::Config {
            file: file.to_string(),
            message,
        };
        for (_, name) in &self.inputs {
            let p = Path::new(name);
            if name.is_empty() || p.components().count() != 1 || p.file_name().is_none() {
                return Err(config(format!(
                    "input file name `{name}` must be a plain file name (no directories)"
                )));
            }
        }
        match &self.command {
            SolverCommand::Argv(argv) if argv.is_empty() || argv[0].is_empty() => {
                return Err(config("the solver command is empty".into()));
            }
            SolverCommand::InProcess { .. } if self.output.format != OutputFormat::Csv => {
                return Err(config(
                    "an in-process solver writes our CSV: the output format must be `csv`".into(),
                ));
            }
            _ => {}
        }
        self.output.check(file)
    }

    /// A 64-bit fingerprint (hex) of everything that decides a run's result: the rendered
    /// form of the templates (their text), the input names, the command and the output
    /// spec. A journal written for another fingerprint is not resumed.
    pub fn fingerprint(&self) -> String {
        let mut h = Fnv::default();
        for (t, name) in &self.inputs {
            h.add(name.as_bytes());
            h.add(t.text().as_bytes());
        }
        h.add(format!("{:?}", self.command).as_bytes());
        h.add(format!("{:?}", self.output).as_bytes());
        format!("{:016x}", h.0)
    }

    /// Runs `solver` in this process on `run` and writes its histories to the output file
    /// in the run's directory (our CSV); on failure the message goes to `stderr.txt` and
    /// the exit status is 1, as if the solver had been a process. Returns the exit status
    /// and the unit of the histories when they have one (our CSV does not carry it).
    pub(crate) fn run_in_process(
        &self,
        solver: &dyn InProcessSolver,
        run: &InProcessRun<'_>,
    ) -> Result<(i32, Option<String>)> {
        let (index, dir) = (run.index, run.dir);
        let io = crate::error::run_io(index, dir.join(crate::workdir::STDERR));
        match solver.solve(run) {
            Ok(h) => {
                let mut text = Vec::new();
                h.write_csv_to(&mut text, &self.output.file)?;
                let out = dir.join(&self.output.file);
                crate::workdir::write_atomic(&out, &text)
                    .map_err(crate::error::run_io(index, out))?;
                std::fs::write(dir.join(crate::workdir::STDERR), "").map_err(io)?;
                let unit = Some(h.unit().to_string()).filter(|u| !u.is_empty());
                Ok((0, unit))
            }
            Err(message) => {
                std::fs::write(dir.join(crate::workdir::STDERR), message + "\n").map_err(io)?;
                Ok((1, None))
            }
        }
    }
}

/// A 64-bit FNV-1a fingerprint of `bytes`, as 16 hex digits: what a journal compares to
/// tell its own batch (or study) from another. Not a cryptographic hash.
pub fn fingerprint(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

/// FNV-1a, 64 bits: a fingerprint, not a cryptographic hash.
struct Fnv(u64);

impl Default for Fnv {
    fn default() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv {
    fn add(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
        // A separator so that ("ab", "c") and ("a", "bc") differ.
        self.0 ^= 0xff;
        self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
    }
}
