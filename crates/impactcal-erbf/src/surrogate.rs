//! One type for every surrogate kind over a parameter space, with named outputs: what the
//! `impactcal surrogate` command fits, saves and loads.
//!
//! All kinds see inputs scaled to the unit cube by the space's bounds. The classic RBF
//! kinds use the ERBF defaults where they have a width: Gaussian `exp(-r^2 / (2 r_c^2))`
//! with `r_c = 0.15` and no tail ("Gaussian-only"), multiquadric `-sqrt(r^2 + c^2)` with
//! `c = 0.15` and a constant tail, cubic and thin-plate with a linear tail.

use faer::{Mat, MatRef};
use impactcal_core::ParameterSpace;
use serde::{Deserialize, Serialize};

use crate::buffer::TrainingValues;
use crate::components::{Components, OutputBasis, Tuning};
use crate::erbf::Erbf;
use crate::error::Result;
use crate::loo::{ErrorSummary, LooMethod};
use crate::options::ValidErbfOptions;
use crate::radial::RadialFunction;
use crate::rbf::{RbfInterpolant, RbfOptions};
use crate::tuning::{ComponentOptions, Selection};

/// The kinds of surrogate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SurrogateKind {
    /// ERBF with the default options ([`ErbfOptions::default`](crate::ErbfOptions)).
    Erbf,
    /// Gaussian RBF, width 0.15 in scaled inputs, no tail.
    Gaussian,
    /// Cubic RBF with a linear tail.
    Cubic,
    /// Thin-plate spline with a linear tail.
    ThinPlate,
    /// Multiquadric RBF, `c = 0.15` in scaled inputs, constant tail.
    Multiquadric,
}

impl SurrogateKind {
    /// The classic RBF options of this kind (`None` for ERBF).
    pub fn rbf_options(self) -> Option<RbfOptions> {
        match self {
            SurrogateKind::Erbf => None,
            SurrogateKind::Gaussian => {
                Some(RbfOptions::new(RadialFunction::Gaussian { width: 0.15 }))
            }
            SurrogateKind::Cubic => Some(RbfOptions::cubic()),
            SurrogateKind::ThinPlate => Some(RbfOptions::thin_plate()),
            SurrogateKind::Multiquadric => {
                Some(RbfOptions::new(RadialFunction::Multiquadric { c: 0.15 }))
            }
        }
    }
}

impl SurrogateKind {
    /// The options of this kind's model with its defaults.
    pub fn component_options(self) -> ComponentOptions {
        match self.rbf_options() {
            None => ComponentOptions::Erbf(crate::ErbfOptions::default()),
            Some(o) => ComponentOptions::Rbf(o),
        }
    }

    /// The kind of a model with these options.
    pub fn of(options: &ComponentOptions) -> Self {
        match options {
            ComponentOptions::Erbf(_) => SurrogateKind::Erbf,
            ComponentOptions::Rbf(o) => match o.radial {
                RadialFunction::Cubic => SurrogateKind::Cubic,
                RadialFunction::ThinPlate => SurrogateKind::ThinPlate,
                RadialFunction::Gaussian { .. } => SurrogateKind::Gaussian,
                RadialFunction::Multiquadric { .. } => SurrogateKind::Multiquadric,
            },
        }
    }
}

/// How [`ResponseSurrogate::fit_with`] builds a surrogate: its kind, the representation of
/// the outputs and what leave-one-out cross-validation chooses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct FitOptions {
    /// The kind (the family whose defaults are used or tuned; with [`Tuning::Kinds`] only
    /// the fall-back when no candidate fits).
    pub kind: SurrogateKind,
    /// Full outputs or impact-shape coordinates.
    pub basis: OutputBasis,
    /// What is chosen by leave-one-out.
    pub tuning: Tuning,
    /// How the tuned candidates are chosen from their leave-one-out errors (no effect
    /// with [`Tuning::Off`]).
    #[serde(default)]
    pub selection: Selection,
}

impl Default for SurrogateKind {
    /// ERBF, the source paper's surrogate.
    fn default() -> Self {
        SurrogateKind::Erbf
    }
}

