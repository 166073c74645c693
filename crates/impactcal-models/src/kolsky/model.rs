//! The Kolsky bar model: the measured incident pulse drives two elastic bars and the
//! specimen between them; the model returns the reflected and transmitted gauge strains.
//!
//! **Bars.** At the specimen faces (compression positive, `eps_I` the incident wave moved
//! from its gauge to the face), the incident bar's face has force
//! `F_1 = E_i A_i (eps_I + eps_R)` and velocity `v_1 = c_i (eps_I - eps_R)`, the transmitted
//! bar's `F_2 = E_t A_t eps_T` and `v_2 = c_t eps_T`. With a specimen that carries the
//! force `F` on both faces (quasi-static: no inertia), `eps_T = F / (E_t A_t)`,
//! `eps_R = F / (E_i A_i) - eps_I`, and the specimen shortens at
//! `v_1 - v_2 = 2 c_i eps_I - F (1 / Z_i + 1 / Z_t)`, `Z = E A / c` the bar impedances.
//!
//! **Specimen.** True strain `eps = ln(L_0 / L)`, elastic-plastic in one dimension with an
//! effective modulus `E_s` (the specimen's and its interfaces' compliance in one number):
//! `sigma = E_s (eps - eps_p)` and, while it flows,
//! `sigma = (A + B eps_p^n) (1 + C ln max(deps_p/dt / 1 s^-1, 1))` (Johnson-Cook's
//! hardening and rate terms, reference rate 1/s); constant volume, so the area is
//! `A_s = A_0 L_0 / L` and `F = A_s sigma`. The force cannot become negative (a
//! specimen is not glued to the bars).
//!
//! **Integration.** On the record's interval (after resampling to what the bars carry),
//! split into sub-steps of at most a tenth of the specimen's elastic time constant
//! `tau = L / (E_s A_s (1 / Z_i + 1 / Z_t))`: an elastic step is the exact solution of
//! the linear equation `dsigma/dt = E_s / L (2 c_i eps_I - K sigma)` (`K = A_s (1 / Z_i +
//! 1 / Z_t)`) for the step's mean input; a plastic step is the backward-Euler return onto
//! the flow stress, the plastic increment the root of a monotone scalar equation.
//!
//! **Parameters.** Declared: `A` and `B` (MPa), `n`, `modulus` (`E_s`, GPa); the nuisance
//! terms `wave_speed` (m/s, the incident bar's, the transmitted bar's scaled with it),
//! `delay_reflected` and `delay_transmitted` (us, trigger offsets that shift the modelled
//! signals later).
//!
//! **Held quantities** ([`Enrichable`]: each with its admissible range and the held value
//! that switches it off; [`KolskyModel::candidates`](Enrichable::candidates)):
//!
//! | name | range | held | effect |
//! |---|---|---|---|
//! | `dispersion` | 0..1 | 0 | the Pochhammer-Chree phase ([`DispersionCurve`]) applied to the incident wave from its gauge to the specimen, and to the reflected and transmitted waves from the specimen to their gauges, scaled by this fraction |
//! | `rate_sensitivity` | 0..0.1 | 0 | Johnson-Cook's `C` |
//! | `friction` | 0..0.3 | 0 | Coulomb friction `mu` at both faces: the bars see the mean pressure `sigma (1 + mu d / (3 L))` of a flowing specimen of diameter `d` (Schmid and Boas 1935, "Kristallplastizitat"; the same first-order term as Siebel's) |
//! | `inertia` | 0..1 | 0 | the specimen's inertia, as this fraction of its mass, by four elements through its length (the face stresses then differ: Davies and Hunter 1963, J. Mech. Phys. Solids 11, 155-179) |
//! | `gain_incident` | 0.3..3 | 1 | the incident gauge reads this factor times the true strain (its input is divided by it, its reflected output multiplied) |
//! | `gain_transmitted` | 0.3..3 | 1 | the same for the transmitted gauge |
//! | `gap` | 0..0.2 | 0 | mm of clearance between the specimen and a bar: no force until the faces have closed it |
//!
//! **Outputs.** Channels `reflected` (the reflected wave at the incident gauge) and
//! `transmitted` (at the transmitted gauge), strains compression positive, on the record's
//! time base, zero outside the waves' windows; [`KolskyModel::measured`] gives the record's
//! own waves on the same base, for comparison.

