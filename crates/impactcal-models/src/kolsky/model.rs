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
//! **Outputs.** Channels `reflected` (the reflected wave at the incident gauge) and
//! `transmitted` (at the transmitted gauge), strains compression positive, on the record's
//! time base, zero outside the waves' windows; [`KolskyModel::measured`] gives the record's
//! own waves on the same base, for comparison.

use impactcal_core::{CoreError, Histories, Model, Parameter, ParameterSpace};

use crate::error::{ModelsError, Result};
use crate::kolsky::form::KolskyTest;
use crate::kolsky::waves::{Separated, at_time, separate};

/// The model's output channels.
pub const OUTPUT_CHANNELS: [&str; 2] = ["reflected", "transmitted"];

/// The declared parameters, in order, with their default ranges and nominals: the material
/// (`A`, `B`, `n`, `modulus`) and the nuisance terms (`wave_speed` is set around the test's).
const DECLARED: [(&str, f64, f64, f64, &str); 6] = [
    ("A", 10.0, 1000.0, 100.0, "MPa"),
    ("B", 0.0, 2000.0, 300.0, "MPa"),
    ("n", 0.05, 1.0, 0.5, "1"),
    ("modulus", 5.0, 300.0, 50.0, "GPa"),
    ("delay_reflected", -10.0, 10.0, 0.0, "us"),
    ("delay_transmitted", -10.0, 10.0, 0.0, "us"),
];

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
    pub rate_sensitivity: f64,
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
}

