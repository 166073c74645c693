//! The airframe as an [`Enrichable`] model: every catalogue quantity it does not declare is
//! a candidate effect, freed by [`Enrichable::enrich`] and set to another test condition by
//! [`Enrichable::at_condition`].
//!
//! The candidates are the whole catalogue ([`catalogue`]) minus the model's space, in
//! catalogue order: impact speeds and attitude (group `condition`), `ground.friction`
//! (`friction`), `damping` (`damping`), the Cowper-Symonds `rate.c` and `rate.p`
//! (`strain-rate`), the five concentrated masses (`mass`), and each part's `t`
//! (`thickness`) and `E`, `Et`, `sigy` (`material`). Each candidate's nominal is the value
//! the model holds it at (its base value), and its admissible range is the catalogue's
//! range, chosen per quantity as follows:
//! - sign-constrained quantities start at their physical edge: `ground.friction` in
//!   `[0, 0.8]` (a Coulomb coefficient is never negative; 0.8 is about the largest quoted for
//!   metal on concrete or soil), `damping` in `[0, 50]` 1/s (mass-proportional damping can
//!   only remove energy; 50 1/s damps a free motion by a factor e^-1.25 over the 25 ms of a
//!   crash pulse, far more than structural damping does);
//! - Cowper-Symonds constants of aluminium: `rate.c` in `[1000, 100000]` 1/s and `rate.p`
//!   in `[2, 8]`, the spread of values fitted to aluminium alloys in the literature (100000
//!   1/s makes the alloy all but rate-insensitive at crash strain rates);
//! - test conditions: `impact.vertical` in `[240, 384]` in/s (26 ft/s +-23 %),
//!   `impact.horizontal` in `[0, 600]` in/s (a vertical drop to 50 ft/s forward), and
//!   `attitude.pitch`, `attitude.roll` within +-10 degrees, the envelope of the source
//!   paper's test and of a survivable crash;
//! - masses, moduli, tangent moduli and yield stresses +-20 % about nominal (the width of the
//!   paper's Table 1); thicknesses +-20 %, or the paper's own Table 2 bounds.
//!
//! Where the model holds a quantity outside that range (a base value set by the user), the
//! range is widened to include the held value, so that freeing it there is admissible.

use impactcal_core::enrich::{Candidate, Enrichable};
use impactcal_core::{CoreError, Parameter, ParameterSpace};

use super::{AirframeModel, catalogue, check_values};

impl AirframeModel {
    /// The candidate named `name`, if the model holds it (not declared, in the catalogue).
    fn candidate(&self, name: &str) -> Option<Candidate> {
        self.candidates().into_iter().find(|c| c.name() == name)
    }
}

impl Enrichable for AirframeModel {
    /// The catalogue quantities not in the space, in catalogue order, each at its held value
    /// with its admissible range (see the module docs) and group.
    fn candidates(&self) -> Vec<Candidate> {
        catalogue()
            .into_iter()
            .filter(|a| self.space.index_of(&a.name).is_none())
            .filter_map(|a| {
                let held = self.base.get(&a.name).ok()?;
                let p = Parameter::new(a.name.clone(), a.lower.min(held), a.upper.max(held), held)
                    .ok()?
                    .with_unit(a.unit);
                Some(Candidate::new(p, a.group, a.description))
            })
            .collect()
    }

    /// The group and description of a catalogue quantity.
    fn describe(&self, name: &str) -> Option<(String, String)> {
        catalogue()
            .into_iter()
            .find(|a| a.name == name)
            .map(|a| (a.group.to_string(), a.description))
    }

    /// The same airframe and base values with `added` appended to the space: at the added
    /// parameters' held values a run is the same run, bit for bit (a point sets the values
    /// the base already holds).
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for a name that is not a candidate (declared already, or
    /// not in the catalogue), a name given twice, or bounds outside the candidate's
    /// admissible range; [`CoreError::Parameter`] for invalid bounds.
    fn enrich(&self, added: &[Parameter]) -> impactcal_core::Result<Self> {
        let mut params = self.space.parameters().to_vec();
        for p in added {
            p.validate()?;
            self.check_candidate(p)?;
            if params.iter().any(|q| q.name == p.name) {
                return Err(CoreError::invalid_option("enrich", &p.name, "added twice"));
            }
            if let Some(c) = self.candidate(&p.name) {
                c.check_bounds(p)?;
            }
            params.push(p.clone());
        }
        Ok(AirframeModel {
            airframe: self.airframe.clone(),
            base: self.base.clone(),
            space: ParameterSpace::new(params)?,
        })
    }

    /// The same model with held quantities set to other values (for example a holdout test
    /// at `impact.vertical = 280` or `attitude.pitch = 5`); the space is unchanged.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for a declared parameter (a point sets it), a name not in
    /// the catalogue, or a value outside the quantity's admissible range.
    fn at_condition(&self, set: &[(String, f64)]) -> impactcal_core::Result<Self> {
        let mut base = self.base.clone();
        for (name, value) in set {
            if self.space.index_of(name).is_some() {
                return Err(CoreError::invalid_option(
                    "condition",
                    name,
                    "a declared parameter of the model (a point sets it), not a held quantity",
                ));
            }
            let Some(c) = self.candidate(name) else {
                return Err(CoreError::invalid_option(
                    "condition",
                    name,
                    "not a quantity of the airframe (`impactcal airframe --list` prints them)",
                ));
            };
            c.check_value(*value)?;
            base.set(name, *value)
                .map_err(|e| CoreError::invalid_option("condition", name, e.to_string()))?;
        }
        check_values(&base)
            .map_err(|e| CoreError::invalid_option("condition", "values", e.to_string()))?;
        Ok(AirframeModel {
            airframe: self.airframe.clone(),
            base,
            space: self.space.clone(),
        })
    }
}
