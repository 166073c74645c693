//! The driven lumped model: a [`LumpedSystem`] driven by the base acceleration of one test
//! record, as a [`Model`] and an [`Enrichable`].
//!
//! **Run.** The record's base channel, times the file's `unit`, drives the base; the
//! system is integrated from rest at the record's samples ([`Dynamics::run`]); each output
//! is the absolute acceleration of its mass, divided by `unit` (so in the record's unit),
//! on the record's time base, labelled with its test channel.
//!
//! **Declared parameters**, for each spring `s` in name order: `k_<s>` (N/m) and `zeta_<s>`
//! (its dashpot's damping ratio, `c = 2 zeta sqrt(k mu)`, `mu` the reduced mass of its
//! ends), with the file's ranges and nominals. Masses are fixed.
//!
//! **Held quantities** ([`Enrichable::candidates`]): each with its admissible range and the
//! held value that switches it off. Scales: `a_pk` is the record's peak base acceleration
//! (m/s^2) and `d_s` the quasi-static stretch of spring `s`: the stretch `|z_a - z_b|` of
//! its ends in the static solution `K z = M 1 a_pk` at the nominal stiffnesses (the system
//! held at the peak input as a constant acceleration). A spring carries the masses on its
//! far side from the base and nothing else, so a board on its own mount has
//! `d_s = a_pk m / k_s`, and a spring in a chain carries the masses beyond it. A pulse of
//! that peak moves a linear oscillator by at most `2 d_s`. `u_s` is the nominal travel of
//! spring `s`: the largest `|z_a - z_b|` over the run of the model at its nominal point,
//! under the reference input (the test's own base acceleration; for repeated tests the
//! strongest one's, [`crate::lumped::LumpedRepeats`], so that the rattles are probed at the
//! same lengths on every test).
//!
//! | name | range | held | effect |
//! |---|---|---|---|
//! | `mode_<m>_ratio` | 0..1 | 0 | a further mode on output mass `m`: a mass of this ratio times `m` hung from it by a spring and dashpot |
//! | `mode_<m>_frequency` | `10/T`..`0.2/dt` Hz | their geometric mean | that mode's frequency on a fixed base, `sqrt(k/m_x) / 2 pi` (damping ratio 0.02) |
//! | `cubic_<s>` | -1/12..1 | 0 | spring `s` becomes `k d (1 + gamma (d/d_s)^2)`: tangent stiffness positive up to `2 d_s` at the softest, four times `k` at `d_s` at the hardest |
//! | `stiffness_change` | -0.5..0.5 | 0 | every spring's stiffness times `1 + change` (the damping ratios kept): a test's stiffness change |
//! | `rattle_<s>_c<j>_stiffness` | 0..`100 k_s` | 0 | a two-sided gap contact between the ends of spring `s` (a rattle), of this penalty stiffness; `j = 1, 2, 3` |
//! | `rattle_<s>_c<j>_gap` | 0..`2 d_s` | `u_s / 2^j` | its clearance (m) |
//!
//! **Why three rattles per spring, at halving clearances.** A contact whose clearance the
//! ends never reach does nothing, so a rattle's stiffness can only be probed by a finite
//! step at a clearance the test's own travel closes; and a contact is a threshold effect,
//! so its stiffness at one clearance does not stand in for another (the recalibration with
//! the stiffness alone, at a clearance far from the true one, realises little of what the
//! contact explains). The clearance is unknown and may lie anywhere below the travel, and
//! the travel at the calibrated point may be well below the nominal one (a linear model
//! fitted to a rattling article stiffens its mount). So each spring carries three rattles,
//! probed at a half, a quarter and an eighth of its nominal travel (`c1`, `c2`, `c3`): a
//! geometric grid, each clearance within a factor of `sqrt 2` of any clearance between
//! `u_s / 8 sqrt 2` and `u_s / sqrt 2`, which closes at the calibrated point as long as its
//! travel stays above an eighth of the nominal one. The attribution scores each; once one's
//! stiffness is added, its clearance is the candidate that refines it. Only the lengths
//! come from the model's response (its nominal run); nothing of a test's residual enters.
//! | `delay` | `-50 dt`..`50 dt` | 0 | outputs later by this time (s): `y(t - delay)`, linear between samples |
//! | `saturation_<c>` | 0..`4 / a_pk` | 0 | channel `c` clipped at the rail `+-1 / value` (value in 1 per record unit; 0 is no rail) |
//!
//! `T` is the record's duration, `dt` its step; `<c>` is the channel's label with every
//! character other than a letter, a digit or `_` written as `_`.