use std::sync::{Arc, OnceLock};

use impactcal_core::{
    Candidate, CoreError, Enrichable, Histories, Model, Parameter, ParameterSpace,
};

use crate::error::{ModelsError, Result};
use crate::kolsky::dispersion::DispersionCurve;
use crate::kolsky::form::{BarSetup, KolskyTest};
use crate::kolsky::waves::{Separated, at_time, separate};

/// The model's output channels.
pub const OUTPUT_CHANNELS: [&str; 2] = ["reflected", "transmitted"];

/// The declared parameters, in order, with their default ranges and nominals: the material
/// (`A`, `B`, `n`, `modulus`) and the nuisance terms (`wave_speed` is set around the test's).
const DECLARED: [(&str, f64, f64, f64, &str); 6] = [
    ("A", 1.0, 2000.0, 100.0, "MPa"),
    ("B", 0.0, 2000.0, 300.0, "MPa"),
    ("n", 0.05, 1.0, 0.5, "1"),
    ("modulus", 5.0, 300.0, 50.0, "GPa"),
    ("delay_reflected", -10.0, 10.0, 0.0, "us"),
    ("delay_transmitted", -10.0, 10.0, 0.0, "us"),
];

/// The held quantities: name, admissible range, held value, unit, group, description.
const HELD: [(&str, f64, f64, f64, &str, &str, &str); 7] = [
    (
        "dispersion",
        0.0,
        1.0,
        0.0,
        "1",
        "dispersion",
        "Pochhammer-Chree dispersion of the bars (fraction of the first mode's phase)",
    ),
    (
        "rate_sensitivity",
        0.0,
        0.1,
        0.0,
        "1",
        "material",
        "Johnson-Cook strain-rate sensitivity C (reference rate 1/s)",
    ),
    (
        "friction",
        0.0,
        0.3,
        0.0,
        "1",
        "friction",
        "Coulomb friction at the specimen faces (Schmid-Boas mean pressure)",
    ),
    (
        "inertia",
        0.0,
        1.0,
        0.0,
        "1",
        "mass",
        "specimen inertia (fraction of its mass, four elements through its length)",
    ),
    (
        "gain_incident",
        0.3,
        3.0,
        1.0,
        "1",
        "gauge",
        "gain error of the incident bar's gauge (recorded over true strain)",
    ),
    (
        "gain_transmitted",
        0.3,
        3.0,
        1.0,
        "1",
        "gauge",
        "gain error of the transmitted bar's gauge (recorded over true strain)",
    ),
    (
        "gap",
        0.0,
        0.2,
        0.0,
        "mm",
        "contact",
        "clearance between the specimen and a bar before loading",
    ),
];

/// The nuisance terms among the declared parameters.
const NUISANCE: [&str; 3] = ["wave_speed", "delay_reflected", "delay_transmitted"];

/// The values a run uses, from a point and the held quantities.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RunValues {
    pub a: f64,
    pub b: f64,
    pub n: f64,
    pub modulus: f64,
    pub wave_speed: f64,
    pub delay_reflected: f64,
    pub delay_transmitted: f64,
    pub dispersion: f64,
    pub rate_sensitivity: f64,
    pub friction: f64,
    pub inertia: f64,
    pub gain_incident: f64,
    pub gain_transmitted: f64,
    pub gap: f64,
}

/// The face histories of one run, on the window's samples.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceRun {
    /// Face time of each sample (s).
    pub time: Vec<f64>,
    /// `eps_I`, `eps_R`, `eps_T` at the faces.
    pub waves: [Vec<f64>; 3],
    /// The specimen's true stress (Pa).
    pub stress: Vec<f64>,
    /// The specimen's true strain.
    pub strain: Vec<f64>,
    /// The specimen's plastic strain.
    pub plastic: Vec<f64>,
}

/// The Kolsky bar model of one test (see the module docs).
#[derive(Debug, Clone)]
pub struct KolskyModel {
    test: KolskyTest,
    waves: Separated,
    space: ParameterSpace,
    /// The held values, in the order of `HELD`.
    held: [f64; 7],
    /// The first-mode dispersion of the incident and the transmitted bar, solved on the
    /// first run that needs it and shared by the model's clones.
    curves: Arc<OnceLock<std::result::Result<[DispersionCurve; 2], String>>>,
}

