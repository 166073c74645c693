//! The batch configuration file (TOML): the solver, the executor and the batch's name.
//!
//! ```toml
//! [batch]
//! study = "strip"          # runs go to <out>/runs/strip/<index>/
//!
//! [solver]
//! template = "strip.k"     # the deck template, relative to this file
//! deck = "deck.k"          # its name in each run's directory (default: the template's)
//! inputs = []              # further templated text inputs, written under their own names
//! # The solver command, run without a shell in the run's directory. Absent: the built-in
//! # solver (in process for kind = "local", handed to the runner by the caller as an
//! # `InProcessSolver`; else `impactcal simulate --deck <deck> --out <output>`).
//! command = ["impactcal", "simulate", "--deck", "deck.k", "--out", "out.csv"]
//! quantity = "velocity"    # built-in solver: the nodal quantity written
//!
//! [solver.output]
//! format = "csv"           # "csv" | "nodout" | "binout" | "user-csv"
//! file = "out.csv"
//! # binout: branch = "nodout" (or "glstat", "matsum", "rwforc/forces", ...) and
//! # channels = ["x_velocity", "167.z_velocity"] (variables or `<id>.<variable>` labels)
//!
//! [executor]
//! kind = "processes"       # "local" | "processes" | "slurm"
//! jobs = 4
//! timeout = 600
//! retries = 2              # further attempts of a run that fails (default 2)
//! ```
//!
//! The `[executor]` table ([`ExecutorTable`]) is the one an experiment file has too: the
//! [`Executor`] by `kind` with its options, and the runner's retries. `[batch] retries` of
//! earlier files is an error naming `[executor] retries`.

use std::path::{Path, PathBuf};

use impactcal_core::NodalQuantity;
use serde::{Deserialize, Serialize};
use toml::de::DeTable;

use crate::error::{Result, RunnerError, io};
use crate::executor::Executor;
use crate::outputs::OutputSpec;
use crate::solver::{Solver, SolverCommand};
use crate::template::Template;

/// The `[batch]` table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BatchSection {
    /// The study name (the runs' directory under `<out>/runs/`).
    #[serde(default = "default_study")]
    pub study: String,
}

fn default_study() -> String {
    "batch".into()
}

fn default_retries() -> u32 {
    2
}

impl Default for BatchSection {
    fn default() -> Self {
        BatchSection {
            study: default_study(),
        }
    }
}

/// The `[solver]` table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverSection {
    /// The deck template, relative to the configuration file.
    pub template: PathBuf,
    /// The deck's name in a run's directory (default: the template's file name).
    #[serde(default)]
    pub deck: Option<String>,
    /// Further templated inputs, relative to the configuration file.
    #[serde(default)]
    pub inputs: Vec<PathBuf>,
    /// The command (argv); absent for the built-in solver.
    #[serde(default)]
    pub command: Option<Vec<String>>,
    /// The built-in solver's nodal quantity (written in the fingerprint of its runs).
    #[serde(default)]
    pub quantity: NodalQuantity,
    /// The output.
    #[serde(default = "default_output")]
    pub output: OutputSpec,
}

fn default_output() -> OutputSpec {
    OutputSpec::csv("out.csv")
}

/// The `[executor]` table of a batch file and of an experiment file: where the runs happen
/// (`kind` and its options) and the runner's retries.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExecutorTable {
    /// Further attempts of a run that fails in a way another attempt may cure (default 2).
    #[serde(default = "default_retries")]
    pub retries: u32,
    /// Where the runs happen.
    #[serde(flatten)]
    pub executor: Executor,
}

impl Default for ExecutorTable {
    fn default() -> Self {
        ExecutorTable {
            retries: default_retries(),
            executor: Executor::Local,
        }
    }
}

/// A batch configuration file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BatchConfig {
    /// `[batch]`.
    #[serde(default)]
    pub batch: BatchSection,
    /// `[solver]`.
    pub solver: SolverSection,
    /// `[executor]`.
    pub executor: ExecutorTable,
    /// The file it was read from (paths are relative to its directory).
    #[serde(skip)]
    pub source: PathBuf,
}

impl BatchConfig {
    /// Reads a configuration file.
    ///
    /// # Errors
    /// [`RunnerError::Io`] when it cannot be read; [`RunnerError::Config`] naming the file,
    /// line and column of a TOML or schema fault (an unknown key, a wrong type), and the
    /// line of `[batch] retries` (now `[executor] retries`).
    pub fn read(path: &Path) -> Result<BatchConfig> {
        let text = std::fs::read_to_string(path).map_err(io(path))?;
        let mut c = BatchConfig::parse(&text, &path.display().to_string())?;
        c.source = path.to_path_buf();
        Ok(c)
    }

    /// Parses configuration text; `name` names it in messages.
    ///
    /// # Errors
    /// As [`BatchConfig::read`].
    pub fn parse(text: &str, name: &str) -> Result<BatchConfig> {
        check_renamed(text, name)?;
        toml::from_str(text).map_err(|e| {
            let place = e
                .span()
                .map(|s| {
                    let line = text[..s.start].matches('\n').count() + 1;
                    let col = s.start - text[..s.start].rfind('\n').map_or(0, |p| p + 1) + 1;
                    format!("line {line}, column {col}: ")
                })
                .unwrap_or_default();
            RunnerError::Config {
                file: name.to_string(),
                message: format!("{place}{}", e.message()),
            }
        })
    }

    fn base(&self) -> PathBuf {
        self.source
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default()
    }

    /// The executor.
    pub fn executor(&self) -> Executor {
        self.executor.executor.clone()
    }

