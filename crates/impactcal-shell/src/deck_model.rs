//! A [`ShellModel`] (for example a keyword deck) as an [`impactcal_core::Model`]: its
//! section thicknesses, material constants and concentrated masses become named
//! parameters, and a run returns the nodal histories of its history nodes.
//!
//! The parameters, in this order:
//! - `section.<id>.t`: the thickness of every section;
//! - `material.<id>.E`: Young's modulus of every material;
//! - `material.<id>.sigy`, `material.<id>.Et`: yield stress and tangent modulus of every
//!   elastic-plastic material (`Et` only where it is not zero);
//! - `mass.<id>`: every non-zero concentrated mass (`*ELEMENT_MASS`).
//!
//! Each has the bounds +-20 % about its value in the model.
//!
//! A deck with `*PARAMETER` cards speaks for itself instead ([`DeckModel::from_deck`]): its
//! real (`R`) parameters are the quantities, under the deck's own names, with the bounds
//! +-20 % about the deck's values unless the caller gives bounds; a run reads the deck
//! again with the point's values in its parameters. These are the quantities a crash
//! analyst would call "the model" as opposed to the test conditions (impact velocity,
//! attitude, ground, controls), and the ones a jitter ensemble perturbs
//! ([`impactcal_core::noise`]).
//!
//! ```
//! use impactcal_core::Model;
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
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use impactcal_core::{CoreError, Histories, Model, Parameter, ParameterSpace};

use crate::error::{Result, ShellError};
use crate::keyword::Deck;
use crate::model::{MaterialLaw, ShellModel};
use crate::simulation::{Quantity, Simulation};

/// Where a parameter of a [`DeckModel`] goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Target {
    Thickness(usize),
    Youngs(usize),
    Yield(usize),
    Tangent(usize),
    Mass(usize),
}

/// A shell model whose thicknesses, material constants and concentrated masses are the
/// parameters of an [`impactcal_core::Model`] (see the module docs).
#[derive(Debug, Clone)]
pub struct DeckModel {
    base: ShellModel,
    space: ParameterSpace,
    targets: Vec<Target>,
    quantity: Quantity,
    /// A parameterised deck: its parameters are the quantities, in the order of `space`.
    deck: Option<Deck>,
}

impl DeckModel {
    /// The model with every thickness, modulus, yield stress, tangent modulus and
    /// concentrated mass as a parameter; the output is the velocity of the history nodes.
    ///
    /// # Errors
    /// [`ShellError::Value`] when the model has no history nodes (nothing to output) or a
    /// value cannot bound a parameter (not finite and positive).
    pub fn new(model: ShellModel) -> Result<Self> {
        if model.output.history_nodes.is_empty() {
            return Err(ShellError::value(
                "model",
                "has no history nodes (*DATABASE_HISTORY_NODE): nothing to output",
            ));
        }
        let mut params = Vec::new();
        let mut targets = Vec::new();
        let mut add = |name: String, v: f64, unit: &str, t: Target| -> Result<()> {
            let p = Parameter::new(name, 0.8 * v, 1.2 * v, v)?.with_unit(unit);
            params.push(p);
            targets.push(t);
            Ok(())
        };
        for (k, s) in model.sections.iter().enumerate() {
            add(
                format!("section.{}.t", s.id),
                s.thickness,
                "length",
                Target::Thickness(k),
            )?;
        }
        for (k, m) in model.materials.iter().enumerate() {
            add(
                format!("material.{}.E", m.id),
                m.youngs,
                "stress",
                Target::Youngs(k),
            )?;
            if let MaterialLaw::Plastic {
                yield_stress,
                tangent_modulus,
                ..
            } = m.law
            {
                add(
                    format!("material.{}.sigy", m.id),
                    yield_stress,
                    "stress",
                    Target::Yield(k),
                )?;
                if tangent_modulus > 0.0 {
                    add(
                        format!("material.{}.Et", m.id),
                        tangent_modulus,
                        "stress",
                        Target::Tangent(k),
                    )?;
                }
            }
        }
        for (k, m) in model.masses.iter().enumerate() {
            if m.mass > 0.0 {
                add(format!("mass.{}", m.id), m.mass, "mass", Target::Mass(k))?;
            }
        }
        Ok(DeckModel {
            space: ParameterSpace::new(params)?,
            base: model,
            targets,
            quantity: Quantity::Velocity,
            deck: None,
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
    /// [`ShellError::Value`] when the model has no history nodes, a bound names a parameter
    /// the deck does not define (or the deck defines none), or a deck value of 0 would be
    /// bounded without bounds given.
    pub fn from_deck(deck: Deck, bounds: Option<&ParameterSpace>) -> Result<Self> {
        let reals: Vec<_> = deck.parameters.iter().filter(|p| !p.integer).collect();
        if reals.is_empty() {
            if bounds.is_some() {
                return Err(ShellError::value(
                    "deck",
                    "defines no real *PARAMETER to take the given bounds",
                ));
            }
            return DeckModel::new(deck.model);
        }
        if deck.model.output.history_nodes.is_empty() {
            return Err(ShellError::value(
                "model",
                "has no history nodes (*DATABASE_HISTORY_NODE): nothing to output",
            ));
        }
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
                    let (lo, hi) = ((0.8 * v).min(1.2 * v), (0.8 * v).max(1.2 * v));
                    params.push(Parameter::new(p.name.clone(), lo, hi, v)?);
                }
                ParameterSpace::new(params)?
            }
        };
        let base = deck.model.clone();
        Ok(DeckModel {
            space,
            base,
            targets: Vec::new(),
            quantity: Quantity::Velocity,
            deck: Some(deck),
        })
    }

    /// The same model returning another nodal quantity.
    #[must_use]
    pub fn with_quantity(mut self, quantity: Quantity) -> Self {
        self.quantity = quantity;
        self
    }

    /// The model as given.
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
            let values: Vec<(&str, f64)> = self
                .space
                .names()
                .into_iter()
                .zip(point.iter().copied())
                .collect();
            return Ok(deck.with_parameters(&values)?.model);
        }
        let mut m = self.base.clone();
        for (&t, &v) in self.targets.iter().zip(point) {
            match t {
                Target::Thickness(k) => m.sections[k].thickness = v,
                Target::Youngs(k) => m.materials[k].youngs = v,
                Target::Yield(k) | Target::Tangent(k) => {
                    if let MaterialLaw::Plastic {
                        yield_stress,
                        tangent_modulus,
                        ..
                    } = &mut m.materials[k].law
                    {
                        if matches!(t, Target::Yield(_)) {
                            *yield_stress = v;
                        } else {
                            *tangent_modulus = v;
                        }
                    }
                }
                Target::Mass(k) => m.masses[k].mass = v,
            }
        }
        Ok(m)
    }
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
