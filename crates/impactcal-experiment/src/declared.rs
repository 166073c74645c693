//! A model whose held quantities the experiment file declares: a deck template run by an
//! external solver, or a parameterised deck run in this process, with the candidate effects
//! of `[candidates.<name>]` (admissible range, held value) and the test conditions of
//! `[held]`.
//!
//! Its space is `[space]` (the template's or the deck's parameter names) followed by the
//! candidates the closed loop adds; every other declared quantity is held, at its held
//! value or at the value a condition sets ([`Enrichable::at_condition`], a holdout's
//! `set`). A run writes every value into the deck: a candidate the loop has not freed and a
//! test condition at their held values, as the template's `<<name>>` placeholders or
//! `*PARAMETER` entries ([`impactcal_runner::Template::holding`]).

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicUsize, Ordering};

use impactcal_core::enrich::{Candidate, Enrichable};
use impactcal_core::{
    CoreError, Histories, Model, NodalQuantity, Parameter, ParameterSpace, Result as CoreResult,
};
use impactcal_runner::{Batch, Hooks, Runner, Solver};
use impactcal_shell::Simulation;
use impactcal_shell::keyword::Deck;

use crate::schema::CandidateSection;

/// The group a declared candidate is reported under.
pub const GROUP: &str = "declared";

/// The candidates of `[candidates]`, in the order of their names.
///
/// # Errors
/// [`CoreError::Parameter`] for a range or held value the schema's checks let through
/// (none: `lower < upper`, `held` in the range, all finite).
pub fn candidates_of(declared: &BTreeMap<String, CandidateSection>) -> CoreResult<Vec<Candidate>> {
    declared
        .iter()
        .map(|(name, c)| {
            let p = Parameter::new(name.clone(), c.lower, c.upper, c.held)?;
            Ok(Candidate::new(
                p,
                GROUP,
                c.description.clone().unwrap_or_default(),
            ))
        })
        .collect()
}

/// `solver` with each of its templates holding `held` (names a run does not give are
/// written at these values).
pub fn holding(mut solver: Solver, held: &BTreeMap<String, f64>) -> Solver {
    solver.inputs = solver
        .inputs
        .into_iter()
        .map(|(t, name)| (t.holding(held), name))
        .collect();
    solver
}

/// What runs a [`DeclaredModel`].
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum Runs {
    /// A parameterised deck in this process: read again with every value in its
    /// `*PARAMETER` cards, run by the built-in solver, the histories of `quantity`.
    Deck {
        /// The deck as read.
        deck: Box<Deck>,
        /// The nodal quantity of the histories.
        quantity: NodalQuantity,
    },
    /// A deck template through a runner (its solver's templates holding the declared
    /// values): each run is a one-run batch in a directory of its own under the system's
    /// temporary directory, removed afterwards.
    Solver(Box<Runner>),
}

/// A model whose candidates and held quantities the experiment file declares.
#[derive(Debug, Clone)]
pub struct DeclaredModel {
    space: ParameterSpace,
    candidates: Vec<Candidate>,
    /// Every declared quantity not in `space`, at the value it is held at.
    values: BTreeMap<String, f64>,
    runs: Runs,
}

impl DeclaredModel {
    /// The model over `space` with the candidates `candidates` (at their held values) and
    /// the held quantities `held`, run by `runs`.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for a name that is both in `space` and declared, or
    /// declared twice.
    pub fn new(
        space: ParameterSpace,
        candidates: Vec<Candidate>,
        held: &BTreeMap<String, f64>,
        runs: Runs,
    ) -> CoreResult<DeclaredModel> {
        let mut values = BTreeMap::new();
        let declared = candidates
            .iter()
            .map(|c| (c.name(), c.parameter.nominal))
            .chain(held.iter().map(|(n, v)| (n.as_str(), *v)));
        for (name, value) in declared {
            if space.index_of(name).is_some() {
                return Err(CoreError::invalid_option(
                    "declared quantities",
                    name,
                    "a parameter of the space: a point sets it, it cannot also be held",
                ));
            }
            if values.insert(name.to_string(), value).is_some() {
                return Err(CoreError::invalid_option(
                    "declared quantities",
                    name,
                    "declared twice",
                ));
            }
        }
        Ok(DeclaredModel {
            space,
            candidates,
            values,
            runs,
        })
    }

    /// Every held quantity at the value a run writes for it.
    pub fn held(&self) -> &BTreeMap<String, f64> {
        &self.values
    }

    /// What runs the model.
    pub fn runs(&self) -> &Runs {
        &self.runs
    }
}

impl Model for DeclaredModel {
    fn space(&self) -> &ParameterSpace {
        &self.space
    }

