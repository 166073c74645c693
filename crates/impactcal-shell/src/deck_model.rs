//! A [`ShellModel`] (for example a keyword deck) as an [`impactcal_core::Model`]: its
//! section thicknesses, material constants and concentrated masses become named
//! parameters, and a run returns the nodal histories of its history nodes.
//!
//! The quantities of a model, in this order:
//! - `section.<id>.t`: the thickness of every section;
//! - `material.<id>.E`: Young's modulus of every material;
//! - `material.<id>.sigy`, `material.<id>.Et`: yield stress and tangent modulus of every
//!   elastic-plastic material (`Et` only where it is not zero);
//! - `mass.<id>`: every non-zero concentrated mass (`*ELEMENT_MASS`, one quantity per mass
//!   element);
//! - `wall.<k>.friction`: the Coulomb coefficient of the k-th rigid wall (1-based, in deck
//!   order);
//! - `damping`: the mass-proportional damping constant of `*DAMPING_GLOBAL` (1/time);
//! - `velocity.<k>.<x|y|z>`: the translational components of the k-th initial velocity.
//!
//! The first four kinds are the structure: by default ([`DeckModel::new`]) they make up the
//! space, each with the bounds +-20 % about its value in the model. [`DeckModel::declare`]
//! declares any subset of the quantities instead. The quantities not declared are held at
//! the model's values; they are the model's candidate effects ([`Enrichable`]), each with an
//! admissible range:
//! - thicknesses, moduli, yield stresses and masses: +-20 % about the deck's value (the
//!   width of the source paper's Table 1);
//! - wall friction: `[0, 0.8]` (a Coulomb coefficient is never negative; 0.8 is about the
//!   largest quoted for metal on concrete or soil);
//! - damping: `[0, 2 / end_time]` (mass-proportional damping only removes energy; at the
//!   upper end a free motion loses all but e^-2 of its speed over the run);
//! - initial velocity components: the deck's value +- 20 % of that initial velocity's speed
//!   (a component that is 0 in the deck can take either sign).
//!
//! A range is widened to include a held value outside it.
//!
//! A deck with `*PARAMETER` cards speaks for itself instead ([`DeckModel::from_deck`]): its
//! real (`R`) parameters are the quantities, under the deck's own names, with the bounds
//! +-20 % about the deck's values unless the caller gives bounds; a run reads the deck
//! again with the point's values in its parameters. Real parameters the caller's bounds do
//! not name are held at the deck's values and are the candidates (+-20 %; one that is 0 in
//! the deck has no such range and is left out). These are the quantities a crash analyst
//! would call "the model" as opposed to the test conditions (impact velocity, attitude,
//! ground, controls), and the ones a jitter ensemble perturbs ([`impactcal_core::noise`]).
//!
//! ```
//! use impactcal_core::{Enrichable, Model};
//! use impactcal_shell::keyword::parse_deck;
//! use impactcal_shell::DeckModel;
//!
//! let text = std::fs::read_to_string(concat!(
//!     env!("CARGO_MANIFEST_DIR"),
//!     "/../../examples/decks/strip_drop.k"
//! ))?;
//! let deck = parse_deck(&text, "strip_drop.k")?;
//! let model = DeckModel::new(deck.model)?;
//! let names: Vec<&str> = model.space().names();
//! assert_eq!(names, ["section.1.t", "material.1.E", "material.1.sigy", "material.1.Et"]);
//! let h = model.simulate(&model.space().nominal())?;
//! assert_eq!(h.labels(), ["21.x", "21.y", "21.z", "42.x", "42.y", "42.z"]);
//! let held: Vec<String> = model.candidates().iter().map(|c| c.name().to_string()).collect();
//! assert_eq!(held, ["wall.1.friction", "damping", "velocity.1.x", "velocity.1.y", "velocity.1.z"]);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use impactcal_core::enrich::{Candidate, Enrichable};
use impactcal_core::{CoreError, Histories, Model, NodalQuantity, Parameter, ParameterSpace};

