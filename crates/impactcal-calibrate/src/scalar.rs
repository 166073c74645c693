//! The scalar test form: a test that is a handful of named scalars (an intrusion, a peak
//! force, an energy, a final velocity...), each with its own scale, rather than time
//! histories on impact shapes.
//!
//! With `y_k` the test's value of scalar `k`, `sigma_k > 0` its scale (the spread of the
//! test, a stated uncertainty, or the spread the parameters make) and `s_k(p)` the model's
//! value at parameters `p`, the misfit is
//!
//! `J(p) = sum_k ((s_k(p) - y_k) / sigma_k)^2`,
//!
//! a sum of squared normalised errors (a chi-square when `sigma_k` is the test's standard
//! uncertainty). [`calibrate`] fits one surrogate per scalar to the model's runs (the
//! study's choice among the ERBF, classic RBF and smoothing cubic surrogates by
//! leave-one-out, [`crate::study::surrogates::choose`]) and minimises `J` of the surrogates
//! by CORS-RBF over the parameter space, warm-started from the runs; the errors per scalar
//! at the nominal point (before) and at the calibrated point (after) come with it. A run of
//! the model at the calibrated point, judged by [`ScalarTest::errors`], confirms them.

use std::collections::BTreeMap;

use faer::Mat;
use impactcal_core::ParameterSpace;
use impactcal_cors::{Cors, CorsOptions, Transform};
use serde::{Deserialize, Serialize};

use crate::error::{CalibrateError, Result};
use crate::study::surrogates::{SurrogateChoice, choose};

/// One scalar of a test: its name, measured value and scale.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scalar {
    /// The name the model's outputs carry too (`dmax`, `fmax`, ...).
    pub name: String,
    /// The test's value.
    pub value: f64,
    /// The scale its error is measured in (positive, in the value's units).
    pub scale: f64,
}

impl Scalar {
    /// A scalar named `name` of value `value` and scale `scale`.
    pub fn new(name: impl Into<String>, value: f64, scale: f64) -> Self {
        Scalar {
            name: name.into(),
            value,
            scale,
        }
    }
}

/// A test made of named scalars, checked: unique non-blank names, finite values, finite
/// positive scales, at least one scalar.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScalarTest {
    scalars: Vec<Scalar>,
}

/// The error of the model on one scalar.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScalarError {
    /// The scalar.
    pub name: String,
    /// The test's value `y`.
    pub test: f64,
    /// Its scale `sigma`.
    pub scale: f64,
    /// The model's value `s`.
    pub model: f64,
    /// `(s - y) / sigma`.
    pub normalised: f64,
    /// `s / y - 1`; `None` when `y` is 0.
    pub relative: Option<f64>,
}

impl ScalarTest {
    /// The test of `scalars`, in the order given.
    ///
    /// # Errors
    /// [`CalibrateError::Study`] for no scalar, a blank name or a name given twice;
    /// [`CalibrateError::NonFiniteScalar`] for a value or scale that is NaN or infinite;
    /// [`CalibrateError::NonPositiveScale`] for a scale `<= 0`.
    pub fn new(scalars: Vec<Scalar>) -> Result<Self> {
        if scalars.is_empty() {
            return Err(CalibrateError::study("scalar test", "no scalar given"));
        }
        for (i, s) in scalars.iter().enumerate() {
            if s.name.trim().is_empty() {
                return Err(CalibrateError::study(
                    format!("scalar test, entry {}", i + 1),
                    "blank name",
                ));
            }
            if scalars[..i].iter().any(|o| o.name == s.name) {
                return Err(CalibrateError::study(
                    format!("scalar `{}`", s.name),
                    "given twice in the test",
                ));
            }
            for (what, v) in [("the test's value", s.value), ("the scale", s.scale)] {
                if !v.is_finite() {
                    return Err(CalibrateError::NonFiniteScalar {
                        scalar: s.name.clone(),
                        origin: what.into(),
                        value: v,
                    });
                }
            }
            if s.scale <= 0.0 {
                return Err(CalibrateError::NonPositiveScale {
                    scalar: s.name.clone(),
                    scale: s.scale,
                });
            }
        }
        Ok(ScalarTest { scalars })
    }