use std::f64::consts::PI;

use impactcal_core::{
    Candidate, CoreError, Enrichable, Histories, Model, Parameter, ParameterSpace,
};

use crate::error::{ModelsError, Result};
use crate::lumped::align::shift_by;
use crate::lumped::integrate::{Dynamics, GapLink, SpringLink};
use crate::lumped::system::{GapSides, LumpedSystem, Node};

/// The damping ratio of an added mode.
const MODE_DAMPING: f64 = 0.02;

/// What a held quantity does, and to which element.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Effect {
    ModeRatio(usize),
    ModeFrequency(usize),
    Cubic(usize),
    StiffnessChange,
    RattleStiffness(usize, usize),
    RattleGap(usize, usize),
    Delay,
    Saturation(usize),
}

/// A held quantity: its candidate parameter (nominal = held value), group, description.
#[derive(Debug, Clone, PartialEq)]
struct Held {
    parameter: Parameter,
    group: &'static str,
    description: String,
    effect: Effect,
}

/// The driven lumped model of one test record (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct LumpedModel {
    system: LumpedSystem,
    /// Base acceleration (m/s^2).
    input: Vec<f64>,
    dt: f64,
    start: f64,
    unit_label: String,
    space: ParameterSpace,
    held: Vec<Held>,
    /// `d_s` of each spring (m).
    reach: Vec<f64>,
}

/// The rattles' held clearances, as fractions of the nominal travel: `c1`, `c2`, `c3`.
const CLEARANCES: [f64; 3] = [0.5, 0.25, 0.125];