use crate::error::{Result, ShellError};
use crate::keyword::Deck;
use crate::model::{MaterialLaw, ShellModel};
use crate::simulation::Simulation;

/// Where a quantity of a [`DeckModel`] goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Target {
    Thickness(usize),
    Youngs(usize),
    Yield(usize),
    Tangent(usize),
    Mass(usize),
    Friction(usize),
    Damping,
    Velocity(usize, usize),
    /// A real `*PARAMETER` of a parameterised deck (set by reading the deck again).
    DeckParameter,
}

impl Target {
    /// Whether the quantity belongs to the structure (the default space).
    fn structural(self) -> bool {
        matches!(
            self,
            Target::Thickness(_)
                | Target::Youngs(_)
                | Target::Yield(_)
                | Target::Tangent(_)
                | Target::Mass(_)
        )
    }

    /// The quantity's value in `m` (`None` for a deck parameter).
    fn get(self, m: &ShellModel) -> Option<f64> {
        Some(match self {
            Target::Thickness(k) => m.sections[k].thickness,
            Target::Youngs(k) => m.materials[k].youngs,
            Target::Yield(k) | Target::Tangent(k) => match m.materials[k].law {
                MaterialLaw::Plastic {
                    yield_stress,
                    tangent_modulus,
                    ..
                } => {
                    if matches!(self, Target::Yield(_)) {
                        yield_stress
                    } else {
                        tangent_modulus
                    }
                }
                _ => return None,
            },
            Target::Mass(k) => m.masses[k].mass,
            Target::Friction(k) => m.walls[k].friction,
            Target::Damping => m.damping,
            Target::Velocity(k, a) => m.initial_velocities[k].translation[a],
            Target::DeckParameter => return None,
        })
    }

    /// Sets the quantity in `m` to `v` (nothing for a deck parameter).
    fn set(self, m: &mut ShellModel, v: f64) {
        match self {
            Target::Thickness(k) => m.sections[k].thickness = v,
            Target::Youngs(k) => m.materials[k].youngs = v,
            Target::Yield(k) | Target::Tangent(k) => {
                if let MaterialLaw::Plastic {
                    yield_stress,
                    tangent_modulus,
                    ..
                } = &mut m.materials[k].law
                {
                    if matches!(self, Target::Yield(_)) {
                        *yield_stress = v;
                    } else {
                        *tangent_modulus = v;
                    }
                }
            }
            Target::Mass(k) => m.masses[k].mass = v,
            Target::Friction(k) => m.walls[k].friction = v,
            Target::Damping => m.damping = v,
            Target::Velocity(k, a) => m.initial_velocities[k].translation[a] = v,
            Target::DeckParameter => {}
        }
    }
}

/// One quantity of a model: its admissible range (nominal = its value in the model as
/// read), where it goes, its group and what it is.
#[derive(Debug, Clone)]
struct DeckQuantity {
    parameter: Parameter,
    target: Target,
    group: &'static str,
    description: String,
}

/// `v +- 20 %` as `(lower, upper)`, ordered for a negative `v`.
fn twenty_percent(v: f64) -> (f64, f64) {
    ((0.8 * v).min(1.2 * v), (0.8 * v).max(1.2 * v))
}