    /// The scalars, in order.
    pub fn scalars(&self) -> &[Scalar] {
        &self.scalars
    }

    /// The names, in order.
    pub fn names(&self) -> Vec<&str> {
        self.scalars.iter().map(|s| s.name.as_str()).collect()
    }

    /// The error per scalar of the model outputs `outputs` (name -> value; names the test
    /// does not have are ignored), in the test's order. `origin` names the outputs in
    /// messages (`run at the calibrated point`).
    ///
    /// # Errors
    /// [`CalibrateError::MissingScalar`] when a scalar of the test is absent from
    /// `outputs`; [`CalibrateError::NonFiniteScalar`] for a NaN or infinite output.
    pub fn errors(
        &self,
        outputs: &BTreeMap<String, f64>,
        origin: &str,
    ) -> Result<Vec<ScalarError>> {
        self.scalars
            .iter()
            .map(|s| {
                let model = *outputs
                    .get(&s.name)
                    .ok_or_else(|| CalibrateError::MissingScalar {
                        scalar: s.name.clone(),
                        origin: origin.into(),
                        available: outputs.keys().cloned().collect(),
                    })?;
                if !model.is_finite() {
                    return Err(CalibrateError::NonFiniteScalar {
                        scalar: s.name.clone(),
                        origin: origin.into(),
                        value: model,
                    });
                }
                Ok(ScalarError {
                    name: s.name.clone(),
                    test: s.value,
                    scale: s.scale,
                    model,
                    normalised: (model - s.value) / s.scale,
                    relative: (s.value != 0.0).then(|| model / s.value - 1.0),
                })
            })
            .collect()
    }

    /// `J = sum_k ((s_k - y_k) / sigma_k)^2` of `outputs`.
    ///
    /// # Errors
    /// As [`errors`](Self::errors).
    pub fn misfit(&self, outputs: &BTreeMap<String, f64>, origin: &str) -> Result<f64> {
        Ok(misfit_of(&self.errors(outputs, origin)?))
    }
}

/// `sum_k normalised_k^2` of errors per scalar.
pub fn misfit_of(errors: &[ScalarError]) -> f64 {
    errors.iter().map(|e| e.normalised * e.normalised).sum()
}

/// Distance in the unit box below which a run is taken to be at the nominal point, and the
/// nominal point is not added to the search's warm start.
pub const NOMINAL_TOLERANCE: f64 = 1e-9;

/// Runs of the model: a point of the parameter space and the model's scalar outputs there.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScalarRuns {
    /// The output names (the columns of `values`).
    pub names: Vec<String>,
    /// One point per run (in the space's order and units).
    pub points: Vec<Vec<f64>>,
    /// One row of outputs per run, in the order of `names`.
    pub values: Vec<Vec<f64>>,
}

/// Options of [`calibrate`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScalarOptions {
    /// Surrogate evaluations CORS-RBF makes after its warm start (default 200).
    pub budget: usize,
    /// Points proposed at a time (default 4).
    pub batch: usize,
    /// Seed of CORS-RBF (default 0).
    pub seed: u64,
}

impl Default for ScalarOptions {
    fn default() -> Self {
        ScalarOptions {
            budget: 200,
            batch: 4,
            seed: 0,
        }
    }
}

/// The surrogate of one scalar.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScalarSurrogate {
    /// The scalar.
    pub name: String,
    /// The leave-one-out table and the kind chosen.
    pub choice: SurrogateChoice,
}

