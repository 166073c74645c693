//! Surrogates of whole histories from the ensemble: ERBF (the paper's) and the classic RBF
//! kernels, each judged by its leave-one-out (LOO) error, plus a smoothing cubic RBF whose
//! regularisation `lambda` is chosen by LOO over a grid (for ensembles that carry the model's
//! own noise, which an interpolant would reproduce). Every kind is also fitted in the
//! impact-shape basis of the ensemble (coordinates on its shapes, histories rebuilt; the
//! shape count chosen by the truncation and LOO errors), and that cheaper form is chosen
//! whenever its LOO error is within [`SHAPES_MARGIN`] of the best.

use std::collections::BTreeMap;

use faer::{Mat, MatRef};
use impactcal_core::ParameterSpace;
use impactcal_erbf::{
    ErrorSummary, FitOptions, LooMethod, OutputBasis, RbfInterpolant, RbfOptions,
    ResponseSurrogate, SurrogateKind, SurrogateModel, Tuning,
};
use serde::{Deserialize, Serialize};

use crate::error::{CalibrateError, Result};

/// The interpolating kinds tried, in order.
pub const KINDS: [SurrogateKind; 5] = [
    SurrogateKind::Erbf,
    SurrogateKind::Cubic,
    SurrogateKind::ThinPlate,
    SurrogateKind::Gaussian,
    SurrogateKind::Multiquadric,
];

/// The smoothing values tried for the smoothing cubic RBF (added to the kernel diagonal of
/// the system in unit-cube inputs; 0 interpolates).
pub const LAMBDAS: [f64; 8] = [0.0, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1];

/// Suffix of the shape-basis form of a kind in the tables (`cubic-shapes`, ...).
pub const SHAPES_SUFFIX: &str = "-shapes";

/// The shape-basis form of a kind is chosen when its LOO error is at most this factor times
/// the best LOO error of all surrogates (1 %: as accurate, and cheaper to predict).
pub const SHAPES_MARGIN: f64 = 1.01;

/// Name of the smoothing surrogate in the tables.
pub const SMOOTHING: &str = "cubic-smoothing";

/// The LOO errors of every surrogate of one set of outputs and the one chosen.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurrogateChoice {
    /// LOO root mean square error over the pooled standard deviation of the outputs, per
    /// surrogate (`erbf`, `cubic`, ..., `cubic-smoothing`); a kind that could not be fitted
    /// is absent and listed in `failed`.
    pub loo_by_kind: BTreeMap<String, f64>,
    /// Kinds that could not be fitted, with the reason.
    pub failed: BTreeMap<String, String>,
    /// The surrogate with the smallest LOO error.
    pub chosen: String,
    /// Its LOO error.
    pub loo_rel_error: f64,
    /// The smoothing chosen by LOO for the smoothing surrogate.
    pub smoothing_lambda: Option<f64>,
    /// Impact shapes kept when the chosen surrogate works in the shape basis (its name
    /// ends in `-shapes`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape_count: Option<usize>,
}

/// A fitted surrogate: one of the kinds, or the smoothing cubic RBF.
#[derive(Debug, Clone)]
pub enum Fitted {
    /// An interpolating kind.
    Response(ResponseSurrogate),
    /// The smoothing cubic RBF in unit-cube inputs.
    Smoothing(ParameterSpace, RbfInterpolant),
}

impl Fitted {
    /// Predictions at raw points (`Q x d`): `Q x T`.
    ///
    /// # Errors
    /// Bad points.
    pub fn predict_batch(&self, points: MatRef<'_, f64>) -> Result<Mat<f64>> {
        Ok(match self {
            Fitted::Response(r) => r.predict_batch(points)?,
            Fitted::Smoothing(space, i) => {
                i.predict_batch(space.to_unit_matrix(points)?.as_ref())?
            }
        })
    }
}

fn name(kind: SurrogateKind) -> String {
    serde_json::to_value(kind)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_else(|| format!("{kind:?}"))
}

