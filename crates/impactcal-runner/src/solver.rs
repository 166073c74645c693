//! The solver of a batch: its templated inputs, how it is run, and where its output is.

use std::path::Path;

use impactcal_core::Histories;
use impactcal_shell::Quantity;

use crate::error::{Result, RunnerError};
use crate::outputs::{OutputFormat, OutputSpec};
use crate::template::Template;

/// How the solver is run.
#[derive(Debug, Clone, PartialEq)]
pub enum SolverCommand {
    /// The built-in shell solver, in this process, on the rendered deck; it writes the
    /// nodal `quantity` of the deck's history nodes as our CSV to the output file. Only the
    /// in-process executor runs it; the other executors run `impactcal simulate` through
    /// [`SolverCommand::Argv`].
    BuiltIn {
        /// The nodal quantity written.
        quantity: Quantity,
    },
    /// A [`Model`](impactcal_core::Model) in this process: the one handed to
    /// [`run_batch_with`](crate::run_batch_with) in [`Hooks::model`](crate::Hooks::model),
    /// called with the run's point; its histories are written to the output file as our CSV
    /// (a failure's message to `stderr.txt`, exit status 1), as if it were a process. Only
    /// the in-process executor runs it. `description` names the model in the fingerprint.
    InProcess {
        /// What the model is (enters the solver's fingerprint).
        description: String,
    },
    /// An external program: `argv[0]` (a path, or a name looked up on `PATH`) with the
    /// arguments `argv[1..]`, started without a shell in the run's directory. Nothing is
    /// substituted into it: the inputs and outputs have fixed names inside the directory.
    Argv(Vec<String>),
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
    /// Checks the solver: input names that are plain file names (and a deck for the
    /// built-in solver), a non-empty command, an output spec inside the directory (and our
    /// CSV for the built-in solver and an in-process model).
    ///
    /// # Errors
    /// [`RunnerError::Config`] naming what is wrong.
    pub fn check(&self, file: &str) -> Result<()> {
        let config = |message: String| RunnerError::Config {
            file: file.to_string(),
            message,
        };
        if self.inputs.is_empty() && matches!(self.command, SolverCommand::BuiltIn { .. }) {
            return Err(config("the built-in solver needs a deck template".into()));
        }
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
            SolverCommand::BuiltIn { .. } | SolverCommand::InProcess { .. }
                if self.output.format != OutputFormat::Csv =>
            {
                return Err(config(
                    "the built-in solver writes our CSV: the output format must be `csv`".into(),
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

    /// Runs `model` in this process at `values` and writes its histories to the output file
    /// in `dir` (our CSV); on failure the message goes to `stderr.txt` and the exit status
    /// is 1, as if the model had been a process. Returns the exit status and the unit of
    /// the histories (our CSV does not carry it).
    pub(crate) fn run_model(
        &self,
        run: usize,
        dir: &Path,
        model: &dyn impactcal_core::Model,
        values: &[f64],
    ) -> Result<(i32, Option<String>)> {
        let outcome = model
            .space()
            .to_unit(values)
            .and_then(|_| model.simulate(values))
            .map_err(|e| e.to_string());
        let unit = outcome.as_ref().ok().map(|h| h.unit().to_string());
        Ok((self.write_outcome(run, dir, outcome)?, unit))
    }

    /// Writes an in-process outcome as a process would leave it: the histories to the
    /// output file, the message of a failure to `stderr.txt`; returns the exit status.
    fn write_outcome(
        &self,
        run: usize,
        dir: &Path,
        outcome: std::result::Result<Histories, String>,
    ) -> Result<i32> {
        let io = crate::error::run_io(run, dir.join(crate::workdir::STDERR));
        match outcome {
            Ok(h) => {
                let mut text = Vec::new();
                h.write_csv_to(&mut text, &self.output.file)?;
                let out = dir.join(&self.output.file);
                crate::workdir::write_atomic(&out, &text)
                    .map_err(crate::error::run_io(run, out))?;
                std::fs::write(dir.join(crate::workdir::STDERR), "").map_err(io)?;
                Ok(0)
            }
            Err(message) => {
                std::fs::write(dir.join(crate::workdir::STDERR), message + "\n").map_err(io)?;
                Ok(1)
            }
        }
    }

    /// Runs the built-in solver in this process on the deck in `dir` and writes the output.
    /// On failure the message is written to the run's `stderr.txt` and the exit status is
    /// 1, as if the solver had been a process.
    pub(crate) fn run_builtin(&self, run: usize, dir: &Path, quantity: Quantity) -> Result<i32> {
        let deck = dir.join(&self.inputs[0].1);
        let outcome = (|| -> std::result::Result<Histories, String> {
            let deck = impactcal_shell::keyword::read_deck(&deck).map_err(|e| e.to_string())?;
            let mut sim =
                impactcal_shell::Simulation::new(&deck.model).map_err(|e| e.to_string())?;
            let result = sim.run().map_err(|e| e.to_string())?;
            result
                .histories(quantity)
                .cloned()
                .ok_or_else(|| "the deck has no history nodes (*DATABASE_HISTORY_NODE)".to_string())
        })();
        self.write_outcome(run, dir, outcome)
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
