//! Models that can grow: the quantities a model holds fixed today and could free, so that a
//! calibration that leaves a residual can look for the effect the model lacks.
//!
//! A [`Model`] declares a [`ParameterSpace`]; everything else it needs (a damping
//! coefficient, a friction coefficient, a concentrated mass, the impact velocity) it holds at
//! one value. An [`Enrichable`] model lists those held quantities as [`Candidate`]s, builds
//! itself with some of them freed ([`Enrichable::enrich`]), and builds itself at another test
//! condition ([`Enrichable::at_condition`], for a holdout test).
//!
//! ```
//! use impactcal_core::enrich::{Candidate, Enrichable};
//! use impactcal_core::{CoreError, Histories, Model, Parameter, ParameterSpace, Result};
//!
//! /// A mass on a spring released at speed `v0`: x(t) = v0/w sin(w t) e^{-c t}; `w` is
//! /// declared, the damping `c` and the speed `v0` are held.
//! struct Oscillator {
//!     space: ParameterSpace,
//!     c: f64,
//!     v0: f64,
//! }
//!
//! impl Model for Oscillator {
//!     fn space(&self) -> &ParameterSpace {
//!         &self.space
//!     }
//!     fn simulate(&self, p: &[f64]) -> Result<Histories> {
//!         let w = p[0];
//!         let c = self.space.index_of("c").map_or(self.c, |i| p[i]);
//!         let x: Vec<f64> = (0..100)
//!             .map(|k| {
//!                 let t = k as f64 * 0.01;
//!                 self.v0 / w * (w * t).sin() * (-c * t).exp()
//!             })
//!             .collect();
//!         Histories::new(vec!["x".into()], 100, 0.01, 0.0, "m", x)
//!     }
//! }
//!
//! impl Enrichable for Oscillator {
//!     fn candidates(&self) -> Vec<Candidate> {
//!         let mut c = vec![];
//!         if self.space.index_of("c").is_none() {
//!             let p = Parameter::new("c", 0.0, 5.0, self.c).expect("valid");
//!             c.push(Candidate::new(p, "damping", "viscous damping rate (1/s)"));
//!         }
//!         c
//!     }
//!     fn enrich(&self, added: &[Parameter]) -> Result<Self> {
//!         let mut params = self.space.parameters().to_vec();
//!         for p in added {
//!             self.check_candidate(p)?;
//!             params.push(p.clone());
//!         }
//!         Ok(Oscillator { space: ParameterSpace::new(params)?, ..*self })
//!     }
//!     fn at_condition(&self, set: &[(String, f64)]) -> Result<Self> {
//!         let mut v0 = self.v0;
//!         for (name, value) in set {
//!             match name.as_str() {
//!                 "v0" => v0 = *value,
//!                 _ => {
//!                     return Err(CoreError::invalid_option("condition", name, "not held"))
//!                 }
//!             }
//!         }
//!         Ok(Oscillator { space: self.space.clone(), v0, ..*self })
//!     }
//! }
//!
//! let model = Oscillator {
//!     space: ParameterSpace::new(vec![Parameter::new("w", 5.0, 15.0, 10.0)?])?,
//!     c: 0.0,
//!     v0: 1.0,
//! };
//! let c = &model.candidates()[0];
//! let enriched = model.enrich(&[c.parameter.clone()])?;
//! assert_eq!(enriched.space().names(), ["w", "c"]);
//! // Freed at its held value, the candidate changes nothing.
//! let before = model.simulate(&[10.0])?;
//! let after = enriched.simulate(&[10.0, 0.0])?;
//! assert_eq!(before.data(), after.data());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use serde::{Deserialize, Serialize};

use crate::error::{CoreError, Result};
use crate::model::Model;
use crate::space::{Parameter, ParameterSpace};

/// A quantity a model holds fixed and could free: an effect it does not declare.
///
/// `parameter.nominal` is the value the model holds it at today (freeing it there changes no
/// run); `parameter.lower..=upper` is the range of physically admissible values (a damping
/// coefficient or a friction coefficient is never negative), which a fitted amplitude must
/// respect to be attributed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Candidate {
    /// The parameter it would add: name, admissible range, held value as nominal, unit.
    pub parameter: Parameter,
    /// Its kind, for grouping in reports: `damping`, `friction`, `material`, `thickness`,
    /// `mass`, `condition`, ...
    pub group: String,
    /// What it is, in a few words.
    pub description: String,
}

impl Candidate {
    /// A candidate from its parameter, group and description.
    pub fn new(
        parameter: Parameter,
        group: impl Into<String>,
        description: impl Into<String>,
    ) -> Self {
        Self {
            parameter,
            group: group.into(),
            description: description.into(),
        }
    }