/// Leave-one-out errors of a surrogate and of the linear trend, as `rms / std` of the
/// training values (see [`ResponseSurrogate::loo_against_trend`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LooComparison {
    /// The surrogate's, per output.
    pub model: Vec<f64>,
    /// The linear trend's, per output (`NaN` when undefined).
    pub trend: Vec<f64>,
    /// The surrogate's, pooled over outputs ([`ErrorSummary::relative_rms`]).
    pub pooled_model: f64,
    /// The linear trend's, pooled.
    pub pooled_trend: f64,
    /// The surrogate's errors summarised (pooled).
    pub summary: ErrorSummary,
}

/// Leave-one-out errors (as `rms / std`) below this are round-off: an output that both the
/// surrogate and the linear trend reproduce to this level is not one where the surrogate
/// does worse (an output linear in the parameters gives `1e-15` against `1e-14`).
pub const LOO_ROUND_OFF: f64 = 1e-8;

impl LooComparison {
    /// The outputs whose leave-one-out error exceeds the linear trend's: where the
    /// surrogate, by its own cross-validation, does worse than a straight line (fitting
    /// noise, or a shape parameter unsuited to the sample spacing). An output counts when
    /// its error exceeds both the trend's and [`LOO_ROUND_OFF`]; an undefined error on
    /// either side (`NaN`: a constant output, or too few samples for the trend) never does.
    pub fn worse_than_trend(&self) -> Vec<usize> {
        (0..self.model.len())
            .filter(|&c| exceeds_trend(self.model[c], self.trend[c]))
            .collect()
    }

    /// Whether the pooled error exceeds the pooled trend's, by the rule of
    /// [`LooComparison::worse_than_trend`].
    pub fn pooled_worse_than_trend(&self) -> bool {
        exceeds_trend(self.pooled_model, self.pooled_trend)
    }
}

fn exceeds_trend(model: f64, trend: f64) -> bool {
    !trend.is_nan() && model > trend.max(LOO_ROUND_OFF)
}

/// The fitted model inside a [`ResponseSurrogate`].
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum SurrogateModel {
    /// An ERBF model (it scales its inputs itself).
    Erbf(Erbf),
    /// A classic RBF interpolant fitted in unit-scaled inputs.
    Rbf {
        /// The kind (Gaussian, cubic, thin-plate or multiquadric).
        rbf_kind: SurrogateKind,
        /// The space whose bounds scale the inputs.
        space: ParameterSpace,
        /// The interpolant in scaled inputs.
        interpolant: RbfInterpolant,
    },
    /// Surrogates of output components (impact-shape coordinates or single outputs), each
    /// group with its own options ([`crate::components`]).
    Components(Components),
}

/// A fitted surrogate of named responses over a parameter space: any [`SurrogateKind`],
/// raw parameter values in, one value per named output out.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ResponseSurrogate {
    /// Names of the outputs (columns of the training responses).
    output_names: Vec<String>,
    /// The model.
    model: SurrogateModel,
}