/// Every quantity of `model`, in the order of the module docs.
fn quantities(model: &ShellModel) -> Result<Vec<DeckQuantity>> {
    let mut q = Vec::new();
    let mut add = |name: String,
                   (lower, upper): (f64, f64),
                   v: f64,
                   unit: &str,
                   target: Target,
                   group: &'static str,
                   description: String|
     -> Result<()> {
        let parameter = Parameter::new(name, lower.min(v), upper.max(v), v)?.with_unit(unit);
        q.push(DeckQuantity {
            parameter,
            target,
            group,
            description,
        });
        Ok(())
    };
    for (k, s) in model.sections.iter().enumerate() {
        let t = s.thickness;
        let d = format!("thickness of section {}", s.id);
        let name = format!("section.{}.t", s.id);
        add(
            name,
            twenty_percent(t),
            t,
            "length",
            Target::Thickness(k),
            "thickness",
            d,
        )?;
    }
    for (k, m) in model.materials.iter().enumerate() {
        let e = m.youngs;
        let d = format!("Young's modulus of material {}", m.id);
        let name = format!("material.{}.E", m.id);
        add(
            name,
            twenty_percent(e),
            e,
            "stress",
            Target::Youngs(k),
            "material",
            d,
        )?;
        if let MaterialLaw::Plastic {
            yield_stress,
            tangent_modulus,
            ..
        } = m.law
        {
            let (y, d) = (yield_stress, format!("yield stress of material {}", m.id));
            let name = format!("material.{}.sigy", m.id);
            add(
                name,
                twenty_percent(y),
                y,
                "stress",
                Target::Yield(k),
                "material",
                d,
            )?;
            if tangent_modulus > 0.0 {
                let et = tangent_modulus;
                let d = format!("tangent modulus of material {}", m.id);
                let name = format!("material.{}.Et", m.id);
                add(
                    name,
                    twenty_percent(et),
                    et,
                    "stress",
                    Target::Tangent(k),
                    "material",
                    d,
                )?;
            }
        }
    }
    for (k, m) in model.masses.iter().enumerate() {
        if m.mass > 0.0 {
            let d = format!("concentrated mass {} on node {}", m.id, m.node);
            let name = format!("mass.{}", m.id);
            add(
                name,
                twenty_percent(m.mass),
                m.mass,
                "mass",
                Target::Mass(k),
                "mass",
                d,
            )?;
        }
    }
    for (k, w) in model.walls.iter().enumerate() {
        let d = format!("Coulomb friction of rigid wall {}", k + 1);
        let name = format!("wall.{}.friction", k + 1);
        add(
            name,
            (0.0, 0.8),
            w.friction,
            "",
            Target::Friction(k),
            "friction",
            d,
        )?;
    }
    let end = model.control.end_time;
    if end.is_finite() && end > 0.0 {
        let d = "mass-proportional damping constant (*DAMPING_GLOBAL)".to_string();
        let range = (0.0, 2.0 / end);
        add(
            "damping".into(),
            range,
            model.damping,
            "1/time",
            Target::Damping,
            "damping",
            d,
        )?;
    }
    for (k, iv) in model.initial_velocities.iter().enumerate() {
        let v = iv.translation;
        let speed = v.iter().map(|c| c * c).sum::<f64>().sqrt();
        if speed > 0.0 {
            for (a, axis) in ["x", "y", "z"].into_iter().enumerate() {
                let d = format!("initial velocity {} along {axis}", k + 1);
                let range = (v[a] - 0.2 * speed, v[a] + 0.2 * speed);
                let name = format!("velocity.{}.{axis}", k + 1);
                let t = Target::Velocity(k, a);
                add(name, range, v[a], "velocity", t, "condition", d)?;
            }
        }
    }
    Ok(q)
}

/// The real parameters of a parameterised deck as quantities (+-20 % about the deck's
/// value; one that is 0 is left out, and so is one computed by `*PARAMETER_EXPRESSION`,
/// which follows the parameters it is computed from).
fn deck_quantities(deck: &Deck) -> Vec<DeckQuantity> {
    deck.parameters
        .iter()
        .filter(|p| !p.integer && p.value != 0.0 && p.expression.is_none())
        .filter_map(|p| {
            let (lo, hi) = twenty_percent(p.value);
            Some(DeckQuantity {
                parameter: Parameter::new(p.name.clone(), lo, hi, p.value).ok()?,
                target: Target::DeckParameter,
                group: "parameter",
                description: format!("*PARAMETER {} ({}: line {})", p.name, p.file, p.line),
            })
        })
        .collect()
}