    /// The candidate's name (its parameter's).
    pub fn name(&self) -> &str {
        &self.parameter.name
    }

    /// Checks that the bounds of `p` (a caller's parameter for this candidate) lie within
    /// the admissible range (a helper for [`Enrichable::enrich`]).
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] naming the candidate and both ranges.
    pub fn check_bounds(&self, p: &Parameter) -> Result<()> {
        let a = &self.parameter;
        if p.lower < a.lower || p.upper > a.upper {
            return Err(CoreError::invalid_option(
                "enrich",
                &p.name,
                format!(
                    "bounds [{}, {}] leave the admissible range [{}, {}]",
                    p.lower, p.upper, a.lower, a.upper
                ),
            ));
        }
        Ok(())
    }

    /// Checks that `value` is finite and admissible (a helper for
    /// [`Enrichable::at_condition`]).
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] naming the candidate, the value and the range.
    pub fn check_value(&self, value: f64) -> Result<()> {
        let a = &self.parameter;
        if !(value.is_finite() && (a.lower..=a.upper).contains(&value)) {
            return Err(CoreError::invalid_option(
                "condition",
                format!("{} = {value}", a.name),
                format!("outside the admissible range [{}, {}]", a.lower, a.upper),
            ));
        }
        Ok(())
    }
}

/// A [`Model`] that lists the quantities it holds fixed and can free them.
///
/// Contract, which the closed loop relies on:
/// - [`candidates`](Enrichable::candidates) lists only quantities not in `space()`, with
///   distinct names; each candidate's nominal is the value the model holds it at.
/// - `enrich(added)` returns the model whose space is `space()` followed by `added` in that
///   order; a point of it is a point of `self` followed by the added values, and at the
///   added parameters' held values it gives the same histories as `self` (bit for bit where
///   the model is deterministic). Each added parameter names a candidate; its bounds and
///   nominal are the caller's (they may narrow the admissible range).
/// - `at_condition(set)` returns the model with held quantities set to other values (a
///   test at another impact velocity or attitude) and the same space.
pub trait Enrichable: Model + Sized {
    /// The held quantities that could be freed, in a fixed order.
    fn candidates(&self) -> Vec<Candidate>;

    /// The model with `added` appended to its space.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] when an added name is not a candidate or is repeated;
    /// [`CoreError::Parameter`] for invalid bounds.
    fn enrich(&self, added: &[Parameter]) -> Result<Self>;

    /// The model at another test condition: each `(name, value)` sets a held quantity.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] when a name is not a held quantity of the model (or is a
    /// declared parameter, which a point sets instead) or the value is not admissible.
    fn at_condition(&self, set: &[(String, f64)]) -> Result<Self>;

    /// The group and description of one of the model's declared parameters, where the model
    /// knows them, so that a wrapper holding some of them (a subspace of the model) can list
    /// them as candidates of the right kind. `None` unless a model says more.
    fn describe(&self, name: &str) -> Option<(String, String)> {
        let _ = name;
        None
    }

    /// Checks that `p` names one of [`candidates`](Enrichable::candidates) (a helper for
    /// implementations of [`enrich`](Enrichable::enrich)).
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] naming the parameter when it is not a candidate.
    fn check_candidate(&self, p: &Parameter) -> Result<()> {
        if self.candidates().iter().any(|c| c.name() == p.name) {
            Ok(())
        } else if self.space().index_of(&p.name).is_some() {
            Err(CoreError::invalid_option(
                "enrich",
                &p.name,
                "already a parameter of the model",
            ))
        } else {
            Err(CoreError::invalid_option(
                "enrich",
                &p.name,
                "not a candidate of the model (held quantities only)",
            ))
        }
    }
}

/// The space of `model` with `added` appended in order (a helper for implementations of
/// [`Enrichable::enrich`]): each added parameter must be one of the model's candidates
/// ([`Enrichable::check_candidate`]), with bounds inside the candidate's admissible range
/// ([`Candidate::check_bounds`]), and none may be added twice.
///
/// # Errors
/// [`CoreError::InvalidOption`] naming the parameter for any of the three; the space's
/// errors (a duplicate name, bounds not holding the nominal).
pub fn enriched_space<M: Enrichable>(model: &M, added: &[Parameter]) -> Result<ParameterSpace> {
    let candidates = model.candidates();
    let mut params = model.space().parameters().to_vec();
    for (k, p) in added.iter().enumerate() {
        model.check_candidate(p)?;
        if added[..k].iter().any(|q| q.name == p.name) {
            return Err(CoreError::invalid_option("enrich", &p.name, "added twice"));
        }
        if let Some(c) = candidates.iter().find(|c| c.name() == p.name) {
            c.check_bounds(p)?;
        }
        params.push(p.clone());
    }
    ParameterSpace::new(params)
}

