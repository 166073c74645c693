//! Named, bounded parameters and the map between their box and the unit cube.

use std::path::Path;

use faer::{Mat, MatRef};
use serde::{Deserialize, Serialize};

use crate::error::{CoreError, Result};

/// One uncertain or adjustable model parameter: a name, a closed interval
/// `[lower, upper]`, a nominal value inside it and a unit string (free text).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Parameter {
    /// Unique name within a space, for example `belly_panel.t`.
    pub name: String,
    /// Lower bound (finite, strictly below `upper`).
    pub lower: f64,
    /// Upper bound (finite).
    pub upper: f64,
    /// Nominal value, `lower <= nominal <= upper`.
    pub nominal: f64,
    /// Unit, for reports only (may be empty).
    pub unit: String,
}

impl Parameter {
    /// A parameter with an empty unit, validated.
    ///
    /// # Errors
    /// [`CoreError::Parameter`] when the name is empty, a value is not finite,
    /// `lower >= upper`, or the nominal lies outside the bounds.
    pub fn new(name: impl Into<String>, lower: f64, upper: f64, nominal: f64) -> Result<Self> {
        let p = Parameter {
            name: name.into(),
            lower,
            upper,
            nominal,
            unit: String::new(),
        };
        p.validate()?;
        Ok(p)
    }

    /// The same parameter with the given unit.
    #[must_use]
    pub fn with_unit(mut self, unit: impl Into<String>) -> Self {
        self.unit = unit.into();
        self
    }

    /// Width of the interval, `upper - lower`.
    pub fn width(&self) -> f64 {
        self.upper - self.lower
    }

    /// Whether `v` lies in `[lower, upper]` up to `1e-12` of the width (the round-off of a
    /// value mapped to the unit cube and back); `false` for NaN.
    pub fn admits(&self, v: f64) -> bool {
        let slack = 1e-12 * self.width();
        v >= self.lower - slack && v <= self.upper + slack
    }

    /// Checks the invariants stated on [`Parameter::new`].
    ///
    /// # Errors
    /// As [`Parameter::new`].
    pub fn validate(&self) -> Result<()> {
        let fail = |message: String| {
            Err(CoreError::Parameter {
                name: self.name.clone(),
                message,
            })
        };
        if self.name.trim().is_empty() {
            return fail("the name is empty".into());
        }
        for (what, v) in [
            ("lower", self.lower),
            ("upper", self.upper),
            ("nominal", self.nominal),
        ] {
            if !v.is_finite() {
                return fail(format!("{what} bound {v} is not finite"));
            }
        }
        if self.lower >= self.upper {
            return fail(format!(
                "lower bound {} is not below upper bound {}",
                self.lower, self.upper
            ));
        }
        if self.nominal < self.lower || self.nominal > self.upper {
            return fail(format!(
                "nominal {} lies outside [{}, {}]",
                self.nominal, self.lower, self.upper
            ));
        }
        Ok(())
    }
}

/// An ordered set of named parameters: the design space of a study.
///
/// A point is a slice of length [`dim`](Self::dim) in the order of the parameters; a set of
/// points is an `n x dim` matrix, one point per row. The unit-cube map is affine per
/// coordinate: with `l_j` and `h_j` the lower and upper bounds of parameter `j`, the unit
/// coordinate of `x_j` is `u_j = (x_j - l_j) / (h_j - l_j)`, and back
/// `x_j = l_j + u_j (h_j - l_j)`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "Vec<Parameter>", into = "Vec<Parameter>")]
pub struct ParameterSpace {
    parameters: Vec<Parameter>,
}

impl TryFrom<Vec<Parameter>> for ParameterSpace {
    type Error = CoreError;
    fn try_from(parameters: Vec<Parameter>) -> Result<Self> {
        ParameterSpace::new(parameters)
    }
}

impl From<ParameterSpace> for Vec<Parameter> {
    fn from(space: ParameterSpace) -> Self {
        space.parameters
    }
}