impl KolskyModel {
    /// The model of `test`, with the default parameter ranges (the material's wide enough
    /// for metals from annealed pure metals to steels: `A` 1 to 2,000 MPa, `B` 0 to 2,000
    /// MPa, `n` 0.05 to 1, `modulus` 5 to 300 GPa; `wave_speed` within 5 % of the test's;
    /// delays within 10 us).
    ///
    /// # Errors
    /// As [`separate`] (a record whose incident pulse cannot be separated).
    pub fn new(test: &KolskyTest) -> Result<KolskyModel> {
        let waves = separate(test)?;
        let c = test.incident.wave_speed();
        let mut params = Vec::with_capacity(7);
        for (name, lo, hi, nom, unit) in DECLARED.iter().take(4) {
            params.push(Parameter::new(*name, *lo, *hi, *nom)?.with_unit(*unit));
        }
        params.push(Parameter::new("wave_speed", 0.95 * c, 1.05 * c, c)?.with_unit("m/s"));
        for (name, lo, hi, nom, unit) in DECLARED.iter().skip(4) {
            params.push(Parameter::new(*name, *lo, *hi, *nom)?.with_unit(*unit));
        }
        Ok(KolskyModel {
            test: test.clone(),
            waves,
            space: ParameterSpace::new(params)?,
            held: HELD.map(|h| h.3),
            curves: Arc::new(OnceLock::new()),
        })
    }

    /// The model with other ranges for its declared parameters (same names, same order).
    ///
    /// # Errors
    /// [`ModelsError::Invalid`] when the names differ from the model's.
    pub fn with_space(mut self, space: ParameterSpace) -> Result<KolskyModel> {
        if space.names() != self.space.names() {
            return Err(ModelsError::invalid(
                "space",
                space.names().join(", "),
                format!("must name {}", self.space.names().join(", ")),
            ));
        }
        self.space = space;
        Ok(self)
    }

    /// The test the model was built on.
    pub fn test(&self) -> &KolskyTest {
        &self.test
    }

    /// The separated waves of the record (resampled, see [`separate`]).
    pub fn separated(&self) -> &Separated {
        &self.waves
    }

    /// The record's reflected and transmitted waves on the model's output base (channels
    /// [`OUTPUT_CHANNELS`]).
    ///
    /// # Errors
    /// Never for a model built by [`KolskyModel::new`]; the core error of histories
    /// otherwise.
    pub fn measured(&self) -> Result<Histories> {
        Ok(Histories::from_channels(
            OUTPUT_CHANNELS.iter().map(|s| s.to_string()).collect(),
            vec![self.waves.reflected.clone(), self.waves.transmitted.clone()],
            self.waves.dt,
            self.waves.start,
            "1",
        )?)
    }

    /// The dispersion curves of both bars (solved once, see [`DispersionCurve::solve`]).
    fn curves(&self) -> Result<&[DispersionCurve; 2]> {
        let solved = self.curves.get_or_init(|| {
            let w = &self.waves;
            let curve = |b: &BarSetup| {
                // Up to the Nyquist frequency at phase velocities down to half the bar's
                // speed (the Rayleigh speed exceeds half the rod speed for any Poisson
                // ratio).
                let ka_max =
                    std::f64::consts::PI / w.dt * b.section.radius() / (0.5 * b.wave_speed());
                DispersionCurve::solve(b.poisson, ka_max.max(1.0), 0.02)
            };
            let (bi, bt) = (&self.test.incident, &self.test.transmitted);
            let ci = curve(bi).map_err(|e| e.to_string())?;
            let same = bi.poisson.to_bits() == bt.poisson.to_bits()
                && (bi.section.radius() / bi.wave_speed()).to_bits()
                    == (bt.section.radius() / bt.wave_speed()).to_bits();
            let ct = if same {
                ci.clone()
            } else {
                curve(bt).map_err(|e| e.to_string())?
            };
            Ok([ci, ct])
        });
        solved.as_ref().map_err(|message| ModelsError::Numerical {
            what: "Pochhammer-Chree dispersion".into(),
            message: message.clone(),
        })
    }

    /// The value of held quantity `i` at point `p`: the point's when freed, else held.
    fn value(&self, p: &[f64], i: usize) -> f64 {
        self.space
            .index_of(HELD[i].0)
            .map_or(self.held[i], |j| p[j])
    }

