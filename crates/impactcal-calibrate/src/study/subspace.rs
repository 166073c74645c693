//! A model restricted to some of its parameters: the study's parameters vary, the others
//! keep base values.
//!
//! A subspace of an [`Enrichable`] model is itself enrichable: its candidates are the
//! model's parameters it does not select (held at the subspace's base values, within the
//! model's bounds) followed by the model's own candidates. [`Plain`] makes any model
//! enrichable with no candidates of its own, so that a subspace of it lists just the
//! parameters it holds.

use impactcal_core::enrich::{Candidate, Enrichable};
use impactcal_core::{CoreError, Histories, Model, Parameter, ParameterSpace};

use crate::error::{CalibrateError, Result};

/// `model` seen through `space`, whose parameters are a subset of the model's (by name):
/// a point of `space` is placed into the model's base point (its nominal values unless
/// [`with_base`](Self::with_base) says otherwise) and run.
#[derive(Debug, Clone)]
pub struct Subspace<M> {
    model: M,
    space: ParameterSpace,
    slots: Vec<usize>,
    base: Vec<f64>,
}

impl<M: Model> Subspace<M> {
    /// Restricts `model` to `space`.
    ///
    /// # Errors
    /// [`CalibrateError::Study`] for a name the model does not have (naming the closest
    /// names it has) or bounds outside the model's own bounds for that parameter.
    pub fn new(model: M, space: ParameterSpace) -> Result<Self> {
        let names: Vec<String> = space.names().iter().map(|s| s.to_string()).collect();
        Self::aliased(model, space, &names)
    }

    /// Restricts `model` to `space`, parameter `i` of which is the model's quantity
    /// `fields[i]` under another name.
    ///
    /// # Errors
    /// As [`new`](Self::new), naming the field; [`CalibrateError::Study`] when `fields` does
    /// not have one entry per parameter.
    pub fn aliased(model: M, space: ParameterSpace, fields: &[String]) -> Result<Self> {
        if fields.len() != space.dim() {
            return Err(CalibrateError::study(
                "parameter fields",
                format!("{} fields for {} parameters", fields.len(), space.dim()),
            ));
        }
        let full = model.space();
        let mut slots = Vec::with_capacity(space.dim());
        for (p, field) in space.parameters().iter().zip(fields) {
            let Some(i) = full.index_of(field) else {
                return Err(CalibrateError::study(
                    format!("parameter `{field}`"),
                    format!(
                        "the model has no such quantity; closest: {}",
                        near(field, &full.names())
                    ),
                ));
            };
            let q = &full.parameters()[i];
            if !within(p, q) {
                return Err(CalibrateError::study(
                    format!("parameter `{}`", p.name),
                    format!(
                        "bounds [{}, {}] lie outside what the model accepts, [{}, {}]",
                        p.lower, p.upper, q.lower, q.upper
                    ),
                ));
            }
            slots.push(i);
        }
        let base = full.nominal();
        Ok(Subspace {
            model,
            space,
            slots,
            base,
        })
    }

    /// The same with the values of the parameters that do not vary taken from `base` (a
    /// point of the model's own space).
    ///
    /// # Errors
    /// [`CalibrateError::Study`] when `base` is not as long as the model's space.
    pub fn with_base(mut self, base: Vec<f64>) -> Result<Self> {
        if base.len() != self.base.len() {
            return Err(CalibrateError::study(
                "base point",
                format!(
                    "has {} values, the model {} parameters",
                    base.len(),
                    self.base.len()
                ),
            ));
        }
        self.base = base;
        Ok(self)
    }

    /// The wrapped model.
    pub fn inner(&self) -> &M {
        &self.model
    }

    /// The model's full point for a point of the subspace. A value beyond the model's own
    /// bounds by round-off (bounds accepted by [`within`]) is moved onto them.
    pub fn full_point(&self, point: &[f64]) -> Vec<f64> {
        let mut x = self.base.clone();
        let full = self.model.space().parameters();
        for (&i, &v) in self.slots.iter().zip(point) {
            x[i] = full.get(i).map_or(v, |q| v.clamp(q.lower, q.upper));
        }
        x
    }
}