impl ResponseSurrogate {
    /// Fits a surrogate of `kind` to raw samples `points` (`N x m`, columns in the order of
    /// `space`) and responses `values` (`N x T`) with one name per output column; lent
    /// responses are copied into the model, given ones moved in ([`TrainingValues`]).
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`](impactcal_core::CoreError::DimensionMismatch) when
    /// the names do not match the columns; otherwise as [`Erbf::fit`] or
    /// [`RbfInterpolant::fit`].
    pub fn fit<'a>(
        space: &ParameterSpace,
        kind: SurrogateKind,
        points: MatRef<'_, f64>,
        values: impl Into<TrainingValues<'a>>,
        output_names: Vec<String>,
    ) -> Result<Self> {
        let values = values.into();
        crate::components::check_names(&output_names, values.view().ncols())?;
        let model = match kind.rbf_options() {
            None => SurrogateModel::Erbf(Erbf::fit(
                space,
                points,
                values,
                ValidErbfOptions::default(),
            )?),
            Some(options) => {
                let unit = space.to_unit_matrix(points)?;
                SurrogateModel::Rbf {
                    rbf_kind: kind,
                    space: space.clone(),
                    interpolant: RbfInterpolant::fit(unit.as_ref(), values, options)?,
                }
            }
        };
        Ok(ResponseSurrogate {
            output_names,
            model,
        })
    }

    /// Fits a surrogate as `options` say: [`fit`](Self::fit) for the full outputs without
    /// tuning, else a [`Components`] model (impact-shape coordinates and/or options chosen
    /// by leave-one-out).
    ///
    /// `values` (`N x T`) may be borrowed (a `MatRef` or `&Mat`) or given away (a `Mat`,
    /// see [`TrainingValues`]): the model moves owned outputs in rather than copying them
    /// (ERBF still keeps a centred copy when it centres the outputs). Outputs given away
    /// are dropped with the error when the fit fails: lend them to keep them.
    ///
    /// # Errors
    /// As [`fit`](Self::fit) and [`Components::fit`].
    pub fn fit_with<'a>(
        space: &ParameterSpace,
        points: MatRef<'_, f64>,
        values: impl Into<TrainingValues<'a>>,
        output_names: Vec<String>,
        options: &FitOptions,
    ) -> Result<Self> {
        let values = values.into();
        if options.basis == OutputBasis::Full && options.tuning == Tuning::Off {
            return Self::fit(space, options.kind, points, values, output_names);
        }
        crate::components::check_names(&output_names, values.view().ncols())?;
        let model = Components::fit(
            space,
            points,
            values,
            options.kind.component_options(),
            options.basis,
            options.tuning,
            options.selection,
        )?;
        Ok(ResponseSurrogate {
            output_names,
            model: SurrogateModel::Components(model),
        })
    }

    /// The kind of the model (for component models, that of the first component).
    pub fn kind(&self) -> SurrogateKind {
        match &self.model {
            SurrogateModel::Erbf(_) => SurrogateKind::Erbf,
            SurrogateModel::Rbf { rbf_kind, .. } => *rbf_kind,
            SurrogateModel::Components(c) => c
                .column_options()
                .first()
                .map_or(SurrogateKind::Erbf, SurrogateKind::of),
        }
    }

    /// The model.
    pub fn model(&self) -> &SurrogateModel {
        &self.model
    }

    /// The parameter space.
    pub fn space(&self) -> &ParameterSpace {
        match &self.model {
            SurrogateModel::Erbf(e) => e.space(),
            SurrogateModel::Rbf { space, .. } => space,
            SurrogateModel::Components(c) => c.space(),
        }
    }

    /// Names of the outputs.
    pub fn output_names(&self) -> &[String] {
        &self.output_names
    }

    /// Number of training samples.
    pub fn n_samples(&self) -> usize {
        match &self.model {
            SurrogateModel::Erbf(e) => e.n_samples(),
            SurrogateModel::Rbf { interpolant, .. } => interpolant.n_samples(),
            SurrogateModel::Components(c) => c.n_samples(),
        }
    }

    /// Predictions at raw points (`Q x m`): `Q x T`.
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`](impactcal_core::CoreError::DimensionMismatch) or
    /// [`CoreError::NonFinite`](impactcal_core::CoreError::NonFinite) for bad points.
    pub fn predict_batch(&self, points: MatRef<'_, f64>) -> Result<Mat<f64>> {
        match &self.model {
            SurrogateModel::Erbf(e) => e.predict_batch(points),
            SurrogateModel::Rbf {
                space, interpolant, ..
            } => interpolant.predict_batch(space.to_unit_matrix(points)?.as_ref()),
            SurrogateModel::Components(c) => c.predict_batch(points),
        }
    }

    /// Gradient with respect to the raw parameters at `x`: `T x m`.
    ///
    /// # Errors
    /// As [`predict_batch`](Self::predict_batch).
    pub fn predict_gradient(&self, x: &[f64]) -> Result<Mat<f64>> {
        match &self.model {
            SurrogateModel::Erbf(e) => e.predict_gradient(x),
            SurrogateModel::Rbf {
                space, interpolant, ..
            } => {
                let u = space.to_unit(x)?;
                let g = interpolant.predict_gradient(&u)?;
                let p = space.parameters();
                Ok(Mat::from_fn(g.nrows(), g.ncols(), |t, j| {
                    g[(t, j)] / p[j].width()
                }))
            }
            SurrogateModel::Components(c) => c.predict_gradient(x),
        }
    }

    /// Whether the raw point `x` lies outside the space's bounds.
    pub fn is_outside(&self, x: &[f64]) -> bool {
        !self.space().contains(x)
    }

    /// Relative reproduction error of the training data (see
    /// [`Erbf::training_residual`]).
    pub fn training_residual(&self) -> f64 {
        match &self.model {
            SurrogateModel::Erbf(e) => e.training_residual(),
            SurrogateModel::Rbf { interpolant, .. } => interpolant.training_residual(),
            SurrogateModel::Components(c) => c.training_residual(),
        }
    }

    /// Leave-one-out errors, `N x T` (see [`Erbf::loo_errors`] and
    /// [`RbfInterpolant::loo_errors`]).
    ///
    /// # Errors
    /// [`ErbfError::LooUndefined`](crate::ErbfError::LooUndefined) when they are undefined.
    pub fn loo_errors(&self, method: LooMethod) -> Result<Mat<f64>> {
        match &self.model {
            SurrogateModel::Erbf(e) => e.loo_errors(method),
            SurrogateModel::Rbf { interpolant, .. } => interpolant.loo_errors(method),
            SurrogateModel::Components(c) => c.loo_errors(method),
        }
    }

    /// The training points in unit-scaled inputs, `N x m`.
    ///
    /// # Errors
    /// Only if the stored points fell outside what the space can scale, which a fitted
    /// model excludes.
    pub fn unit_points(&self) -> Result<Mat<f64>> {
        Ok(match &self.model {
            SurrogateModel::Erbf(e) => e.space().to_unit_matrix(e.points())?,
            SurrogateModel::Rbf { interpolant, .. } => interpolant.points().to_owned(),
            SurrogateModel::Components(c) => c.unit_points().to_owned(),
        })
    }

    /// The leave-one-out errors of the model beside those of the linear trend (plain
    /// linear regression, [`linear_trend_loo`](crate::linear_trend_loo)), per output and
    /// pooled, each as `rms / std` of the training values.
    ///
    /// # Errors
    /// [`ErbfError::LooUndefined`](crate::ErbfError::LooUndefined) when the model's
    /// leave-one-out errors are undefined; the trend's being undefined (too few samples)
    /// leaves its entries `NaN` instead.
    pub fn loo_against_trend(&self, method: LooMethod) -> Result<LooComparison> {
        let values = self.values();
        let model = self.loo_errors(method)?;
        let unit = self.unit_points()?;
        let trend = crate::trend::linear_trend_loo(unit.as_ref(), values).ok();
        let per = |e: MatRef<'_, f64>| -> Vec<f64> {
            (0..e.ncols())
                .map(|c| ErrorSummary::new(e.subcols(c, 1), values.subcols(c, 1)).relative_rms)
                .collect()
        };
        let t = values.ncols();
        let summary = ErrorSummary::new(model.as_ref(), values);
        Ok(LooComparison {
            summary,
            model: per(model.as_ref()),
            trend: trend
                .as_ref()
                .map_or(vec![f64::NAN; t], |e| per(e.as_ref())),
            pooled_model: summary.relative_rms,
            pooled_trend: trend.as_ref().map_or(f64::NAN, |e| {
                ErrorSummary::new(e.as_ref(), values).relative_rms
            }),
        })
    }

    /// The training responses, `N x T`.
    pub fn values(&self) -> MatRef<'_, f64> {
        match &self.model {
            SurrogateModel::Erbf(e) => e.values(),
            SurrogateModel::Rbf { interpolant, .. } => interpolant.values(),
            SurrogateModel::Components(c) => c.values(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn comparison(model: Vec<f64>, trend: Vec<f64>) -> LooComparison {
        LooComparison {
            pooled_model: model[0],
            pooled_trend: trend[0],
            model,
            trend,
            summary: ErrorSummary {
                rms: 0.0,
                max_abs: 0.0,
                relative_rms: 0.0,
            },
        }
    }

    #[test]
    fn worse_than_trend_ignores_round_off_and_undefined_errors() {
        let c = comparison(
            vec![0.30, 0.05, 1.5e-14, 0.20, f64::NAN, 0.10],
            vec![0.20, 0.10, 1.0e-15, f64::NAN, f64::NAN, 3.0e-16],
        );
        // Worse: a real margin (0), and a linear output the trend reproduces exactly (5).
        assert_eq!(c.worse_than_trend(), vec![0, 5]);
        assert!(c.pooled_worse_than_trend());
        assert!(!comparison(vec![2e-9], vec![1e-12]).pooled_worse_than_trend());
        assert!(!comparison(vec![0.5], vec![f64::NAN]).pooled_worse_than_trend());
    }
}