    fn values(&self, p: &[f64]) -> Result<RunValues> {
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
        let get = |name: &str| self.space.index_of(name).map(|i| p[i]);
        let need = |name: &str| {
            get(name).ok_or_else(|| ModelsError::invalid("space", name, "missing parameter"))
        };
        let v = RunValues {
            a: need("A")? * 1e6,
            b: need("B")? * 1e6,
            n: need("n")?,
            modulus: need("modulus")? * 1e9,
            wave_speed: need("wave_speed")?,
            delay_reflected: need("delay_reflected")? * 1e-6,
            delay_transmitted: need("delay_transmitted")? * 1e-6,
            dispersion: self.value(p, 0),
            rate_sensitivity: self.value(p, 1),
            friction: self.value(p, 2),
            inertia: self.value(p, 3),
            gain_incident: self.value(p, 4),
            gain_transmitted: self.value(p, 5),
            gap: self.value(p, 6) * 1e-3,
        };
        if !(v.a >= 0.0 && v.b >= 0.0 && v.n > 0.0 && v.modulus > 0.0 && v.wave_speed > 0.0) {
            return Err(ModelsError::invalid(
                "point",
                format!("{p:?}"),
                "A and B must be non-negative, n, modulus and wave_speed positive",
            ));
        }
        Ok(v)
    }

    /// The face histories of a run at point `p` (see the module docs).
    ///
    /// # Errors
    /// [`ModelsError::Invalid`] for a point of the wrong length or a non-physical value;
    /// [`ModelsError::Numerical`] when the flow stress cannot be met in a step.
    pub fn faces(&self, p: &[f64]) -> Result<FaceRun> {
        let v = self.values(p)?;
        self.run_faces(&v)
    }

    pub(crate) fn run_faces(&self, v: &RunValues) -> Result<FaceRun> {
        let w = &self.waves;
        let (bi, bt) = (&self.test.incident, &self.test.transmitted);
        let ci = v.wave_speed;
        let ct = bt.wave_speed() * v.wave_speed / bi.wave_speed();
        let bars = Bars {
            zi: bi.modulus * bi.area() / ci,
            zt: bt.modulus * bt.area() / ct,
            ci,
        };
        let (ki, kt) = (bi.modulus * bi.area(), bt.modulus * bt.area());
        let delay = bi.gauge_distance / ci;
        let t0 = w.start + w.window_start as f64 * w.dt + delay;
        let n = w.window_len;
        let time: Vec<f64> = (0..n).map(|k| t0 + k as f64 * w.dt).collect();
        // The incident wave in its window, dispersed from the gauge to the face, as the true
        // strain (the gauge reads `gain_incident` times it).
        let segment: Vec<f64> = w.incident[w.window_start..w.window_start + n]
            .iter()
            .map(|e| e / v.gain_incident)
            .collect();
        let segment = if v.dispersion == 0.0 {
            segment
        } else {
            self.curves()?[0].disperse(
                &segment,
                w.dt,
                bi.gauge_distance,
                bi.section.radius(),
                ci,
                v.dispersion,
            )
        };
        let seg_start = w.start + w.window_start as f64 * w.dt;
        let eps_i: Vec<f64> = time
            .iter()
            .map(|t| at_time(&segment, seg_start, w.dt, t - delay))
            .collect();
        let sp = &self.test.specimen;
        let geometry = Geometry {
            length: sp.length,
            volume: sp.section.area() * sp.length,
            diameter: 2.0 * sp.section.radius(),
            mass: v.inertia * sp.density * sp.section.area() * sp.length,
        };
        let mut state = if v.inertia > 0.0 {
            Specimen::Elements(Elements::new(&geometry))
        } else {
            Specimen::Lumped(Lumped {
                sigma: 0.0,
                plastic: 0.0,
                length: geometry.length,
            })
        };
        let mut gap = v.gap;
        let (mut stress, mut strain, mut plastic) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let (mut er, mut et) = (vec![0.0; n], vec![0.0; n]);
        for k in 0..n {
            let mut forces = (0.0, 0.0);
            if k > 0 {
                let h_max = state.max_step(v, &bars, &geometry);
                let subs = ((w.dt / h_max).ceil() as usize).clamp(1, 100_000);
                let h = w.dt / subs as f64;
                for j in 0..subs {
                    let f = (j as f64 + 0.5) / subs as f64;
                    let e_in = eps_i[k - 1] * (1.0 - f) + eps_i[k] * f;
                    if gap > 0.0 {
                        // The faces close the clearance at 2 c_i eps_I with no force.
                        gap -= h * 2.0 * ci * e_in;
                        continue;
                    }
                    gap = 0.0;
                    forces = state.step(v, &bars, &geometry, h, e_in)?;
                }
            }
            et[k] = forces.1 / kt;
            er[k] = forces.0 / ki - eps_i[k];
            let (sg, st, pl) = state.measures(&geometry);
            stress[k] = sg;
            strain[k] = st;
            plastic[k] = pl;
        }
        if let Some(k) = stress.iter().position(|x| !x.is_finite()) {
            return Err(ModelsError::Numerical {
                what: "Kolsky specimen".into(),
                message: format!(
                    "the stress became non-finite at face time {:.3e} s",
                    time[k]
                ),
            });
        }
        Ok(FaceRun {
            time,
            waves: [eps_i, er, et],
            stress,
            strain,
            plastic,
        })
    }