/// Fits every kind and the smoothing surrogate to `values` (`N x T`) at `points`
/// (`N x d`), and returns the LOO table and the surrogate with the smallest LOO error.
///
/// # Errors
/// [`CalibrateError::Study`] when no surrogate could be fitted (each kind's reason in the
/// message).
pub fn choose(
    space: &ParameterSpace,
    points: MatRef<'_, f64>,
    values: MatRef<'_, f64>,
) -> Result<(SurrogateChoice, Fitted)> {
    let mut loo = BTreeMap::new();
    let mut failed = BTreeMap::new();
    let mut best: Option<(f64, String, Fitted)> = None;
    let mut consider = |label: String, outcome: Result<(f64, Fitted)>| match outcome {
        Ok((e, f)) if e.is_finite() => {
            loo.insert(label.clone(), e);
            if best.as_ref().is_none_or(|(b, _, _)| e < *b) {
                best = Some((e, label, f));
            }
        }
        Ok((e, _)) => {
            failed.insert(label, format!("LOO error {e}"));
        }
        Err(err) => {
            failed.insert(label, err.to_string());
        }
    };
    let names: Vec<String> = (0..values.ncols()).map(|c| format!("y{c}")).collect();
    let mut shaped: Vec<(f64, String, Fitted)> = Vec::new();
    for kind in KINDS {
        for basis in [OutputBasis::Full, OutputBasis::Shapes { count: None }] {
            let options = FitOptions {
                kind,
                basis,
                tuning: Tuning::Off,
                ..FitOptions::default()
            };
            let outcome = (|| {
                let s =
                    ResponseSurrogate::fit_with(space, points, values, names.clone(), &options)?;
                let e = s.loo_errors(LooMethod::Auto)?;
                Ok((
                    ErrorSummary::new(e.as_ref(), values).relative_rms,
                    Fitted::Response(s),
                ))
            })();
            let label = match basis {
                OutputBasis::Full => name(kind),
                OutputBasis::Shapes { .. } => format!("{}{SHAPES_SUFFIX}", name(kind)),
            };
            if let (OutputBasis::Shapes { .. }, Ok((e, f))) = (basis, &outcome)
                && e.is_finite()
            {
                shaped.push((*e, label.clone(), f.clone()));
            }
            consider(label, outcome);
        }
    }
    let unit = space.to_unit_matrix(points)?;
    let mut smooth: Option<(f64, f64, RbfInterpolant)> = None;
    let mut last_error = None;
    for lambda in LAMBDAS {
        let fit = RbfInterpolant::fit(
            unit.as_ref(),
            values,
            RbfOptions::cubic().with_smoothing(lambda),
        )
        .and_then(|i| i.loo_errors(LooMethod::Closed).map(|e| (i, e)));
        match fit {
            Ok((i, e)) => {
                let r = ErrorSummary::new(e.as_ref(), values).relative_rms;
                if r.is_finite() && smooth.as_ref().is_none_or(|(b, _, _)| r < *b) {
                    smooth = Some((r, lambda, i));
                }
            }
            Err(e) => last_error = Some(e.to_string()),
        }
    }
    let smoothing_lambda = smooth.as_ref().map(|s| s.1);
    match smooth {
        Some((r, _, i)) => consider(
            SMOOTHING.into(),
            Ok((r, Fitted::Smoothing(space.clone(), i))),
        ),
        None => consider(
            SMOOTHING.into(),
            Err(CalibrateError::study(
                SMOOTHING,
                last_error.unwrap_or_default(),
            )),
        ),
    }
    let Some((mut loo_rel_error, mut chosen, mut fitted)) = best else {
        return Err(CalibrateError::study(
            "surrogates",
            format!("none could be fitted: {failed:?}"),
        ));
    };
    // The shape basis where it is as accurate: the best shape-basis form within the margin.
    if let Some((e, label, f)) = shaped
        .into_iter()
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .filter(|(e, _, _)| *e <= SHAPES_MARGIN * loo_rel_error)
    {
        (loo_rel_error, chosen, fitted) = (e, label, f);
    }
    let shape_count = match &fitted {
        Fitted::Response(r) => match r.model() {
            SurrogateModel::Components(c) => c.basis().map(|b| b.len()),
            _ => None,
        },
        Fitted::Smoothing(..) => None,
    };
    Ok((
        SurrogateChoice {
            loo_by_kind: loo,
            failed,
            chosen,
            loo_rel_error,
            smoothing_lambda,
            shape_count,
        },
        fitted,
    ))
}
