//! A fast impact model with real impact physics, for tests, examples and the closed loop's
//! validation: a chain of three masses joined by springs, dropped at speed `v0` onto a
//! penalty contact with the ground.
//!
//! Bodies: masses `m1 = 1.0`, `m2 = 0.8`, `m3 = 1.2 + added_mass` kg, bottom to top. The
//! springs between neighbours have stiffness `k_i = modulus * 1e9 * a_i * stiffness_scale`
//! N/m with the fixed section-over-length factors `a = [6e-6, 5e-6]` m (the "modulus" is in
//! GPa, nominal 70), and dashpots `c_i = 2 damping sqrt(k_i mu_i)`, `mu_i` the reduced mass
//! of the pair. The ground pushes the bottom mass with `F = max(0, k_contact d + c_c d')`
//! where `d` is the penetration and `c_c = 2 contact_damping sqrt(k_contact M)`, `M` the
//! total mass. Gravity 9.81 m/s^2 acts on every mass. At `t = 0` the chain is unstressed and
//! falls at `v0` with the bottom mass `v0 * 5 ms` above the ground, so every record has a
//! pre-impact window of about 5 ms.
//!
//! Integration: semi-implicit (symplectic) Euler with a fixed step of 1 us; the outputs are
//! the three accelerations `a1, a2, a3` (m/s^2) every 0.1 ms over 40 ms (401 samples). A
//! run takes well under a millisecond.
//!
//! Declared parameters: `modulus` (GPa) and `k_contact` (N/m). Held quantities, listed as
//! candidates ([`Enrichable`]): `damping`, `contact_damping`, `added_mass` and
//! `stiffness_scale` (which multiplies the modulus, so it is confounded with it by
//! construction). The impact speed `v0` is a test condition ([`Enrichable::at_condition`]).
//! An appendage (a mass on a spring hung from `m2`, [`DropTower::with_appendage`]) is a
//! feature the model can carry but does not list: it stands for physics outside any
//! candidate list.
//!
//! ```
//! use impactcal_core::drop_tower::DropTower;
//! use impactcal_core::{Enrichable, Model};
//!
//! let model = DropTower::new();
//! let h = model.simulate(&model.space().nominal())?;
//! assert_eq!(h.labels(), ["a1", "a2", "a3"]);
//! // Free fall before the impact, a deceleration of tens of g after it.
//! assert!((h.value(2, 10) + 9.81).abs() < 1e-9);
//! assert!(h.channel(0).iter().fold(0.0_f64, |m, v| m.max(*v)) > 300.0);
//! assert_eq!(model.candidates().len(), 4);
//! # Ok::<(), impactcal_core::CoreError>(())
//! ```

use crate::enrich::{Candidate, Enrichable};
use crate::error::{CoreError, Result};
use crate::histories::Histories;
use crate::model::Model;
use crate::space::{Parameter, ParameterSpace};

const GRAVITY: f64 = 9.81;
const MASSES: [f64; 3] = [1.0, 0.8, 1.2];
const SECTIONS: [f64; 2] = [6e-6, 5e-6];
const STEP: f64 = 1e-6;
const OUTPUT_EVERY: usize = 100;
const SAMPLES: usize = 401;
const PRE_IMPACT: f64 = 0.005;

/// The held quantities, by name, with their admissible range and held value.
const HELD: [(&str, f64, f64, f64, &str, &str, &str); 4] = [
    (
        "damping",
        0.0,
        0.2,
        0.0,
        "1",
        "damping",
        "damping ratio of the dashpots beside the chain's springs",
    ),
    (
        "contact_damping",
        0.0,
        0.5,
        0.0,
        "1",
        "contact",
        "damping ratio of a dashpot in the ground contact",
    ),
    (
        "added_mass",
        0.0,
        1.0,
        0.0,
        "kg",
        "mass",
        "a mass added to the top body",
    ),
    (
        "stiffness_scale",
        0.5,
        1.5,
        1.0,
        "1",
        "material",
        "a factor on the chain's stiffness (the modulus times it)",
    ),
];

/// The drop-tower model (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct DropTower {
    space: ParameterSpace,
    /// Held values of the candidates, in the order of `HELD`.
    held: [f64; 4],
    v0: f64,
    appendage: Option<(f64, f64)>,
}

impl Default for DropTower {
    fn default() -> Self {
        Self::new()
    }
}