    /// The gauge signals of a face run at the model's wave speed, delays, gains and
    /// dispersion.
    pub(crate) fn gauges(&self, v: &RunValues, run: &FaceRun) -> Result<Histories> {
        let w = &self.waves;
        let (bi, bt) = (&self.test.incident, &self.test.transmitted);
        let ci = v.wave_speed;
        let ct = bt.wave_speed() * v.wave_speed / bi.wave_speed();
        let dr = bi.gauge_distance / ci + v.delay_reflected;
        let dt_ = bt.gauge_distance / ct + v.delay_transmitted;
        let t0 = run.time[0];
        let samples = w.incident.len();
        let moved =
            |x: &[f64], bar: &BarSetup, which: usize, c: f64, gain: f64| -> Result<Vec<f64>> {
                let y = if v.dispersion == 0.0 {
                    x.to_vec()
                } else {
                    self.curves()?[which].disperse(
                        x,
                        w.dt,
                        bar.gauge_distance,
                        bar.section.radius(),
                        c,
                        v.dispersion,
                    )
                };
                Ok(y.into_iter().map(|e| e * gain).collect())
            };
        let reflected = moved(&run.waves[1], bi, 0, ci, v.gain_incident)?;
        let transmitted = moved(&run.waves[2], bt, 1, ct, v.gain_transmitted)?;
        let out = |x: &[f64], d: f64| -> Vec<f64> {
            (0..samples)
                .map(|k| at_time(x, t0, w.dt, w.start + k as f64 * w.dt - d))
                .collect()
        };
        Ok(Histories::from_channels(
            OUTPUT_CHANNELS.iter().map(|s| s.to_string()).collect(),
            vec![out(&reflected, dr), out(&transmitted, dt_)],
            w.dt,
            w.start,
            "1",
        )?)
    }

    fn run(&self, p: &[f64]) -> Result<Histories> {
        let v = self.values(p)?;
        let faces = self.run_faces(&v)?;
        self.gauges(&v, &faces)
    }
}

/// The bars as the specimen sees them.
struct Bars {
    /// Impedances `E A / c` (kg/s).
    zi: f64,
    zt: f64,
    /// The incident bar's wave speed (m/s).
    ci: f64,
}

/// The specimen's undeformed geometry.
struct Geometry {
    length: f64,
    volume: f64,
    diameter: f64,
    /// The mass that inertia moves (kg): the held fraction of the specimen's.
    mass: f64,
}

impl Geometry {
    /// The Schmid-Boas factor `1 + mu d / (3 L)` at the current length (constant volume).
    fn friction(&self, mu: f64, length: f64) -> f64 {
        let d = self.diameter * (self.length / length).sqrt();
        1.0 + mu * d / (3.0 * length)
    }
}

/// The flow stress at plastic strain `p` and plastic rate `rate` (1/s).
fn flow(v: &RunValues, p: f64, rate: f64) -> f64 {
    let hard = v.a + v.b * p.max(0.0).powf(v.n);
    hard * (1.0 + v.rate_sensitivity * rate.max(1.0).ln())
}