/// A shell model whose thicknesses, material constants and concentrated masses are the
/// parameters of an [`impactcal_core::Model`] (see the module docs).
#[derive(Debug, Clone)]
pub struct DeckModel {
    /// The model with every held quantity at its held value.
    base: ShellModel,
    space: ParameterSpace,
    /// Where each parameter of `space` goes.
    targets: Vec<Target>,
    /// Every quantity the model knows, with its admissible range.
    quantities: Vec<DeckQuantity>,
    quantity: NodalQuantity,
    /// A parameterised deck: its parameters are the quantities, in the order of `space`.
    deck: Option<Deck>,
    /// A parameterised deck's real parameters not in `space`, at their held values.
    held: Vec<(String, f64)>,
}

impl DeckModel {
    /// The model with every thickness, modulus, yield stress, tangent modulus and
    /// concentrated mass as a parameter; the output is the velocity of the history nodes.
    ///
    /// # Errors
    /// As [`ShellModel::check`] for a model the solver would refuse; [`ShellError::Value`]
    /// when the model has no history nodes (nothing to output) or a value cannot bound a
    /// parameter (not finite and positive).
    pub fn new(model: ShellModel) -> Result<Self> {
        model.check()?;
        check_outputs(&model)?;
        let quantities = quantities(&model)?;
        let (params, targets) = quantities
            .iter()
            .filter(|q| q.target.structural())
            .map(|q| (q.parameter.clone(), q.target))
            .unzip();
        Ok(DeckModel {
            space: ParameterSpace::new(params)?,
            base: model,
            targets,
            quantities,
            quantity: NodalQuantity::Velocity,
            deck: None,
            held: Vec::new(),
        })
    }

    /// The model of a deck: with `*PARAMETER` cards, the deck's real (`R`) parameters are
    /// the quantities (names as in the deck; `bounds`, when given, names some or all of
    /// them with their bounds and nominal values, the others keep the deck's values; else
    /// each is bounded +-20 % about the deck's value); without, as [`DeckModel::new`] on the
    /// deck's model (`bounds` must then be `None`). The output is the velocity of the
    /// history nodes.
    ///
    /// # Errors
    /// As [`ShellModel::check`] for a model the solver would refuse; [`ShellError::Value`]
    /// when the model has no history nodes, a bound names a parameter
    /// the deck does not define (or the deck defines none), or a deck value of 0 would be
    /// bounded without bounds given.
    pub fn from_deck(deck: Deck, bounds: Option<&ParameterSpace>) -> Result<Self> {
        let reals: Vec<_> = deck
            .parameters
            .iter()
            .filter(|p| !p.integer && p.expression.is_none())
            .collect();
        if reals.is_empty() {
            if bounds.is_some() {
                return Err(ShellError::value(
                    "deck",
                    "defines no real *PARAMETER to take the given bounds",
                ));
            }
            return DeckModel::new(deck.model);
        }
        deck.model.check()?;
        check_outputs(&deck.model)?;
        let space = match bounds {
            Some(space) => {
                for n in space.names() {
                    if !reals.iter().any(|p| p.name.eq_ignore_ascii_case(n)) {
                        return Err(ShellError::value(
                            format!("parameter {n}"),
                            "is not a real *PARAMETER of the deck",
                        ));
                    }
                }
                space.clone()
            }
            None => {
                let mut params = Vec::with_capacity(reals.len());
                for p in &reals {
                    let v = p.value;
                    if v == 0.0 {
                        return Err(ShellError::value(
                            format!("parameter {} ({}: line {})", p.name, p.file, p.line),
                            "is 0 in the deck: +-20 % bounds are empty, give its bounds",
                        ));
                    }
                    let (lo, hi) = twenty_percent(v);
                    params.push(Parameter::new(p.name.clone(), lo, hi, v)?);
                }
                ParameterSpace::new(params)?
            }
        };
        let held = reals
            .iter()
            .filter(|p| {
                space
                    .names()
                    .iter()
                    .all(|n| !p.name.eq_ignore_ascii_case(n))
            })
            .map(|p| (p.name.clone(), p.value))
            .collect();
        Ok(DeckModel {
            targets: vec![Target::DeckParameter; space.dim()],
            quantities: deck_quantities(&deck),
            space,
            base: deck.model.clone(),
            quantity: NodalQuantity::Velocity,
            deck: Some(deck),
            held,
        })
    }

