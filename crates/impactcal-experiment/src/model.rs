//! Model assembly: what an experiment file's `[model]`, `[parameters]`, `[space]` and
//! `[solver]` describe ([`ModelSpec`]) built into one model ([`ExperimentModel`]), the only
//! place that knows every model kind.
//!
//! - the built-in airframe: its catalogue of quantities, held values `set`, the study's
//!   space a preset or a bounds file ([`Subspace`] of the whole catalogue);
//! - a keyword deck: with `*PARAMETER` cards, the deck's real parameters under their own
//!   names; otherwise its sections, materials and masses (`section.<id>.t`, ...), which
//!   `[parameters]` may give other names; the space a bounds file or `[parameters]` (each
//!   quantity +-20 % about the deck's value);
//! - the drop tower (`kind = "drop-tower"`) at the condition `set`;
//! - the Kolsky bar (`kind = "kolsky-bar"`) on its bar test (`test`; module `kolsky`);
//! - a driven lumped system (`kind = "lumped"`, [`crate::lumped`]) driven by each test's
//!   own input;
//! - an external solver (`[solver]`): the space a bounds file naming the template's
//!   parameters, the candidates and held quantities those of `[candidates]` and `[held]`
//!   ([`DeclaredModel`], its runs the runner's);
//! - a parameterised deck with `[candidates]` or `[held]`: the same declared model, run in
//!   this process on the deck's `*PARAMETER` cards (the in-process twin of the deck as a
//!   template).
//!
//! Every built-in model is one [`ExperimentModel`], which implements [`Model`] and
//! [`Enrichable`] by delegating to the model it holds, so that the study, the loop and a
//! worker process each need one code path.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use impactcal_calibrate::study::Subspace;
use impactcal_calibrate::study::document::Geometry;
use impactcal_calibrate::study::subspace::near;
use impactcal_core::drop_tower::DropTower;
use impactcal_core::enrich::Candidate;
use impactcal_core::{
    CoreError, Enrichable, Histories, Model, Parameter, ParameterSpace, Result as CoreResult,
};
use impactcal_models::kolsky::KolskyModel;
use impactcal_runner::config::SolverSection;
use impactcal_runner::{Executor, Runner, Template, fingerprint};
use impactcal_shell::DeckModel;
use impactcal_shell::airframe::{
    Airframe, AirframeModel, AirframeOptions, AirframeValues, MeshDensity, Preset, catalogue,
    space_of,
};
use impactcal_shell::keyword::read_deck;

use crate::builtin::BuiltInSolver;
use crate::declared::{DeclaredModel, Runs, candidates_of, holding};
use crate::error::{ExperimentError, Result, io};
use crate::schema::{CandidateSection, ExperimentFile, SpaceSection};

/// `[candidates]` and `[held]`: the quantities a deck template (or a parameterised deck)
/// holds, the candidates with their admissible ranges.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Declarations {
    /// `[candidates.<name>]`.
    pub candidates: BTreeMap<String, CandidateSection>,
    /// `[held]`.
    pub held: BTreeMap<String, f64>,
}

impl Declarations {
    /// Whether nothing is declared.
    pub fn is_empty(&self) -> bool {
        self.candidates.is_empty() && self.held.is_empty()
    }

    /// Every declared quantity at its held value.
    pub fn values(&self) -> BTreeMap<String, f64> {
        self.candidates
            .iter()
            .map(|(n, c)| (n.clone(), c.held))
            .chain(self.held.iter().map(|(n, v)| (n.clone(), *v)))
            .collect()
    }

    /// The names declared, candidates first.
    fn names(&self) -> impl Iterator<Item = (&str, String)> {
        self.candidates
            .keys()
            .map(|n| (n.as_str(), format!("candidates.{n}")))
            .chain(self.held.keys().map(|n| (n.as_str(), "held".to_string())))
    }