    /// The solver: [`SolverSection::solver`] with this file's directory and executor.
    ///
    /// # Errors
    /// As [`SolverSection::solver`].
    pub fn solver(&self, impactcal: Option<&Path>) -> Result<Solver> {
        self.solver.solver(
            &self.base(),
            &self.source,
            &self.executor.executor,
            impactcal,
        )
    }
}

/// `[batch] retries` of earlier files: an error naming its line and new place. TOML that
/// does not parse is left to the typed parse, which places the fault.
fn check_renamed(text: &str, name: &str) -> Result<()> {
    let Ok(doc) = DeTable::parse(text) else {
        return Ok(());
    };
    let batch = doc.get_ref().get("batch").map(|v| v.get_ref());
    let Some(table) = batch.and_then(|b| b.as_table()) else {
        return Ok(());
    };
    match table
        .iter()
        .find(|(k, _)| k.get_ref().as_ref() == "retries")
    {
        Some((k, _)) => {
            let line = text[..k.span().start.min(text.len())].matches('\n').count() + 1;
            Err(RunnerError::Config {
                file: name.to_string(),
                message: format!("line {line}: [batch] retries: renamed: write [executor] retries"),
            })
        }
        None => Ok(()),
    }
}

impl SolverSection {
    /// The solver: the templates read (relative to `base`), the command resolved. Without a
    /// `command`, the local executor runs the built-in solver in process
    /// ([`SolverCommand::InProcess`], described as `built-in solver, <quantity>`: the caller
    /// hands the runner the solver itself) and the others run `<impactcal> simulate --deck
    /// <deck> --out <output> --quantity <q>`, `impactcal` being the program given (the
    /// running `impactcal` binary). `source` names the configuration file in messages.
    ///
    /// # Errors
    /// [`RunnerError::Io`] / [`RunnerError::Template`] for a template that cannot be read
    /// or parsed; [`RunnerError::Config`] when the built-in solver is asked of another
    /// executor and no program is given.
    pub fn solver(
        &self,
        base: &Path,
        source: &Path,
        executor: &Executor,
        impactcal: Option<&Path>,
    ) -> Result<Solver> {
        let s = self;
        let template_path = base.join(&s.template);
        let deck = match &s.deck {
            Some(d) => d.clone(),
            None => s
                .template
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| "deck.k".into()),
        };
        let mut inputs = vec![(Template::read(&template_path)?, deck.clone())];
        for p in &s.inputs {
            let name = p
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            inputs.push((Template::read(&base.join(p))?, name));
        }
        let command = match (&s.command, executor) {
            (Some(argv), _) => SolverCommand::Argv(argv.clone()),
            (None, Executor::Local) => SolverCommand::InProcess {
                description: format!("built-in solver, {}", s.quantity.as_str()),
            },
            (None, _) => {
                let Some(exe) = impactcal else {
                    return Err(RunnerError::Config {
                        file: source.display().to_string(),
                        message: "solver.command is required for this executor".into(),
                    });
                };
                SolverCommand::Argv(vec![
                    exe.display().to_string(),
                    "simulate".into(),
                    "--deck".into(),
                    deck,
                    "--out".into(),
                    s.output.file.clone(),
                    "--quantity".into(),
                    s.quantity.as_str().into(),
                ])
            }
        };
        let solver = Solver {
            inputs,
            command,
            output: s.output.clone(),
        };
        solver.check(&source.display().to_string())?;
        Ok(solver)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn config_parses_and_names_faults() {
        let c = BatchConfig::parse(
            "[solver]\ntemplate = \"d.k\"\n[executor]\nkind = \"slurm\"\npartition = \"debug\"\nmax_running = 4\n",
            "b.toml",
        )
        .unwrap();
        assert_eq!(c.batch, BatchSection::default());
        assert_eq!(c.executor.retries, 2);
        let Executor::Slurm(s) = &c.executor.executor else {
            panic!("{:?}", c.executor)
        };
        assert_eq!(s.partition.as_deref(), Some("debug"));
        assert_eq!(s.max_running, Some(4));
        assert_eq!(s.max_array, 1000);
        let e = BatchConfig::parse(
            "[solver]\ntemplate = \"d.k\"\n[executor]\nkind = \"processes\"\njobs = 2\ntimeuot = 3\n",
            "b.toml",
        )
        .unwrap_err();
        assert!(e.to_string().starts_with("b.toml: line "), "{e}");
        assert!(e.to_string().contains("timeuot"), "{e}");
        let e = BatchConfig::parse(
            "[solver]\ntemplate = \"d.k\"\n[executor]\nkind = \"cloud\"\n",
            "b.toml",
        )
        .unwrap_err();
        assert!(e.to_string().contains("cloud"), "{e}");
    }

    #[test]
    fn retries_are_an_executor_key_and_the_old_place_is_named() {
        let c = BatchConfig::parse(
            "[solver]\ntemplate = \"d.k\"\n[executor]\nkind = \"processes\"\njobs = 2\nretries = 5\n",
            "b.toml",
        )
        .unwrap();
        assert_eq!(c.executor.retries, 5);
        assert_eq!(
            c.executor(),
            Executor::Processes(crate::ProcessOptions {
                jobs: 2,
                timeout: None
            })
        );
        let e = BatchConfig::parse(
            "[batch]\nstudy = \"s\"\nretries = 1\n[solver]\ntemplate = \"d.k\"\n[executor]\nkind = \"local\"\n",
            "b.toml",
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "b.toml: line 3: [batch] retries: renamed: write [executor] retries"
        );
    }
}