    /// The same model declaring the quantities of `space` (names of the module docs, or a
    /// parameterised deck's real parameters) with the caller's bounds and nominal values;
    /// every other quantity is held at the model's value and becomes a candidate.
    ///
    /// # Errors
    /// [`ShellError::Value`] naming a quantity the model does not have, or bounds outside
    /// its admissible range.
    pub fn declare(&self, space: &ParameterSpace) -> Result<Self> {
        let mut targets = Vec::with_capacity(space.dim());
        for p in space.parameters() {
            let q = self.quantity_named(&p.name).ok_or_else(|| {
                ShellError::value(
                    format!("quantity `{}`", p.name),
                    "the model has no such quantity (section.<id>.t, material.<id>.E|sigy|Et, \
                     mass.<id>, wall.<k>.friction, damping, velocity.<k>.x|y|z, or a real \
                     *PARAMETER)",
                )
            })?;
            Candidate::new(q.parameter.clone(), q.group, "")
                .check_bounds(p)
                .map_err(ShellError::from)?;
            targets.push(q.target);
        }
        let mut m = self.clone();
        m.held = self
            .held_parameters()
            .filter(|(n, _)| space.index_of(n).is_none())
            .collect();
        m.space = space.clone();
        m.targets = targets;
        Ok(m)
    }

    /// The same model returning another nodal quantity.
    #[must_use]
    pub fn with_quantity(mut self, quantity: NodalQuantity) -> Self {
        self.quantity = quantity;
        self
    }

    /// The model as given (with held quantities at their held values).
    pub fn base(&self) -> &ShellModel {
        &self.base
    }

    /// The model with the parameters set to `point`.
    ///
    /// # Errors
    /// A core dimension or finiteness error for a bad point.
    pub fn model_at(&self, point: &[f64]) -> Result<ShellModel> {
        self.space.to_unit(point)?;
        if let Some(deck) = &self.deck {
            let mut values: Vec<(&str, f64)> = self
                .space
                .names()
                .into_iter()
                .zip(point.iter().copied())
                .collect();
            values.extend(self.held.iter().map(|(n, v)| (n.as_str(), *v)));
            return Ok(deck.with_parameters(&values)?.model);
        }
        let mut m = self.base.clone();
        for (&t, &v) in self.targets.iter().zip(point) {
            t.set(&mut m, v);
        }
        Ok(m)
    }

    /// The quantity named `name` (deck parameters without regard to case).
    fn quantity_named(&self, name: &str) -> Option<&DeckQuantity> {
        self.quantities.iter().find(|q| match q.target {
            Target::DeckParameter => q.parameter.name.eq_ignore_ascii_case(name),
            _ => q.parameter.name == name,
        })
    }

    /// The real parameters of a parameterised deck at their held values, declared or not.
    fn held_parameters(&self) -> impl Iterator<Item = (String, f64)> + '_ {
        self.quantities
            .iter()
            .filter(|q| q.target == Target::DeckParameter)
            .map(|q| {
                let n = &q.parameter.name;
                let v = self
                    .held
                    .iter()
                    .find(|(h, _)| h.eq_ignore_ascii_case(n))
                    .map_or(q.parameter.nominal, |h| h.1);
                (n.clone(), v)
            })
    }

    /// Whether the quantity named `name` is declared.
    fn declared(&self, name: &str) -> bool {
        self.space
            .names()
            .iter()
            .any(|n| n.eq_ignore_ascii_case(name))
    }

    /// The value the model holds `q` at.
    fn held_value(&self, q: &DeckQuantity) -> f64 {
        q.target.get(&self.base).unwrap_or_else(|| {
            self.held
                .iter()
                .find(|(n, _)| n.eq_ignore_ascii_case(&q.parameter.name))
                .map_or(q.parameter.nominal, |h| h.1)
        })
    }
}