impl DropTower {
    /// The model with its two declared parameters (`modulus` in [40, 120] GPa, nominal 70;
    /// `k_contact` in [2e5, 2e6] N/m, nominal 8e5), every candidate at its held value and
    /// `v0 = 4` m/s.
    pub fn new() -> Self {
        let params = vec![
            Parameter {
                name: "modulus".into(),
                lower: 40.0,
                upper: 120.0,
                nominal: 70.0,
                unit: "GPa".into(),
            },
            Parameter {
                name: "k_contact".into(),
                lower: 2e5,
                upper: 2e6,
                nominal: 8e5,
                unit: "N/m".into(),
            },
        ];
        DropTower {
            space: ParameterSpace::from_valid(params),
            held: HELD.map(|h| h.3),
            v0: 4.0,
            appendage: None,
        }
    }

    /// The same model with an appendage hung from the middle body: a mass `mass` (kg) on a
    /// spring tuned to `frequency` (Hz) when its base is fixed. Not a candidate.
    ///
    /// # Errors
    /// [`CoreError::InvalidOption`] for a mass or frequency that is not finite and positive.
    pub fn with_appendage(mut self, mass: f64, frequency: f64) -> Result<Self> {
        for (name, v) in [("appendage mass", mass), ("appendage frequency", frequency)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(CoreError::invalid_option(
                    name,
                    v,
                    "must be finite and positive",
                ));
            }
        }
        self.appendage = Some((mass, frequency));
        Ok(self)
    }

    /// The impact speed (m/s).
    pub fn v0(&self) -> f64 {
        self.v0
    }

    /// The value of held quantity `i` at point `p`: the point's when the quantity is in the
    /// space, else the held value.
    fn value(&self, i: usize, p: &[f64]) -> f64 {
        self.space
            .index_of(HELD[i].0)
            .map_or(self.held[i], |j| p[j])
    }

    fn run(&self, p: &[f64]) -> Result<Histories> {
        if p.len() != self.space.dim() {
            return Err(CoreError::DimensionMismatch {
                what: "drop tower point".into(),
                expected: self.space.dim(),
                found: p.len(),
            });
        }
        let modulus = p[0];
        let k_contact = p[1];
        let (zeta, zeta_c, dm, scale) = (
            self.value(0, p),
            self.value(1, p),
            self.value(2, p),
            self.value(3, p),
        );
        let m = [MASSES[0], MASSES[1], MASSES[2] + dm];
        let k: Vec<f64> = SECTIONS.iter().map(|a| modulus * 1e9 * a * scale).collect();
        let c: Vec<f64> = (0..2)
            .map(|i| {
                let mu = m[i] * m[i + 1] / (m[i] + m[i + 1]);
                2.0 * zeta * (k[i] * mu).sqrt()
            })
            .collect();
        let total: f64 = m.iter().sum::<f64>() + self.appendage.map_or(0.0, |a| a.0);
        let c_contact = 2.0 * zeta_c * (k_contact * total).sqrt();
        let appendage = self
            .appendage
            .map(|(ma, f)| (ma, ma * (2.0 * std::f64::consts::PI * f).powi(2)));
        // Displacements from the initial configuration (up positive) and velocities; the
        // fourth entry is the appendage.
        let gap = self.v0 * PRE_IMPACT;
        let mut u = [0.0; 4];
        let mut v = [-self.v0; 4];
        let forces = |u: &[f64; 4], v: &[f64; 4]| -> [f64; 4] {
            let mut f = [0.0; 4];
            for i in 0..2 {
                let s = k[i] * (u[i + 1] - u[i]) + c[i] * (v[i + 1] - v[i]);
                f[i] += s;
                f[i + 1] -= s;
            }
            let d = -(gap + u[0]);
            if d > 0.0 {
                f[0] += (k_contact * d - c_contact * v[0]).max(0.0);
            }
            if let Some((_, ka)) = appendage {
                let s = ka * (u[3] - u[1]);
                f[1] += s;
                f[3] -= s;
            }
            f
        };
        let mass4 = [m[0], m[1], m[2], appendage.map_or(1.0, |a| a.0)];
        let mut out = vec![vec![0.0; SAMPLES]; 3];
        for step in 0..(SAMPLES - 1) * OUTPUT_EVERY + 1 {
            let f = forces(&u, &v);
            let a: Vec<f64> = (0..4).map(|i| f[i] / mass4[i] - GRAVITY).collect();
            if step % OUTPUT_EVERY == 0 {
                let k = step / OUTPUT_EVERY;
                for ch in 0..3 {
                    out[ch][k] = a[ch];
                }
            }
            for i in 0..4 {
                v[i] += a[i] * STEP;
                u[i] += v[i] * STEP;
            }
        }
        Histories::from_channels(
            vec!["a1".into(), "a2".into(), "a3".into()],
            out,
            STEP * OUTPUT_EVERY as f64,
            0.0,
            "m/s^2",
        )
    }
}

impl Model for DropTower {
    fn space(&self) -> &ParameterSpace {
        &self.space
    }

    fn simulate(&self, params: &[f64]) -> Result<Histories> {
        self.run(params)
    }
}

