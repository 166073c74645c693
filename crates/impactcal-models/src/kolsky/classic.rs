//! The classic one- and three-wave analysis of a Kolsky bar test (Kolsky 1949, "An
//! investigation of the mechanical properties of materials at very high rates of loading",
//! Proc. Phys. Soc. B 62, 676-700; Gray 2000, "Classic split-Hopkinson pressure bar
//! testing", ASM Handbook vol. 8, Mechanical Testing and Evaluation, 462-476).
//!
//! The gauge strains (compression positive) are split into the incident `eps_I`, reflected
//! `eps_R` and transmitted `eps_T` waves ([`separate`]) and moved to the specimen faces:
//! at face time `t`, `eps_I(t - x_i / c_i)`, `eps_R(t + x_i / c_i)` and
//! `eps_T(t + x_t / c_t)` of the gauge records (linear interpolation; elastic,
//! non-dispersive bars). With the bars' moduli `E`, areas `A`, wave speeds `c`, and the
//! specimen's initial area `A_s` and length `L_s`:
//!
//! | quantity | one wave | three waves |
//! |---|---|---|
//! | face velocities | | `v_1 = c_i (eps_I - eps_R)`, `v_2 = c_t eps_T` |
//! | face forces | | `F_1 = E_i A_i (eps_I + eps_R)`, `F_2 = E_t A_t eps_T` |
//! | stress | `sigma = E_t A_t eps_T / A_s` | `sigma = (F_1 + F_2) / (2 A_s)` |
//! | strain rate | `-2 c_i eps_R / L_s` | `(v_1 - v_2) / L_s` |
//! | strain | `int rate dt` | `int rate dt` |
//!
//! Stresses and strains are engineering values, compression positive; the one-wave forms
//! assume equilibrium (`F_1 = F_2`) and, for the rate, identical bars. Equilibrium is judged
//! by the ratio of the front and back impulses, `int F_1 dt / int F_2 dt` over the window:
//! 1 for a specimen in equilibrium with correctly converted gauges (a gain wrong by a factor
//! `k` on the transmitted bar gives `1 / k`). True values follow from constant volume:
//! `eps_true = -ln(1 - e)`, `sigma_true = sigma (1 - e)`.
//!
//! The window is the incident wave's (the round trip `2 x_i / c_i`, centred on the pulse)
//! moved to the face.

use crate::error::{ModelsError, Result};
use crate::kolsky::form::KolskyTest;
use crate::kolsky::waves::{Resampling, Separated, at_time, separate};

/// The classic analysis of a test, on face time (see the module docs). All vectors have
/// one entry per sample of the window.
#[derive(Debug, Clone, PartialEq)]
pub struct ClassicAnalysis {
    /// Face time of each sample (s).
    pub time: Vec<f64>,
    /// `eps_I`, `eps_R`, `eps_T` at the faces.
    pub waves: [Vec<f64>; 3],
    /// Front force `F_1` (N).
    pub front_force: Vec<f64>,
    /// Back force `F_2` (N).
    pub back_force: Vec<f64>,
    /// One-wave stress (Pa).
    pub stress_one: Vec<f64>,
    /// Three-wave stress (Pa).
    pub stress_three: Vec<f64>,
    /// One-wave strain rate (1/s).
    pub rate_one: Vec<f64>,
    /// Three-wave strain rate (1/s).
    pub rate_three: Vec<f64>,
    /// One-wave engineering strain.
    pub strain_one: Vec<f64>,
    /// Three-wave engineering strain.
    pub strain_three: Vec<f64>,
    /// `int F_1 dt / int F_2 dt` over the window.
    pub equilibrium: f64,
    /// How the record was resampled before the analysis, if it was.
    pub resampling: Option<Resampling>,
}

impl ClassicAnalysis {
    /// Analyses a test (see the module docs).
    ///
    /// # Errors
    /// As [`separate`]; [`ModelsError::Record`] when the transmitted gauge carries no
    /// force in the window (the equilibrium ratio would divide by zero).
    pub fn of(test: &KolskyTest) -> Result<ClassicAnalysis> {
        let s = separate(test)?;
        ClassicAnalysis::of_waves(test, &s)
    }

    /// Analyses already separated waves of `test`.
    ///
    /// # Errors
    /// As [`ClassicAnalysis::of`].
    pub fn of_waves(test: &KolskyTest, s: &Separated) -> Result<ClassicAnalysis> {
        let (bi, bt) = (&test.incident, &test.transmitted);
        let (ci, ct) = (bi.wave_speed(), bt.wave_speed());
        let (di, dtr) = (bi.gauge_distance / ci, bt.gauge_distance / ct);
        let t0 = s.start + s.window_start as f64 * s.dt + di;
        let time: Vec<f64> = (0..s.window_len).map(|k| t0 + k as f64 * s.dt).collect();
        let wave = |x: &[f64], delay: f64| -> Vec<f64> {
            time.iter()
                .map(|t| at_time(x, s.start, s.dt, t + delay))
                .collect()
        };
        let ei = wave(&s.incident, -di);
        let er = wave(&s.reflected, di);
        let et = wave(&s.transmitted, dtr);
        let (ki, kt) = (bi.modulus * bi.area(), bt.modulus * bt.area());
        let a_s = test.specimen.section.area();
        let l_s = test.specimen.length;
        let front_force: Vec<f64> = ei.iter().zip(&er).map(|(i, r)| ki * (i + r)).collect();
        let back_force: Vec<f64> = et.iter().map(|t| kt * t).collect();
        let stress_one = back_force.iter().map(|f| f / a_s).collect();
        let stress_three = front_force
            .iter()
            .zip(&back_force)
            .map(|(a, b)| 0.5 * (a + b) / a_s)
            .collect();
        let rate_one: Vec<f64> = er.iter().map(|r| -2.0 * ci * r / l_s).collect();
        let rate_three: Vec<f64> = (0..time.len())
            .map(|k| (ci * (ei[k] - er[k]) - ct * et[k]) / l_s)
            .collect();
        let impulse = |f: &[f64]| trapezoid(f, s.dt).last().copied().unwrap_or(0.0);
        let back = impulse(&back_force);
        if back.abs() <= f64::MIN_POSITIVE {
            return Err(ModelsError::record(
                format!("{}: transmitted gauge", test.source),
                "carries no force in the analysis window",
            ));
        }
        Ok(ClassicAnalysis {
            equilibrium: impulse(&front_force) / back,
            strain_one: trapezoid(&rate_one, s.dt),
            strain_three: trapezoid(&rate_three, s.dt),
            time,
            waves: [ei, er, et],
            front_force,
            back_force,
            stress_one,
            stress_three,
            rate_one,
            rate_three,
            resampling: s.resampling,
        })
    }

    /// True strain and true stress of the three-wave curve (constant volume).
    pub fn true_curve(&self) -> (Vec<f64>, Vec<f64>) {
        self.strain_three
            .iter()
            .zip(&self.stress_three)
            .map(|(e, s)| (-(1.0 - e).ln(), s * (1.0 - e)))
            .unzip()
    }
}

/// The running trapezoidal integral of `y` at interval `dt`, starting at 0.
pub(crate) fn trapezoid(y: &[f64], dt: f64) -> Vec<f64> {
    let mut acc = 0.0;
    let mut out = Vec::with_capacity(y.len());
    for k in 0..y.len() {
        if k > 0 {
            acc += 0.5 * dt * (y[k - 1] + y[k]);
        }
        out.push(acc);
    }
    out
}