impl KolskyModel {
    /// The model of `test`, with the default parameter ranges (the material's wide enough
    /// for metals from annealed copper to steels; `wave_speed` within 5 % of the test's).
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
            rate_sensitivity: 0.0,
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
        let (zi, zt) = (bi.modulus * bi.area() / ci, bt.modulus * bt.area() / ct);
        let (ki, kt) = (bi.modulus * bi.area(), bt.modulus * bt.area());
        let delay = bi.gauge_distance / ci;
        let t0 = w.start + w.window_start as f64 * w.dt + delay;
        let n = w.window_len;
        let time: Vec<f64> = (0..n).map(|k| t0 + k as f64 * w.dt).collect();
        let eps_i: Vec<f64> = time
            .iter()
            .map(|t| at_time(&w.incident, w.start, w.dt, t - delay))
            .collect();
        let sp = &self.test.specimen;
        let (a0, l0) = (sp.section.area(), sp.length);
        let mut s = Specimen {
            sigma: 0.0,
            plastic: 0.0,
            length: l0,
        };
        let (mut stress, mut strain, mut plastic) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let (mut er, mut et) = (vec![0.0; n], vec![0.0; n]);
        let inv_z = 1.0 / zi + 1.0 / zt;
        for k in 0..n {
            if k > 0 {
                // Sub-steps of at most a tenth of the elastic time constant.
                let area = a0 * l0 / s.length;
                let tau = s.length / (v.modulus * area * inv_z);
                let subs = ((w.dt / (0.1 * tau)).ceil() as usize).clamp(1, 10_000);
                let h = w.dt / subs as f64;
                for j in 0..subs {
                    let f = (j as f64 + 0.5) / subs as f64;
                    let e_in = eps_i[k - 1] * (1.0 - f) + eps_i[k] * f;
                    s.step(v, h, 2.0 * ci * e_in, inv_z, a0 * l0)?;
                }
            }
            let force = s.sigma * a0 * l0 / s.length;
            et[k] = force / kt;
            er[k] = force / ki - eps_i[k];
            stress[k] = s.sigma;
            strain[k] = (l0 / s.length).ln();
            plastic[k] = s.plastic;
        }
        Ok(FaceRun {
            time,
            waves: [eps_i, er, et],
            stress,
            strain,
            plastic,
        })
    }

    /// The gauge signals of a face run at the model's wave speed and delays.
    pub(crate) fn gauges(&self, v: &RunValues, run: &FaceRun) -> Result<Histories> {
        let w = &self.waves;
        let (bi, bt) = (&self.test.incident, &self.test.transmitted);
        let ci = v.wave_speed;
        let ct = bt.wave_speed() * v.wave_speed / bi.wave_speed();
        let dr = bi.gauge_distance / ci + v.delay_reflected;
        let dt_ = bt.gauge_distance / ct + v.delay_transmitted;
        let t0 = run.time[0];
        let samples = w.incident.len();
        let out = |x: &[f64], d: f64| -> Vec<f64> {
            (0..samples)
                .map(|k| at_time(x, t0, w.dt, w.start + k as f64 * w.dt - d))
                .collect()
        };
        Ok(Histories::from_channels(
            OUTPUT_CHANNELS.iter().map(|s| s.to_string()).collect(),
            vec![out(&run.waves[1], dr), out(&run.waves[2], dt_)],
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

/// The specimen's state.
#[derive(Debug, Clone, Copy)]
struct Specimen {
    /// True stress (Pa).
    sigma: f64,
    /// Plastic strain.
    plastic: f64,
    /// Current length (m).
    length: f64,
}

impl Specimen {
    /// The flow stress at plastic strain `p` and plastic rate `rate`.
    fn flow(v: &RunValues, p: f64, rate: f64) -> f64 {
        let hard = v.a + v.b * p.max(0.0).powf(v.n);
        hard * (1.0 + v.rate_sensitivity * rate.max(1.0).ln())
    }

    /// The derivative of the flow stress along a step's plastic increment `dp` (plastic
    /// strain `p`, step `h`).
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

    /// One step of length `h` under the drive `2 c_i eps_I` (m/s); `inv_z` is
    /// `1 / Z_i + 1 / Z_t`, `volume` the specimen's.
    fn step(&mut self, v: &RunValues, h: f64, drive: f64, inv_z: f64, volume: f64) -> Result<()> {
        let l = self.length;
        let area = volume / l;
        let k = area * inv_z;
        let e = v.modulus;
        // Elastic: dsigma/dt = (E / L) (drive - K sigma), solved exactly over the step.
        let sig_inf = drive / k;
        let decay = (-h * e * k / l).exp();
        let trial = sig_inf + (self.sigma - sig_inf) * decay;
        let (sigma, dp) = if trial <= Specimen::flow(v, self.plastic, 0.0) {
            (trial.max(0.0), 0.0)
        } else {
            // Backward Euler: sigma(dp) = (sigma_n + E (h drive / L - dp)) / (1 + E h K / L)
            // falls with dp; the flow stress rises: one root in (0, dp_max].
            let g = 1.0 + e * h * k / l;
            let sig = |dp: f64| (self.sigma + e * (h * drive / l - dp)) / g;
            let res = |dp: f64| sig(dp) - Specimen::flow(v, self.plastic + dp, dp / h);
            let (mut lo, mut hi) = (0.0, self.sigma / e + h * drive / l);
            if !(hi > 0.0 && res(hi) < 0.0) {
                return Err(ModelsError::Numerical {
                    what: "Kolsky specimen".into(),
                    message: format!(
                        "the flow stress cannot be met in a step (stress {:.4e} Pa, plastic \
                         strain {:.4e})",
                        self.sigma, self.plastic
                    ),
                });
            }
            // Newton's method kept inside the bracket (bisection when it would leave it).
            let mut dp = 0.5 * hi;
            for _ in 0..100 {
                let r = res(dp);
                if r > 0.0 {
                    lo = dp;
                } else {
                    hi = dp;
                }
                let slope = -e / g - Specimen::flow_slope(v, self.plastic + dp, dp, h);
                let newton = dp - r / slope;
                let next = if newton > lo && newton < hi && slope < 0.0 {
                    newton
                } else {
                    0.5 * (lo + hi)
                };
                if (next - dp).abs() <= 1e-14 * next.abs().max(1e-300) || hi - lo <= 1e-16 * hi {
                    dp = next;
                    break;
                }
                dp = next;
            }
            (sig(dp), dp)
        };
        // The strain increment the bars impose at the new force.
        let deps = h * (drive - k * sigma) / l;
        self.sigma = sigma;
        self.plastic += dp;
        self.length = l * (-deps).exp();
        Ok(())
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