    /// Refuses a declared name that is also a parameter of `space`.
    fn check_against(&self, space: &ParameterSpace, name: &str) -> Result<()> {
        for (n, section) in self.names() {
            if space.index_of(n).is_some() {
                return Err(fault(
                    name,
                    &section,
                    format!(
                        "`{n}` is also a parameter of [space]: a quantity is calibrated or \
                         held, not both"
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// What the model sections of a file describe, before anything is read.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum ModelSpec {
    /// The built-in airframe.
    Airframe {
        /// Mesh density (`coarse`, `medium`, `fine`).
        mesh: String,
        /// Simulated time (s); default: the airframe's.
        end_time: Option<f64>,
        /// Held values of catalogue quantities.
        set: BTreeMap<String, f64>,
        /// The declared parameters.
        space: SpaceSection,
    },
    /// A keyword deck.
    Deck {
        /// The deck file.
        path: PathBuf,
        /// Experiment names -> deck quantities.
        parameters: BTreeMap<String, String>,
        /// The declared parameters.
        space: SpaceSection,
        /// Candidates and held quantities among the deck's `*PARAMETER`s (none: the deck
        /// lists its own).
        declared: Declarations,
    },
    /// The built-in drop tower at a condition.
    DropTower {
        /// The condition (`v0`, ...).
        set: Vec<(String, f64)>,
    },
    /// The Kolsky bar on a bar test in the neutral form.
    KolskyBar {
        /// The bar test's file.
        test: PathBuf,
    },
    /// A driven lumped system and the tests that drive it.
    Lumped(crate::lumped::LumpedSpec),
    /// An external solver through a deck template.
    External {
        /// The `[solver]` table.
        solver: Box<SolverSection>,
        /// The declared parameters (a bounds file naming the template's parameters).
        space: SpaceSection,
        /// The template's candidates and held quantities.
        declared: Declarations,
    },
}

/// A built-in model of an experiment file: every kind, one type.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum ExperimentModel {
    /// The airframe restricted to the declared quantities.
    Airframe(Box<Subspace<AirframeModel>>),
    /// A deck restricted to the declared quantities.
    Deck(Box<Subspace<DeckModel>>),
    /// The drop tower.
    DropTower(DropTower),
    /// The Kolsky bar.
    KolskyBar(Box<KolskyModel>),
    /// A driven lumped system on its calibration or holdout tests.
    Lumped(Box<impactcal_models::lumped::LumpedRepeats>),
    /// A deck template or parameterised deck with declared candidates and held quantities.
    Declared(Box<DeclaredModel>),
}

/// Calls `$body` with `$m` bound to the model inside `$self`, whatever its kind; `$wrap`
/// is the variant's constructor where the body returns a model of the same kind.
macro_rules! each {
    ($self:expr, $m:ident => $body:expr) => {
        match $self {
            ExperimentModel::Airframe($m) => $body,
            ExperimentModel::Deck($m) => $body,
            ExperimentModel::DropTower($m) => $body,
            ExperimentModel::KolskyBar($m) => $body,
            ExperimentModel::Lumped($m) => $body,
            ExperimentModel::Declared($m) => $body,
        }
    };
    ($self:expr, $m:ident => $body:expr, wrap) => {
        match $self {
            ExperimentModel::Airframe($m) => ExperimentModel::Airframe(Box::new($body)),
            ExperimentModel::Deck($m) => ExperimentModel::Deck(Box::new($body)),
            ExperimentModel::DropTower($m) => ExperimentModel::DropTower($body),
            ExperimentModel::KolskyBar($m) => ExperimentModel::KolskyBar(Box::new($body)),
            ExperimentModel::Lumped($m) => ExperimentModel::Lumped(Box::new($body)),
            ExperimentModel::Declared($m) => ExperimentModel::Declared(Box::new($body)),
        }
    };
}

impl Model for ExperimentModel {
    fn space(&self) -> &ParameterSpace {
        each!(self, m => m.space())
    }

    fn simulate(&self, params: &[f64]) -> CoreResult<Histories> {
        each!(self, m => m.simulate(params))
    }
}

impl Enrichable for ExperimentModel {
    fn candidates(&self) -> Vec<Candidate> {
        each!(self, m => m.candidates())
    }

    fn enrich(&self, added: &[Parameter]) -> CoreResult<Self> {
        Ok(each!(self, m => m.enrich(added)?, wrap))
    }

    fn at_condition(&self, set: &[(String, f64)]) -> CoreResult<Self> {
        Ok(each!(self, m => m.at_condition(set)?, wrap))
    }

    fn describe(&self, name: &str) -> Option<(String, String)> {
        each!(self, m => m.describe(name))
    }

    fn check_candidate(&self, p: &Parameter) -> CoreResult<()> {
        each!(self, m => m.check_candidate(p))
    }
}

/// A model built from its spec.
#[derive(Debug, Clone)]
pub struct Built {
    /// The model (for an external solver, a [`DeclaredModel`] whose runs go through the
    /// runner in this process; a study or loop on an executor runs them there instead).
    pub model: Option<ExperimentModel>,
    /// The declared parameters.
    pub space: ParameterSpace,
    /// What the model is: enters the study's and the loop's fingerprint, so a changed deck
    /// or template is another experiment.
    pub description: String,
    /// Where the airframe's sensors are (for the report's figures).
    pub geometry: Option<Geometry>,
    /// Warnings of the deck reader.
    pub notes: Vec<String>,
}

impl ModelSpec {
    /// The spec of a parsed file.
    ///
    /// # Errors
    /// [`ExperimentError::File`] for `[model]` and `[solver]` that do not name exactly one
    /// model, an unknown `kind`, or keys that do not apply to the model named (`end_time`
    /// and `set` on a deck, `[space]` or `[parameters]` on the drop tower, `[parameters]`
    /// on the airframe or an external solver; for the Kolsky bar, those of
    /// the `kolsky` module's `spec`), a missing `[test] data` (every model but the Kolsky bar).
    pub fn of(file: &ExperimentFile, name: &str) -> Result<ModelSpec> {
        let fault = |message: &str| ExperimentError::File {
            file: name.to_string(),
            message: message.to_string(),
        };
        let m = file.model.clone().unwrap_or_default();
        let space = file.space.clone();
        let params = &file.parameters;
        let no_space = space.preset.is_none() && space.bounds.is_none();
        let declared = Declarations {
            candidates: file.candidates.clone(),
            held: file.held.clone(),
        };
        let declares = |what: &str| -> Result<()> {
            if declared.is_empty() {
                Ok(())
            } else {
                Err(fault(&format!(
                    "[candidates] and [held] declare the held quantities of a deck template or \
                     a parameterised deck; {what} lists its own candidates"
                )))
            }
        };
        if m.kind.as_deref() == Some("kolsky-bar") && m.airframe.is_none() && m.deck.is_none() {
            return crate::kolsky::spec(&m, file, name);
        }
        if m.kind.as_deref() != Some(crate::lumped::KIND) {
            crate::lumped::refuse_elsewhere(file, name)?;
        }
        if m.test.is_some() {
            return Err(fault(
                "[model] test names the bar test of kind = \"kolsky-bar\"; other models \
                 take their test from [test] data",
            ));
        }
        if file.test.data.is_none() {
            return Err(fault(
                "[test] data: missing (the measured test, wide CSV or ISO-MME)",
            ));
        }
        match (&m.kind, &m.airframe, &m.deck, &file.solver) {
            (Some(k), None, None, None) if k == crate::lumped::KIND => {
                crate::lumped::LumpedSpec::of(file, name).map(ModelSpec::Lumped)
            }
            (Some(k), None, None, None) if k == "drop-tower" => {
                if !no_space || !params.is_empty() || m.end_time.is_some() {
                    return Err(fault(
                        "[space], [parameters] and [model] end_time apply to the airframe and \
                         decks; the drop tower declares modulus and k_contact",
                    ));
                }
                declares("the drop tower")?;
                Ok(ModelSpec::DropTower {
                    set: m.set.into_iter().collect(),
                })
            }
            (Some(k), None, None, None) => Err(fault(&format!(
                "[model] kind = \"{k}\": unknown (the built-in models are \"drop-tower\", \
                 \"kolsky-bar\" and \"lumped\"; the airframe and decks are \
                 `airframe = \"coarse\"`, `deck = \"model.k\"`)"
            ))),
            (None, Some(mesh), None, None) => {
                if !params.is_empty() {
                    return Err(fault(
                        "[parameters] maps deck quantities; the airframe's names are its \
                         catalogue's",
                    ));
                }
                declares("the airframe")?;
                Ok(ModelSpec::Airframe {
                    mesh: mesh.clone(),
                    end_time: m.end_time,
                    set: m.set,
                    space,
                })
            }
            (None, None, Some(deck), None) => {
                if !m.set.is_empty() || m.end_time.is_some() {
                    return Err(fault(
                        "[model]: `set` and `end_time` apply to the airframe; edit the deck \
                         instead",
                    ));
                }
                if !declared.is_empty() && !params.is_empty() {
                    return Err(fault(
                        "[parameters] renames deck quantities; with [candidates] or [held] the \
                         deck's *PARAMETER names are the experiment's",
                    ));
                }
                Ok(ModelSpec::Deck {
                    path: deck.clone(),
                    parameters: params.clone(),
                    space,
                    declared,
                })
            }
            (None, None, None, Some(solver)) if file.model.is_none() => {
                if !params.is_empty() {
                    return Err(fault(
                        "[parameters] maps deck quantities of a built-in deck model; an \
                         external solver's parameters are its template's",
                    ));
                }
                Ok(ModelSpec::External {
                    solver: Box::new(solver.clone()),
                    space,
                    declared,
                })
            }
            _ => Err(fault(
                "[model]: give one of `airframe = \"coarse\"`, `deck = \"model.k\"` or \
                 `kind = \"drop-tower\"`, or a [solver] table instead of [model]",
            )),
        }
    }

    /// Builds the model; relative paths start at `base`; `name` names the file in
    /// messages.
    ///
    /// # Errors
    /// I/O errors of the deck, template or bounds file; the deck reader's and the
    /// airframe's errors; [`ExperimentError::File`] for a space the model cannot take (a
    /// name it does not have, with the closest names it has; bounds outside what it accepts
    /// beyond round-off).
    pub fn build(&self, base: &Path, name: &str) -> Result<Built> {
        match self {
            ModelSpec::Airframe {
                mesh,
                end_time,
                set,
                space,
            } => airframe(mesh, *end_time, set, space, base, name),
            ModelSpec::Deck {
                path,
                parameters,
                space,
                declared,
            } if declared.is_empty() => deck(&resolve(base, path), parameters, space, base, name),
            ModelSpec::Deck {
                path,
                space,
                declared,
                ..
            } => declared_deck(&resolve(base, path), space, declared, base, name),
            ModelSpec::DropTower { set } => {
                let model = DropTower::new().at_condition(set)?;
                Ok(Built {
                    space: model.space().clone(),
                    model: Some(ExperimentModel::DropTower(model)),
                    description: format!("drop-tower {set:?}"),
                    geometry: None,
                    notes: Vec::new(),
                })
            }
            ModelSpec::KolskyBar { test } => crate::kolsky::build(&resolve(base, test)),
            ModelSpec::Lumped(spec) => spec.build(base),
            ModelSpec::External {
                solver,
                space,
                declared,
            } => external(solver, space, declared, base, name),
        }
    }
}

/// `p` relative to `base` unless absolute.
pub fn resolve(base: &Path, p: &Path) -> PathBuf {
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        base.join(p)
    }
}

/// A fault of `section` of the file `name`.
fn fault(name: &str, section: &str, message: impl std::fmt::Display) -> ExperimentError {
    ExperimentError::File {
        file: name.to_string(),
        message: format!("[{section}]: {message}"),
    }
}

/// The space a `[space]` table declares, if any.
fn declared_space(space: &SpaceSection, base: &Path, name: &str) -> Result<Option<ParameterSpace>> {
    match (&space.preset, &space.bounds) {
        (Some(p), None) => Ok(Some(
            Preset::parse(p)
                .and_then(|p| p.space())
                .map_err(|e| fault(name, "space", e))?,
        )),
        (None, Some(b)) => Ok(Some(ParameterSpace::read_csv(resolve(base, b))?)),
        (None, None) => Ok(None),
        (Some(_), Some(_)) => Err(fault(name, "space", "give `preset` or `bounds`, not both")),
    }
}

fn airframe(
    mesh: &str,
    end_time: Option<f64>,
    set: &BTreeMap<String, f64>,
    space: &SpaceSection,
    base: &Path,
    name: &str,
) -> Result<Built> {
    let mut options =
        AirframeOptions::new(MeshDensity::parse(mesh).map_err(|e| fault(name, "model", e))?);
    if let Some(t) = end_time {
        options.end_time = t;
        options.output_interval = options.output_interval.min(t);
    }
    let airframe = Airframe::new(options).map_err(|e| fault(name, "model", e))?;
    let mut values = AirframeValues::nominal();
    for (k, v) in set {
        values.set(k, *v).map_err(|e| fault(name, "model", e))?;
    }
    let Some(space) = declared_space(space, base, name)? else {
        return Err(fault(
            name,
            "space",
            "give `preset = \"table1\"|\"table2\"` or `bounds = \"bounds.csv\"`",
        ));
    };
    let names: Vec<String> = catalogue().into_iter().map(|a| a.name).collect();
    let full = space_of(&names).map_err(|e| fault(name, "model", e))?;
    let base_point: Vec<f64> = names
        .iter()
        .map(|n| values.get(n))
        .collect::<std::result::Result<_, _>>()
        .map_err(|e| fault(name, "model", e))?;
    let geometry = geometry_of(&airframe);
    let solver = AirframeModel::new(airframe, full).map_err(|e| fault(name, "model", e))?;
    let sub = Subspace::new(solver, space)?.with_base(base_point)?;
    Ok(Built {
        space: sub.space().clone(),
        model: Some(ExperimentModel::Airframe(Box::new(sub))),
        description: format!(
            "built-in airframe, {mesh} mesh, {} s, set {set:?}",
            options.end_time
        ),
        geometry: Some(geometry),
        notes: Vec::new(),
    })
}

/// The airframe's nodes, the position of each sensor channel and the nodes of each part
/// (named as its parameters are: `belly_panel` for `belly_panel.t`).
pub fn geometry_of(airframe: &Airframe) -> Geometry {
    let nodes = airframe.node_positions();
    let mut channels = BTreeMap::new();
    for &n in airframe.sensor_nodes() {
        if let Some(at) = usize::try_from(n)
            .ok()
            .and_then(|i| nodes.get(i.wrapping_sub(1)))
        {
            for a in ["x", "y", "z"] {
                channels.insert(format!("{n}.{a}"), *at);
            }
        }
    }
    let mut regions: BTreeMap<String, Vec<[f64; 3]>> = BTreeMap::new();
    let mut seen = std::collections::BTreeSet::new();
    for (shell, part) in airframe.shells() {
        for n in shell {
            let at = usize::try_from(n)
                .ok()
                .and_then(|i| nodes.get(i.wrapping_sub(1)));
            if let Some(at) = at.filter(|_| seen.insert((part.id(), n))) {
                regions
                    .entry(part.name().to_string())
                    .or_default()
                    .push(*at);
            }
        }
    }
    Geometry {
        points: nodes.to_vec(),
        unit: "in".into(),
        channels,
        regions,
    }
}

/// A keyword deck restricted to the declared quantities. A deck with real `*PARAMETER`s
/// speaks for itself: its quantities are those parameters under the deck's names, as in
/// `impactcal noise --deck`. The sections, materials and masses of the deck are its
/// quantities otherwise, and whenever the experiment names one of them.
fn deck(
    path: &Path,
    parameters: &BTreeMap<String, String>,
    space: &SpaceSection,
    base: &Path,
    name: &str,
) -> Result<Built> {
    let bytes = std::fs::read(path).map_err(io(path))?;
    let read = read_deck(path)?;
    let notes = read.warnings.clone();
    let field_of = |name: &str| parameters.get(name).cloned().unwrap_or_else(|| name.into());
    let declared = declared_space(space, base, name)?;
    let wanted: Vec<String> = match &declared {
        Some(s) => s.names().iter().map(|n| field_of(n)).collect(),
        None => parameters.values().cloned().collect(),
    };
    let by_parameters = DeckModel::from_deck(read.clone(), None).ok().filter(|m| {
        !read.parameters.is_empty() && wanted.iter().all(|w| m.space().index_of(w).is_some())
    });
    let model = match by_parameters {
        Some(m) => m,
        None => DeckModel::new(read.model).map_err(|e| ExperimentError::File {
            file: path.display().to_string(),
            message: e.to_string(),
        })?,
    };
    let space = match declared {
        Some(s) => s,
        None if !parameters.is_empty() => {
            let full = model.space();
            let params = parameters
                .iter()
                .map(|(key, field)| {
                    let q = full.index_of(field).map(|i| full.parameters()[i].clone()).ok_or_else(|| {
                        fault(
                            name,
                            "parameters",
                            format!(
                                "`{key}` = `{field}`: the deck has no such quantity; closest: {}",
                                near(field, &full.names())
                            ),
                        )
                    })?;
                    Ok(Parameter::new(key.clone(), q.lower, q.upper, q.nominal)?)
                })
                .collect::<Result<Vec<_>>>()?;
            ParameterSpace::new(params)?
        }
        None => {
            return Err(fault(
                name,
                "space",
                "give `bounds = \"bounds.csv\"` or a [parameters] table",
            ));
        }
    };
    let fields: Vec<String> = space.names().iter().map(|n| field_of(n)).collect();
    let sub = Subspace::aliased(model, space, &fields)?;
    Ok(Built {
        space: sub.space().clone(),
        model: Some(ExperimentModel::Deck(Box::new(sub))),
        description: format!("deck {} ({})", path.display(), fingerprint(&bytes)),
        geometry: None,
        notes,
    })
}

/// An external solver: its description fingerprints the `[solver]` table, the text of its
/// templates and the declarations, so that a changed deck, command, range or held value is
/// another study or loop. The model runs the solver through a runner in this process.
fn external(
    solver: &SolverSection,
    space: &SpaceSection,
    declared: &Declarations,
    base: &Path,
    name: &str,
) -> Result<Built> {
    let mut bytes = serde_json::to_vec(solver).unwrap_or_default();
    for p in std::iter::once(&solver.template).chain(&solver.inputs) {
        let p = resolve(base, p);
        bytes.extend(std::fs::read(&p).map_err(io(&p))?);
    }
    if !declared.is_empty() {
        bytes.extend(format!("{declared:?}").as_bytes());
    }
    let Some(space) = declared_space(space, base, name)? else {
        return Err(fault(
            name,
            "space",
            "an external solver needs `bounds = \"bounds.csv\"` naming its template's parameters",
        ));
    };
    declared.check_against(&space, name)?;
    let local = solver
        .solver(base, Path::new(name), &Executor::Local, None)
        .map_err(|e| ExperimentError::from(e).in_section(name, "solver"))?;
    let templates: Vec<&Template> = local.inputs.iter().map(|(t, _)| t).collect();
    check_template(&templates, &space, declared, name)?;
    let runner = Runner {
        in_process: Some(std::sync::Arc::new(BuiltInSolver::new(solver.quantity))),
        ..Runner::new(holding(local, &declared.values()), Executor::Local)
    };
    let model = DeclaredModel::new(
        space.clone(),
        candidates_of(&declared.candidates)?,
        &declared.held,
        Runs::Solver(Box::new(runner)),
    )?;
    Ok(Built {
        model: Some(ExperimentModel::Declared(Box::new(model))),
        space,
        description: format!(
            "solver {} ({})",
            solver.template.display(),
            fingerprint(&bytes)
        ),
        geometry: None,
        notes: Vec::new(),
    })
}

/// Checks a template against what the file declares: every `<<name>>` placeholder a
/// parameter of the space, a candidate or a held quantity, and every candidate and held
/// quantity somewhere in the templates (a placeholder or an `R`/`I` `*PARAMETER` entry).
fn check_template(
    templates: &[&Template],
    space: &ParameterSpace,
    declared: &Declarations,
    name: &str,
) -> Result<()> {
    let known: Vec<&str> = space
        .names()
        .into_iter()
        .chain(declared.names().map(|(n, _)| n))
        .collect();
    for t in templates {
        if let Some(p) = t
            .placeholder_names()
            .into_iter()
            .find(|p| !known.contains(p))
        {
            return Err(fault(
                name,
                "solver",
                format!(
                    "template {}: `<<{p}>>` is neither a parameter of [space], a [candidates] \
                     entry nor a [held] quantity; closest: {}",
                    t.file(),
                    near(p, &known)
                ),
            ));
        }
    }
    for (n, section) in declared.names() {
        if !templates.iter().any(|t| t.names().contains(n)) {
            return Err(fault(
                name,
                &section,
                format!(
                    "`{n}` appears nowhere in the template (neither a <<{n}>> placeholder nor \
                     an R/I *PARAMETER entry), so no run could write it"
                ),
            ));
        }
    }
    Ok(())
}

/// A parameterised deck with declared candidates and held quantities, run in this process:
/// the space a bounds file naming the deck's real `*PARAMETER`s, every candidate and held
/// quantity one of them too.
fn declared_deck(
    path: &Path,
    space: &SpaceSection,
    declared: &Declarations,
    base: &Path,
    name: &str,
) -> Result<Built> {
    let bytes = std::fs::read(path).map_err(io(path))?;
    let read = read_deck(path)?;
    let Some(space) = declared_space(space, base, name)? else {
        return Err(fault(
            name,
            "space",
            "give `bounds = \"bounds.csv\"` naming the deck's *PARAMETERs",
        ));
    };
    declared.check_against(&space, name)?;
    let reals: Vec<&str> = read
        .parameters
        .iter()
        .filter(|p| !p.integer && p.expression.is_none())
        .map(|p| p.name.as_str())
        .collect();
    let sections = space
        .names()
        .into_iter()
        .map(|n| (n, "space".to_string()))
        .collect::<Vec<_>>();
    for (n, section) in sections.into_iter().chain(declared.names()) {
        if !reals.iter().any(|r| r.eq_ignore_ascii_case(n)) {
            return Err(fault(
                name,
                &section,
                format!(
                    "`{n}` is not a real *PARAMETER of {}; closest: {}",
                    path.display(),
                    near(n, &reals)
                ),
            ));
        }
    }
    let notes = read.warnings.clone();
    let model = DeclaredModel::new(
        space.clone(),
        candidates_of(&declared.candidates)?,
        &declared.held,
        Runs::Deck {
            deck: Box::new(read),
            quantity: impactcal_core::NodalQuantity::Velocity,
        },
    )?;
    Ok(Built {
        model: Some(ExperimentModel::Declared(Box::new(model))),
        space,
        description: format!(
            "deck {} ({}) declaring {declared:?}",
            path.display(),
            fingerprint(&bytes)
        ),
        geometry: None,
        notes,
    })
}

/// A [`CoreError`] for a run record that does not fit the model.
pub(crate) fn record_error(what: &str, message: String) -> ExperimentError {
    ExperimentError::Core(CoreError::invalid_option("params.json", what, message))
}