/// Whether the bounds of `p` lie inside those of `q` up to round-off: a few units in the
/// last place of the larger bound's magnitude, so that `-20 %` of a deck value of 0.1
/// (`0.8 * 0.1 = 0.08000000000000002` in the model's range) accepts the user's `0.08`.
pub fn within(p: &Parameter, q: &Parameter) -> bool {
    let scale = q.lower.abs().max(q.upper.abs());
    let tol = 8.0 * f64::EPSILON * scale;
    p.lower >= q.lower - tol && p.upper <= q.upper + tol
}

/// Up to three names of `names` closest to `name` (Jaro-Winkler similarity).
pub fn near(name: &str, names: &[&str]) -> String {
    let mut scored: Vec<(f64, &str)> = names
        .iter()
        .map(|n| (strsim::jaro_winkler(name, n), *n))
        .collect();
    scored.sort_by(|a, b| b.0.total_cmp(&a.0));
    scored
        .iter()
        .take(3)
        .map(|(_, n)| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

impl<M: Model> Model for Subspace<M> {
    fn space(&self) -> &ParameterSpace {
        &self.space
    }

    fn simulate(&self, params: &[f64]) -> impactcal_core::Result<Histories> {
        self.space.to_unit(params)?;
        self.model.simulate(&self.full_point(params))
    }
}

impl<M: Enrichable + Clone> Subspace<M> {
    /// The candidates that are the model's parameters this subspace does not select, each
    /// at its base value with the model's bounds (widened to include the base value), with
    /// the group and description the model gives ([`Enrichable::describe`], else
    /// `parameter`), paired with the parameter's index in the model's space.
    fn held_parameters(&self) -> Vec<(usize, Candidate)> {
        let full = self.model.space();
        full.parameters()
            .iter()
            .enumerate()
            .filter(|(i, q)| !self.slots.contains(i) && self.space.index_of(&q.name).is_none())
            .filter_map(|(i, q)| {
                let v = self.base[i];
                let p = Parameter::new(q.name.clone(), q.lower.min(v), q.upper.max(v), v)
                    .ok()?
                    .with_unit(q.unit.clone());
                let (group, description) = self.model.describe(&q.name).unwrap_or_else(|| {
                    (
                        "parameter".into(),
                        "a parameter the study holds fixed".into(),
                    )
                });
                Some((i, Candidate::new(p, group, description)))
            })
            .collect()
    }

    /// The model's own candidates whose names the subspace does not use.
    fn inner_candidates(&self) -> Vec<Candidate> {
        self.model
            .candidates()
            .into_iter()
            .filter(|c| self.space.index_of(c.name()).is_none())
            .collect()
    }
}

impl<M: Enrichable + Clone> Enrichable for Subspace<M> {
    /// The model's parameters not selected (in the model's order), then the model's own
    /// candidates (in its order).
    fn candidates(&self) -> Vec<Candidate> {
        let mut c: Vec<Candidate> = self.held_parameters().into_iter().map(|(_, c)| c).collect();
        c.extend(self.inner_candidates());
        c
    }

    fn describe(&self, name: &str) -> Option<(String, String)> {
        let i = self.space.index_of(name)?;
        let field = &self.model.space().parameters()[*self.slots.get(i)?].name;
        self.model.describe(field)
    }

    /// The subspace with `added` appended: a held parameter of the model becomes a slot of
    /// the same model; a candidate of the model is added to the model
    /// ([`Enrichable::enrich`] on it) and becomes a slot of the enriched model. At the held
    /// values the runs are the model's runs at the same full point, so they are unchanged.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for a name that is not a candidate, a name given twice,
    /// or bounds outside the candidate's admissible range; [`CoreError::Parameter`] for
    /// invalid bounds; the model's errors from its own `enrich`.
    fn enrich(&self, added: &[Parameter]) -> impactcal_core::Result<Self> {
        let held = self.held_parameters();
        let inner = self.inner_candidates();
        let mut params = self.space.parameters().to_vec();
        let mut slots = self.slots.clone();
        let mut inner_added: Vec<Parameter> = Vec::new();
        let mut inner_held: Vec<f64> = Vec::new();
        let dim = self.model.space().dim();
        for p in added {
            p.validate()?;
            self.check_candidate(p)?;
            if params.iter().any(|q| q.name == p.name) {
                return Err(CoreError::invalid_option("enrich", &p.name, "added twice"));
            }
            let (candidate, slot) =
                if let Some((i, c)) = held.iter().find(|(_, c)| c.name() == p.name) {
                    (c, *i)
                } else if let Some(c) = inner.iter().find(|c| c.name() == p.name) {
                    inner_added.push(p.clone());
                    inner_held.push(c.parameter.nominal);
                    (c, dim + inner_added.len() - 1)
                } else {
                    return Err(CoreError::invalid_option(
                        "enrich",
                        &p.name,
                        "not a candidate of the model",
                    ));
                };
            candidate.check_bounds(p)?;
            params.push(p.clone());
            slots.push(slot);
        }
        let model = if inner_added.is_empty() {
            self.model.clone()
        } else {
            self.model.enrich(&inner_added)?
        };
        let mut base = self.base.clone();
        base.extend(inner_held);
        Ok(Subspace {
            model,
            space: ParameterSpace::new(params)?,
            slots,
            base,
        })
    }

    /// The subspace at another condition: a held parameter of the model takes the value in
    /// the base point (within its admissible range); any other name goes to the model's own
    /// [`Enrichable::at_condition`].
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for a parameter of the subspace (a point sets it), a
    /// value outside a held parameter's admissible range, and the model's errors for the
    /// names it is given.
    fn at_condition(&self, set: &[(String, f64)]) -> impactcal_core::Result<Self> {
        let held = self.held_parameters();
        let mut base = self.base.clone();
        let mut rest = Vec::new();
        for (name, value) in set {
            if self.space.index_of(name).is_some()
                || self
                    .slots
                    .iter()
                    .any(|&i| self.model.space().parameters()[i].name == *name)
            {
                return Err(CoreError::invalid_option(
                    "condition",
                    name,
                    "a declared parameter of the model (a point sets it), not a held quantity",
                ));
            }
            match held.iter().find(|(_, c)| c.name() == name) {
                Some((i, c)) => {
                    c.check_value(*value)?;
                    base[*i] = *value;
                }
                None => rest.push((name.clone(), *value)),
            }
        }
        let model = if rest.is_empty() {
            self.model.clone()
        } else {
            self.model.at_condition(&rest)?
        };
        Ok(Subspace {
            model,
            space: self.space.clone(),
            slots: self.slots.clone(),
            base,
        })
    }
}

/// Any [`Model`] as an [`Enrichable`] one that holds nothing of its own: no candidates, no
/// conditions. A [`Subspace`] of it lists the parameters it holds as its candidates.
#[derive(Debug, Clone)]
pub struct Plain<M>(pub M);

impl<M: Model> Model for Plain<M> {
    fn space(&self) -> &ParameterSpace {
        self.0.space()
    }

    fn simulate(&self, params: &[f64]) -> impactcal_core::Result<Histories> {
        self.0.simulate(params)
    }
}

impl<M: Model + Clone> Enrichable for Plain<M> {
    /// None.
    fn candidates(&self) -> Vec<Candidate> {
        Vec::new()
    }

    /// The same model when `added` is empty.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for any added parameter (there are no candidates).
    fn enrich(&self, added: &[Parameter]) -> impactcal_core::Result<Self> {
        for p in added {
            self.check_candidate(p)?;
        }
        Ok(self.clone())
    }

    /// The same model when `set` is empty.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for any name (the model holds nothing it can set).
    fn at_condition(&self, set: &[(String, f64)]) -> impactcal_core::Result<Self> {
        match set.first() {
            Some((name, _)) => Err(CoreError::invalid_option(
                "condition",
                name,
                "the model holds no quantity it can set",
            )),
            None => Ok(self.clone()),
        }
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;
    use impactcal_core::Parameter;

    #[derive(Debug, Clone)]
    struct Sum(ParameterSpace);
    impl Model for Sum {
        fn space(&self) -> &ParameterSpace {
            &self.0
        }
        fn simulate(&self, p: &[f64]) -> impactcal_core::Result<Histories> {
            Histories::from_channels(vec!["s".into()], vec![p.to_vec()], 1.0, 0.0, "")
        }
    }

    #[test]
    fn points_go_to_their_slots_and_bad_names_or_bounds_are_refused() {
        let full = ParameterSpace::new(vec![
            Parameter::new("belly_panel.t", 0.05, 0.15, 0.1).unwrap(),
            Parameter::new("roof.t", 0.02, 0.04, 0.03).unwrap(),
            Parameter::new("mass.tail", 0.05, 0.1, 0.07).unwrap(),
        ])
        .unwrap();
        let sub = ParameterSpace::new(vec![Parameter::new("mass.tail", 0.06, 0.08, 0.07).unwrap()])
            .unwrap();
        let m = Subspace::new(Sum(full.clone()), sub).unwrap();
        assert_eq!(
            m.simulate(&[0.075]).unwrap().channel(0),
            &[0.1, 0.03, 0.075]
        );
        let m = m.with_base(vec![0.12, 0.025, 0.0]).unwrap();
        assert_eq!(
            m.simulate(&[0.06]).unwrap().channel(0),
            &[0.12, 0.025, 0.06]
        );
        let typo = ParameterSpace::new(vec![
            Parameter::new("bely_panel.t", 0.05, 0.1, 0.07).unwrap(),
        ])
        .unwrap();
        let e = Subspace::new(Sum(full.clone()), typo)
            .unwrap_err()
            .to_string();
        assert!(e.contains("closest: `belly_panel.t`"), "{e}");
        let wide =
            ParameterSpace::new(vec![Parameter::new("roof.t", 0.01, 0.04, 0.03).unwrap()]).unwrap();
        let e = Subspace::new(Sum(full), wide).unwrap_err().to_string();
        assert!(e.contains("outside what the model accepts"), "{e}");
    }

    /// The parameters as the first channel, and the held damping `c` as a second.
    #[derive(Debug, Clone)]
    struct Damped {
        space: ParameterSpace,
        c: f64,
    }
    impl Model for Damped {
        fn space(&self) -> &ParameterSpace {
            &self.space
        }
        fn simulate(&self, p: &[f64]) -> impactcal_core::Result<Histories> {
            let c = self.space.index_of("c").map_or(self.c, |i| p[i]);
            let mut x: Vec<f64> = p
                .iter()
                .zip(self.space.names())
                .filter(|(_, n)| *n != "c")
                .map(|(v, _)| *v)
                .collect();
            x.push(c);
            Histories::from_channels(vec!["s".into()], vec![x], 1.0, 0.0, "")
        }
    }
    impl Enrichable for Damped {
        fn candidates(&self) -> Vec<Candidate> {
            if self.space.index_of("c").is_some() {
                return vec![];
            }
            let p = Parameter::new("c", 0.0, 5.0, self.c).unwrap();
            vec![Candidate::new(p, "damping", "damping rate")]
        }
        fn describe(&self, name: &str) -> Option<(String, String)> {
            name.ends_with(".t")
                .then(|| ("thickness".into(), format!("{name} thickness")))
        }
        fn enrich(&self, added: &[Parameter]) -> impactcal_core::Result<Self> {
            let mut params = self.space.parameters().to_vec();
            for p in added {
                self.check_candidate(p)?;
                params.push(p.clone());
            }
            Ok(Damped {
                space: ParameterSpace::new(params)?,
                c: self.c,
            })
        }
        fn at_condition(&self, set: &[(String, f64)]) -> impactcal_core::Result<Self> {
            let mut m = self.clone();
            for (n, v) in set {
                if n != "c" || self.space.index_of("c").is_some() {
                    return Err(CoreError::invalid_option("condition", n, "not held"));
                }
                m.c = *v;
            }
            Ok(m)
        }
    }

    fn full() -> ParameterSpace {
        ParameterSpace::new(vec![
            Parameter::new("belly_panel.t", 0.05, 0.15, 0.1).unwrap(),
            Parameter::new("roof.t", 0.02, 0.04, 0.03).unwrap(),
            Parameter::new("mass.tail", 0.05, 0.1, 0.07).unwrap(),
        ])
        .unwrap()
    }

    fn tail_only() -> ParameterSpace {
        ParameterSpace::new(vec![Parameter::new("mass.tail", 0.06, 0.08, 0.07).unwrap()]).unwrap()
    }

    #[test]
    fn the_candidates_are_the_held_parameters_then_the_models_own() {
        // A plain model: just the parameters the subspace holds, at the base values.
        let plain = Subspace::new(Plain(Sum(full())), tail_only())
            .unwrap()
            .with_base(vec![0.16, 0.03, 0.07])
            .unwrap();
        let c = plain.candidates();
        let got: Vec<(&str, f64, f64, f64, &str)> = c
            .iter()
            .map(|c| {
                let p = &c.parameter;
                (c.name(), p.lower, p.nominal, p.upper, c.group.as_str())
            })
            .collect();
        // The base value 0.16 lies above the model's bound: the range widens to it.
        assert_eq!(
            got,
            [
                ("belly_panel.t", 0.05, 0.16, 0.16, "parameter"),
                ("roof.t", 0.02, 0.03, 0.04, "parameter")
            ]
        );
        assert!(plain.enrich(&[]).is_ok());
        // An enrichable model: its groups, then its own candidate.
        let sub = Subspace::new(
            Damped {
                space: full(),
                c: 0.5,
            },
            tail_only(),
        )
        .unwrap();
        let c = sub.candidates();
        let names: Vec<(&str, &str)> = c.iter().map(|c| (c.name(), c.group.as_str())).collect();
        assert_eq!(
            names,
            [
                ("belly_panel.t", "thickness"),
                ("roof.t", "thickness"),
                ("c", "damping")
            ]
        );
        assert_eq!(c[2].parameter.nominal, 0.5);
    }

    #[test]
    fn enriched_the_values_go_to_their_slots_and_held_values_change_nothing() {
        let sub = Subspace::new(
            Damped {
                space: full(),
                c: 0.5,
            },
            tail_only(),
        )
        .unwrap();
        let c = sub.candidates();
        let e = sub
            .enrich(&[c[2].parameter.clone(), c[1].parameter.clone()])
            .unwrap();
        assert_eq!(e.space().names(), ["mass.tail", "c", "roof.t"]);
        assert!(
            e.candidates()
                .iter()
                .map(|c| c.name())
                .eq(["belly_panel.t"])
        );
        let before = sub.simulate(&[0.075]).unwrap();
        let after = e.simulate(&[0.075, 0.5, 0.03]).unwrap();
        assert_eq!(before.data(), after.data());
        assert_eq!(
            e.simulate(&[0.075, 2.0, 0.035]).unwrap().channel(0),
            &[0.1, 0.035, 0.075, 2.0]
        );
        // Errors: not a candidate, declared, twice, beyond the admissible range.
        let p = |n: &str, l: f64, u: f64, v: f64| Parameter::new(n, l, u, v).unwrap();
        let msg = |r: impactcal_core::Result<Subspace<Damped>>| {
            let e = r.unwrap_err();
            assert!(matches!(e, CoreError::InvalidOption { .. }), "{e}");
            e.to_string()
        };
        assert!(msg(sub.enrich(&[p("spin", 0.0, 1.0, 0.0)])).contains("not a candidate"));
        assert!(msg(sub.enrich(&[p("mass.tail", 0.06, 0.08, 0.07)])).contains("already"));
        let r = p("roof.t", 0.02, 0.04, 0.03);
        assert!(msg(sub.enrich(&[r.clone(), r])).contains("twice"));
        assert!(msg(sub.enrich(&[p("c", -1.0, 5.0, 0.5)])).contains("admissible"));
    }

    #[test]
    fn conditions_set_held_parameters_or_go_to_the_model() {
        let sub = Subspace::new(
            Damped {
                space: full(),
                c: 0.5,
            },
            tail_only(),
        )
        .unwrap();
        let at = sub
            .at_condition(&[("roof.t".into(), 0.025), ("c".into(), 1.5)])
            .unwrap();
        assert_eq!(at.space(), sub.space());
        assert_eq!(
            at.simulate(&[0.075]).unwrap().channel(0),
            &[0.1, 0.025, 0.075, 1.5]
        );
        let held = at.candidates();
        assert_eq!(held[1].parameter.nominal, 0.025);
        assert_eq!(held[2].parameter.nominal, 1.5);
        let msg = |set: &[(&str, f64)]| {
            let set: Vec<(String, f64)> = set.iter().map(|(n, v)| (n.to_string(), *v)).collect();
            let e = sub.at_condition(&set).unwrap_err();
            assert!(matches!(e, CoreError::InvalidOption { .. }), "{e}");
            e.to_string()
        };
        assert!(msg(&[("mass.tail", 0.07)]).contains("declared parameter"));
        assert!(msg(&[("roof.t", 0.05)]).contains("[0.02, 0.04]"));
        assert!(msg(&[("spin", 1.0)]).contains("spin"));
        // A plain model holds nothing it can set itself.
        let plain = Subspace::new(Plain(Sum(full())), tail_only()).unwrap();
        let e = plain.at_condition(&[("gravity".into(), 1.0)]).unwrap_err();
        assert!(e.to_string().contains("holds no quantity"), "{e}");
    }
}
