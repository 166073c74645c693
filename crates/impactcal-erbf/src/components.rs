//! Surrogates of output components: the coordinates of histories in the impact-shape basis
//! ([`crate::shape_basis`]), or the output columns themselves, each group of components
//! with its own options (as [`crate::tuning`] chose them).
//!
//! The outputs `F` (`N x T`) are mapped to targets `A` (`N x k`): the shape coordinates
//! (`F ~ 1 f_bar^T + A G^T`) or `A = F` (`k = T`). The targets are split into groups of
//! columns; every group is one surrogate (one factorisation for all its columns) of the
//! family and parameters of its [`ComponentOptions`]. A prediction evaluates every group
//! at the queries and, in the shape basis, rebuilds the histories.

use faer::{Mat, MatRef};
use impactcal_core::error::invalid_option;
use impactcal_core::{ParameterSpace, error::dimension_mismatch};
use serde::{Deserialize, Serialize};

use crate::buffer::TrainingValues;
use crate::data::StoredMat;
use crate::erbf::Erbf;
use crate::error::{ErbfError, Result};
use crate::loo::LooMethod;
use crate::rbf::{RbfInterpolant, relative_max_error};
use crate::shape_basis::{ShapeBasis, ShapeSpectrum, choose_count};
use crate::tuning::{ComponentOptions, Selection, candidates, tune};

/// How the outputs are represented for the surrogate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OutputBasis {
    /// Every output column is a target (the plain surrogate).
    #[default]
    Full,
    /// The outputs are histories of one ensemble: the targets are their coordinates on the
    /// ensemble's impact shapes ([`crate::shape_basis`]).
    Shapes {
        /// How many shapes to keep; `None` chooses the fewest whose truncation error stays
        /// below the surrogate's own leave-one-out error
        /// ([`choose_count`]).
        count: Option<usize>,
    },
}

/// Which parameters are chosen by leave-one-out cross-validation ([`crate::tuning`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Tuning {
    /// The kind's defaults.
    #[default]
    Off,
    /// The kind's shape parameter and smoothing, per target column.
    Parameters,
    /// The kind too: the candidates of every classic RBF kind (cubic, thin-plate, Gaussian,
    /// multiquadric) compete per target column. ERBF is left out because its closed-form
    /// leave-one-out error is only approximate.
    Kinds,
}

/// Targets above which [`Tuning`] chooses one set of options for all target columns
/// (the sum of their squared LOO errors) instead of one per column.
const PER_COLUMN_LIMIT: usize = 64;

/// A fitted model of one group of target columns.
#[derive(Debug, Clone)]
pub(crate) enum Fitted {
    Erbf(Erbf),
    /// In unit-scaled inputs.
    Rbf(RbfInterpolant),
}

impl Fitted {
    pub(crate) fn fit(
        space: &ParameterSpace,
        points: MatRef<'_, f64>,
        unit: MatRef<'_, f64>,
        targets: MatRef<'_, f64>,
        options: ComponentOptions,
    ) -> Result<Self> {
        Ok(match options {
            ComponentOptions::Erbf(o) => Fitted::Erbf(Erbf::fit(space, points, targets, o)?),
            ComponentOptions::Rbf(o) => Fitted::Rbf(RbfInterpolant::fit(unit, targets, o)?),
        })
    }

    pub(crate) fn predict(
        &self,
        points: MatRef<'_, f64>,
        unit: MatRef<'_, f64>,
    ) -> Result<Mat<f64>> {
        match self {
            Fitted::Erbf(e) => e.predict_batch(points),
            Fitted::Rbf(r) => r.predict_batch(unit),
        }
    }

    /// Gradient with respect to the raw inputs (`k x m`) at raw `x` / unit `u`.
    fn gradient(&self, x: &[f64], u: &[f64], space: &ParameterSpace) -> Result<Mat<f64>> {
        match self {
            Fitted::Erbf(e) => e.predict_gradient(x),
            Fitted::Rbf(r) => {
                let g = r.predict_gradient(u)?;
                let p = space.parameters();
                Ok(Mat::from_fn(g.nrows(), g.ncols(), |t, j| {
                    g[(t, j)] / p[j].width()
                }))
            }
        }
    }