/// The outcome of [`calibrate`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScalarCalibration {
    /// Runs behind the surrogates.
    pub runs: usize,
    /// Surrogate evaluations of the search (warm start included).
    pub evaluations: usize,
    /// The surrogate of each scalar, in the test's order.
    pub surrogates: Vec<ScalarSurrogate>,
    /// The nominal point, by parameter.
    pub nominal: BTreeMap<String, f64>,
    /// The calibrated point (the best evaluation of `J` on the surrogates), by parameter.
    pub calibrated: BTreeMap<String, f64>,
    /// The same point in the space's order.
    pub calibrated_point: Vec<f64>,
    /// Errors of the surrogates at the nominal point.
    pub before: Vec<ScalarError>,
    /// Errors of the surrogates at the calibrated point.
    pub after: Vec<ScalarError>,
    /// `J` of the surrogates at the nominal point.
    pub misfit_before: f64,
    /// `J` of the surrogates at the calibrated point.
    pub misfit_after: f64,
}

/// Calibrates the parameters of `space` to `test` from the model's `runs`: one surrogate per
/// scalar of the test (chosen by leave-one-out among the study's kinds), and CORS-RBF on
/// `ln J` of the surrogates (a sum of squares spans decades near its minimum), its
/// perturbation horizon set to the whole search, warm-started from the runs' points and the
/// nominal point (unless a run lies within [`NOMINAL_TOLERANCE`] of it); `options.budget`
/// further evaluations in batches of `options.batch`.
/// Scalars of the runs the test does not name are ignored.
///
/// # Errors
/// [`CalibrateError::UnknownScalar`] when the test names a scalar the runs lack;
/// [`CalibrateError::NonFiniteScalar`] for a NaN or infinite output of a run;
/// [`CalibrateError::Study`] for runs of the wrong shape (points not of the space's
/// dimension, rows not as long as `names`, a name given twice), fewer runs than the
/// dimension plus two, a zero budget or batch, or no surrogate that can be fitted; CORS
/// errors.
pub fn calibrate(
    space: &ParameterSpace,
    test: &ScalarTest,
    runs: &ScalarRuns,
    options: &ScalarOptions,
) -> Result<ScalarCalibration> {
    let d = space.dim();
    check_runs(space, runs)?;
    if options.budget == 0 || options.batch == 0 {
        return Err(CalibrateError::study(
            "scalar calibration",
            format!(
                "budget {} and batch {} must both be at least 1",
                options.budget, options.batch
            ),
        ));
    }
    let columns = test
        .scalars()
        .iter()
        .map(|s| {
            runs.names.iter().position(|n| *n == s.name).ok_or_else(|| {
                CalibrateError::UnknownScalar {
                    scalar: s.name.clone(),
                    available: runs.names.clone(),
                }
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let n = runs.points.len();
    let points = Mat::from_fn(n, d, |i, j| runs.points[i][j]);
    let mut surrogates = Vec::new();
    let mut fitted = Vec::new();
    for (s, &c) in test.scalars().iter().zip(&columns) {
        let values = Mat::from_fn(n, 1, |i, _| runs.values[i][c]);
        let (choice, f) = choose(space, points.as_ref(), values.as_ref())
            .map_err(|e| e.with_subject(|w| format!("scalar `{}`: {w}", s.name)))?;
        surrogates.push(ScalarSurrogate {
            name: s.name.clone(),
            choice,
        });
        fitted.push(f);
    }
    let predict = |pts: &[Vec<f64>]| -> Result<Vec<BTreeMap<String, f64>>> {
        let m = Mat::from_fn(pts.len(), d, |i, j| pts[i][j]);
        let mut out = vec![BTreeMap::new(); pts.len()];
        for (s, f) in test.scalars().iter().zip(&fitted) {
            let y = f.predict_batch(m.as_ref())?;
            for (i, o) in out.iter_mut().enumerate() {
                o.insert(s.name.clone(), y[(i, 0)]);
            }
        }
        Ok(out)
    };
    let objective = |pts: &[Vec<f64>]| -> Result<Vec<f64>> {
        predict(pts)?
            .iter()
            .map(|o| {
                // A surrogate that returns NaN is a failed evaluation to CORS, not an error.
                match test.misfit(o, "the surrogates") {
                    Ok(j) => Ok(j.max(1e-300)),
                    Err(CalibrateError::NonFiniteScalar { .. }) => Ok(f64::NAN),
                    Err(e) => Err(e),
                }
            })
            .collect()
    };
    let nominal = space.nominal();
    // The nominal point first unless a run is already there (CORS refuses a point twice).
    let unit_nominal = space.to_unit(&nominal)?;
    let mut run_at_nominal = false;
    for p in &runs.points {
        let u = space.to_unit(p)?;
        let d2: f64 = u
            .iter()
            .zip(&unit_nominal)
            .map(|(a, b)| (a - b).powi(2))
            .sum();
        run_at_nominal |= d2.sqrt() < NOMINAL_TOLERANCE;
    }
    let mut start = if run_at_nominal {
        Vec::new()
    } else {
        vec![nominal.clone()]
    };
    start.extend(runs.points.iter().cloned());
    let cors_options = CorsOptions {
        transform: Transform::Log,
        budget: Some(start.len() + options.budget),
        ..CorsOptions::with_seed(options.seed)
    };
    let mut cors = Cors::new(space.clone(), cors_options)?;
    cors.warm_start_rows(&start, &objective(&start)?)?;
    let mut evaluations = start.len();
    let mut made = 0;
    while made < options.budget {
        let suggestions = cors.suggest(options.batch.min(options.budget - made))?;
        if suggestions.is_empty() {
            break;
        }
        let pts: Vec<Vec<f64>> = suggestions.iter().map(|s| s.x.clone()).collect();
        for (s, v) in suggestions.iter().zip(objective(&pts)?) {
            cors.tell(s.id, v)?;
        }
        made += pts.len();
        evaluations += pts.len();
    }
    let best = cors
        .best()
        .map(|e| e.x.clone())
        .ok_or_else(|| CalibrateError::study("scalar calibration", "no finite misfit"))?;
    let at = predict(&[nominal.clone(), best.clone()])?;
    let before = test.errors(&at[0], "the surrogates at the nominal point")?;
    let after = test.errors(&at[1], "the surrogates at the calibrated point")?;
    let by_name = |x: &[f64]| -> BTreeMap<String, f64> {
        space
            .names()
            .iter()
            .zip(x)
            .map(|(n, v)| (n.to_string(), *v))
            .collect()
    };
    Ok(ScalarCalibration {
        runs: n,
        evaluations,
        surrogates,
        nominal: by_name(&nominal),
        calibrated: by_name(&best),
        calibrated_point: best,
        misfit_before: misfit_of(&before),
        misfit_after: misfit_of(&after),
        before,
        after,
    })
}

fn check_runs(space: &ParameterSpace, runs: &ScalarRuns) -> Result<()> {
    let d = space.dim();
    for (i, n) in runs.names.iter().enumerate() {
        if runs.names[..i].contains(n) {
            return Err(CalibrateError::study(
                format!("scalar runs, output `{n}`"),
                "named twice",
            ));
        }
    }
    if runs.points.len() != runs.values.len() {
        return Err(CalibrateError::study(
            "scalar runs",
            format!(
                "{} points but {} rows of outputs",
                runs.points.len(),
                runs.values.len()
            ),
        ));
    }
    if runs.points.len() < d + 2 {
        return Err(CalibrateError::study(
            "scalar runs",
            format!(
                "{} runs; the surrogates of {d} parameters need at least {}",
                runs.points.len(),
                d + 2
            ),
        ));
    }
    for (i, (p, v)) in runs.points.iter().zip(&runs.values).enumerate() {
        if p.len() != d {
            return Err(CalibrateError::study(
                format!("scalar run {i}"),
                format!("{} parameters, the space has {d}", p.len()),
            ));
        }
        if v.len() != runs.names.len() {
            return Err(CalibrateError::study(
                format!("scalar run {i}"),
                format!("{} outputs, {} names", v.len(), runs.names.len()),
            ));
        }
        if let Some(j) = v.iter().position(|x| !x.is_finite()) {
            return Err(CalibrateError::NonFiniteScalar {
                scalar: runs.names[j].clone(),
                origin: format!("run {i}"),
                value: v[j],
            });
        }
    }
    Ok(())
}