/// The model a run names: `model` with the parameters `names` (its own, in order, then
/// candidates freed, in the order they were added) and held quantities set to `set` (a test
/// condition), i.e. `model.enrich(named candidates).at_condition(set)`, each candidate with
/// the parameter [`Enrichable::candidates`] lists for it. This is how the closed loop builds
/// the model of each of its runs, so a worker process that reads a run's names from a file
/// rebuilds exactly the model the loop ran.
///
/// # Errors
/// [`CoreError::InvalidOption`] when `names` does not start with the model's parameters in
/// their order, or names a quantity that is not one of its candidates (naming it and
/// listing the candidates); the model's errors from `enrich` and `at_condition` (a repeated
/// name, a condition the model cannot take).
pub fn rebuild<M: Enrichable>(model: &M, names: &[String], set: &[(String, f64)]) -> Result<M> {
    let own = model.space().names();
    let d = own.len();
    if names.len() < d || names[..d].iter().zip(&own).any(|(a, b)| a != b) {
        return Err(CoreError::invalid_option(
            "parameters",
            names.join(", "),
            format!(
                "must start with the model's own parameters, in order: {}",
                own.join(", ")
            ),
        ));
    }
    let candidates = model.candidates();
    let added = names[d..]
        .iter()
        .map(|n| {
            candidates
                .iter()
                .find(|c| c.name() == n)
                .map(|c| c.parameter.clone())
                .ok_or_else(|| {
                    CoreError::invalid_option(
                        "parameters",
                        n,
                        format!(
                            "neither a parameter nor a candidate of the model (candidates: {})",
                            candidates
                                .iter()
                                .map(Candidate::name)
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    )
                })
        })
        .collect::<Result<Vec<_>>>()?;
    let enriched = model.enrich(&added)?;
    if set.is_empty() {
        Ok(enriched)
    } else {
        enriched.at_condition(set)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_and_values_outside_the_admissible_range_are_refused() {
        let c = Candidate::new(
            Parameter::new("damping", 0.0, 50.0, 0.0).unwrap(),
            "damping",
            "mass-proportional damping",
        );
        let p = |l: f64, u: f64| Parameter::new("damping", l, u, l.max(0.0)).unwrap();
        assert!(c.check_bounds(&p(0.0, 50.0)).is_ok());
        assert!(c.check_bounds(&p(5.0, 10.0)).is_ok());
        let e = c.check_bounds(&p(-1.0, 10.0)).unwrap_err().to_string();
        assert!(e.contains("[-1, 10]") && e.contains("[0, 50]"), "{e}");
        assert!(c.check_bounds(&p(0.0, 60.0)).is_err());
        assert!(c.check_value(0.0).is_ok() && c.check_value(50.0).is_ok());
        for v in [-0.1, 50.1, f64::NAN, f64::INFINITY] {
            let e = c.check_value(v).unwrap_err();
            assert!(matches!(e, CoreError::InvalidOption { .. }), "{e}");
        }
    }

    #[test]
    fn rebuild_is_enrich_then_at_condition_and_refuses_unknown_names() {
        use crate::drop_tower::DropTower;
        let m = DropTower::new();
        let names = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let damping = m
            .candidates()
            .into_iter()
            .find(|c| c.name() == "damping")
            .unwrap()
            .parameter;
        let set = [("v0".to_string(), 5.0)];
        let direct = m.enrich(&[damping]).unwrap().at_condition(&set).unwrap();
        let rebuilt = rebuild(&m, &names(&["modulus", "k_contact", "damping"]), &set).unwrap();
        assert_eq!(rebuilt.space(), direct.space());
        let p = [75.0, 9e5, 0.02];
        assert_eq!(
            rebuilt.simulate(&p).unwrap().data(),
            direct.simulate(&p).unwrap().data()
        );
        // Without added names and condition: the model itself.
        let same = rebuild(&m, &names(&["modulus", "k_contact"]), &[]).unwrap();
        assert_eq!(same.space(), m.space());
        for bad in [
            names(&["modulus", "k_contact", "dampnig"]),
            names(&["k_contact", "modulus"]),
            names(&["modulus"]),
        ] {
            let e = rebuild(&m, &bad, &[]).unwrap_err();
            assert!(matches!(e, CoreError::InvalidOption { .. }), "{e}");
        }
        let e = rebuild(&m, &names(&["modulus", "k_contact", "dampnig"]), &[]).unwrap_err();
        assert!(e.to_string().contains("dampnig"), "{e}");
        assert!(rebuild(&m, &names(&["modulus", "k_contact"]), &[("v9".into(), 1.0)]).is_err());
    }
}