    /// The histories at `params` with every held quantity at its value.
    ///
    /// # Errors
    /// A point outside the space; the deck's, the solver's or the runner's error as a
    /// simulation error.
    fn simulate(&self, params: &[f64]) -> CoreResult<Histories> {
        self.space.to_unit(params)?;
        match &self.runs {
            Runs::Deck { deck, quantity } => {
                let values: Vec<(&str, f64)> = self
                    .space
                    .names()
                    .into_iter()
                    .zip(params.iter().copied())
                    .chain(self.values.iter().map(|(n, v)| (n.as_str(), *v)))
                    .collect();
                let model = deck
                    .with_parameters(&values)
                    .map_err(CoreError::simulation)?
                    .model;
                let result = Simulation::new(&model)
                    .and_then(|mut s| s.run())
                    .map_err(CoreError::simulation)?;
                result
                    .histories(*quantity)
                    .cloned()
                    .ok_or_else(|| CoreError::Invalid("the run produced no nodal histories".into()))
            }
            Runs::Solver(runner) => one_run(runner, &self.space, params, &self.values),
        }
    }
}

/// One run of `runner`'s solver at `params` (coordinates of `space`) with `held` written
/// beside them, in a fresh directory under the system's temporary directory.
fn one_run(
    runner: &Runner,
    space: &ParameterSpace,
    params: &[f64],
    held: &BTreeMap<String, f64>,
) -> CoreResult<Histories> {
    static RUN: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "impactcal-run-{}-{}",
        std::process::id(),
        RUN.fetch_add(1, Ordering::SeqCst)
    ));
    let set: Vec<(String, f64)> = held.iter().map(|(n, v)| (n.clone(), *v)).collect();
    let result = Batch::for_space_at(
        &dir,
        "run",
        runner.solver.clone(),
        space,
        std::slice::from_ref(&params.to_vec()),
        &set,
    )
    .map(|b| b.with_retries(runner.retries))
    .and_then(|b| runner.run(&b, Hooks::default()))
    .and_then(|r| r.histories(0));
    let _ = std::fs::remove_dir_all(&dir);
    result.map_err(CoreError::simulation)
}

impl Enrichable for DeclaredModel {
    /// The declared candidates not yet added, at the values they are held at.
    fn candidates(&self) -> Vec<Candidate> {
        self.candidates
            .iter()
            .filter_map(|c| {
                let held = *self.values.get(c.name())?;
                let mut c = c.clone();
                c.parameter.nominal = held;
                Some(c)
            })
            .collect()
    }

    /// # Errors
    /// [`CoreError::InvalidOption`] for a name that is not a candidate (or added twice) or
    /// bounds outside its admissible range; [`CoreError::Parameter`] for invalid bounds.
    fn enrich(&self, added: &[Parameter]) -> CoreResult<Self> {
        let listed = self.candidates();
        let mut m = self.clone();
        let mut params = self.space.parameters().to_vec();
        for p in added {
            p.validate()?;
            let Some(c) = listed.iter().find(|c| c.name() == p.name) else {
                return Err(self.check_candidate(p).err().unwrap_or_else(|| {
                    CoreError::invalid_option("enrich", &p.name, "added twice")
                }));
            };
            if m.values.remove(&p.name).is_none() {
                return Err(CoreError::invalid_option("enrich", &p.name, "added twice"));
            }
            c.check_bounds(p)?;
            params.push(p.clone());
        }
        m.space = ParameterSpace::new(params)?;
        Ok(m)
    }

    /// # Errors
    /// [`CoreError::InvalidOption`] for a parameter of the space, a name nothing declares,
    /// or a candidate's value outside its admissible range.
    fn at_condition(&self, set: &[(String, f64)]) -> CoreResult<Self> {
        let mut m = self.clone();
        for (name, value) in set {
            if self.space.index_of(name).is_some() {
                return Err(CoreError::invalid_option(
                    "condition",
                    name,
                    "a declared parameter of the model (a point sets it), not a held quantity",
                ));
            }
            let Some(v) = m.values.get_mut(name) else {
                return Err(CoreError::invalid_option(
                    "condition",
                    name,
                    "neither a [candidates] entry nor a [held] quantity",
                ));
            };
            if let Some(c) = self.candidates.iter().find(|c| c.name() == name) {
                c.check_value(*value)?;
            }
            impactcal_core::check_finite(&format!("condition `{name}`"), &[*value])?;
            *v = *value;
        }
        Ok(m)
    }

    fn describe(&self, name: &str) -> Option<(String, String)> {
        self.candidates
            .iter()
            .find(|c| c.name() == name)
            .map(|c| (GROUP.to_string(), c.description.clone()))
    }
}