/// The derivative of the flow stress along a step's plastic increment `dp` (plastic strain
/// `p`, step `h`).
fn flow_slope(v: &RunValues, p: f64, dp: f64, h: f64) -> f64 {
    let p = p.max(1e-300);
    let rate = dp / h;
    let factor = 1.0 + v.rate_sensitivity * rate.max(1.0).ln();
    let hard = v.a + v.b * p.powf(v.n);
    let dhard = v.b * v.n * p.powf(v.n - 1.0);
    let dfactor = if rate > 1.0 {
        v.rate_sensitivity / dp
    } else {
        0.0
    };
    dhard * factor + hard * dfactor
}

/// The plastic increment `dp` in `[0, hi]` where the falling `stress(dp)` (slope `-slope`)
/// meets the flow stress from plastic strain `p` over a step `h`: Newton's method kept in
/// the bracket (bisection when it would leave it).
fn return_to_flow(
    v: &RunValues,
    p: f64,
    h: f64,
    hi: f64,
    stress: impl Fn(f64) -> f64,
    slope: f64,
) -> Result<f64> {
    let res = |dp: f64| stress(dp) - flow(v, p + dp, dp / h);
    let (mut lo, mut hi) = (0.0, hi);
    if !(hi > 0.0 && res(hi) < 0.0) {
        return Err(ModelsError::Numerical {
            what: "Kolsky specimen".into(),
            message: format!("the flow stress cannot be met in a step (plastic strain {p:.4e})"),
        });
    }
    let mut dp = 0.5 * hi;
    for _ in 0..100 {
        let r = res(dp);
        if r > 0.0 {
            lo = dp;
        } else {
            hi = dp;
        }
        let d = -slope - flow_slope(v, p + dp, dp, h);
        let newton = dp - r / d;
        let next = if newton > lo && newton < hi && d < 0.0 {
            newton
        } else {
            0.5 * (lo + hi)
        };
        let done = (next - dp).abs() <= 1e-14 * next.abs().max(1e-300) || hi - lo <= 1e-16 * hi;
        dp = next;
        if done {
            break;
        }
    }
    Ok(dp)
}

/// The specimen: quasi-static (one stress) or with inertia (elements through its length).
enum Specimen {
    Lumped(Lumped),
    Elements(Elements),
}

impl Specimen {
    /// The largest stable and accurate sub-step (s).
    fn max_step(&self, v: &RunValues, bars: &Bars, g: &Geometry) -> f64 {
        match self {
            Specimen::Lumped(s) => {
                let area = g.volume / s.length;
                let k = area * g.friction(v.friction, s.length) * (1.0 / bars.zi + 1.0 / bars.zt);
                // A tenth of the elastic time constant L / (E_s K).
                0.1 * s.length / (v.modulus * k)
            }
            Specimen::Elements(e) => e.max_step(v, bars, g),
        }
    }

    /// One sub-step under the incident face wave `e_in`; returns the face forces (N).
    fn step(
        &mut self,
        v: &RunValues,
        bars: &Bars,
        g: &Geometry,
        h: f64,
        e_in: f64,
    ) -> Result<(f64, f64)> {
        match self {
            Specimen::Lumped(s) => s.step(v, bars, g, h, e_in),
            Specimen::Elements(e) => e.step(v, bars, g, h, e_in),
        }
    }

    /// Stress (Pa), true strain and plastic strain of the specimen as a whole.
    fn measures(&self, g: &Geometry) -> (f64, f64, f64) {
        match self {
            Specimen::Lumped(s) => (s.sigma, (g.length / s.length).ln(), s.plastic),
            Specimen::Elements(e) => e.measures(g),
        }
    }
}

/// The quasi-static specimen.
#[derive(Debug, Clone, Copy)]
struct Lumped {
    /// True stress (Pa).
    sigma: f64,
    /// Plastic strain.
    plastic: f64,
    /// Current length (m).
    length: f64,
}