fn check_outputs(model: &ShellModel) -> Result<()> {
    if model.output.history_nodes.is_empty() {
        return Err(ShellError::value(
            "model",
            "has no history nodes (*DATABASE_HISTORY_NODE): nothing to output",
        ));
    }
    Ok(())
}

impl Model for DeckModel {
    fn space(&self) -> &ParameterSpace {
        &self.space
    }

    fn simulate(&self, params: &[f64]) -> impactcal_core::Result<Histories> {
        let model = self.model_at(params).map_err(CoreError::simulation)?;
        let r = Simulation::new(&model)
            .and_then(|mut s| s.run())
            .map_err(CoreError::simulation)?;
        r.histories(self.quantity)
            .cloned()
            .ok_or_else(|| CoreError::Invalid("the run produced no nodal histories".into()))
    }
}

impl Enrichable for DeckModel {
    /// The quantities not declared, in the order of the module docs, at their held values
    /// with their admissible ranges (widened to include the held value).
    fn candidates(&self) -> Vec<Candidate> {
        self.quantities
            .iter()
            .filter(|q| !self.declared(&q.parameter.name))
            .filter_map(|q| {
                let v = self.held_value(q);
                let a = &q.parameter;
                let p = Parameter::new(a.name.clone(), a.lower.min(v), a.upper.max(v), v)
                    .ok()?
                    .with_unit(a.unit.clone());
                Some(Candidate::new(p, q.group, q.description.clone()))
            })
            .collect()
    }

    /// The group and description of a quantity of the model.
    fn describe(&self, name: &str) -> Option<(String, String)> {
        self.quantity_named(name)
            .map(|q| (q.group.to_string(), q.description.clone()))
    }

    /// The same model with `added` declared after the space; at their held values the runs
    /// are the same runs, bit for bit.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for a name that is not a candidate, a name given twice,
    /// or bounds outside the admissible range; [`CoreError::Parameter`] for invalid bounds.
    fn enrich(&self, added: &[Parameter]) -> impactcal_core::Result<Self> {
        let candidates = self.candidates();
        let mut params = self.space.parameters().to_vec();
        for p in added {
            p.validate()?;
            self.check_candidate(p)?;
            if params.iter().any(|q| q.name.eq_ignore_ascii_case(&p.name)) {
                return Err(CoreError::invalid_option("enrich", &p.name, "added twice"));
            }
            if let Some(c) = candidates.iter().find(|c| c.name() == p.name) {
                c.check_bounds(p)?;
            }
            params.push(p.clone());
        }
        let mut m = self.clone();
        for p in added {
            if let Some(q) = self.quantity_named(&p.name) {
                m.targets.push(q.target);
            }
            m.held.retain(|(n, _)| !n.eq_ignore_ascii_case(&p.name));
        }
        m.space = ParameterSpace::new(params)?;
        Ok(m)
    }

    /// The same model with held quantities set to other values (an initial velocity for a
    /// holdout test at another impact speed, a wall's friction, ...); the space is unchanged.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for a declared parameter, a name the model does not
    /// hold, or a value outside the quantity's admissible range.
    fn at_condition(&self, set: &[(String, f64)]) -> impactcal_core::Result<Self> {
        let candidates = self.candidates();
        let mut m = self.clone();
        for (name, value) in set {
            if self.declared(name) {
                return Err(CoreError::invalid_option(
                    "condition",
                    name,
                    "a declared parameter of the model (a point sets it), not a held quantity",
                ));
            }
            let (Some(c), Some(q)) = (
                candidates.iter().find(|c| c.name() == name),
                self.quantity_named(name),
            ) else {
                return Err(CoreError::invalid_option(
                    "condition",
                    name,
                    "not a quantity the model holds",
                ));
            };
            c.check_value(*value)?;
            q.target.set(&mut m.base, *value);
            if let Some(h) = m
                .held
                .iter_mut()
                .find(|(n, _)| n.eq_ignore_ascii_case(name))
            {
                h.1 = *value;
            }
        }
        Ok(m)
    }
}