impl ParameterSpace {
    /// A space of the given parameters, each validated, names unique.
    ///
    /// # Errors
    /// [`CoreError::Invalid`] for an empty list; [`CoreError::Parameter`] for an invalid
    /// parameter or a repeated name.
    pub fn new(parameters: Vec<Parameter>) -> Result<Self> {
        if parameters.is_empty() {
            return Err(CoreError::Invalid(
                "a parameter space needs at least one parameter".into(),
            ));
        }
        for (i, p) in parameters.iter().enumerate() {
            p.validate()?;
            if parameters[..i].iter().any(|q| q.name == p.name) {
                return Err(CoreError::Parameter {
                    name: p.name.clone(),
                    message: "the name is used twice".into(),
                });
            }
        }
        Ok(ParameterSpace { parameters })
    }

    /// A space of parameters known to be valid with unique names (built-in models only).
    pub(crate) fn from_valid(parameters: Vec<Parameter>) -> Self {
        ParameterSpace { parameters }
    }

    /// Number of parameters `d`.
    pub fn dim(&self) -> usize {
        self.parameters.len()
    }

    /// The parameters in order.
    pub fn parameters(&self) -> &[Parameter] {
        &self.parameters
    }

    /// The names in order.
    pub fn names(&self) -> Vec<&str> {
        self.parameters.iter().map(|p| p.name.as_str()).collect()
    }