    fn loo(&self, method: LooMethod) -> Result<Mat<f64>> {
        match self {
            Fitted::Erbf(e) => e.loo_errors(method),
            Fitted::Rbf(r) => r.loo_errors(method),
        }
    }

    fn keep_outputs(&mut self, k: usize) {
        match self {
            Fitted::Erbf(e) => e.keep_outputs(k),
            Fitted::Rbf(r) => r.keep_outputs(k),
        }
    }
}

/// One surrogate of some target columns.
#[derive(Debug, Clone)]
struct Group {
    /// The target columns it predicts, in order.
    columns: Vec<usize>,
    options: ComponentOptions,
    model: Fitted,
}

/// A surrogate of output components: shape coordinates or output columns, in groups with
/// their own options. Serialises as its space, training data, shape count and the options
/// of every group; loading refits (deterministically, so predictions are reproduced).
#[derive(Debug, Clone)]
pub struct Components {
    space: ParameterSpace,
    points: Mat<f64>,
    unit: Mat<f64>,
    values: Mat<f64>,
    basis: Option<ShapeBasis>,
    /// Training targets, `N x k` (coordinates; empty when there is no basis and the
    /// targets are `values`).
    coords: Mat<f64>,
    groups: Vec<Group>,
}

impl Components {
    /// Fits the surrogate: targets from `basis`, options from `base` (and [`Tuning`], the
    /// tuned candidates picked by `selection`).
    ///
    /// Steps: the targets (shape coordinates up to the numerical rank, or the outputs);
    /// with tuning, the options per target column (or for all when there are more than 64
    /// columns) by leave-one-out; in the shape basis without a given count, the count by
    /// [`choose_count`] from the leave-one-out errors of the coordinates; then one
    /// surrogate per group of columns that share their options.
    ///
    /// The model keeps the training outputs `values` (`N x T`): moved in when owned
    /// ([`TrainingValues`]), copied when borrowed.
    ///
    /// # Errors
    /// As [`Erbf::fit`] and [`RbfInterpolant::fit`];
    /// [`CoreError::InvalidOption`](impactcal_core::CoreError::InvalidOption) for a shape
    /// count of 0 or above the numerical rank of the deviations from the mean history;
    /// [`ErbfError::Shapes`] when the decomposition fails.
    pub fn fit<'a>(
        space: &ParameterSpace,
        points: MatRef<'_, f64>,
        values: impl Into<TrainingValues<'a>>,
        base: ComponentOptions,
        basis: OutputBasis,
        tuning: Tuning,
        selection: Selection,
    ) -> Result<Self> {
        let training = values.into();
        let values = training.view();
        // In the shape basis the spectrum checks the values in its first pass.
        match basis {
            OutputBasis::Full => crate::data::check_training(points, values, Some(space.dim()))?,
            OutputBasis::Shapes { .. } => {
                crate::data::check_training_points(points, values, Some(space.dim()))?
            }
        }
        let unit = space.to_unit_matrix(points)?;
        let (spectrum, coords) = match basis {
            OutputBasis::Full => (None, Mat::<f64>::zeros(0, 0)),
            OutputBasis::Shapes { .. } => {
                let s = ShapeSpectrum::new(values)?;
                let a = s.coordinates();
                (Some(s), a)
            }
        };
        let targets = if spectrum.is_some() {
            coords.as_ref()
        } else {
            values
        };
        let per_column = targets.ncols() <= PER_COLUMN_LIMIT;
        // Options per target column, and the LOO errors that choose a shape count.
        let mut prefit = None;
        let (options, loo) = match tuning {
            Tuning::Off => (vec![base; targets.ncols()], None),
            Tuning::Parameters | Tuning::Kinds => {
                let cands = match tuning {
                    Tuning::Kinds => classic_candidates(unit.as_ref()),
                    _ => candidates(base, unit.as_ref()),
                };
                let tuned = tune(space, points, targets, &cands, per_column, selection)?;
                (tuned.options, Some(tuned.loo))
            }
        };
        let count = match (basis, &spectrum) {
            (OutputBasis::Shapes { count: Some(k) }, Some(b)) => {
                if k == 0 || k > b.singular_values().len() {
                    return Err(invalid_option::<ErbfError>(
                        "shape count",
                        k,
                        format!(
                            "must lie between 1 and the numerical rank of the deviations \
                             from the mean history, {}",
                            b.singular_values().len()
                        ),
                    ));
                }
                k
            }
            (OutputBasis::Shapes { count: None }, Some(b)) => {
                let loo = match loo {
                    Some(l) => l,
                    None => {
                        let model = Fitted::fit(space, points, unit.as_ref(), targets, base)?;
                        let l = model.loo(LooMethod::Closed)?;
                        prefit = Some(model);
                        l
                    }
                };
                let energy: Vec<f64> = (0..loo.ncols())
                    .map(|c| loo.col(c).iter().map(|e| e * e).sum())
                    .collect();
                choose_count(b.singular_values(), &energy)
            }
            _ => targets.ncols(),
        };
        let shape_basis = match spectrum {
            Some(s) => Some(s.into_basis(values, count)?),
            None => None,
        };
        let coords = if shape_basis.is_some() {
            coords.subcols(0, count).to_owned()
        } else {
            coords
        };
        let mut out = Components {
            space: space.clone(),
            points: points.to_owned(),
            unit,
            values: training.into_owned(),
            basis: shape_basis,
            coords,
            groups: Vec::new(),
        };
        out.groups = match prefit {
            // The fit to every coordinate already holds the first `count` (each column is
            // solved on its own): keep those rather than fit again.
            Some(mut model) => {
                model.keep_outputs(count);
                vec![Group {
                    columns: (0..count).collect(),
                    options: base,
                    model,
                }]
            }
            None => out.fit_groups(&group_columns(&options[..count]))?,
        };
        Ok(out)
    }

    /// Fits one surrogate per `(columns, options)`.
    fn fit_groups(&self, plan: &[(Vec<usize>, ComponentOptions)]) -> Result<Vec<Group>> {
        let targets = self.targets();
        plan.iter()
            .map(|(columns, options)| {
                let contiguous = columns
                    .iter()
                    .enumerate()
                    .all(|(i, &c)| c == columns[0] + i);
                let model = if contiguous {
                    let sub = targets.subcols(columns[0], columns.len());
                    Fitted::fit(
                        &self.space,
                        self.points.as_ref(),
                        self.unit.as_ref(),
                        sub,
                        *options,
                    )?
                } else {
                    let sub = Mat::from_fn(targets.nrows(), columns.len(), |i, j| {
                        targets[(i, columns[j])]
                    });
                    Fitted::fit(
                        &self.space,
                        self.points.as_ref(),
                        self.unit.as_ref(),
                        sub.as_ref(),
                        *options,
                    )?
                };
                Ok(Group {
                    columns: columns.clone(),
                    options: *options,
                    model,
                })
            })
            .collect()
    }

    fn targets(&self) -> MatRef<'_, f64> {
        if self.basis.is_some() {
            self.coords.as_ref()
        } else {
            self.values.as_ref()
        }
    }

    fn n_targets(&self) -> usize {
        self.targets().ncols()
    }

    /// The parameter space whose bounds scale the inputs.
    pub fn space(&self) -> &ParameterSpace {
        &self.space
    }

    /// The shape basis, when the targets are shape coordinates.
    pub fn basis(&self) -> Option<&ShapeBasis> {
        self.basis.as_ref()
    }

    /// The options of every target column (shape coordinate or output), in order.
    pub fn column_options(&self) -> Vec<ComponentOptions> {
        let mut out = vec![self.groups[0].options; self.n_targets()];
        for g in &self.groups {
            for &c in &g.columns {
                out[c] = g.options;
            }
        }
        out
    }

    /// Number of training samples.
    pub fn n_samples(&self) -> usize {
        self.points.nrows()
    }

    /// The training points in unit-scaled inputs, `N x m`.
    pub fn unit_points(&self) -> MatRef<'_, f64> {
        self.unit.as_ref()
    }

    /// The training outputs, `N x T`.
    pub fn values(&self) -> MatRef<'_, f64> {
        self.values.as_ref()
    }

    /// Target predictions (`Q x k`) at raw `points`.
    fn predict_targets(&self, points: MatRef<'_, f64>) -> Result<Mat<f64>> {
        crate::data::check_queries(points, self.space.dim())?;
        let unit = self.space.to_unit_matrix(points)?;
        if let [only] = self.groups.as_slice()
            && only.columns.len() == self.n_targets()
        {
            return only.model.predict(points, unit.as_ref());
        }
        let mut out = crate::buffer::zeros(points.nrows(), self.n_targets());
        for g in &self.groups {
            let p = g.model.predict(points, unit.as_ref())?;
            for (j, &c) in g.columns.iter().enumerate() {
                out.col_mut(c).copy_from(p.col(j));
            }
        }
        Ok(out)
    }

    /// Predictions at raw `points` (`Q x m`): `Q x T` (histories rebuilt from the
    /// predicted coordinates in the shape basis).
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`](impactcal_core::CoreError::DimensionMismatch) or
    /// [`CoreError::NonFinite`](impactcal_core::CoreError::NonFinite) for bad points.
    pub fn predict_batch(&self, points: MatRef<'_, f64>) -> Result<Mat<f64>> {
        let a = self.predict_targets(points)?;
        Ok(match &self.basis {
            Some(b) => b.rebuild(a.as_ref()),
            None => a,
        })
    }

    /// Predicted shape coordinates at raw `points` (`Q x k`): the cheap part of a
    /// prediction in the shape basis, before the histories are rebuilt. Without a basis,
    /// the outputs.
    ///
    /// # Errors
    /// As [`predict_batch`](Self::predict_batch).
    pub fn predict_coordinates(&self, points: MatRef<'_, f64>) -> Result<Mat<f64>> {
        self.predict_targets(points)
    }

    /// Gradient with respect to the raw parameters at `x`: `T x m`.
    ///
    /// # Errors
    /// As [`predict_batch`](Self::predict_batch).
    pub fn predict_gradient(&self, x: &[f64]) -> Result<Mat<f64>> {
        let u = self.space.to_unit(x)?;
        let m = self.space.dim();
        let mut g = Mat::<f64>::zeros(self.n_targets(), m);
        for group in &self.groups {
            let gg = group.model.gradient(x, &u, &self.space)?;
            for (j, &c) in group.columns.iter().enumerate() {
                g.row_mut(c).copy_from(gg.row(j));
            }
        }
        Ok(match &self.basis {
            Some(b) => b.functions() * &g,
            None => g,
        })
    }

    /// `max_k |f(x_k) - F_k| / max |F|`: the reproduction error of the training data. In
    /// the shape basis without smoothing it is the truncation error (at most
    /// [`ShapeBasis::truncation_error`] in the Frobenius norm), not machine precision.
    pub fn training_residual(&self) -> f64 {
        match self.predict_batch(self.points.as_ref()) {
            Ok(p) => relative_max_error(p.as_ref(), self.values.as_ref()),
            Err(_) => f64::NAN,
        }
    }

    /// Leave-one-out errors of the outputs, `N x T`. In the shape basis the basis is kept
    /// fixed (the mean history and shapes of all `N` runs): `e_k = r_k + G e^a_k`, with
    /// `r_k` run `k`'s truncation residual and `e^a_k` the coordinates' own LOO errors.
    ///
    /// # Errors
    /// [`ErbfError::LooUndefined`] when they are undefined.
    pub fn loo_errors(&self, method: LooMethod) -> Result<Mat<f64>> {
        let n = self.n_samples();
        let mut e = Mat::<f64>::zeros(n, self.n_targets());
        for g in &self.groups {
            let eg = g.model.loo(method)?;
            for (j, &c) in g.columns.iter().enumerate() {
                e.col_mut(c).copy_from(eg.col(j));
            }
        }
        Ok(match &self.basis {
            Some(b) => {
                let mut r = b.residual(self.values.as_ref(), self.coords.as_ref());
                r += &e * b.functions().transpose();
                r
            }
            None => e,
        })
    }
}

/// Candidates of every classic RBF kind, least smoothing first within each kind.
fn classic_candidates(unit: MatRef<'_, f64>) -> Vec<ComponentOptions> {
    use crate::surrogate::SurrogateKind;
    [
        SurrogateKind::Cubic,
        SurrogateKind::ThinPlate,
        SurrogateKind::Gaussian,
        SurrogateKind::Multiquadric,
    ]
    .into_iter()
    .filter_map(|k| k.rbf_options())
    .flat_map(|o| candidates(ComponentOptions::Rbf(o), unit))
    .collect()
}

/// Groups column indices by equal options, in order of first appearance.
fn group_columns(options: &[ComponentOptions]) -> Vec<(Vec<usize>, ComponentOptions)> {
    let mut plan: Vec<(Vec<usize>, ComponentOptions)> = Vec::new();
    for (c, o) in options.iter().enumerate() {
        match plan.iter_mut().find(|(_, p)| p == o) {
            Some((cols, _)) => cols.push(c),
            None => plan.push((vec![c], *o)),
        }
    }
    plan
}

/// The serialised form of [`Components`].
#[derive(Debug, Clone, Serialize, Deserialize)]
struct ComponentsData {
    space: ParameterSpace,
    points: StoredMat,
    values: StoredMat,
    /// Shapes kept (absent: no shape basis).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    shapes: Option<usize>,
    groups: Vec<GroupData>,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct GroupData {
    columns: Vec<usize>,
    options: ComponentOptions,
}

impl Serialize for Components {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        ComponentsData {
            space: self.space.clone(),
            points: StoredMat::from_mat(self.points.as_ref()),
            values: StoredMat::from_mat(self.values.as_ref()),
            shapes: self.basis.as_ref().map(ShapeBasis::len),
            groups: self
                .groups
                .iter()
                .map(|g| GroupData {
                    columns: g.columns.clone(),
                    options: g.options,
                })
                .collect(),
        }
        .serialize(s)
    }
}

impl<'de> Deserialize<'de> for Components {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let data = ComponentsData::deserialize(d)?;
        let build = || -> Result<Self> {
            let points = data.points.to_mat("points")?;
            let values = data.values.to_mat("values")?;
            crate::data::check_training(points.as_ref(), values.as_ref(), Some(data.space.dim()))?;
            let unit = data.space.to_unit_matrix(points.as_ref())?;
            let (basis, coords) = match data.shapes {
                None => (None, Mat::zeros(0, 0)),
                Some(k) => {
                    let s = ShapeSpectrum::new(values.as_ref())?;
                    let r = s.singular_values().len();
                    if k == 0 || k > r {
                        return Err(ErbfError::InvalidModel(format!(
                            "{k} shapes kept, but the data have {r}"
                        )));
                    }
                    let coords = s.coordinates().subcols(0, k).to_owned();
                    (Some(s.into_basis(values.as_ref(), k)?), coords)
                }
            };
            let mut out = Components {
                space: data.space.clone(),
                points,
                unit,
                values,
                basis,
                coords,
                groups: Vec::new(),
            };
            let k = out.n_targets();
            let mut seen = vec![false; k];
            for g in &data.groups {
                for &c in &g.columns {
                    if c >= k || std::mem::replace(&mut seen[c], true) {
                        return Err(ErbfError::InvalidModel(format!(
                            "group column {c} is out of range (0..{k}) or repeated"
                        )));
                    }
                }
            }
            if seen.iter().any(|s| !s) {
                return Err(ErbfError::InvalidModel(
                    "the groups do not cover every target column".into(),
                ));
            }
            let plan: Vec<(Vec<usize>, ComponentOptions)> = data
                .groups
                .iter()
                .map(|g| (g.columns.clone(), g.options))
                .collect();
            out.groups = out.fit_groups(&plan)?;
            Ok(out)
        };
        build().map_err(serde::de::Error::custom)
    }
}

/// Checks that `names` has one entry per output column.
pub(crate) fn check_names(names: &[String], t: usize) -> Result<()> {
    if names.len() != t {
        return Err(dimension_mismatch(
            "output names (one per output column)",
            t,
            names.len(),
        ));
    }
    Ok(())
}