impl Lumped {
    fn step(
        &mut self,
        v: &RunValues,
        bars: &Bars,
        g: &Geometry,
        h: f64,
        e_in: f64,
    ) -> Result<(f64, f64)> {
        let drive = 2.0 * bars.ci * e_in;
        let l = self.length;
        let phi = g.friction(v.friction, l);
        let area = g.volume / l;
        let k = area * phi * (1.0 / bars.zi + 1.0 / bars.zt);
        let e = v.modulus;
        // Elastic: dsigma/dt = (E / L) (drive - K sigma), solved exactly over the step.
        let sig_inf = drive / k;
        let decay = (-h * e * k / l).exp();
        let trial = sig_inf + (self.sigma - sig_inf) * decay;
        let (sigma, dp) = if trial <= flow(v, self.plastic, 0.0) {
            (trial.max(0.0), 0.0)
        } else {
            // Backward Euler: sigma(dp) = (sigma_n + E (h drive / L - dp)) / (1 + E h K / L).
            let gk = 1.0 + e * h * k / l;
            let sigma_n = self.sigma;
            let stress = |dp: f64| (sigma_n + e * (h * drive / l - dp)) / gk;
            let dp = return_to_flow(
                v,
                self.plastic,
                h,
                sigma_n / e + h * drive / l,
                stress,
                e / gk,
            )?;
            (stress(dp), dp)
        };
        // The strain increment the bars impose at the new force.
        let deps = h * (drive - k * sigma) / l;
        self.sigma = sigma;
        self.plastic += dp;
        self.length = l * (-deps).exp();
        // The force on the section and friction factor at the step's end.
        let force = sigma * g.volume / self.length * g.friction(v.friction, self.length);
        Ok((force, force))
    }
}

/// Elements through the specimen's length.
const ELEMENTS: usize = 4;

/// The specimen with inertia: `ELEMENTS` elastic-plastic elements, lumped nodal masses,
/// the bars as impedances at its faces (`F_1 = 2 E_i A_i eps_I - Z_i v_0`, `F_2 = Z_t v_N`,
/// neither negative), explicit (symplectic Euler) in time but for the faces' dashpots.
#[derive(Debug, Clone)]
struct Elements {
    /// Nodal displacements towards the transmitted bar (m) and velocities (m/s).
    u: [f64; ELEMENTS + 1],
    vel: [f64; ELEMENTS + 1],
    /// Element stresses (Pa, compression positive) and plastic strains.
    sigma: [f64; ELEMENTS],
    plastic: [f64; ELEMENTS],
    /// Element lengths at the last step (m).
    length: [f64; ELEMENTS],
}

impl Elements {
    fn new(g: &Geometry) -> Elements {
        Elements {
            u: [0.0; ELEMENTS + 1],
            vel: [0.0; ELEMENTS + 1],
            sigma: [0.0; ELEMENTS],
            plastic: [0.0; ELEMENTS],
            length: [g.length / ELEMENTS as f64; ELEMENTS],
        }
    }

    fn masses(g: &Geometry) -> [f64; ELEMENTS + 1] {
        let m = g.mass / ELEMENTS as f64;
        let mut out = [m; ELEMENTS + 1];
        out[0] = 0.5 * m;
        out[ELEMENTS] = 0.5 * m;
        out
    }

    fn max_step(&self, v: &RunValues, bars: &Bars, g: &Geometry) -> f64 {
        let m = Elements::masses(g);
        let l: f64 = self.length.iter().sum();
        let area = g.volume / l;
        let le = self.length.iter().fold(f64::INFINITY, |a, b| a.min(*b));
        // Within the elements' stability limit 2 sqrt(m / k), and resolving the faces'
        // relaxation on the bars' dashpots, m / Z, down to a 25th of that limit (the
        // dashpots are integrated implicitly, so a lighter face stays stable).
        let k_el = v.modulus * area / le;
        let wave = 2.0 * (m[1].min(m[0]) / k_el).sqrt();
        let dash = 2.0 * m[0] / bars.zi.max(bars.zt);
        0.4 * wave.min(dash.max(wave / 25.0))
    }