    /// Position of the parameter called `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.parameters.iter().position(|p| p.name == name)
    }

    /// The nominal point.
    pub fn nominal(&self) -> Vec<f64> {
        self.parameters.iter().map(|p| p.nominal).collect()
    }

    /// The lower bounds.
    pub fn lower(&self) -> Vec<f64> {
        self.parameters.iter().map(|p| p.lower).collect()
    }

    /// The upper bounds.
    pub fn upper(&self) -> Vec<f64> {
        self.parameters.iter().map(|p| p.upper).collect()
    }

    /// Whether `x` has the right length and lies inside the closed box.
    pub fn contains(&self, x: &[f64]) -> bool {
        x.len() == self.dim()
            && self
                .parameters
                .iter()
                .zip(x)
                .all(|(p, &v)| v >= p.lower && v <= p.upper)
    }

    /// Maps a point of the box to the unit cube: `u_j = (x_j - l_j) / (h_j - l_j)` with `l_j`
    /// and `h_j` the bounds of parameter `j`. Points outside the box map outside `[0, 1]`
    /// (no clamping).
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`] for a wrong length, [`CoreError::NonFinite`] for
    /// NaN or infinite coordinates.
    pub fn to_unit(&self, x: &[f64]) -> Result<Vec<f64>> {
        self.check_point("point", x)?;
        Ok(self
            .parameters
            .iter()
            .zip(x)
            .map(|(p, &v)| (v - p.lower) / p.width())
            .collect())
    }

    /// Maps a point of the unit cube to the box: `x_j = l_j + u_j (h_j - l_j)`.
    ///
    /// # Errors
    /// As [`to_unit`](Self::to_unit).
    pub fn from_unit(&self, u: &[f64]) -> Result<Vec<f64>> {
        self.check_point("unit-cube point", u)?;
        Ok(self
            .parameters
            .iter()
            .zip(u)
            .map(|(p, &v)| p.lower + v * p.width())
            .collect())
    }

    /// Maps every point (row) of `x`, an `n x dim` matrix in the box's units, to the unit
    /// cube: entry `(i, j)` becomes `(x_ij - l_j) / (h_j - l_j)`. Points outside the box
    /// map outside `[0, 1]` (no clamping). Bit for bit the same as [`to_unit`](Self::to_unit)
    /// row by row.
    ///
    /// # Errors
    /// [`CoreError::DimensionMismatch`] when `x` has not `dim` columns;
    /// [`CoreError::NonFinite`] naming the row and parameter of a NaN or infinite entry.
    pub fn to_unit_matrix(&self, x: MatRef<'_, f64>) -> Result<Mat<f64>> {
        self.check_matrix("points", x)?;
        let p = &self.parameters;
        Ok(Mat::from_fn(x.nrows(), x.ncols(), |i, j| {
            (x[(i, j)] - p[j].lower) / p[j].width()
        }))
    }

    /// Maps every point (row) of `u`, an `n x dim` matrix of unit-cube coordinates, to the
    /// box: entry `(i, j)` becomes `l_j + u_ij (h_j - l_j)`.
    ///
    /// # Errors
    /// As [`to_unit_matrix`](Self::to_unit_matrix).
    pub fn from_unit_matrix(&self, u: MatRef<'_, f64>) -> Result<Mat<f64>> {
        self.check_matrix("unit-cube points", u)?;
        let p = &self.parameters;
        Ok(Mat::from_fn(u.nrows(), u.ncols(), |i, j| {
            p[j].lower + u[(i, j)] * p[j].width()
        }))
    }

    fn check_matrix(&self, what: &str, x: MatRef<'_, f64>) -> Result<()> {
        if x.ncols() != self.dim() {
            return Err(CoreError::DimensionMismatch {
                what: format!("{what}: number of columns (parameters)"),
                expected: self.dim(),
                found: x.ncols(),
            });
        }
        for j in 0..x.ncols() {
            if let Some(i) = x.col(j).iter().position(|v| !v.is_finite()) {
                return Err(CoreError::NonFinite {
                    what: what.to_string(),
                    location: format!("row {i} (0-based), parameter `{}`", self.parameters[j].name),
                    value: x[(i, j)],
                });
            }
        }
        Ok(())
    }

    fn check_point(&self, what: &str, x: &[f64]) -> Result<()> {
        if x.len() != self.dim() {
            return Err(CoreError::DimensionMismatch {
                what: format!("{what} length (number of parameters)"),
                expected: self.dim(),
                found: x.len(),
            });
        }
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return Err(CoreError::NonFinite {
                what: what.to_string(),
                location: format!("parameter `{}`", self.parameters[i].name),
                value: x[i],
            });
        }
        Ok(())
    }

    /// Reads a bounds file: a header `name,lower,upper,nominal[,unit]`, then one parameter
    /// per row.
    ///
    /// # Errors
    /// [`CoreError::Io`] when unreadable; otherwise as [`parse_csv`](Self::parse_csv).
    pub fn read_csv(path: impl AsRef<Path>) -> Result<Self> {
        let (text, name) = crate::table::read_text(path.as_ref())?;
        Self::parse_csv(&text, &name)
    }

    /// Parses bounds CSV text; see [`read_csv`](Self::read_csv).
    ///
    /// # Errors
    /// [`CoreError::File`] for an empty text or no rows; [`CoreError::Csv`] (file, row,
    /// column) for a wrong header, a ragged row, a number that does not parse or is not
    /// finite, `lower >= upper`, a nominal outside the bounds, or a repeated name.
    pub fn parse_csv(text: &str, source_name: &str) -> Result<Self> {
        let mut reader = crate::table::csv_reader(text);
        let err = |row: usize, column: usize, message: String| CoreError::Csv {
            file: source_name.to_string(),
            row,
            column,
            message,
        };
        let line_index = crate::table::LineIndex::new(text);
        let mut header_seen = false;
        let mut parameters: Vec<Parameter> = Vec::new();
        for record in reader.records() {
            let record = record.map_err(|e| CoreError::File {
                file: source_name.to_string(),
                message: e.to_string(),
            })?;
            if record.iter().all(str::is_empty) {
                continue;
            }
            let row = line_index.line_of(&record);
            if !header_seen {
                const EXPECTED: [&str; 5] = ["name", "lower", "upper", "nominal", "unit"];
                if !(4..=5).contains(&record.len()) {
                    return Err(err(
                        row,
                        1,
                        "expected the header `name,lower,upper,nominal[,unit]`".into(),
                    ));
                }
                for (j, field) in record.iter().enumerate() {
                    if !field.eq_ignore_ascii_case(EXPECTED[j]) {
                        return Err(err(
                            row,
                            j + 1,
                            format!("header field `{field}` should be `{}`", EXPECTED[j]),
                        ));
                    }
                }
                header_seen = true;
                continue;
            }
            if !(4..=5).contains(&record.len()) {
                return Err(err(
                    row,
                    record.len().min(5) + 1,
                    format!("row has {} fields; expected 4 or 5", record.len()),
                ));
            }
            let name = record.get(0).unwrap_or_default().to_string();
            if name.is_empty() {
                return Err(err(row, 1, "empty parameter name".into()));
            }
            let mut values = [0.0; 3];
            for (k, value) in values.iter_mut().enumerate() {
                let cell = record.get(k + 1).unwrap_or_default();
                *value = crate::table::parse_cell(cell, crate::table::TableOptions::default())
                    .map_err(|m| err(row, k + 2, m))?;
            }
            let [lower, upper, nominal] = values;
            let p = Parameter {
                name,
                lower,
                upper,
                nominal,
                unit: record.get(4).unwrap_or_default().to_string(),
            };
            if let Err(CoreError::Parameter { message, .. }) = p.validate() {
                let column = if lower >= upper { 3 } else { 4 };
                return Err(err(
                    row,
                    column,
                    format!("parameter `{}`: {message}", p.name),
                ));
            }
            if parameters.iter().any(|q| q.name == p.name) {
                return Err(err(
                    row,
                    1,
                    format!("parameter `{}` is listed twice", p.name),
                ));
            }
            parameters.push(p);
        }
        if !header_seen {
            return Err(CoreError::File {
                file: source_name.to_string(),
                message: "the file is empty (expected a header `name,lower,upper,nominal[,unit]`)"
                    .into(),
            });
        }
        if parameters.is_empty() {
            return Err(CoreError::File {
                file: source_name.to_string(),
                message: "no parameters after the header".into(),
            });
        }
        ParameterSpace::new(parameters)
    }

    /// Writes the space as a bounds CSV (with the unit column).
    pub fn to_csv_string(&self) -> String {
        let mut s = String::from("name,lower,upper,nominal,unit\n");
        for p in &self.parameters {
            s.push_str(&format!(
                "{},{},{},{},{}\n",
                p.name, p.lower, p.upper, p.nominal, p.unit
            ));
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    fn space() -> ParameterSpace {
        ParameterSpace::new(vec![
            Parameter::new("a", -1.0, 3.0, 0.0).unwrap(),
            Parameter::new("b", 10.0, 20.0, 12.0)
                .unwrap()
                .with_unit("psi"),
        ])
        .unwrap()
    }

    #[test]
    fn unit_map_is_affine() {
        let s = space();
        let u = s.to_unit(&[1.0, 15.0]).unwrap();
        assert_relative_eq!(u[0], 0.5);
        assert_relative_eq!(u[1], 0.5);
        assert_eq!(s.from_unit(&[0.0, 1.0]).unwrap(), vec![-1.0, 20.0]);
        assert!(s.to_unit(&[1.0]).is_err());
        assert!(s.to_unit(&[f64::NAN, 1.0]).is_err());
    }

    #[test]
    fn admits_the_bounds_up_to_round_off() {
        let p = Parameter::new("t", 1.0, 3.0, 2.0).unwrap();
        for v in [1.0, 2.5, 3.0, 1.0 - 1e-13, 3.0 + 1e-13] {
            assert!(p.admits(v), "{v}");
        }
        for v in [1.0 - 1e-11, 3.0 + 1e-11, f64::NAN, f64::INFINITY] {
            assert!(!p.admits(v), "{v}");
        }
    }

    #[test]
    fn invalid_parameters_are_rejected() {
        assert!(Parameter::new("x", 1.0, 1.0, 1.0).is_err());
        assert!(Parameter::new("x", 0.0, 1.0, 2.0).is_err());
        assert!(Parameter::new("x", 0.0, f64::INFINITY, 0.5).is_err());
        assert!(Parameter::new("", 0.0, 1.0, 0.5).is_err());
        let dup = vec![
            Parameter::new("x", 0.0, 1.0, 0.5).unwrap(),
            Parameter::new("x", 0.0, 2.0, 0.5).unwrap(),
        ];
        assert!(ParameterSpace::new(dup).is_err());
        assert!(ParameterSpace::new(vec![]).is_err());
    }

    #[test]
    fn bounds_csv_round_trip_and_faults() {
        let s = space();
        let back = ParameterSpace::parse_csv(&s.to_csv_string(), "b.csv").unwrap();
        assert_eq!(back, s);
        let four = ParameterSpace::parse_csv("name,lower,upper,nominal\nt,1,2,1.5\n", "b.csv");
        assert_eq!(four.unwrap().dim(), 1);
        let pos = |text: &str| match ParameterSpace::parse_csv(text, "b.csv").unwrap_err() {
            CoreError::Csv { row, column, .. } => (row, column),
            e => panic!("unexpected {e}"),
        };
        assert_eq!(pos("name,low,upper,nominal\n"), (1, 2));
        assert_eq!(pos("name,lower,upper,nominal\nt,1,x,1\n"), (2, 3));
        assert_eq!(pos("name,lower,upper,nominal\nt,2,1,1.5\n"), (2, 3));
        assert_eq!(pos("name,lower,upper,nominal\nt,1,2,3\n"), (2, 4));
        assert_eq!(pos("name,lower,upper,nominal\nt,1,2\n"), (2, 4));
        assert_eq!(pos("name,lower,upper,nominal\nt,1,2,1\nt,1,2,1\n"), (3, 1));
        assert!(ParameterSpace::parse_csv("", "b.csv").is_err());
        assert!(ParameterSpace::parse_csv("name,lower,upper,nominal\n", "b.csv").is_err());
    }

    #[test]
    fn serde_round_trip_validates() {
        let s = space();
        let json = serde_json::to_string(&s).unwrap();
        let back: ParameterSpace = serde_json::from_str(&json).unwrap();
        assert_eq!(back, s);
        let bad = json.replace("\"upper\":3.0", "\"upper\":-2.0");
        assert!(serde_json::from_str::<ParameterSpace>(&bad).is_err());
    }

    #[test]
    fn matrix_maps_equal_the_point_maps() {
        let s = space();
        let x = faer::Mat::from_fn(5, 2, |i, j| [-1.0, 10.0][j] + 0.37 * (i * (j + 2)) as f64);
        let u = s.to_unit_matrix(x.as_ref()).unwrap();
        for i in 0..5 {
            let row: Vec<f64> = x.row(i).iter().copied().collect();
            let expected = s.to_unit(&row).unwrap();
            let got: Vec<f64> = u.row(i).iter().copied().collect();
            assert_eq!(got, expected);
            let back: Vec<f64> = s
                .from_unit_matrix(u.as_ref())
                .unwrap()
                .row(i)
                .iter()
                .copied()
                .collect();
            assert_eq!(back, s.from_unit(&expected).unwrap());
        }
        assert!(matches!(
            s.to_unit_matrix(faer::Mat::<f64>::zeros(2, 3).as_ref()),
            Err(CoreError::DimensionMismatch {
                expected: 2,
                found: 3,
                ..
            })
        ));
        let mut bad = x.clone();
        bad[(3, 1)] = f64::NAN;
        match s.to_unit_matrix(bad.as_ref()).unwrap_err() {
            CoreError::NonFinite { location, .. } => assert!(location.contains("`b`")),
            e => panic!("unexpected {e}"),
        }
    }

    proptest! {
        #[test]
        fn unit_round_trip(lo in -1e3f64..1e3, w in 1e-3f64..1e3, f in 0.0f64..1.0) {
            let s = ParameterSpace::new(vec![Parameter::new("p", lo, lo + w, lo).unwrap()]).unwrap();
            let x = lo + f * w;
            let back = s.from_unit(&s.to_unit(&[x]).unwrap()).unwrap()[0];
            prop_assert!((back - x).abs() <= 1e-12 * (1.0 + x.abs()));
        }
    }
}