/// A channel label as a parameter-name fragment.
fn fragment(label: &str) -> String {
    label
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

impl LumpedModel {
    /// The model of `system` driven by the base channel of `record`.
    ///
    /// # Errors
    /// [`ModelsError::Core`] when the record has no channel named by the system's base
    /// channel; [`ModelsError::Record`] for a record of fewer than two samples, a base
    /// channel with a non-finite sample (naming it) or that never moves; [`ModelsError::Invalid`]
    /// when two output labels give the same saturation parameter name.
    pub fn new(system: LumpedSystem, record: &Histories) -> Result<LumpedModel> {
        LumpedModel::scaled(system, record, None, None)
    }

    /// The model of `system` driven by the base channel of `record`, its held quantities
    /// scaled by `peak` (m/s^2) in place of the record's own peak base acceleration: what
    /// repeated tests of one article share, so that a rattle's gap or a rail means the same
    /// on every test ([`crate::lumped::LumpedRepeats`]).
    ///
    /// # Errors
    /// As [`LumpedModel::new`]; [`ModelsError::Invalid`] for a `peak` that is not positive
    /// and finite.
    pub fn with_scale(system: LumpedSystem, record: &Histories, peak: f64) -> Result<LumpedModel> {
        if !(peak.is_finite() && peak > 0.0) {
            return Err(ModelsError::invalid(
                "peak base acceleration",
                peak,
                "must be positive and finite",
            ));
        }
        LumpedModel::scaled(system, record, Some(peak), None)
    }

    fn scaled(
        system: LumpedSystem,
        record: &Histories,
        scale: Option<f64>,
        reference: Option<&[f64]>,
    ) -> Result<LumpedModel> {
        let raw = record.channel_by_label(&system.base_channel)?;
        let what = format!("base channel `{}`", system.base_channel);
        if raw.len() < 2 {
            return Err(ModelsError::record(what, "needs at least two samples"));
        }
        if let Some(k) = raw.iter().position(|x| !x.is_finite()) {
            return Err(ModelsError::record(
                what,
                format!("sample {k} is {}", raw[k]),
            ));
        }
        let input: Vec<f64> = raw.iter().map(|a| a * system.unit).collect();
        let peak = input.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
        if peak == 0.0 {
            return Err(ModelsError::record(
                what,
                "is zero throughout: nothing drives the system",
            ));
        }
        let peak = scale.unwrap_or(peak);
        let dt = record.dt();
        let duration = dt * (raw.len() - 1) as f64;
        let reach = static_stretch(&system, peak)?;
        let reference = reference.unwrap_or(&input);
        if reference.len() != input.len() {
            return Err(ModelsError::invalid(
                "reference input",
                format!("{} samples", reference.len()),
                format!("the record has {}", input.len()),
            ));
        }
        if let Some(k) = reference.iter().position(|x| !x.is_finite()) {
            return Err(ModelsError::invalid(
                "reference input",
                format!("sample {k} = {}", reference[k]),
                "must be finite",
            ));
        }
        let nominal: Vec<f64> = system
            .springs
            .iter()
            .flat_map(|s| [s.stiffness, s.damping_ratio])
            .collect();
        let travel = travel_of(&linear(&system, &nominal)?, reference, dt, &reach, &system)?;

        let mut params = Vec::with_capacity(2 * system.springs.len());
        for s in &system.springs {
            params.push(
                Parameter::new(format!("k_{}", s.name), s.range[0], s.range[1], s.stiffness)?
                    .with_unit("N/m"),
            );
            params.push(
                Parameter::new(
                    format!("zeta_{}", s.name),
                    s.damping_range[0],
                    s.damping_range[1],
                    s.damping_ratio,
                )?
                .with_unit("1"),
            );
        }

        let mut held = Vec::new();
        let mut add = |name: String,
                       lo: f64,
                       hi: f64,
                       nominal: f64,
                       unit: &str,
                       group: &'static str,
                       description: String,
                       effect: Effect|
         -> Result<()> {
            held.push(Held {
                parameter: Parameter::new(name, lo, hi, nominal)?.with_unit(unit),
                group,
                description,
                effect,
            });
            Ok(())
        };
        let mut mode_masses: Vec<usize> = system.outputs.iter().map(|o| o.mass).collect();
        mode_masses.sort_unstable();
        mode_masses.dedup();
        let (f_lo, f_hi) = (10.0 / duration, 0.2 / dt);
        for &m in &mode_masses {
            let name = &system.masses[m].0;
            add(
                format!("mode_{name}_ratio"),
                0.0,
                1.0,
                0.0,
                "1",
                "mode",
                format!("a further mode on `{name}`: its mass over `{name}`'s"),
                Effect::ModeRatio(m),
            )?;
            add(
                format!("mode_{name}_frequency"),
                f_lo.min(0.5 * f_hi),
                f_hi,
                (f_lo.min(0.5 * f_hi) * f_hi).sqrt(),
                "Hz",
                "mode",
                format!("the frequency of the further mode on `{name}` on a fixed base"),
                Effect::ModeFrequency(m),
            )?;
        }
        for (i, s) in system.springs.iter().enumerate() {
            add(
                format!("cubic_{}", s.name),
                -1.0 / 12.0,
                1.0,
                0.0,
                "1",
                "stiffness",
                format!(
                    "cubic stiffness of `{}`: k d (1 + gamma (d / {:.3e} m)^2)",
                    s.name, reach[i]
                ),
                Effect::Cubic(i),
            )?;
        }
        add(
            "stiffness_change".into(),
            -0.5,
            0.5,
            0.0,
            "1",
            "stiffness",
            "every spring's stiffness times 1 + change (a test's stiffness change)".into(),
            Effect::StiffnessChange,
        )?;
        for (i, s) in system.springs.iter().enumerate() {
            let [a, b] = s.between;
            let pair = format!("`{}` and `{}`", system.node_name(a), system.node_name(b));
            for (j, fraction) in CLEARANCES.iter().enumerate() {
                let c = j + 1;
                let gap = (fraction * travel[i]).min(2.0 * reach[i]);
                add(
                    format!("rattle_{}_c{c}_stiffness", s.name),
                    0.0,
                    100.0 * s.stiffness,
                    0.0,
                    "N/m",
                    "contact",
                    format!(
                        "penalty stiffness of a rattle (two-sided gap contact) between {pair}, \
                         probed at {fraction} of the nominal travel ({gap:.3e} m)"
                    ),
                    Effect::RattleStiffness(i, j),
                )?;
                add(
                    format!("rattle_{}_c{c}_gap", s.name),
                    0.0,
                    2.0 * reach[i],
                    gap,
                    "m",
                    "contact",
                    format!("clearance of rattle c{c} between {pair}"),
                    Effect::RattleGap(i, j),
                )?;
            }
        }
        add(
            "delay".into(),
            -50.0 * dt,
            50.0 * dt,
            0.0,
            "s",
            "timing",
            "outputs later than the base by this time".into(),
            Effect::Delay,
        )?;
        for (o, out) in system.outputs.iter().enumerate() {
            add(
                format!("saturation_{}", fragment(&out.channel)),
                0.0,
                4.0 * system.unit / peak,
                0.0,
                "1/unit",
                "sensor",
                format!(
                    "channel `{}` clipped at +-1/value (record units; 0: no rail)",
                    out.channel
                ),
                Effect::Saturation(o),
            )?;
        }
        for (i, h) in held.iter().enumerate() {
            let name = &h.parameter.name;
            if held[..i].iter().any(|g| &g.parameter.name == name)
                || params.iter().any(|p| &p.name == name)
            {
                return Err(ModelsError::invalid(
                    "held quantity",
                    name,
                    "two elements or channels give this name; rename one",
                ));
            }
        }
        Ok(LumpedModel {
            space: ParameterSpace::new(params)?,
            system,
            dt,
            start: record.start(),
            unit_label: record.unit().to_string(),
            held,
            reach,
            input,
        })
    }

    /// The model of `system` driven by the base channel of `record`, its held quantities
    /// scaled by `peak` (m/s^2) as [`LumpedModel::with_scale`], and its rattles probed at
    /// clearances taken from the nominal run under `reference` (m/s^2, one value per sample
    /// of `record`) in place of its own input: what repeated tests share
    /// ([`crate::lumped::LumpedRepeats`]).
    ///
    /// # Errors
    /// As [`LumpedModel::with_scale`]; [`ModelsError::Invalid`] for a reference of another
    /// length than the record, or with a sample that is not finite.
    pub fn with_reference(
        system: LumpedSystem,
        record: &Histories,
        peak: f64,
        reference: &[f64],
    ) -> Result<LumpedModel> {
        if !(peak.is_finite() && peak > 0.0) {
            return Err(ModelsError::invalid(
                "peak base acceleration",
                peak,
                "must be positive and finite",
            ));
        }
        LumpedModel::scaled(system, record, Some(peak), Some(reference))
    }

    /// The quasi-static stretch `d_s` of each spring (m), in name order (see the module
    /// docs): what the held quantities' ranges are scaled by.
    pub fn reach(&self) -> &[f64] {
        &self.reach
    }

    /// The travel of each spring (m), in name order: the largest stretch of its ends over
    /// the model's own run at point `p` without its rattles (every other held quantity as at
    /// `p`). At the nominal point under the reference input it is the `u_s` of the module
    /// docs.
    ///
    /// # Errors
    /// As [`LumpedModel::dynamics`] and the integrator.
    pub fn travel(&self, p: &[f64]) -> Result<Vec<f64>> {
        let (mut dynamics, _, _) = self.dynamics(p)?;
        let declared = self.system.gaps.len();
        dynamics.gaps.truncate(declared);
        travel_of(&dynamics, &self.input, self.dt, &self.reach, &self.system)
    }

    /// The system the model runs.
    pub fn system(&self) -> &LumpedSystem {
        &self.system
    }

    /// The base acceleration that drives it (m/s^2), one value per record sample.
    pub fn input(&self) -> &[f64] {
        &self.input
    }

    /// The value of each held quantity at point `p`: the point's where freed, else held.
    fn held_values(&self, p: &[f64]) -> Vec<f64> {
        self.held
            .iter()
            .map(|h| {
                self.space
                    .index_of(&h.parameter.name)
                    .map_or(h.parameter.nominal, |i| p[i])
            })
            .collect()
    }

    /// The system at point `p` as the integrator runs it, with the delay and the rails.
    ///
    /// # Errors
    /// [`ModelsError::Invalid`] for a point of the wrong length or a value outside what the
    /// physics admits (a stiffness that is not positive, a negative damping ratio).
    pub fn dynamics(&self, p: &[f64]) -> Result<(Dynamics, f64, Vec<f64>)> {
        if p.len() != self.space.dim() {
            return Err(ModelsError::invalid(
                "point",
                format!("{} values", p.len()),
                format!(
                    "the model takes {}: {}",
                    self.space.dim(),
                    self.space.names().join(", ")
                ),
            ));
        }
        if let Some(i) = p.iter().position(|x| !x.is_finite()) {
            return Err(ModelsError::invalid(
                self.space.names()[i],
                p[i],
                "must be finite",
            ));
        }
        let h = self.held_values(p);
        let sys = &self.system;
        let mass_of = |n: Node| match n {
            Node::Base => None,
            Node::Mass(i) => Some(sys.masses[i].1),
        };
        let mut change = 0.0;
        let mut delay = 0.0;
        let mut rails = vec![0.0; sys.outputs.len()];
        let mut cubic = vec![0.0; sys.springs.len()];
        let mut rattle = vec![[(0.0, 0.0); CLEARANCES.len()]; sys.springs.len()];
        let mut modes = vec![(0.0, 0.0); sys.masses.len()];
        for (held, v) in self.held.iter().zip(&h) {
            match held.effect {
                Effect::ModeRatio(m) => modes[m].0 = *v,
                Effect::ModeFrequency(m) => modes[m].1 = *v,
                Effect::Cubic(s) => cubic[s] = *v,
                Effect::StiffnessChange => change = *v,
                Effect::RattleStiffness(s, j) => rattle[s][j].0 = *v,
                Effect::RattleGap(s, j) => rattle[s][j].1 = *v,
                Effect::Delay => delay = *v,
                Effect::Saturation(o) => rails[o] = *v,
            }
        }
        let mut masses: Vec<f64> = sys.masses.iter().map(|m| m.1).collect();
        let mut springs = Vec::with_capacity(sys.springs.len() + masses.len());
        for (i, s) in sys.springs.iter().enumerate() {
            let k = p[2 * i] * (1.0 + change);
            let zeta = p[2 * i + 1];
            if !(k > 0.0 && zeta >= 0.0) {
                return Err(ModelsError::invalid(
                    format!("spring `{}`", s.name),
                    format!("k = {k}, zeta = {zeta}"),
                    "needs a positive stiffness and a damping ratio not below 0",
                ));
            }
            let mu = match (mass_of(s.between[0]), mass_of(s.between[1])) {
                (Some(a), Some(b)) => a * b / (a + b),
                (Some(a), None) | (None, Some(a)) => a,
                (None, None) => 0.0,
            };
            springs.push(SpringLink {
                ends: s.between,
                k,
                beta: cubic[i] / (self.reach[i] * self.reach[i]),
                c: 2.0 * zeta * (k * mu).sqrt(),
            });
        }
        for (m, &(ratio, f)) in modes.iter().enumerate() {
            if ratio > 0.0 {
                let mx = ratio * masses[m];
                let k = mx * (2.0 * PI * f).powi(2);
                springs.push(SpringLink {
                    ends: [Node::Mass(m), Node::Mass(masses.len())],
                    k,
                    beta: 0.0,
                    c: 2.0 * MODE_DAMPING * (k * mx * masses[m] / (mx + masses[m])).sqrt(),
                });
                masses.push(mx);
            }
        }
        let mut dynamics = Dynamics {
            masses,
            springs,
            ..declared_elements(sys)
        };
        for (i, slots) in rattle.iter().enumerate() {
            for &(k, gap) in slots {
                if k > 0.0 {
                    dynamics.gaps.push(GapLink {
                        ends: sys.springs[i].between,
                        gap: gap.max(0.0),
                        k,
                        sides: GapSides::Both,
                    });
                }
            }
        }
        Ok((dynamics, delay, rails))
    }

    fn run(&self, p: &[f64]) -> Result<Histories> {
        let (dynamics, delay, rails) = self.dynamics(p)?;
        let reach = 2.0 * self.reach.iter().fold(0.0_f64, |m, r| m.max(*r));
        let traj = dynamics.run(&self.input, self.dt, reach)?;
        let unit = self.system.unit;
        let mut out = Vec::with_capacity(self.system.outputs.len());
        for (o, output) in self.system.outputs.iter().enumerate() {
            let a: Vec<f64> = traj.accel[output.mass].iter().map(|x| x / unit).collect();
            let mut a = if delay == 0.0 {
                a
            } else {
                shift_by(&a, delay / self.dt)
            };
            if rails[o] > 0.0 {
                let rail = 1.0 / rails[o];
                a.iter_mut().for_each(|x| *x = x.clamp(-rail, rail));
            }
            out.push(a);
        }
        Ok(Histories::from_channels(
            self.system
                .outputs
                .iter()
                .map(|o| o.channel.clone())
                .collect(),
            out,
            self.dt,
            self.start,
            self.unit_label.clone(),
        )?)
    }
}

/// The declared system at `point` (each spring's stiffness and damping ratio, in name
/// order), without held quantities: what the nominal travel is read from.
fn linear(system: &LumpedSystem, point: &[f64]) -> Result<Dynamics> {
    let mass_of = |n: Node| match n {
        Node::Base => None,
        Node::Mass(i) => Some(system.masses[i].1),
    };
    let springs = system
        .springs
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let (k, zeta) = (point[2 * i], point[2 * i + 1]);
            let mu = match (mass_of(s.between[0]), mass_of(s.between[1])) {
                (Some(a), Some(b)) => a * b / (a + b),
                (Some(a), None) | (None, Some(a)) => a,
                (None, None) => 0.0,
            };
            SpringLink {
                ends: s.between,
                k,
                beta: 0.0,
                c: 2.0 * zeta * (k * mu).sqrt(),
            }
        })
        .collect();
    Ok(Dynamics {
        masses: system.masses.iter().map(|m| m.1).collect(),
        springs,
        ..declared_elements(system)
    })
}