impl Enrichable for DropTower {
    fn candidates(&self) -> Vec<Candidate> {
        HELD.iter()
            .enumerate()
            .filter(|(_, h)| self.space.index_of(h.0).is_none())
            .map(|(i, h)| {
                let parameter = Parameter {
                    name: h.0.into(),
                    lower: h.1,
                    upper: h.2,
                    nominal: self.held[i],
                    unit: h.4.into(),
                };
                Candidate::new(parameter, h.5, h.6)
            })
            .collect()
    }

    fn enrich(&self, added: &[Parameter]) -> Result<Self> {
        let mut params = self.space.parameters().to_vec();
        for (k, p) in added.iter().enumerate() {
            self.check_candidate(p)?;
            if added[..k].iter().any(|q| q.name == p.name) {
                return Err(CoreError::invalid_option("enrich", &p.name, "added twice"));
            }
            params.push(p.clone());
        }
        Ok(DropTower {
            space: ParameterSpace::new(params)?,
            ..self.clone()
        })
    }

    fn at_condition(&self, set: &[(String, f64)]) -> Result<Self> {
        let mut out = self.clone();
        for (name, value) in set {
            if name == "v0" {
                if !(value.is_finite() && (0.5..=15.0).contains(value)) {
                    return Err(CoreError::invalid_option(
                        "condition v0",
                        value,
                        "the drop tower takes impact speeds in [0.5, 15] m/s",
                    ));
                }
                out.v0 = *value;
                continue;
            }
            let Some(i) = HELD.iter().position(|h| h.0 == name) else {
                return Err(CoreError::invalid_option(
                    "condition",
                    name,
                    "not a held quantity of the drop tower (v0, damping, contact_damping, \
                     added_mass, stiffness_scale)",
                ));
            };
            if self.space.index_of(name).is_some() {
                return Err(CoreError::invalid_option(
                    "condition",
                    name,
                    "a parameter of the model; a point sets it",
                ));
            }
            if !(value.is_finite() && (HELD[i].1..=HELD[i].2).contains(value)) {
                return Err(CoreError::invalid_option(
                    format!("condition {name}"),
                    value,
                    format!(
                        "outside its admissible range [{}, {}]",
                        HELD[i].1, HELD[i].2
                    ),
                ));
            }
            out.held[i] = *value;
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn momentum_and_free_fall() {
        let m = DropTower::new();
        let h = m.simulate(&m.space().nominal()).unwrap();
        // Before contact every body is in free fall.
        for c in 0..3 {
            assert!((h.value(c, 20) + GRAVITY).abs() < 1e-9);
        }
        // Impulse balance over the record: the ground's impulse equals the change of
        // momentum plus gravity's impulse. sum m a dt = total force impulse - M g T.
        let dt = h.dt();
        let impulse: f64 = (0..3)
            .map(|c| MASSES[c] * h.channel(c).iter().map(|a| a + GRAVITY).sum::<f64>() * dt)
            .sum();
        // The bodies rebound: the impulse exceeds M v0 (it is at most 2 M v0 when elastic).
        let mv0 = MASSES.iter().sum::<f64>() * 4.0;
        assert!(impulse > mv0 && impulse < 2.05 * mv0, "{impulse} vs {mv0}");
    }

    #[test]
    fn freed_at_held_value_changes_nothing_and_conditions_check() {
        let m = DropTower::new();
        let all: Vec<Parameter> = m.candidates().into_iter().map(|c| c.parameter).collect();
        let e = m.enrich(&all).unwrap();
        assert_eq!(e.space().dim(), 6);
        let a = m.simulate(&[70.0, 8e5]).unwrap();
        let b = e.simulate(&[70.0, 8e5, 0.0, 0.0, 0.0, 1.0]).unwrap();
        assert_eq!(a.data(), b.data());
        // The stiffness scale and the modulus are the same thing.
        let c = e.simulate(&[35.0, 8e5, 0.0, 0.0, 0.0, 2.0]).unwrap();
        assert_eq!(a.data(), c.data());
        assert!(e.candidates().is_empty());
        assert!(m.enrich(&[all[0].clone(), all[0].clone()]).is_err());
        assert!(m.at_condition(&[("v0".into(), 30.0)]).is_err());
        assert!(m.at_condition(&[("modulus".into(), 30.0)]).is_err());
        assert!(m.at_condition(&[("damping".into(), -1.0)]).is_err());
        let fast = m.at_condition(&[("v0".into(), 6.0)]).unwrap();
        let peak = |h: &Histories| h.channel(0).iter().fold(0.0_f64, |x, v| x.max(*v));
        assert!(peak(&fast.simulate(&[70.0, 8e5]).unwrap()) > peak(&a));
    }
}