    fn step(
        &mut self,
        v: &RunValues,
        bars: &Bars,
        g: &Geometry,
        h: f64,
        e_in: f64,
    ) -> Result<(f64, f64)> {
        let m = Elements::masses(g);
        let l: f64 = self.length.iter().sum();
        let phi = g.friction(v.friction, l);
        let mut inner = [0.0; ELEMENTS + 1];
        for e in 0..ELEMENTS {
            let area = g.volume / (ELEMENTS as f64 * self.length[e]);
            let fe = self.sigma[e] * area * phi;
            inner[e] -= fe;
            inner[e + 1] += fe;
        }
        // The faces' dashpots (the bars) implicitly, so that light face masses stay stable;
        // a bar that would pull on the specimen leaves it instead.
        let last = ELEMENTS;
        let drive = 2.0 * bars.zi * bars.ci * e_in;
        let mut v0 = (m[0] * self.vel[0] + h * (drive + inner[0])) / (m[0] + h * bars.zi);
        let mut f1 = drive - bars.zi * v0;
        if f1 < 0.0 {
            f1 = 0.0;
            v0 = self.vel[0] + h * inner[0] / m[0];
        }
        let mut vn = (m[last] * self.vel[last] + h * inner[last]) / (m[last] + h * bars.zt);
        let mut f2 = bars.zt * vn;
        if f2 < 0.0 {
            f2 = 0.0;
            vn = self.vel[last] + h * inner[last] / m[last];
        }
        for j in 0..=ELEMENTS {
            self.vel[j] = if j == 0 {
                v0
            } else if j == last {
                vn
            } else {
                self.vel[j] + h * inner[j] / m[j]
            };
            self.u[j] += h * self.vel[j];
        }
        let l0 = g.length / ELEMENTS as f64;
        for e in 0..ELEMENTS {
            let new_len = l0 + self.u[e + 1] - self.u[e];
            if new_len <= 0.0 {
                return Err(ModelsError::Numerical {
                    what: "Kolsky specimen".into(),
                    message: format!("element {e} collapsed"),
                });
            }
            let deps = (self.length[e] / new_len).ln();
            self.length[e] = new_len;
            let trial = self.sigma[e] + v.modulus * deps;
            if trial <= flow(v, self.plastic[e], 0.0) {
                self.sigma[e] = trial;
            } else {
                let stress = |dp: f64| trial - v.modulus * dp;
                let dp =
                    return_to_flow(v, self.plastic[e], h, trial / v.modulus, stress, v.modulus)?;
                self.sigma[e] = stress(dp);
                self.plastic[e] += dp;
            }
        }
        Ok((f1, f2))
    }

    fn measures(&self, g: &Geometry) -> (f64, f64, f64) {
        let l: f64 = self.length.iter().sum();
        let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
        (mean(&self.sigma), (g.length / l).ln(), mean(&self.plastic))
    }
}

impl Model for KolskyModel {
    fn space(&self) -> &ParameterSpace {
        &self.space
    }

    fn simulate(&self, params: &[f64]) -> impactcal_core::Result<Histories> {
        self.run(params).map_err(CoreError::from)
    }
}

impl Enrichable for KolskyModel {
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

    fn enrich(&self, added: &[Parameter]) -> impactcal_core::Result<Self> {
        Ok(KolskyModel {
            space: impactcal_core::enrich::enriched_space(self, added)?,
            ..self.clone()
        })
    }

    fn at_condition(&self, set: &[(String, f64)]) -> impactcal_core::Result<Self> {
        let mut out = self.clone();
        for (name, value) in set {
            let Some(i) = HELD.iter().position(|h| h.0 == name) else {
                return Err(CoreError::invalid_option(
                    "condition",
                    name,
                    format!(
                        "not a held quantity of the Kolsky bar model ({})",
                        HELD.map(|h| h.0).join(", ")
                    ),
                ));
            };
            match self.candidates().iter().find(|c| c.name() == name) {
                Some(c) => c.check_value(*value)?,
                None => {
                    return Err(CoreError::invalid_option(
                        "condition",
                        name,
                        "a parameter of the model; a point sets it",
                    ));
                }
            }
            out.held[i] = *value;
        }
        Ok(out)
    }

    fn describe(&self, name: &str) -> Option<(String, String)> {
        let nuisance = |what: &str| Some(("nuisance".to_string(), what.to_string()));
        match name {
            "A" | "B" | "n" => Some((
                "material".into(),
                format!("hardening law A + B eps_p^n: {name}"),
            )),
            "modulus" => Some(("material".into(), "effective specimen modulus".into())),
            "wave_speed" => nuisance("the bars' wave speed"),
            "delay_reflected" => nuisance("trigger offset of the reflected wave"),
            "delay_transmitted" => nuisance("trigger offset of the transmitted wave"),
            _ => HELD
                .iter()
                .find(|h| h.0 == name)
                .map(|h| (h.5.to_string(), h.6.to_string())),
        }
    }
}

impl KolskyModel {
    /// The names of the nuisance terms among the declared parameters.
    pub fn nuisance() -> [&'static str; 3] {
        NUISANCE
    }
}