/// The file's dashpots and gap contacts of `system`, as the integrator takes them (no mass,
/// no spring).
fn declared_elements(system: &LumpedSystem) -> Dynamics {
    Dynamics {
        masses: Vec::new(),
        springs: Vec::new(),
        dashpots: system
            .dashpots
            .iter()
            .map(|d| (d.between, d.coefficient))
            .collect(),
        gaps: system
            .gaps
            .iter()
            .map(|g| GapLink {
                ends: g.between,
                gap: g.gap,
                k: g.stiffness,
                sides: g.sides,
            })
            .collect(),
    }
}

/// The largest stretch of each declared spring's ends (m) in the run of `dynamics` under
/// `input` (m/s^2, step `dt`); `reach` the springs' `d_s`.
fn travel_of(
    dynamics: &Dynamics,
    input: &[f64],
    dt: f64,
    reach: &[f64],
    system: &LumpedSystem,
) -> Result<Vec<f64>> {
    let far = 2.0 * reach.iter().fold(0.0_f64, |m, r| m.max(*r));
    let traj = dynamics.run(input, dt, far)?;
    let at = |node: Node, k: usize| match node {
        Node::Base => 0.0,
        Node::Mass(i) => traj.z[i][k],
    };
    Ok(system
        .springs
        .iter()
        .map(|s| {
            (0..input.len()).fold(0.0_f64, |m, k| {
                m.max((at(s.between[1], k) - at(s.between[0], k)).abs())
            })
        })
        .collect())
}

