//! A model restricted to some of its parameters: the study's parameters vary, the others
//! keep base values.

use impactcal_core::{Histories, Model, ParameterSpace};

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
            if p.lower < q.lower || p.upper > q.upper {
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

    /// The model's full point for a point of the subspace.
    pub fn full_point(&self, point: &[f64]) -> Vec<f64> {
        let mut x = self.base.clone();
        for (&i, &v) in self.slots.iter().zip(point) {
            x[i] = v;
        }
        x
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use impactcal_core::Parameter;

    #[derive(Debug)]
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
}
