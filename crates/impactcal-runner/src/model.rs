//! An external solver as a [`Model`]: each call to `simulate` is a run in its own work
//! directory, through the same templates, command and output reader as a batch.

use std::path::PathBuf;

use impactcal_core::{CoreError, Histories, Model, ParameterSpace};

use crate::batch::{Batch, Cancel};
use crate::error::{Result, RunnerError};
use crate::executor::{Executor, run_batch};
use crate::solver::Solver;
use crate::template::{Template, check_names};

/// A [`Solver`] over a [`ParameterSpace`]: `simulate(x)` writes the templates with `x`,
/// runs the solver in a new directory `<root>/runs/model-<n>/0/` (n counting up from the
/// first free number) and reads its output. Batches of such runs are better run through
/// [`run_batch`], which adds the journal, resuming and the other executors; this type
/// serves code written against [`Model`].
#[derive(Debug)]
pub struct SolverModel {
    space: ParameterSpace,
    solver: Solver,
    root: PathBuf,
    next: std::sync::atomic::AtomicUsize,
}

impl SolverModel {
    /// The model of `solver` over `space`, with its runs under `root`.
    ///
    /// # Errors
    /// [`RunnerError::Config`] for a bad solver; [`RunnerError::Names`] when the space's
    /// names are not identifiers or do not match the templates.
    pub fn new(space: ParameterSpace, solver: Solver, root: impl Into<PathBuf>) -> Result<Self> {
        solver.check("configuration")?;
        let names: Vec<String> = space.names().iter().map(|s| s.to_string()).collect();
        let templates: Vec<&Template> = solver.inputs.iter().map(|(t, _)| t).collect();
        check_names(&templates, &names)?;
        Ok(SolverModel {
            space,
            solver,
            root: root.into(),
            next: std::sync::atomic::AtomicUsize::new(0),
        })
    }

    /// Claims the next free run directory name `model-<n>`.
    fn claim(&self) -> Result<String> {
        let runs = self.root.join("runs");
        std::fs::create_dir_all(&runs).map_err(crate::error::io(&runs))?;
        loop {
            let n = self.next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
            let name = format!("model-{n}");
            match std::fs::create_dir(runs.join(&name)) {
                Ok(()) => return Ok(name),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(crate::error::io(runs.join(&name))(e)),
            }
        }
    }

    fn run(&self, params: &[f64]) -> Result<Histories> {
        let study = self.claim()?;
        let names = self.space.names().iter().map(|s| s.to_string()).collect();
        let point = vec![params.to_vec()];
        let batch = Batch::new(&self.root, &study, self.solver.clone(), names, &point)?;
        let mut report = run_batch(&batch, &Executor::Local, &Cancel::new())?;
        match report.runs.pop() {
            Some(Ok(r)) => r.read(),
            Some(Err(e)) => Err(e),
            None => Err(RunnerError::Config {
                file: "model".into(),
                message: "no run".into(),
            }),
        }
    }
}

impl Model for SolverModel {
    fn space(&self) -> &ParameterSpace {
        &self.space
    }

    /// # Errors
    /// [`CoreError::Simulation`] wrapping the [`RunnerError`] (which names the run
    /// directory and the file at fault).
    fn simulate(&self, params: &[f64]) -> impactcal_core::Result<Histories> {
        self.run(params).map_err(CoreError::simulation)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::outputs::OutputSpec;
    use crate::solver::SolverCommand;
    use impactcal_core::Parameter;

    #[test]
    fn a_solver_is_a_model() {
        let template = Template::parse("time,y\n0,<<a>>\n1,<<b>>\n", "deck.csv").unwrap();
        let solver = Solver {
            inputs: vec![(template, "deck.csv".into())],
            command: SolverCommand::Argv(vec!["cp".into(), "deck.csv".into(), "out.csv".into()]),
            output: OutputSpec::csv("out.csv"),
        };
        let space = ParameterSpace::new(vec![
            Parameter::new("a", -5.0, 5.0, 0.0).unwrap(),
            Parameter::new("b", -5.0, 5.0, 0.0).unwrap(),
        ])
        .unwrap();
        let dir = tempfile::tempdir().unwrap();
        let model = SolverModel::new(space, solver, dir.path()).unwrap();
        let points: Vec<Vec<f64>> = (0..5).map(|i| vec![i as f64, -(i as f64)]).collect();
        let out = model.simulate_batch(&points);
        for (i, h) in out.successes() {
            assert_eq!(h.channel(0), [i as f64, -(i as f64)]);
        }
        assert_eq!(out.failures().count(), 0);
        // Five runs, five directories.
        let dirs = std::fs::read_dir(dir.path().join("runs")).unwrap().count();
        assert_eq!(dirs, 5);
    }
}