/// The quasi-static stretch of each spring of `system` (m): `|z_a - z_b|` at its ends in
/// the solution of `K z = M 1 peak` at the nominal stiffnesses (Gaussian elimination with
/// partial pivoting; `K` is positive definite since every mass is tied to the base by
/// springs, which the file reader checks).
///
/// # Errors
/// [`ModelsError::Invalid`] if `K` is singular to working precision.
fn static_stretch(system: &LumpedSystem, peak: f64) -> Result<Vec<f64>> {
    let n = system.masses.len();
    let mut k = vec![0.0; n * n];
    for s in &system.springs {
        let [a, b] = s.between;
        for (x, y, w) in [(a, a, 1.0), (b, b, 1.0), (a, b, -1.0), (b, a, -1.0)] {
            if let (Node::Mass(i), Node::Mass(j)) = (x, y) {
                k[i * n + j] += w * s.stiffness;
            }
        }
    }
    let mut z: Vec<f64> = system.masses.iter().map(|m| m.1 * peak).collect();
    for c in 0..n {
        let pivot = (c..n)
            .max_by(|&i, &j| k[i * n + c].abs().total_cmp(&k[j * n + c].abs()))
            .unwrap_or(c);
        if k[pivot * n + c] == 0.0 {
            return Err(ModelsError::invalid(
                "stiffness matrix",
                format!("column {c}"),
                "is singular: a mass is not held by springs",
            ));
        }
        for j in 0..n {
            k.swap(c * n + j, pivot * n + j);
        }
        z.swap(c, pivot);
        for i in c + 1..n {
            let f = k[i * n + c] / k[c * n + c];
            for j in c..n {
                k[i * n + j] -= f * k[c * n + j];
            }
            z[i] -= f * z[c];
        }
    }
    for c in (0..n).rev() {
        let tail: f64 = (c + 1..n).map(|j| k[c * n + j] * z[j]).sum();
        z[c] = (z[c] - tail) / k[c * n + c];
    }
    let at = |node: Node| match node {
        Node::Base => 0.0,
        Node::Mass(i) => z[i],
    };
    Ok(system
        .springs
        .iter()
        .map(|s| (at(s.between[1]) - at(s.between[0])).abs())
        .collect())
}

impl Model for LumpedModel {
    fn space(&self) -> &ParameterSpace {
        &self.space
    }

    fn simulate(&self, params: &[f64]) -> impactcal_core::Result<Histories> {
        self.run(params).map_err(CoreError::from)
    }
}

impl Enrichable for LumpedModel {
    fn candidates(&self) -> Vec<Candidate> {
        self.held
            .iter()
            .filter(|h| self.space.index_of(&h.parameter.name).is_none())
            .map(|h| Candidate::new(h.parameter.clone(), h.group, h.description.clone()))
            .collect()
    }

    fn enrich(&self, added: &[Parameter]) -> impactcal_core::Result<Self> {
        Ok(LumpedModel {
            space: impactcal_core::enrich::enriched_space(self, added)?,
            ..self.clone()
        })
    }

    fn at_condition(&self, set: &[(String, f64)]) -> impactcal_core::Result<Self> {
        let mut out = self.clone();
        for (name, value) in set {
            let Some(i) = self.held.iter().position(|h| &h.parameter.name == name) else {
                return Err(CoreError::invalid_option(
                    "condition",
                    name,
                    format!(
                        "not a held quantity of the lumped model ({})",
                        self.held
                            .iter()
                            .map(|h| h.parameter.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                ));
            };
            if self.space.index_of(name).is_some() {
                return Err(CoreError::invalid_option(
                    "condition",
                    name,
                    "a parameter of the model; a point sets it",
                ));
            }
            Candidate::new(self.held[i].parameter.clone(), "", "").check_value(*value)?;
            out.held[i].parameter.nominal = *value;
        }
        Ok(out)
    }

    fn describe(&self, name: &str) -> Option<(String, String)> {
        if let Some(s) = name.strip_prefix("k_") {
            if self.system.springs.iter().any(|x| x.name == s) {
                return Some(("stiffness".into(), format!("stiffness of spring `{s}`")));
            }
        }
        if let Some(s) = name.strip_prefix("zeta_") {
            if self.system.springs.iter().any(|x| x.name == s) {
                return Some((
                    "damping".into(),
                    format!("damping ratio of the dashpot beside spring `{s}`"),
                ));
            }
        }
        self.held
            .iter()
            .find(|h| h.parameter.name == name)
            .map(|h| (h.group.to_string(), h.description.clone()))
    }
}
